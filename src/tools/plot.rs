//! A line plot as PNG (for `tinydem analyze --plot`): one series against time, with axis
//! titles and units, round ticks with their values, and a light grid.

use anyhow::{Result, bail};
use image::{Rgb, RgbImage};

use crate::tools::text::{self, put};

/// The axis titles of a plot, units included (`time [s]`, `kinetic_energy [J]`).
#[derive(Clone, Debug)]
pub struct Axes<'a> {
    pub x: &'a str,
    pub y: &'a str,
}

const BLACK: Rgb<u8> = Rgb([0, 0, 0]);
const GRID: Rgb<u8> = Rgb([225, 225, 225]);
const LINE: Rgb<u8> = Rgb([31, 90, 180]);

/// Plots the points `(t, y)` (non-finite ones are skipped) as a line on a `width` x
/// `height` picture with the titles `axes`.
pub fn line_plot(points: &[(f64, f64)], width: u32, height: u32, axes: &Axes) -> Result<RgbImage> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(t, y)| t.is_finite() && y.is_finite())
        .collect();
    if pts.is_empty() {
        bail!("nothing to plot: the column has no finite values");
    }
    let range = |f: fn(&(f64, f64)) -> f64| {
        let (lo, hi) = pts
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if hi > lo {
            (lo, hi)
        } else {
            let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            (lo - pad, hi + pad)
        }
    };
    let (t0, t1) = range(|p| p.0);
    let (y0, y1) = range(|p| p.1);
    // A little room above and below the line.
    let (y0, y1) = (y0 - 0.04 * (y1 - y0), y1 + 0.04 * (y1 - y0));
    let scale = (height / 300).clamp(1, 4);
    let s = scale as i64;
    let y_ticks = text::ticks(y0, y1, 5);
    let label_width = y_ticks
        .iter()
        .map(|v| text::width(&text::number(*v), scale))
        .max()
        .unwrap_or(0);
    let (l, r) = (label_width + 16 * s, width as i64 - 16 * s);
    let (top, bottom) = (28 * s, height as i64 - 38 * s);
    if r <= l + 20 || bottom <= top + 20 {
        bail!("plot size {width}x{height} is too small");
    }
    let mut img = RgbImage::from_pixel(width, height, Rgb([255, 255, 255]));
    let px = |t: f64| l as f64 + (t - t0) / (t1 - t0) * (r - l) as f64;
    let py = |y: f64| bottom as f64 - (y - y0) / (y1 - y0) * (bottom - top) as f64;
    // Grid and ticks with their values.
    for v in &y_ticks {
        let y = py(*v).round() as i64;
        for x in l..=r {
            put(&mut img, x, y, GRID);
        }
        for x in l - 4 * s..l {
            put(&mut img, x, y, BLACK);
        }
        let label = text::number(*v);
        let w = text::width(&label, scale);
        text::draw(&mut img, l - 6 * s - w, y - 4 * s, &label, scale, BLACK);
    }
    for v in text::ticks(t0, t1, 6) {
        let x = px(v).round() as i64;
        for y in top..=bottom {
            put(&mut img, x, y, GRID);
        }
        for y in bottom..bottom + 4 * s {
            put(&mut img, x, y, BLACK);
        }
        let label = text::number(v);
        let w = text::width(&label, scale);
        text::draw(&mut img, x - w / 2, bottom + 7 * s, &label, scale, BLACK);
    }
    // The frame of the plot area.
    for x in l..=r {
        put(&mut img, x, top, BLACK);
        put(&mut img, x, bottom, BLACK);
    }
    for y in top..=bottom {
        put(&mut img, l, y, BLACK);
        put(&mut img, r, y, BLACK);
    }
    for w in pts.windows(2) {
        let (ax, ay, bx, by) = (px(w[0].0), py(w[0].1), px(w[1].0), py(w[1].1));
        let n = ((bx - ax).abs().max((by - ay).abs()).ceil() as usize).max(1);
        for k in 0..=n {
            let f = k as f64 / n as f64;
            let (x, y) = (ax + f * (bx - ax), ay + f * (by - ay));
            for dy in 0..s.max(2) {
                for dx in 0..s.max(2) {
                    put(&mut img, x as i64 + dx, y as i64 + dy, LINE);
                }
            }
        }
    }
    // Axis titles: y above the axis, x centred below the tick values.
    text::draw(&mut img, l, top - 14 * s, axes.y, scale, BLACK);
    let w = text::width(axes.x, scale);
    text::draw(
        &mut img,
        (l + r) / 2 - w / 2,
        bottom + 22 * s,
        axes.x,
        scale,
        BLACK,
    );
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_a_line_with_titles_and_ticks() {
        let pts: Vec<(f64, f64)> = (0..50)
            .map(|k| (k as f64 * 0.1, (k as f64 * 0.2).sin()))
            .collect();
        let axes = Axes {
            x: "time [s]",
            y: "kinetic_energy [J]",
        };
        let img = line_plot(&pts, 400, 300, &axes).unwrap();
        let line = img.pixels().filter(|p| **p == LINE).count();
        let black = img.pixels().filter(|p| **p == BLACK).count();
        let grid = img.pixels().filter(|p| **p == GRID).count();
        assert!(
            line > 300 && black > 1500 && grid > 500,
            "{line} {black} {grid}"
        );
        assert!(line_plot(&[(0.0, f64::NAN)], 400, 300, &axes).is_err());
        // A constant series still gets a range.
        assert!(line_plot(&[(0.0, 2.0), (1.0, 2.0)], 400, 300, &axes).is_ok());
    }
}

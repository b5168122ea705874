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
    let plot = Area::of(&pts, width, height)?;
    let mut img = RgbImage::from_pixel(width, height, Rgb([255, 255, 255]));
    plot.y_grid(&mut img);
    plot.t_grid(&mut img);
    plot.frame(&mut img);
    plot.line(&mut img, &pts);
    plot.titles(&mut img, axes);
    Ok(img)
}

/// The range of `f` over `pts`, widened when it is a single value.
fn range(pts: &[(f64, f64)], f: fn(&(f64, f64)) -> f64) -> (f64, f64) {
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
}

/// The plot area of a picture: where it lies in pixels, and the data ranges it shows.
struct Area {
    /// The left, right, top and bottom edges [px].
    l: i64,
    r: i64,
    top: i64,
    bottom: i64,
    t: (f64, f64),
    y: (f64, f64),
    /// The y values with a tick.
    y_ticks: Vec<f64>,
    /// The size of text and lines: one per 300 pixels of height.
    scale: u32,
}

impl Area {
    /// The area for `pts` on a `width` x `height` picture, with room for the tick values
    /// and titles around it.
    fn of(pts: &[(f64, f64)], width: u32, height: u32) -> Result<Area> {
        let t = range(pts, |p| p.0);
        let (y0, y1) = range(pts, |p| p.1);
        // A little room above and below the line.
        let y = (y0 - 0.04 * (y1 - y0), y1 + 0.04 * (y1 - y0));
        let scale = (height / 300).clamp(1, 4);
        let s = scale as i64;
        let y_ticks = text::ticks(y.0, y.1, 5);
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
        Ok(Area {
            l,
            r,
            top,
            bottom,
            t,
            y,
            y_ticks,
            scale,
        })
    }

    fn s(&self) -> i64 {
        self.scale as i64
    }

    /// The pixel column of time `t`.
    fn px(&self, t: f64) -> f64 {
        let (t0, t1) = self.t;
        self.l as f64 + (t - t0) / (t1 - t0) * (self.r - self.l) as f64
    }

    /// The pixel row of value `y`.
    fn py(&self, y: f64) -> f64 {
        let (y0, y1) = self.y;
        self.bottom as f64 - (y - y0) / (y1 - y0) * (self.bottom - self.top) as f64
    }

    /// The grid lines across at the y ticks, with their ticks and values on the left.
    fn y_grid(&self, img: &mut RgbImage) {
        let s = self.s();
        for v in &self.y_ticks {
            let y = self.py(*v).round() as i64;
            for x in self.l..=self.r {
                put(img, x, y, GRID);
            }
            for x in self.l - 4 * s..self.l {
                put(img, x, y, BLACK);
            }
            let label = text::number(*v);
            let w = text::width(&label, self.scale);
            text::draw(
                img,
                self.l - 6 * s - w,
                y - 4 * s,
                &label,
                self.scale,
                BLACK,
            );
        }
    }

    /// The grid lines up at the time ticks, with their ticks and values below.
    fn t_grid(&self, img: &mut RgbImage) {
        let s = self.s();
        for v in text::ticks(self.t.0, self.t.1, 6) {
            let x = self.px(v).round() as i64;
            for y in self.top..=self.bottom {
                put(img, x, y, GRID);
            }
            for y in self.bottom..self.bottom + 4 * s {
                put(img, x, y, BLACK);
            }
            let label = text::number(v);
            let w = text::width(&label, self.scale);
            text::draw(
                img,
                x - w / 2,
                self.bottom + 7 * s,
                &label,
                self.scale,
                BLACK,
            );
        }
    }

    /// The frame around the area.
    fn frame(&self, img: &mut RgbImage) {
        for x in self.l..=self.r {
            put(img, x, self.top, BLACK);
            put(img, x, self.bottom, BLACK);
        }
        for y in self.top..=self.bottom {
            put(img, self.l, y, BLACK);
            put(img, self.r, y, BLACK);
        }
    }

    /// The line through `pts`, at least two pixels thick.
    fn line(&self, img: &mut RgbImage, pts: &[(f64, f64)]) {
        let thick = self.s().max(2);
        for w in pts.windows(2) {
            let (ax, ay) = (self.px(w[0].0), self.py(w[0].1));
            let (bx, by) = (self.px(w[1].0), self.py(w[1].1));
            let n = ((bx - ax).abs().max((by - ay).abs()).ceil() as usize).max(1);
            for k in 0..=n {
                let f = k as f64 / n as f64;
                let (x, y) = (ax + f * (bx - ax), ay + f * (by - ay));
                for dy in 0..thick {
                    for dx in 0..thick {
                        put(img, x as i64 + dx, y as i64 + dy, LINE);
                    }
                }
            }
        }
    }

    /// The axis titles: y above the axis, x centred below the tick values.
    fn titles(&self, img: &mut RgbImage, axes: &Axes) {
        let s = self.s();
        text::draw(img, self.l, self.top - 14 * s, axes.y, self.scale, BLACK);
        let w = text::width(axes.x, self.scale);
        let x = (self.l + self.r) / 2 - w / 2;
        text::draw(img, x, self.bottom + 22 * s, axes.x, self.scale, BLACK);
    }
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
        // The axes are black; the labels, anti-aliased, dark.
        let black = img
            .pixels()
            .filter(|p| p.0.iter().all(|&c| c < 100))
            .count();
        let grid = img.pixels().filter(|p| **p == GRID).count();
        assert!(
            line > 300 && black > 1000 && grid > 500,
            "{line} {black} {grid}"
        );
        assert!(line_plot(&[(0.0, f64::NAN)], 400, 300, &axes).is_err());
        // A constant series still gets a range.
        assert!(line_plot(&[(0.0, 2.0), (1.0, 2.0)], 400, 300, &axes).is_ok());
    }
}

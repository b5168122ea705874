//! A small line plot as PNG (for `tinydem analyze --plot`): one series against time, with
//! the axis ranges written at the corners in a built-in 5x7 pixel font.

use anyhow::{Result, bail};
use image::{Rgb, RgbImage};

/// 5x7 glyphs for the characters of numbers; each row is 5 bits, most significant left.
fn glyph(c: char) -> Option<[u8; 7]> {
    Some(match c {
        '0' => [14, 17, 19, 21, 25, 17, 14],
        '1' => [4, 12, 4, 4, 4, 4, 14],
        '2' => [14, 17, 1, 2, 4, 8, 31],
        '3' => [30, 1, 1, 14, 1, 1, 30],
        '4' => [2, 6, 10, 18, 31, 2, 2],
        '5' => [31, 16, 30, 1, 1, 17, 14],
        '6' => [6, 8, 16, 30, 17, 17, 14],
        '7' => [31, 1, 2, 4, 8, 8, 8],
        '8' => [14, 17, 17, 14, 17, 17, 14],
        '9' => [14, 17, 17, 15, 1, 2, 12],
        '.' => [0, 0, 0, 0, 0, 12, 12],
        '-' => [0, 0, 0, 31, 0, 0, 0],
        '+' => [0, 4, 4, 31, 4, 4, 0],
        'e' => [0, 0, 14, 17, 31, 16, 14],
        ' ' => [0; 7],
        _ => return None,
    })
}

/// Draws `text` with its top-left corner at (x, y), 2x scaled.
fn text(img: &mut RgbImage, x: i64, y: i64, s: &str) {
    for (k, c) in s.chars().enumerate() {
        let Some(rows) = glyph(c) else { continue };
        for (r, bits) in rows.iter().enumerate() {
            for col in 0..5 {
                if bits & (16 >> col) != 0 {
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let (px, py) = (x + 12 * k as i64 + 2 * col + dx, y + 2 * r as i64 + dy);
                        if px >= 0
                            && py >= 0
                            && (px as u32) < img.width()
                            && (py as u32) < img.height()
                        {
                            img.put_pixel(px as u32, py as u32, Rgb([0, 0, 0]));
                        }
                    }
                }
            }
        }
    }
}

/// Plots the points `(t, y)` (non-finite y are skipped) as a line on a `width` x `height`
/// picture; the y range is written top-left and bottom-left, the t range along the bottom.
pub fn line_plot(points: &[(f64, f64)], width: u32, height: u32) -> Result<RgbImage> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(t, y)| t.is_finite() && y.is_finite())
        .collect();
    if pts.is_empty() {
        bail!("nothing to plot: the column has no finite values");
    }
    let (t0, t1) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    let (y0, y1) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.1), b.max(p.1))
        });
    let (t1, y1) = (
        if t1 > t0 { t1 } else { t0 + 1.0 },
        if y1 > y0 { y1 } else { y0 + 1.0 },
    );
    let mut img = RgbImage::from_pixel(width, height, Rgb([255, 255, 255]));
    let (l, r, top, bottom) = (20.0, width as f64 - 20.0, 40.0, height as f64 - 40.0);
    if r <= l + 10.0 || bottom <= top + 10.0 {
        bail!("plot size {width}x{height} is too small");
    }
    let px = |t: f64, y: f64| {
        (
            l + (t - t0) / (t1 - t0) * (r - l),
            bottom - (y - y0) / (y1 - y0) * (bottom - top),
        )
    };
    let grey = Rgb([150, 150, 150]);
    for x in l as u32..=r as u32 {
        img.put_pixel(x, bottom as u32, grey);
        img.put_pixel(x, top as u32, grey);
    }
    for y in top as u32..=bottom as u32 {
        img.put_pixel(l as u32, y, grey);
        img.put_pixel(r as u32, y, grey);
    }
    let blue = Rgb([31, 90, 180]);
    for w in pts.windows(2) {
        let ((ax, ay), (bx, by)) = (px(w[0].0, w[0].1), px(w[1].0, w[1].1));
        let n = ((bx - ax).abs().max((by - ay).abs()).ceil() as usize).max(1);
        for k in 0..=n {
            let f = k as f64 / n as f64;
            let (x, y) = (ax + f * (bx - ax), ay + f * (by - ay));
            for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
                let (x, y) = ((x + dx) as u32, (y + dy) as u32);
                if x < width && y < height {
                    img.put_pixel(x, y, blue);
                }
            }
        }
    }
    text(&mut img, l as i64, 8, &format!("{y1:.4e}"));
    text(&mut img, l as i64, bottom as i64 + 6, &format!("{y0:.4e}"));
    text(&mut img, l as i64, bottom as i64 + 22, &format!("{t0:.3e}"));
    let right = format!("{t1:.3e}");
    text(
        &mut img,
        r as i64 - 12 * right.len() as i64,
        bottom as i64 + 22,
        &right,
    );
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_a_line_and_its_ranges() {
        let pts: Vec<(f64, f64)> = (0..50)
            .map(|k| (k as f64 * 0.1, (k as f64 * 0.2).sin()))
            .collect();
        let img = line_plot(&pts, 400, 300).unwrap();
        let blue = img.pixels().filter(|p| p.0 == [31, 90, 180]).count();
        let black = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
        assert!(blue > 300 && black > 100, "{blue} {black}");
        assert!(line_plot(&[(0.0, f64::NAN)], 400, 300).is_err());
    }
}

//! Text and number labels on pictures (plots, renders): the 8x8 bitmap font of `font8x8`
//! (ASCII, Latin-1 and Greek, so "µ", "°" and "ω" too), drawn at an integer scale.

use font8x8::{BASIC_FONTS, GREEK_FONTS, LATIN_FONTS, UnicodeFonts};
use image::{Rgb, RgbImage};

/// Width of a glyph cell at scale 1 [px] (the font's 8, less the blank column most glyphs
/// end with, so that text does not look spaced out).
const ADVANCE: i64 = 7;
/// Height of a line at scale 1 \[px\].
pub const LINE: i64 = 8;

fn glyph(c: char) -> [u8; 8] {
    BASIC_FONTS
        .get(c)
        .or_else(|| LATIN_FONTS.get(c))
        .or_else(|| GREEK_FONTS.get(c))
        .unwrap_or([0; 8])
}

/// The width of `s` at `scale` \[px\].
pub fn width(s: &str, scale: u32) -> i64 {
    s.chars().count() as i64 * ADVANCE * scale as i64
}

/// Draws `s` with its top-left corner at (x, y), each font pixel a `scale` x `scale` block.
pub fn draw(img: &mut RgbImage, x: i64, y: i64, s: &str, scale: u32, colour: Rgb<u8>) {
    let k = scale as i64;
    for (n, c) in s.chars().enumerate() {
        let rows = glyph(c);
        let x0 = x + n as i64 * ADVANCE * k;
        for (r, bits) in rows.iter().enumerate() {
            for col in 0..8 {
                // Bit 0 is the leftmost pixel.
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..k {
                    for dx in 0..k {
                        put(img, x0 + col * k + dx, y + r as i64 * k + dy, colour);
                    }
                }
            }
        }
    }
}

/// Sets a pixel if it lies in the picture.
pub fn put(img: &mut RgbImage, x: i64, y: i64, colour: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, colour);
    }
}

/// A number for a label: plain with up to 4 significant digits between 10^-3 and 10^5,
/// otherwise in scientific notation ("2.5e-7"); no trailing zeros.
pub fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        if s == "-0" { "0".into() } else { s }
    } else {
        let s = format!("{v:.2e}");
        let (m, e) = s.split_once('e').expect("scientific");
        let m = m.trim_end_matches('0').trim_end_matches('.');
        format!("{m}e{e}")
    }
}

/// `v` rounded to `digits` significant digits (for labels such as a time stamp, where a
/// frame's 0.59994 s reads as 0.6 s).
pub fn rounded(v: f64, digits: usize) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    format!("{v:.*e}", digits.saturating_sub(1))
        .parse()
        .unwrap_or(v)
}

/// Round tick values covering [lo, hi]: about `count` steps of 1, 2 or 5 times a power of
/// ten, the ticks that lie within the range.
pub fn ticks(lo: f64, hi: f64, count: usize) -> Vec<f64> {
    if hi <= lo || !lo.is_finite() || !hi.is_finite() {
        return vec![lo];
    }
    let raw = (hi - lo) / count.max(1) as f64;
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .map(|k| k as f64 * step)
        .map(|t| if t.abs() < 1e-12 * step { 0.0 } else { t })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_round_to_significant_digits() {
        assert_eq!(number(rounded(0.59994638, 3)), "0.6");
        assert_eq!(number(rounded(9.064373, 3)), "9.06");
        assert_eq!(number(rounded(0.2589821, 3)), "0.259");
        assert_eq!(rounded(0.0, 3), 0.0);
    }

    #[test]
    fn numbers_read_as_people_write_them() {
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(1.25), "1.25");
        assert_eq!(number(1234.56), "1235");
        assert_eq!(number(0.012345), "0.01235");
        assert_eq!(number(2.5e-7), "2.5e-7");
        assert_eq!(number(-3.0), "-3");
        assert_eq!(number(0.0), "0");
    }

    #[test]
    fn ticks_are_round_and_inside() {
        let t = ticks(0.0, 1.0, 5);
        assert_eq!(t.len(), 6, "{t:?}");
        assert!(
            t.iter()
                .zip([0.0, 0.2, 0.4, 0.6, 0.8, 1.0])
                .all(|(a, b)| (a - b).abs() < 1e-12)
        );
        let t = ticks(-0.013, 0.27, 4);
        assert!(t.iter().all(|&v| (-0.013..=0.27).contains(&v)));
        assert_eq!(t.len(), 3, "{t:?}"); // 0, 0.1, 0.2
        assert_eq!(ticks(1.0, 1.0, 5), vec![1.0]);
    }

    #[test]
    fn text_is_drawn_where_asked() {
        let mut img = RgbImage::from_pixel(100, 20, Rgb([255, 255, 255]));
        draw(&mut img, 2, 2, "m/s µ", 2, Rgb([0, 0, 0]));
        let dark = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
        assert!(dark > 40, "{dark}");
        assert_eq!(width("abc", 2), 42);
        assert!(img.get_pixel(99, 19).0 == [255, 255, 255]);
    }
}

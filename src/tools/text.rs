//! Text and number labels on pictures (plots, renders): DejaVu Sans (`assets/fonts`, its
//! licence beside it), anti-aliased, at a size that `scale` sets as the 8x8 cells of a
//! bitmap font would be (a line is `LINE` x `scale` pixels).

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use image::{Rgb, RgbImage};

/// Height of a line at scale 1 \[px\].
pub const LINE: i64 = 8;

/// The font's em at scale 1 \[px\]: its capitals 6.2 px tall, as the bitmap font's were.
const EM: f32 = 8.5;

/// The font file, inflated on first use.
pub fn ttf() -> &'static [u8] {
    static TTF: OnceLock<Vec<u8>> = OnceLock::new();
    TTF.get_or_init(|| {
        use std::io::Read;
        let gz: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf.gz");
        let mut ttf = Vec::with_capacity(800_000);
        flate2::read::GzDecoder::new(gz)
            .read_to_end(&mut ttf)
            .expect("the font built in is gzip");
        ttf
    })
}

/// The font, parsed on first use.
fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| {
        FontRef::try_from_slice(ttf()).expect("the font built in is a TrueType font")
    })
}

/// Each glyph of `s` at `scale` with its pen position along the line \[px\], and the
/// line's width.
fn layout(s: &str, scale: u32) -> (Vec<(ab_glyph::GlyphId, f32)>, f32) {
    let f = font().as_scaled(PxScale::from(EM * scale as f32));
    let mut x = 0.0;
    let mut last = None;
    let mut glyphs = Vec::with_capacity(s.len());
    for c in s.chars() {
        let id = f.glyph_id(c);
        if let Some(prev) = last {
            x += f.kern(prev, id);
        }
        glyphs.push((id, x));
        x += f.h_advance(id);
        last = Some(id);
    }
    (glyphs, x)
}

/// The width of `s` at `scale` \[px\].
pub fn width(s: &str, scale: u32) -> i64 {
    layout(s, scale).1.ceil() as i64
}

/// Draws `s` with its top-left corner at (x, y): capitals from about y + scale to the
/// baseline at y + 7.2 scale, anti-aliased over what is there.
pub fn draw(img: &mut RgbImage, x: i64, y: i64, s: &str, scale: u32, colour: Rgb<u8>) {
    let size = PxScale::from(EM * scale as f32);
    let f = font().as_scaled(size);
    let baseline = y as f32 + 7.2 * scale as f32;
    for (id, pen) in layout(s, scale).0 {
        let glyph = id.with_scale_and_position(size, point(x as f32 + pen, baseline));
        let Some(outline) = f.outline_glyph(glyph) else {
            continue;
        };
        let b = outline.px_bounds();
        outline.draw(|gx, gy, coverage| {
            let (px, py) = (b.min.x as i64 + gx as i64, b.min.y as i64 + gy as i64);
            blend(img, px, py, colour, coverage);
        });
    }
}

/// Mixes `colour` into the pixel at (x, y) by `coverage` (0 to 1), if it lies in the
/// picture.
fn blend(img: &mut RgbImage, x: i64, y: i64, colour: Rgb<u8>, coverage: f32) {
    if x < 0 || y < 0 || x as u32 >= img.width() || y as u32 >= img.height() {
        return;
    }
    let c = coverage.clamp(0.0, 1.0);
    let p = img.get_pixel_mut(x as u32, y as u32);
    for k in 0..3 {
        p.0[k] = (p.0[k] as f32 * (1.0 - c) + colour.0[k] as f32 * c).round() as u8;
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
        let mut img = RgbImage::from_pixel(100, 24, Rgb([255, 255, 255]));
        draw(&mut img, 2, 2, "m/s µ", 2, Rgb([0, 0, 0]));
        // Anti-aliased: some pixels wholly ink, more partly.
        let dark = img.pixels().filter(|p| p.0[0] < 128).count();
        let ink = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
        assert!(dark > 40 && ink > 0, "{dark} {ink}");
        // Within the line: from y to y + LINE x scale, and descenders a little below.
        let rows: Vec<u32> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| p.0[0] < 128)
            .map(|(_, y, _)| y)
            .collect();
        assert!(rows.iter().all(|&y| (2..24).contains(&y)), "{rows:?}");
        assert!(img.get_pixel(99, 23).0 == [255, 255, 255]);
        // Widths grow with the text and the scale; an unknown character still advances.
        let (one, two) = (width("abc", 1), width("abc", 2));
        assert!(one > 10 && (two - 2 * one).abs() <= 1, "{one} {two}");
        assert!(width("abcd", 1) > one && width("\u{10FFFF}", 1) >= 0);
    }
}

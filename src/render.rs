//! Pictures of frames: particles as shaded spheres (coloured by speed, height or radius)
//! with the mesh edges, in an orthographic view, written as PNG (or an animated GIF).

use anyhow::{Result, bail};
use glam::{DMat3, DVec3};
use image::{Rgb, RgbImage};

use crate::mesh::{Mesh, Primitive};
use crate::particles::Particles;

/// What the particle colour shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ColorBy {
    Speed,
    Height,
    Radius,
    Tag,
}

/// Where the camera looks from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum View {
    /// Along +y: x to the right, z up.
    Front,
    /// Along -x: y to the right, z up.
    Side,
    /// Down -z: x to the right, y up.
    Top,
    /// From azimuth 45°, elevation 30°.
    Iso,
}

/// Picture settings.
#[derive(Clone, Copy, Debug)]
pub struct Style {
    pub width: u32,
    pub height: u32,
    pub color: ColorBy,
    pub view: View,
}

const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
const EDGE: Rgb<u8> = Rgb([60, 60, 60]);

/// Camera axes: rows are screen right, screen up and the direction toward the viewer.
fn camera(view: View) -> DMat3 {
    let (right, up) = match view {
        View::Front => (DVec3::X, DVec3::Z),
        View::Side => (-DVec3::Y, DVec3::Z),
        View::Top => (DVec3::X, DVec3::Y),
        View::Iso => {
            let (az, el) = (45f64.to_radians(), 30f64.to_radians());
            let toward = DVec3::new(el.cos() * az.sin(), -el.cos() * az.cos(), el.sin());
            let right = DVec3::Z.cross(toward).normalize();
            (right, toward.cross(right))
        }
    };
    DMat3::from_cols(right, up, right.cross(up)).transpose()
}

/// A perceptual blue-green-yellow colour map (after viridis), for s in [0, 1].
fn colormap(s: f64) -> DVec3 {
    const STOPS: [[f64; 3]; 5] = [
        [0.267, 0.005, 0.329],
        [0.230, 0.322, 0.546],
        [0.128, 0.567, 0.551],
        [0.369, 0.789, 0.383],
        [0.993, 0.906, 0.144],
    ];
    let x = s.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let k = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - k as f64;
    DVec3::from_array(STOPS[k]).lerp(DVec3::from_array(STOPS[k + 1]), f)
}

/// Renders particles (and mesh edges) to an image.
pub fn render(p: &Particles, mesh: &Mesh, style: &Style) -> Result<RgbImage> {
    if style.width == 0 || style.height == 0 || style.width > 16384 || style.height > 16384 {
        bail!(
            "picture size {}x{} must be between 1 and 16384 pixels a side",
            style.width,
            style.height
        );
    }
    let cam = camera(style.view);
    // Rounded mesh primitives (points and edges with a radius) are drawn as grey spheres.
    let mut balls: Vec<(DVec3, f64)> = Vec::new();
    for face in &mesh.faces {
        match face.shape {
            Primitive::Point(a) if face.radius > 0.0 => balls.push((a, face.radius)),
            Primitive::Segment(a, b) if face.radius > 0.0 => {
                let n = ((a.distance(b) / (0.25 * face.radius)).ceil() as usize).clamp(1, 4096);
                balls.extend((0..=n).map(|k| (a.lerp(b, k as f64 / n as f64), face.radius)));
            }
            _ => {}
        }
    }
    // Bounds in camera coordinates: the mesh, and the particles without the farthest
    // half per cent on each side (a few escaped grains should not shrink the picture).
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for face in &mesh.faces {
        for c in face.corners() {
            let c = cam * c;
            lo = lo.min(c - face.radius);
            hi = hi.max(c + face.radius);
        }
    }
    if !p.is_empty() {
        let r_max = p.max_radius();
        let cut = p.len() / 200;
        for axis in 0..3 {
            let mut v: Vec<f64> = p.x.iter().map(|x| (cam * *x)[axis]).collect();
            v.sort_by(f64::total_cmp);
            lo[axis] = lo[axis].min(v[cut] - r_max);
            hi[axis] = hi[axis].max(v[v.len() - 1 - cut] + r_max);
        }
    }
    if !lo.is_finite() || !hi.is_finite() {
        lo = DVec3::splat(-1.0);
        hi = DVec3::splat(1.0);
    }
    let (w, h) = (style.width as f64, style.height as f64);
    let span = (hi - lo).max(DVec3::splat(1e-12));
    let scale = 0.95 * (w / span.x).min(h / span.y);
    let mid = 0.5 * (lo + hi);
    let to_px = |c: DVec3| {
        (
            0.5 * w + (c.x - mid.x) * scale,
            0.5 * h - (c.y - mid.y) * scale,
        )
    };

    let values: Vec<f64> = match style.color {
        ColorBy::Speed => p.v.iter().map(|v| v.length()).collect(),
        ColorBy::Height => p.x.iter().map(|x| x.z).collect(),
        ColorBy::Radius => p.radius.clone(),
        ColorBy::Tag => p.tag.iter().map(|&t| t as f64).collect(),
    };
    // Colour range from the 1 % to the 99 % quantile, so that outliers do not wash it out
    // (radii and tags: the full range, as a few special particles are the point of such a
    // picture).
    let (vmin, vmax) = {
        let mut sorted = values.clone();
        sorted.sort_by(f64::total_cmp);
        let cut = if style.color == ColorBy::Radius {
            0
        } else {
            sorted.len() / 100
        };
        match sorted.len() {
            0 => (0.0, 1.0),
            n => (sorted[cut], sorted[n - 1 - cut]),
        }
    };
    let norm = |v: f64| {
        if vmax > vmin {
            (v - vmin) / (vmax - vmin)
        } else {
            0.5
        }
    };

    let mut img = RgbImage::from_pixel(style.width, style.height, BACKGROUND);
    let mut depth = vec![f64::NEG_INFINITY; (style.width * style.height) as usize];
    let light = DVec3::new(-0.4, 0.6, 0.7).normalize();
    let mut sphere = |centre: DVec3, radius: f64, base: DVec3| {
        let c = cam * centre;
        let (cx, cy) = to_px(c);
        let rp = radius * scale;
        if cx + rp < 0.0 || cy + rp < 0.0 || cx - rp > w || cy - rp > h {
            return;
        }
        let (x0, x1) = (
            (cx - rp).floor().max(0.0) as i64,
            (cx + rp).ceil().min(w - 1.0) as i64,
        );
        let (y0, y1) = (
            (cy - rp).floor().max(0.0) as i64,
            (cy + rp).ceil().min(h - 1.0) as i64,
        );
        for py in y0..=y1 {
            for px in x0..=x1 {
                let dx = (px as f64 + 0.5 - cx) / rp.max(1e-9);
                let dy = (cy - py as f64 - 0.5) / rp.max(1e-9);
                let d2 = dx * dx + dy * dy;
                if d2 > 1.0 && rp >= 0.7 {
                    continue;
                }
                let dz = (1.0 - d2).max(0.0).sqrt();
                let z = c.z + dz * radius;
                let at = (py as u32 * style.width + px as u32) as usize;
                if z <= depth[at] {
                    continue;
                }
                depth[at] = z;
                let shade = 0.35 + 0.65 * DVec3::new(dx, dy, dz).dot(light).max(0.0);
                let rgb = (base * shade * 255.0).clamp(DVec3::ZERO, DVec3::splat(255.0));
                img.put_pixel(
                    px as u32,
                    py as u32,
                    Rgb([rgb.x as u8, rgb.y as u8, rgb.z as u8]),
                );
            }
        }
    };
    for ((x, r), v) in p.x.iter().zip(&p.radius).zip(&values) {
        sphere(*x, *r, colormap(norm(*v)));
    }
    for (c, r) in balls {
        sphere(c, r, DVec3::splat(0.75));
    }
    // Mesh edges, hidden behind particles that are in front of them.
    for face in &mesh.faces {
        let corners = face.corners();
        let n = corners.len();
        let edges = if n <= 2 { n - 1 } else { n };
        for e in 0..edges.max(1) {
            let (a, b) = (cam * corners[e % n], cam * corners[(e + 1) % n]);
            let ((ax, ay), (bx, by)) = (to_px(a), to_px(b));
            let steps = ((bx - ax).abs().max((by - ay).abs()).ceil() as usize).max(1);
            for s in 0..=steps {
                let f = s as f64 / steps as f64;
                let (x, y) = (ax + f * (bx - ax), ay + f * (by - ay));
                if x < 0.0 || y < 0.0 || x >= w || y >= h {
                    continue;
                }
                let at = (y as u32 * style.width + x as u32) as usize;
                if a.z + f * (b.z - a.z) >= depth[at] - 1e-9 * span.z {
                    img.put_pixel(x as u32, y as u32, EDGE);
                }
            }
        }
    }
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::particles::Particle;
    use glam::DQuat;

    #[test]
    fn a_sphere_is_drawn_in_the_middle() {
        let p: Particles = [Particle {
            x: DVec3::ZERO,
            radius: 1.0,
            v: DVec3::ZERO,
            q: DQuat::IDENTITY,
            w: DVec3::ZERO,
            tag: 0,
            material: 0,
        }]
        .into_iter()
        .collect();
        let style = Style {
            width: 64,
            height: 48,
            color: ColorBy::Speed,
            view: View::Iso,
        };
        let img = render(&p, &Mesh::default(), &style).unwrap();
        assert_eq!(img.dimensions(), (64, 48));
        assert_ne!(*img.get_pixel(32, 24), BACKGROUND);
        assert_eq!(*img.get_pixel(0, 0), BACKGROUND);
    }
}

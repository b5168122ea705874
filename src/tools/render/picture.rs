//! One picture: the particles as shaded spheres and the mesh edges in a depth buffer, the
//! time stamp, the colour bar or legend on the right, and the scale bar.

use super::*;

/// Where the scene lies in the picture, and how space maps to it.
struct Scene {
    cam: DMat3,
    /// The text scale and the pixel unit of the panels.
    k: u32,
    s: i64,
    /// The picture's size.
    w: f64,
    h: f64,
    /// The scene's top margin (the time stamp), width and height.
    top: f64,
    scene_w: f64,
    scene_h: f64,
    /// The extent of the view box (for the depth test's tolerance), pixels per metre and
    /// the view box's centre.
    span: DVec3,
    scale: f64,
    mid: DVec3,
}

impl Scene {
    /// The scene of `style` and `layout`, beside a panel `panel` pixels wide.
    fn new(style: &Style, layout: &Layout, panel: i64) -> Scene {
        let k = style.scale();
        let s = k as i64;
        let (w, h) = (style.width as f64, style.height as f64);
        let top = 14.0 * s as f64;
        let scene_w = (w - panel as f64).max(16.0);
        // A band below the scene for the scale bar, so that it never covers the particles.
        let bottom = if style.scale_bar {
            14.0 * s as f64
        } else {
            0.0
        };
        let scene_h = (h - top - bottom).max(16.0);
        let (mut lo, mut hi) = (layout.lo, layout.hi);
        if !lo.is_finite() || !hi.is_finite() {
            lo = DVec3::splat(-1.0);
            hi = DVec3::splat(1.0);
        }
        let span = (hi - lo).max(DVec3::splat(1e-12));
        Scene {
            cam: camera(style.view),
            k,
            s,
            w,
            h,
            top,
            scene_w,
            scene_h,
            span,
            scale: 0.95 * (scene_w / span.x).min(scene_h / span.y),
            mid: 0.5 * (lo + hi),
        }
    }

    /// The pixel of a point in camera coordinates.
    fn to_px(&self, c: DVec3) -> (f64, f64) {
        (
            0.5 * self.scene_w + (c.x - self.mid.x) * self.scale,
            self.top + 0.5 * self.scene_h - (c.y - self.mid.y) * self.scale,
        )
    }

    /// The right edge of the scene.
    fn right(&self) -> f64 {
        self.scene_w.min(self.w)
    }
}

/// A picture with its depth buffer.
struct Canvas {
    img: RgbImage,
    depth: Vec<f64>,
    width: u32,
}

/// Renders particles (and mesh edges) in `layout`, with the colour bar or legend, the time
/// stamp (if `time` is given) and the scale bar (if the style asks).
pub fn render_in(
    p: &Particles,
    mesh: &Mesh,
    style: &Style,
    layout: &Layout,
    time: Option<f64>,
) -> Result<RgbImage> {
    if style.width < 64 || style.height < 48 || style.width > 16384 || style.height > 16384 {
        bail!(
            "picture size {}x{} must be between 64x48 and 16384x16384 pixels",
            style.width,
            style.height
        );
    }
    let (vmin, vmax) = layout.range();
    // The panel on the right: a colour bar with its tick values, or a legend.
    let bar_ticks = text::ticks(vmin, vmax, 5);
    let scene = Scene::new(style, layout, panel_width(style, layout, &bar_ticks));
    let values = style.color.values(p);
    let colour = |v: f64| {
        if style.color.categorical() {
            style.color.category(v)
        } else if vmax > vmin {
            colormap((v - vmin) / (vmax - vmin))
        } else {
            colormap(0.5)
        }
    };
    let mut canvas = Canvas {
        img: RgbImage::from_pixel(style.width, style.height, BACKGROUND),
        depth: vec![f64::NEG_INFINITY; (style.width * style.height) as usize],
        width: style.width,
    };
    for ((x, r), v) in p.x.iter().zip(&p.radius).zip(&values) {
        canvas.sphere(&scene, *x, *r, colour(*v));
    }
    for (c, r) in mesh_balls(mesh) {
        canvas.sphere(&scene, c, r, DVec3::splat(0.75));
    }
    canvas.edges(&scene, mesh);
    let (img, s, k) = (&mut canvas.img, scene.s, scene.k);
    // The time stamp, top left.
    if let Some(t) = time {
        let stamp = format!("t = {} s", text::number(text::rounded(t, 3)));
        text::draw(img, 4 * s, 3 * s, &stamp, k, INK);
    }
    if style.color.categorical() {
        legend(img, &scene, style, layout);
    } else {
        colour_bar(img, &scene, style, (vmin, vmax), &bar_ticks);
    }
    if style.scale_bar && scene.scale.is_finite() && scene.scale > 0.0 {
        scale_bar(img, &scene);
    }
    Ok(canvas.img)
}

/// The width of the panel on the right: the legend's or the colour bar's with its ticks.
fn panel_width(style: &Style, layout: &Layout, bar_ticks: &[f64]) -> i64 {
    let k = style.scale();
    let s = k as i64;
    if style.color.categorical() {
        let widest = layout
            .categories
            .iter()
            .map(|&c| text::width(&layout.label(style.color, c), k))
            .max()
            .unwrap_or(0);
        widest + 30 * s
    } else {
        let widest = bar_ticks
            .iter()
            .map(|v| text::width(&text::number(*v), k))
            .max()
            .unwrap_or(0);
        widest + 34 * s
    }
}

impl Canvas {
    /// A shaded sphere at `centre` of `radius` and colour `base`, where it is in front.
    fn sphere(&mut self, scene: &Scene, centre: DVec3, radius: f64, base: DVec3) {
        let light = DVec3::new(-0.4, 0.6, 0.7).normalize();
        let (right, h) = (scene.right(), scene.h);
        let c = scene.cam * centre;
        let (cx, cy) = scene.to_px(c);
        let rp = radius * scene.scale;
        if cx + rp < 0.0 || cy + rp < 0.0 || cx - rp > right || cy - rp > h {
            return;
        }
        let (x0, x1) = (
            (cx - rp).floor().max(0.0) as i64,
            (cx + rp).ceil().min(right - 1.0) as i64,
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
                let at = (py as u32 * self.width + px as u32) as usize;
                if z <= self.depth[at] {
                    continue;
                }
                self.depth[at] = z;
                let shade = 0.35 + 0.65 * DVec3::new(dx, dy, dz).dot(light).max(0.0);
                self.img.put_pixel(px as u32, py as u32, rgb(base * shade));
            }
        }
    }

    /// The mesh's outline ([`outline`]), hidden behind particles that are in front of it.
    fn edges(&mut self, scene: &Scene, mesh: &Mesh) {
        let (right, h) = (scene.right(), scene.h);
        for (a, b) in outline(mesh, scene.cam.row(2)) {
            {
                let (a, b) = (scene.cam * a, scene.cam * b);
                let ((ax, ay), (bx, by)) = (scene.to_px(a), scene.to_px(b));
                let steps = ((bx - ax).abs().max((by - ay).abs()).ceil() as usize).max(1);
                for st in 0..=steps {
                    let f = st as f64 / steps as f64;
                    let (x, y) = (ax + f * (bx - ax), ay + f * (by - ay));
                    if x < 0.0 || y < 0.0 || x >= right || y >= h {
                        continue;
                    }
                    let at = (y as u32 * self.width + x as u32) as usize;
                    if a.z + f * (b.z - a.z) >= self.depth[at] - 1e-9 * scene.span.z {
                        self.img.put_pixel(x as u32, y as u32, EDGE);
                    }
                }
            }
        }
    }
}

/// The edges of a mesh that show its shape, as a draughtsman draws it: the edges of a
/// surface's border, the creases where its faces meet at more than 30 degrees, and the
/// silhouette, where a face turned toward the viewer (`toward`) meets one turned away;
/// not the edges that only cut a flat or gently curved surface into faces (the spokes of a
/// drum's end cap, the seams along its side). Points and segments are drawn whole.
pub(super) fn outline(mesh: &Mesh, toward: DVec3) -> Vec<(DVec3, DVec3)> {
    let mut lo = DVec3::INFINITY;
    let mut hi = DVec3::NEG_INFINITY;
    for f in &mesh.faces {
        let (a, b) = f.bounding_box();
        (lo, hi) = (lo.min(a), hi.max(b));
    }
    // Corners of neighbouring faces, computed apart, meet within a rounding error.
    let tol = 1e-9 * (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let key = |p: DVec3| (p / tol).round().as_i64vec3().to_array();
    // Each edge by its ends' keys: its ends, and the normals of the faces it borders.
    type Edge = (DVec3, DVec3, Vec<DVec3>);
    let mut edges: std::collections::HashMap<([i64; 3], [i64; 3]), Edge> = Default::default();
    let mut whole = Vec::new();
    for face in &mesh.faces {
        let corners = face.corners();
        let Some(n) = face.normal() else {
            match corners[..] {
                [a] => whole.push((a, a)),
                [a, b] => whole.push((a, b)),
                _ => {}
            }
            continue;
        };
        for e in 0..corners.len() {
            let (a, b) = (corners[e], corners[(e + 1) % corners.len()]);
            let (ka, kb) = (key(a), key(b));
            let k = if ka <= kb { (ka, kb) } else { (kb, ka) };
            edges.entry(k).or_insert((a, b, Vec::new())).2.push(n);
        }
    }
    let crease = 30f64.to_radians().cos();
    let mut lines: Vec<(DVec3, DVec3)> = edges
        .into_values()
        .filter(|(_, _, normals)| {
            if normals.len() == 1 {
                return true; // a border
            }
            // (A file's faces may wind either way: a normal opposed to the first is turned.)
            let m = normals[0];
            let aligned = normals.iter().map(|&n| if m.dot(n) < 0.0 { -n } else { n });
            let sharp = aligned.clone().any(|n| m.dot(n) < crease);
            let facing = |n: DVec3| n.dot(toward) > 0.0;
            let silhouette = aligned.clone().any(facing) && !aligned.clone().all(facing);
            sharp || silhouette
        })
        .map(|(a, b, _)| (a, b))
        .collect();
    // (In a fixed order: the hash map's is not.)
    lines.sort_by(|x, y| {
        (x.0.to_array(), x.1.to_array())
            .partial_cmp(&(y.0.to_array(), y.1.to_array()))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    lines.extend(whole);
    lines
}

/// The legend of a categorical colouring, right of the scene.
fn legend(img: &mut RgbImage, scene: &Scene, style: &Style, layout: &Layout) {
    let (s, k, top) = (scene.s, scene.k, scene.top);
    let x0 = scene.scene_w as i64 + 6 * s;
    let mut y = top as i64 + 8 * s;
    let title = style.color.title();
    text::draw(img, x0, top as i64 - 8 * s, title, k, INK);
    for &c in &layout.categories {
        let col = rgb(style.color.legend_colour(c));
        for dy in 0..8 * s {
            for dx in 0..8 * s {
                put(img, x0 + dx, y + dy, col);
            }
        }
        text::draw(img, x0 + 12 * s, y, &layout.label(style.color, c), k, INK);
        y += 12 * s;
    }
}

/// The colour bar of the range `(vmin, vmax)` with its ticks, right of the scene.
fn colour_bar(
    img: &mut RgbImage,
    scene: &Scene,
    style: &Style,
    (vmin, vmax): (f64, f64),
    bar_ticks: &[f64],
) {
    let (s, k, top, h) = (scene.s, scene.k, scene.top, scene.h);
    let x0 = scene.scene_w as i64 + 6 * s;
    let title = style.color.title();
    let tw = text::width(title, k);
    text::draw(
        img,
        (style.width as i64 - tw - 4 * s).min(x0),
        3 * s,
        title,
        k,
        INK,
    );
    let (bar_top, bar_bottom) = (
        top as i64 + 10 * s,
        (h as i64 - 16 * s).max(top as i64 + 40),
    );
    let bar_w = 10 * s;
    for y in bar_top..=bar_bottom {
        let f = (bar_bottom - y) as f64 / (bar_bottom - bar_top).max(1) as f64;
        let col = rgb(colormap(f));
        for x in x0..x0 + bar_w {
            put(img, x, y, col);
        }
    }
    for x in x0..x0 + bar_w {
        put(img, x, bar_top, INK);
        put(img, x, bar_bottom, INK);
    }
    for y in bar_top..=bar_bottom {
        put(img, x0, y, INK);
        put(img, x0 + bar_w - 1, y, INK);
    }
    let label_x = x0 + bar_w + 5 * s;
    if vmax > vmin {
        for v in bar_ticks {
            let f = (v - vmin) / (vmax - vmin);
            let y = bar_bottom - (f * (bar_bottom - bar_top) as f64).round() as i64;
            for x in x0 + bar_w..x0 + bar_w + 3 * s {
                put(img, x, y, INK);
            }
            text::draw(img, label_x, y - 4 * s, &text::number(*v), k, INK);
        }
    } else {
        let y = (bar_top + bar_bottom) / 2;
        text::draw(img, label_x, y - 4 * s, &text::number(vmin), k, INK);
    }
}

/// The scale bar, bottom left: a round length near a fifth of the scene's width.
fn scale_bar(img: &mut RgbImage, scene: &Scene) {
    let (s, k, scale) = (scene.s, scene.k, scene.scale);
    let want = 0.2 * scene.scene_w / scale;
    let power = 10f64.powf(want.log10().floor());
    let length = [5.0, 2.0, 1.0]
        .iter()
        .map(|m| m * power)
        .find(|l| *l <= want)
        .unwrap_or(power);
    let px_len = (length * scale).round() as i64;
    let (x, y) = (8 * s, scene.h as i64 - 4 * s);
    for dx in 0..=px_len {
        for dy in 0..2 * s {
            put(img, x + dx, y - dy, INK);
        }
    }
    for dy in 0..6 * s {
        put(img, x, y - dy, INK);
        put(img, x + px_len, y - dy, INK);
    }
    let label = if length >= 1.0 {
        format!("{} m", text::number(length))
    } else if length >= 0.01 {
        format!("{} cm", text::number(length * 100.0))
    } else {
        format!("{} mm", text::number(length * 1000.0))
    };
    text::draw(img, x + px_len + 4 * s, y - 8 * s, &label, k, INK);
}

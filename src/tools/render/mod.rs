//! Pictures of frames: particles as shaded spheres (coloured by speed, height, radius,
//! tag or material) with the mesh edges, in an orthographic view, with a colour bar or
//! legend, a time stamp and a scale bar; one view and colour range for a whole sequence.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use glam::{DMat3, DVec3};
use image::{Rgb, RgbImage};

use crate::geometry::mesh::{Mesh, Primitive};
use crate::model::particles::Particles;
use crate::tools::frames::{RunFrames, frames_of};
use crate::tools::text::{self, put};

mod picture;
pub use picture::render_in;

/// What the particle colour shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ColorBy {
    Speed,
    Height,
    Radius,
    Tag,
    Material,
    /// Each clump in a colour of its own (drawn from ten by its id), plain spheres grey.
    Clump,
    /// The temperature (frames of a run with heat transfer: the `T` column).
    Temperature,
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
    /// Draw a scale bar (a round length) at the bottom left.
    pub scale_bar: bool,
}

impl Style {
    /// Scale of the text and lines: 1 up to 599 pixels high, 2 up to 899, and so on.
    fn scale(&self) -> u32 {
        (self.height / 300).clamp(1, 4)
    }
}

impl ColorBy {
    /// The quantity with its unit, for the colour bar.
    pub fn title(self) -> &'static str {
        match self {
            ColorBy::Speed => "speed [m/s]",
            ColorBy::Height => "height z [m]",
            ColorBy::Radius => "radius [m]",
            ColorBy::Tag => "tag",
            ColorBy::Material => "material",
            ColorBy::Clump => "grain",
            ColorBy::Temperature => "temperature [K]",
        }
    }

    /// Whether the values are categories (a legend) rather than a scale (a colour bar).
    fn categorical(self) -> bool {
        matches!(self, ColorBy::Tag | ColorBy::Material | ColorBy::Clump)
    }

    /// The colour of value `v` of a categorical colouring.
    fn category(self, v: f64) -> DVec3 {
        match self {
            ColorBy::Clump if v < 0.0 => PLAIN,
            // A clump's colour from its id, mixed, so that neighbours (of nearby ids) differ.
            ColorBy::Clump => {
                let mut h = (v as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
                h ^= h >> 31;
                category_colour((h % CATEGORIES.len() as u64) as u32)
            }
            _ => category_colour(v as u32),
        }
    }

    /// The entries of the legend for the categories seen: each with its colour.
    fn legend_colour(self, k: u32) -> DVec3 {
        match (self, k) {
            (ColorBy::Clump, CLUMPS) => category_colour(0),
            (ColorBy::Clump, _) => PLAIN,
            _ => category_colour(k),
        }
    }

    fn values(self, p: &Particles) -> Vec<f64> {
        match self {
            ColorBy::Speed => p.v.iter().map(|v| v.length()).collect(),
            ColorBy::Height => p.x.iter().map(|x| x.z).collect(),
            ColorBy::Radius => p.radius.clone(),
            ColorBy::Temperature => p.temperature.clone(),
            ColorBy::Tag => p.tag.iter().map(|&t| t as f64).collect(),
            ColorBy::Material => p.material.iter().map(|&m| m as f64).collect(),
            ColorBy::Clump => (p.body.iter())
                .map(|b| b.map_or(-1.0, |b| b.first() as f64))
                .collect(),
        }
    }
}

/// Ranges set by the user instead of fitted to the frames.
#[derive(Clone, Copy, Debug, Default)]
pub struct Fixed {
    /// The box to show, in world coordinates (its corners, any order).
    pub bounds: Option<(DVec3, DVec3)>,
    /// The values at the two ends of the colour bar.
    pub range: Option<(f64, f64)>,
}

/// What all the pictures of a sequence share, so that the view does not jump and a colour
/// means the same value in each: the box in view (camera coordinates), the colour range,
/// the categories of a legend.
#[derive(Clone, Debug)]
pub struct Layout {
    lo: DVec3,
    hi: DVec3,
    range: (f64, f64),
    categories: std::collections::BTreeSet<u32>,
    /// Names of materials by index, for the legend.
    pub material_names: Vec<String>,
}

const BACKGROUND: Rgb<u8> = Rgb([255, 255, 255]);
const EDGE: Rgb<u8> = Rgb([60, 60, 60]);
const INK: Rgb<u8> = Rgb([0, 0, 0]);

/// Ten distinct colours for categories (after Tableau 10).
const CATEGORIES: [[f64; 3]; 10] = [
    [0.122, 0.467, 0.706],
    [1.000, 0.498, 0.055],
    [0.173, 0.627, 0.173],
    [0.839, 0.153, 0.157],
    [0.580, 0.404, 0.741],
    [0.549, 0.337, 0.294],
    [0.890, 0.467, 0.761],
    [0.498, 0.498, 0.498],
    [0.737, 0.741, 0.133],
    [0.090, 0.745, 0.812],
];

/// Plain spheres among clumps (`--color clump`).
const PLAIN: DVec3 = DVec3::new(0.78, 0.78, 0.78);

/// The legend's entries of `--color clump`: clumps (each its colour), plain spheres.
const CLUMPS: u32 = 0;
const SPHERES: u32 = 1;

fn category_colour(k: u32) -> DVec3 {
    DVec3::from_array(CATEGORIES[k as usize % CATEGORIES.len()])
}

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

fn rgb(c: DVec3) -> Rgb<u8> {
    let c = (c * 255.0).clamp(DVec3::ZERO, DVec3::splat(255.0));
    Rgb([c.x as u8, c.y as u8, c.z as u8])
}

/// Rounded mesh primitives (points and edges with a radius), drawn as grey spheres.
fn mesh_balls(mesh: &Mesh) -> Vec<(DVec3, f64)> {
    let mut balls = Vec::new();
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
    balls
}

impl Layout {
    /// A layout that shows nothing yet: grow it with [`Layout::include`].
    pub fn empty() -> Layout {
        Layout {
            lo: DVec3::splat(f64::INFINITY),
            hi: DVec3::splat(f64::NEG_INFINITY),
            range: (f64::INFINITY, f64::NEG_INFINITY),
            categories: Default::default(),
            material_names: Vec::new(),
        }
    }

    /// The layout of one frame.
    pub fn of(p: &Particles, mesh: &Mesh, style: &Style) -> Layout {
        let mut l = Layout::empty();
        l.include(p, mesh, style);
        l
    }

    /// Grows the layout to show the frame `p` with `mesh`: the particles without the
    /// farthest half per cent on each side (a few escaped grains should not shrink the
    /// picture), and the mesh along the axes where it is at most twice as wide as they (a
    /// drum around its charge shows whole; a settled bed fills the picture rather than lie as a
    /// strip at the bottom of a tall container); the mesh alone where there are no particles;
    /// and the colour values from the 1 % to the 99 % quantile (radii: all, as a few special
    /// particles are the point of such a picture).
    pub fn include(&mut self, p: &Particles, mesh: &Mesh, style: &Style) {
        let cam = camera(style.view);
        if p.is_empty() {
            for face in &mesh.faces {
                for c in face.corners() {
                    let c = cam * c;
                    self.lo = self.lo.min(c - face.radius);
                    self.hi = self.hi.max(c + face.radius);
                }
            }
            return;
        }
        let r_max = p.max_radius();
        let cut = p.len() / 200;
        let range = |of: &dyn Fn(DVec3) -> f64| {
            let mut v: Vec<f64> = p.x.iter().map(|x| of(*x)).collect();
            v.sort_by(f64::total_cmp);
            (v[cut] - r_max, v[v.len() - 1 - cut] + r_max)
        };
        for axis in 0..3 {
            let (lo, hi) = range(&|x| (cam * x)[axis]);
            self.lo[axis] = self.lo[axis].min(lo);
            self.hi[axis] = self.hi[axis].max(hi);
        }
        // The mesh's vertices within the box of the particles, grown along the world axes
        // where the mesh is at most twice as wide.
        let (mut lo, mut hi) = (DVec3::ZERO, DVec3::ZERO);
        for a in 0..3 {
            (lo[a], hi[a]) = range(&|x| x[a]);
        }
        let (mesh_lo, mesh_hi) =
            (mesh.faces.iter()).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), f| {
                let (a, b) = f.bounding_box();
                (l.min(a), h.max(b))
            });
        for a in 0..3 {
            if mesh_hi[a] - mesh_lo[a] <= 2.0 * (hi[a] - lo[a]) {
                (lo[a], hi[a]) = (lo[a].min(mesh_lo[a]), hi[a].max(mesh_hi[a]));
            }
        }
        for face in &mesh.faces {
            for c in face.corners() {
                let c = cam * c.clamp(lo, hi);
                self.lo = self.lo.min(c);
                self.hi = self.hi.max(c);
            }
        }
        let mut values = style.color.values(p);
        match style.color {
            ColorBy::Clump => (self.categories).extend(
                values
                    .iter()
                    .map(|&v| if v < 0.0 { SPHERES } else { CLUMPS }),
            ),
            _ if style.color.categorical() => {
                self.categories.extend(values.iter().map(|&v| v as u32))
            }
            _ => {}
        }
        values.sort_by(f64::total_cmp);
        let cut = if style.color == ColorBy::Radius {
            0
        } else {
            values.len() / 100
        };
        // Speeds from rest: the bar starts at 0.
        let low = if style.color == ColorBy::Speed {
            0.0
        } else {
            values[cut]
        };
        self.range.0 = self.range.0.min(low);
        self.range.1 = self.range.1.max(values[values.len() - 1 - cut]);
    }

    /// Sets what the user fixed.
    pub fn fix(&mut self, fixed: &Fixed, style: &Style) {
        if let Some((a, b)) = fixed.bounds {
            let cam = camera(style.view);
            self.lo = DVec3::splat(f64::INFINITY);
            self.hi = DVec3::splat(f64::NEG_INFINITY);
            for k in 0..8 {
                let corner = DVec3::new(
                    if k & 1 == 0 { a.x } else { b.x },
                    if k & 2 == 0 { a.y } else { b.y },
                    if k & 4 == 0 { a.z } else { b.z },
                );
                self.lo = self.lo.min(cam * corner);
                self.hi = self.hi.max(cam * corner);
            }
        }
        if let Some(range) = fixed.range {
            self.range = range;
        }
    }

    /// The colour range, (0, 1) if nothing was included.
    pub fn range(&self) -> (f64, f64) {
        if self.range.0 <= self.range.1 {
            self.range
        } else {
            (0.0, 1.0)
        }
    }

    /// The box in view, in camera coordinates (screen right, up, toward the viewer).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.lo, self.hi)
    }

    fn label(&self, color: ColorBy, k: u32) -> String {
        match color {
            ColorBy::Clump if k == CLUMPS => "clumps (a colour each)".to_string(),
            ColorBy::Clump => "plain spheres".to_string(),
            ColorBy::Material => match self.material_names.get(k as usize) {
                Some(name) => format!("{k} {name}"),
                None => format!("material {k}"),
            },
            _ => k.to_string(),
        }
    }
}

/// Renders one frame with its own layout.
pub fn render(p: &Particles, mesh: &Mesh, style: &Style) -> Result<RgbImage> {
    render_in(p, mesh, style, &Layout::of(p, mesh, style), None)
}

/// What to make of a directory's pictures besides the PNGs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Animation {
    None,
    /// `animation.gif`.
    Gif,
    /// `animation.mp4` with the system's ffmpeg, or the GIF where there is none.
    Movie,
}

impl Animation {
    /// The animation the flags `gif` and `movie` ask for (a movie if both).
    pub fn of(gif: bool, movie: bool) -> Animation {
        match (gif, movie) {
            (_, true) => Animation::Movie,
            (true, _) => Animation::Gif,
            _ => Animation::None,
        }
    }
}

/// What `render_path` made.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The pictures, in frame order.
    pub pictures: Vec<PathBuf>,
    pub animation: Option<PathBuf>,
    /// Said to the user (a fallback taken).
    pub notes: Vec<String>,
}

/// Renders a frame `particlesNNNNNN.csv` to `output` (default: beside it, as .png), or every
/// frame of an output directory into `output` (default: the directory), all in one layout
/// (view and colour range fitted to all frames, or as `fixed`), with an animation if asked.
/// Meshes come from `scenario` (default: the run's `run.toml`) at each frame's time, and
/// from the mesh files `meshes`.
pub fn render_path(
    path: &Path,
    output: Option<&Path>,
    scenario: Option<&Path>,
    meshes: &[PathBuf],
    style: &Style,
    fixed: &Fixed,
    animation: Animation,
) -> Result<Rendered> {
    let dir = if path.is_dir() {
        path.to_path_buf()
    } else {
        path.parent().unwrap_or(Path::new(".")).to_path_buf()
    };
    let mut source = RunFrames::open(&dir, scenario, meshes)?;
    let frames = frames_of(path)?;
    // The layout of all frames, then the pictures in it.
    let mut layout = Layout::empty();
    for f in &frames {
        let p = source.particles_of(f)?;
        if style.color == ColorBy::Temperature && !p.active.temperature {
            bail!(
                "{}: no temperatures (a T column) to colour by: the run had no heat transfer",
                f.display()
            );
        }
        let t = source.time_of(f);
        layout.include(&p, &source.mesh_of(f, t), style);
    }
    layout.fix(fixed, style);
    if let Some(sim) = &source.sim {
        layout.material_names = sim
            .scenario
            .materials
            .iter()
            .map(|m| m.name.clone())
            .collect();
    }
    let out_dir = match (path.is_dir(), output) {
        (true, Some(o)) => o.to_path_buf(),
        (true, None) => path.to_path_buf(),
        (false, _) => PathBuf::new(),
    };
    if path.is_dir() {
        std::fs::create_dir_all(&out_dir)
            .with_context(|| format!("cannot create {}", out_dir.display()))?;
    }
    let mut rendered = Rendered {
        pictures: Vec::new(),
        animation: None,
        notes: Vec::new(),
    };
    let mut images = Vec::new();
    for f in &frames {
        let p = source.particles_of(f)?;
        let t = source.time_of(f);
        let img = render_in(&p, &source.mesh_of(f, t), style, &layout, t)?;
        let png = if path.is_dir() {
            out_dir.join(f.with_extension("png").file_name().expect("a file name"))
        } else {
            output.map_or_else(|| f.with_extension("png"), Path::to_path_buf)
        };
        img.save(&png)
            .with_context(|| format!("cannot write {}", png.display()))?;
        rendered.pictures.push(png);
        if animation != Animation::None {
            images.push(img);
        }
    }
    animate(&out_dir, images, animation, &mut rendered)?;
    Ok(rendered)
}

/// The animation of `images` into `out_dir` that `animation` asks for: an MP4 (a GIF where
/// there is no ffmpeg, with a note) or a GIF.
fn animate(
    out_dir: &Path,
    images: Vec<RgbImage>,
    animation: Animation,
    rendered: &mut Rendered,
) -> Result<()> {
    if animation == Animation::Movie {
        let movie = out_dir.join("animation.mp4");
        match write_movie(&movie, &images) {
            Ok(()) => rendered.animation = Some(movie),
            Err(e) => rendered
                .notes
                .push(format!("no movie ({e:#}); an animated GIF instead")),
        }
    }
    if animation == Animation::Gif
        || (animation == Animation::Movie && rendered.animation.is_none())
    {
        let gif = out_dir.join("animation.gif");
        write_gif(&gif, images)?;
        rendered.animation = Some(gif);
    }
    Ok(())
}

/// Frames per second of animations.
const FPS: u32 = 10;

/// Writes the pictures as an animated GIF, looping.
fn write_gif(path: &Path, images: Vec<RgbImage>) -> Result<()> {
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot write {}", path.display()))?;
    let mut enc = image::codecs::gif::GifEncoder::new_with_speed(file, 10);
    enc.set_repeat(image::codecs::gif::Repeat::Infinite)?;
    for img in images {
        enc.encode_frame(image::Frame::from_parts(
            dithered(img),
            0,
            0,
            image::Delay::from_numer_denom_ms(1000 / FPS, 1),
        ))?;
    }
    Ok(())
}

/// A picture in a GIF's 256 colours without bands across the shading of the spheres: a
/// palette fitted to it (NeuQuant) and Floyd-Steinberg dithering (the encoder then keeps
/// those colours as they are).
fn dithered(img: RgbImage) -> image::RgbaImage {
    let mut rgba = image::DynamicImage::ImageRgb8(img).to_rgba8();
    let palette = color_quant::NeuQuant::new(5, 256, rgba.as_raw());
    image::imageops::dither(&mut rgba, &palette);
    rgba
}

/// Writes the pictures as an H.264 MP4 (MPEG-4 part 2 where ffmpeg lacks H.264) by piping
/// them to the system's `ffmpeg`; an error if there is none.
fn write_movie(path: &Path, images: &[RgbImage]) -> Result<()> {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let Some(first) = images.first() else {
        bail!("no pictures");
    };
    let (w, h) = first.dimensions();
    let mut last_error = String::new();
    for codec in [
        &["-c:v", "libx264", "-pix_fmt", "yuv420p"][..],
        &["-c:v", "mpeg4", "-q:v", "2"],
    ] {
        let child = Command::new("ffmpeg")
            .args([
                "-y",
                "-loglevel",
                "error",
                "-f",
                "rawvideo",
                "-pix_fmt",
                "rgb24",
            ])
            .args(["-s", &format!("{w}x{h}"), "-r", &FPS.to_string(), "-i", "-"])
            // Even sizes, as the encoders' 4:2:0 colour needs.
            .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white"])
            .args(codec)
            .arg(path)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn();
        let mut child = match child {
            Ok(c) => c,
            Err(e) => bail!("cannot start ffmpeg: {e}"),
        };
        let mut stdin = child.stdin.take().expect("piped");
        let fed = images
            .iter()
            .try_for_each(|img| stdin.write_all(img.as_raw()));
        drop(stdin);
        let out = child.wait_with_output().context("ffmpeg")?;
        if fed.is_ok() && out.status.success() {
            return Ok(());
        }
        last_error = String::from_utf8_lossy(&out.stderr).trim().to_string();
    }
    bail!("ffmpeg failed: {last_error}")
}

#[cfg(test)]
mod tests;

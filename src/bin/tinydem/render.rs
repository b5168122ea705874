//! `tinydem render`: pictures of frames, and animations of output directories.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use glam::DVec3;

use tinydem::tools::render::{Animation, ColorBy, Fixed, Style, View};

#[derive(Args)]
pub struct RenderArgs {
    /// A frame `particlesNNNNNN.csv`, or an output directory.
    path: PathBuf,
    /// Output PNG (for a frame) or directory (for a directory; default: beside the frames).
    #[arg(long, short)]
    output: Option<PathBuf>,
    /// Draw the meshes of this scenario (moving meshes at the frame's time).
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// Draw this mesh file (OFF or STL); may be repeated.
    #[arg(long)]
    mesh: Vec<PathBuf>,
    /// The picture's size in pixels, WIDTHxHEIGHT (or --width, --height).
    #[arg(long, value_name = "WIDTHxHEIGHT", value_parser = crate::size, conflicts_with_all = ["width", "height"])]
    size: Option<(u32, u32)>,
    #[arg(long, default_value_t = 1600)]
    width: u32,
    #[arg(long, default_value_t = 1200)]
    height: u32,
    /// Particle colour.
    #[arg(long, value_enum, default_value_t = ColorBy::Speed)]
    color: ColorBy,
    /// Direction of view.
    #[arg(long, value_enum, default_value_t = View::Iso)]
    view: View,
    /// For a directory, also write an animated GIF `animation.gif`.
    #[arg(long)]
    gif: bool,
    /// For a directory, also write a movie `animation.mp4` (with the system's ffmpeg;
    /// an animated GIF where there is none).
    #[arg(long, conflicts_with = "gif")]
    movie: bool,
    /// The values at the ends of the colour bar, LO,HI (default: fitted to all frames).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    range: Option<Vec<f64>>,
    /// The box to show, X0,Y0,Z0,X1,Y1,Z1 [m] (default: fitted to all frames).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    bounds: Option<Vec<f64>>,
    /// Draw a scale bar.
    #[arg(long)]
    scale_bar: bool,
}

impl RenderArgs {
    /// Draws the pictures (and the animation) and says where they are.
    pub fn execute(self) -> Result<()> {
        let style = Style {
            width: self.size.map_or(self.width, |s| s.0),
            height: self.size.map_or(self.height, |s| s.1),
            color: self.color,
            view: self.view,
            scale_bar: self.scale_bar,
        };
        let fixed = fixed(self.range, self.bounds)?;
        let animation = Animation::of(self.gif, self.movie);
        let done = tinydem::tools::render::render_path(
            &self.path,
            self.output.as_deref(),
            self.scenario.as_deref(),
            &self.mesh,
            &style,
            &fixed,
            animation,
        )?;
        for note in &done.notes {
            eprintln!("note: {note}");
        }
        match done.pictures.as_slice() {
            [one] => eprintln!("picture in {}", one.display()),
            all => eprintln!(
                "{} pictures in {}",
                all.len(),
                all[0]
                    .parent()
                    .map_or(".".into(), |d| d.display().to_string())
            ),
        }
        if let Some(a) = done.animation {
            eprintln!("animation in {}", a.display());
        }
        Ok(())
    }
}

/// The colour range and the box fixed by `--range` and `--bounds`, checked.
fn fixed(range: Option<Vec<f64>>, bounds: Option<Vec<f64>>) -> Result<Fixed> {
    if let Some(r) = range.as_ref().filter(|r| r.len() != 2) {
        anyhow::bail!("--range takes two numbers LO,HI, not {}", r.len());
    }
    if let Some(b) = bounds.as_ref().filter(|b| b.len() != 6) {
        anyhow::bail!(
            "--bounds takes six numbers X0,Y0,Z0,X1,Y1,Z1, not {}",
            b.len()
        );
    }
    let fixed = Fixed {
        range: range.map(|r| (r[0], r[1])),
        bounds: bounds.map(|b| (DVec3::new(b[0], b[1], b[2]), DVec3::new(b[3], b[4], b[5]))),
    };
    if let Some((lo, hi)) = fixed.range {
        anyhow::ensure!(
            lo < hi && lo.is_finite() && hi.is_finite(),
            "--range {lo},{hi}: LO must be below HI"
        );
    }
    Ok(fixed)
}

//! `tinydem plot`: columns of a run's CSV table against one of its columns, and the plot
//! options `analyze --plot` shares.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;

use tinydem::tools::plot::{self, Plot, Table};

/// `tinydem plot FILE --y a,b`.
#[derive(Args)]
pub struct PlotArgs {
    /// A CSV table of a run: log.csv, walls.csv, a table of `analyze --csv`, a field profile.
    table: PathBuf,
    /// The columns to draw, comma-separated (each a line, with a legend).
    #[arg(long, short, value_delimiter = ',', required = true)]
    y: Vec<String>,
    /// The column along the horizontal axis.
    #[arg(long, short, default_value = "time")]
    x: String,
    /// Only the rows where a column has a value, COLUMN=VALUE (e.g. mesh=1 in walls.csv).
    #[arg(long = "where", value_name = "COLUMN=VALUE")]
    filter: Option<String>,
    /// The picture: SVG if it ends in .svg, else PNG.
    #[arg(long, short, default_value = "plot.png")]
    output: PathBuf,
    #[command(flatten)]
    pub style: Style,
}

/// How a plot looks: its axes and size.
#[derive(Args, Clone, Copy)]
pub struct Style {
    /// A logarithmic horizontal axis (rows with x <= 0 are left out).
    #[arg(long)]
    pub log_x: bool,
    /// A logarithmic vertical axis (points with y <= 0 are left out).
    #[arg(long)]
    pub log_y: bool,
    /// The plot's size in pixels, WIDTHxHEIGHT.
    #[arg(long = "plot-size", value_name = "WIDTHxHEIGHT", value_parser = crate::size, default_value = "1200x800")]
    pub size: (u32, u32),
}

impl PlotArgs {
    pub fn execute(self) -> Result<()> {
        let text = std::fs::read_to_string(&self.table)
            .with_context(|| format!("cannot read {}", self.table.display()))?;
        let mut table = Table::parse(&text, &self.table.display().to_string())?;
        if let Some(f) = &self.filter {
            let (name, value) = f
                .split_once('=')
                .and_then(|(n, v)| Some((n.trim(), v.trim().parse::<f64>().ok()?)))
                .with_context(|| format!("--where {f}: expected COLUMN=NUMBER, e.g. mesh=1"))?;
            table = table.filter(name, value)?;
        }
        let y: Vec<&str> = self.y.iter().map(String::as_str).collect();
        draw(&table, &self.x, &y, self.style, &self.output)
    }
}

/// Draws the columns `y` of `table` against `x` into `path`, and says so.
pub fn draw(table: &Table, x: &str, y: &[&str], style: Style, path: &Path) -> Result<()> {
    let p = Plot {
        x,
        y: y.to_vec(),
        log_x: style.log_x,
        log_y: style.log_y,
        size: style.size,
    };
    plot::save(table, &p, path)?;
    eprintln!("plot of {} against {x} in {}", y.join(", "), path.display());
    Ok(())
}

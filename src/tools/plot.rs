//! Line plots of a run's tables (`tinydem plot`, `tinydem analyze --plot`) through the
//! `plotters` crate: several columns against one, a legend, axis titles with units, linear
//! or logarithmic axes, as SVG (for a paper) or PNG, labels in the built-in DejaVu Sans.

use std::path::Path;
use std::sync::Once;

use anyhow::{Context, Result, bail};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

use crate::tools::text;

/// A table of numbers with named columns (a CSV file of the run: `log.csv`, `walls.csv`,
/// the table of `analyze`, a field profile).
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub header: Vec<String>,
    /// One vector per column; a cell that is not a number is NaN.
    pub columns: Vec<Vec<f64>>,
}

impl Table {
    /// The table of CSV text (a header line, then rows), `file` naming it in errors.
    pub fn parse(csv: &str, file: &str) -> Result<Table> {
        let mut lines = csv.lines().filter(|l| !l.trim().is_empty());
        let Some(head) = lines.next() else {
            bail!("{file}: empty, expected a header line");
        };
        let header: Vec<String> = head.split(',').map(|h| h.trim().to_string()).collect();
        let mut columns = vec![Vec::new(); header.len()];
        for (k, line) in lines.enumerate() {
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != header.len() {
                bail!(
                    "{file}:{}: {} cells, the header has {}",
                    k + 2,
                    cells.len(),
                    header.len()
                );
            }
            for (col, cell) in columns.iter_mut().zip(cells) {
                col.push(cell.trim().parse().unwrap_or(f64::NAN));
            }
        }
        Ok(Table { header, columns })
    }

    /// The column named `name`, or an error listing the names there are.
    pub fn column(&self, name: &str) -> Result<&[f64]> {
        match self.header.iter().position(|h| h == name) {
            Some(c) => Ok(&self.columns[c]),
            None => bail!(
                "no column {name:?} (the columns: {})",
                self.header.join(", ")
            ),
        }
    }

    /// The rows where column `name` equals `value` (e.g. `mesh` = 1 in `walls.csv`).
    pub fn filter(&self, name: &str, value: f64) -> Result<Table> {
        let keep: Vec<bool> = self.column(name)?.iter().map(|v| *v == value).collect();
        let columns = self
            .columns
            .iter()
            .map(|c| c.iter().zip(&keep).filter(|p| *p.1).map(|p| *p.0).collect())
            .collect();
        Ok(Table {
            header: self.header.clone(),
            columns,
        })
    }
}

/// The unit of a column the program writes, for axis titles (`None`: a pure number).
pub fn unit(column: &str) -> Option<&'static str> {
    let c = column;
    let tail = c.rsplit_once('_').map_or(c, |t| t.1);
    Some(match c {
        "time" => "s",
        "kinetic_energy" | "rotational_energy" => "J",
        "x" | "y" | "z" | "R" | "large_mean_height" | "tagged_mean_height" => "m",
        "vx" | "vy" | "vz" => "m/s",
        "wx" | "wy" | "wz" => "rad/s",
        "fx" | "fy" | "fz" => "N",
        "tx" | "ty" | "tz" => "N m",
        "density" => "kg/m^3",
        "max_overlap" => "of the smaller radius",
        _ if c.starts_with("repose_") => "°",
        _ if ["work_", "stored_", "dissipated_", "energy_"]
            .iter()
            .any(|p| c.starts_with(p)) =>
        {
            "J"
        }
        _ if c.starts_with("mesh") && c.ends_with("_position") => "m",
        _ if c.starts_with("mesh") && c.ends_with("_load") => "N",
        _ if ["stress_", "contact_", "kinetic_"]
            .iter()
            .any(|p| c.starts_with(p))
            && tail.len() == 2 =>
        {
            "Pa"
        }
        _ => return None,
    })
}

/// The title of a column on an axis or in a legend: its name and unit.
pub fn title(column: &str) -> String {
    match unit(column) {
        Some(u) => format!("{column} [{u}]"),
        None => column.to_string(),
    }
}

/// What to draw: the columns `y` of a table against its column `x`.
#[derive(Clone, Debug)]
pub struct Plot<'a> {
    pub x: &'a str,
    pub y: Vec<&'a str>,
    pub log_x: bool,
    pub log_y: bool,
    /// Width and height \[px\] (of the SVG's view too).
    pub size: (u32, u32),
}

/// Colours told apart by colour-blind readers too (Okabe & Ito), then again.
const COLOURS: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// One line of the plot: its legend and its finite points.
struct Line {
    label: String,
    points: Vec<(f64, f64)>,
}

/// Draws `plot` of `table` into `path`: SVG if it ends in `.svg`, else PNG.
pub fn save(table: &Table, plot: &Plot, path: &Path) -> Result<()> {
    let lines = lines(table, plot)?;
    let (w, h) = plot.size;
    if !(200..=16384).contains(&w) || !(150..=16384).contains(&h) {
        bail!("plot size {w}x{h} must be between 200x150 and 16384x16384 pixels");
    }
    let svg = path.extension().is_some_and(|e| e == "svg");
    let written = if svg {
        let root = SVGBackend::new(path, (w, h)).into_drawing_area();
        draw(&root, plot, &lines).and_then(|_| root.present().map_err(|e| anyhow::anyhow!("{e}")))
    } else {
        let mut rgb = vec![0u8; 3 * w as usize * h as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
            draw(&root, plot, &lines)?;
            root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        let img = image::RgbImage::from_raw(w, h, rgb).expect("the buffer holds w x h pixels");
        img.save(path).map_err(anyhow::Error::from)
    };
    written.with_context(|| format!("cannot write the plot {}", path.display()))
}

/// The lines of `plot`: for each y column its finite points (positive on a log axis).
fn lines(table: &Table, plot: &Plot) -> Result<Vec<Line>> {
    if plot.y.is_empty() {
        bail!("nothing to plot: no y column");
    }
    let x = table.column(plot.x)?;
    let usable = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    let mut lines = Vec::new();
    for name in &plot.y {
        let points: Vec<(f64, f64)> = x
            .iter()
            .zip(table.column(name)?)
            .map(|(a, b)| (*a, *b))
            .filter(|(a, b)| usable(*a, plot.log_x) && usable(*b, plot.log_y))
            .collect();
        if points.is_empty() {
            let why = if plot.log_x || plot.log_y {
                "finite positive values (on a log axis)"
            } else {
                "finite values"
            };
            bail!(
                "nothing to plot: column {name} against {} has no {why}",
                plot.x
            );
        }
        lines.push(Line {
            label: title(name),
            points,
        });
    }
    Ok(lines)
}

/// The range of `f` over all points, widened when it is a single value; on a log axis a
/// factor around it; room of 4 % of the axis on both sides.
fn range(lines: &[Line], f: fn(&(f64, f64)) -> f64, log: bool) -> std::ops::Range<f64> {
    let (lo, hi) = lines
        .iter()
        .flat_map(|l| l.points.iter().map(f))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    match (log, hi > lo) {
        (true, true) => {
            let pad = (hi / lo).powf(0.04);
            lo / pad..hi * pad
        }
        (true, false) => lo / 2.0..hi * 2.0,
        (false, true) => lo - 0.04 * (hi - lo)..hi + 0.04 * (hi - lo),
        (false, false) => {
            let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            lo - pad..hi + pad
        }
    }
}

/// Draws the lines on `root` with linear or log axes as `plot` says.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &Plot,
    lines: &[Line],
) -> Result<()> {
    let x = range(lines, |p| p.0, plot.log_x);
    let y = range(lines, |p| p.1, plot.log_y);
    match (plot.log_x, plot.log_y) {
        (false, false) => chart(root, plot, lines, x, y),
        (true, false) => chart(root, plot, lines, x.log_scale(), y),
        (false, true) => chart(root, plot, lines, x, y.log_scale()),
        (true, true) => chart(root, plot, lines, x.log_scale(), y.log_scale()),
    }
}

/// The font of every label, registered once with `plotters`.
fn sans(size: f64) -> TextStyle<'static> {
    static FONT: Once = Once::new();
    FONT.call_once(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, text::ttf())
            .unwrap_or_else(|_| panic!("the font built in is a TrueType font"));
    });
    ("sans-serif", size).into_font().color(&BLACK)
}

/// The chart: a light grid with round ticks, the axis titles, the lines and their legend.
fn chart<DB, X, Y>(
    root: &DrawingArea<DB, Shift>,
    plot: &Plot,
    lines: &[Line],
    x: X,
    y: Y,
) -> Result<()>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let fail = |e: &dyn std::fmt::Display| anyhow::anyhow!("{e}");
    let px = plot.size.1 as f64 / 30.0;
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let mut chart = ChartBuilder::on(root)
        .margin(px as i32)
        .x_label_area_size((3.0 * px) as i32)
        .y_label_area_size((4.5 * px) as i32)
        .build_cartesian_2d(x, y)
        .map_err(|e| fail(&e))?;
    let y_title = match lines {
        [one] => one.label.clone(),
        _ => common_unit(plot).map_or(String::new(), |u| format!("[{u}]")),
    };
    chart
        .configure_mesh()
        .x_desc(title(plot.x))
        .y_desc(y_title)
        .x_labels(8)
        .y_labels(8)
        .label_style(sans(px))
        .axis_desc_style(sans(1.15 * px))
        .x_label_formatter(&|v| text::number(*v))
        .y_label_formatter(&|v| text::number(*v))
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(|e| fail(&e))?;
    let width = (px / 8.0).ceil().max(2.0) as u32;
    for (k, line) in lines.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let style = colour.stroke_width(width);
        let points = line.points.iter().copied();
        // The colours once more, dashed.
        let (dash, gap) = (3 * width, 2 * width);
        let drawn = match k < COLOURS.len() {
            true => chart.draw_series(LineSeries::new(points, style)),
            false => chart.draw_series(DashedLineSeries::new(points, dash, gap, style)),
        };
        let series = drawn.map_err(|e| fail(&e))?.label(line.label.as_str());
        match k < COLOURS.len() {
            true => series.legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], style)),
            false => series.legend(move |(x, y)| {
                plotters::element::DashedPathElement::new([(x, y), (x + 18, y)], dash, gap, style)
            }),
        };
    }
    if lines.len() > 1 {
        chart
            .configure_series_labels()
            .label_font(sans(px))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| fail(&e))?;
    }
    Ok(())
}

/// The unit the y columns share, if they do.
fn common_unit(plot: &Plot) -> Option<&'static str> {
    let first = unit(plot.y[0])?;
    plot.y
        .iter()
        .all(|c| unit(c) == Some(first))
        .then_some(first)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> Table {
        let mut csv = String::from("time,kinetic_energy,rotational_energy,note\n");
        for k in 0..50 {
            let t = k as f64 * 0.1;
            csv += &format!("{t},{},{},x\n", (-t).exp(), 0.1 * (-2.0 * t).exp());
        }
        Table::parse(&csv, "t.csv").unwrap()
    }

    fn plot<'a>(y: Vec<&'a str>, log_y: bool) -> Plot<'a> {
        Plot {
            x: "time",
            y,
            log_x: false,
            log_y,
            size: (800, 500),
        }
    }

    #[test]
    fn several_columns_on_a_log_axis_as_png_and_svg() {
        let t = tempfile::tempdir().unwrap();
        let both = plot(vec!["kinetic_energy", "rotational_energy"], true);
        save(&table(), &both, &t.path().join("e.png")).unwrap();
        let img = image::open(t.path().join("e.png")).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (800, 500));
        let of = |c: RGBColor| img.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count();
        // Both lines are drawn (each ~600 px long, 2 px wide), in their colours.
        assert!(
            of(COLOURS[0]) > 600 && of(COLOURS[1]) > 600,
            "{} {}",
            of(COLOURS[0]),
            of(COLOURS[1])
        );
        save(&table(), &both, &t.path().join("e.svg")).unwrap();
        let svg = std::fs::read_to_string(t.path().join("e.svg")).unwrap();
        // The legend names both with units; the log axis has its decades.
        assert!(svg.contains("kinetic_energy [J]") && svg.contains("rotational_energy [J]"));
        assert!(
            svg.contains("\n1e-4\n") && svg.contains("\n0.01\n"),
            "{svg}"
        );
        assert!(svg.contains("time [s]"));
    }

    #[test]
    fn bad_plots_are_refused_with_reasons() {
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("p.png");
        let err = |pl: &Plot| save(&table(), pl, &p).unwrap_err().to_string();
        assert!(err(&plot(vec!["nope"], false)).contains("no column \"nope\" (the columns: time,"));
        assert!(err(&plot(vec!["note"], false)).contains("has no finite values"));
        let mut neg = table();
        neg.columns[1].iter_mut().for_each(|v| *v = -*v);
        let e = save(&neg, &plot(vec!["kinetic_energy"], true), &p).unwrap_err();
        assert!(e.to_string().contains("positive values (on a log axis)"));
        let mut small = plot(vec!["kinetic_energy"], false);
        small.size = (10, 10);
        assert!(err(&small).contains("plot size 10x10"));
        // A constant column still gets a range.
        let mut flat = table();
        flat.columns[1].iter_mut().for_each(|v| *v = 2.0);
        save(&flat, &plot(vec!["kinetic_energy"], false), &p).unwrap();
    }

    #[test]
    fn tables_parse_filter_and_know_units() {
        let t = Table::parse("frame,mesh,fz\n0,1,2.5\n0,2,3\n1,1,4\n", "w.csv").unwrap();
        assert_eq!(
            t.filter("mesh", 1.0).unwrap().column("fz").unwrap(),
            &[2.5, 4.0]
        );
        assert!(
            Table::parse("a,b\n1\n", "w.csv")
                .unwrap_err()
                .to_string()
                .contains("w.csv:2: 1 cells")
        );
        assert_eq!(title("mesh2_load"), "mesh2_load [N]");
        assert_eq!(title("stress_zz"), "stress_zz [Pa]");
        assert_eq!(title("coordination"), "coordination");
    }
}

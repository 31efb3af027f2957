//! Figures as SVG and PNG with `plotters`, drawn in memory and written through
//! the atomic writer like every other output.
//!
//! Text goes through plotters' pure-Rust `ab_glyph` path with the bundled
//! DejaVu Sans (assets/, Bitstream Vera licence), so that a machine with
//! nothing but the Rust toolchain renders every figure: no system font, no C
//! library.

use std::path::{Path, PathBuf};

use image::codecs::png::PngEncoder;
use image::{ColorType, ImageEncoder};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::register_font;

use crate::EvalError;
use crate::harness_runs::ExampleTrace;

/// What drawing returns: the backend's message on failure.
pub type DrawResult = Result<(), String>;

static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The font family every figure uses.
const FONT: &str = "sans-serif";

/// Colours of the series, in order (Okabe-Ito, distinguishable by colour-blind readers).
const COLOURS: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// Registers the bundled font under the family name the figures use.
pub fn register_bundled_font() -> Result<(), EvalError> {
    register_font(FONT, FontStyle::Normal, DEJAVU_SANS).map_err(|_| EvalError::Figure {
        figure: "every figure".to_owned(),
        message: "the bundled font assets/DejaVuSans.ttf cannot be read".to_owned(),
    })
}

fn plot_error(error: impl std::fmt::Display) -> String {
    error.to_string()
}

/// A figure that can be drawn on any plotters backend.
pub trait Figure {
    /// Draws on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult;
}

/// Writes `stem.svg` and `stem.png` under `dir` through the atomic writer
/// ([`palc_aggregator::output::write`], like every other output); returns both paths.
/// Both are drawn in memory first, so a figure that cannot be drawn writes nothing.
pub fn save<F: Figure>(
    dir: &Path,
    stem: &str,
    size: (u32, u32),
    figure: &F,
) -> Result<[PathBuf; 2], EvalError> {
    let svg = dir.join(format!("{stem}.svg"));
    let png = dir.join(format!("{stem}.png"));
    let (svg_text, png_bytes) = render(size, figure).map_err(|message| EvalError::Figure {
        figure: stem.to_owned(),
        message,
    })?;
    palc_aggregator::output::write(&svg, svg_text.as_bytes())?;
    palc_aggregator::output::write(&png, &png_bytes)?;
    Ok([svg, png])
}

/// Draws `figure` as an SVG document (plotters' string backend) and as a PNG file's
/// bytes: drawn on an in-memory RGB buffer, encoded by the `image` crate's PNG encoder
/// with its defaults, as plotters' file backend encodes it.
fn render<F: Figure>(size: (u32, u32), figure: &F) -> Result<(String, Vec<u8>), String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        figure.draw(&root)?;
        root.present().map_err(plot_error)?;
    }
    let (width, height) = size;
    let mut pixels = vec![0; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        figure.draw(&root)?;
        root.present().map_err(plot_error)?;
    }
    let mut png = Vec::new();
    PngEncoder::new(&mut png)
        .write_image(&pixels, width, height, ColorType::Rgb8)
        .map_err(plot_error)?;
    Ok((svg, png))
}

/// Grouped bars: one group per category, one bar per series; a missing value
/// draws no bar.
pub struct Bars {
    /// Title.
    pub title: String,
    /// Axis descriptions.
    pub x_desc: String,
    /// Axis descriptions.
    pub y_desc: String,
    /// Category labels along x.
    pub categories: Vec<String>,
    /// Series: name and one value per category.
    pub series: Vec<(String, Vec<Option<f64>>)>,
    /// Label every n-th category only (1 labels all).
    pub label_every: usize,
}

impl Figure for Bars {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let n = self.categories.len().max(1);
        let top = (self.series.iter())
            .flat_map(|(_, values)| values.iter().flatten())
            .fold(0.0f64, |a, &b| a.max(b));
        let top = if top > 0.0 { top * 1.15 } else { 1.0 };
        let [plot, legend_area] = with_legend_area(root, &self.title)?;
        let mut chart = ChartBuilder::on(&plot)
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5f64..(n as f64 - 0.5), 0.0f64..top)
            .map_err(plot_error)?;
        let label = |x: &f64| {
            let i = x.round();
            let every = self.label_every.max(1);
            if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) % every == 0 {
                self.categories.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n.min(40))
            .x_label_formatter(&label)
            .x_desc(&self.x_desc)
            .y_desc(&self.y_desc)
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(plot_error)?;
        let groups = self.series.len().max(1) as f64;
        let width = 0.8 / groups;
        for (s, (_, values)) in self.series.iter().enumerate() {
            let colour = COLOURS[s % COLOURS.len()];
            let left = -0.4 + s as f64 * width;
            let bars = values.iter().enumerate().filter_map(|(c, v)| {
                v.map(|v| {
                    let x0 = c as f64 + left;
                    Rectangle::new([(x0, 0.0), (x0 + width * 0.95, v)], colour.filled())
                })
            });
            chart.draw_series(bars).map_err(plot_error)?;
        }
        let entries: Vec<(&str, RGBColor)> = (self.series.iter().enumerate())
            .map(|(s, (name, _))| (name.as_str(), COLOURS[s % COLOURS.len()]))
            .collect();
        legend(&legend_area, &entries, Swatch::Box)
    }
}

/// Lines with markers.
pub struct Lines {
    /// Title.
    pub title: String,
    /// Axis descriptions.
    pub x_desc: String,
    /// Axis descriptions.
    pub y_desc: String,
    /// Series: name and points.
    pub series: Vec<(String, Vec<(f64, f64)>)>,
    /// Fixed y range, or from the data (ignored with `log_y`).
    pub y_range: Option<(f64, f64)>,
    /// A logarithmic y axis, for values that span decades (whole decades from the data).
    pub log_y: bool,
}

impl Figure for Lines {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let points = || self.series.iter().flat_map(|(_, p)| p.iter());
        let (x0, x1) = points().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
        let (x0, x1) = if x0.is_finite() && x1 > x0 {
            (x0, x1)
        } else {
            (0.0, 1.0)
        };
        let (y0, y1) = self.y_range.unwrap_or_else(|| {
            let top = points().fold(0.0f64, |a, p| a.max(p.1));
            (0.0, if top > 0.0 { top * 1.15 } else { 1.0 })
        });
        let pad = (x1 - x0) * 0.03;
        let [plot, legend_area] = with_legend_area(root, &self.title)?;
        let y_value = |y: f64| if self.log_y { y.log10() } else { y };
        let (y0, y1) = if self.log_y {
            let positive = || points().map(|p| p.1).filter(|&y| y > 0.0);
            let low = positive().fold(f64::INFINITY, f64::min);
            let high = positive().fold(0.0f64, f64::max);
            if low.is_finite() && high > 0.0 {
                (
                    low.log10().floor(),
                    high.log10().ceil().max(low.log10().floor() + 1.0),
                )
            } else {
                (0.0, 1.0)
            }
        } else {
            (y0, y1)
        };
        let mut chart = ChartBuilder::on(&plot)
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((x0 - pad)..(x1 + pad), y0..y1)
            .map_err(plot_error)?;
        let y_label = |y: &f64| {
            if self.log_y {
                // Powers of ten at whole decades, nothing in between.
                if (y - y.round()).abs() < 1e-9 {
                    format!("{}", 10f64.powi(y.round() as i32))
                } else {
                    String::new()
                }
            } else {
                tick(*y)
            }
        };
        let decades = (y1 - y0).round().max(1.0) as usize;
        let mut mesh = chart.configure_mesh();
        let x_label = |x: &f64| tick(*x);
        mesh.x_desc(&self.x_desc)
            .y_desc(&self.y_desc)
            .x_label_formatter(&x_label)
            .y_label_formatter(&y_label)
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16));
        if self.log_y {
            mesh.y_labels(decades * 4 + 1);
        }
        mesh.draw().map_err(plot_error)?;
        for (s, (_, series)) in self.series.iter().enumerate() {
            let colour = COLOURS[s % COLOURS.len()];
            let shown = || {
                (series.iter())
                    .filter(|p| !self.log_y || p.1 > 0.0)
                    .map(|&(x, y)| (x, y_value(y)))
            };
            chart
                .draw_series(LineSeries::new(shown(), colour.stroke_width(2)))
                .map_err(plot_error)?;
            chart
                .draw_series(shown().map(|p| Circle::new(p, 3, colour.filled())))
                .map_err(plot_error)?;
        }
        // A log axis cannot show 0: say so in the legend instead of dropping it silently.
        let names: Vec<String> = (self.series.iter())
            .map(|(name, points)| {
                let zeros = points.iter().filter(|p| p.1 <= 0.0).count();
                match zeros {
                    0 => name.clone(),
                    _ if !self.log_y => name.clone(),
                    z if z == points.len() => format!("{name} (0, not drawn)"),
                    z => format!("{name} ({z} at 0, not drawn)"),
                }
            })
            .collect();
        let entries: Vec<(&str, RGBColor)> = (names.iter().enumerate())
            .map(|(s, name)| (name.as_str(), COLOURS[s % COLOURS.len()]))
            .collect();
        legend(&legend_area, &entries, Swatch::Line)
    }
}

/// A tick label: the value rounded to 1e-6, so that a tick at 0.7999999999 (the
/// sum of floating steps) reads 0.8.
fn tick(value: f64) -> String {
    let rounded = (value * 1e6).round() / 1e6;
    format!("{}", if rounded == 0.0 { 0.0 } else { rounded })
}

/// Share of a figure's width kept for the legend, right of the plot.
const LEGEND_WIDTH_PERCENT: u32 = 22;

/// Titles `root` and splits it into the plot and, on its right, the legend's
/// column, so that no legend hides data.
fn with_legend_area<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<[DrawingArea<DB, Shift>; 2], String> {
    let titled = root.titled(title, (FONT, 22)).map_err(plot_error)?;
    let width = titled.dim_in_pixel().0;
    let (plot, legend) = titled.split_horizontally(width * (100 - LEGEND_WIDTH_PERCENT) / 100);
    Ok([plot, legend])
}

/// How a legend entry shows its series.
#[derive(Debug, Clone, Copy)]
enum Swatch {
    /// A filled box (bars).
    Box,
    /// A line (line series).
    Line,
}

/// One legend entry per series, top down, in the legend's column.
fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(&str, RGBColor)],
    swatch: Swatch,
) -> DrawResult {
    for (i, &(name, colour)) in entries.iter().enumerate() {
        let y = 40 + 24 * i as i32;
        match swatch {
            Swatch::Box => area
                .draw(&Rectangle::new([(6, y - 6), (20, y + 6)], colour.filled()))
                .map_err(plot_error)?,
            Swatch::Line => area
                .draw(&PathElement::new([(4, y), (22, y)], colour.stroke_width(2)))
                .map_err(plot_error)?,
        }
        area.draw(&Text::new(
            name.to_owned(),
            (28, y - 7),
            (FONT, 14).into_font().color(&BLACK),
        ))
        .map_err(plot_error)?;
    }
    Ok(())
}

/// Fig. 6: the lateral profiles of every lane change of one run, and the
/// learned weight matrix as a heat map.
pub struct Example<'a> {
    /// The run.
    pub trace: &'a ExampleTrace,
}

impl Figure for Example<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let trace = self.trace;
        let outcome = if trace.personalized {
            format!("personalized after {} takeovers", trace.takeovers)
        } else {
            format!("not personalized ({} takeovers)", trace.takeovers)
        };
        let root = root
            .titled(&format!("{}: {outcome}", trace.label), (FONT, 20))
            .map_err(plot_error)?;
        let (left, right) = root.split_horizontally(root.dim_in_pixel().0 * 11 / 20);
        self.profiles(&left)?;
        self.heat_map(&right)
    }
}

impl Example<'_> {
    fn profiles<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult {
        let trace = self.trace;
        let steps = (trace.lane_changes.iter())
            .map(|lc| lc.planned_l.len().max(lc.expected_l.len()))
            .max()
            .unwrap_or(1);
        let t_end = (steps.max(2) - 1) as f64 * trace.dt;
        let mut chart = ChartBuilder::on(area)
            .caption("lateral position over the lane changes", (FONT, 16))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..t_end, -0.5f64..4.2)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("time from the trigger (s)")
            .y_desc("l (m)")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(plot_error)?;
        let to_points = |values: &[f64]| -> Vec<(f64, f64)> {
            values
                .iter()
                .enumerate()
                .map(|(i, &l)| (i as f64 * trace.dt, l))
                .collect()
        };
        let count = trace.lane_changes.len().max(1);
        for (k, lc) in trace.lane_changes.iter().enumerate() {
            // Light to dark blue with the iteration.
            let f = if count > 1 {
                k as f64 / (count - 1) as f64
            } else {
                1.0
            };
            let shade = |light: f64, dark: f64| (light + (dark - light) * f) as u8;
            let colour = RGBColor(shade(180.0, 8.0), shade(205.0, 48.0), shade(235.0, 107.0));
            let series = chart
                .draw_series(LineSeries::new(
                    to_points(&lc.planned_l),
                    colour.stroke_width(2),
                ))
                .map_err(plot_error)?;
            if k == 0 || k + 1 == count {
                let name = if k == 0 {
                    "planned, first"
                } else {
                    "planned, last"
                };
                series.label(name).legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2))
                });
            }
            if lc.takeover_step.is_some() {
                chart
                    .draw_series(LineSeries::new(to_points(&lc.driven_l), RED.mix(0.35)))
                    .map_err(plot_error)?;
            }
        }
        if let Some(first) = trace.lane_changes.first() {
            let dashed =
                DashedLineSeries::new(to_points(&first.expected_l), 8, 5, BLACK.stroke_width(2));
            chart
                .draw_series(dashed)
                .map_err(plot_error)?
                .label("expected by the user")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK.stroke_width(2)));
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(0.0, 0.0)],
                    RED.mix(0.35),
                )))
                .map_err(plot_error)?
                .label("driven after a takeover")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED.mix(0.6)));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 12))
            .draw()
            .map_err(plot_error)?;
        Ok(())
    }

    fn heat_map<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult {
        let weights = &self.trace.weights;
        let columns = weights.len().max(1);
        let rows = self.trace.weight_names.len();
        let mut chart = ChartBuilder::on(area)
            .caption("learned weights (each row / its largest |w|)", (FONT, 16))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..columns as f64, 0.0..rows as f64)
            .map_err(plot_error)?;
        let names = &self.trace.weight_names;
        let row_label = |y: &f64| {
            let r = y.floor();
            if (y - r - 0.5).abs() < 1e-6 {
                names
                    .get(rows - 1 - r as usize)
                    .cloned()
                    .unwrap_or_default()
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("stage (control step)")
            .y_labels(rows * 2 + 1)
            .y_label_formatter(&row_label)
            .label_style((FONT, 12))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(plot_error)?;
        let scale: Vec<f64> = (0..rows)
            .map(|r| weights.iter().fold(0.0f64, |a, c| a.max(c[r].abs())))
            .collect();
        let cells = weights.iter().enumerate().flat_map(|(c, column)| {
            let scale = &scale;
            (0..rows).map(move |r| {
                let v = if scale[r] > 0.0 {
                    column[r] / scale[r]
                } else {
                    0.0
                };
                let y = (rows - 1 - r) as f64;
                Rectangle::new(
                    [(c as f64, y), (c as f64 + 1.0, y + 1.0)],
                    diverging(v).filled(),
                )
            })
        });
        chart.draw_series(cells).map_err(plot_error)?;
        Ok(())
    }
}

/// Blue (−1) through white (0) to red (+1).
fn diverging(v: f64) -> RGBColor {
    let v = v.clamp(-1.0, 1.0);
    let fade = |full: f64| (255.0 + (full - 255.0) * v.abs()) as u8;
    if v >= 0.0 {
        RGBColor(fade(178.0), fade(24.0), fade(43.0))
    } else {
        RGBColor(fade(33.0), fade(102.0), fade(172.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_read_as_the_steps_they_are() {
        assert_eq!(tick(0.7999999999999999), "0.8");
        assert_eq!(tick(0.30000000000000004), "0.3");
        assert_eq!(tick(-1e-12), "0");
        assert_eq!(tick(12.5), "12.5");
        assert_eq!(tick(-5.0), "-5");
    }

    #[test]
    fn bars_and_lines_render_to_svg_and_png_with_the_bundled_font() {
        register_bundled_font().unwrap();
        let dir = std::env::temp_dir().join(format!("palc-eval-figures-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bars = Bars {
            title: "takeovers by style".into(),
            x_desc: "style".into(),
            y_desc: "mean takeovers".into(),
            categories: vec!["aggressive".into(), "neutral".into(), "cautious".into()],
            series: vec![
                ("paper".into(), vec![Some(30.0), Some(28.0), None]),
                ("palc".into(), vec![Some(2.0), Some(3.0), Some(5.0)]),
            ],
            label_every: 1,
        };
        let lines = Lines {
            title: "ratio".into(),
            x_desc: "iteration".into(),
            y_desc: "ratio".into(),
            series: vec![("palc".into(), vec![(1.0, 0.2), (2.0, 0.6), (3.0, 1.0)])],
            y_range: Some((0.0, 1.05)),
            log_y: false,
        };
        let log = Lines {
            title: "compute".into(),
            x_desc: "K".into(),
            y_desc: "ms (log scale)".into(),
            series: vec![
                (
                    "palc".into(),
                    vec![(40.0, 0.01), (80.0, 0.4), (120.0, 25.0)],
                ),
                ("paper".into(), vec![(40.0, 0.0), (80.0, 0.0)]),
            ],
            y_range: None,
            log_y: true,
        };
        let [log_svg, _] = save(&dir, "log", (640, 400), &log).unwrap();
        let log_text = std::fs::read_to_string(&log_svg).unwrap();
        assert!(log_text.contains("paper (0, not drawn)"), "{log_text}");
        // Whole decades from 0.01 to 100 ms, each a tick label of its own.
        for decade in ["0.01", "0.1", "1", "10", "100"] {
            assert!(
                log_text.lines().any(|line| line.trim() == decade),
                "no {decade} tick: {log_text}"
            );
        }
        for [svg, png] in [
            save(&dir, "bars", (640, 400), &bars).unwrap(),
            save(&dir, "lines", (640, 400), &lines).unwrap(),
        ] {
            let svg_text = std::fs::read_to_string(&svg).unwrap();
            assert!(
                svg_text.contains("<svg") && svg_text.contains("mean takeovers")
                    || svg_text.contains("ratio")
            );
            let png_bytes = std::fs::read(&png).unwrap();
            assert_eq!(&png_bytes[1..4], b"PNG");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_diverging_map_is_white_at_zero_and_saturated_at_the_ends() {
        assert_eq!(diverging(0.0), RGBColor(255, 255, 255));
        assert_eq!(diverging(1.0), RGBColor(178, 24, 43));
        assert_eq!(diverging(-2.0), RGBColor(33, 102, 172));
    }
}

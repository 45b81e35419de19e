//! SVG figures of the validation cases ([`Plot`]), drawn with `plotters`' SVG back end.
//!
//! Only the SVG back end is compiled (no font or bitmap system libraries): text goes into the
//! file as `<text>` elements and the viewer picks the font, so label boxes are estimated.

use std::path::Path;

use std::ops::Range;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::prelude::*;

use crate::report::{Plot, Style};
use crate::{Error, Result};

/// Figure size in pixels.
const SIZE: (u32, u32) = (640, 420);

/// Series colours, in order (a colour-blind-safe qualitative palette).
const COLOURS: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
];

/// Renders `plot` as an SVG file at `path` (atomic write): axis labels, a legend, and
/// logarithmic axes where `plot.log_x` / `plot.log_y` ask for them. Points that cannot be
/// shown (not finite, or ≤ 0 on a logarithmic axis) are left out.
pub fn write_svg(plot: &Plot, path: &Path) -> Result<()> {
    let svg = render_svg(plot)?;
    crate::io::write_atomic(path, |w| w.write_all(svg.as_bytes()))
}

/// Renders `plot` as a PNG file at `path` (atomic write): the SVG of [`render_svg`]
/// rasterised by resvg at twice its size, text set in the system's fonts (none installed:
/// the text is left out).
pub fn write_png(plot: &Plot, path: &Path) -> Result<()> {
    use resvg::{tiny_skia, usvg};
    let svg = render_svg(plot)?;
    let fail = |e: String| Error::Other(format!("figure `{}` as PNG: {e}", plot.name));
    let mut options = usvg::Options::default();
    let fonts = options.fontdb_mut();
    fonts.load_system_fonts();
    // The SVG asks for `sans-serif`: map it to an installed sans face (DejaVu Sans on Debian).
    let family = fonts
        .faces()
        .flat_map(|f| f.families.iter().map(|(name, _)| name.clone()))
        .min_by_key(|name| {
            (
                !name.contains("Sans"),
                !name.starts_with("DejaVu"),
                name.len(),
            )
        });
    if let Some(family) = family {
        fonts.set_sans_serif_family(family);
    }
    let tree = usvg::Tree::from_str(&svg, &options).map_err(|e| fail(e.to_string()))?;
    let scale = 2.0;
    let size = tree
        .size()
        .to_int_size()
        .scale_by(scale)
        .ok_or_else(|| fail("size".into()))?;
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| fail("empty image".into()))?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    let png = pixmap.encode_png().map_err(|e| fail(e.to_string()))?;
    crate::io::write_atomic(path, |w| w.write_all(&png))
}

/// Renders `plot` into an SVG document in memory.
pub fn render_svg(plot: &Plot) -> Result<String> {
    let fail = |e: String| Error::Other(format!("figure `{}`: {e}", plot.name));
    let mut series: Vec<Vec<(f64, f64)>> = plot
        .series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|&(x, y)| shown(x, plot.log_x) && shown(y, plot.log_y))
                .collect()
        })
        .collect();
    let all = |series: &[Vec<(f64, f64)>]| series.iter().flatten().copied().collect::<Vec<_>>();
    let pts = all(&series);
    let x = extent(pts.iter().map(|p| p.0), plot.log_x).ok_or_else(|| fail("no data".into()))?;
    let mut y = match plot.y_range {
        Some(r) if r.0 < r.1 && shown(r.0, plot.log_y) && shown(r.1, plot.log_y) => r,
        Some(r) => return Err(fail(format!("invalid vertical range {r:?}"))),
        None => {
            extent(pts.iter().map(|p| p.1), plot.log_y).ok_or_else(|| fail("no data".into()))?
        }
    };
    if plot.y_range.is_some() {
        for s in &mut series {
            for p in s.iter_mut() {
                p.1 = p.1.clamp(y.0, y.1);
            }
        }
    }
    // The legend goes into the emptiest corner; if every corner holds data, the vertical range
    // grows at the top to make room for it there (unless the range is fixed).
    let labels = plot.series.iter().map(|s| s.label.len()).max().unwrap_or(0);
    // Series with an empty label have no legend entry.
    let entries = plot.series.iter().filter(|s| !s.label.is_empty()).count();
    let legend = (
        ((6 * labels + 50) as f64 / 540.0).min(0.9),
        (0.05 + 0.065 * entries as f64).min(0.8),
    );
    let (mut corner, crowded) = legend_corner(&pts, x, y, (plot.log_x, plot.log_y), legend);
    if crowded > 0 && plot.y_range.is_none() {
        let grow = legend.1 / (1.0 - legend.1);
        y.1 = if plot.log_y {
            y.1 * (y.1 / y.0).powf(grow)
        } else {
            y.1 + grow * (y.1 - y.0)
        };
        corner = legend_corner(&pts, x, y, (plot.log_x, plot.log_y), legend).0;
    }
    let (xt, yt) = (ticks(x, plot.log_x), ticks(y, plot.log_y));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        let r = draw(
            &root,
            plot,
            &series,
            Axis::new(x, plot.log_x, &xt),
            Axis::new(y, plot.log_y, &yt),
            corner,
        );
        r.map_err(fail)?;
        root.present().map_err(|e| fail(e.to_string()))?;
    }
    Ok(svg)
}

/// Whether a coordinate can be drawn on a linear or logarithmic axis.
fn shown(v: f64, log: bool) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

/// Axis range of the values with a margin: 5 % of the span on a linear axis, a factor
/// 10^(5 % of the decades) on a logarithmic one. `None` without values.
fn extent(values: impl Iterator<Item = f64>, log: bool) -> Option<(f64, f64)> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    if lo > hi {
        return None;
    }
    if log {
        let (a, b) = (lo.log10(), hi.log10());
        let pad = if b > a { 0.05 * (b - a) } else { 0.5 };
        Some((10f64.powf(a - pad), 10f64.powf(b + pad)))
    } else {
        let span = hi - lo;
        let pad = if span > 0.0 {
            0.05 * span
        } else if lo != 0.0 {
            0.1 * lo.abs()
        } else {
            1.0
        };
        Some((lo - pad, hi + pad))
    }
}

/// Tick positions of one axis: labelled (`bold`) and grid-only (`light`).
struct Ticks {
    bold: Vec<f64>,
    light: Vec<f64>,
    /// Labels are exact to this (absolute on a linear axis, relative on a logarithmic one).
    tol: f64,
}

/// Round ticks in `r`: multiples of 1, 2 or 5 × 10^k (four to eight) on a linear axis; on a
/// logarithmic one decades, or 1-2-5 or 1…9 × 10^k where the range spans few decades.
fn ticks(r: (f64, f64), log: bool) -> Ticks {
    let inside = |v: &f64| *v >= r.0 && *v <= r.1;
    if log {
        let (a, b) = (r.0.log10().floor() as i32, r.1.log10().ceil() as i32);
        let decades = r.1.log10() - r.0.log10();
        let every = |ms: &[f64], stride: i32| -> Vec<f64> {
            (a..=b)
                .filter(|k| k.rem_euclid(stride) == 0)
                .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
                .filter(inside)
                .collect()
        };
        let all: [f64; 9] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
        let bold = if decades > 8.0 {
            every(&[1.0], 2)
        } else if decades > 2.5 {
            every(&[1.0], 1)
        } else if decades > 0.8 {
            every(&[1.0, 2.0, 5.0], 1)
        } else {
            every(&all, 1)
        };
        return Ticks {
            bold,
            light: every(&all, 1),
            tol: 1e-6,
        };
    }
    let raw = (r.1 - r.0) / 8.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let multiples = |step: f64| -> Vec<f64> {
        let (i0, i1) = ((r.0 / step).ceil() as i64, (r.1 / step).floor() as i64);
        (i0..=i1).map(|i| i as f64 * step).collect()
    };
    Ticks {
        bold: multiples(step),
        light: multiples(step / 5.0),
        tol: 1e-6 * step,
    }
}

/// `v` in the shortest decimal (or, for magnitudes outside [10⁻³, 10⁵), scientific) form that
/// is within `tol` of it.
fn number(v: f64, tol: f64) -> String {
    if v.abs() <= tol {
        return "0".into();
    }
    let sci = !(1e-3..1e5).contains(&v.abs());
    (0..=8)
        .map(|p| {
            if sci {
                format!("{v:.p$e}")
            } else {
                format!("{v:.p$}")
            }
        })
        .find(|s| s.parse::<f64>().is_ok_and(|w| (w - v).abs() <= tol))
        .unwrap_or_else(|| format!("{v:e}"))
}

/// The corner of the axes with the fewest data points under a legend box of `size` (fractions
/// of the width and height), and that number.
fn legend_corner(
    pts: &[(f64, f64)],
    x: (f64, f64),
    y: (f64, f64),
    log: (bool, bool),
    size: (f64, f64),
) -> (SeriesLabelPosition, usize) {
    let unit = |v: f64, (a, b): (f64, f64), log: bool| {
        if log {
            (v.ln() - a.ln()) / (b.ln() - a.ln())
        } else {
            (v - a) / (b - a)
        }
    };
    let pts: Vec<(f64, f64)> = pts
        .iter()
        .map(|&(px, py)| (unit(px, x, log.0), unit(py, y, log.1)))
        .collect();
    let count = |right: bool, top: bool| {
        pts.iter()
            .filter(|&&(u, v)| {
                let inside_x = if right { u > 1.0 - size.0 } else { u < size.0 };
                let inside_y = if top { v > 1.0 - size.1 } else { v < size.1 };
                inside_x && inside_y
            })
            .count()
    };
    [
        (SeriesLabelPosition::UpperRight, count(true, true)),
        (SeriesLabelPosition::UpperLeft, count(false, true)),
        (SeriesLabelPosition::LowerRight, count(true, false)),
        (SeriesLabelPosition::LowerLeft, count(false, false)),
    ]
    .into_iter()
    .min_by_key(|c| c.1)
    .unwrap_or((SeriesLabelPosition::UpperRight, 0))
}

/// A linear or logarithmic axis with the given ticks.
#[derive(Clone)]
struct Axis {
    range: (f64, f64),
    log: bool,
    bold: Vec<f64>,
    light: Vec<f64>,
    /// Label precision (see [`Ticks::tol`]).
    tol: f64,
}

impl Axis {
    fn new(range: (f64, f64), log: bool, t: &Ticks) -> Self {
        Axis {
            range,
            log,
            bold: t.bold.clone(),
            light: t.light.clone(),
            tol: t.tol,
        }
    }

    /// Tick label of `v`.
    fn label(&self, v: f64) -> String {
        number(
            v,
            if self.log {
                self.tol * v.abs()
            } else {
                self.tol
            },
        )
    }
}

impl Ranged for Axis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let (a, b) = self.range;
        let t = if self.log {
            (v.ln() - a.ln()) / (b.ln() - a.ln())
        } else {
            (v - a) / (b - a)
        };
        limit.0 + (t * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.range.0..self.range.1
    }
}

/// Draws axes, series and a legend in `corner` on `root`.
fn draw(
    root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    plot: &Plot,
    series: &[Vec<(f64, f64)>],
    x: Axis,
    y: Axis,
    corner: SeriesLabelPosition,
) -> std::result::Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let (xa, ya) = (x.clone(), y.clone());
    let x_fmt = |v: &f64| xa.label(*v);
    let y_fmt = |v: &f64| ya.label(*v);
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(root)
        .caption(&plot.title, ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(x, y)
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(plot.x_label.as_str())
        .y_desc(plot.y_label.as_str())
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()
        .map_err(|e| err(&e))?;
    let mut markers = 0;
    for (k, (s, pts)) in plot.series.iter().zip(series).enumerate() {
        let colour = COLOURS[s.colour.unwrap_or(k) % COLOURS.len()];
        match s.style {
            Style::Line => {
                let line = colour.stroke_width(2);
                let drawn = chart
                    .draw_series(LineSeries::new(pts.iter().copied(), line))
                    .map_err(|e| err(&e))?;
                if !s.label.is_empty() {
                    drawn
                        .label(s.label.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], line));
                }
            }
            Style::Dashed => {
                let line = colour.stroke_width(2);
                let drawn = chart
                    .draw_series(DashedLineSeries::new(pts.iter().copied(), 7, 5, line))
                    .map_err(|e| err(&e))?;
                if !s.label.is_empty() {
                    drawn.label(s.label.as_str()).legend(move |(x, y)| {
                        plotters::element::DashedPathElement::new(
                            vec![(x, y), (x + 20, y)],
                            7,
                            5,
                            line,
                        )
                    });
                }
            }
            Style::Markers => {
                // Shapes differ between marker series (or groups of them, `Series::shape`) so
                // that coinciding points stay visible. 0: filled circle, 1: open square, 2: cross, 3: open triangle.
                let (fill, thin, thick) = (
                    colour.filled(),
                    colour.stroke_width(1),
                    colour.stroke_width(2),
                );
                macro_rules! shape {
                    ($p:ident => $e:expr) => {{
                        let drawn = chart
                            .draw_series(pts.iter().map(|&$p| $e))
                            .map_err(|e| err(&e))?;
                        if !s.label.is_empty() {
                            drawn.label(s.label.as_str()).legend(move |(x, y)| {
                                let $p = (x + 10, y);
                                $e
                            });
                        }
                    }};
                }
                match s.shape.unwrap_or(markers) % 4 {
                    0 => shape!(p => Circle::new(p, 3, fill)),
                    1 => {
                        shape!(p => EmptyElement::at(p) + Rectangle::new([(-4, -4), (4, 4)], thin))
                    }
                    2 => shape!(p => Cross::new(p, 4, thick)),
                    _ => shape!(p => TriangleMarker::new(p, 5, thin)),
                };
                markers += 1;
            }
        }
    }
    chart
        .configure_series_labels()
        .position(corner)
        .label_font(("sans-serif", 13))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .draw()
        .map_err(|e| err(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::Series;

    /// A dashed line is drawn as dashes: many more strokes than the one polyline of the same
    /// curve drawn solid.
    #[test]
    fn a_dashed_line_is_drawn_in_dashes() {
        let pts = vec![(0.0, 0.0), (1.0, 1.0)];
        let strokes = |s: Series| {
            let mut plot = Plot::new("t", "t", "x", "y");
            plot.series.push(s);
            render_svg(&plot).unwrap().matches("<polyline").count()
        };
        let (solid, dashed) = (
            strokes(Series::line("", pts.clone())),
            strokes(Series::dashed("", pts)),
        );
        assert!(
            dashed > solid + 10,
            "solid {solid}, dashed {dashed} strokes"
        );
    }
}

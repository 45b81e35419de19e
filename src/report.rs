//! Checks and figures: what a validation case, a material test or a study reports.
//!
//! A [`Check`] compares one measured quantity with its reference (an analytic solution, a
//! published table, a conservation law) under a stated tolerance; a [`Plot`] holds the data of
//! one figure, which [`crate::io::write_svg`] draws. [`Fidelity`] says how hard a case tries:
//! the test suite runs [`Fidelity::Test`], `granflow validate --full` [`Fidelity::Full`].

use serde::Serialize;

/// One checked quantity.
#[derive(Clone, Debug, Serialize)]
pub struct Check {
    /// Case name, e.g. `poiseuille`.
    pub case: String,
    /// What was measured.
    pub quantity: String,
    /// Measured value.
    pub value: f64,
    /// Reference value.
    pub reference: f64,
    /// Allowed deviation (absolute unless the quantity name says otherwise).
    pub tolerance: f64,
    /// Whether the check passed; `None`-like reports (reference shown, no gate) always pass.
    pub pass: bool,
}

impl Check {
    /// |value − reference| ≤ tolerance.
    pub fn abs(case: &str, quantity: &str, value: f64, reference: f64, tolerance: f64) -> Self {
        Check {
            case: case.into(),
            quantity: quantity.into(),
            value,
            reference,
            tolerance,
            pass: (value - reference).abs() <= tolerance,
        }
    }

    /// |value − reference| ≤ tolerance·|reference|.
    pub fn rel(case: &str, quantity: &str, value: f64, reference: f64, tolerance: f64) -> Self {
        Check {
            case: case.into(),
            quantity: format!("{quantity} (relative tolerance)"),
            value,
            reference,
            tolerance,
            pass: (value - reference).abs() <= tolerance * reference.abs(),
        }
    }

    /// value ≤ limit (reference = limit, tolerance 0).
    pub fn at_most(case: &str, quantity: &str, value: f64, limit: f64) -> Self {
        Check {
            case: case.into(),
            quantity: format!("{quantity} (at most)"),
            value,
            reference: limit,
            tolerance: 0.0,
            pass: value <= limit,
        }
    }

    /// value ≥ limit.
    pub fn at_least(case: &str, quantity: &str, value: f64, limit: f64) -> Self {
        Check {
            case: case.into(),
            quantity: format!("{quantity} (at least)"),
            value,
            reference: limit,
            tolerance: 0.0,
            pass: value >= limit,
        }
    }

    /// A reported quantity beside its reference, not gated (always passes).
    pub fn report(case: &str, quantity: &str, value: f64, reference: f64) -> Self {
        Check {
            case: case.into(),
            quantity: format!("{quantity} (reported, not gated)"),
            value,
            reference,
            tolerance: f64::INFINITY,
            pass: true,
        }
    }
}

/// What a case returns: its checks and the data of its figures.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Report {
    /// One per checked quantity.
    pub checks: Vec<Check>,
    /// Figures made from data the case computed anyway (no extra simulation).
    pub plots: Vec<Plot>,
}

/// How a [`Series`] is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Style {
    /// Points joined by a line (analytic solutions, time histories).
    Line,
    /// One marker per point (measurements, reference tables).
    Markers,
    /// Points joined by a dashed line (a second kind of curve beside `Line`).
    Dashed,
}

/// One curve or point set of a [`Plot`].
#[derive(Clone, Debug, Serialize)]
pub struct Series {
    /// Legend entry (empty: none).
    pub label: String,
    /// (x, y) data.
    pub points: Vec<(f64, f64)>,
    /// Line or markers.
    pub style: Style,
    /// Palette index of the colour; `None`: the series' position in the plot.
    pub colour: Option<usize>,
    /// Marker shape index (markers only); `None`: the series' position among the markers.
    pub shape: Option<usize>,
}

impl Series {
    /// A line through `points`.
    pub fn line(label: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            style: Style::Line,
            colour: None,
            shape: None,
        }
    }

    /// Markers at `points`.
    pub fn markers(label: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            style: Style::Markers,
            colour: None,
            shape: None,
        }
    }

    /// A dashed line through `points`.
    pub fn dashed(label: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            style: Style::Dashed,
            ..Series::line(label, points)
        }
    }

    /// Draw in palette colour `k` (so related series can share a colour).
    pub fn coloured(mut self, k: usize) -> Self {
        self.colour = Some(k);
        self
    }

    /// Draw markers of shape `k` (so the series of one group share a shape).
    pub fn shaped(mut self, k: usize) -> Self {
        self.shape = Some(k);
        self
    }

    /// Keep at most `max` points (≥ 2) by taking every k-th one, always keeping the last, so
    /// long time series stay small in a figure.
    pub fn decimated(mut self, max: usize) -> Self {
        let n = self.points.len();
        let max = max.max(2);
        if n > max {
            let stride = n.div_ceil(max - 1);
            let last = self.points[n - 1];
            let mut kept: Vec<_> = self.points.iter().copied().step_by(stride).collect();
            if kept.last() != Some(&last) {
                kept.push(last);
            }
            self.points = kept;
        }
        self
    }
}

/// The data of one figure; `granflow validate --figures DIR` writes it to `DIR/<name>.svg`.
#[derive(Clone, Debug, Serialize)]
pub struct Plot {
    /// File stem, e.g. `poiseuille-profile`.
    pub name: String,
    /// Caption drawn above the axes.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// Logarithmic horizontal axis.
    pub log_x: bool,
    /// Logarithmic vertical axis.
    pub log_y: bool,
    /// Fixed vertical range (points outside are drawn at its edge); `None`: fit the data.
    pub y_range: Option<(f64, f64)>,
    /// The curves, drawn in order.
    pub series: Vec<Series>,
}

impl Plot {
    /// An empty plot with linear axes.
    pub fn new(name: &str, title: &str, x_label: &str, y_label: &str) -> Self {
        Plot {
            name: name.into(),
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: false,
            y_range: None,
            series: Vec::new(),
        }
    }

    /// Fix the vertical range to [lo, hi] instead of fitting the data.
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Logarithmic axes (x, y).
    pub fn log(mut self, x: bool, y: bool) -> Self {
        self.log_x = x;
        self.log_y = y;
        self
    }

    /// Add a series.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }
}

/// Largest number of points a time series keeps in a figure.
pub const MAX_PLOT_POINTS: usize = 500;

/// How hard to try.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fidelity {
    /// The smallest resolution that still proves the claim (the test suite).
    Test,
    /// The full resolution of docs/validation.md.
    Full,
}

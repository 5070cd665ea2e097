//! Line plots of benchmark results: what a plot shows ([`LinePlot`], plain
//! data the benchmarks fill in) and, with the `plots` feature, its drawing
//! as PNG (`plot/draw.rs`). A build without that feature still describes every plot
//! but draws none: [`ENABLED`] is false and [`LinePlot::write_png`] writes
//! nothing, so the benchmarks write only their CSV tables.

use super::BenchError;
use std::path::Path;

#[cfg(feature = "plots")]
mod draw;

/// Whether this build draws plots (the `plots` feature).
pub const ENABLED: bool = cfg!(feature = "plots");

/// One line: a name for the legend and its (x, y) points.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// Points in drawing order; on a log axis, non-positive values are not
    /// drawable.
    pub points: Vec<(f64, f64)>,
    /// Drawn thin, grey and without markers: for guide lines such as n log n.
    pub guide: bool,
}

/// A titled plot of several series.
#[derive(Clone, Debug, Default)]
pub struct LinePlot {
    /// Heading drawn above the plot.
    pub title: String,
    /// Caption of the x axis (with units).
    pub x_label: String,
    /// Caption of the y axis (with units).
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The lines drawn, legend in this order.
    pub series: Vec<Series>,
}

impl LinePlot {
    /// Draws the plot and writes it as a PNG at `path`.
    #[cfg(feature = "plots")]
    pub fn write_png(&self, path: &Path) -> Result<(), BenchError> {
        draw::write_png(self, path)
    }

    /// Without the `plots` feature, writes nothing (see [`ENABLED`]).
    #[cfg(not(feature = "plots"))]
    pub fn write_png(&self, _path: &Path) -> Result<(), BenchError> {
        Ok(())
    }
}

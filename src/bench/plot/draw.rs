//! Drawing a [`LinePlot`] with `plotters` into an RGB buffer, written as PNG
//! with the `png` crate (only with the `plots` feature). Text uses the DejaVu
//! Sans font shipped in `assets/` (through plotters' `ab_glyph` feature), so
//! plotting needs no system fontconfig or freetype.
//!
//! Logarithmic axes are drawn by plotting log10 of the data on linear axes
//! and labelling ticks with 10^v: one code path for every mix of scales.

use super::{LinePlot, Series};
use crate::bench::BenchError;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

const FONT: &[u8] = include_bytes!("../../../assets/DejaVuSans.ttf");
const FONT_NAME: &str = "sans-serif";
const WIDTH: u32 = 960;
const HEIGHT: u32 = 640;

fn register_font() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        // The font is compiled in; if it were unreadable, labels would be
        // missing but the lines still drawn.
        let _ = plotters::style::register_font(FONT_NAME, FontStyle::Normal, FONT);
    });
}

/// A tick label for a coordinate that is log10 of the value when `log`.
fn tick_label(v: f64, log: bool) -> String {
    let value = if log { 10f64.powf(v) } else { v };
    let magnitude = value.abs();
    if magnitude == 0.0 {
        "0".into()
    } else if !(1e-2..1e5).contains(&magnitude) {
        format!("{value:.1e}")
    } else if magnitude >= 100.0 {
        format!("{value:.0}")
    } else {
        // Three significant digits, trailing zeros trimmed.
        let decimals = (2 - magnitude.log10().floor() as i32).max(0) as usize;
        let text = format!("{value:.decimals$}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    }
}

/// The plotted coordinate of a value (None if it cannot be shown on a log axis).
fn coordinate(v: f64, log: bool) -> Option<f64> {
    match log {
        true if v > 0.0 && v.is_finite() => Some(v.log10()),
        true => None,
        false => v.is_finite().then_some(v),
    }
}

/// Range covering `values` with 5% padding (a unit range when degenerate).
fn padded_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (low, high) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    if !low.is_finite() || !high.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((high - low) * 0.05).max(1e-3);
    (low - pad)..(high + pad)
}

/// Draws `plot` and writes it as a PNG at `path`.
pub fn write_png(plot: &LinePlot, path: &Path) -> Result<(), BenchError> {
    let mut rgb = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    draw(plot, &mut rgb).map_err(|message| BenchError::Plot {
        path: path.display().to_string(),
        message,
    })?;
    let mut png_bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut png_bytes, WIDTH, HEIGHT);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let plot_error = |e: png::EncodingError| BenchError::Plot {
            path: path.display().to_string(),
            message: e.to_string(),
        };
        let mut writer = encoder.write_header().map_err(plot_error)?;
        writer.write_image_data(&rgb).map_err(plot_error)?;
        writer.finish().map_err(plot_error)?;
    }
    crate::bench::write_atomically(path, &png_bytes)
}

fn draw(plot: &LinePlot, rgb: &mut [u8]) -> Result<(), String> {
    register_font();
    let series: Vec<(&Series, Vec<(f64, f64)>)> = plot
        .series
        .iter()
        .map(|s| {
            let points = s
                .points
                .iter()
                .filter_map(|&(x, y)| Some((coordinate(x, plot.log_x)?, coordinate(y, plot.log_y)?)))
                .collect();
            (s, points)
        })
        .collect();
    let x_range = padded_range(series.iter().flat_map(|(_, p)| p.iter().map(|q| q.0)));
    let y_range = padded_range(series.iter().flat_map(|(_, p)| p.iter().map(|q| q.1)));

    let root = BitMapBackend::with_buffer(rgb, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&plot.title, (FONT_NAME, 24))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range, y_range)
        .map_err(|e| e.to_string())?;
    let (log_x, log_y) = (plot.log_x, plot.log_y);
    let x_format = move |v: &f64| tick_label(*v, log_x);
    let y_format = move |v: &f64| tick_label(*v, log_y);
    let axis_note = |label: &str, log: bool| {
        if log {
            format!("{label} (log scale)")
        } else {
            label.to_string()
        }
    };
    chart
        .configure_mesh()
        .x_desc(axis_note(&plot.x_label, log_x))
        .y_desc(axis_note(&plot.y_label, log_y))
        .x_label_formatter(&x_format)
        .y_label_formatter(&y_format)
        .label_style((FONT_NAME, 15))
        .axis_desc_style((FONT_NAME, 17))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(|e| e.to_string())?;

    for (index, (s, points)) in series.iter().enumerate() {
        let color = Palette99::pick(index).to_rgba();
        let style = if s.guide {
            BLACK.mix(0.5).stroke_width(1)
        } else {
            color.stroke_width(2)
        };
        chart
            .draw_series(LineSeries::new(points.iter().copied(), style))
            .map_err(|e| e.to_string())?
            .label(s.name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
        if !s.guide {
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(|e| e.to_string())?;
        }
    }
    chart
        .configure_series_labels()
        .label_font((FONT_NAME, 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_read_as_values() {
        assert_eq!(tick_label(0.0, true), "1");
        assert_eq!(tick_label(2.0, true), "100");
        assert_eq!(tick_label(-1.0, true), "0.1");
        assert_eq!(tick_label(0.5, false), "0.5");
        assert_eq!(tick_label(-4.0, true), "1.0e-4");
    }

    #[test]
    fn log_axes_drop_values_they_cannot_show() {
        assert_eq!(coordinate(0.0, true), None);
        assert_eq!(coordinate(10.0, true), Some(1.0));
        assert_eq!(coordinate(-3.0, false), Some(-3.0));
    }
}

//! Line plots (plotters, drawing into a pixel buffer with the bundled DejaVu font, so no
//! system fonts are needed): stacked panels sharing an x axis, linear or log-log.

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;

/// Colours of the series, in order: distinct on white and in print.
pub const SERIES_COLOURS: [(u8, u8, u8); 8] = [
    (31, 119, 180),
    (214, 39, 40),
    (44, 160, 44),
    (255, 127, 14),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (23, 190, 207),
];

/// One line: points (x, y) and its legend text.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
}

/// One panel of the figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Heading above the panel.
    pub title: String,
    /// Label of the y axis.
    pub y_label: String,
    /// Its lines.
    pub series: Vec<Series>,
    /// Both axes logarithmic (every value must then be > 0).
    pub log_log: bool,
    /// Mark each point with a dot as well as joining them.
    pub points: bool,
}

/// A figure of panels stacked top to bottom, written as PNG.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Label of the shared x axis.
    pub x_label: String,
    /// The panels.
    pub panels: Vec<Panel>,
    /// Size (px).
    pub width: u32,
    /// Size (px).
    pub height: u32,
}

fn register_font() {
    static FONT: Once = Once::new();
    FONT.call_once(|| {
        // The font is compiled in and known to parse; a failure would leave text blank.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            crate::text::font_bytes(),
        );
    });
}

impl Figure {
    /// Draws the figure into RGB bytes (width × height × 3).
    pub fn draw(&self) -> Result<Vec<u8>, String> {
        register_font();
        let mut rgb = vec![255u8; self.width as usize * self.height as usize * 3];
        {
            let root =
                BitMapBackend::with_buffer(&mut rgb, (self.width, self.height)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let areas = root.split_evenly((self.panels.len().max(1), 1));
            for (panel, area) in self.panels.iter().zip(&areas) {
                draw_panel(panel, area, &self.x_label).map_err(|e| e.to_string())?;
            }
            root.present().map_err(|e| e.to_string())?;
        }
        Ok(rgb)
    }

    /// Draws the figure and writes it as PNG.
    pub fn write_png(&self, path: &Path) -> Result<(), String> {
        let rgb = self.draw()?;
        let rgba: Vec<u8> = rgb
            .chunks(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect();
        crate::encode::write_png_rgba(path, self.width, self.height, &rgba)
            .map_err(|e| e.to_string())
    }
}

/// The smallest and largest finite values, widened when they coincide.
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (-1.0, 1.0) };
    }
    if log {
        (lo / 1.5, hi * 1.5)
    } else if hi - lo <= 1e-12 * lo.abs().max(1.0) {
        let pad = lo.abs().max(1.0) * 0.05;
        (lo - pad, hi + pad)
    } else {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    }
}

/// A tick label: on log axes one significant digit in exponent form (1e-3, 5e-2), which
/// plotters' default writes as 9.9999999e-5.
fn tick(v: f64, log: bool) -> String {
    if log {
        format!("{v:.0e}")
    } else {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

fn draw_panel(
    panel: &Panel,
    area: &Area<'_>,
    x_label: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let xs = range(
        panel.series.iter().flat_map(|s| s.x.iter().copied()),
        panel.log_log,
    );
    let ys = range(
        panel.series.iter().flat_map(|s| s.y.iter().copied()),
        panel.log_log,
    );
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(&panel.title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(38)
        .y_label_area_size(70);
    let style = |i: usize| {
        let (r, g, b) = SERIES_COLOURS[i % SERIES_COLOURS.len()];
        RGBColor(r, g, b)
    };
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(&panel.y_label)
                .label_style(("sans-serif", 13))
                .axis_desc_style(("sans-serif", 14))
                .light_line_style(RGBColor(235, 235, 235))
                .x_labels(if panel.log_log { 6 } else { 10 })
                .y_labels(if panel.log_log { 8 } else { 10 })
                .x_label_formatter(&|v| tick(*v, panel.log_log))
                .y_label_formatter(&|v| tick(*v, panel.log_log))
                .draw()?;
            for (i, s) in panel.series.iter().enumerate() {
                let colour = style(i);
                let points: Vec<(f64, f64)> = s
                    .x
                    .iter()
                    .zip(&s.y)
                    .map(|(x, y)| (*x, *y))
                    .filter(|(x, y)| {
                        x.is_finite() && y.is_finite() && (!panel.log_log || (*x > 0.0 && *y > 0.0))
                    })
                    .collect();
                chart
                    .draw_series(LineSeries::new(
                        points.iter().copied(),
                        colour.stroke_width(2),
                    ))?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                    });
                if panel.points {
                    chart
                        .draw_series(points.iter().map(|p| Circle::new(*p, 3, colour.filled())))?;
                }
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(200, 200, 200))
                .label_font(("sans-serif", 13))
                // Error lines rise to the right on a log-log plot: the lower right is free.
                .position(if panel.log_log {
                    SeriesLabelPosition::LowerRight
                } else {
                    SeriesLabelPosition::UpperLeft
                })
                .draw()?;
        }};
    }
    if panel.log_log {
        body!(builder.build_cartesian_2d((xs.0..xs.1).log_scale(), (ys.0..ys.1).log_scale())?);
    } else {
        body!(builder.build_cartesian_2d(xs.0..xs.1, ys.0..ys.1)?);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_pad_and_survive_flat_or_empty_data() {
        assert_eq!(range([1.0, 1.0].into_iter(), false), (0.95, 1.05));
        assert_eq!(range(std::iter::empty(), true), (0.1, 10.0));
        let (lo, hi) = range([0.0, 10.0].into_iter(), false);
        assert!(lo < 0.0 && hi > 10.0);
        let (lo, _) = range([-1.0, 0.0, 1e-3].into_iter(), true);
        assert!(lo > 0.0);
    }
}

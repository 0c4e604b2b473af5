//! Line plots of observables: MPPphys's particle inspector (seed 002 §3.2) —
//! several series against one abscissa, linear or logarithmic axes, axis labels
//! with units — written as PNG or SVG with the bundled font.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::RenderError;

/// One curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
}

/// A plot of several series.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    pub title: Option<String>,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub log_x: bool,
    pub log_y: bool,
    pub width: u32,
    pub height: u32,
}

impl Plot {
    /// Writes the plot; the format follows the extension (`.png` or `.svg`).
    pub fn write(&self, path: &Path) -> Result<(), RenderError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("svg") => {
                let mut s = String::new();
                {
                    let root = SVGBackend::with_string(&mut s, (self.width, self.height))
                        .into_drawing_area();
                    self.draw(&root)?;
                }
                std::fs::write(path, s).map_err(|e| RenderError::io(path, e))
            }
            Some("png") => {
                let mut buf = vec![0u8; 3 * self.width as usize * self.height as usize];
                {
                    let root = BitMapBackend::with_buffer(&mut buf, (self.width, self.height))
                        .into_drawing_area();
                    self.draw(&root)?;
                }
                let img = crate::image::Image {
                    width: self.width,
                    height: self.height,
                    rgb: buf,
                    depth: Vec::new(),
                };
                img.write_png(path)
            }
            _ => Err(RenderError::Invalid(format!(
                "{}: unknown picture format, expected a name ending in .png or .svg",
                path.display()
            ))),
        }
    }

    /// The ranges of the finite (and, on log axes, positive) points.
    fn ranges(&self) -> Result<[(f64, f64); 2], RenderError> {
        let mut xr = (f64::INFINITY, f64::NEG_INFINITY);
        let mut yr = (f64::INFINITY, f64::NEG_INFINITY);
        for s in &self.series {
            for (&x, &y) in s.x.iter().zip(&s.y) {
                if self.usable(x, y) {
                    xr = (xr.0.min(x), xr.1.max(x));
                    yr = (yr.0.min(y), yr.1.max(y));
                }
            }
        }
        if xr.0 > xr.1 {
            return Err(RenderError::Invalid(
                "no finite points to plot (on a log axis, values must be positive)".into(),
            ));
        }
        Ok([pad(xr, self.log_x, 0.0), pad(yr, self.log_y, 0.05)])
    }

    fn usable(&self, x: f64, y: f64) -> bool {
        x.is_finite() && y.is_finite() && (!self.log_x || x > 0.0) && (!self.log_y || y > 0.0)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), RenderError>
    where
        DB::ErrorType: 'static,
    {
        crate::register_font();
        let err = |e: &dyn std::fmt::Display| RenderError::Plot(format!("plot: {e}"));
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let [xr, yr] = self.ranges()?;
        let scale = self.height as f64 / 600.0;
        let font = |px: f64| ("sans-serif", px * scale).into_font();
        let mut builder = ChartBuilder::on(root);
        builder
            .margin((16.0 * scale) as u32)
            .x_label_area_size((50.0 * scale) as u32)
            .y_label_area_size((80.0 * scale) as u32);
        if let Some(t) = &self.title {
            builder.caption(t, font(22.0));
        }
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(self.x_label.as_str())
                    .y_desc(self.y_label.as_str())
                    .label_style(font(15.0))
                    .axis_desc_style(font(17.0))
                    .light_line_style(RGBColor(235, 235, 235))
                    .draw()
                    .map_err(|e| err(&e))?;
                for (k, s) in self.series.iter().enumerate() {
                    let color = Palette99::pick(k).to_rgba();
                    let color = if k < 8 {
                        let c = crate::colormap::category_color(k + 4);
                        RGBColor(
                            (c[0] * 255.0) as u8,
                            (c[1] * 255.0) as u8,
                            (c[2] * 255.0) as u8,
                        )
                        .to_rgba()
                    } else {
                        color
                    };
                    let pts: Vec<(f64, f64)> =
                        s.x.iter()
                            .zip(&s.y)
                            .filter(|(&x, &y)| self.usable(x, y))
                            .map(|(&x, &y)| (x, y))
                            .collect();
                    chart
                        .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                        .map_err(|e| err(&e))?
                        .label(s.name.as_str())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                        });
                }
                if self.series.len() > 1 || !self.series.is_empty() {
                    chart
                        .configure_series_labels()
                        .label_font(font(15.0))
                        .background_style(WHITE.mix(0.85))
                        .border_style(BLACK)
                        .position(SeriesLabelPosition::UpperRight)
                        .draw()
                        .map_err(|e| err(&e))?;
                }
            }};
        }
        match (self.log_x, self.log_y) {
            (false, false) => body!(builder
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
                .map_err(|e| err(&e))?),
            (true, false) => body!(builder
                .build_cartesian_2d((xr.0..xr.1).log_scale(), yr.0..yr.1)
                .map_err(|e| err(&e))?),
            (false, true) => body!(builder
                .build_cartesian_2d(xr.0..xr.1, (yr.0..yr.1).log_scale())
                .map_err(|e| err(&e))?),
            (true, true) => body!(builder
                .build_cartesian_2d((xr.0..xr.1).log_scale(), (yr.0..yr.1).log_scale())
                .map_err(|e| err(&e))?),
        }
        root.present().map_err(|e| err(&e))?;
        Ok(())
    }
}

/// Widens a range by `frac` on each side (multiplicatively on a log axis) and
/// makes an empty range non-empty.
fn pad((lo, hi): (f64, f64), log: bool, frac: f64) -> (f64, f64) {
    if log {
        let (a, b) = (lo.ln(), hi.ln());
        let w = if b > a { (b - a) * frac } else { 0.5 };
        ((a - w).exp(), (b + w).exp())
    } else {
        let w = if hi > lo {
            (hi - lo) * frac
        } else if lo != 0.0 {
            lo.abs() * 0.05
        } else {
            1.0
        };
        (lo - w, hi + w)
    }
}

/// An axis label: the column name with its unit in brackets if there is one.
pub fn axis_label(name: &str, unit: Option<&str>) -> String {
    match unit.map(str::trim).filter(|u| !u.is_empty()) {
        Some(u) => format!("{name} [{u}]"),
        None => name.to_string(),
    }
}

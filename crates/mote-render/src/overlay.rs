//! Things drawn over a rendered picture: the colour bar of a per-particle quantity.

use plotters::prelude::*;

use crate::colormap::ColorMap;
use crate::image::Image;
use crate::RenderError;

/// Draws a vertical colour bar at the right edge: the map from `lo` (bottom) to
/// `hi` (top), five tick labels and the `label` above it.
pub fn color_bar(
    img: &mut Image,
    map: ColorMap,
    lo: f64,
    hi: f64,
    label: &str,
) -> Result<(), RenderError> {
    crate::register_font();
    let (w, h) = (img.width, img.height);
    let scale = (h as f64 / 1080.0).max(0.35);
    let bar_w = (28.0 * scale).round().max(6.0) as i32;
    let bar_h = (h as f64 * 0.6).round() as i32;
    let font_px = (26.0 * scale).max(9.0);
    let label_w = (font_px * 5.5) as i32;
    let x0 = w as i32 - bar_w - label_w - (20.0 * scale) as i32;
    let y0 = (h as i32 - bar_h) / 2;
    if x0 < 0 || bar_h < 10 {
        return Ok(());
    }
    let err = |e: &dyn std::fmt::Display| RenderError::Plot(format!("colour bar: {e}"));
    let root = BitMapBackend::with_buffer(&mut img.rgb, (w, h)).into_drawing_area();
    for k in 0..bar_h {
        let s = 1.0 - k as f32 / (bar_h - 1) as f32;
        let c = map.at(s);
        let col = RGBColor(
            (c[0] * 255.0).round() as u8,
            (c[1] * 255.0).round() as u8,
            (c[2] * 255.0).round() as u8,
        );
        root.draw(&Rectangle::new(
            [(x0, y0 + k), (x0 + bar_w, y0 + k + 1)],
            col.filled(),
        ))
        .map_err(|e| err(&e))?;
    }
    root.draw(&Rectangle::new(
        [(x0, y0), (x0 + bar_w, y0 + bar_h)],
        BLACK.stroke_width(1),
    ))
    .map_err(|e| err(&e))?;
    let style = ("sans-serif", font_px).into_font().color(&BLACK);
    for k in 0..5 {
        let s = k as f64 / 4.0;
        let v = lo + (hi - lo) * s;
        let y = y0 + bar_h - (s * bar_h as f64).round() as i32;
        root.draw(&PathElement::new(
            vec![(x0 + bar_w, y), (x0 + bar_w + 6, y)],
            BLACK.stroke_width(1),
        ))
        .map_err(|e| err(&e))?;
        root.draw(&Text::new(
            format_tick(v),
            (x0 + bar_w + 9, y - (font_px * 0.5) as i32),
            style.clone(),
        ))
        .map_err(|e| err(&e))?;
    }
    root.draw(&Text::new(
        label.to_string(),
        (x0 - (font_px * 0.5) as i32, y0 - (font_px * 1.6) as i32),
        style,
    ))
    .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// A short label for a tick value.
pub fn format_tick(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

//! PNG heat maps of two-parameter scans with a colour bar (in the style of 003, Fig. 5),
//! drawn directly into an RGB buffer with a small built-in 3×5 pixel font.

use std::io::Write;

use crate::design::Scan;

/// An RGB image.
#[derive(Debug, Clone)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// RGB bytes, row by row.
    pub pixels: Vec<u8>,
}

impl Image {
    fn new(width: usize, height: usize) -> Self {
        Image {
            width,
            height,
            pixels: vec![255; width * height * 3],
        }
    }

    fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = (y * self.width + x) * 3;
            self.pixels[i..i + 3].copy_from_slice(&c);
        }
    }

    fn fill(&mut self, x0: usize, y0: usize, w: usize, h: usize, c: [u8; 3]) {
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                self.set(x, y, c);
            }
        }
    }

    /// Text with the built-in font at pixel scale `s`, left edge at x.
    fn text(&mut self, x: usize, y: usize, s: usize, text: &str) {
        let mut cx = x;
        for ch in text.chars() {
            let g = glyph(ch);
            for row in 0..5 {
                for col in 0..3 {
                    if g >> (14 - (row * 3 + col)) & 1 == 1 {
                        self.fill(cx + col * s, y + row * s, s, s, [0, 0, 0]);
                    }
                }
            }
            cx += 4 * s;
        }
    }

    fn text_width(s: usize, text: &str) -> usize {
        (text.chars().count() * 4).saturating_sub(1) * s
    }

    /// Encodes the image as PNG.
    pub fn write_png(&self, w: impl Write) -> Result<(), mote_io::png::EncodingError> {
        mote_io::png::encode_rgb(w, self.width as u32, self.height as u32, &self.pixels)
    }
}

/// 3×5 glyphs, 15 bits row-major from the top-left (upper-case letters for both cases).
fn glyph(c: char) -> u16 {
    let rows: [u8; 5] = match c.to_ascii_uppercase() {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        ',' => [0, 0, 0, 2, 4],
        '-' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        ':' => [0, 2, 0, 2, 0],
        '=' => [0, 7, 0, 7, 0],
        '_' => [0, 0, 0, 0, 7],
        '(' => [2, 4, 4, 4, 2],
        ')' => [2, 1, 1, 1, 2],
        '/' => [1, 1, 2, 4, 4],
        'A' => [2, 5, 7, 5, 5],
        'B' => [6, 5, 6, 5, 6],
        'C' => [3, 4, 4, 4, 3],
        'D' => [6, 5, 5, 5, 6],
        'E' => [7, 4, 6, 4, 7],
        'F' => [7, 4, 6, 4, 4],
        'G' => [3, 4, 5, 5, 3],
        'H' => [5, 5, 7, 5, 5],
        'I' => [7, 2, 2, 2, 7],
        'J' => [1, 1, 1, 5, 2],
        'K' => [5, 5, 6, 5, 5],
        'L' => [4, 4, 4, 4, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'O' => [2, 5, 5, 5, 2],
        'P' => [6, 5, 6, 4, 4],
        'Q' => [2, 5, 5, 6, 3],
        'R' => [6, 5, 6, 5, 5],
        'S' => [3, 4, 2, 1, 6],
        'T' => [7, 2, 2, 2, 2],
        'U' => [5, 5, 5, 5, 7],
        'V' => [5, 5, 5, 5, 2],
        'W' => [5, 5, 7, 7, 5],
        'X' => [5, 5, 2, 5, 5],
        'Y' => [5, 5, 2, 2, 2],
        'Z' => [7, 1, 2, 4, 7],
        _ => [0, 0, 0, 0, 0],
    };
    rows.iter().fold(0u16, |acc, &r| (acc << 3) | r as u16)
}

/// A perceptually ordered colour map (viridis, 9 anchors, linear in between), t in [0, 1].
pub fn colour(t: f64) -> [u8; 3] {
    const V: [[f64; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    if !t.is_finite() {
        return [200, 200, 200];
    }
    let u = t.clamp(0.0, 1.0) * 8.0;
    let i = (u.floor() as usize).min(7);
    let f = u - i as f64;
    let mut c = [0u8; 3];
    for k in 0..3 {
        c[k] = (V[i][k] + f * (V[i + 1][k] - V[i][k])).round() as u8;
    }
    c
}

fn label(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s
    }
}

/// Draws φ of a scan as a heat map (x to the right, y upwards) with axis labels and a
/// colour bar from the smallest to the largest φ.
pub fn render(scan: &Scan, title: &str) -> Image {
    let (w, h) = (720usize, 540usize);
    let mut img = Image::new(w, h);
    let (left, top, pw, ph) = (80usize, 50usize, 500usize, 420usize);
    let finite: Vec<f64> = scan.phi.iter().copied().filter(|v| v.is_finite()).collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let span = if hi > lo { hi - lo } else { 1.0 };
    let (nx, ny) = (scan.x.count, scan.y.count);
    // Each pixel shows the nearest grid point, so that ticks sit on cell centres.
    let nearest = |p: usize, len: usize, n: usize| -> usize {
        ((p as f64 / (len - 1) as f64 * (n - 1) as f64).round() as usize).min(n - 1)
    };
    for py in 0..ph {
        let j = nearest(ph - 1 - py, ph, ny);
        for px in 0..pw {
            let i = nearest(px, pw, nx);
            let v = scan.phi[j * nx + i];
            img.set(left + px, top + py, colour((v - lo) / span));
        }
    }
    // Frame and ticks.
    let black = [0, 0, 0];
    img.fill(left - 1, top - 1, pw + 2, 1, black);
    img.fill(left - 1, top + ph, pw + 2, 1, black);
    img.fill(left - 1, top - 1, 1, ph + 2, black);
    img.fill(left + pw, top - 1, 1, ph + 2, black);
    let s = 2;
    for k in 0..=4 {
        let fx = k as f64 / 4.0;
        let vx = scan.x.start + fx * (scan.x.stop - scan.x.start);
        let px = left + (fx * (pw - 1) as f64) as usize;
        img.fill(px, top + ph, 1, 6, black);
        let t = label(vx);
        img.text(
            px.saturating_sub(Image::text_width(s, &t) / 2),
            top + ph + 10,
            s,
            &t,
        );
        let vy = scan.y.start + fx * (scan.y.stop - scan.y.start);
        let py = top + ph - 1 - (fx * (ph - 1) as f64) as usize;
        img.fill(left - 6, py, 6, 1, black);
        let t = label(vy);
        img.text(
            (left - 10).saturating_sub(Image::text_width(s, &t)),
            py.saturating_sub(5),
            s,
            &t,
        );
    }
    let xl = scan.x.param.to_string();
    img.text(
        left + pw / 2 - Image::text_width(3, &xl) / 2,
        top + ph + 32,
        3,
        &xl,
    );
    let yl = scan.y.param.to_string();
    img.text(8, top.saturating_sub(22), 3, &yl);
    img.text(
        left + pw / 2 - Image::text_width(3, title) / 2,
        12,
        3,
        title,
    );
    // Colour bar.
    let (bx, bw) = (left + pw + 30, 24usize);
    for py in 0..ph {
        let t = 1.0 - py as f64 / (ph - 1) as f64;
        img.fill(bx, top + py, bw, 1, colour(t));
    }
    img.fill(bx - 1, top - 1, bw + 2, 1, black);
    img.fill(bx - 1, top + ph, bw + 2, 1, black);
    img.fill(bx - 1, top - 1, 1, ph + 2, black);
    img.fill(bx + bw, top - 1, 1, ph + 2, black);
    if lo.is_finite() {
        for k in 0..=4 {
            let fy = k as f64 / 4.0;
            let py = top + ph - 1 - (fy * (ph - 1) as f64) as usize;
            img.fill(bx + bw, py, 5, 1, black);
            img.text(
                bx + bw + 8,
                py.saturating_sub(5),
                s,
                &format!("{:.4}", lo + fy * span),
            );
        }
    }
    img.text(bx, top - 22, 3, "PHI");
    img
}

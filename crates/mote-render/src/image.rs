//! An 8-bit RGB picture with its depth buffer; PNG in and out; comparisons for
//! golden-image tests; red–cyan anaglyphs.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use crate::RenderError;

/// An RGB picture, rows top to bottom, and per pixel the distance along the
/// primary ray to the first surface (infinite for background).
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
    pub depth: Vec<f32>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            rgb: vec![0; 3 * n],
            depth: vec![f32::INFINITY; n],
        }
    }

    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let k = 3 * (y as usize * self.width as usize + x as usize);
        [self.rgb[k], self.rgb[k + 1], self.rgb[k + 2]]
    }

    pub fn set_pixel(&mut self, x: u32, y: u32, c: [u8; 3]) {
        let k = 3 * (y as usize * self.width as usize + x as usize);
        self.rgb[k..k + 3].copy_from_slice(&c);
    }

    /// Writes the picture as an 8-bit RGB PNG.
    pub fn write_png(&self, path: &Path) -> Result<(), RenderError> {
        let file = File::create(path).map_err(|e| RenderError::io(path, e))?;
        mote_io::png::encode_rgb(BufWriter::new(file), self.width, self.height, &self.rgb)
            .map_err(|e| RenderError::Png(path.display().to_string(), e.to_string()))
    }

    /// Reads an 8-bit RGB or RGBA PNG (alpha dropped); depth is left infinite.
    pub fn read_png(path: &Path) -> Result<Self, RenderError> {
        let file = File::open(path).map_err(|e| RenderError::io(path, e))?;
        let name = path.display().to_string();
        let dec = png::Decoder::new(file);
        let mut reader = dec
            .read_info()
            .map_err(|e| RenderError::Png(name.clone(), e.to_string()))?;
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader
            .next_frame(&mut buf)
            .map_err(|e| RenderError::Png(name.clone(), e.to_string()))?;
        if info.bit_depth != png::BitDepth::Eight {
            return Err(RenderError::Png(name, "only 8-bit PNGs are read".into()));
        }
        let channels = match info.color_type {
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            other => {
                return Err(RenderError::Png(
                    name,
                    format!("colour type {other:?}, expected RGB or RGBA"),
                ))
            }
        };
        let mut img = Image::new(info.width, info.height);
        for (k, px) in buf[..info.buffer_size()].chunks(channels).enumerate() {
            img.rgb[3 * k..3 * k + 3].copy_from_slice(&px[..3]);
        }
        Ok(img)
    }

    /// How two pictures of the same size differ: (mean absolute difference per
    /// channel in 0..=255, fraction of pixels where some channel differs by more than
    /// `tol`). `None` if the sizes differ.
    pub fn difference(&self, other: &Image, tol: u8) -> Option<(f64, f64)> {
        if self.width != other.width || self.height != other.height {
            return None;
        }
        let mut sum = 0u64;
        let mut bad = 0usize;
        for (a, b) in self.rgb.chunks(3).zip(other.rgb.chunks(3)) {
            let mut worst = 0u8;
            for c in 0..3 {
                let d = a[c].abs_diff(b[c]);
                sum += d as u64;
                worst = worst.max(d);
            }
            if worst > tol {
                bad += 1;
            }
        }
        let n = (self.width as usize * self.height as usize).max(1);
        Some((sum as f64 / (3 * n) as f64, bad as f64 / n as f64))
    }
}

/// Red–cyan anaglyph: the red channel shows the left eye's picture and green and
/// blue the right eye's, each as grey levels (so that colours do not leak between
/// the eyes). Depth is taken from the left picture.
pub fn anaglyph(left: &Image, right: &Image) -> Image {
    assert_eq!((left.width, left.height), (right.width, right.height));
    let mut out = left.clone();
    let lum = |p: &[u8]| -> u8 {
        (0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32).round() as u8
    };
    for ((o, l), r) in out
        .rgb
        .chunks_mut(3)
        .zip(left.rgb.chunks(3))
        .zip(right.rgb.chunks(3))
    {
        let (gl, gr) = (lum(l), lum(r));
        o[0] = gl;
        o[1] = gr;
        o[2] = gr;
    }
    out
}

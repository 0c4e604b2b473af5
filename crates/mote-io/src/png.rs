//! PNG pictures as plain data: 8-bit RGB rows, top to bottom. The one PNG
//! encoder of mote (ray-traced pictures, plots, rod-packing heat maps).

use std::io::Write;

pub use ::png::EncodingError;

/// Encodes `rgb` (width × height × 3 bytes, rows from the top) as an 8-bit
/// RGB PNG into `w`.
pub fn encode_rgb(w: impl Write, width: u32, height: u32, rgb: &[u8]) -> Result<(), EncodingError> {
    let mut enc = ::png::Encoder::new(w, width, height);
    enc.set_color(::png::ColorType::Rgb);
    enc.set_depth(::png::BitDepth::Eight);
    let mut writer = enc.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodes_what_a_decoder_reads_back() {
        let rgb: Vec<u8> = (0..2 * 3 * 3).map(|k| (k * 13) as u8).collect();
        let mut bytes = Vec::new();
        encode_rgb(&mut bytes, 3, 2, &rgb).unwrap();
        let mut reader = ::png::Decoder::new(bytes.as_slice()).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(&buf[..info.buffer_size()], rgb.as_slice());
        assert!(encode_rgb(Vec::new(), 3, 2, &rgb[..5]).is_err());
    }
}

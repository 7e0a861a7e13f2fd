//! Text on pictures, from the DejaVu Sans font compiled in (no system fonts needed).

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use tiny_skia::Pixmap;

use crate::model::Rgb;

/// DejaVu Sans, as shipped by the `dejavu` crate.
pub fn font_bytes() -> &'static [u8] {
    dejavu::sans::regular()
}

/// Draws `text` with its baseline's left end at (x, y) px, `size` px tall, blending
/// glyph coverage over the opaque picture.
pub fn draw(pixmap: &mut Pixmap, text: &str, x: f32, y: f32, size: f32, colour: Rgb) {
    let font = FontRef::try_from_slice(font_bytes()).expect("the bundled font parses");
    let scaled = font.as_scaled(PxScale::from(size));
    let (w, h) = (pixmap.width() as i32, pixmap.height() as i32);
    let data = pixmap.data_mut();
    let mut pen = x;
    for c in text.chars() {
        let glyph = scaled.scaled_glyph(c);
        let advance = scaled.h_advance(glyph.id);
        let glyph = ab_glyph::Glyph {
            position: ab_glyph::point(pen, y),
            ..glyph
        };
        if let Some(outline) = font.outline_glyph(glyph) {
            let b = outline.px_bounds();
            outline.draw(|gx, gy, coverage| {
                let (px, py) = (b.min.x as i32 + gx as i32, b.min.y as i32 + gy as i32);
                if px < 0 || py < 0 || px >= w || py >= h {
                    return;
                }
                let i = 4 * (py * w + px) as usize;
                let a = coverage.clamp(0.0, 1.0);
                for (k, channel) in colour.0.iter().enumerate() {
                    let old = f32::from(data[i + k]);
                    data[i + k] = (old + (f32::from(*channel) - old) * a).round() as u8;
                }
            });
        }
        pen += advance;
    }
}

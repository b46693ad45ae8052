//! The SVG drawing rendered to a PNG with `resvg` (pure Rust): the very document
//! [`svg`](super::svg()) writes, so the two cannot differ. Text is set in the DejaVu faces the
//! `dejavu` crate ships (Sans Mono, which the SVG asks for, regular and bold; Sans, regular
//! and bold, for any glyph the mono face lacks): no system fonts are read, so a PNG is the
//! same on every machine.

use resvg::{tiny_skia, usvg};

/// The default pixels per SVG pixel: crisp on a high-density screen, small enough for docs.
pub const DEFAULT_SCALE: f32 = 2.0;

/// Largest side of a PNG (px): a bigger one is refused rather than allocated.
pub const MAX_SIDE: u32 = 16_384;

/// The rendering options: the DejaVu faces only, every generic family mapped onto them.
fn options() -> usvg::Options<'static> {
    let mut opt = usvg::Options::default();
    let db = opt.fontdb_mut();
    for face in [
        dejavu::sans_mono::regular(),
        dejavu::sans_mono::bold(),
        dejavu::sans::regular(),
        dejavu::sans::bold(),
    ] {
        db.load_font_data(face.to_vec());
    }
    db.set_monospace_family("DejaVu Sans Mono");
    db.set_sans_serif_family("DejaVu Sans");
    // usvg's last resort for an unmatched family is `serif`: the mono face, as the SVG asks
    db.set_serif_family("DejaVu Sans Mono");
    opt.font_family = "DejaVu Sans Mono".into();
    opt
}

/// Render `svg` at `scale` pixels per SVG pixel. Err: a scale that is not a finite positive
/// number, an image beyond [`MAX_SIDE`], or an SVG that does not parse.
pub fn render(svg: &str, scale: f32) -> Result<tiny_skia::Pixmap, String> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(format!("--scale must be a finite number > 0, not {scale}"));
    }
    let tree = usvg::Tree::from_str(svg, &options()).map_err(|e| format!("bad SVG: {e}"))?;
    let size = tree.size();
    let (w, h) = (size.width() * scale, size.height() * scale);
    let side = MAX_SIDE as f32;
    if !(w >= 1.0 && h >= 1.0 && w <= side && h <= side) {
        return Err(format!(
            "a {w:.0} × {h:.0} px image at --scale {scale}: each side must be 1 to {MAX_SIDE} px (choose a smaller --scale)"
        ));
    }
    // `w`, `h` are in 1..=MAX_SIDE (checked above): the casts are exact after ceil
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let mut pixmap = tiny_skia::Pixmap::new(w.ceil() as u32, h.ceil() as u32)
        .ok_or_else(|| format!("cannot allocate a {w:.0} × {h:.0} px image"))?;
    // white, not transparent, where the drawing's white ground does not reach: the SVG's
    // size is whole pixels and its viewBox tenths, so the edge columns are partly covered
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    Ok(pixmap)
}

/// `svg` rendered at `scale` and encoded as PNG.
pub fn png(svg: &str, scale: f32) -> Result<Vec<u8>, String> {
    render(svg, scale)?
        .encode_png()
        .map_err(|e| format!("cannot encode the PNG: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Darkest channel sum in a rectangle of `p` (in px of the image).
    fn darkest(p: &tiny_skia::Pixmap, x0: u32, y0: u32, x1: u32, y1: u32) -> u32 {
        let mut min = u32::MAX;
        for y in y0..y1.min(p.height()) {
            for x in x0..x1.min(p.width()) {
                let c = p.pixel(x, y).unwrap();
                min = min.min(u32::from(c.red()) + u32::from(c.green()) + u32::from(c.blue()));
            }
        }
        min
    }

    const DOC: &str = r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="40" viewBox="0 0 200 40" font-family="DejaVu Sans Mono, monospace"><rect width="100%" height="100%" fill="white"/><text x="10" y="25" font-size="14" font-weight="bold">Se: gravity ⇀ ▸</text></svg>"#;

    #[test]
    fn text_is_set_in_the_shipped_faces() {
        let p = render(DOC, 2.0).unwrap();
        assert_eq!((p.width(), p.height()), (400, 80));
        // the label's ink (x 10..~150, baseline 25, cap height ~10 px; ×2) is black
        assert!(darkest(&p, 20, 28, 300, 50) < 100, "no text drawn");
        // above it: white
        assert_eq!(darkest(&p, 0, 0, 400, 10), 3 * 255);
        // the arrows the legend uses have glyphs (mono or the sans fallback): ink at the end
        assert!(darkest(&p, 230, 20, 330, 52) < 200, "no glyph for ⇀ or ▸");
    }

    #[test]
    fn bad_scales_and_huge_images_are_refused() {
        for s in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(render(DOC, s).unwrap_err().contains("--scale"), "{s}");
        }
        let e = render(DOC, 1000.0).unwrap_err();
        assert!(e.contains("16384") && e.contains("smaller --scale"), "{e}");
    }
}

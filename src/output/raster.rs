//! Text metrics and PNG rendering of chart SVGs, with one bundled font (DejaVu Sans, see
//! `assets/fonts/LICENSE`), so that a chart is laid out and rasterised the same on every
//! machine. resvg does the rendering; this module only holds the font and the options.
//!
//! Contract: the SVG documents of `charts.rs` name the font family [`FAMILY`]; the same font
//! measures their texts for the layout and draws them in the PNG.

use resvg::tiny_skia;
use resvg::usvg;
use std::sync::{Arc, OnceLock};

/// The bundled font's family name, as the chart SVGs write it.
pub const FAMILY: &str = "DejaVu Sans";

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The SVG parser's options, with the bundled font as every generic family.
pub fn options() -> &'static usvg::Options<'static> {
    static OPTIONS: OnceLock<usvg::Options<'static>> = OnceLock::new();
    OPTIONS.get_or_init(|| {
        let mut db = usvg::fontdb::Database::new();
        db.load_font_data(FONT.to_vec());
        db.set_sans_serif_family(FAMILY);
        db.set_serif_family(FAMILY);
        db.set_monospace_family(FAMILY);
        usvg::Options {
            fontdb: Arc::new(db),
            font_family: FAMILY.to_string(),
            ..usvg::Options::default()
        }
    })
}

/// Escapes text for an SVG text node or attribute.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The widths in pixels of `texts` set in the bundled font at `size` px (0 for an empty text).
pub fn widths(texts: &[String], size: f64) -> Vec<f64> {
    let mut svg =
        String::from(r#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10">"#);
    for (k, t) in texts.iter().enumerate() {
        svg.push_str(&format!(
            r#"<text id="t{k}" x="0" y="{}" font-family="{FAMILY}" font-size="{size}">{}</text>"#,
            (k + 1) as f64 * size * 2.0,
            escape(t)
        ));
    }
    svg.push_str("</svg>");
    let mut out = vec![0.0; texts.len()];
    if let Ok(tree) = usvg::Tree::from_str(&svg, options()) {
        for node in tree.root().children() {
            if let usvg::Node::Text(t) = node {
                if let Some(k) = t
                    .id()
                    .strip_prefix('t')
                    .and_then(|k| k.parse::<usize>().ok())
                {
                    if let Some(w) = out.get_mut(k) {
                        *w = t.bounding_box().width() as f64;
                    }
                }
            }
        }
    }
    out
}

/// An SVG document rendered to PNG at its own size (white where it draws nothing).
pub fn png(svg: &str) -> Result<Vec<u8>, String> {
    let tree = usvg::Tree::from_str(svg, options()).map_err(|e| format!("bad SVG: {e}"))?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| "the chart has no area".to_string())?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    pixmap
        .encode_png()
        .map_err(|e| format!("cannot encode the PNG: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texts_are_measured_with_the_bundled_font() {
        let w = widths(&["0.001".into(), String::new(), "0.0010.001".into()], 12.0);
        // DejaVu Sans digits advance 0.636 em: "0.001" is about 4.6 em minus side bearings.
        assert!(w[0] > 25.0 && w[0] < 40.0, "{w:?}");
        assert_eq!(w[1], 0.0);
        assert!((w[2] - 2.0 * w[0]).abs() < 6.0, "{w:?}");
    }

    #[test]
    fn svg_renders_to_png() {
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20"><text x="2" y="15" font-size="12">1e-6</text></svg>"#;
        let bytes = png(svg).unwrap_or_default();
        assert!(bytes.starts_with(b"\x89PNG"));
        let image = tiny_skia::Pixmap::decode_png(&bytes).ok();
        let dark = image.map(|p| p.pixels().iter().filter(|c| c.red() < 128).count());
        assert!(dark.unwrap_or(0) > 10, "the text drew no pixels");
    }
}

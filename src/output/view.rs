//! The 3-D view as one self-contained HTML file (`mbd view`, `mbd run --view`): the scene's
//! shapes and the sampled poses as JSON with base64 typed arrays, three.js and the viewer's
//! script embedded (`assets/view/`), so it opens offline.

use crate::runtime::scene::{Frames, Scene};
use base64::Engine;
use serde_json::json;
use std::io::{self, Write};

/// three.js r187 bundled as one script defining `THREE` (`assets/view/build.sh`).
const THREE: &str = include_str!("../../assets/view/three.min.js");
const VIEWER: &str = include_str!("../../assets/view/viewer.js");
const PAGE: &str = include_str!("../../assets/view/viewer.html");

/// A channel's time history for the plot under the scene.
pub struct History {
    pub name: String,
    pub unit: String,
    /// One value per sample.
    pub values: Vec<f64>,
}

/// At most this many samples reach the page: a run is decimated to about the display rate.
pub const MAX_FRAMES: usize = 3000;

/// Every how many written rows a sample is kept for a run of `rows` rows.
pub fn stride(rows: usize) -> usize {
    rows.div_ceil(MAX_FRAMES).max(1)
}

fn b64(v: &[f32]) -> String {
    let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// The page's data: the scene, the poses, the histories.
pub fn data(
    title: &str,
    scene: &Scene,
    frames: &Frames,
    histories: &[History],
) -> serde_json::Value {
    json!({
        "title": title,
        "size": scene.size,
        "up": scene.up,
        "anchors": scene.anchors.len(),
        "loads": scene.loads.len(),
        "torques": scene.loads.iter().map(|l| l.torque).collect::<Vec<_>>(),
        "shapes": scene.shapes,
        "t": frames.t,
        "positions": b64(&frames.positions),
        "rotations": b64(&frames.rotations),
        "load_vectors": b64(&frames.loads),
        "histories": histories.iter().map(|h| json!({
            "name": h.name,
            "unit": h.unit,
            "values": b64(&h.values.iter().map(|&x| x as f32).collect::<Vec<_>>()),
        })).collect::<Vec<_>>(),
    })
}

/// Writes the page.
pub fn write_html(
    out: &mut dyn Write,
    title: &str,
    scene: &Scene,
    frames: &Frames,
    histories: &[History],
) -> io::Result<()> {
    let data = data(title, scene, frames, histories).to_string();
    // The data sits in a JSON script element: `</` must not end it early.
    let data = data.replace("</", "<\\/");
    let escaped = title
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;");
    let page = PAGE
        .replacen("{{TITLE}}", &escaped, 1)
        .replacen("{{DATA}}", &data, 1)
        .replacen("{{THREE}}", THREE, 1)
        .replacen("{{VIEWER}}", VIEWER, 1);
    out.write_all(page.as_bytes())
}

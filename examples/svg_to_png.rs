//! Renders SVG charts to PNG with the bundled font, as `mbd ... -o chart.png` does:
//! `svg_to_png A.svg [B.svg ...]` writes `A.png` beside each (used by `docs/charts/make*.sh`).

fn main() -> std::process::ExitCode {
    let mut failed = false;
    for path in std::env::args().skip(1) {
        let out = std::path::Path::new(&path).with_extension("png");
        let done = std::fs::read_to_string(&path)
            .map_err(|e| e.to_string())
            .and_then(|svg| mbd::output::raster::png(&svg))
            .and_then(|png| std::fs::write(&out, png).map_err(|e| e.to_string()));
        if let Err(e) = done {
            eprintln!("error: {path}: {e}");
            failed = true;
        }
    }
    if failed {
        std::process::ExitCode::FAILURE
    } else {
        std::process::ExitCode::SUCCESS
    }
}

//! Shared by the benchmarks: each is its own crate and includes this file with `mod common;`.

/// The text of `models/{file}`. Panics naming the file if it cannot be read, so that a missing
/// model is never benchmarked as an empty one.
pub fn model_text(file: &str) -> String {
    let path = format!("{}/models/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

//! Shared by the benchmarks: each is its own crate and includes this file with `mod common;`.

/// The text of `models/{file}`. Panics naming the file if it cannot be read, so that a missing
/// model is never benchmarked as an empty one.
#[allow(dead_code)]
pub fn model_text(file: &str) -> String {
    let path = format!("{}/models/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

/// `models/chain.mbd` and the `--set`s that make it `n` links of 0.1 m and 0.1 kg, run for
/// `steps` steps of 1 ms.
#[allow(dead_code)]
pub fn chain(n: usize, steps: usize) -> (String, Vec<String>) {
    (
        model_text("chain.mbd"),
        vec![format!("links={n}"), format!("steps={steps}")],
    )
}

//! Shared by the benchmarks: each is its own crate and includes this file with `mod common;`.

/// The text of `models/{file}`. Panics naming the file if it cannot be read, so that a missing
/// model is never benchmarked as an empty one.
#[allow(dead_code)]
pub fn model_text(file: &str) -> String {
    let path = format!("{}/models/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

/// The chain's text, `n` links of 0.1 m and 0.1 kg.
#[allow(dead_code)]
pub fn chain(n: usize, steps: usize) -> String {
    format!(
        "model chain \"{n} rods on revolute hinges\"
param l = 0.1 m
gravity = (0, -9.81, 0) m/s^2
ground earth
for i in 1..={n} {{
    rigid_rod rod[i] {{ from = ((i - 1) * l, 0, 0), to = (i * l, 0, 0), mass = 0.1 kg }}
}}
joint pin = revolute(earth, rod[1].start) {{ axis = z }}
for i in 1..{n} {{
    joint hinge[i] = revolute(rod[i].end, rod[i + 1].start) {{ axis = z }}
}}
output tip_y = rod[{n}].end.position.y
solve hht(alpha = -0.1) {{ dt = 1 ms, until = {steps} ms }}
"
    )
}

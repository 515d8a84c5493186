//! The windmill's multiblade eigenvalues (THEORY §9.1), computed independently of mbd (the
//! code of tests/mbc.rs): the reference curve of docs/charts/p5_stability.svg.
//! Usage: cargo run --release --example windmill_mbc -- [BLADES] > mbc.csv
//! Writes `Omega_bar,multiblade max Re s` from 0.8 to 2.6 in steps of 0.005.

#[path = "../tests/mbc.rs"]
#[allow(dead_code)]
mod mbc;

fn main() {
    let blades: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(4);
    println!("Omega_bar,multiblade max Re s");
    for k in 0..=360 {
        let w = 0.8 + 0.005 * k as f64;
        println!("{w},{}", mbc::mbc_growth(blades, w));
    }
}

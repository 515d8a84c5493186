//! One integration-test binary (keeps link time down); each module is one concern.

mod architecture;
mod beams;
mod cli;
mod common;
mod diagnostics;
mod docs;
mod emit;
mod fet;
mod friction;
mod grammar;
mod joints;
mod loads;
mod mbc;
mod models;
mod modes;
mod outputs;
mod pendulum;
mod reference;
mod rigid;
mod robustness;
mod rotor;
mod rotor_stability;
mod study;

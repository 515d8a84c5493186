//! One integration-test binary (keeps link time down); each module is one concern.

mod architecture;
mod beam_order;
mod beams;
mod cli;
mod common;
mod diagnostics;
mod docs;
mod fet;
mod friction;
mod grammar;
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
mod shapes;
mod spectral;
mod study;
mod timoshenko;
mod towers;

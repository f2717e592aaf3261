//! kerf: contact forces between a tunnel-boring-machine disc cutter and rock,
//! as an FMI 2.0 FMU (Model Exchange and Co-Simulation in one binary).
//!
//! * [`core`] is the physics: plain safe Rust, no FFI types (`#![forbid(unsafe_code)]`).
//! * `fmi2` is the thin FMI 2.0 layer; it holds every `unsafe` block of the crate.

pub mod core;
pub mod fmi2;
pub mod scenes;

//! The physics core: plain safe Rust, no FFI types.
//!
//! A [`Model`] owns the parameters, the rock height map and the bookkeeping
//! (excavated volume, cutting energy). It answers three questions:
//!
//! * [`Model::evaluate`]: the contact force for a pose, against the rock as
//!   committed (a trial evaluation; never changes anything);
//! * [`Model::commit`]: cut the rock at a pose (Model Exchange event);
//! * [`Model::advance`]: move the cutter for a time step and cut the rock along
//!   the whole path (Co-Simulation step).
#![forbid(unsafe_code)]

pub mod error;
pub mod params;
pub mod pose;

mod model;

pub mod disc;
pub mod face;
pub mod head;
pub mod layout;

pub use disc::{Disc, DiscState};
pub use error::{KerfError, Result};
pub use face::Face;
pub use model::{
    friction_coefficient, friction_force, rim_speed, rim_spin_speed, rim_travel, step_travel,
    Model, ModelState, Outputs, RimReach,
};
pub use params::{CsmVariant, DirectionRule, Params};
pub use pose::{Pose, Twist};
pub mod baseline;
pub mod chip_heightmap;
pub mod contact_bruteforce;
pub mod contact_cutter_heightmap;
pub mod contact_law;
pub mod contact_thesis;
pub mod csm;
pub mod cut_cutter_heightmap;
pub mod cutter;
pub mod heightmap;
pub mod rsf;
mod schedule;

/// Uniform numbers in [0, 1) from `seed` (xorshift64), for tests that
/// sample many cases and must draw the same ones every run.
#[cfg(test)]
pub(crate) fn uniforms(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

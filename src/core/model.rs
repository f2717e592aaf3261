//! PLACEHOLDER: API fixed, physics being written (flat-face closed form only).
use nalgebra::Vector3;

use super::error::{KerfError, Result};
use super::params::Params;
use super::pose::{advance_pose, Pose, Twist};

/// Everything the FMU reports, for one pose.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Outputs {
    /// Force of the rock on the cutter, at the disc centre, rock frame \[N\].
    pub force: [f64; 3],
    /// Moment of the rock on the cutter about the disc centre, rock frame \[N m\].
    pub moment: [f64; 3],
    /// Force along cutter +z \[N\].
    pub normal_force: f64,
    /// Force along cutter -x \[N\].
    pub rolling_force: f64,
    /// Force along cutter +y \[N\].
    pub side_force: f64,
    /// Depth of the contact zone (thesis eq. 54) \[m\].
    pub penetration: f64,
    /// Angle `phi` of the contact arc \[rad\].
    pub contact_angle: f64,
    pub in_contact: bool,
    /// Committed rock removed so far \[m3\].
    pub excavated_volume: f64,
    /// Work of the cutter on the rock so far \[J\].
    pub cutting_energy: f64,
    /// `cutting_energy / excavated_volume`, 0 while nothing was removed \[J/m3\].
    pub specific_energy: f64,
}

/// The discrete state: what `fmi2GetFMUstate` captures.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelState {
    excavated_volume: f64,
    cutting_energy: f64,
}

impl ModelState {
    /// Versioned binary form (for `fmi2SerializeFMUstate`).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut v = b"KERFST01".to_vec();
        v.extend_from_slice(&self.excavated_volume.to_le_bytes());
        v.extend_from_slice(&self.cutting_energy.to_le_bytes());
        v
    }

    /// Inverse of [`ModelState::to_bytes`]; rejects corrupt or foreign blobs
    /// and blobs made for another height-map grid.
    pub fn from_bytes(bytes: &[u8], _params: &Params) -> Result<Self> {
        if bytes.len() != 24 || &bytes[..8] != b"KERFST01" {
            return Err(KerfError::BadState("not a kerf state blob".into()));
        }
        let f = |i: usize| f64::from_le_bytes(bytes[i..i + 8].try_into().unwrap());
        Ok(Self {
            excavated_volume: f(8),
            cutting_energy: f(16),
        })
    }
}

pub struct Model {
    params: Params,
    state: ModelState,
}

impl Model {
    /// Validates the parameters and builds the rock (flat, or from
    /// `rock.initial_surface`).
    pub fn new(params: Params) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            state: ModelState {
                excavated_volume: 0.0,
                cutting_energy: 0.0,
            },
        })
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Warnings about the parameters that are legal but questionable (for the
    /// FMI logger), e.g. an Ozdemir regression used outside its Table 1 range.
    pub fn warnings(&self) -> Vec<String> {
        Vec::new()
    }

    /// Contact force for `pose`, against the committed rock. Never changes the rock.
    pub fn evaluate(&self, pose: &Pose, twist: &Twist) -> Result<Outputs> {
        pose.validate()?;
        twist.validate()?;
        let p = (self.params.rock.z0 - (pose.position.z - self.params.cutter.radius)).max(0.0);
        let mut o = Outputs {
            penetration: p,
            in_contact: p > 0.0,
            ..Default::default()
        };
        o.excavated_volume = self.state.excavated_volume;
        o.cutting_energy = self.state.cutting_energy;
        let _ = Vector3::<f64>::zeros();
        Ok(o)
    }

    /// Would [`Model::commit`] at `pose` change the rock?
    pub fn cuts(&self, pose: &Pose) -> Result<bool> {
        pose.validate()?;
        Ok(false)
    }

    /// Cuts the rock at `pose` (a Model Exchange event). `dt` is the time since
    /// the previous commit, for the energy bookkeeping. Returns whether the rock changed.
    pub fn commit(&mut self, pose: &Pose, twist: &Twist, dt: f64) -> Result<bool> {
        pose.validate()?;
        twist.validate()?;
        let _ = dt;
        Ok(false)
    }

    /// Moves the cutter from `start` along `twist` for `h` seconds, cutting the
    /// rock along the whole path (a Co-Simulation step). Returns the end pose.
    pub fn advance(&mut self, start: &Pose, twist: &Twist, h: f64) -> Result<Pose> {
        start.validate()?;
        twist.validate()?;
        if !(h.is_finite() && h >= 0.0) {
            return Err(KerfError::BadInput {
                name: "communicationStepSize",
                value: h,
            });
        }
        Ok(advance_pose(start, twist, h))
    }

    /// A copy of the discrete state.
    pub fn state(&self) -> ModelState {
        self.state.clone()
    }

    /// Restores a state taken from a model with the same parameters.
    pub fn set_state(&mut self, s: &ModelState) -> Result<()> {
        self.state = s.clone();
        Ok(())
    }

    /// Writes the committed surface as an `.rsf` file.
    pub fn write_surface(&self, path: &std::path::Path) -> Result<()> {
        let _ = path;
        Ok(())
    }
}

//! Cutter pose and velocities, and the frame convention of interface.md.
//!
//! Rock frame: fixed, z up out of the rock. Cutter frame: origin at the disc
//! centre, x rolling direction, y axle, z from the lowest rim point to the
//! centre. Orientation: intrinsic 3-2-1 (yaw, pitch, roll); the rotation that
//! maps cutter-frame vectors into the rock frame is
//! `Rz(yaw) * Ry(pitch) * Rx(roll)` with right-handed active matrices.

use nalgebra::{Rotation3, Vector3};

use super::error::{KerfError, Result};

/// Position and orientation of the cutter frame in the rock frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Disc centre \[m\], rock frame.
    pub position: Vector3<f64>,
    pub yaw: f64,
    pub pitch: f64,
    pub roll: f64,
}

/// Velocities of the disc, rock frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Twist {
    /// Velocity of the disc centre \[m/s\].
    pub velocity: Vector3<f64>,
    /// Angular velocity of the disc (spin about the axle included) \[rad/s\].
    pub omega: Vector3<f64>,
}

impl Default for Twist {
    fn default() -> Self {
        Self {
            velocity: Vector3::zeros(),
            omega: Vector3::zeros(),
        }
    }
}

/// Positions farther than this from the origin \[m\] are rejected as absurd.
pub const MAX_POSITION: f64 = 1.0e6;
/// Speeds above this \[m/s\] or spins above this \[rad/s\] are rejected.
pub const MAX_SPEED: f64 = 1.0e4;

/// `v` finite and within `bound` of zero; the error says so ("at most
/// 1e4 m/s", `what` the unit and what is measured).
fn check(name: &'static str, v: f64, bound: f64, what: &'static str) -> Result<()> {
    if v.is_finite() && v.abs() <= bound {
        Ok(())
    } else {
        Err(KerfError::BadInput {
            name,
            value: v,
            allowed: format!("at most {bound:e} {what}").into(),
        })
    }
}

const POSITION: &str = "m from the origin";
const ANGLE: &str = "rad";
const SPEED: &str = "m/s or rad/s";

/// Angles beyond this \[rad\] are rejected.
const MAX_ANGLE: f64 = 1.0e3;

impl Pose {
    pub fn new(x: f64, y: f64, z: f64, yaw: f64, pitch: f64, roll: f64) -> Self {
        Self {
            position: Vector3::new(x, y, z),
            yaw,
            pitch,
            roll,
        }
    }

    /// The pose's six numbers in the order of [`Pose::new`] and of the pose
    /// inputs: position, then yaw, pitch, roll.
    pub fn to_array(&self) -> [f64; 6] {
        [
            self.position.x,
            self.position.y,
            self.position.z,
            self.yaw,
            self.pitch,
            self.roll,
        ]
    }

    /// Rotation mapping cutter-frame vectors into the rock frame.
    /// nalgebra's `from_euler_angles(roll, pitch, yaw)` is exactly
    /// `Rz(yaw) * Ry(pitch) * Rx(roll)` (tested in `tests`).
    pub fn rotation(&self) -> Rotation3<f64> {
        Rotation3::from_euler_angles(self.roll, self.pitch, self.yaw)
    }

    /// The cutter frame of a disc at this pose, as the contract defines it
    /// (interface.md): `y` the axle, `z` from the rim's lowest point to the
    /// centre, `x` the rolling direction, horizontal. That is
    /// [`Pose::rotation`] turned about its own axle until its `x` is
    /// horizontal and its `z` points up: a disc is a body of revolution, so
    /// a host that gives the pose the angle the disc has spun to (a
    /// revolute joint's pitch) poses the same disc, and the law's rolling
    /// direction, its outputs' normal and rolling forces and the contact's
    /// angles follow the disc, not the spin. The same matrix, bit for bit,
    /// when `x` is already horizontal and `z` up (pitch 0 and |roll| < 90
    /// deg, as every disc of a head whose axis is vertical). A vertical
    /// axle (a disc lying flat) keeps the pose's own frame.
    pub fn cutter_rotation(&self) -> Rotation3<f64> {
        let r = self.rotation();
        let (a, b) = (r[(2, 0)], r[(2, 2)]);
        if a == 0.0 && b >= 0.0 {
            return r;
        }
        r * Rotation3::from_axis_angle(&Vector3::y_axis(), a.atan2(b))
    }

    /// Builds a pose from a rotation, inverse of [`Pose::rotation`].
    pub fn from_rotation(position: Vector3<f64>, r: &Rotation3<f64>) -> Self {
        let (roll, pitch, yaw) = r.euler_angles();
        Self {
            position,
            yaw,
            pitch,
            roll,
        }
    }

    /// Rejects non-finite or absurd values (angles beyond 1e3 rad included).
    pub fn validate(&self) -> Result<()> {
        check("x", self.position.x, MAX_POSITION, POSITION)?;
        check("y", self.position.y, MAX_POSITION, POSITION)?;
        check("z", self.position.z, MAX_POSITION, POSITION)?;
        check("yaw", self.yaw, MAX_ANGLE, ANGLE)?;
        check("pitch", self.pitch, MAX_ANGLE, ANGLE)?;
        check("roll", self.roll, MAX_ANGLE, ANGLE)
    }
}

impl Twist {
    /// The angular velocity of the cutter frame (the fork's) for a disc
    /// whose axle points along `axle` (unit): the twist's less its spin
    /// about the axle, which moves no point of the disc's surface.
    pub fn frame_rate(&self, axle: &Vector3<f64>) -> Vector3<f64> {
        self.omega - axle * self.omega.dot(axle)
    }

    pub fn new(v: [f64; 3], w: [f64; 3]) -> Self {
        Self {
            velocity: Vector3::from(v),
            omega: Vector3::from(w),
        }
    }

    /// A cutterhead boring: turning at `w` \[rad/s\] about +z and
    /// advancing `p_rev` per revolution along -z (the contract's boring
    /// direction: `z` decreasing, `wz > 0`).
    pub fn boring(w: f64, p_rev: f64) -> Self {
        Self::new(
            [0.0, 0.0, -p_rev * w / std::f64::consts::TAU],
            [0.0, 0.0, w],
        )
    }

    pub fn validate(&self) -> Result<()> {
        check("vx", self.velocity.x, MAX_SPEED, SPEED)?;
        check("vy", self.velocity.y, MAX_SPEED, SPEED)?;
        check("vz", self.velocity.z, MAX_SPEED, SPEED)?;
        check("wx", self.omega.x, MAX_SPEED, SPEED)?;
        check("wy", self.omega.y, MAX_SPEED, SPEED)?;
        check("wz", self.omega.z, MAX_SPEED, SPEED)
    }
}

/// Moves a pose along a twist for a time `h`: the centre with the velocity,
/// the cutter frame with the angular velocity less its spin about the axle
/// (the frame is the fork's; it does not spin with the disc).
pub fn advance_pose(pose: &Pose, twist: &Twist, h: f64) -> Pose {
    let r = pose.rotation();
    let dr = Rotation3::from_scaled_axis(twist.frame_rate(&(r * Vector3::y())) * h);
    Pose::from_rotation(pose.position + twist.velocity * h, &(dr * r))
}

//! A thesis-faithful baseline, for benchmarks and the speed-vs-error report
//! only (`docs/speed-vs-error.md`); it is not the FMU's default path.
//!
//! It does what the thesis's Fortran GFOSUB did, on the same height map and
//! CSM law as [`Model`](super::Model), so the two can be compared on equal
//! inputs:
//!
//! * **Contact (ch. 6.3, 7.3-7.5).** A fixed grid of rim points: `alpha` from 0
//!   to `pi` (the lower half of the rim only, eqs 39-40) times the axle
//!   coordinate from `-T/2` to `T/2`, `n_alpha x n_y` points, every one
//!   transformed to the rock frame and compared with the rock height. The
//!   penetration is the spread of the local z of the penetrated points
//!   (eq. 54), `phi = acos((R - p)/R)`, the magnitude `F_t(p)` from the same
//!   [`CsmLaw`]. The direction is the mean of the normals of the distinct
//!   rock triangles under the penetrated points (eqs 41-42), applied where
//!   the ray to the centre of the penetrated plane meets the rim (eqs 43-53,
//!   ray normalised), with the STEP friction of eqs 55-60 read there.
//! * **Deformation (ch. 8, eqs 67-72).** At every step, every node of the
//!   whole face is visited: its coordinates are formed (eqs 67-70) and moved
//!   into the cutter frame; a node inside the disc (eq. 71's comparison) is
//!   moved down onto the disc's lower boundary on its vertical (eq. 72, fully
//!   plastic; for an upright disc that is eq. 71's rim point). The cut
//!   is written into a temporary matrix that becomes the rock once the step
//!   is done (ch. 8.2.1).
//! * **Co-Simulation step.** The rock changes only at the sampled poses (the
//!   end of each step), as in the thesis.
//!
//! The cost of a step therefore grows with the face (nodes) and with
//! `n_alpha * n_y`, whatever the contact. Two things are kinder to the
//! baseline than the Fortran was: the height map is kerf's tiled one, so the
//! temporary copy holds only the tiles cut so far instead of the whole dense
//! matrix.

use std::collections::HashSet;

use nalgebra::Vector3;

use super::csm::{contact_angle, CsmLaw};
use super::cutter::PosedDisc;
use super::error::{KerfError, Result};
use super::heightmap::{Grid, HeightMap};
use super::model::{check_interval, check_step};
use super::params::Params;
use super::pose::{advance_pose, Pose, Twist};
use super::{friction_force, Outputs};

/// Resolution of the rim-point grid of the thesis's contact loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BaselineResolution {
    /// Points along `alpha` in `[0, pi]` (at least 2).
    pub n_alpha: usize,
    /// Points along the axle in `[-T/2, T/2]` (at least 2).
    pub n_y: usize,
}

impl Default for BaselineResolution {
    /// 0.5 degree along the rim (1.9 mm of rim at R = 0.2159 m), 9 points
    /// across the tip.
    fn default() -> Self {
        Self {
            n_alpha: 361,
            n_y: 9,
        }
    }
}

/// The thesis's contact of one pose.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BaselineContact {
    pub in_contact: bool,
    /// Eq. 54 \[m\].
    pub penetration: f64,
    pub phi: f64,
    /// Cutting force on the cutter (mean triangle normal times `F_t`), rock frame \[N\].
    pub rim_force: Vector3<f64>,
    /// Mean normal of the penetrated triangles.
    pub normal: Vector3<f64>,
    /// Point of force application `f_p`, offset from the disc centre \[m\].
    pub application: Vector3<f64>,
    /// Penetrated rim points and distinct triangles under them.
    pub points: usize,
    pub triangles: usize,
}

/// The thesis's model: the [`Model`](super::Model) interface, the Fortran's algorithms.
#[derive(Debug, Clone)]
pub struct BaselineModel {
    params: Params,
    law: CsmLaw,
    res: BaselineResolution,
    map: HeightMap,
    excavated_volume: f64,
    cutting_energy: f64,
}

impl BaselineModel {
    /// A flat face from `params.rock` (an initial surface file is not read:
    /// the baseline is for the flat reference scene).
    pub fn new(params: Params, res: BaselineResolution) -> Result<Self> {
        params.validate()?;
        if res.n_alpha < 2 || res.n_y < 2 {
            return Err(KerfError::BadParameter {
                name: "baseline resolution",
                value: res.n_alpha.min(res.n_y) as f64,
                why: "n_alpha and n_y need at least 2 points".into(),
            });
        }
        let r = &params.rock;
        let grid = Grid::new(r.x_min, r.x_max, r.y_min, r.y_max, r.nx, r.ny);
        let map = HeightMap::flat(grid, r.z0);
        let law = CsmLaw::new(params.cutter, params.csm, params.numerics.p_reg);
        Ok(Self {
            params,
            law,
            res,
            map,
            excavated_volume: 0.0,
            cutting_energy: 0.0,
        })
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    pub fn resolution(&self) -> BaselineResolution {
        self.res
    }

    /// The committed rock.
    pub fn map(&self) -> &HeightMap {
        &self.map
    }

    fn disc(&self, pose: &Pose) -> PosedDisc {
        PosedDisc::new(&self.params.cutter, pose)
    }

    /// The thesis's rim loop (ch. 7.3-7.5) at `pose`.
    pub fn contact(&self, pose: &Pose) -> BaselineContact {
        let disc = self.disc(pose);
        let map = &self.map;
        let (na, ny) = (self.res.n_alpha, self.res.n_y);
        let b = disc.half_width;
        let mut seen: HashSet<u64> = HashSet::new();
        let mut sum = Vector3::zeros();
        let mut first: Option<Vector3<f64>> = None;
        let mut last = Vector3::zeros();
        let (mut zl_min, mut zl_max) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut points = 0usize;
        for iy in 0..ny {
            let y = -b + 2.0 * b * iy as f64 / (ny - 1) as f64;
            let rho = disc.rho(y);
            for ia in 0..na {
                let alpha = std::f64::consts::PI * ia as f64 / (na - 1) as f64;
                // eqs 39-40: x = R(y) cos(alpha), z = -R(y) sin(alpha)
                let local = Vector3::new(rho * alpha.cos(), y, -rho * alpha.sin());
                let p = disc.to_world(&local);
                if map.height(p.x, p.y) > p.z {
                    points += 1;
                    zl_min = zl_min.min(local.z);
                    zl_max = zl_max.max(local.z);
                    if let Some((id, n)) = map.triangle(p.x, p.y) {
                        if seen.insert(id) {
                            sum += Vector3::from(n);
                        }
                    }
                    first.get_or_insert(p);
                    last = p;
                }
            }
        }
        let (Some(first), true) = (first, sum.norm() > 0.0) else {
            return BaselineContact::default();
        };
        let normal = sum / sum.norm();
        let p = zl_max - zl_min;
        let phi = contact_angle(disc.radius, p.min(2.0 * disc.radius));
        // eqs 43-53: the ray from the centre to the penetrated plane's
        // centre meets the rim torus (radii R - r and r) at f_p
        let pc = 0.5 * (first + last);
        let dp = (pc - disc.centre)
            .try_normalize(1e-300)
            .unwrap_or(-Vector3::z());
        let dl = disc.rot.transpose() * dp;
        let (big, r) = (disc.radius - disc.tip_radius, disc.tip_radius);
        let sin_t = dl.y.abs().min(1.0);
        let cos_t = (1.0 - sin_t * sin_t).sqrt();
        let lf = big * cos_t + (r * r - big * big * sin_t * sin_t).max(0.0).sqrt();
        BaselineContact {
            in_contact: true,
            penetration: p,
            phi,
            rim_force: normal * self.law.force(p),
            normal,
            application: dp * lf,
            points,
            triangles: seen.len(),
        }
    }

    /// Contact force for `pose` against the committed rock (eqs 55-66).
    pub fn evaluate(&self, pose: &Pose, twist: &Twist) -> Result<Outputs> {
        pose.validate()?;
        twist.validate()?;
        let c = self.contact(pose);
        let rot = pose.cutter_rotation();
        let f = &self.params.friction;
        let friction = if c.in_contact {
            let slip_v = twist.velocity + twist.omega.cross(&c.application);
            friction_force(c.rim_force.norm(), slip_v, c.normal, f.mu, f.vs)
        } else {
            Vector3::zeros()
        };
        let force = c.rim_force + friction;
        let moment = c.application.cross(&force);
        let mut o = Outputs::from_force(force, moment, &rot, c.penetration, c.phi, c.in_contact);
        o.excavated_volume = self.excavated_volume;
        o.cutting_energy = self.cutting_energy;
        o.specific_energy = if self.excavated_volume > 0.0 {
            self.cutting_energy / self.excavated_volume
        } else {
            0.0
        };
        Ok(o)
    }

    /// Subroutine DEFORM (ch. 8): visits every node of the face, cuts those
    /// in the disc's shadow down to its lower boundary in a temporary matrix,
    /// and makes that the rock (the step is always accepted here). Returns
    /// the nodes lowered.
    fn deform(&mut self, pose: &Pose) -> usize {
        let disc = self.disc(pose);
        let mut temp = self.map.clone();
        let g = *self.map.grid();
        let rt = disc.rot.transpose();
        let b = disc.half_width;
        let big_r = disc.radius;
        let mut lowered = 0usize;
        let mut volume = 0.0;
        for j in 0..g.ny {
            for i in 0..g.nx {
                // eqs 67-70
                let (x, y) = g.node_xy(i, j);
                let z = self.map.node(i, j);
                let v = Vector3::new(x - disc.centre.x, y - disc.centre.y, z - disc.centre.z);
                // into the cutter frame (eq. 70 rotated); ch. 8.1: the node
                // can be cut only if it lies inside the disc (|y| <= T/2 and
                // within the rim radius R(y) of the axle)
                let xl = rt[(0, 0)] * v.x + rt[(0, 1)] * v.y + rt[(0, 2)] * v.z;
                let yl = rt[(1, 0)] * v.x + rt[(1, 1)] * v.y + rt[(1, 2)] * v.z;
                let zl = rt[(2, 0)] * v.x + rt[(2, 1)] * v.y + rt[(2, 2)] * v.z;
                if !(yl.abs() <= b && xl.abs() < big_r) {
                    continue;
                }
                let rho = disc.rho(yl);
                if xl * xl + zl * zl >= rho * rho {
                    continue;
                }
                // eqs 71-72: the node goes down onto the disc (fully plastic)
                if let Some((zb, _)) = disc.lower_boundary(x, y) {
                    if z > zb {
                        temp.set_node(i, j, zb);
                        volume += (z - zb) * g.cell_area();
                        lowered += 1;
                    }
                }
            }
        }
        // ch. 8.2.1: the temporary matrix becomes the rock after the step
        self.map = temp;
        self.excavated_volume += volume;
        lowered
    }

    /// Cuts the rock at `pose` (a Model Exchange event); `dt` is the time
    /// since the previous commit, for the energy bookkeeping.
    pub fn commit(&mut self, pose: &Pose, twist: &Twist, dt: f64) -> Result<bool> {
        check_interval(dt)?;
        let o = self.evaluate(pose, twist)?;
        self.cutting_energy += o.work_on_rock(twist, dt);
        Ok(self.deform(pose) > 0)
    }

    /// A Co-Simulation step as the thesis's solver made it: the cutter moves
    /// to the end of the step and the rock is cut there only.
    pub fn advance(&mut self, start: &Pose, twist: &Twist, h: f64) -> Result<Pose> {
        check_step(h)?;
        let o0 = self.evaluate(start, twist)?;
        let end = advance_pose(start, twist, h);
        end.validate()?;
        self.deform(&end);
        let o1 = self.evaluate(&end, twist)?;
        self.cutting_energy += 0.5 * (o0.work_on_rock(twist, h) + o1.work_on_rock(twist, h));
        Ok(end)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: f64 = 0.2159;

    fn small_params() -> Params {
        let mut p = Params::default();
        let r = &mut p.rock;
        (r.x_min, r.x_max, r.y_min, r.y_max) = (-0.25, 0.35, -0.03, 0.03);
        (r.nx, r.ny) = (601, 61);
        p
    }

    #[test]
    fn steady_cut_is_near_csm_and_removes_the_groove() {
        let p = 3.8e-3;
        let mut m = BaselineModel::new(
            small_params(),
            BaselineResolution {
                n_alpha: 1801,
                n_y: 9,
            },
        )
        .unwrap();
        let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
        let mut pose = Pose::new(0.0, 0.0, R - p, 0.0, 0.0, 0.0);
        let (mut fz, mut k) = (0.0, 0.0);
        for _ in 0..100 {
            pose = m.advance(&pose, &tw, 1e-3).unwrap();
            let o = m.evaluate(&pose, &tw).unwrap();
            if pose.position.x > 0.05 {
                fz += o.normal_force;
                k += 1.0;
            }
            assert!(o.in_contact);
        }
        let phi = ((R - p) / R).acos();
        let pp = 2.12 * ((158e6f64).powi(2) * 6.78e6 * 0.051 / (R * 0.013).sqrt()).cbrt();
        let fnn = 0.013 * R * phi * pp * (phi / 2.0).cos();
        // the fixed rim grid and the triangle normals: a few per cent
        assert!(((fz / k) - fnn).abs() < 0.05 * fnn, "{} vs {fnn}", fz / k);
        // the groove bottom is at the rim
        let g = *m.map().grid();
        let i = ((0.05 - g.x_min) / g.dx).round() as usize;
        let j = ((0.0 - g.y_min) / g.dy).round() as usize;
        assert!(
            (m.map().node(i, j) + p).abs() < 1e-5,
            "{}",
            m.map().node(i, j)
        );
    }

    #[test]
    fn whole_face_deform_cuts_every_node_the_disc_reaches_for_a_tilted_disc() {
        // the thesis's shadow test (node inside the disc) must not miss a node
        // whose vertical meets the disc below the face: after one commit every
        // node is min(z0, lower boundary), checked by brute force
        let params = small_params();
        for roll in [0.0f64, 30.0, 60.0] {
            // lowest point of the posed disc 4 mm into the face at (0.1, 0)
            let probe = Pose::new(0.1, 0.0, 1.0, 0.0, 0.0, roll.to_radians());
            let d = PosedDisc::new(&params.cutter, &probe);
            let low = (0..=400)
                .filter_map(|k| {
                    let y = -d.half_width + 2.0 * d.half_width * k as f64 / 400.0;
                    let (t0, _) = d.arc_below(y, d.rho(y), 10.0)?;
                    Some(d.to_world(&d.rim_point_local(t0, y)))
                })
                .min_by(|a, b| a.z.total_cmp(&b.z))
                .unwrap();
            let pose = Pose::new(
                0.1,
                -low.y,
                1.0 - low.z - 0.004,
                0.0,
                0.0,
                roll.to_radians(),
            );
            let mut b = BaselineModel::new(params.clone(), BaselineResolution::default()).unwrap();
            b.commit(&pose, &Twist::default(), 0.0).unwrap();
            let disc = PosedDisc::new(&params.cutter, &pose);
            let g = *b.map().grid();
            let mut cut = 0;
            for j in 0..g.ny {
                for i in 0..g.nx {
                    let (x, y) = g.node_xy(i, j);
                    let want = disc.lower_boundary(x, y).map_or(0.0, |(z, _)| z.min(0.0));
                    let got = b.map().node(i, j);
                    if got < 0.0 {
                        cut += 1;
                    }
                    assert!(
                        (got - want).abs() < 1e-12,
                        "roll {roll}: node ({i},{j}) {got} vs {want}"
                    );
                }
            }
            assert!(cut > 50, "roll {roll}: only {cut} nodes cut");
        }
    }
}

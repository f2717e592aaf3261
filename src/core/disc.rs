//! One disc cutter: its geometry and force law, its contact cache, and the
//! part of the discrete state that is its own (where it last cut, where its
//! chips are along its path). The rock it cuts is a [`Face`], shared with
//! every other disc of a head.
//!
//! The operations that move discs and cut the face ([`commit_paths`],
//! [`sweep`]) take any number of discs: the single-disc [`super::Model`]
//! and the cutterhead [`super::head::Head`] both run through them. Discs are
//! evaluated in parallel (they only read the face) and cut in their fixed
//! order, so the results do not depend on the number of threads.

use std::cell::Cell;

use nalgebra::{UnitQuaternion, Vector3};
use rayon::prelude::*;

use super::chip_heightmap::ChipState;
use super::contact_cutter_heightmap::{contact, Contact};
use super::contact_thesis::contact_thesis;
use super::csm::CsmLaw;
use super::cut_cutter_heightmap::{cut, would_cut};
use super::cutter::PosedDisc;
use super::error::Result;
use super::face::Face;
use super::heightmap::HeightMap;
use super::model::{check_interval, friction_force, steps_for, Outputs};
use super::params::{CsmParams, CutterParams, DirectionRule, Params};
use super::pose::{Pose, Twist};

/// A disc: geometry, CSM law (with its own spacing) and the last evaluation.
#[derive(Debug)]
pub struct Disc {
    cutter: CutterParams,
    law: CsmLaw,
    /// The last evaluation (pose, twist, outputs without bookkeeping);
    /// cleared whenever the face changes.
    cache: Cell<Option<(Pose, Twist, Outputs)>>,
}

impl Clone for Disc {
    fn clone(&self) -> Self {
        Self {
            cutter: self.cutter,
            law: self.law,
            cache: Cell::new(None),
        }
    }
}

/// The discrete state of one disc.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscState {
    /// Where the disc last cut (end of the last commit or sweep): the next
    /// Model Exchange commit cuts along the path from here.
    pub(crate) last_cut: Option<Pose>,
    /// Where the chips are along the disc's path (chipping on).
    pub(crate) chips: ChipState,
}

impl DiscState {
    /// The state before the first cut.
    pub fn new(params: &Params) -> Self {
        Self {
            last_cut: None,
            chips: ChipState::new(&params.chipping),
        }
    }

    pub fn last_cut(&self) -> Option<Pose> {
        self.last_cut
    }

    pub fn chips(&self) -> &ChipState {
        &self.chips
    }
}

impl Disc {
    /// A disc of geometry `cutter` under the CSM law `csm` (its spacing is
    /// this disc's), its pressure times `pressure_scale`
    /// (`ChipParams::pressure_scale_in_use`: 1 without chips). `p_reg`
    /// regularises the law at zero penetration.
    pub fn new(cutter: CutterParams, csm: CsmParams, p_reg: f64, pressure_scale: f64) -> Self {
        Self {
            cutter,
            law: CsmLaw::scaled(cutter, csm, p_reg, pressure_scale),
            cache: Cell::new(None),
        }
    }

    pub fn cutter(&self) -> &CutterParams {
        &self.cutter
    }

    pub fn law(&self) -> &CsmLaw {
        &self.law
    }

    /// The disc at `pose`, ready for geometric queries.
    pub fn posed(&self, pose: &Pose) -> PosedDisc {
        PosedDisc::new(&self.cutter, pose)
    }

    /// The contact geometry and cutting force (no friction) at `pose`.
    pub fn contact(&self, map: &HeightMap, pose: &Pose, twist: &Twist, params: &Params) -> Contact {
        let disc = self.posed(pose);
        let n = &params.numerics;
        match n.direction {
            DirectionRule::Kerf => contact(map, &disc, &self.law, n, n.elastic_depth, twist),
            DirectionRule::Thesis => contact_thesis(map, &disc, &self.law, n, twist),
        }
    }

    /// Force and moment on the disc at `pose` moving with `twist`, against
    /// `map` (no bookkeeping, no cache).
    pub fn compute(&self, map: &HeightMap, pose: &Pose, twist: &Twist, params: &Params) -> Outputs {
        let c = self.contact(map, pose, twist, params);
        let rot = pose.rotation();
        // friction on the slip of the rim over the rock where the contact is
        // lowest (kerf) or at the point of force application (thesis eq. 56)
        let slip_v = twist.velocity + twist.omega.cross(&c.slip_point);
        let f = &params.friction;
        let friction = if c.in_contact {
            friction_force(c.rim_force.norm(), slip_v, c.slip_normal, f.mu, f.vs)
        } else {
            Vector3::zeros()
        };
        let force = c.rim_force + c.side_force + friction;
        let moment = c.rim_moment + c.slip_point.cross(&friction) + c.side_moment;
        Outputs::from_force(force, moment, &rot, c.penetration, c.phi, c.in_contact)
    }

    /// [`Disc::compute`] through the cache of the last evaluation. The
    /// caller must [`Disc::forget`] whenever the face changes.
    pub fn evaluate(
        &self,
        map: &HeightMap,
        pose: &Pose,
        twist: &Twist,
        params: &Params,
    ) -> Outputs {
        if let Some((p, t, o)) = self.cache.get() {
            if p == *pose && t == *twist {
                return o;
            }
        }
        let o = self.compute(map, pose, twist, params);
        self.cache.set(Some((*pose, *twist, o)));
        o
    }

    /// Drops the cached evaluation (the face changed).
    pub fn forget(&self) {
        self.cache.set(None);
    }

    /// Would a cut at `pose` change the face?
    pub fn would_cut(&self, map: &HeightMap, pose: &Pose, params: &Params) -> bool {
        would_cut(map, &self.posed(pose), params.numerics.elastic_depth)
    }

    /// Cuts the face at `pose` and breaks out the chips the disc reached;
    /// returns whether the face changed. Forgets this disc's cache if it
    /// did; the caller forgets the other discs'.
    pub fn cut_at(
        &self,
        face: &mut Face,
        state: &mut DiscState,
        pose: &Pose,
        twist: &Twist,
        params: &Params,
    ) -> bool {
        let disc = self.posed(pose);
        let stats = cut(
            &mut face.map,
            &disc,
            params.numerics.elastic_depth,
            params.rock.plastic_fraction,
        );
        face.excavated_volume += stats.volume;
        let chips = chip_at(face, state, &disc, twist, stats.nodes > 0, params);
        if stats.nodes > 0 || chips {
            self.forget();
        }
        stats.nodes > 0 || chips
    }
}

/// Longest move in plan between two poses of one path: a path is cut in
/// sub-steps of at most `sweep_step` of rim travel; anything longer is a
/// jump to a new pass.
pub(crate) fn chip_max_step(map: &HeightMap, params: &Params) -> f64 {
    let g = map.grid();
    2.0 * params.numerics.sweep_step + g.dx.max(g.dy)
}

/// Curvature in plan (1/m, positive turning left) of the path of the
/// disc's lowest point `low` for `disc` moving with `twist`. The
/// disc's angular velocity is read as a turn `a` about the vertical plus a
/// spin about the axle (exact for a head turning about its axis, 0 for a disc
/// rolling straight); the lowest point then moves with `v + a z x (low - c)`
/// and its heading turns at `a`.
fn path_curvature(disc: &PosedDisc, twist: &Twist, low: &Vector3<f64>) -> f64 {
    let axle = disc.rot.column(1).into_owned();
    let c = axle.z;
    if 1.0 - c * c < 1e-9 {
        return 0.0;
    }
    let w = &twist.omega;
    let a = (w.z - c * w.dot(&axle)) / (1.0 - c * c);
    let arm = low - disc.centre;
    let v = twist.velocity + Vector3::z().cross(&arm) * a;
    let speed = v.x.hypot(v.y);
    if speed < 1e-12 {
        return 0.0;
    }
    a / speed
}

/// With chipping on, records the pose `disc` on the path (`cut`: the disc
/// removed rock there) and breaks out the chips it has reached, following
/// the path's curvature; returns whether any did.
fn chip_at(
    face: &mut Face,
    state: &mut DiscState,
    disc: &PosedDisc,
    twist: &Twist,
    cut: bool,
    params: &Params,
) -> bool {
    let p = &params.chipping;
    if !p.enabled {
        return false;
    }
    let max_step = chip_max_step(&face.map, params);
    let low = disc.lowest_point();
    let curvature = path_curvature(disc, twist, &low);
    let s = state.chips.after_cut_curved(
        &mut face.map,
        p,
        low,
        cut,
        disc.half_width,
        max_step,
        curvature,
    );
    face.excavated_volume += s.volume;
    s.count > 0
}

/// Evaluates every disc at its motion against `map` (through each disc's
/// cache). Discs only read the face, so they run in parallel on rayon's
/// current pool; each result depends on its disc alone, so the outputs are
/// the same for any number of threads.
pub fn evaluate_all(
    discs: &mut [Disc],
    map: &HeightMap,
    motions: &[(Pose, Twist)],
    params: &Params,
) -> Vec<Outputs> {
    if discs.len() == 1 {
        return vec![discs[0].evaluate(map, &motions[0].0, &motions[0].1, params)];
    }
    discs
        .par_iter_mut()
        .zip(motions.par_iter())
        .map(|(d, (p, t))| d.evaluate(map, p, t, params))
        .collect()
}

/// A straight path from a disc's last cut: its pose and both orientations.
type Path = (Pose, UnitQuaternion<f64>, UnitQuaternion<f64>);

/// Cuts the face at the motions' poses (a Model Exchange event): `dt` is the
/// time since the previous commit, for the energy bookkeeping. Each disc's
/// cut follows the path from its previous cut, straight (positions linear,
/// orientation by slerp), in sub-steps of at most `numerics.sweep_step` of
/// rim travel, when the move is one a step can make: shorter than the disc
/// radius, or explained by the velocity inputs. A longer jump (a host that
/// moves the disc to start a new pass) is not a path: only the new pose is
/// cut. All discs advance sub-step by sub-step, cutting in their order.
/// Returns whether the face changed. The motions must have been validated.
pub fn commit_paths(
    face: &mut Face,
    discs: &mut [Disc],
    states: &mut [DiscState],
    motions: &[(Pose, Twist)],
    dt: f64,
    params: &Params,
) -> Result<bool> {
    check_interval(dt)?;
    let outputs = evaluate_all(discs, &face.map, motions, params);
    for (o, (_, twist)) in outputs.iter().zip(motions) {
        face.cutting_energy += o.work_on_rock(twist, dt);
    }
    // per disc: the path from its last cut, if it has one, and its sub-steps
    let plans: Vec<Option<Path>> = states
        .iter()
        .zip(motions)
        .zip(discs.iter())
        .map(|((s, (pose, twist)), d)| {
            let prev = s.last_cut?;
            let jump = (pose.position - prev.position).norm();
            let explained = jump <= 2.0 * twist.velocity.norm() * dt + d.cutter.radius;
            (explained && prev != *pose).then(|| {
                (
                    prev,
                    UnitQuaternion::from_rotation_matrix(&prev.rotation()),
                    UnitQuaternion::from_rotation_matrix(&pose.rotation()),
                )
            })
        })
        .collect();
    let n = plans
        .iter()
        .zip(motions)
        .zip(discs.iter())
        .filter_map(|((plan, (pose, _)), d)| {
            let (prev, q0, q1) = plan.as_ref()?;
            let travel = (pose.position - prev.position).norm() + q0.angle_to(q1) * d.cutter.radius;
            Some(
                (travel / params.numerics.sweep_step)
                    .ceil()
                    .clamp(1.0, 1.0e6) as usize,
            )
        })
        .max()
        .unwrap_or(1);
    let mut changed = false;
    for k in 1..n {
        let t = k as f64 / n as f64;
        for (i, plan) in plans.iter().enumerate() {
            if let Some((prev, q0, q1)) = plan {
                let pose = &motions[i].0;
                let q = q0.slerp(q1, t);
                let p = prev.position + (pose.position - prev.position) * t;
                let at = Pose::from_rotation(p, &q.to_rotation_matrix());
                changed |= discs[i].cut_at(face, &mut states[i], &at, &motions[i].1, params);
            }
        }
    }
    for (i, (pose, twist)) in motions.iter().enumerate() {
        changed |= discs[i].cut_at(face, &mut states[i], pose, twist, params);
        states[i].last_cut = Some(*pose);
    }
    if changed {
        discs.iter().for_each(Disc::forget);
    }
    Ok(changed)
}

/// Moves the discs along their paths for `h` seconds and cuts the face along
/// the whole of them (a Co-Simulation step): `path(t)` gives every disc's
/// pose and twist at time `t` in `[0, h]` (`path(0)` the start). Disc `i`
/// is cut at its own `counts[i]` sub-steps `t = h k / counts[i]` (the
/// count [`sub_steps`] gives it: a disc near the axis moves a fraction of
/// the gauge's way and takes fewer cuts); the cuts are committed in time
/// order, discs in layout order at equal times, a fixed order. The cutting
/// energy takes the trapezoidal rule over the step for each disc. Returns
/// the motions at `t = h`.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    face: &mut Face,
    discs: &mut [Disc],
    states: &mut [DiscState],
    params: &Params,
    start: &[(Pose, Twist)],
    h: f64,
    counts: &[usize],
    path: impl Fn(f64) -> Result<Vec<(Pose, Twist)>>,
) -> Result<Vec<(Pose, Twist)>> {
    // at the start of the run (nothing cut yet) a disc's start pose is cut
    // first, as Model Exchange's initial event does (kerf.fmu's rule)
    let mut first = false;
    for (i, (pose, twist)) in start.iter().enumerate() {
        if states[i].last_cut.is_none() {
            discs[i].cut_at(face, &mut states[i], pose, twist, params);
            states[i].last_cut = Some(*pose);
            first = true;
        }
    }
    if first {
        discs.iter().for_each(Disc::forget);
    }
    let o0 = evaluate_all(discs, &face.map, start, params);
    if params.chipping.enabled {
        // a path that does not continue the last one starts here: chip
        // boundaries count on from this pose, not from the first sub-step
        let max_step = chip_max_step(&face.map, params);
        for ((d, s), (pose, _)) in discs.iter().zip(states.iter_mut()).zip(start) {
            let low = d.posed(pose).lowest_point();
            let c = &mut s.chips;
            if c.last_low
                .is_none_or(|p| (low.x - p[0]).hypot(low.y - p[1]) > max_step)
            {
                c.last_low = Some(low.into());
            }
        }
    }
    // every disc's cut times k / n as (k, n, disc), in time order (exact:
    // k1 / n1 < k2 / n2 <=> k1 n2 < k2 n1), ties in layout order
    let mut cuts: Vec<(usize, usize, usize)> = counts
        .iter()
        .enumerate()
        .flat_map(|(i, &n)| (1..=n).map(move |k| (k, n, i)))
        .collect();
    cuts.sort_by(|a, b| (a.0 * b.1).cmp(&(b.0 * a.1)).then(a.2.cmp(&b.2)));
    let mut end = start.to_vec();
    let mut at: Option<(usize, usize)> = None;
    for (k, n, i) in cuts {
        if at.is_none_or(|(k0, n0)| k0 * n != k * n0) {
            end = path(h * k as f64 / n as f64)?;
            at = Some((k, n));
        }
        let (pose, twist) = &end[i];
        pose.validate()?;
        discs[i].cut_at(face, &mut states[i], pose, twist, params);
    }
    // the last time is k / n = 1 for every disc: `end` holds the motions at h
    discs.iter().for_each(Disc::forget);
    let o1 = evaluate_all(discs, &face.map, &end, params);
    for i in 0..discs.len() {
        face.cutting_energy +=
            0.5 * (o0[i].work_on_rock(&start[i].1, h) + o1[i].work_on_rock(&end[i].1, h));
    }
    for (s, (pose, _)) in states.iter_mut().zip(&end) {
        s.last_cut = Some(*pose);
    }
    Ok(end)
}

/// Sub-steps of a sweep in which no rim point of a disc whose centre moves
/// with `twist` travels more than `numerics.sweep_step` (the spin about the
/// axle does not count: a rolling rim point does not move over the rock).
pub fn sub_steps(pose: &Pose, twist: &Twist, radius: f64, h: f64, params: &Params) -> usize {
    let rot = pose.rotation();
    let axle = rot * Vector3::y();
    let w_frame = twist.omega - axle * twist.omega.dot(&axle);
    let travel = (twist.velocity.norm() + w_frame.norm() * radius) * h;
    steps_for(travel, params.numerics.sweep_step).min(1.0e7) as usize
}

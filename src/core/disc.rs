//! One disc cutter: its geometry and force law, its contact cache, and the
//! part of the discrete state that is its own (where it last cut, where its
//! chips are along its path). The rock it cuts is a [`Face`], shared with
//! every other disc of a head.
//!
//! The operations that move discs and cut the face ([`commit_paths`],
//! [`sweep`]) take any number of discs: the single-disc [`super::Model`]
//! and the cutterhead [`super::head::Head`] both run through them. Discs are
//! evaluated in parallel (they only read the face). They cut in a fixed
//! order, time by time, discs in layout order; discs whose windows share no
//! tile cut at once (`cut_together`), which leaves the face that order
//! leaves. The results do not depend on the number of threads.

use std::cell::Cell;

use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use rayon::prelude::*;

use super::chip_heightmap::ChipState;
use super::contact_cutter_heightmap::{contact, Contact};
use super::contact_thesis::contact_thesis;
use super::csm::CsmLaw;
use super::cut_cutter_heightmap::{
    cut, cut_patch, cut_reach, node_window, would_cut, Back, CutStats, Front, Window,
};
use super::cutter::PosedDisc;
use super::error::Result;
use super::face::Face;
use super::heightmap::{HeightMap, TileRect};
use super::model::{
    bound_sub_steps, check_interval, check_posed_visits, friction_force, most_visits_per_cut,
    reach_nodes, rim_travel_between, step_travel, steps_for, Outputs, RimReach,
};
use super::params::MAX_NODE_VISITS_PER_CALL;
use super::params::{CsmParams, CutterParams, DirectionRule, Params};
use super::pose::{Pose, Twist};
use super::schedule::{dearest_first, WorkHints};

/// A disc: geometry, CSM law (with its own spacing) and the last evaluation.
#[derive(Debug)]
pub struct Disc {
    cutter: CutterParams,
    /// The law at the closed form's pressure, and the law of a relieved
    /// pass (its pressure times `pressure_scale`; the same law without chips).
    plain: CsmLaw,
    relieved: CsmLaw,
    /// The last evaluation (pose, twist, relieved, outputs without
    /// bookkeeping); cleared whenever the face changes.
    cache: Kept,
    /// The disc turns freely on its bearing ([`Disc::turning_freely`]).
    free: bool,
    /// This disc's last cut, while the map it was made on has only lost
    /// rock since: what the next cut may leave out behind ([`Back`]).
    /// Not state: without it a cut walks its whole window, to the same face.
    cut_record: Cell<Option<CutRecord>>,
    /// What this disc's last contact and cut took: the order a head hands
    /// its discs to the pool ([`dearest_first`]).
    work: WorkHints,
}

/// A cut a disc made: on which map history ([`HeightMap::lineage`]), at
/// which pose, how far ahead, how much rock it left over the disc
/// ([`cut_limits`]: the elastic layer, more for a plunging disc) and with
/// which plastic fraction.
#[derive(Debug, Clone, Copy)]
struct CutRecord {
    lineage: u64,
    disc: PosedDisc,
    front: Option<Front>,
    leave: f64,
    fraction: f64,
}

impl Clone for Disc {
    fn clone(&self) -> Self {
        Self {
            cutter: self.cutter,
            plain: self.plain,
            relieved: self.relieved,
            cache: Cell::new(None),
            free: self.free,
            cut_record: Cell::new(None),
            work: self.work.clone(),
        }
    }
}

/// A kept evaluation: (pose, twist, whether the pass was relieved, outputs).
type Kept = Cell<Option<(Pose, Twist, bool, Outputs)>>;

/// The outputs `kept` holds for `key` (pose, twist, relieved), if it does.
fn cached(kept: &Kept, key: &(Pose, Twist, bool)) -> Option<Outputs> {
    kept.get()
        .and_then(|(p, t, r, o)| (p == key.0 && t == key.1 && r == key.2).then_some(o))
}

/// The discrete state of one disc.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscState {
    /// Where the disc last cut (end of the last commit or sweep): the next
    /// Model Exchange commit cuts along the path from here.
    pub(crate) last_cut: Option<Pose>,
    /// The power the disc put into the rock just after its last cut, at the
    /// twist of that time \[W\] (0 before the first): the start of the next
    /// step's or commit's trapezoid for the cutting energy, so that the
    /// power there is not evaluated a second time (with the new twist, or at
    /// a start pose the host set a round-off away from the last end).
    pub(crate) last_power: f64,
    /// Where the chips are along the disc's path (chipping on).
    pub(crate) chips: ChipState,
}

impl DiscState {
    /// The state before the first cut.
    pub fn new(params: &Params) -> Self {
        Self {
            last_cut: None,
            last_power: 0.0,
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
    /// this disc's), its pressure times `pressure_scale` while its pass is
    /// relieved ([`ChipState::relieved`]; `ChipParams::pressure_scale_in_use`
    /// is 1 without chips). `p_reg` regularises the law at zero penetration.
    pub fn new(cutter: CutterParams, csm: CsmParams, p_reg: f64, pressure_scale: f64) -> Self {
        Self {
            cutter,
            plain: CsmLaw::new(cutter, csm, p_reg),
            relieved: CsmLaw::scaled(cutter, csm, p_reg, pressure_scale),
            cache: Cell::new(None),
            free: false,
            cut_record: Cell::new(None),
            work: WorkHints::default(),
        }
    }

    /// The same disc turning freely on its bearing, as a cutterhead's discs
    /// do: its spin is whatever rolls its contact over the rock, so the
    /// friction reads only the slip a free spin cannot take up (the slip at
    /// the contact less its part along the rim). A host that sets the spin
    /// of kerf.fmu's disc (a braked or skidding cutter) gets the friction of
    /// all of its slip.
    ///
    /// Without it a tilted disc on a head, whose spin rolls its nominal tip
    /// while it touches the rock near the tip's low edge, slid at 1-2 % of
    /// its rolling speed and felt nearly full sliding friction along its
    /// path (docs/hosts.md, K2).
    pub fn turning_freely(mut self) -> Self {
        self.free = true;
        self
    }

    /// The disc turns as its host spins it ([`Disc::turning_freely`]'s
    /// opposite, kerf.fmu's disc): friction reads all the slip at the
    /// contact, its part along the rim included.
    pub fn spun_by_host(mut self) -> Self {
        self.free = false;
        self
    }

    pub fn cutter(&self) -> &CutterParams {
        &self.cutter
    }

    /// The law at the closed form's pressure (a pass that is not relieved).
    pub fn law(&self) -> &CsmLaw {
        &self.plain
    }

    /// The law the disc cuts with in `state`: the relieved pass's, or the
    /// closed form's pressure.
    pub fn law_in(&self, state: &DiscState) -> &CsmLaw {
        if state.chips.relieved() {
            &self.relieved
        } else {
            &self.plain
        }
    }

    /// The disc at `pose`, ready for geometric queries.
    pub fn posed(&self, pose: &Pose) -> PosedDisc {
        PosedDisc::new(&self.cutter, pose)
    }

    /// The contact geometry and cutting force (no friction) at `pose`, in
    /// `state`.
    pub fn contact(
        &self,
        map: &HeightMap,
        state: &DiscState,
        pose: &Pose,
        twist: &Twist,
        params: &Params,
    ) -> Contact {
        self.contact_of(map, state, &self.posed(pose), twist, params)
    }

    /// [`Disc::contact`] of the disc already posed.
    fn contact_of(
        &self,
        map: &HeightMap,
        state: &DiscState,
        disc: &PosedDisc,
        twist: &Twist,
        params: &Params,
    ) -> Contact {
        let n = &params.numerics;
        let law = self.law_in(state);
        match n.direction {
            DirectionRule::Kerf => contact(map, disc, law, n, n.elastic_depth, twist),
            DirectionRule::Thesis => contact_thesis(map, disc, law, n, twist),
        }
    }

    /// Force and moment on the disc in `state` at `pose` moving with `twist`,
    /// against `map` (no bookkeeping, no cache).
    pub fn compute(
        &self,
        map: &HeightMap,
        state: &DiscState,
        pose: &Pose,
        twist: &Twist,
        params: &Params,
    ) -> Outputs {
        // (the disc posed once: its rotation is the outputs' frame too, a
        // second `cutter_rotation` was three `sin_cos` an evaluation)
        let disc = self.posed(pose);
        let c = self.contact_of(map, state, &disc, twist, params);
        let rot = Rotation3::from_matrix_unchecked(disc.rot);
        // friction on the slip of the rim over the rock where the contact is
        // lowest (kerf) or at the point of force application (thesis eq. 56)
        let mut slip_v = twist.velocity + twist.omega.cross(&c.slip_point);
        if self.free {
            // the rim's direction of travel at the contact, which the spin
            // takes up
            let along = (rot * Vector3::y()).cross(&c.slip_point);
            let n2 = along.norm_squared();
            if n2 > 0.0 {
                slip_v -= along * (slip_v.dot(&along) / n2);
            }
        }
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
        state: &DiscState,
        pose: &Pose,
        twist: &Twist,
        params: &Params,
    ) -> Outputs {
        if let Some(o) = self.cached_at(state, pose, twist) {
            return o;
        }
        let key = (*pose, *twist, state.chips.relieved());
        let o = self.compute(map, state, pose, twist, params);
        self.cache.set(Some((key.0, key.1, key.2, o)));
        o
    }

    /// The evaluation [`Disc::evaluate`] keeps for this state, pose and
    /// twist, if it keeps one.
    fn cached_at(&self, state: &DiscState, pose: &Pose, twist: &Twist) -> Option<Outputs> {
        cached(&self.cache, &(*pose, *twist, state.chips.relieved()))
    }

    /// Drops the cached evaluation (the face changed).
    pub fn forget(&self) {
        self.cache.set(None);
    }

    /// What a cut of `disc` on `map` may leave out behind ([`Back`]): from
    /// this disc's last cut, if it was made on this map's history and left
    /// the elastic layer alone over the disc (not a plunging cut's more),
    /// and both plastic fractions are 1.
    fn cut_back(&self, map: &HeightMap, disc: &PosedDisc, params: &Params) -> Option<Back> {
        back_after(self.cut_record.get(), map, disc, params)
    }

    /// Keeps the cut just made on `map`, which left the rock `leave` over
    /// the disc ([`cut_limits`]), for the next one's [`Back`].
    fn record_cut(
        &self,
        map: &HeightMap,
        disc: PosedDisc,
        front: Option<Front>,
        leave: f64,
        params: &Params,
    ) {
        self.cut_record.set(Some(CutRecord {
            lineage: map.lineage(),
            disc,
            front,
            leave,
            fraction: params.rock.plastic_fraction,
        }));
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
        let (front, leave) = cut_limits(&face.map, &disc, twist, params);
        let back = self.cut_back(&face.map, &disc, params);
        let stats = cut(
            &mut face.map,
            &disc,
            leave,
            params.rock.plastic_fraction,
            (front, back),
        );
        self.record_cut(&face.map, disc, front, leave, params);
        face.excavated_volume += stats.volume;
        let chips = chip_at(face, state, &disc, twist, stats.nodes > 0, params);
        if stats.nodes > 0 || chips {
            self.forget();
        }
        stats.nodes > 0 || chips
    }
}

/// How far `disc` moving with `twist` cuts: how far ahead its cut reaches
/// and how much rock it leaves over the disc (`cut_reach`: its [`Front`],
/// and the elastic layer plus, for a disc plunging into the rock, half a
/// sweep step); no front and the elastic layer alone when
/// `numerics.cut_ahead` asks for whole cuts.
fn cut_limits(
    map: &HeightMap,
    disc: &PosedDisc,
    twist: &Twist,
    params: &Params,
) -> (Option<Front>, f64) {
    let n = &params.numerics;
    if n.cut_ahead {
        return (None, n.elastic_depth);
    }
    let (front, lag) = cut_reach(
        disc,
        &twist.velocity,
        &twist.omega,
        map.grid(),
        n,
        params.rock.plastic_fraction,
    );
    (front, n.elastic_depth + lag)
}

/// A cut's window and the tiles it scans, if it scans any.
type WindowTiles = Option<(Window, TileRect)>;

/// [`Disc::cut_back`] from the disc's last cut `record` (read off the disc
/// first: a disc's cells are not for other threads).
fn back_after(
    record: Option<CutRecord>,
    map: &HeightMap,
    disc: &PosedDisc,
    params: &Params,
) -> Option<Back> {
    let r = record?;
    let n = &params.numerics;
    let same = r.lineage == map.lineage()
        && r.leave == n.elastic_depth
        && r.fraction == 1.0
        && params.rock.plastic_fraction == 1.0;
    if n.cut_behind || !same {
        return None;
    }
    Back::of(&r.disc, r.front, disc)
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
    states: &[DiscState],
    map: &HeightMap,
    motions: &[(Pose, Twist)],
    params: &Params,
) -> Vec<Outputs> {
    if discs.len() == 1 {
        return vec![discs[0].evaluate(map, &states[0], &motions[0].0, &motions[0].1, params)];
    }
    // every disc kept its evaluation (a host reading the outputs after a
    // step evaluates where the step ended): read them here, without handing
    // 56 look-ups to the pool's threads (waking them cost the reference
    // head's read after a fast-setting step about 30 us)
    let kept: Option<Vec<Outputs>> = discs
        .iter()
        .zip(states)
        .zip(motions)
        .map(|((d, s), (p, t))| d.cached_at(s, p, t))
        .collect();
    if let Some(outputs) = kept {
        return outputs;
    }
    // the dearest first (a step's gauge discs cost four to six face discs)
    let jobs = discs
        .iter_mut()
        .zip(states)
        .zip(motions)
        .map(|((d, s), m)| (d.work.contact.get(), (d, s, m)))
        .collect();
    let done = dearest_first(jobs, |(d, s, (p, t))| d.evaluate(map, s, p, t, params));
    discs
        .iter()
        .zip(done)
        .map(|(d, (outputs, took))| {
            d.work.contact.set(took);
            outputs
        })
        .collect()
}

/// A straight path from a disc's last cut: its pose and both orientations.
pub(crate) type Path = (Pose, UnitQuaternion<f64>, UnitQuaternion<f64>);

/// The path a Model Exchange commit cuts along, from the disc's last cut
/// `prev` to `pose`: `None` (only `pose` is cut) before the first cut, when
/// the disc has not moved, or when the move is a jump no step can make
/// (longer than the disc radius and than twice the travel the velocity
/// input explains over `dt`).
pub(crate) fn path_since(
    prev: Option<Pose>,
    (pose, twist): (&Pose, &Twist),
    dt: f64,
    radius: f64,
) -> Option<Path> {
    let prev = prev?;
    let jump = (pose.position - prev.position).norm();
    let explained = jump <= 2.0 * twist.velocity.norm() * dt + radius;
    (explained && prev != *pose).then(|| {
        (
            prev,
            UnitQuaternion::from_rotation_matrix(&prev.rotation()),
            UnitQuaternion::from_rotation_matrix(&pose.rotation()),
        )
    })
}

/// Rim travel along `path` to `pose` ([`rim_travel_between`]).
pub(crate) fn path_travel((prev, q0, q1): &Path, pose: &Pose, reach: &RimReach) -> f64 {
    rim_travel_between((&prev.position, &pose.position), q0, q1, reach)
}

/// The pose `k / n` of the way along `path` to `pose` (positions linear,
/// orientation by slerp); `pose` itself at the end or without a path.
pub(crate) fn along_path(path: &Option<Path>, pose: &Pose, k: usize, n: usize) -> Pose {
    match path {
        Some((prev, q0, q1)) if k < n => {
            let t = k as f64 / n as f64;
            let q = q0.slerp(q1, t);
            let p = prev.position + (pose.position - prev.position) * t;
            Pose::from_rotation(p, &q.to_rotation_matrix())
        }
        _ => *pose,
    }
}

/// Cuts the face at the motions' poses (a Model Exchange event): `dt` is the
/// time since the previous commit, for the energy bookkeeping. Each disc's
/// cut follows the path from its previous cut (`path_since`), straight
/// (positions linear, orientation by slerp), in sub-steps of at most
/// `numerics.sweep_step` of rim travel; a jump is not a path: only the new
/// pose is cut. All discs advance sub-step by sub-step, cutting in their
/// order. Returns whether the face changed. The motions must have been
/// validated. All or nothing: every pose it will cut at is checked first,
/// and a call that returns an error has changed nothing. The cutting energy
/// takes the trapezoid between the power after the last commit
/// (`DiscState::last_power`) and the power after this one, over `dt`; the
/// first commit books the latter alone.
pub fn commit_paths(
    face: &mut Face,
    discs: &mut [Disc],
    states: &mut [DiscState],
    motions: &[(Pose, Twist)],
    dt: f64,
    params: &Params,
) -> Result<bool> {
    check_interval(dt)?;
    // per disc: the path from its last cut, if it has one, and its sub-steps
    let plans: Vec<Option<Path>> = states
        .iter()
        .zip(motions)
        .zip(discs.iter())
        .map(|((s, (pose, twist)), d)| path_since(s.last_cut, (pose, twist), dt, d.cutter.radius))
        .collect();
    // each disc's own sub-steps (1 without a path: only the new pose)
    let counts: Vec<usize> = plans
        .iter()
        .zip(motions)
        .zip(discs.iter())
        .map(|((plan, (pose, _)), d)| {
            plan.as_ref().map_or(1, |path| {
                let travel = path_travel(path, pose, &RimReach::new(&d.cutter, &face.map));
                steps_for(travel, params.numerics.sweep_step).min(1.0e7) as usize
            })
        })
        .collect();
    let at = |k: usize, n: usize| -> Result<Vec<(Pose, Twist)>> {
        Ok(plans
            .iter()
            .zip(motions)
            .map(|(plan, (pose, twist))| (along_path(plan, pose, k, n), *twist))
            .collect())
    };
    let what = "the event's paths since the last commit";
    let groups = cut_times(&face.map, discs, &counts, params, at, (what, dt))?;
    // nothing fails from here on: the commit is all or nothing
    commit_checked(face, discs, states, motions, dt, params, &groups, at)
}

/// [`commit_paths`] after its checks, at the cut times `groups`
/// ([`time_groups`] of the discs' sub-step counts), `at(k, n)` every
/// disc's pose and twist at time `k / n`: what kerf.fmu's Model Exchange
/// commit (`Model::commit`, which checks its one disc's path with its own
/// words) and a head's both run.
#[allow(clippy::too_many_arguments)]
pub(crate) fn commit_checked(
    face: &mut Face,
    discs: &mut [Disc],
    states: &mut [DiscState],
    motions: &[(Pose, Twist)],
    dt: f64,
    params: &Params,
    groups: &[(usize, usize, Vec<usize>)],
    at: impl FnMut(usize, usize) -> Result<Vec<(Pose, Twist)>>,
) -> Result<bool> {
    // the energy takes kerf.fmu's trapezoid between the power after the
    // last commit (`DiscState::last_power`) and the power after this one
    let before: Vec<Option<f64>> = states
        .iter()
        .map(|s| s.last_cut.map(|_| s.last_power))
        .collect();
    let (changed, _) = cut_in_time_order(face, discs, states, params, groups, at)?;
    if changed {
        discs.iter().for_each(Disc::forget);
    }
    book_end(face, discs, states, motions, &before, dt, params);
    Ok(changed)
}

/// The end of a commit or a step: each disc's last cut is its pose in
/// `end`, and the cutting energy takes the trapezoid over `dt` from its
/// power at the start (`before`; `None`: nothing cut before, the rectangle
/// at the end) to the power its outputs report now, kept for the next one
/// (`DiscState::last_power`). The caller has forgotten what the cuts
/// changed.
fn book_end(
    face: &mut Face,
    discs: &mut [Disc],
    states: &mut [DiscState],
    end: &[(Pose, Twist)],
    before: &[Option<f64>],
    dt: f64,
    params: &Params,
) {
    for (s, (pose, _)) in states.iter_mut().zip(end) {
        s.last_cut = Some(*pose);
    }
    let after = evaluate_all(discs, states, &face.map, end, params);
    for (i, (_, twist)) in end.iter().enumerate() {
        let p1 = after[i].power_into_rock(twist);
        face.cutting_energy += energy_over(before[i], p1, dt);
        states[i].last_power = p1;
    }
}

/// The cutting energy over `dt` by the trapezoidal rule between the power
/// `p0` at the start (`None`: nothing cut before, the rectangle at the end)
/// and `p1` at the end \[J\]: kerf.fmu and the head share it.
pub(crate) fn energy_over(p0: Option<f64>, p1: f64, dt: f64) -> f64 {
    match p0 {
        Some(p0) => 0.5 * (p0 + p1) * dt,
        None => p1 * dt,
    }
}

/// The checks of a commit or a step, before anything changes: the sub-steps
/// each disc would take (`counts`, [`check_sub_steps`]) and the work of the
/// whole call (`at(k, n)` every disc's pose and twist at time `k / n`,
/// [`check_call`]); returns the cut times ([`time_groups`]). `what` and
/// `span` (its duration) name the call in a refusal.
fn cut_times(
    map: &HeightMap,
    discs: &[Disc],
    counts: &[usize],
    params: &Params,
    at: impl FnMut(usize, usize) -> Result<Vec<(Pose, Twist)>>,
    (what, span): (&str, f64),
) -> Result<Vec<(usize, usize, Vec<usize>)>> {
    check_sub_steps(counts, params, what, span)?;
    let groups = time_groups(counts);
    check_call(map, discs, &groups, at, what, span)?;
    Ok(groups)
}

/// Refuses, before anything changes, a call in which some disc would take
/// more than `MAX_SUBSTEPS_PER_CALL` sub-steps (a host stepping a head by
/// hours), naming the split that would fit. `what` and `span` (its
/// duration) name the call.
fn check_sub_steps(counts: &[usize], params: &Params, what: &str, span: f64) -> Result<()> {
    match counts.iter().enumerate().max_by_key(|&(_, n)| *n) {
        Some((i, &n)) => bound_sub_steps(n as f64, params.numerics.sweep_step, what, span, || {
            format!("takes disc {i} through")
        }),
        None => Ok(()),
    }
}

/// The times of a step at which discs cut, in order: disc `i` cuts at its
/// `counts[i]` times `k / counts[i]` (`k = 1..=counts[i]`); each entry is
/// `(k, n, discs)`, the discs that cut at time `k / n` in layout order
/// (exact: `k1 / n1 < k2 / n2 <=> k1 n2 < k2 n1`). A fixed order.
pub(crate) fn time_groups(counts: &[usize]) -> Vec<(usize, usize, Vec<usize>)> {
    let mut cuts: Vec<(usize, usize, usize)> = counts
        .iter()
        .enumerate()
        .flat_map(|(i, &n)| (1..=n).map(move |k| (k, n, i)))
        .collect();
    cuts.sort_by(|a, b| (a.0 * b.1).cmp(&(b.0 * a.1)).then(a.2.cmp(&b.2)));
    let mut groups = Vec::new();
    let mut rest = &cuts[..];
    while let Some(&(k, n, _)) = rest.first() {
        let same = rest.partition_point(|c| c.0 * n == k * c.1);
        groups.push((k, n, rest[..same].iter().map(|c| c.2).collect()));
        rest = &rest[same..];
    }
    groups
}

/// Checks every pose a call will cut at (`at(k, n)`: every disc's pose and
/// twist at time `k / n`), before anything changes: each is validated, so a
/// step whose path leaves the poses' bounds on the way is refused whole,
/// not cut halfway; and the cuts may scan at most as many height-map nodes
/// as kerf.fmu may in one call for each disc (`MAX_NODE_VISITS_PER_CALL`
/// times the number of discs; a tilted disc's node counts
/// `TILTED_NODE_WEIGHT`, as `Model` counts them), else the call is refused
/// naming the split that would fit. The discs are posed for it only when
/// their reach, every node counted as a tilted disc's, does not bound the
/// work already (a head's 1 ms step never needs it: 78 cuts of the
/// reference head may make at most 9e8 visits against its budget of
/// 2.8e9), and the windows counted only when the reach weighed by each pose
/// does not either ([`check_posed_visits`]). `what` and `span` name the
/// call.
fn check_call(
    map: &HeightMap,
    discs: &[Disc],
    groups: &[(usize, usize, Vec<usize>)],
    mut at: impl FnMut(usize, usize) -> Result<Vec<(Pose, Twist)>>,
    what: &str,
    span: f64,
) -> Result<()> {
    let budget = MAX_NODE_VISITS_PER_CALL * discs.len() as f64;
    let most: Vec<f64> = discs
        .iter()
        .map(|d| most_visits_per_cut(d.cutter(), map.grid()))
        .collect();
    let bound: f64 = groups
        .iter()
        .flat_map(|(_, _, group)| group.iter().map(|&i| most[i]))
        .sum();
    let count = bound > budget;
    let mut cuts = Vec::new();
    for (k, n, group) in groups {
        let m = at(*k, *n)?;
        for &i in group {
            m[i].0.validate()?;
            if count {
                let d = &discs[i];
                cuts.push((reach_nodes(d.cutter(), map.grid()), d.posed(&m[i].0)));
            }
        }
    }
    check_posed_visits(map, &cuts, budget, what, span)
}

/// Cuts the discs at the times of `groups` ([`time_groups`]), in that
/// order, discs in layout order at equal times. `at(k, n)` gives every
/// disc's pose and twist at time `k / n` of the step, already validated
/// ([`check_call`]). Returns whether the face changed, and the motions at
/// the step's end (`k / n = 1`, every disc's last cut).
fn cut_in_time_order(
    face: &mut Face,
    discs: &[Disc],
    states: &mut [DiscState],
    params: &Params,
    groups: &[(usize, usize, Vec<usize>)],
    mut at: impl FnMut(usize, usize) -> Result<Vec<(Pose, Twist)>>,
) -> Result<(bool, Vec<(Pose, Twist)>)> {
    let mut end = Vec::new();
    let mut changed = false;
    for (k, n, group) in groups {
        let group = group.as_slice();
        end = at(*k, *n)?;
        if params.chipping.enabled || group.len() == 1 {
            // a chip reaches past its disc's window: one disc at a time
            for &i in group {
                let (pose, twist) = &end[i];
                changed |= discs[i].cut_at(face, &mut states[i], pose, twist, params);
            }
        } else {
            changed |= cut_together(face, discs, group, &end, params);
        }
        // the tiles' height bounds follow the face down before the next
        // sub-step's windows read them
        face.map.refresh_bounds();
    }
    Ok((changed, end))
}

/// Moves the discs along their paths for `h` seconds and cuts the face along
/// the whole of them (a Co-Simulation step): `path(t)` gives every disc's
/// pose and twist at time `t` in `[0, h]` (`path(0)` the start). Disc `i`
/// is cut at its own `counts[i]` sub-steps `t = h k / counts[i]` (the
/// count [`sub_steps`] gives it: a disc near the axis moves a fraction of
/// the gauge's way and takes fewer cuts); the cuts are committed in time
/// order, discs in layout order at equal times, a fixed order. The cutting
/// energy takes the trapezoidal rule over the step for each disc, from the
/// power reported after its last step (`DiscState::last_power`). Returns
/// the motions at `t = h`. All or nothing, as [`commit_paths`].
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
    let at = |k: usize, n: usize| path(h * k as f64 / n as f64);
    let groups = cut_times(&face.map, discs, counts, params, at, ("the step", h))?;
    // nothing fails from here on: the step is all or nothing
    sweep_checked(face, discs, states, params, start, h, &groups, path)
}

/// [`sweep`] after its checks, at the cut times `groups` ([`time_groups`]
/// of the discs' sub-step counts): what kerf.fmu's Co-Simulation step
/// (`Model::advance`, which checks its one disc's path with its own words)
/// and a head's both run. `path` fails nowhere the checks passed.
#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep_checked(
    face: &mut Face,
    discs: &mut [Disc],
    states: &mut [DiscState],
    params: &Params,
    start: &[(Pose, Twist)],
    h: f64,
    groups: &[(usize, usize, Vec<usize>)],
    path: impl Fn(f64) -> Result<Vec<(Pose, Twist)>>,
) -> Result<Vec<(Pose, Twist)>> {
    let at = |k: usize, n: usize| path(h * k as f64 / n as f64);
    // at the start of the run (nothing cut yet) a disc's start pose is cut
    // first, as Model Exchange's initial event does (kerf.fmu's rule)
    let first: Vec<bool> = states.iter().map(|s| s.last_cut.is_none()).collect();
    for (i, (pose, twist)) in start.iter().enumerate() {
        if first[i] {
            discs[i].cut_at(face, &mut states[i], pose, twist, params);
            states[i].last_cut = Some(*pose);
        }
    }
    face.map.refresh_bounds();
    // the energy's trapezoid starts from the power after the last step
    // (`DiscState::last_power`), or, for a disc cut first here, from the
    // power at its start pose
    let mut p0: Vec<f64> = states.iter().map(|s| s.last_power).collect();
    if first.contains(&true) {
        discs.iter().for_each(Disc::forget);
        for (i, (pose, twist)) in start.iter().enumerate() {
            if first[i] {
                let o = discs[i].evaluate(&face.map, &states[i], pose, twist, params);
                p0[i] = o.power_into_rock(twist);
            }
        }
    }
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
    let (_, end) = cut_in_time_order(face, discs, states, params, groups, at)?;
    // the last time is k / n = 1 for every disc: `end` holds the motions at h
    discs.iter().for_each(Disc::forget);
    let before: Vec<Option<f64>> = p0.into_iter().map(Some).collect();
    book_end(face, discs, states, &end, &before, h, params);
    Ok(end)
}

/// The cuts of the discs `group` (in layout order) at their poses in
/// `motions`, as [`Disc::cut_at`] one after another in that order without
/// chips, but the cuts whose windows share no tile run at once.
///
/// Each disc's window is found on the map as it stands before the group
/// cuts (a cut elsewhere changes no tile's height bound, so the window is
/// the one it would find in turn). Discs go into waves, each the earliest
/// after every earlier disc whose window shares a tile with its own; a
/// wave's cuts touch disjoint tiles, so they commute, and a disc that shares
/// tiles with an earlier one cuts after it, as in layout order. The face is
/// therefore the one the sequential cuts leave, for any number of threads,
/// and the removed volume is summed in layout order. Returns whether the
/// face changed.
fn cut_together(
    face: &mut Face,
    discs: &[Disc],
    group: &[usize],
    motions: &[(Pose, Twist)],
    params: &Params,
) -> bool {
    let fraction = params.rock.plastic_fraction;
    let posed: Vec<PosedDisc> = group
        .iter()
        .map(|&i| discs[i].posed(&motions[i].0))
        .collect();
    let map = &face.map;
    // each disc's front, box and window on the pool's threads (the boxes
    // from the discs' last cuts, read off them here)
    let records: Vec<(Option<CutRecord>, &Twist)> = group
        .iter()
        .map(|&i| (discs[i].cut_record.get(), &motions[i].1))
        .collect();
    // (each disc's front with the layer its cut leaves, `cut_limits`)
    let (fronts, windows): (Vec<(Option<Front>, f64)>, Vec<WindowTiles>) = posed
        .par_iter()
        .zip(records.par_iter())
        .map(|(d, &(record, twist))| {
            let (front, leave) = cut_limits(map, d, twist, params);
            let back = back_after(record, map, d, params);
            let window =
                node_window(map, d, front, back).and_then(|w| w.tiles(map).map(|r| (w, r)));
            ((front, leave), window)
        })
        .unzip();
    let mut wave = vec![0usize; group.len()];
    for a in 0..group.len() {
        let Some((_, ra)) = &windows[a] else { continue };
        for b in 0..a {
            if let Some((_, rb)) = &windows[b] {
                if ra.overlaps(rb) {
                    wave[a] = wave[a].max(wave[b] + 1);
                }
            }
        }
    }
    let mut stats = vec![CutStats::default(); group.len()];
    for w in 0..=wave.iter().copied().max().unwrap_or(0) {
        let members: Vec<usize> = (0..group.len())
            .filter(|&a| wave[a] == w && windows[a].is_some())
            .collect();
        let rects: Vec<TileRect> = members
            .iter()
            .map(|&a| windows[a].as_ref().expect("member").1)
            .collect();
        let patches = face
            .map
            .patches(&rects)
            .expect("a wave's windows share no tile");
        // the dearest first (a gauge disc's cut costs up to twenty face
        // discs'); each cut on its own patch, so the order changes nothing
        let jobs = patches
            .into_iter()
            .zip(&members)
            .map(|(patch, &a)| (discs[group[a]].work.cut.get(), (patch, a)))
            .collect();
        let done = dearest_first(jobs, |(mut patch, a)| {
            let win = &windows[a].as_ref().expect("member").0;
            cut_patch(&mut patch, win, &posed[a], fronts[a].1, fraction)
        });
        for (&a, (st, took)) in members.iter().zip(done) {
            stats[a] = st;
            discs[group[a]].work.cut.set(took);
        }
    }
    let mut changed = false;
    for (a, (&i, st)) in group.iter().zip(&stats).enumerate() {
        let (front, leave) = fronts[a];
        discs[i].record_cut(&face.map, posed[a], front, leave, params);
        face.excavated_volume += st.volume;
        if st.nodes > 0 {
            discs[i].forget();
            changed = true;
        }
    }
    changed
}

/// Sub-steps of a sweep in which no rim point in the rock ([`RimReach`])
/// of a disc whose centre moves with `twist` travels more than
/// `numerics.sweep_step` (the spin about the axle does not count: a rolling
/// rim point does not move over the rock).
pub fn sub_steps(pose: &Pose, twist: &Twist, reach: &RimReach, h: f64, params: &Params) -> usize {
    let travel = step_travel(pose, twist, reach, h);
    steps_for(travel, params.numerics.sweep_step).min(1.0e7) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cuts at once what layout order would cut one by one: the same face,
    /// bit for bit, and the same volume. The discs stand in pairs whose
    /// windows share tiles (so waves must keep their order), apart, and
    /// tilted; each group cuts twice so the second cut meets the first.
    #[test]
    fn cuts_together_leave_the_face_layout_order_leaves() {
        let mut p = Params::default();
        (p.rock.x_min, p.rock.x_max, p.rock.y_min, p.rock.y_max) = (-0.6, 0.6, -0.6, 0.6);
        (p.rock.nx, p.rock.ny) = (1201, 1201);
        // half plastic: a node two discs cut ends where the order puts it
        p.rock.plastic_fraction = 0.5;
        let disc = Disc::new(p.cutter, p.csm, p.numerics.p_reg, 1.0);
        let at = |x: f64, y: f64, depth: f64, yaw: f64, roll: f64| {
            let probe = Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, roll);
            let low = disc.posed(&probe).lowest_point();
            let pose = Pose::new(x, y, 1.0 - low.z - depth, 0.0, 0.0, roll);
            Pose::from_rotation(
                pose.position,
                &(nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), yaw) * pose.rotation()),
            )
        };
        let poses = [
            at(-0.3, -0.3, 0.004, 0.0, 0.0),
            at(-0.29, -0.296, 0.006, 0.3, 0.0), // shares tiles with the first
            at(0.3, 0.3, 0.005, 1.0, 0.5),      // tilted, apart
            at(0.3, -0.3, 0.003, -0.7, 0.0),
            at(0.31, 0.305, 0.004, 1.2, 0.9), // tilted, shares with the third
            at(0.0, 0.0, 0.002, 2.0, 0.0),
        ];
        let twist = Twist::new([1.0, 0.0, 0.0], [0.0, 0.0, 0.0]);
        let n = poses.len();
        let discs: Vec<Disc> = (0..n).map(|_| disc.clone()).collect();
        let group: Vec<usize> = (0..n).collect();
        let mut together = Face::new(&p.rock).unwrap();
        let mut in_turn = together.clone();
        let mut states: Vec<DiscState> = (0..n).map(|_| DiscState::new(&p)).collect();
        for shift in [0.0, 0.002] {
            let motions: Vec<(Pose, Twist)> = poses
                .iter()
                .map(|q| {
                    let mut q = *q;
                    q.position.x += shift;
                    (q, twist)
                })
                .collect();
            cut_together(&mut together, &discs, &group, &motions, &p);
            for i in 0..n {
                discs[i].cut_at(&mut in_turn, &mut states[i], &motions[i].0, &twist, &p);
            }
        }
        assert!(together.excavated_volume > 0.0);
        assert_eq!(
            together.excavated_volume.to_bits(),
            in_turn.excavated_volume.to_bits()
        );
        assert!(together == in_turn, "the faces differ");
    }
}

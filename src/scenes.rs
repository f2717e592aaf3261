//! The scenes a cutterhead makes of one disc, as plain functions of the
//! model: a fresh straight cut, a tilted (gauge) disc, a second pass beside a
//! groove (partial engagement), and a re-roll of a groove on a straight or
//! curved track. Tests, the speed-vs-error report and `examples/contact_scenes`
//! share them, so every figure comes from the same definitions.
//!
//! Every scene rolls the disc free (spin `v/R` about its own axle) at 1 m/s
//! in Co-Simulation steps of `h`, and averages the cutter-frame forces
//! (normal, rolling, side) and the moment about the centre over a window of
//! steady cutting.

use nalgebra::Vector3;

use crate::core::cutter::PosedDisc;
use crate::core::params::CutterParams;
use crate::core::{Model, Outputs, Params, Pose, Twist};

/// Penetration of the reference scene \[m\].
pub const P_REF: f64 = 0.0038;

/// Mean outputs over a window.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Mean {
    /// Cutter-frame force: normal (+z), rolling (-x), side (+y) \[N\].
    pub force: [f64; 3],
    /// Moment about the disc centre, cutter frame \[N m\].
    pub moment: [f64; 3],
    /// The contact's cutting force alone (no friction), cutter frame, in the
    /// same order as `force` \[N\].
    pub cutting: [f64; 3],
    /// Rock removed inside the window \[m3\].
    pub volume: f64,
    /// Path length of the window \[m\].
    pub length: f64,
    /// Steps averaged.
    pub steps: usize,
    /// Median wall time of one step (cut along the path, then evaluate) in
    /// the window \[us\]: for reports only.
    pub us_median: f64,
}

impl Mean {
    /// Rolling work of the cutting force per volume removed \[J/m3\]
    /// (`F_R * length / volume`, friction left out).
    pub fn rolling_work_per_volume(&self) -> f64 {
        if self.volume > 0.0 {
            self.cutting[1] * self.length / self.volume
        } else {
            f64::INFINITY
        }
    }
}

/// Parameters of the default disc and rock on a face of `[x0, x1] x [y0, y1]`
/// with cells of `cell` metres.
pub fn face(cell: f64, x0: f64, x1: f64, y0: f64, y1: f64) -> Params {
    let mut p = Params::default();
    let r = &mut p.rock;
    r.nx = ((x1 - x0) / cell).round() as usize + 1;
    r.ny = ((y1 - y0) / cell).round() as usize + 1;
    r.x_min = x0;
    r.x_max = x0 + cell * (r.nx - 1) as f64;
    r.y_min = y0;
    r.y_max = y0 + cell * (r.ny - 1) as f64;
    p
}

/// Pose of a disc with heading `yaw` and roll `roll` whose lowest point is
/// at `(x, y, -depth)` (the face is at z = 0).
pub fn pose_with_lowest_point(
    prm: &Params,
    x: f64,
    y: f64,
    depth: f64,
    yaw: f64,
    roll: f64,
) -> Pose {
    let probe = Pose::new(0.0, 0.0, 1.0, yaw, 0.0, roll);
    let low = PosedDisc::new(&prm.cutter, &probe).lowest_point();
    Pose::new(x - low.x, y - low.y, 1.0 - low.z - depth, yaw, 0.0, roll)
}

/// The free-rolling twist of a disc at `pose` moving at `speed` along its
/// heading, turning at `yaw_rate` about the vertical.
pub fn rolling_twist(prm: &Params, pose: &Pose, speed: f64, yaw_rate: f64) -> Twist {
    let rot = pose.cutter_rotation();
    let heading = rot * Vector3::x();
    let mut v = Vector3::new(heading.x, heading.y, 0.0).normalize() * speed;
    let axle = rot * Vector3::y();
    let w = axle * (speed / prm.cutter.radius) + Vector3::z() * yaw_rate;
    // turning, the centre of a tilted disc runs on its own circle, off the
    // lowest point's by the lowest point's offset in plan: its velocity is
    // the lowest point's less the turn's `yaw_rate z x offset` (an upright
    // disc's offset is round-off, left out)
    if yaw_rate != 0.0 {
        let low = PosedDisc::new(&prm.cutter, pose).lowest_point() - pose.position;
        let off = Vector3::new(low.x, low.y, 0.0);
        if off.norm() > 1e-9 {
            v -= Vector3::z().cross(&off) * yaw_rate;
        }
    }
    Twist::new(v.into(), w.into())
}

fn cutter_frame(o: &Outputs, pose: &Pose) -> ([f64; 3], [f64; 3]) {
    let rt = pose.cutter_rotation().transpose();
    let m = rt * Vector3::from(o.moment);
    (
        [o.normal_force, o.rolling_force, o.side_force],
        [m.x, m.y, m.z],
    )
}

/// A path: the pose after travelling `s` metres.
pub trait Track {
    fn pose(&self, s: f64) -> Pose;
    fn twist(&self, s: f64) -> Twist;
}

/// A straight pass along +x at lateral offset `y`, lowest point `depth` deep,
/// rolled by `roll`.
pub struct Straight {
    pub prm: Params,
    pub x0: f64,
    pub y: f64,
    pub depth: f64,
    pub roll: f64,
}

impl Track for Straight {
    fn pose(&self, s: f64) -> Pose {
        pose_with_lowest_point(&self.prm, self.x0 + s, self.y, self.depth, 0.0, self.roll)
    }
    fn twist(&self, s: f64) -> Twist {
        rolling_twist(&self.prm, &self.pose(s), 1.0, 0.0)
    }
}

/// A circular track of radius `radius` about `(cx, cy)`, counter-clockwise
/// from the angle `a0`, lowest point `depth` deep.
pub struct Circle {
    pub prm: Params,
    pub cx: f64,
    pub cy: f64,
    pub radius: f64,
    pub a0: f64,
    pub depth: f64,
}

impl Track for Circle {
    fn pose(&self, s: f64) -> Pose {
        let a = self.a0 + s / self.radius;
        let (x, y) = (
            self.cx + self.radius * a.cos(),
            self.cy + self.radius * a.sin(),
        );
        pose_with_lowest_point(
            &self.prm,
            x,
            y,
            self.depth,
            a + std::f64::consts::FRAC_PI_2,
            0.0,
        )
    }
    fn twist(&self, s: f64) -> Twist {
        rolling_twist(&self.prm, &self.pose(s), 1.0, 1.0 / self.radius)
    }
}

/// A gauge cutter's track without the head: a disc rolled by `roll` on a
/// circle of radius `radius` (counter-clockwise about a centre to the
/// disc's left; `radius` 0: a straight line), heading `yaw` to the grid at
/// the start, its lowest point `depth` deep, at `speed`, turning with the
/// track. A negative `roll` leans the tip away from the centre, as the
/// contract's gauge cutters lean outwards (interface.md).
pub struct TiltedArc {
    pub prm: Params,
    pub yaw: f64,
    pub roll: f64,
    pub depth: f64,
    pub radius: f64,
    pub speed: f64,
}

impl Track for TiltedArc {
    fn pose(&self, s: f64) -> Pose {
        // start 0.1 m before the face's centre
        let s = s - 0.1;
        let (sn, c) = self.yaw.sin_cos();
        if self.radius == 0.0 {
            return pose_with_lowest_point(
                &self.prm,
                s * c,
                s * sn,
                self.depth,
                self.yaw,
                self.roll,
            );
        }
        let (cx, cy) = (-sn * self.radius, c * self.radius);
        let a = self.yaw - std::f64::consts::FRAC_PI_2 + s / self.radius;
        pose_with_lowest_point(
            &self.prm,
            cx + self.radius * a.cos(),
            cy + self.radius * a.sin(),
            self.depth,
            a + std::f64::consts::FRAC_PI_2,
            self.roll,
        )
    }
    fn twist(&self, s: f64) -> Twist {
        let yaw_rate = if self.radius == 0.0 {
            0.0
        } else {
            self.speed / self.radius
        };
        rolling_twist(&self.prm, &self.pose(s), self.speed, yaw_rate)
    }
}

/// The gauge scene for the disc `cutter`: a `TiltedArc` rolled by `tilt`,
/// heading 30 deg to the grid, through fresh rock on a 0.7 m square face
/// at cells of `cell` and sweep steps of `sweep`, in steps of 1 ms of
/// travel. Returns the mean over 0.15-0.28 m of a 0.3 m pass, and the side
/// faces' (and flanks') share of the cutting force at its last pose
/// (cutter frame: normal, rolling, side). (`roll` hands the model each
/// step's travel as its time step, right at 1 m/s; at other speeds only the
/// energy bookkeeping, which this scene does not read, sees the
/// difference.)
pub fn gauge(
    cutter: &CutterParams,
    cell: f64,
    sweep: f64,
    depth: f64,
    tilt: f64,
    radius: f64,
    speed: f64,
) -> (Mean, [f64; 3]) {
    let mut prm = gauge_face(cell);
    prm.numerics.sweep_step = sweep;
    prm.cutter = *cutter;
    let t = gauge_arc(&prm, depth, tilt, radius, speed);
    let mut m = Model::new(prm).unwrap();
    let mean = roll(&mut m, &t, 0.3, 1e-3 * speed, 0.15, 0.28);
    let end = t.pose(0.3);
    let mut c = m.contact(&end, &t.twist(0.3));
    c.rim_force = Vector3::zeros();
    (mean, cutting_force(&end, &c))
}

/// The gauge scenes' face: a 0.7 m square about the origin, cells of `cell`.
fn gauge_face(cell: f64) -> Params {
    face(cell, -0.35, 0.35, -0.35, 0.35)
}

/// The gauge scenes' track: heading 30 deg to the grid, rolled by `tilt`.
fn gauge_arc(prm: &Params, depth: f64, tilt: f64, radius: f64, speed: f64) -> TiltedArc {
    TiltedArc {
        prm: prm.clone(),
        yaw: 30f64.to_radians(),
        roll: tilt,
        depth,
        radius,
        speed,
    }
}

/// [`gauge`]'s scene for the default disc as a [`Plan`] like the others
/// (1 m/s, one pass of [`PASS`], measured over [`WINDOW`]), for the
/// speed-vs-error report.
pub fn gauge_plan(cell: f64, depth: f64, tilt: f64, radius: f64) -> Plan {
    let prm = gauge_face(cell);
    let t = gauge_arc(&prm, depth, tilt, radius, 1.0);
    Plan {
        prm,
        passes: vec![(Box::new(t), PASS)],
    }
}

/// Rolls along `track` from `s = 0` to `length` in steps of `h` metres,
/// each step a Co-Simulation step that ends exactly on the track (the pose
/// is set from the track, the path between cut by the model), and averages
/// over `s` in `[lo, hi]`.
pub fn roll(model: &mut Model, track: &dyn Track, length: f64, h: f64, lo: f64, hi: f64) -> Mean {
    let n = (length / h).round() as usize;
    let mut mean = Mean::default();
    let mut v_lo = None;
    let mut v_hi = 0.0;
    let mut us = Vec::new();
    for k in 0..=n {
        let s = k as f64 * h;
        let pose = track.pose(s);
        let tw = track.twist(s);
        let t0 = std::time::Instant::now();
        if k == 0 {
            model.commit(&pose, &tw, 0.0).expect("commit");
        } else {
            // Model Exchange style: the model cuts along the path from the
            // last cut, so the pose stays exactly on the track
            model.commit(&pose, &tw, h).expect("commit");
        }
        let o = model.evaluate(&pose, &tw).expect("evaluate");
        let dt_us = t0.elapsed().as_secs_f64() * 1e6;
        if s >= lo - 1e-12 && s <= hi + 1e-12 {
            let (f, m) = cutter_frame(&o, &pose);
            let cut = cutting_force(&pose, &model.contact(&pose, &tw));
            for i in 0..3 {
                mean.force[i] += f[i];
                mean.moment[i] += m[i];
                mean.cutting[i] += cut[i];
            }
            mean.steps += 1;
            us.push(dt_us);
            if v_lo.is_none() {
                v_lo = Some((o.excavated_volume, s));
            }
            v_hi = o.excavated_volume;
            mean.length = s - v_lo.unwrap().1;
        }
    }
    let k = mean.steps.max(1) as f64;
    mean.force = mean.force.map(|x| x / k);
    mean.moment = mean.moment.map(|x| x / k);
    mean.cutting = mean.cutting.map(|x| x / k);
    mean.volume = v_hi - v_lo.map_or(0.0, |v| v.0);
    us.sort_by(f64::total_cmp);
    mean.us_median = us.get(us.len() / 2).copied().unwrap_or(0.0);
    mean
}

/// Length of the scenes' passes and their averaging window \[m\]: the
/// contact is steady 0.05 m after the start (R sin(phi) = 40 mm).
pub const PASS: f64 = 0.15;
pub const WINDOW: (f64, f64) = (0.06, 0.14);

/// A scene as the passes that make it: the face, then each pass rolled in
/// turn over its length on one model; the last pass is the measured one,
/// averaged over `WINDOW`. The speed-vs-error report's C host replays the
/// same passes through the FMU.
pub struct Plan {
    pub prm: Params,
    pub passes: Vec<(Box<dyn Track>, f64)>,
}

impl Plan {
    /// Rolls every pass in turn on a new model: the mean of the last.
    pub fn run(&self) -> Mean {
        let mut m = Model::new(self.prm.clone()).unwrap();
        let (last, first) = self.passes.split_last().unwrap();
        for (t, len) in first {
            roll(&mut m, t.as_ref(), *len, 1e-3, 0.0, 0.0);
            lift(&mut m);
        }
        measured_pass(&mut m, last.0.as_ref(), last.1)
    }
}

/// Lifts the disc 1 m clear of the rock after a pass, so that the next
/// pass starts with a jump, not a path: a Model Exchange commit cuts along
/// the path from the last cut when the move is shorter than the disc's
/// radius, and the start of a 0.1 m track's second lap lies 0.19 m from the
/// end of its first (the C host's Co-Simulation replay jumps there).
fn lift(m: &mut Model) {
    if let Some(mut p) = m.state().disc().last_cut() {
        p.position.z += 1.0;
        m.commit(&p, &Twist::default(), 0.0).expect("lift");
    }
}

/// The measured pass of [`Plan::run`], a function of its own so that a
/// profile can take it alone:
/// `valgrind --tool=callgrind --toggle-collect='*measured_pass*' target/release/examples/scene_cost beside 2`.
#[inline(never)]
fn measured_pass(m: &mut Model, track: &dyn Track, length: f64) -> Mean {
    roll(m, track, length, 1e-3, WINDOW.0, WINDOW.1)
}

/// A fresh straight cut `depth` deep, rolled by `roll` (0 = upright).
pub fn fresh_plan(cell: f64, depth: f64, roll: f64) -> Plan {
    straight_plan(face(cell, -0.3, 0.5, -0.06, 0.06), depth, roll)
}

/// One straight pass on the face of `prm`, `depth` deep, rolled by `roll`.
fn straight_plan(prm: Params, depth: f64, roll: f64) -> Plan {
    let t = Straight {
        prm: prm.clone(),
        x0: 0.0,
        y: 0.0,
        depth,
        roll,
    };
    Plan {
        prm,
        passes: vec![(Box::new(t), PASS)],
    }
}

/// The mean of `fresh_plan`.
pub fn fresh(cell: f64, depth: f64, roll: f64) -> Mean {
    fresh_plan(cell, depth, roll).run()
}

/// A second pass `offset` beside a first groove of the same depth (upright
/// discs), measured on the second pass.
pub fn beside_plan(cell: f64, depth: f64, offset: f64) -> Plan {
    let prm = face(cell, -0.3, 0.5, -0.06, 0.06);
    let first = Straight {
        prm: prm.clone(),
        x0: -0.1,
        y: 0.0,
        depth,
        roll: 0.0,
    };
    let second = Straight {
        prm: prm.clone(),
        x0: 0.0,
        y: offset,
        depth,
        roll: 0.0,
    };
    Plan {
        prm,
        passes: vec![(Box::new(first), PASS + 0.2), (Box::new(second), PASS)],
    }
}

/// The mean of `beside_plan`.
pub fn beside(cell: f64, depth: f64, offset: f64) -> Mean {
    beside_plan(cell, depth, offset).run()
}

/// An arc of a circular track of radius `rt` centred on (0, rt), the disc
/// passing (0, 0) heading +x: on fresh rock (`reroll` false), or a second
/// lap rolling the groove the first lap cut, at its own depth.
pub fn lap_plan(cell: f64, depth: f64, rt: f64, reroll: bool) -> Plan {
    laps_plan(
        &Params::default().cutter,
        cell,
        rt,
        reroll.then_some(depth),
        depth,
    )
}

/// [`lap_plan`] for a disc of `cutter`, the measured lap `depth` deep, after
/// a first lap `first` deep (`None`: on fresh rock), as a cutterhead's disc
/// runs its own groove a revolution's penetration deeper.
pub fn laps_plan(
    cutter: &CutterParams,
    cell: f64,
    rt: f64,
    first: Option<f64>,
    depth: f64,
) -> Plan {
    // a0 = -pi/2 puts the disc at (0, 0) heading +x
    let len = PASS + 0.2;
    let half = 0.5 * len.min(std::f64::consts::PI * rt);
    let ang = (half / rt).min(std::f64::consts::PI);
    let reach = if ang > std::f64::consts::FRAC_PI_2 {
        rt
    } else {
        rt * ang.sin()
    };
    let mut prm = face(
        cell,
        -reach - 0.3,
        reach + 0.3,
        -0.06,
        0.06 + rt * (1.0 - ang.cos()),
    );
    prm.cutter = *cutter;
    let a0 = -std::f64::consts::FRAC_PI_2 - (half - 0.1) / rt;
    let lap = |a0: f64, depth: f64| Circle {
        prm: prm.clone(),
        cx: 0.0,
        cy: rt,
        radius: rt,
        a0,
        depth,
    };
    let mut passes: Vec<(Box<dyn Track>, f64)> = Vec::new();
    if let Some(d) = first {
        passes.push((Box::new(lap(a0 - 0.1 / rt, d)), len));
    }
    passes.push((Box::new(lap(a0, depth)), PASS));
    Plan { prm, passes }
}

/// The reference head's 19 in disc (`layouts/reference-9.72m.json`).
pub fn head_disc() -> CutterParams {
    CutterParams {
        radius: 0.2413,
        tip_width: 0.019,
        tip_radius: 0.0127,
        ..CutterParams::default()
    }
}

/// A cutterhead's centre disc in its own groove: a disc of `cutter` (the
/// reference head's is [`head_disc`]) runs a first lap of the circle of
/// radius `rt` `first` deep, then the same circle `depth` deep
/// ([`laps_plan`]), on a face that holds the whole circle and the disc
/// around it (the face of [`laps_plan`] ends at the circle's top).
/// On a track this tight the disc's plane leaves its curved groove ahead
/// of the lowest point and behind it: the rim's strips meet the groove's
/// walls over part of the tip, and the rear of the disc scrubs the outer
/// wall.
pub fn own_groove_plan(cutter: &CutterParams, cell: f64, rt: f64, first: f64, depth: f64) -> Plan {
    let mut plan = laps_plan(cutter, cell, rt, Some(first), depth);
    let mut prm = face(cell, -rt - 0.35, rt + 0.35, -0.35, 2.0 * rt + 0.35);
    prm.cutter = plan.prm.cutter;
    plan.prm = prm;
    plan
}

/// The contact's cutting force on the measured pass of `plan` at each
/// path length of `at` \[m\] (1 mm steps, as [`Plan::run`]), and the
/// brute-force oracle's there too at resolution `oracle`, if given.
pub fn forces_along(
    plan: &Plan,
    at: &[f64],
    oracle: Option<&crate::core::contact_bruteforce::Resolution>,
) -> Vec<([f64; 3], Option<[f64; 3]>)> {
    let mut m = Model::new(plan.prm.clone()).unwrap();
    let (last, first) = plan.passes.split_last().unwrap();
    for (t, len) in first {
        roll(&mut m, t.as_ref(), *len, 1e-3, 0.0, 0.0);
    }
    let t = last.0.as_ref();
    let end = at.iter().copied().fold(0.0, f64::max);
    let mut out = Vec::new();
    for k in 0..=(end / 1e-3).round() as usize {
        let s = k as f64 * 1e-3;
        let (pose, tw) = (t.pose(s), t.twist(s));
        m.commit(&pose, &tw, if k == 0 { 0.0 } else { 1e-3 })
            .expect("commit");
        if at.iter().any(|a| (a - s).abs() < 1e-9) {
            let fast = cutting_force(&pose, &m.contact(&pose, &tw));
            let brute = oracle.map(|r| cutting_force(&pose, &m.contact_brute(&pose, &tw, r)));
            out.push((fast, brute));
        }
    }
    out
}

/// Re-rolls a groove at its own depth: the first pass cuts it, the second
/// rolls it again on the same track (`radius` = None: straight).
pub fn reroll(cell: f64, depth: f64, radius: Option<f64>) -> Mean {
    match radius {
        None => beside(cell, depth, 0.0),
        Some(rt) => lap_plan(cell, depth, rt, true).run(),
    }
}

/// A model after rolling each `(track, length)` in turn, with the pose and
/// twist at the end of the last one.
pub fn rolled(prm: &Params, tracks: &[(&dyn Track, f64)]) -> (Model, Pose, Twist) {
    let mut m = Model::new(prm.clone()).unwrap();
    for (t, len) in tracks {
        roll(&mut m, *t, *len, 1e-3, 0.0, 0.0);
    }
    let (t, len) = tracks.last().unwrap();
    (m, t.pose(*len), t.twist(*len))
}

/// The end states of the scenes the fast contact is checked against the
/// brute-force oracle on: tilted 0, 10, 30, 60 deg and 2, 4, 8 mm beside a
/// groove, at cells of `cell`.
pub fn oracle_scenes(cell: f64) -> Vec<(String, Model, Pose, Twist)> {
    let prm = face(cell, -0.3, 0.5, -0.06, 0.06);
    let mut scenes = Vec::new();
    for g in [0.0f64, 10.0, 30.0, 60.0] {
        let t = Straight {
            prm: prm.clone(),
            x0: 0.0,
            y: 0.0,
            depth: P_REF,
            roll: g.to_radians(),
        };
        let (m, p, tw) = rolled(&prm, &[(&t, 0.1)]);
        scenes.push((format!("tilt {g}"), m, p, tw));
    }
    for d in [2e-3, 4e-3, 8e-3] {
        let a = Straight {
            prm: prm.clone(),
            x0: -0.1,
            y: 0.0,
            depth: P_REF,
            roll: 0.0,
        };
        let b = Straight {
            prm: prm.clone(),
            x0: 0.0,
            y: d,
            depth: P_REF,
            roll: 0.0,
        };
        let (m, p, tw) = rolled(&prm, &[(&a, 0.35), (&b, 0.1)]);
        scenes.push((format!("beside {} mm", d * 1e3), m, p, tw));
    }
    scenes
}

/// A contact's cutting force (rim and faces, no friction) in the cutter
/// frame: normal (+z), rolling (-x), side (+y).
pub fn cutting_force(pose: &Pose, c: &crate::core::contact_cutter_heightmap::Contact) -> [f64; 3] {
    let f = pose.cutter_rotation().transpose() * (c.rim_force + c.side_force);
    [f.z, -f.x, f.y]
}

/// Flank angle of the flanked scenes \[deg\] (docs/flanks.md: a typical CCS
/// ring, inferred).
pub const FLANK_DEG: f64 = 30.0;
/// Hub width of the flanked scenes \[m\] (`params::HUB_WIDTH_DEFAULT`).
pub const HUB_WIDTH: f64 = crate::core::params::HUB_WIDTH_DEFAULT;

/// The thesis's disc with flanks at `flank_deg` to the hub width
/// [`HUB_WIDTH`] (0: the thesis's disc itself).
pub fn flanked_cutter(flank_deg: f64) -> CutterParams {
    CutterParams {
        flank_angle: flank_deg.to_radians(),
        hub_width: HUB_WIDTH,
        ..CutterParams::default()
    }
}

/// [`fresh`] with the disc `cutter`.
pub fn fresh_disc(cutter: &CutterParams, cell: f64, depth: f64, roll: f64) -> Mean {
    let mut prm = face(cell, -0.3, 0.5, -0.08, 0.08);
    prm.cutter = *cutter;
    straight_plan(prm, depth, roll).run()
}

/// The scenes flanks change (docs/flanks.md), with the disc `cutter`: a
/// fresh cut 3.8 mm deep tilted 10, 30 and 60 deg, and upright fresh cuts
/// 8 and 12 mm deep.
pub fn flank_cases() -> Vec<(String, f64, f64)> {
    let mut v = Vec::new();
    for g in [10.0f64, 30.0, 60.0] {
        v.push((format!("tilt {g}"), P_REF, g.to_radians()));
    }
    for p in [8e-3, 12e-3] {
        v.push((format!("deep {} mm", p * 1e3), p, 0.0));
    }
    v
}

/// The end states of [`flank_cases`] for the disc `cutter` at cells of
/// `cell` (for the oracle).
pub fn flank_scenes(cutter: &CutterParams, cell: f64) -> Vec<(String, Model, Pose, Twist)> {
    let mut prm = face(cell, -0.3, 0.5, -0.08, 0.08);
    prm.cutter = *cutter;
    flank_cases()
        .into_iter()
        .map(|(name, depth, roll)| {
            let t = Straight {
                prm: prm.clone(),
                x0: 0.0,
                y: 0.0,
                depth,
                roll,
            };
            let (m, p, tw) = rolled(&prm, &[(&t, 0.1)]);
            (name, m, p, tw)
        })
        .collect()
}

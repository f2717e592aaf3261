//! Speed against error: every scene a cutterhead makes, per force
//! component, and every numerical setting of the core against the
//! thesis-faithful baseline. Run by `scripts/speed-vs-error`, which turns the
//! JSON this writes into `docs/speed-vs-error.md` and its plots.
//!
//! `cargo run --release --example speed-vs-error -- [--out FILE] [--reps N] [--quick]`
//! writes the rows; three more modes serve the script:
//! * `--scene-costs`: one timing round, every scene once at 1 mm, one JSON
//!   line each (median µs of a step in the window);
//! * `--host-scenes DIR`: the scenes' passes as replay files for the bare C
//!   host (`host/kerf_host.c`), which drives them through the FMU;
//! * `--scenes-only`: the scene rows alone, printed.
//!
//! **Scenes** (`kerf::scenes`, defined once there, shared with the tests):
//! the fresh straight cut, tilted 10/30/60°, a pass 2/4/8 mm beside a 3.8 mm
//! groove, curved tracks of 0.2 and 0.5 m (fresh lap and re-roll), the
//! straight re-roll; at 2, 1, 0.5 and 0.25 mm cells (the last the converged
//! reference; `--quick`: 1 and 0.5 mm), with the fast contact against the
//! brute-force oracle at a pose inside the window.
//!
//! **Settings** (reference cutter and rock of thesis Table 2, 1 m/s, wy = v/R):
//! * flat: a 0.3 m cut at p = 3.8 mm along y = 0 of a flat 0.8 m x 0.2 m
//!   face, outputs averaged over the steady middle x in [0.1, 0.25] m, against
//!   the CSM closed form and the analytic groove;
//! * tilt: the same cut with the cutter rolled 30 deg, its lowest point 3.8 mm
//!   deep (0.2 m, window [0.08, 0.18] m);
//! * groove: a cut at y = 10 mm beside a groove cut first along y = 0 (0.2 m
//!   each, window [0.08, 0.18] m);
//!
//! tilt and groove against a converged run (0.25 mm cells, 17 slices, arc
//! step 1 cell, sweep step 0.5 mm), as the largest component difference over
//! the CSM normal force. Times are wall-clock microseconds of one
//! `advance` plus one `evaluate`, per millimetre of travel, over the window
//! of the flat scene, for `reps` rounds that run every row once (so load
//! from other processes falls on all rows alike): median and quartiles.

use std::fmt::Write as _;
use std::time::Instant;

use kerf::core::baseline::{BaselineModel, BaselineResolution};
use kerf::core::contact_bruteforce::Resolution;
use kerf::core::cutter::PosedDisc;
use kerf::core::params::CutterParams;
use kerf::core::{Model, Outputs, Params, Pose, Twist};
use kerf::scenes::{
    beside_plan, cutting_force, fresh_plan, gauge_plan, lap_plan, own_groove_plan, rolled, Mean,
    Plan, Track, P_REF, WINDOW,
};
use nalgebra::Vector3;
use serde_json::{json, Value};

const R: f64 = 0.2159;
const P: f64 = 3.8e-3;

trait Sim {
    fn step(&mut self, pose: &Pose, tw: &Twist, h: f64) -> Pose;
    fn eval(&self, pose: &Pose, tw: &Twist) -> Outputs;
    fn memory(&self) -> usize;
}

impl Sim for Model {
    fn step(&mut self, pose: &Pose, tw: &Twist, h: f64) -> Pose {
        self.advance(pose, tw, h).unwrap()
    }
    fn eval(&self, pose: &Pose, tw: &Twist) -> Outputs {
        self.evaluate(pose, tw).unwrap()
    }
    fn memory(&self) -> usize {
        self.map().memory_bytes()
    }
}

impl Sim for BaselineModel {
    fn step(&mut self, pose: &Pose, tw: &Twist, h: f64) -> Pose {
        self.advance(pose, tw, h).unwrap()
    }
    fn eval(&self, pose: &Pose, tw: &Twist) -> Outputs {
        self.evaluate(pose, tw).unwrap()
    }
    fn memory(&self) -> usize {
        self.map().memory_bytes()
    }
}

#[derive(Clone)]
struct Setting {
    label: String,
    group: &'static str,
    cell_mm: f64,
    step_mm: f64,
    params: Params,
    baseline: Option<BaselineResolution>,
}

impl Setting {
    fn make(&self) -> Box<dyn Sim> {
        match self.baseline {
            None => Box::new(Model::new(self.params.clone()).unwrap()),
            Some(res) => Box::new(BaselineModel::new(self.params.clone(), res).unwrap()),
        }
    }
}

/// The report's face, 0.8 m x 0.2 m, at `cell_mm` cells.
fn face(cell_mm: f64) -> Params {
    let mut p = Params::default();
    let c = cell_mm * 1e-3;
    let r = &mut p.rock;
    (r.x_min, r.x_max, r.y_min, r.y_max) = (-0.25, 0.55, -0.1, 0.1);
    r.nx = (0.8 / c).round() as usize + 1;
    r.ny = (0.2 / c).round() as usize + 1;
    p
}

fn kerf(
    label: &str,
    group: &'static str,
    cell_mm: f64,
    step_mm: f64,
    f: impl Fn(&mut Params),
) -> Setting {
    let mut params = face(cell_mm);
    f(&mut params);
    Setting {
        label: label.to_string(),
        group,
        cell_mm,
        step_mm,
        params,
        baseline: None,
    }
}

fn baseline(cell_mm: f64, n_alpha: usize, n_y: usize) -> Setting {
    Setting {
        label: format!("thesis baseline {n_alpha} x {n_y}, {cell_mm} mm"),
        group: "baseline",
        cell_mm,
        step_mm: 1.0,
        params: face(cell_mm),
        baseline: Some(BaselineResolution { n_alpha, n_y }),
    }
}

fn rolling_twist() -> Twist {
    Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0])
}

/// Start pose of a cutter rolled by `roll` whose lowest point is `P` deep at (0, y).
fn start_pose(roll: f64, y: f64) -> Pose {
    if roll == 0.0 {
        return Pose::new(0.0, y, R - P, 0.0, 0.0, 0.0);
    }
    let probe = Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, roll);
    let disc = PosedDisc::new(&Params::default().cutter, &probe);
    let mut low = Vector3::new(0.0, 0.0, f64::INFINITY);
    for k in 0..=2000 {
        let yy = -disc.half_width + 2.0 * disc.half_width * k as f64 / 2000.0;
        if let Some((t0, _)) = disc.arc_below(yy, disc.rho(yy), 10.0) {
            let p = disc.to_world(&disc.rim_point_local(t0, yy));
            if p.z < low.z {
                low = p;
            }
        }
    }
    Pose::new(-low.x, y - low.y, 1.0 - low.z - P, 0.0, 0.0, roll)
}

struct Pass {
    /// Mean cutter-frame force (normal, rolling, side) over the window.
    force: [f64; 3],
    window_volume: f64,
    window_len: f64,
    /// Per-step wall time, per mm of travel, inside the window \[us\].
    us_per_mm: Vec<f64>,
    us_per_call: Vec<f64>,
}

/// Rolls `sim` along +x from `start` to `x_end` in steps of `h`, averaging
/// over poses with x in `[lo, hi]`.
fn pass(sim: &mut dyn Sim, start: Pose, tw: &Twist, h: f64, x_end: f64, lo: f64, hi: f64) -> Pass {
    let n = ((x_end - start.position.x) / h).round() as usize;
    let mut pose = start;
    let mut f = [0.0; 3];
    let mut k = 0usize;
    let (mut v_lo, mut v_hi, mut x_lo, mut x_hi) = (None, 0.0, 0.0, 0.0);
    let mut us_per_mm = Vec::new();
    let mut us_per_call = Vec::new();
    for _ in 0..n {
        let t = Instant::now();
        pose = sim.step(&pose, tw, h);
        let o = sim.eval(&pose, tw);
        let us = t.elapsed().as_secs_f64() * 1e6;
        let x = pose.position.x;
        if x >= lo - 1e-9 && x <= hi + 1e-9 {
            f[0] += o.normal_force;
            f[1] += o.rolling_force;
            f[2] += o.side_force;
            k += 1;
            if v_lo.is_none() {
                v_lo = Some(o.excavated_volume);
                x_lo = x;
            }
            v_hi = o.excavated_volume;
            x_hi = x;
            us_per_mm.push(us / (h * 1e3));
            us_per_call.push(us);
        }
    }
    assert!(k > 0, "no sample in the window");
    Pass {
        force: f.map(|s| s / k as f64),
        window_volume: v_hi - v_lo.unwrap(),
        window_len: x_hi - x_lo,
        us_per_mm,
        us_per_call,
    }
}

fn flat(s: &Setting) -> (Pass, usize) {
    let mut sim = s.make();
    let p = pass(
        sim.as_mut(),
        start_pose(0.0, 0.0),
        &rolling_twist(),
        s.step_mm * 1e-3,
        0.3,
        0.1,
        0.25,
    );
    (p, sim.memory())
}

/// Mean force and median cost \[us per mm\] of the tilted scene.
fn tilt(s: &Setting) -> ([f64; 3], f64) {
    let mut sim = s.make();
    let roll = 30f64.to_radians();
    let start = start_pose(roll, 0.0);
    let axle = start.rotation() * Vector3::y();
    let tw = Twist {
        velocity: Vector3::new(1.0, 0.0, 0.0),
        omega: axle / R,
    };
    let mut p = pass(sim.as_mut(), start, &tw, s.step_mm * 1e-3, 0.2, 0.08, 0.18);
    (p.force, quantile(&mut p.us_per_mm, 0.5))
}

fn groove(s: &Setting) -> [f64; 3] {
    let mut sim = s.make();
    let tw = rolling_twist();
    let h = s.step_mm * 1e-3;
    pass(sim.as_mut(), start_pose(0.0, 0.0), &tw, h, 0.2, 0.08, 0.18);
    pass(
        sim.as_mut(),
        start_pose(0.0, 0.010),
        &tw,
        h,
        0.2,
        0.08,
        0.18,
    )
    .force
}

/// CSM closed form (thesis eqs 13-17): (F_N, F_R).
fn csm() -> (f64, f64) {
    let phi = ((R - P) / R).acos();
    let pp = 2.12 * ((158e6f64).powi(2) * 6.78e6 * 0.051 / (R * 0.013).sqrt()).cbrt();
    let ft = 0.013 * R * phi * pp;
    (ft * (phi / 2.0).cos(), ft * (phi / 2.0).sin())
}

/// Analytic groove cross-section at depth `P` (tip profile, flat sides at |y| = T/2).
fn groove_area() -> f64 {
    let (t, r) = (0.013, 0.0127);
    let n = 200_000;
    (0..n)
        .map(|k| {
            let y = -t / 2.0 + t * (k as f64 + 0.5) / n as f64;
            (P - (r - (r * r - y * y).sqrt())).max(0.0) * t / n as f64
        })
        .sum()
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let x = q * (v.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    if i + 1 < v.len() {
        v[i] * (1.0 - f) + v[i + 1] * f
    } else {
        v[i]
    }
}

/// Largest component difference (normal, rolling, side) over the fresh
/// cut's normal force (CSM closed form): no norm that one component rules.
fn comp_err(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max) / csm().0
}

/// Median, quartiles, min and max of per-step times of `steps` steps of the
/// reference cut on a face of `w x w` metres at 1 mm cells, `x` from
/// `-0.25`: kerf (default numerics) or the baseline.
fn face_cost(w: f64, steps: usize, base: Option<BaselineResolution>, reps: usize) -> [f64; 5] {
    let mut ts = Vec::new();
    for _ in 0..reps {
        let mut params = Params::default();
        let r = &mut params.rock;
        (r.x_min, r.x_max, r.y_min, r.y_max) = (-0.25, w - 0.25, -0.5 * w, 0.5 * w);
        r.nx = (w / 1e-3).round() as usize + 1;
        r.ny = r.nx;
        let mut sim: Box<dyn Sim> = match base {
            None => Box::new(Model::new(params).unwrap()),
            Some(res) => Box::new(BaselineModel::new(params, res).unwrap()),
        };
        let tw = rolling_twist();
        let mut pose = start_pose(0.0, 0.0);
        // lead-in (not timed): 50 mm to reach the steady cut
        for _ in 0..50.min(steps) {
            pose = sim.step(&pose, &tw, 1e-3);
            sim.eval(&pose, &tw);
        }
        for _ in 0..steps {
            let t = Instant::now();
            pose = sim.step(&pose, &tw, 1e-3);
            sim.eval(&pose, &tw);
            ts.push(t.elapsed().as_secs_f64() * 1e6);
        }
    }
    [
        quantile(&mut ts, 0.5),
        quantile(&mut ts, 0.25),
        quantile(&mut ts, 0.75),
        quantile(&mut ts, 0.0),
        quantile(&mut ts, 1.0),
    ]
}

// ---------------------------------------------------------------- scenes
//
// The scenes a cutterhead makes (issue 7), exactly as `kerf::scenes` defines
// them: each at the default 1 mm cells, and at 0.5 and 0.25 mm (the
// converged reference); the fast contact against the brute-force oracle at
// a pose inside the window; and their cost, from the core here and from the
// bare C host, which replays the same passes through the FMU.

type PlanAt = Box<dyn Fn(f64) -> Plan>;

/// Name, kind and plan (at a cell size \[m\]) of every scene of the report.
fn scene_defs() -> Vec<(String, &'static str, PlanAt)> {
    let mut v: Vec<(String, &'static str, PlanAt)> = vec![(
        "fresh straight".into(),
        "fresh",
        Box::new(|c| fresh_plan(c, P_REF, 0.0)),
    )];
    for g in [10.0f64, 30.0, 60.0] {
        v.push((
            format!("tilted {g}°"),
            "tilted",
            Box::new(move |c| fresh_plan(c, P_REF, g.to_radians())),
        ));
    }
    for d in [2.0f64, 4.0, 8.0] {
        v.push((
            format!("beside groove, d = {d} mm"),
            "partial",
            Box::new(move |c| beside_plan(c, P_REF, d * 1e-3)),
        ));
    }
    v.push((
        "re-roll straight".into(),
        "reroll",
        Box::new(|c| beside_plan(c, P_REF, 0.0)),
    ));
    for r in [0.2f64, 0.5] {
        v.push((
            format!("curved r = {r} m, fresh lap"),
            "curved",
            Box::new(move |c| lap_plan(c, P_REF, r, false)),
        ));
        v.push((
            format!("curved r = {r} m, re-roll"),
            "reroll",
            Box::new(move |c| lap_plan(c, P_REF, r, true)),
        ));
    }
    // a gauge cutter: tilted, turning on its track (docs/head.md, "Gauge
    // cutters on curved tracks": its side force does not converge)
    v.push((
        "gauge 60°, r = 4.83 m".into(),
        "gauge",
        Box::new(|c| gauge_plan(c, P_REF, -60f64.to_radians(), 4.83)),
    ));
    // a centre disc re-entering its own groove a revolution's penetration
    // deeper on a tight track (README, "Centre discs in their own grooves")
    v.push((
        "own groove, r = 0.1 m".into(),
        "own",
        Box::new(|c| own_groove_plan(&CutterParams::default(), c, 0.1, P_REF, 2.0 * P_REF)),
    ));
    v
}

fn mean_json(m: &Mean) -> Value {
    json!({
        "force": m.force, "moment": m.moment, "cutting": m.cutting,
        "volume": m.volume, "length": m.length, "steps": m.steps,
        "us_median": m.us_median,
    })
}

/// Every scene at every cell size of `cells_mm`, and the oracle at 1 mm.
fn scene_accuracy(cells_mm: &[f64], oracle: bool) -> Value {
    let mut out = Vec::new();
    for (name, kind, plan) in scene_defs() {
        let t = Instant::now();
        let mut runs = serde_json::Map::new();
        for &c in cells_mm {
            runs.insert(format!("{c}"), mean_json(&plan(c * 1e-3).run()));
        }
        let mut row = json!({"scene": name, "kind": kind, "cells": runs});
        if oracle {
            // the model after the scene's passes, the measured one stopped
            // at 0.1 m, inside the window
            let p = plan(1e-3);
            let n = p.passes.len();
            let legs: Vec<(&dyn Track, f64)> = p
                .passes
                .iter()
                .enumerate()
                .map(|(i, (t, l))| (t.as_ref(), if i + 1 == n { 0.1 } else { *l }))
                .collect();
            let (m, pose, tw) = rolled(&p.prm, &legs);
            let t0 = Instant::now();
            let fast = cutting_force(&pose, &m.contact(&pose, &tw));
            let us_fast = t0.elapsed().as_secs_f64() * 1e6;
            let t0 = Instant::now();
            let brute = cutting_force(&pose, &m.contact_brute(&pose, &tw, &Resolution::default()));
            let ms_brute = t0.elapsed().as_secs_f64() * 1e3;
            row["oracle"] =
                json!({"fast": fast, "brute": brute, "us_fast": us_fast, "ms_brute": ms_brute});
        }
        eprintln!("  {name:<32} ({:.1} s)", t.elapsed().as_secs_f64());
        out.push(row);
    }
    Value::Array(out)
}

/// One timing round: every scene once at 1 mm, one JSON line each (for
/// scripts/speed-vs-error to interleave with the C host).
fn scene_costs() {
    let defs = scene_defs();
    // warm-up, not recorded: the first run in a process pays for page faults
    // and cold caches, and the first scene is the straight cut every ratio
    // divides by
    (defs[0].2)(1e-3).run();
    for (name, _, plan) in defs {
        let m = plan(1e-3).run();
        println!(
            "{}",
            json!({"kind": "core", "scene": name, "us_median": m.us_median, "steps": m.steps})
        );
    }
}

/// Writes one replay file per scene (at 1 mm) for host/kerf_host.c: the
/// face's parameters and, per 1 ms step, the inputs at its start; a step is
/// timed when it ends inside the measured pass's window.
fn host_scenes(dir: &str) {
    std::fs::create_dir_all(dir).unwrap();
    let h = 1e-3;
    for (k, (name, _, plan)) in scene_defs().iter().enumerate() {
        let p = plan(1e-3);
        let r = &p.prm.rock;
        let mut f = format!(
            "# kerf::scenes replay for host/kerf_host.c (examples/speed-vs-error.rs)\nname {name}\n\
param rock.xMin {:e}\nparam rock.xMax {:e}\nparam rock.yMin {:e}\nparam rock.yMax {:e}\n\
param rock.nx {}\nparam rock.ny {}\n",
            r.x_min, r.x_max, r.y_min, r.y_max, r.nx, r.ny
        );
        let n_pass = p.passes.len();
        for (i, (t, len)) in p.passes.iter().enumerate() {
            let n = (len / h).round() as usize;
            for j in 0..n {
                let s = j as f64 * h;
                let (pose, tw) = (t.pose(s), t.twist(s));
                let end = s + h;
                let timed = i + 1 == n_pass && end >= WINDOW.0 - 1e-12 && end <= WINDOW.1 + 1e-12;
                let (q, v, w) = (pose.position, tw.velocity, tw.omega);
                let _ = writeln!(
                    f,
                    "step {} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e}",
                    u8::from(timed),
                    q.x,
                    q.y,
                    q.z,
                    pose.yaw,
                    pose.pitch,
                    pose.roll,
                    v.x,
                    v.y,
                    v.z,
                    w.x,
                    w.y,
                    w.z
                );
            }
        }
        std::fs::write(format!("{dir}/{k:02}.scene"), f).unwrap();
    }
}

fn json_num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.6e}")
    } else {
        "null".into()
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let get = |k: &str| {
        args.iter()
            .position(|a| a == k)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let out = get("--out").unwrap_or_else(|| "target/speed-vs-error/rows.json".into());
    let reps: usize = get("--reps").map_or(5, |s| s.parse().unwrap());
    let quick = args.iter().any(|a| a == "--quick");
    if args.iter().any(|a| a == "--scene-costs") {
        scene_costs();
        return;
    }
    if let Some(dir) = get("--host-scenes") {
        host_scenes(&dir);
        return;
    }
    if args.iter().any(|a| a == "--scenes-only") {
        // the scene table alone (for a look without the settings sweep)
        let cells: &[f64] = if quick {
            &[1.0, 0.5]
        } else {
            &[2.0, 1.0, 0.5, 0.25]
        };
        println!("{}", scene_accuracy(cells, !quick));
        return;
    }
    let t_all = Instant::now();

    let mut settings = vec![kerf("defaults", "defaults", 1.0, 1.0, |_| {})];
    for c in [4.0, 2.0, 0.5, 0.25] {
        settings.push(kerf(&format!("cell {c} mm"), "cell", c, 1.0, |_| {}));
    }
    for n in [3, 5, 17] {
        settings.push(kerf(
            &format!("tip_slices {n}"),
            "tip_slices",
            1.0,
            1.0,
            |p| p.numerics.tip_slices = n,
        ));
    }
    for a in [1.0, 2.0, 8.0] {
        settings.push(kerf(
            &format!("arc_step_cells {a}"),
            "arc_step_cells",
            1.0,
            1.0,
            |p| p.numerics.arc_step_cells = a,
        ));
    }
    for h in [0.1, 10.0, 50.0] {
        settings.push(kerf(&format!("step {h} mm"), "step", 1.0, h, |_| {}));
    }
    for s in [0.1, 1.0, 10.0, 50.0] {
        settings.push(kerf(
            &format!("step 50 mm, sweep_step {s} mm"),
            "sweep_step",
            1.0,
            50.0,
            |p| p.numerics.sweep_step = s * 1e-3,
        ));
    }
    for e in [0.5, 10.0, 50.0] {
        settings.push(kerf(
            &format!("elastic_depth {e} um"),
            "elastic_depth",
            1.0,
            1.0,
            |p| p.numerics.elastic_depth = e * 1e-6,
        ));
    }
    for r in [10.0, 200.0] {
        settings.push(kerf(&format!("p_reg {r} um"), "p_reg", 1.0, 1.0, |p| {
            p.numerics.p_reg = r * 1e-6
        }));
    }
    // combinations towards either end of the trade
    settings.push(kerf("cell 2 mm, tip 5, arc 8", "combo", 2.0, 1.0, |p| {
        p.numerics.tip_slices = 5;
        p.numerics.arc_step_cells = 8.0
    }));
    settings.push(kerf(
        "cell 2 mm, tip 3, arc 8, step 10 mm",
        "combo",
        2.0,
        10.0,
        |p| {
            p.numerics.tip_slices = 3;
            p.numerics.arc_step_cells = 8.0
        },
    ));
    settings.push(kerf("tip 5, arc 8", "combo", 1.0, 1.0, |p| {
        p.numerics.tip_slices = 5;
        p.numerics.arc_step_cells = 8.0
    }));
    settings.push(kerf("cell 0.5 mm, tip 17, arc 2", "combo", 0.5, 1.0, |p| {
        p.numerics.tip_slices = 17;
        p.numerics.arc_step_cells = 2.0
    }));
    settings.push(baseline(1.0, 181, 5));
    settings.push(baseline(1.0, 361, 9));
    settings.push(baseline(1.0, 1801, 17));
    // the same without the friction of eqs 55-60 (read at f_p, where a rolling
    // rim slips): what the mean-triangle-normal direction alone gives
    let mut nf = baseline(1.0, 1801, 17);
    nf.label = "thesis baseline 1801 x 17, 1 mm, mu = 0".into();
    nf.group = "baseline-nofriction";
    nf.params.friction.mu = 0.0;
    settings.push(nf);
    if !quick {
        settings.push(baseline(0.5, 1801, 17));
    }
    let reference = kerf("reference (converged)", "reference", 0.25, 1.0, |p| {
        p.numerics.tip_slices = 17;
        p.numerics.arc_step_cells = 1.0;
        p.numerics.sweep_step = 0.5e-3;
    });
    if quick {
        settings.retain(|s| {
            matches!(
                s.group,
                "defaults" | "cell" | "baseline" | "baseline-nofriction"
            )
        });
    }

    eprintln!("reference runs (tilt, groove) ...");
    let t = Instant::now();
    let ref_tilt = tilt(&reference).0;
    let ref_groove = groove(&reference);
    eprintln!(
        "  tilt {ref_tilt:?} groove {ref_groove:?} ({:.1} s)",
        t.elapsed().as_secs_f64()
    );

    let (fn_csm, fr_csm) = csm();
    let v_area = groove_area();
    let mut rows = String::from("[\n");
    let all: Vec<Setting> = std::iter::once(reference.clone()).chain(settings).collect();
    // timing rounds: every row once per round, so that load from other
    // processes falls on all rows alike
    let mut us_all: Vec<Vec<f64>> = vec![Vec::new(); all.len()];
    let mut calls_all: Vec<Vec<f64>> = vec![Vec::new(); all.len()];
    let mut flat_res: Vec<Option<(Pass, usize)>> = (0..all.len()).map(|_| None).collect();
    // warm-up (not recorded): page in the allocator and the code
    flat(&all[1]);
    let n_rows = all.len();
    for round in 0..reps.max(1) {
        let t = Instant::now();
        // each round starts elsewhere in the list, so that a slow stretch of
        // a round does not always fall on the same rows
        let shift = round * n_rows / reps.max(1);
        for k in 0..n_rows {
            let idx = (k + shift) % n_rows;
            let s = &all[idx];
            let (p, m) = flat(s);
            us_all[idx].extend_from_slice(&p.us_per_mm);
            calls_all[idx].extend_from_slice(&p.us_per_call);
            flat_res[idx] = Some((p, m));
        }
        eprintln!(
            "timing round {}/{} ({:.1} s)",
            round + 1,
            reps.max(1),
            t.elapsed().as_secs_f64()
        );
    }
    for (idx, s) in all.iter().enumerate() {
        let t = Instant::now();
        let mut us = std::mem::take(&mut us_all[idx]);
        let mut calls = std::mem::take(&mut calls_all[idx]);
        let (fl, memory) = flat_res[idx].take().unwrap();
        let (et, eg, us_tilt) = if s.group == "reference" {
            (0.0, 0.0, f64::NAN)
        } else {
            let (ft, us_tilt) = tilt(s);
            (
                comp_err(ft, ref_tilt),
                comp_err(groove(s), ref_groove),
                us_tilt,
            )
        };
        let e_n = (fl.force[0] - fn_csm).abs() / fn_csm;
        let e_r = (fl.force[1] - fr_csm).abs() / fr_csm;
        let e_s = fl.force[2].abs() / fn_csm;
        let v_exp = v_area * fl.window_len;
        let e_v = (fl.window_volume - v_exp).abs() / v_exp;
        let q = [0.5, 0.25, 0.75, 0.0, 1.0].map(|q| quantile(&mut us, q));
        let call_med = quantile(&mut calls, 0.5);
        let n = &s.params.numerics;
        let (na, ny) = s.baseline.map_or((0, 0), |b| (b.n_alpha, b.n_y));
        eprintln!(
            "[{}/{}] {:40} N {:.2e} R {:.2e} S {:.2e} V {:.2e} tilt {:.2e} groove {:.2e}  {:.0} us/mm ({:.1} s)",
            idx + 1,
            all.len(),
            s.label,
            e_n,
            e_r,
            e_s,
            e_v,
            et,
            eg,
            q[0],
            t.elapsed().as_secs_f64()
        );
        let _ = writeln!(
            rows,
            "  {{\"label\": \"{}\", \"group\": \"{}\", \"model\": \"{}\", \"cell_mm\": {}, \"tip_slices\": {}, \
\"arc_step_cells\": {}, \"sweep_step_mm\": {}, \"step_mm\": {}, \"n_alpha\": {na}, \"n_y\": {ny}, \
\"elastic_depth_um\": {}, \"p_reg_um\": {}, \"nodes\": {}, \"normal\": {}, \"rolling\": {}, \"side\": {}, \"err_normal\": {}, \"err_rolling\": {}, \
\"err_side\": {}, \"err_volume\": {}, \"err_tilt\": {}, \"err_groove\": {}, \"us_median\": {}, \
\"us_p25\": {}, \"us_p75\": {}, \"us_min\": {}, \"us_max\": {}, \"us_per_call\": {}, \"us_tilt_median\": {}, \"samples\": {}, \
\"memory_bytes\": {memory}}}{}",
            s.label,
            s.group,
            if s.baseline.is_some() { "baseline" } else { "kerf" },
            s.cell_mm,
            n.tip_slices,
            n.arc_step_cells,
            n.sweep_step * 1e3,
            s.step_mm,
            n.elastic_depth * 1e6,
            n.p_reg * 1e6,
            s.params.rock.nx * s.params.rock.ny,
            json_num(fl.force[0]),
            json_num(fl.force[1]),
            json_num(fl.force[2]),
            json_num(e_n),
            json_num(e_r),
            json_num(e_s),
            json_num(e_v),
            json_num(et),
            json_num(eg),
            json_num(q[0]),
            json_num(q[1]),
            json_num(q[2]),
            json_num(q[3]),
            json_num(q[4]),
            json_num(call_med),
            json_num(us_tilt),
            us.len(),
            if idx + 1 < all.len() { "," } else { "" }
        );
    }
    rows.push(']');

    // cost against the size of the face (1 mm cells, reference cut)
    eprintln!("face scaling ...");
    let res = BaselineResolution {
        n_alpha: 361,
        n_y: 9,
    };
    let (k_steps, b_steps) = if quick { (100, 5) } else { (300, 20) };
    let faces = [
        ("kerf", 1.0, face_cost(1.0, k_steps, None, reps)),
        ("kerf", 10.0, face_cost(10.0, k_steps, None, reps)),
        (
            "baseline 361 x 9",
            1.0,
            face_cost(1.0, b_steps, Some(res), 1),
        ),
        ("baseline 361 x 9", 10.0, face_cost(10.0, 3, Some(res), 1)),
    ];
    let mut fj = String::from("[\n");
    for (k, (m, w, q)) in faces.iter().enumerate() {
        eprintln!("  {m} {w} m x {w} m: median {:.0} us", q[0]);
        let _ = writeln!(
            fj,
            "  {{\"model\": \"{m}\", \"face_m2\": {}, \"us_median\": {}, \"us_p25\": {}, \"us_p75\": {}, \"us_min\": {}, \"us_max\": {}}}{}",
            w * w,
            json_num(q[0]),
            json_num(q[1]),
            json_num(q[2]),
            json_num(q[3]),
            json_num(q[4]),
            if k + 1 < faces.len() { "," } else { "" }
        );
    }
    fj.push(']');

    // the cutterhead's scenes, per component, against the converged cells
    // and the oracle
    eprintln!("scenes ...");
    let cells: &[f64] = if quick {
        &[1.0, 0.5]
    } else {
        &[2.0, 1.0, 0.5, 0.25]
    };
    let scenes = scene_accuracy(cells, true);

    let (fnn, frr) = csm();
    let doc = format!(
        "{{\n\"csm\": {{\"normal\": {}, \"rolling\": {}, \"groove_area\": {}}},\n\"reps\": {reps},\n\
\"reference\": {{\"tilt\": [{}, {}, {}], \"groove\": [{}, {}, {}]}},\n\
\"scenes\": {scenes},\n\
\"faces\": {fj},\n\"rows\": {rows},\n\"wall_s\": {:.1}\n}}\n",
        json_num(fnn),
        json_num(frr),
        json_num(v_area),
        json_num(ref_tilt[0]),
        json_num(ref_tilt[1]),
        json_num(ref_tilt[2]),
        json_num(ref_groove[0]),
        json_num(ref_groove[1]),
        json_num(ref_groove[2]),
        t_all.elapsed().as_secs_f64()
    );
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir).unwrap();
    }
    std::fs::write(&out, doc).unwrap();
    eprintln!("wrote {out} in {:.0} s", t_all.elapsed().as_secs_f64());
}

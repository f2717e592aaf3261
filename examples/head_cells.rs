//! The cutterhead's speed against its error as the cells and the sweep step
//! coarsen: the layout's head bores from the steady start (`p_rev` per
//! revolution at `rpm`, 1 ms steps) for `steps` steps at each setting
//! `cell_mm:sweep_mm` (`cell_mm:sweep_mm:whole`: every cut takes the
//! disc's whole front arc, `numerics.cut_ahead`; `...:sN`: `N` tip slices,
//! `numerics.tip_slices`; `...:rX`: side-face bands `X` cells wide,
//! `numerics.ring_step_cells`); each setting's mean thrust, torque and per-disc
//! loads are compared with the first setting's (the reference).
//! `cargo run --release --example head_cells -- layouts/reference-9.72m.json 300 0.5:0.5 1:1 2:2`
//! (docs/head.md, "Gauge cutters on curved tracks"). Prints one row a
//! setting: median wall ms per step (RAYON_NUM_THREADS threads; at 1 ms
//! steps also the wall seconds per machine second), mean thrust and torque
//! with their errors, and the largest error of a disc's mean normal and side
//! force, relative to that disc's mean normal force. `DETAIL=1` adds every
//! disc's mean forces against the reference's (stderr). `DISCS=a-b` keeps
//! only the layout's cutters `a..=b` (numbered from 0), on a face sized for
//! them.
use kerf::core::head::{default_params, DiscSpec, Head};
use kerf::core::{layout, Pose, Twist};
use std::time::Instant;

struct Run {
    ms: f64,
    thrust: f64,
    torque: f64,
    normal: Vec<f64>,
    side: Vec<f64>,
}

/// Cell, sweep step, whole cuts, tip slices and ring step (`None`: the
/// default).
type Setting = (f64, f64, bool, Option<usize>, Option<f64>);

fn run(
    file: &str,
    (cell, sweep, whole, slices, rings): Setting,
    steps: usize,
    rpm: f64,
    p_rev: f64,
) -> Run {
    let mut lay = layout::load(std::path::Path::new(file)).unwrap();
    if let Ok(r) = std::env::var("DISCS") {
        // a range of the layout's cutters alone, on a face sized for them
        let (a, b) = r.split_once('-').expect("DISCS=first-last");
        let (a, b): (usize, usize) = (a.parse().unwrap(), b.parse().unwrap());
        lay.cutters = lay.cutters[a..=b].to_vec();
    }
    let mut p = default_params(&lay, cell);
    p.numerics.sweep_step = sweep;
    p.numerics.cut_ahead = whole;
    if let Some(n) = slices {
        p.numerics.tip_slices = n;
    }
    if let Some(r) = rings {
        p.numerics.ring_step_cells = r;
    }
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let n = specs.len();
    let mut head = Head::new(p, specs).unwrap();
    head.steady_start(p_rev).unwrap();
    let w = rpm * std::f64::consts::TAU / 60.0;
    let twist = Twist::boring(w, p_rev);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut times = Vec::with_capacity(steps);
    let mut r = Run {
        ms: 0.0,
        thrust: 0.0,
        torque: 0.0,
        normal: vec![0.0; n],
        side: vec![0.0; n],
    };
    for _ in 0..steps {
        let t = Instant::now();
        pose = head.advance_head(&pose, &twist, 1e-3).unwrap();
        let o = head.evaluate_head(&pose, &twist).unwrap();
        times.push(t.elapsed().as_secs_f64());
        r.thrust += o.thrust / steps as f64;
        r.torque += o.torque / steps as f64;
        for (k, d) in o.discs.iter().enumerate() {
            r.normal[k] += d.normal_force / steps as f64;
            r.side[k] += d.side_force / steps as f64;
        }
    }
    times.sort_by(f64::total_cmp);
    r.ms = times[steps / 2] * 1e3;
    r
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let file = a.first().map_or("layouts/reference-9.72m.json", |s| s);
    let steps: usize = a.get(1).map_or(300, |s| s.parse().unwrap());
    let settings: Vec<Setting> = if a.len() > 2 {
        a[2..]
            .iter()
            .map(|s| {
                let mut f = s.split(':');
                let mut mm = || {
                    f.next()
                        .expect("cell_mm:sweep_mm[:whole][:sN][:rX]")
                        .parse::<f64>()
                        .unwrap()
                        * 1e-3
                };
                let (c, w) = (mm(), mm());
                let slices = s
                    .split(':')
                    .find_map(|t| t.strip_prefix('s').map(|n| n.parse().unwrap()));
                let rings = s
                    .split(':')
                    .find_map(|t| t.strip_prefix('r').map(|x| x.parse().unwrap()));
                (c, w, s.split(':').any(|t| t == "whole"), slices, rings)
            })
            .collect()
    } else {
        vec![
            (0.5e-3, 0.5e-3, false, None, None),
            (1e-3, 1e-3, false, None, None),
            (2e-3, 2e-3, false, None, None),
        ]
    };
    let (rpm, p_rev) = (3.0, 0.006);
    println!(
        "{file}: {steps} steps of 1 ms from the steady start ({rpm} rpm, {} mm/rev)",
        p_rev * 1e3
    );
    println!(
        "| cells mm | sweep mm | ms per step | thrust kN | err | torque kN m | err | disc F_N err, max | disc F_S err, max |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut reference: Option<Run> = None;
    for setting in settings {
        let r = run(file, setting, steps, rpm, p_rev);
        let (cell, sweep, whole, slices, rings) = setting;
        let (e_t, e_q, e_n, e_s) = match &reference {
            None => (0.0, 0.0, 0.0, 0.0),
            Some(f) => {
                let worst = |a: &[f64], b: &[f64]| {
                    a.iter()
                        .zip(b)
                        .zip(&f.normal)
                        .map(|((x, y), n)| (x - y).abs() / n.abs().max(1.0))
                        .fold(0.0, f64::max)
                };
                (
                    (r.thrust - f.thrust) / f.thrust,
                    (r.torque - f.torque) / f.torque,
                    worst(&r.normal, &f.normal),
                    worst(&r.side, &f.side),
                )
            }
        };
        let mut sweep = format!("{}", sweep * 1e3);
        if whole {
            sweep += ", whole cuts";
        }
        if let Some(n) = slices {
            sweep += &format!(", {n} tip slices");
        }
        if let Some(r) = rings {
            sweep += &format!(", side-face bands {r} cells wide");
        }
        println!(
            "| {} | {} | {:.2} | {:.0} | {:+.2} % | {:.0} | {:+.2} % | {:.2} % | {:.2} % |",
            cell * 1e3,
            sweep,
            r.ms,
            r.thrust / 1e3,
            100.0 * e_t,
            r.torque / 1e3,
            100.0 * e_q,
            100.0 * e_n,
            100.0 * e_s
        );
        if let (Some(f), Ok(_)) = (&reference, std::env::var("DETAIL")) {
            for k in 0..r.normal.len() {
                eprintln!(
                    "disc {k}: F_N {:.1} / {:.1} kN, F_S {:.2} / {:.2} kN",
                    r.normal[k] / 1e3,
                    f.normal[k] / 1e3,
                    r.side[k] / 1e3,
                    f.side[k] / 1e3
                );
            }
        }
        reference.get_or_insert(r);
    }
}

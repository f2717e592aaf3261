//! The contact's start search passes over runs of rim samples that lie
//! above every node of the cells under them
//! (`contact_cutter_heightmap::RimCircle::out_of_rock`). Held here against
//! the search that reads the rock at every sample
//! (`numerics.search_every_sample`): every output of every step, and every
//! contact at poses swept across old grooves, must be the same bit for bit.
//! The skip is a bound, not an approximation: any difference fails.
//!
//! Likewise a moving disc's circles (rim slices, side-face rings, flank
//! bands) are walked only on the sides that drive into the rock somewhere
//! within their reach (their other arcs carry nothing), and the edge
//! search across the tip asks a rolling disc's circles about their driving
//! side alone, held against walking and asking every side
//! (`numerics.walk_every_side`).

use kerf::core::{Model, Pose, Twist};
use kerf::scenes::*;

/// Every step's outputs (Debug: full precision, the sign of zero) of the
/// plan's passes.
fn outputs(plan: &Plan, every: bool) -> Vec<String> {
    outputs_with(plan, |n| n.search_every_sample = every)
}

/// [`outputs`] with the plan's numerics set by `set`.
fn outputs_with(plan: &Plan, set: impl Fn(&mut kerf::core::params::Numerics)) -> Vec<String> {
    let mut prm = plan.prm.clone();
    set(&mut prm.numerics);
    let mut m = Model::new(prm).unwrap();
    let mut out = Vec::new();
    for (t, len) in &plan.passes {
        let n = (len / 1e-3).round() as usize;
        for k in 0..=n {
            let s = k as f64 * 1e-3;
            let (pose, tw) = (t.pose(s), t.twist(s));
            m.commit(&pose, &tw, if k == 0 { 0.0 } else { 1e-3 })
                .unwrap();
            out.push(format!("{:?}", m.evaluate(&pose, &tw).unwrap()));
        }
    }
    out
}

fn same_steps(name: &str, plan: Plan) {
    same(name, outputs(&plan, true), outputs(&plan, false));
}

/// Every step of `a` (the exhaustive run) and `b` (the fast one) the same.
fn same(name: &str, a: Vec<String>, b: Vec<String>) {
    assert_eq!(a.len(), b.len());
    let differ: Vec<usize> = (0..a.len()).filter(|&k| a[k] != b[k]).collect();
    if let Some(&k) = differ.first() {
        panic!(
            "{name}: {} of {} steps differ; step {k}:\n  exhaustive: {}\n  skipping:   {}",
            differ.len(),
            a.len(),
            a[k],
            b[k]
        );
    }
}

#[test]
fn passes_beside_old_grooves_are_the_same_bit_for_bit() {
    for d in [1.0, 2.0, 4.0, 8.0, 12.0] {
        same_steps(
            &format!("beside {d} mm"),
            beside_plan(1e-3, P_REF, d * 1e-3),
        );
    }
    same_steps(
        "beside 3 mm, 0.5 mm cells",
        beside_plan(0.5e-3, P_REF, 3e-3),
    );
}

#[test]
fn fresh_tilted_and_curved_passes_are_the_same_bit_for_bit() {
    same_steps("straight", fresh_plan(1e-3, P_REF, 0.0));
    for g in [10.0f64, 30.0, 60.0] {
        same_steps(
            &format!("tilted {g}"),
            fresh_plan(1e-3, P_REF, g.to_radians()),
        );
    }
    for r in [0.2, 0.5] {
        same_steps(&format!("lap {r} m"), lap_plan(1e-3, P_REF, r, false));
        same_steps(&format!("re-roll {r} m"), lap_plan(1e-3, P_REF, r, true));
    }
    same_steps(
        "gauge 60",
        gauge_plan(1e-3, P_REF, (-60f64).to_radians(), 4.83),
    );
}

/// Rolling discs (their rim's trailing side drives nowhere), gauge discs
/// turning either way on curved tracks (their side faces shave the wall on
/// one side of the lowest point), re-rolls of a groove, passes beside one
/// and a tilted lap of a tight track: every step's outputs the same bit for
/// bit whether or not the non-driving sides are walked. (Leaving out the
/// driving sides instead fails this test; the straight cut takes 28 % fewer
/// instructions, `examples/scene_cost` under callgrind.)
#[test]
fn sides_that_drive_nowhere_change_nothing_when_left_out() {
    let every = |n: &mut kerf::core::params::Numerics| n.walk_every_side = true;
    let fast = |_: &mut kerf::core::params::Numerics| {};
    for (name, plan) in [
        (
            "gauge -60",
            gauge_plan(1e-3, P_REF, (-60f64).to_radians(), 4.83),
        ),
        (
            "gauge +60",
            gauge_plan(1e-3, P_REF, 60f64.to_radians(), 4.83),
        ),
        (
            "gauge -30, 1 m",
            gauge_plan(1e-3, P_REF, (-30f64).to_radians(), 1.0),
        ),
        ("tilted 30", fresh_plan(1e-3, P_REF, 30f64.to_radians())),
        ("straight", fresh_plan(1e-3, P_REF, 0.0)),
        ("lap 0.2 m", lap_plan(1e-3, P_REF, 0.2, false)),
        ("re-roll 0.5 m", lap_plan(1e-3, P_REF, 0.5, true)),
        ("re-roll 0.2 m", lap_plan(1e-3, P_REF, 0.2, true)),
        ("beside 2 mm", beside_plan(1e-3, P_REF, 2e-3)),
        ("beside 4 mm", beside_plan(1e-3, P_REF, 4e-3)),
    ] {
        same(name, outputs_with(&plan, every), outputs_with(&plan, fast));
    }
}

/// The contact of `m`'s face at `pose`, searching every sample and walking
/// every side (`every`) or neither.
fn contact_at(m: &Model, every: bool, pose: &Pose, tw: &Twist) -> String {
    let mut prm = m.params().clone();
    prm.numerics.search_every_sample = every;
    prm.numerics.walk_every_side = every;
    let mut q = Model::new(prm).unwrap();
    q.set_state(&m.state()).unwrap();
    format!("{:?}", q.contact(pose, tw))
}

/// Poses swept across the old grooves of the oracle's scenes (laterally
/// 0-20 mm, lifted and lowered, rolled, yawed), where the rim grazes old
/// floors and walls: each contact the same bit for bit, with both shortcuts
/// or neither.
#[test]
fn contacts_swept_across_old_grooves_are_the_same_bit_for_bit() {
    let mut checked = 0;
    let mut touching = 0;
    for (name, m, pose, tw) in oracle_scenes(1e-3) {
        for k in 0..=40 {
            let dy = 0.5e-3 * k as f64;
            for (dz, roll, yaw) in [
                (0.0, 0.0, 0.0),
                (1.5e-3, 0.0, 0.0),
                (-2e-3, 0.0, 0.0),
                (0.0, 0.3, 0.0),
                (0.0, 0.0, 0.2),
            ] {
                let mut p = pose;
                p.position.y += dy;
                p.position.z += dz;
                p.roll += roll;
                p.yaw += yaw;
                let a = contact_at(&m, true, &p, &tw);
                let b = contact_at(&m, false, &p, &tw);
                assert_eq!(a, b, "{name}, dy {dy}, dz {dz}, roll {roll}, yaw {yaw}");
                checked += 1;
                touching += usize::from(a.contains("in_contact: true"));
            }
        }
    }
    // (the sweep reaches both contact and lift-off)
    assert!(
        touching > checked / 2 && touching < checked,
        "{touching} of {checked}"
    );
}

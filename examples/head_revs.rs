//! The cost of a cutterhead's steps revolution by revolution, boring from
//! flat rock: the demo head (`layouts/demo-1.2m.json`) at 10 rpm and 6 mm a
//! revolution, 720 Co-Simulation steps a revolution, one disc-step's wall
//! time and the mean thrust for each revolution:
//! `cargo run --release --example head_revs -- [CHIPS 0|1] [REVS]`
//! (chips on and 4 revolutions by default). The last revolution runs in
//! `measured_rev` alone, so that
//! `valgrind --tool=callgrind --toggle-collect='*measured_rev*'` counts its
//! instructions (set RAYON_NUM_THREADS=1).
use kerf::core::head::{default_params, DiscSpec, Head};
use kerf::core::{layout, Pose, Twist};
use std::time::Instant;

const PER_REV: usize = 720;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let chips = a.first().is_none_or(|s| s == "1");
    let revs: usize = a.get(1).map_or(4, |s| s.parse().unwrap());
    let lay = layout::load(std::path::Path::new("layouts/demo-1.2m.json")).unwrap();
    let mut p = default_params(&lay, 1e-3);
    p.chipping.enabled = chips;
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let n = specs.len();
    let mut head = Head::new(p, specs).unwrap();
    let rpm = 10.0;
    let w = rpm * 2.0 * std::f64::consts::PI / 60.0;
    let twist = Twist::boring(w, 0.006);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let h = 60.0 / rpm / PER_REV as f64;
    for r in 0..revs {
        let t = Instant::now();
        let thrust = if r + 1 == revs {
            measured_rev(&mut head, &mut pose, &twist, h)
        } else {
            (0..PER_REV)
                .map(|_| step(&mut head, &mut pose, &twist, h))
                .sum()
        };
        let us = t.elapsed().as_secs_f64() * 1e6 / (PER_REV * n) as f64;
        println!(
            "revolution {}: {us:.1} us a disc-step, mean thrust {:.1} kN",
            r + 1,
            thrust / PER_REV as f64 / 1e3
        );
    }
}

/// One step: cut along it, then evaluate; returns the thrust.
fn step(head: &mut Head, pose: &mut Pose, twist: &Twist, h: f64) -> f64 {
    *pose = head.advance_head(pose, twist, h).unwrap();
    head.evaluate_head(pose, twist).unwrap().thrust
}

#[inline(never)]
fn measured_rev(head: &mut Head, pose: &mut Pose, twist: &Twist, h: f64) -> f64 {
    (0..PER_REV).map(|_| step(head, pose, twist, h)).sum()
}

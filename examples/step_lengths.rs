//! Co-Simulation steps of different lengths on the same scenes:
//! `cargo run --release --example step_lengths [-- PLUNGE_SPEED_M_PER_S]`.
//! - Rolling (a fresh straight cut, tilted 30 deg, 4 mm beside a groove):
//!   the mean forces over the window with steps of 1, 0.5, 0.25 and 0.1 mm
//!   of travel (they agree: the leading arc meets uncut rock whatever the
//!   step).
//! - Plunging straight down (20 mm/s, or the speed given) from 1 mm above the face: the normal
//!   force against the CSM F_N(p) when every 1 ms step cuts (20 um a step)
//!   and when the cuts come once a millimetre of plunge (as Model Exchange
//!   commits them). A plunging disc's cut stops half a sweep step short
//!   (`cut_cutter_heightmap::plunge_lag`), so the two agree and, deeper
//!   than 1 mm, meet the CSM F_N(p); README, "Contact law: known gaps".
use kerf::core::csm::contact_angle;
use kerf::core::{Model, Params, Pose, Twist};
use kerf::scenes::*;

fn main() {
    for (name, plan) in [
        ("straight", fresh_plan(1e-3, P_REF, 0.0)),
        ("tilted 30", fresh_plan(1e-3, P_REF, 30f64.to_radians())),
        ("beside 4 mm", beside_plan(1e-3, P_REF, 4e-3)),
    ] {
        for h in [1e-3f64, 0.5e-3, 0.25e-3, 0.1e-3] {
            let mut m = Model::new(plan.prm.clone()).unwrap();
            let (last, first) = plan.passes.split_last().unwrap();
            for (t, len) in first {
                roll(&mut m, t.as_ref(), *len, 1e-3, 0.0, 0.0);
            }
            let t = last.0.as_ref();
            let (mut f, mut k) = ([0.0; 3], 0);
            for i in 0..(PASS / h).round() as usize {
                let s = i as f64 * h;
                let end = m.advance(&t.pose(s), &t.twist(s), h).unwrap();
                if (WINDOW.0..=WINDOW.1).contains(&(s + h)) {
                    let o = m.evaluate(&end, &t.twist(s + h)).unwrap();
                    f[0] += o.normal_force;
                    f[1] += o.rolling_force;
                    f[2] += o.side_force;
                    k += 1;
                }
            }
            let k = k as f64;
            println!(
                "{name:<12} step {:.2} mm: N {:.3} R {:.3} S {:.3} kN",
                h * 1e3,
                f[0] / k / 1e3,
                f[1] / k / 1e3,
                f[2] / k / 1e3
            );
        }
    }
    // the plunge speed [m/s] (argument; 20 mm/s by default), 1 ms steps
    let v: f64 = std::env::args().nth(1).map_or(0.02, |a| {
        a.parse()
            .expect("the argument is the plunge speed in m/s, e.g. 0.002")
    });
    let p = Params::default();
    let r = p.cutter.radius;
    let tw = Twist::new([0.0, 0.0, -v], [0.0; 3]);
    let start = Pose::new(0.5, 0.0, r + 1e-3, 0.0, 0.0, 0.0);
    let (mut cs, mut me) = (Model::new(p.clone()).unwrap(), Model::new(p).unwrap());
    cs.commit(&start, &tw, 0.0).unwrap();
    me.commit(&start, &tw, 0.0).unwrap();
    let mut pose = start;
    // steps a millimetre of plunge takes, and the depths printed: every
    // 0.04 mm from 0.32 to 1.6 mm, then every 0.2 mm to 3 mm
    let per_mm = (1e-3 / (v * 1e-3)).round() as usize;
    let at = |d: f64| {
        let q = d * 1e3;
        let on = |s: f64| ((q / s).round() * s - q).abs() < 1e-6;
        (0.32 - 1e-9..=1.6 + 1e-9).contains(&q) && on(0.04) || q > 1.6 && on(0.2)
    };
    println!(
        "plunge at {} mm/s: depth, N cutting every 1 ms step, N cutting once a mm, CSM F_N [kN]",
        v * 1e3
    );
    let mut worst: f64 = 0.0;
    for k in 1..=4 * per_mm {
        pose = cs.advance(&pose, &tw, 1e-3).unwrap();
        let depth = r - pose.position.z;
        if k % per_mm == 0 {
            me.commit(&pose, &tw, per_mm as f64 * 1e-3).unwrap();
        }
        if depth < 0.3e-3 {
            continue;
        }
        let a = cs.evaluate(&pose, &tw).unwrap().normal_force;
        let law = cs.law();
        let beta = law.resultant_angle(contact_angle(r, depth));
        let csm = law.force(depth) * beta.cos();
        if depth > 1e-3 {
            worst = worst.min(a / csm - 1.0);
        }
        if at(depth) {
            let b = me.evaluate(&pose, &tw).unwrap().normal_force;
            println!(
                "{:.2} mm {:8.3} {:8.3} {:8.3}",
                depth * 1e3,
                a / 1e3,
                b / 1e3,
                csm / 1e3
            );
        }
    }
    println!(
        "cutting every step, deeper than 1 mm: at worst {:+.1} % of the CSM F_N",
        worst * 1e2
    );
}

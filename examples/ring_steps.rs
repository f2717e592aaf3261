//! The side-face rings' spacing (`numerics.ringStepCells`) against the
//! error it makes, on the scenes where a side face carries load: gauge
//! cutters tilted 60 and 30 degrees turning on a 4.83 m track (`cargo run
//! --release --example ring_steps`, under a second after the build). Each
//! at the default 1 mm cells with rings 0.25 to 4 cells apart: the mean
//! cutter-frame force (normal, rolling, side) of its measured pass, and the
//! largest difference of a force component (in % of the fresh straight
//! cut's normal force F_N) and of a moment component (in % of F_N R) from
//! the converged reference (0.25 mm cells, rings at the default half cell,
//! at most 24 a face) and from the default spacing at 1 mm. The cost of
//! each spacing: `tools/instr_per_step.py scene "gauge -60 4.83 1"`.
use kerf::scenes::*;

fn main() {
    let fnorm = fresh(1e-3, P_REF, 0.0).force[0];
    let fr = fnorm * kerf::core::Params::default().cutter.radius;
    println!(
        "| scene | ring step [cells] | normal (N) | rolling (N) | side (N) | force, moment vs 0.25 mm cells [% F_N, % F_N R] | vs 0.5 cell at 1 mm |"
    );
    println!("|---|---|---|---|---|---|---|");
    for tilt in [-60.0f64, -30.0] {
        let name = format!("gauge {}°, r = 4.83 m", -tilt);
        let reference = gauge_plan(0.25e-3, P_REF, tilt.to_radians(), 4.83).run();
        let mut plan = gauge_plan(1e-3, P_REF, tilt.to_radians(), 4.83);
        let runs: Vec<(f64, Mean)> = [0.25, 0.5, 1.0, 1.5, 2.0, 4.0]
            .iter()
            .map(|&r| {
                plan.prm.numerics.ring_step_cells = r;
                (r, plan.run())
            })
            .collect();
        let default = &runs.iter().find(|(r, _)| *r == 0.5).expect("the default").1;
        let worst = |a: &[f64; 3], b: &[f64; 3], scale: f64| {
            (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max) * 100.0 / scale
        };
        let errs = |m: &Mean, r: &Mean| {
            format!(
                "{:.2} %, {:.2} %",
                worst(&m.force, &r.force, fnorm),
                worst(&m.moment, &r.moment, fr)
            )
        };
        let f = reference.force;
        println!(
            "| {name}, 0.25 mm cells | 0.5 | {:.0} | {:.0} | {:.0} | 0 (ref) | |",
            f[0], f[1], f[2]
        );
        for (r, m) in &runs {
            let f = m.force;
            println!(
                "| {name} | {r} | {:.0} | {:.0} | {:.0} | {} | {} |",
                f[0],
                f[1],
                f[2],
                errs(m, &reference),
                errs(m, default),
            );
        }
    }
}

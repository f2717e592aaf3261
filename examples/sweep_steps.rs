//! The sweep step's part in the error on the scenes that turn: `cargo run
//! --release --example sweep_steps`. Each scene (curved 0.2 and 0.5 m laps,
//! fresh and re-rolled; the 60° gauge cutter on its 4.83 m track) at the
//! default 1 mm cells, with `numerics.sweepStep` of 1 (the default), 0.5,
//! 0.25 and 0.1 mm: the mean cutter-frame force (normal, rolling, side) of
//! its measured pass, the largest component's difference from the 0.1 mm
//! run in % of the fresh straight cut's normal force (at 1 mm cells).
use kerf::scenes::*;

fn main() {
    let fnorm = fresh(1e-3, P_REF, 0.0).force[0];
    let scenes: Vec<(&str, Plan)> = vec![
        ("curved 0.2 m, fresh lap", lap_plan(1e-3, P_REF, 0.2, false)),
        ("curved 0.2 m, re-roll", lap_plan(1e-3, P_REF, 0.2, true)),
        ("curved 0.5 m, fresh lap", lap_plan(1e-3, P_REF, 0.5, false)),
        ("curved 0.5 m, re-roll", lap_plan(1e-3, P_REF, 0.5, true)),
        (
            "gauge 60°, r = 4.83 m",
            gauge_plan(1e-3, P_REF, -60f64.to_radians(), 4.83),
        ),
    ];
    println!("| scene | sweep step | normal (N) | rolling (N) | side (N) | vs 0.1 mm |");
    println!("|---|---|---|---|---|---|");
    for (name, mut plan) in scenes {
        let runs: Vec<(f64, Mean)> = [1.0, 0.5, 0.25, 0.1]
            .iter()
            .map(|&s| {
                plan.prm.numerics.sweep_step = s * 1e-3;
                (s, plan.run())
            })
            .collect();
        let fine = runs.last().unwrap().1.force;
        for (s, m) in &runs {
            let err = (0..3)
                .map(|i| (m.force[i] - fine[i]).abs())
                .fold(0.0, f64::max);
            println!(
                "| {name} | {s} mm | {:.0} | {:.0} | {:.0} | {:.2} % |",
                m.force[0],
                m.force[1],
                m.force[2],
                100.0 * err / fnorm,
            );
        }
    }
}

//! One scene of `kerf::scenes` for an instruction-count profile:
//! `valgrind --tool=callgrind target/release/examples/scene_cost curved 0.5`
//! (scenes: `straight`, `tilted DEG`, `curved R`, `reroll R`, `beside D_MM`,
//! `gauge DEG R [RING_STEP]` (side-face rings `RING_STEP` cells apart,
//! `numerics.ringStepCells`; 0.5 by default),
//! `deeper R D1 D2`: a 19 in disc's second lap of an R track, D2 deep, in
//! the groove of a first lap D1 deep, as a head's face disc runs),
//! `own R`: the report's centre disc in its own groove (`own_groove_plan`,
//! the thesis's disc 7.6 mm deep in its 3.8 mm groove on an R track).
use kerf::scenes::*;
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let x = |i: usize, d: f64| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let plan = match a.first().map(String::as_str).unwrap_or("straight") {
        "tilted" => fresh_plan(1e-3, P_REF, x(1, 30.0).to_radians()),
        "curved" => lap_plan(1e-3, P_REF, x(1, 0.5), false),
        "beside" => beside_plan(1e-3, P_REF, x(1, 4.0) * 1e-3),
        "reroll" => lap_plan(1e-3, P_REF, x(1, 0.5), true),
        "gauge" => {
            let mut p = gauge_plan(1e-3, P_REF, x(1, -60f64).to_radians(), x(2, 4.83));
            p.prm.numerics.ring_step_cells = x(3, 0.5);
            p
        }
        "deeper" => {
            let first = Some(x(2, 0.006)).filter(|&d| d > 0.0);
            laps_plan(&head_disc(), 1e-3, x(1, 2.0), first, x(3, 0.012))
        }
        "own" => {
            let c = kerf::core::Params::default().cutter;
            own_groove_plan(&c, 1e-3, x(1, 0.1), P_REF, 2.0 * P_REF)
        }
        _ => fresh_plan(1e-3, P_REF, 0.0),
    };
    let m = plan.run();
    println!("{:?} {:.1} us", m.cutting, m.us_median);
}

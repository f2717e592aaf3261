//! One disc of a layout, alone on the face, through part of a revolution
//! from the steady start (3 rpm, 6 mm/rev, 1 ms steps, sweep step = cell):
//! its mean normal and side force in 18 bins of head angle. A disc's track
//! crosses the grid at every angle as the head turns; what the physics
//! gives does not depend on it, so the bins should agree
//! (docs/head.md, "Tilted discs across the grid").
//! `cargo run --release --example head_disc_angle -- [CELL_MM STEPS DISC LAYOUT]`
//! (default 1 5400 55 layouts/reference-9.72m.json: the reference head's
//! outer gauge disc, 60 deg, through 97 deg of head angle).
use kerf::core::head::{default_params, DiscSpec, Head};
use kerf::core::{layout, Pose, Twist};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let cell = a.first().map_or(1.0, |s| s.parse::<f64>().unwrap()) * 1e-3;
    let steps: usize = a.get(1).map_or(5400, |s| s.parse().unwrap());
    let k: usize = a.get(2).map_or(55, |s| s.parse().unwrap());
    let file = a.get(3).map_or("layouts/reference-9.72m.json", |s| s);
    let mut lay = layout::load(std::path::Path::new(file)).unwrap();
    lay.cutters = vec![lay.cutters[k].clone()];
    let mut p = default_params(&lay, cell);
    p.numerics.sweep_step = cell;
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let mut head = Head::new(p, specs).unwrap();
    let (rpm, p_rev) = (3.0, 0.006);
    head.steady_start(p_rev).unwrap();
    let w = rpm * std::f64::consts::TAU / 60.0;
    let twist = Twist::boring(w, p_rev);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    println!(
        "{file} disc {k} (track {} m, tilt {} deg), {} mm cells; head angle at the bin's end",
        lay.cutters[0].track,
        lay.cutters[0].tilt_deg,
        cell * 1e3
    );
    let bin = (steps / 18).max(1);
    let (mut sn, mut ss, mut c) = (0.0, 0.0, 0);
    for i in 0..steps {
        pose = head.advance_head(&pose, &twist, 1e-3).unwrap();
        let o = head.evaluate_head(&pose, &twist).unwrap();
        sn += o.discs[0].normal_force;
        ss += o.discs[0].side_force;
        c += 1;
        if c == bin {
            println!(
                "angle {:6.1} deg  F_N {:8.2} kN  F_S {:8.2} kN",
                ((i + 1) as f64 * 1e-3 * w).to_degrees(),
                sn / c as f64 / 1e3,
                ss / c as f64 / 1e3
            );
            (sn, ss, c) = (0.0, 0.0, 0);
        }
    }
}

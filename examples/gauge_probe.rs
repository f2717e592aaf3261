//! A gauge cutter's forces against the cell size and the sweep step, without
//! the head: `scenes::gauge`, a disc rolled by ROLL on a track of radius
//! RADIUS (0: straight) through fresh rock DEPTH deep at SPEED. Prints the
//! mean cutter-frame forces (friction left out) and, at the last pose, the
//! rim's and the side face's shares.
//! `cargo run --release --example gauge_probe -- [ROLL_DEG DEPTH_MM RADIUS_M SPEED_M_S FLANK_DEG]`
//! (default -60 6 4.83 1.5 0: the reference head's outer gauge cutter with
//! the thesis's flat-sided section, docs/head.md; FLANK_DEG > 0: the
//! flanked section of docs/flanks.md, whose 0.25 mm row is left out: it
//! asks more of one step than a call may scan).
use kerf::scenes::*;

fn main() {
    let a: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    let arg = |i: usize, d: f64| a.get(i).copied().unwrap_or(d);
    let (tilt, depth, radius, speed) = (
        arg(0, -60.0).to_radians(),
        arg(1, 6.0) * 1e-3,
        arg(2, 4.83),
        arg(3, 1.5),
    );
    let flank = arg(4, 0.0);
    let disc = if flank > 0.0 {
        flanked_cutter(flank)
    } else {
        kerf::core::params::CutterParams::default()
    };
    println!("| cells mm | sweep mm | F_N kN | F_R kN | F_S kN | of which side face and flanks, F_S at the end kN |");
    println!("|---|---|---|---|---|---|");
    for (cell, sweep) in [
        (0.25e-3, 0.25e-3),
        (0.5e-3, 0.5e-3),
        (0.5e-3, 1e-3),
        (1e-3, 1e-3),
        (1e-3, 2e-3),
        (2e-3, 2e-3),
    ] {
        if flank > 0.0 && cell < 0.5e-3 {
            continue;
        }
        let (m, face) = gauge(&disc, cell, sweep, depth, tilt, radius, speed);
        println!(
            "| {} | {} | {:.1} | {:.2} | {:.2} | {:.1} |",
            cell * 1e3,
            sweep * 1e3,
            m.cutting[0] / 1e3,
            m.cutting[1] / 1e3,
            m.cutting[2] / 1e3,
            face[2] / 1e3
        );
    }
}

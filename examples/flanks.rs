//! What flanks change (docs/flanks.md): N/R/S cutting forces on the tilted
//! (10, 30, 60 deg at 3.8 mm) and deep (8, 12 mm, upright) fresh cuts, for
//! the thesis's disc (flank angle 0) and the same disc with 20 and 30 deg
//! flanks, the cost of a step, and the fast contact against the brute-force
//! oracle at the flanked scenes' end poses, and how the flanked scenes
//! converge with the cell size (1, 0.5, 0.25 mm):
//! `cargo run --release --example flanks > docs/flanks-table.md`.
use kerf::core::contact_bruteforce::Resolution;
use kerf::scenes::*;

fn main() {
    let discs = [0.0, 20.0, FLANK_DEG];
    println!(
        "The thesis's disc (R 215.9 mm, T 13 mm, r 12.7 mm) with flank angle f = {:?} deg and hub width {} mm. Fresh cuts at 1 mm cells, 1 m/s, mean over 0.06-0.14 m; cutting forces (no friction) in kN: N normal, R rolling, S side.\n",
        discs,
        HUB_WIDTH * 1e3
    );
    println!("| scene | f | N | R | S | N / flat | S / flat | median us / step |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, depth, roll) in flank_cases() {
        let mut flat = [0.0; 3];
        for f in discs {
            let m = fresh_disc(&flanked_cutter(f), 1e-3, depth, roll);
            let c = m.cutting;
            if f == 0.0 {
                flat = c;
            }
            let ratio = |i: usize| {
                if flat[i].abs() > 1.0 {
                    format!("{:.2}", c[i] / flat[i])
                } else {
                    "-".into()
                }
            };
            println!(
                "| {name} | {f} | {:.1} | {:.2} | {:.2} | {} | {} | {:.0} |",
                c[0] / 1e3,
                c[1] / 1e3,
                c[2] / 1e3,
                ratio(0),
                ratio(2),
                m.us_median
            );
        }
    }
    println!(
        "\nFast contact vs the brute-force oracle, flank angle {FLANK_DEG} deg, end pose of each scene (kN; difference in % of the fresh cut's 60.8 kN normal force):\n"
    );
    println!("| scene | fast N / R / S | oracle N / R / S | diff % N / R / S |");
    println!("|---|---|---|---|");
    for (name, m, pose, tw) in flank_scenes(&flanked_cutter(FLANK_DEG), 1e-3) {
        let f = cutting_force(&pose, &m.contact(&pose, &tw));
        let o = cutting_force(&pose, &m.contact_brute(&pose, &tw, &Resolution::default()));
        let d: Vec<f64> = (0..3).map(|i| (f[i] - o[i]) / 60_795.388 * 100.0).collect();
        println!(
            "| {name} | {:.2} / {:.2} / {:.2} | {:.2} / {:.2} / {:.2} | {:.2} / {:.2} / {:.2} |",
            f[0] / 1e3,
            f[1] / 1e3,
            f[2] / 1e3,
            o[0] / 1e3,
            o[1] / 1e3,
            o[2] / 1e3,
            d[0],
            d[1],
            d[2]
        );
    }
    println!(
        "\nConvergence, flank angle {FLANK_DEG} deg: N / R / S (kN) at 1, 0.5 and 0.25 mm cells, and the largest difference of 1 mm from 0.25 mm in % of 60.8 kN:\n"
    );
    println!("| scene | 1 mm | 0.5 mm | 0.25 mm | 1 mm vs 0.25 mm |");
    println!("|---|---|---|---|---|");
    let fl = flanked_cutter(FLANK_DEG);
    let kn = |c: [f64; 3]| format!("{:.1} / {:.2} / {:.1}", c[0] / 1e3, c[1] / 1e3, c[2] / 1e3);
    let mut cases = flank_cases();
    for g in [0.5f64, 1.0, 1.5, 2.0, 2.5, 3.0] {
        cases.push((format!("tilt {g}"), P_REF, g.to_radians()));
    }
    for (name, depth, roll) in cases {
        let c: Vec<[f64; 3]> = [1e-3, 0.5e-3, 0.25e-3]
            .iter()
            .map(|&cell| fresh_disc(&fl, cell, depth, roll).cutting)
            .collect();
        let e = (0..3)
            .map(|i| (c[0][i] - c[2][i]).abs())
            .fold(0.0, f64::max)
            / 60_795.388
            * 100.0;
        println!(
            "| {name} | {} | {} | {} | {e:.1} |",
            kn(c[0]),
            kn(c[1]),
            kn(c[2])
        );
    }
}

//! What flanks change (docs/flanks.md): N/R/S cutting forces on the tilted
//! (10, 30, 60 deg at 3.8 mm) and deep (8, 12 mm, upright) fresh cuts, for
//! the thesis's disc (flank angle 0) and the same disc with flanks, and the
//! fast contact against the brute-force oracle at the flanked scenes' end
//! poses: `cargo run --release --example flanks` (prints a Markdown table).
use kerf::core::contact_bruteforce::Resolution;
use kerf::scenes::*;

fn main() {
    let flat = flanked_cutter(0.0);
    let fl = flanked_cutter(FLANK_DEG);
    println!(
        "Flanked disc: flank angle {FLANK_DEG} deg, hub width {} mm; otherwise the thesis's disc (R 215.9 mm, T 13 mm, r 12.7 mm). 1 mm cells, 1 m/s, mean over 0.06-0.14 m of a fresh cut; cutting forces (no friction) in kN.\n",
        HUB_WIDTH * 1e3
    );
    println!("| scene | N flat | N flanks | R flat | R flanks | S flat | S flanks |");
    println!("|---|---|---|---|---|---|---|");
    for (name, depth, roll) in flank_cases() {
        let a = fresh_disc(&flat, 1e-3, depth, roll).cutting;
        let b = fresh_disc(&fl, 1e-3, depth, roll).cutting;
        println!(
            "| {name} | {:.1} | {:.1} | {:.2} | {:.2} | {:.2} | {:.2} |",
            a[0] / 1e3,
            b[0] / 1e3,
            a[1] / 1e3,
            b[1] / 1e3,
            a[2] / 1e3,
            b[2] / 1e3
        );
    }
    println!("\nFast contact vs the brute-force oracle, flanked disc, end pose of each scene (kN; difference in % of the fresh cut's 60.8 kN normal force):\n");
    println!("| scene | fast N/R/S | oracle N/R/S | diff % N/R/S |");
    println!("|---|---|---|---|");
    for (name, m, pose, tw) in flank_scenes(&fl, 1e-3) {
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
}

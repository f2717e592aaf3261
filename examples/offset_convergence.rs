//! Convergence with the cell size across every offset beside a groove: a
//! second pass `d` beside a 3.8 mm groove (`kerf::scenes::beside`) for `d`
//! from `D0` to `D1` mm in `N` steps, at 1 mm and 0.5 mm cells against
//! 0.25 mm cells (issue 7: 2 % and 0.5 % of the fresh cut's normal force).
//!
//! Two measures, both in % of the fresh cut's F_N (60.8 kN):
//! - `cut`: the largest difference of the three cutting-force components
//!   (friction left out), as `tests/contact_law.rs`'s convergence tests read;
//! - `out`: the largest of the FMU outputs' three force components and three
//!   moments about the centre (moments over F_N R), as the speed-vs-error
//!   report reads.
//!
//! `cargo run --release --example offset_convergence -- [D0 D1 N] [--json]`
//! (defaults 0 13 130: 0.1 mm steps over the tip width; about 10 s).
//! `--json` prints the summary alone, a JSON object a cell size and
//! measure, for `scripts/speed-vs-error`'s report.

use kerf::scenes::{beside, Mean, P_REF};

const FN: f64 = 60_795.388;
const R: f64 = 0.2159;

fn errors(m: &Mean, r: &Mean) -> (f64, f64) {
    let cut = (0..3)
        .map(|i| (m.cutting[i] - r.cutting[i]).abs())
        .fold(0.0, f64::max)
        / FN;
    let f = (0..3)
        .map(|i| (m.force[i] - r.force[i]).abs())
        .fold(0.0, f64::max)
        / FN;
    let mo = (0..3)
        .map(|i| (m.moment[i] - r.moment[i]).abs())
        .fold(0.0, f64::max)
        / (FN * R);
    (100.0 * cut, 100.0 * f.max(mo))
}

fn main() {
    let json = std::env::args().any(|a| a == "--json");
    let a: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let (d0, d1, n) = (
        a.first().copied().unwrap_or(0.0),
        a.get(1).copied().unwrap_or(13.0),
        a.get(2).copied().unwrap_or(130.0) as usize,
    );
    let cells = [1e-3, 0.5e-3];
    // per cell: every offset's (cut, out) error
    let mut all: Vec<Vec<(f64, f64, f64)>> = vec![Vec::new(); cells.len()];
    if !json {
        println!("  d [mm]   F_N at 0.25 mm [kN]   1 mm: cut / out [%]   0.5 mm: cut / out [%]");
    }
    for k in 0..=n {
        let d = d0 + (d1 - d0) * k as f64 / n.max(1) as f64;
        let r = beside(0.25e-3, P_REF, d * 1e-3);
        let mut line = format!("{d:8.2}   {:19.2}", r.cutting[0] / 1e3);
        for (j, &c) in cells.iter().enumerate() {
            let (cut, out) = errors(&beside(c, P_REF, d * 1e-3), &r);
            all[j].push((d, cut, out));
            line += &format!("   {cut:8.2} / {out:5.2}     ");
        }
        if !json {
            println!("{line}");
        }
    }
    for (j, &c) in cells.iter().enumerate() {
        let target = if j == 0 { 2.0 } else { 0.5 };
        for (name, pick) in [("cut", 1usize), ("out", 2)] {
            let mut v: Vec<(f64, f64)> = all[j]
                .iter()
                .map(|e| (if pick == 1 { e.1 } else { e.2 }, e.0))
                .collect();
            let worst = v
                .iter()
                .copied()
                .fold((0.0, 0.0), |w, e| if e.0 > w.0 { e } else { w });
            let over = v.iter().filter(|e| e.0 > target).count();
            v.sort_by(|x, y| x.0.total_cmp(&y.0));
            let median = v[v.len() / 2].0;
            if json {
                println!(
                    "{{\"cell_mm\": {}, \"measure\": \"{name}\", \"worst_pct\": {:.4}, \
                     \"at_mm\": {:.2}, \"median_pct\": {median:.4}, \"target_pct\": {target}, \
                     \"over\": {over}, \"offsets\": {}, \"from_mm\": {d0}, \"to_mm\": {d1}}}",
                    c * 1e3,
                    worst.0,
                    worst.1,
                    v.len()
                );
                continue;
            }
            println!(
                "{} mm cells, {name}: worst {:.2} % at d = {:.2} mm, median {median:.2} %, \
                 {over} of {} offsets above the issue's {target} %",
                c * 1e3,
                worst.0,
                worst.1,
                v.len()
            );
        }
    }
}

//! The contact on the scenes a cutterhead makes, printed as a table:
//! `cargo run --release --example contact_scenes -- [cell_mm ...]`.
//! Forces are the cutter-frame means of `kerf::scenes` (kN); `W/V` is the
//! rolling work of the cutting force (friction left out) per volume removed,
//! relative to the fresh cut's.
use kerf::scenes::{beside, fresh, reroll, Mean, P_REF};

fn row(name: &str, m: &Mean, fresh: &Mean) {
    let wv = m.rolling_work_per_volume() / fresh.rolling_work_per_volume();
    println!(
        "{name:<18} N {:6.2} R {:6.2} S {:6.2} | cut N {:6.2} R {:6.2} S {:6.2} | V/L {:6.2} mm2  W/V {:5.2} {:6.1} us",
        m.force[0] / 1e3,
        m.force[1] / 1e3,
        m.force[2] / 1e3,
        m.cutting[0] / 1e3,
        m.cutting[1] / 1e3,
        m.cutting[2] / 1e3,
        m.volume / m.length.max(1e-12) * 1e6,
        wv,
        m.us_median
    );
}

fn main() {
    let cells: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse::<f64>().unwrap() * 1e-3)
        .collect();
    let cells = if cells.is_empty() { vec![1e-3] } else { cells };
    for cell in cells {
        println!("--- cells {} mm", cell * 1e3);
        let f = fresh(cell, P_REF, 0.0);
        row("fresh", &f, &f);
        for g in [10.0f64, 20.0, 30.0, 45.0, 60.0] {
            row(
                &format!("tilt {g}"),
                &fresh(cell, P_REF, g.to_radians()),
                &f,
            );
        }
        for d in [2.0, 4.0, 8.0, 13.0] {
            row(
                &format!("beside d={d}mm"),
                &beside(cell, P_REF, d * 1e-3),
                &f,
            );
        }
        row("reroll straight", &reroll(cell, P_REF, None), &f);
        for r in [0.2, 0.5, 1.0] {
            row(&format!("reroll r={r}m"), &reroll(cell, P_REF, Some(r)), &f);
        }
    }
}

//! A cutterhead's centre disc in its own groove on a tight track
//! (`kerf::scenes::own_groove_plan`: the reference head's 19 in disc, a
//! first lap `first` deep, then the same circle `depth` deep), at 1 mm
//! cells or `cell_mm`: the fast contact at 9 (the default), 17 and 33 tip slices against
//! the brute-force oracle (101 slices, 0.05 mm of arc). Prints the mean
//! cutting force (normal / rolling / side) at s = 70, 100 and 130 mm of the
//! measured lap, and the largest component's difference from the oracle's,
//! in % of the oracle's normal force.
//! `cargo run --release --example slice_convergence -- [first_mm depth_mm [cell_mm [thesis]]]`
//! (`thesis`: the thesis's 17 in disc instead of the head's 19 in one)
use kerf::core::contact_bruteforce::Resolution;
use kerf::scenes::{forces_along, head_disc, own_groove_plan};

fn mean(v: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
    let v: Vec<[f64; 3]> = v.collect();
    let k = v.len() as f64;
    [0, 1, 2].map(|i| v.iter().map(|f| f[i]).sum::<f64>() / k)
}

fn main() {
    let a: Vec<f64> = std::env::args()
        .skip(1)
        .take(3)
        .map(|s| s.parse().expect("first_mm depth_mm cell_mm"))
        .collect();
    let (first, depth) = (a.first().map_or(6.0, |v| *v), a.get(1).map_or(12.0, |v| *v));
    let cell = a.get(2).map_or(1.0, |v| *v) * 1e-3;
    // the reference head's disc, or the thesis's (`thesis` as a 4th argument)
    let disc = if std::env::args().nth(4).as_deref() == Some("thesis") {
        kerf::core::params::CutterParams::default()
    } else {
        head_disc()
    };
    let at = [0.07, 0.10, 0.13];
    println!(
        "R = {} mm disc, first lap {first} mm, measured lap {depth} mm deep, {} mm cells; \
         mean cutting force at s = 70, 100, 130 mm [kN]",
        disc.radius * 1e3,
        cell * 1e3
    );
    println!(
        "track [m]  contact         normal  rolling     side   worst vs oracle [% of its normal]"
    );
    for rt in [0.06, 0.1, 0.145, 0.23, 0.4, 1.0] {
        let plan = |n: usize| {
            let mut p = own_groove_plan(&disc, cell, rt, first * 1e-3, depth * 1e-3);
            p.prm.numerics.tip_slices = n;
            p
        };
        let base = forces_along(&plan(9), &at, Some(&Resolution::default()));
        let oracle = mean(base.iter().map(|b| b.1.unwrap()));
        let show = |name: &str, f: [f64; 3]| {
            let worst = (0..3).map(|k| (f[k] - oracle[k]).abs()).fold(0.0, f64::max);
            println!(
                "{rt:8.3}  {name:<12} {:8.1} {:8.1} {:8.1}   {:6.2}",
                f[0] / 1e3,
                f[1] / 1e3,
                f[2] / 1e3,
                100.0 * worst / oracle[0].abs()
            );
        };
        show("oracle", oracle);
        show("fast, 9", mean(base.iter().map(|b| b.0)));
        for n in [17, 33] {
            let f = forces_along(&plan(n), &at, None);
            show(&format!("fast, {n}"), mean(f.iter().map(|b| b.0)));
        }
    }
}

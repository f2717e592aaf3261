//! The offset sweep's steps (issue 7's continuity requirement): a second
//! pass `d` beside a 3.8 mm groove (`kerf::scenes::beside_plan`, 1 mm
//! cells) for `d` from 0 to 20 mm in 0.1 mm steps, and the largest step of
//! any cutting-force component between neighbouring offsets, in % of the
//! fresh cut's normal force, as `tests/contact_law.rs`'s
//! `full_offset_sweep_0_to_20_mm_is_continuous` reads it.
//!
//! `cargo run --release --example offset_steps -- [--oracle K]`
//! prints the `TOP` largest steps (a few seconds). `--oracle K` also rolls
//! every pass again and reads the brute-force oracle's cutting force at
//! every `K`-th step of the averaging window (its mean: the reference the
//! fast contact's steps are held against; some 3 minutes at K = 4).
//!
//! `-- --at D0 D1 N` prints instead the mean cutting force (normal,
//! rolling, side) at `N + 1` offsets from `D0` to `D1` mm, to find where
//! inside a step the force moves.
use kerf::core::contact_bruteforce::Resolution;
use kerf::core::Model;
use kerf::scenes::{beside_plan, cutting_force, roll, P_REF, WINDOW};

const FN: f64 = 60_795.388;
const TOP: usize = 12;
const N: usize = 200;

/// The oracle's mean cutting force over the plan's averaging window, read
/// every `every`-th step (the passes rolled as `Plan::run` rolls them).
fn oracle_mean(offset: f64, every: usize) -> [f64; 3] {
    let plan = beside_plan(1e-3, P_REF, offset);
    let mut m = Model::new(plan.prm.clone()).unwrap();
    let (last, first) = plan.passes.split_last().unwrap();
    for (t, len) in first {
        roll(&mut m, t.as_ref(), *len, 1e-3, 0.0, 0.0);
    }
    let (track, len) = (last.0.as_ref(), last.1);
    let h = 1e-3;
    let n = (len / h).round() as usize;
    let (mut sum, mut count) = ([0.0; 3], 0);
    let mut in_window = 0;
    for k in 0..=n {
        let s = k as f64 * h;
        let (pose, tw) = (track.pose(s), track.twist(s));
        m.commit(&pose, &tw, if k == 0 { 0.0 } else { h }).unwrap();
        if s >= WINDOW.0 - 1e-12 && s <= WINDOW.1 + 1e-12 {
            if in_window % every == 0 {
                let c = m.contact_brute(&pose, &tw, &Resolution::default());
                let f = cutting_force(&pose, &c);
                (0..3).for_each(|i| sum[i] += f[i]);
                count += 1;
            }
            in_window += 1;
        }
    }
    sum.map(|x| x / count.max(1) as f64)
}

/// Each neighbouring pair's largest component step, % of FN, with the
/// offset it starts at [mm].
fn steps(forces: &[[f64; 3]]) -> Vec<(f64, f64)> {
    forces
        .windows(2)
        .enumerate()
        .map(|(k, w)| {
            let e = (0..3)
                .map(|i| (w[1][i] - w[0][i]).abs())
                .fold(0.0, f64::max);
            (100.0 * e / FN, 0.1 * k as f64)
        })
        .collect()
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if let Some(i) = a.iter().position(|s| s == "--at") {
        let num = |k: usize| -> f64 { a[i + k].parse().expect("--at D0 D1 N") };
        let (d0, d1, n) = (num(1), num(2), num(3) as usize);
        println!("  d [mm]   normal / rolling / side [N]");
        for k in 0..=n {
            let d = d0 + (d1 - d0) * k as f64 / n.max(1) as f64;
            let c = beside_plan(1e-3, P_REF, d * 1e-3).run().cutting;
            println!("{d:8.3}   {:9.1} {:8.1} {:9.1}", c[0], c[1], c[2]);
        }
        return;
    }
    let every = a
        .iter()
        .position(|s| s == "--oracle")
        .map(|i| a.get(i + 1).map_or(4, |s| s.parse().expect("--oracle K")));
    let offsets: Vec<f64> = (0..=N).map(|k| 1e-4 * k as f64).collect();
    let fast: Vec<[f64; 3]> = offsets
        .iter()
        .map(|&d| beside_plan(1e-3, P_REF, d).run().cutting)
        .collect();
    let fast_steps = steps(&fast);
    let oracle_steps = every.map(|e| {
        let o: Vec<[f64; 3]> = offsets.iter().map(|&d| oracle_mean(d, e)).collect();
        steps(&o)
    });
    let mut order: Vec<usize> = (0..fast_steps.len()).collect();
    order.sort_by(|&a, &b| fast_steps[b].0.total_cmp(&fast_steps[a].0));
    println!("offset sweep 0-20 mm, 1 mm cells: the largest steps of a cutting-force component, % of F_N");
    println!("  step [mm]       fast   oracle");
    for &k in order.iter().take(TOP) {
        let (e, d) = fast_steps[k];
        let o = oracle_steps
            .as_ref()
            .map_or(String::from("-"), |s| format!("{:.2}", s[k].0));
        println!("  {d:4.1} -> {:4.1}  {e:6.2}  {o:>7}", d + 0.1);
    }
    let over = fast_steps.iter().filter(|s| s.0 > 2.0).count();
    println!("{over} of {} steps above 2 %", fast_steps.len());
    if let Some(s) = &oracle_steps {
        let worst = s
            .iter()
            .copied()
            .fold((0.0, 0.0), |m, x| if x.0 > m.0 { x } else { m });
        let over = s.iter().filter(|x| x.0 > 2.0).count();
        println!(
            "oracle: worst {:.2} % at {:.1} -> {:.1} mm; {over} steps above 2 %",
            worst.0,
            worst.1,
            worst.1 + 0.1
        );
    }
}

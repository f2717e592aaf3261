//! Cost of a cutterhead step: the layout's discs boring from the steady
//! start at `rpm` with `p_rev` per revolution, `steps` steps of `h`.
//! `cargo run --release --example head_cost -- layouts/reference-9.72m.json [h] [steps] [rpm] [p_rev] [sweep_step] [cell] [ring_step_cells]`
//! Prints the median wall time per step (and the mean) and per disc-step,
//! and the wall time per machine second from the total (set
//! RAYON_NUM_THREADS for the thread count; WHOLE_CUTS=1 makes every cut
//! take the disc's whole front arc, `numerics.cut_ahead`).
use kerf::core::head::{default_params, DiscSpec, Head};
use kerf::core::{layout, Pose, Twist};
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let file = a.first().map_or("layouts/reference-9.72m.json", |s| s);
    let num = |i: usize, d: f64| a.get(i).map_or(d, |s| s.parse().unwrap());
    let (h, steps, rpm, p_rev) = (
        num(1, 1e-3),
        num(2, 200.0) as usize,
        num(3, 3.0),
        num(4, 0.006),
    );
    let lay = layout::load(std::path::Path::new(file)).unwrap();
    let mut p = default_params(&lay, num(6, 1e-3));
    if let Some(s) = a.get(5) {
        p.numerics.sweep_step = s.parse().unwrap();
    }
    p.numerics.cut_ahead = std::env::var_os("WHOLE_CUTS").is_some();
    p.numerics.ring_step_cells = num(7, 0.5);
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let n = specs.len();
    let mut head = Head::new(p, specs).unwrap();
    let t0 = Instant::now();
    head.steady_start(p_rev).unwrap();
    eprintln!("steady start {:.1} s", t0.elapsed().as_secs_f64());
    let w = rpm * 2.0 * std::f64::consts::PI / 60.0;
    let twist = Twist::boring(w, p_rev);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut times = Vec::with_capacity(steps);
    let mut thrust = 0.0;
    for _ in 0..steps {
        let t = Instant::now();
        pose = head.advance_head(&pose, &twist, h).unwrap();
        let o = head.evaluate_head(&pose, &twist).unwrap();
        times.push(t.elapsed().as_secs_f64());
        thrust = o.thrust;
    }
    // (wall per machine second is the steps' total over the time bored:
    // a median step leaves out the slow ones)
    let total: f64 = times.iter().sum();
    times.sort_by(f64::total_cmp);
    let med = times[steps / 2];
    println!(
        "{file}: {n} discs, h = {h} s: median {:.2} ms per step (mean {:.2}), {:.1} us per \
         disc-step, {:.2} s wall per machine second; thrust {:.0} kN",
        med * 1e3,
        total / steps as f64 * 1e3,
        med * 1e6 / n as f64,
        total / (steps as f64 * h),
        thrust / 1e3
    );
}

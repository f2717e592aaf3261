//! Cost of saving and restoring a cutterhead's state, against a step: the
//! layout's discs from the steady start (the whole bore pre-cut, every tile
//! of it allocated), as a master that saves the state before every step and
//! sometimes goes back does it.
//! `cargo run --release --example head_state_cost -- [layout] [h] [rounds] [r_max]`
//! (`r_max`: keep only the discs on tracks within it, e.g. 1.8 for the
//! 3.6 m face at the middle of the 9.72 m reference head)
//! Prints medians over `rounds` of: a step alone; `state()` + `set_state()`;
//! a step right after a restore, and a step while a saved state is held
//! (their writes copy the tiles they share with the saved state); the state's serialized size and the time to write
//! and read it. Set RAYON_NUM_THREADS for the thread count.
use kerf::core::head::{default_params, DiscSpec, Head, HeadState};
use kerf::core::{layout, Pose, Twist};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let file = a.first().map_or("layouts/reference-9.72m.json", |s| s);
    let h: f64 = a.get(1).map_or(1e-3, |s| s.parse().unwrap());
    let rounds: usize = a.get(2).map_or(30, |s| s.parse().unwrap());
    let (rpm, p_rev) = (3.0, 0.006);
    let r_max: f64 = a.get(3).map_or(f64::INFINITY, |s| s.parse().unwrap());
    let mut lay = layout::load(std::path::Path::new(file)).unwrap();
    lay.cutters.retain(|c| c.track <= r_max);
    let p = default_params(&lay, 1e-3);
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let mut head = Head::new(p.clone(), specs).unwrap();
    head.steady_start(p_rev).unwrap();
    let w = rpm * 2.0 * std::f64::consts::PI / 60.0;
    let twist = Twist::boring(w, p_rev);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for _ in 0..5 {
        pose = head.advance_head(&pose, &twist, h).unwrap();
    }
    let (mut step, mut get_set, mut step_after, mut step_held) = (vec![], vec![], vec![], vec![]);
    for _ in 0..rounds {
        let t = Instant::now();
        pose = head.advance_head(&pose, &twist, h).unwrap();
        step.push(t.elapsed().as_secs_f64());
        // save, step, go back, step again (a rejected step retried)
        let t = Instant::now();
        let saved: HeadState = head.state();
        head.set_state(&saved).unwrap();
        get_set.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let next = head.advance_head(&pose, &twist, h).unwrap();
        step_after.push(t.elapsed().as_secs_f64());
        head.set_state(&saved).unwrap();
        pose = head.advance_head(&pose, &twist, h).unwrap();
        assert_eq!(next, pose, "a restored state replays the step");
        drop(saved);
        // a master that saves before every step: the step runs while the
        // saved state shares the face
        let held = head.state();
        let t = Instant::now();
        pose = head.advance_head(&pose, &twist, h).unwrap();
        step_held.push(t.elapsed().as_secs_f64());
        drop(held);
    }
    let tiles = head.map().touched_tiles().count();
    let t = Instant::now();
    let bytes = head.state().to_bytes();
    let write = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let back = HeadState::from_bytes(&bytes, &p, head.len()).unwrap();
    let read = t.elapsed().as_secs_f64();
    assert!(back == head.state(), "the state reads back");
    let (s, gs, sa, sh) = (
        median(step),
        median(get_set),
        median(step_after),
        median(step_held),
    );
    println!(
        "{file} (tracks within {r_max} m): {} discs, {tiles} tiles written ({:.0} MB of heights); medians over {rounds}: \
         step {:.2} ms, state() + set_state() {:.3} ms ({:.1} % of a step), step after a \
         restore {:.2} ms, step while a saved state is held {:.2} ms; serialized {:.1} MB, written in {:.2} s, read in {:.2} s",
        head.len(),
        tiles as f64 * 8192.0 / 1e6,
        s * 1e3,
        gs * 1e3,
        100.0 * gs / s,
        sa * 1e3,
        sh * 1e3,
        bytes.len() as f64 / 1e6,
        write,
        read
    );
}

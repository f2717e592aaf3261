//! Bit patterns of the default disc's forces, moments and rock removed on
//! seven scenes (fresh cuts tilted 0, 10, 30, 60 deg and 12 mm deep, a pass
//! 4 mm beside a groove, a re-roll on a 0.5 m track): run it on two commits
//! and `cmp` the outputs to show a change leaves the default path bit for
//! bit (docs/flanks.md: flank angle 0 against the commit before flanks).
//! `cargo run --release --example scene_bits > bits.txt`.
use kerf::scenes::*;

fn main() {
    let mut out = Vec::new();
    for g in [0.0f64, 10.0, 30.0, 60.0] {
        out.push(fresh(1e-3, P_REF, g.to_radians()));
    }
    out.push(fresh(1e-3, 12e-3, 0.0));
    out.push(beside(1e-3, P_REF, 4e-3));
    out.push(reroll(1e-3, P_REF, Some(0.5)));
    for m in out {
        let b: Vec<u64> = m
            .force
            .iter()
            .chain(m.moment.iter())
            .chain(m.cutting.iter())
            .chain([m.volume, m.length].iter())
            .map(|x| x.to_bits())
            .collect();
        println!("{:?} {:?}", m.cutting, b);
    }
}

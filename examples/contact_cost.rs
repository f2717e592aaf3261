//! Where a step's time goes on a scene: contact evaluation vs cutting.
//! `cargo run --release --example contact_cost -- ROLL_DEG`
use kerf::core::cut_cutter_heightmap::cut;
use kerf::core::cutter::PosedDisc;
use kerf::core::*;
use kerf::scenes::*;
use std::time::Instant;
fn main() {
    let g: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(30.0);
    let prm = face(1e-3, -0.3, 0.5, -0.06, 0.06);
    let mut m = Model::new(prm.clone()).unwrap();
    let t = Straight {
        prm: prm.clone(),
        x0: 0.0,
        y: 0.0,
        depth: P_REF,
        roll: g.to_radians(),
    };
    roll(&mut m, &t, 0.1, 1e-3, 0.0, 0.0);
    let pose = t.pose(0.1);
    let n = 200;
    let t0 = Instant::now();
    for _ in 0..n {
        std::hint::black_box(m.contact(&pose, &Twist::new([0.0; 3], [0.0; 3])));
    }
    let c_us = t0.elapsed().as_secs_f64() * 1e6 / n as f64;
    let mut map = m.map().clone();
    let disc = PosedDisc::new(&prm.cutter, &t.pose(0.101));
    let t0 = Instant::now();
    for _ in 0..n {
        std::hint::black_box(cut(&mut map, &disc, 2e-6, 1.0, (None, None)));
    }
    let k_us = t0.elapsed().as_secs_f64() * 1e6 / n as f64;
    println!("roll {g}: contact {c_us:.1} us, cut {k_us:.1} us");
}

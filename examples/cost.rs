//! Runs `n` reference 1 mm steps (after a 100-step start-up) for an
//! instruction-count profile: `valgrind --tool=callgrind target/release/examples/cost 200`.
use kerf::core::*;
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(200);
    let prm = Params::default();
    let r = prm.cutter.radius;
    let mut m = Model::new(prm).unwrap();
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / r, 0.0]);
    let mut pose = Pose::new(0.0, 0.0, r - 0.0038, 0.0, 0.0, 0.0);
    for _ in 0..100 + n {
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
        std::hint::black_box(m.evaluate(&pose, &tw).unwrap());
    }
}

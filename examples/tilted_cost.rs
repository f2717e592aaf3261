//! Cost of a rolling cut with the cutter rolled `roll` degrees (gauge cutters
//! are tilted): `target/release/examples/tilted_cost 30`.
use kerf::core::*;
use std::time::Instant;
fn main() {
    let roll: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(30.0);
    let prm = Params::default();
    let r = prm.cutter.radius;
    let mut m = Model::new(prm.clone()).unwrap();
    let probe = Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, roll.to_radians());
    let low = kerf::core::cutter::PosedDisc::new(&prm.cutter, &probe).lowest_point();
    let mut pose = Pose::new(
        0.0 - low.x,
        -low.y,
        1.0 - low.z - 0.0038,
        0.0,
        0.0,
        roll.to_radians(),
    );
    let axle = pose.rotation() * nalgebra::Vector3::y();
    let w = axle / r;
    let tw = Twist::new([1.0, 0.0, 0.0], [w.x, w.y, w.z]);
    let mut times = Vec::new();
    let mut last = Outputs::default();
    for _ in 0..300 {
        let t = Instant::now();
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
        last = m.evaluate(&pose, &tw).unwrap();
        if times.len() < 6 || times.len() % 50 == 0 {
            eprintln!(
                "x={:.3} p={:.2}mm N={:.0} S={:.0}",
                pose.position.x,
                last.penetration * 1e3,
                last.normal_force,
                last.side_force
            );
        }
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "contact {:?}",
        m.contact(&pose, &Twist::new([0.0; 3], [0.0; 3]))
    );
    println!(
        "roll {roll} deg: median {:.1} us per 1 mm step; N={:.0} R={:.0} S={:.0}",
        times[150], last.normal_force, last.rolling_force, last.side_force
    );
}

use kerf::core::*;
fn main() {
    let step: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e-3);
    let prm = Params::default();
    let r = prm.cutter.radius;
    let mut m = Model::new(prm).unwrap();
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / r, 0.0]);
    let mut pose = Pose::new(-0.30, 0.0, r - 0.0038, 0.0, 0.0, 0.0);
    let mut last = 0.0;
    for _ in 0..(0.06 / step) as usize {
        pose = m.advance(&pose, &tw, step).unwrap();
        let o = m.evaluate(&pose, &tw).unwrap();
        if o.normal_force != last {
            println!(
                "x={:.4} N={:9.1} R={:8.1} p={:.4}mm dN={:8.1}",
                pose.position.x,
                o.normal_force,
                o.rolling_force,
                o.penetration * 1e3,
                o.normal_force - last
            );
        }
        last = o.normal_force;
    }
}

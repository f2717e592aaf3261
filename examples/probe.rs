use kerf::core::*;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let p_mm: f64 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(3.8);
    let step_mm: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(1.0);
    let y0: f64 = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(0.0);
    let mut prm = Params::default();
    let env = |k: &str| std::env::var(k).ok().map(|v| v.parse::<f64>().unwrap());
    if let Some(v) = env("STEP") {
        prm.numerics.arc_step_cells = v;
    }
    if let Some(v) = env("SLICES") {
        prm.numerics.tip_slices = v as usize;
    }
    if let Some(v) = env("SWEEP") {
        prm.numerics.sweep_step = v;
    }
    if env("DIR") == Some(2.0) {
        prm.numerics.direction = DirectionRule::Thesis;
    }
    let r = prm.cutter.radius;
    let mut m = Model::new(prm.clone()).unwrap();
    let p = p_mm * 1e-3;
    let mut pose = Pose::new(0.0, y0, r - p, 0.0, 0.0, 0.0);
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / r, 0.0]);
    let h = step_mm * 1e-3;
    let n = (1.0 / h).round() as usize;
    let (mut sn, mut sr, mut ss, mut cnt) = (0.0, 0.0, 0.0, 0);
    let t0 = Instant::now();
    let mut first = None;
    for _ in 0..n {
        pose = m.advance(&pose, &tw, h).unwrap();
        let o = m.evaluate(&pose, &tw).unwrap();
        if first.is_none() {
            first = Some(o);
        }
        if pose.position.x > 0.2 && pose.position.x < 0.8 {
            sn += o.normal_force;
            sr += o.rolling_force;
            ss += o.side_force;
            cnt += 1;
        }
    }
    let el = t0.elapsed().as_secs_f64();
    let law = m.law();
    let ft = law.force(p);
    let phi = (1.0f64 - p / r).acos();
    let (fn_, fr) = (ft * (phi / 2.0).cos(), ft * (phi / 2.0).sin());
    let o = m.evaluate(&pose, &tw).unwrap();
    println!("p={p_mm}mm step={step_mm}mm  N={:.2} ({:+.4}%)  R={:.2} ({:+.4}%)  S={:.3} ({:.4}%N)  vol={:.4e} pen={:.5}mm  {:.2} us/step",
        sn / cnt as f64, 100.0 * (sn / cnt as f64 / fn_ - 1.0), sr / cnt as f64, 100.0 * (sr / cnt as f64 / fr - 1.0), ss / cnt as f64, 100.0*(ss/cnt as f64)/fn_, o.excavated_volume, o.penetration*1e3, el / n as f64 * 1e6);
    println!("first step: {:?}", first.unwrap().normal_force);
}

use kerf::core::contact_cutter_heightmap::walk;
use kerf::core::cutter::PosedDisc;
use kerf::core::*;
fn main() {
    let prm = Params::default();
    let r = prm.cutter.radius;
    let mut m = Model::new(prm.clone()).unwrap();
    let mut pose = Pose::new(0.0, 0.0, r - 0.0038, 0.0, 0.0, 0.0);
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / r, 0.0]);
    for _ in 0..300 {
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
    }
    let disc = PosedDisc::new(&prm.cutter, &pose);
    let map = m.map();
    for k in 0..9 {
        let y = -0.0065 + 0.013 * k as f64 / 8.0;
        let rho = disc.rho(y);
        let (t0, reach) = disc.arc_below(y, rho, 0.0).unwrap();
        for dir in [1.0, -1.0] {
            let a = walk(map, &disc, y, t0, reach, dir, 0.5e-3 / rho, 1e-3);
            println!(
                "y={:+.4} dir={dir:+} {:?}",
                y,
                a.map(|a| (a.a, a.b, a.depth * 1e3, a.length * 1e3, a.u_max * 1e6))
            );
        }
    }
    let c = m.contact(&pose);
    println!("{:?}", c);
}

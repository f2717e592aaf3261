use kerf::core::contact_cutter_heightmap::{slice_y, walk};
use kerf::core::cutter::PosedDisc;
use kerf::core::*;
fn main() {
    let prm = Params::default();
    let r = prm.cutter.radius;
    let mut m = Model::new(prm.clone()).unwrap();
    let pose = Pose::new(0.3, 0.0, r - 0.0038, 0.0, 0.0, 0.0);
    m.commit(&pose, &Twist::default(), 0.0).unwrap();
    let lift: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(2.6e-6);
    let up = Pose::new(0.3, 0.0, r - 0.0038 + lift, 0.0, 0.0, 0.0);
    let disc = PosedDisc::new(&prm.cutter, &up);
    let map = m.map();
    for k in 0..9 {
        let y = slice_y(0.0065, 9, k);
        let rho = disc.rho(y);
        let (t0, reach) = disc.arc_below(y, rho, 0.0).unwrap_or((0.0, 0.0));
        for dir in [1.0, -1.0] {
            let a = walk(map, &disc, y, t0, reach, dir, 4e-3 / rho, 1e-3);
            println!(
                "y={:+.4} dir={dir:+} {:?}",
                y,
                a.map(|a| (a.a, a.b, a.depth * 1e3, a.u_max * 1e6))
            );
        }
    }
    println!("{:?}", m.contact(&up));
}

use kerf::core::*;
fn main() {
    let roll: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(60.0);
    let depth: f64 = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(3e-3);
    let mut m = Model::new(Params::default()).unwrap();
    let probe = Pose::new(0.3, 0.0, 1.0, 0.0, 0.0, roll.to_radians());
    let disc = kerf::core::cutter::PosedDisc::new(&m.params().cutter, &probe);
    let mut z_low = f64::INFINITY;
    for k in 0..=200 {
        let y = -disc.half_width + 2.0 * disc.half_width * k as f64 / 200.0;
        if let Some((t0, _)) = disc.arc_below(y, disc.rho(y), 10.0) {
            z_low = z_low.min(disc.to_world(&disc.rim_point_local(t0, y)).z);
        }
    }
    let pose = Pose::new(0.3, 0.0, 1.0 - z_low - depth, 0.0, 0.0, roll.to_radians());
    println!(
        "before commit {:?}",
        m.evaluate(&pose, &Twist::default()).unwrap()
    );
    m.commit(&pose, &Twist::default(), 0.0).unwrap();
    println!("after {:?}", m.evaluate(&pose, &Twist::default()).unwrap());
    println!("contact {:?}", m.contact(&pose));
}

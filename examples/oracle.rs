//! Fast contact vs the brute-force oracle on the scenes' end poses:
//! `cargo run --release --example oracle`.
use kerf::core::contact_bruteforce::Resolution;
use kerf::core::*;
use kerf::scenes::*;
fn show(name: &str, m: &Model, pose: &Pose, tw: &Twist, fresh_n: f64) {
    let t0 = std::time::Instant::now();
    let f = m.contact(pose, tw);
    let tf = t0.elapsed().as_secs_f64() * 1e6;
    let t0 = std::time::Instant::now();
    let b = m.contact_brute(pose, tw, &Resolution::default());
    let tb = t0.elapsed().as_secs_f64() * 1e3;
    let rt = pose.rotation().transpose();
    let ff = rt * (f.rim_force + f.side_force);
    let bb = rt * (b.rim_force + b.side_force);
    let d = (ff - bb) / fresh_n * 100.0;
    println!("{name:<16} fast [{:8.0} {:8.0} {:8.0}] brute [{:8.0} {:8.0} {:8.0}] diff %Fn [{:6.2} {:6.2} {:6.2}]  {tf:.0} us / {tb:.0} ms", ff.x, ff.y, ff.z, bb.x, bb.y, bb.z, d.x, d.y, d.z);
}
fn main() {
    let cell = 1e-3;
    let fresh_n = 60795.0;
    for g in [0.0f64, 10.0, 30.0, 60.0] {
        let prm = face(cell, -0.3, 0.5, -0.06, 0.06);
        let mut m = Model::new(prm.clone()).unwrap();
        let t = Straight {
            prm,
            x0: 0.0,
            y: 0.0,
            depth: P_REF,
            roll: g.to_radians(),
        };
        roll(&mut m, &t, 0.1, 1e-3, 0.0, 0.0);
        show(
            &format!("tilt {g}"),
            &m,
            &t.pose(0.1),
            &t.twist(0.1),
            fresh_n,
        );
    }
    for d in [2.0, 4.0, 8.0] {
        let prm = face(cell, -0.3, 0.5, -0.06, 0.06);
        let mut m = Model::new(prm.clone()).unwrap();
        let a = Straight {
            prm: prm.clone(),
            x0: -0.1,
            y: 0.0,
            depth: P_REF,
            roll: 0.0,
        };
        roll(&mut m, &a, 0.35, 1e-3, 0.0, 0.0);
        let b = Straight {
            prm,
            x0: 0.0,
            y: d * 1e-3,
            depth: P_REF,
            roll: 0.0,
        };
        roll(&mut m, &b, 0.1, 1e-3, 0.0, 0.0);
        show(
            &format!("beside {d}"),
            &m,
            &b.pose(0.1),
            &b.twist(0.1),
            fresh_n,
        );
    }
}

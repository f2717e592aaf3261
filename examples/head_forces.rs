//! The reference head's mean forces over `steps` steps of 1 ms from the
//! steady start (3 rpm, 6 mm a revolution, 1 mm cells): mean thrust and
//! torque, and each disc's mean normal, rolling and side force, at full
//! precision, for comparing two builds (`diff` the outputs):
//! `cargo run --release --example head_forces -- [steps] > forces.txt`.
use kerf::core::head::{default_params, DiscSpec, Head};
use kerf::core::{layout, Pose, Twist};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let steps: usize = a.first().map_or(300, |s| s.parse().unwrap());
    let lay = layout::load(std::path::Path::new("layouts/reference-9.72m.json")).unwrap();
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let n = specs.len();
    let mut head = Head::new(default_params(&lay, 1e-3), specs).unwrap();
    head.steady_start(0.006).unwrap();
    let twist = Twist::boring(3.0 * 2.0 * std::f64::consts::PI / 60.0, 0.006);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut thrust, mut torque) = (0.0, 0.0);
    let mut per = vec![[0.0f64; 3]; n];
    for _ in 0..steps {
        pose = head.advance_head(&pose, &twist, 1e-3).unwrap();
        let o = head.evaluate_head(&pose, &twist).unwrap();
        thrust += o.thrust;
        torque += o.torque;
        for (p, d) in per.iter_mut().zip(&o.discs) {
            p[0] += d.normal_force;
            p[1] += d.rolling_force;
            p[2] += d.side_force;
        }
    }
    let k = steps as f64;
    println!("thrust {:e} N torque {:e} N m", thrust / k, torque / k);
    for (i, f) in per.iter().enumerate() {
        println!("disc {i} {:e} {:e} {:e}", f[0] / k, f[1] / k, f[2] / k);
    }
}

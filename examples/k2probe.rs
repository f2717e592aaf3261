//! K2 probe: the torque of a head and its gauge discs' rolling forces, with
//! the default friction and without (MU=0): `k2probe LAYOUT RPM STEADY(0/1) STEPS`.
use kerf::core::head::{default_params, DiscSpec, Head};
use kerf::core::{layout, Pose, Twist};
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let file = a.first().map_or("layouts/demo-1.2m.json", |s| s);
    let rpm: f64 = a.get(1).map_or(10.0, |s| s.parse().unwrap());
    let steady = a.get(2).is_some_and(|s| s == "1");
    let steps: usize = a.get(3).map_or(200, |s| s.parse().unwrap());
    let lay = layout::load(std::path::Path::new(file)).unwrap();
    let mut p = default_params(&lay, 1e-3);
    if let Ok(m) = std::env::var("MU") {
        p.friction.mu = m.parse().unwrap();
    }
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let tilted: Vec<usize> = specs
        .iter()
        .enumerate()
        .filter(|(_, s)| s.mount.tilt != 0.0)
        .map(|(i, _)| i)
        .collect();
    let mut head = Head::new(p, specs).unwrap();
    if steady {
        head.steady_start(0.006).unwrap();
    }
    let w = rpm * 2.0 * std::f64::consts::PI / 60.0;
    let twist = Twist::boring(w, 0.006);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut tq, mut th) = (0.0, 0.0);
    let mut gr = vec![0.0; tilted.len()];
    for _ in 0..steps {
        pose = head.advance_head(&pose, &twist, 1e-3).unwrap();
        let o = head.evaluate_head(&pose, &twist).unwrap();
        tq += o.torque / steps as f64;
        th += o.thrust / steps as f64;
        for (g, &i) in gr.iter_mut().zip(&tilted) {
            *g += o.discs[i].rolling_force / steps as f64;
        }
    }
    println!(
        "mean thrust {:.0} kN torque {:.1} kN.m; gauge rolling forces {:?} kN",
        th / 1e3,
        tq / 1e3,
        gr.iter()
            .map(|g| (g / 100.0).round() / 10.0)
            .collect::<Vec<_>>()
    );
}

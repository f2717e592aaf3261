//! K1 scan: the demo head bored from the flat face at 10 rpm, 6 mm/rev, 1 ms
//! steps; every step is taken twice from the same state, with the head's z
//! and z + dz; prints the largest relative change of thrust and of any
//! disc's normal force (the core side of tools/hosts/z_sensitivity.py).
use kerf::core::head::{default_params, DiscSpec, Head};
use kerf::core::{layout, Pose, Twist};
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let dz: f64 = a.first().map_or(1e-15, |s| s.parse().unwrap());
    let steps: usize = a.get(1).map_or(200, |s| s.parse().unwrap());
    let lay = layout::load(std::path::Path::new("layouts/demo-1.2m.json")).unwrap();
    let p = default_params(&lay, 1e-3);
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let mut head = Head::new(p, specs).unwrap();
    let w = 10.0 * 2.0 * std::f64::consts::PI / 60.0;
    let twist = Twist::boring(w, 0.006);
    let vz = twist.velocity.z;
    let h = 1e-3;
    let (mut wt, mut wd, mut at) = (0.0f64, 0.0f64, (0, 0));
    let mut rels = Vec::new();
    for k in 0..steps {
        let t = k as f64 * h;
        let pose = Pose::new(0.0, 0.0, vz * t, w * t, 0.0, 0.0);
        let s = head.state();
        let mut p2 = pose;
        p2.position.z += dz;
        let e2 = head.advance_head(&p2, &twist, h).unwrap();
        let o2 = head.evaluate_head(&e2, &twist).unwrap();
        head.set_state(&s).unwrap();
        let e1 = head.advance_head(&pose, &twist, h).unwrap();
        let o1 = head.evaluate_head(&e1, &twist).unwrap();
        let rt = (o1.thrust - o2.thrust).abs() / o1.thrust.abs().max(1e-9);
        rels.push(rt);
        if rt > wt {
            wt = rt;
            at.0 = k + 1;
        }
        for (x, y) in o1.discs.iter().zip(o2.discs.iter()) {
            let r = (x.normal_force - y.normal_force).abs() / x.normal_force.abs().max(1e-9);
            if r > wd {
                wd = r;
                at.1 = k + 1;
            }
        }
    }
    rels.sort_by(f64::total_cmp);
    println!("dz {dz:e}, {steps} steps: thrust worst {wt:.2e} (step {}), median {:.2e}, 90th {:.2e}; a disc's normal force worst {wd:.2e} (step {})",
        at.0, rels[steps / 2], rels[steps * 9 / 10], at.1);
}

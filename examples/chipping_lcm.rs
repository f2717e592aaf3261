//! A virtual LCM block with and without chips, through the core model: mean
//! forces of a relieved pass and specific energy against S/p.
//!
//! `cargo run --release --example chipping_lcm`
//!
//! Block: thesis Table 2 disc and rock, 1 mm cells, passes 0.6 m long along
//! x, p = 3.8 mm; each spacing cuts 4 passes side by side and reports the
//! last (relieved on one side), over its middle 0.4 m.
use kerf::core::{Model, Params, Pose, Twist};

const R: f64 = 0.2159;

fn block(chipping: bool, s: f64) -> Params {
    let mut p = Params::default();
    p.rock.x_min = -0.25;
    p.rock.x_max = 0.85;
    p.rock.y_min = -0.05 - 4.0 * s;
    p.rock.y_max = 0.15;
    p.rock.nx = 1101;
    p.rock.ny = ((p.rock.y_max - p.rock.y_min) / 0.001).round() as usize + 1;
    p.csm.spacing = s;
    p.chipping.enabled = chipping;
    p
}

/// (normal, rolling, side) means over 0.1..0.5, and volume removed there.
fn pass(m: &mut Model, y: f64, p: f64) -> ([f64; 3], f64, f64) {
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut pose = Pose::new(0.0, y, R - p, 0.0, 0.0, 0.0);
    let (mut f, mut k, mut v0, mut v1) = ([0.0; 3], 0.0, None, 0.0);
    let mut work = 0.0;
    for _ in 0..600 {
        pose = m.advance(&pose, &tw, 0.001).unwrap();
        let o = m.evaluate(&pose, &tw).unwrap();
        if (0.1..=0.5).contains(&pose.position.x) {
            f[0] += o.normal_force;
            f[1] += o.rolling_force;
            f[2] += o.side_force;
            k += 1.0;
            work += o.rolling_force * 0.001;
            v0.get_or_insert(o.excavated_volume);
            v1 = o.excavated_volume;
        }
    }
    ([f[0] / k, f[1] / k, f[2] / k], v1 - v0.unwrap(), work)
}

fn main() {
    let p = 0.0038;
    println!("S/p    chips  Fn kN   Fr kN   Fs kN   SE MJ/m3   (last of 4 passes, 0.4 m)");
    for s in [0.03, 0.04, 0.051, 0.065, 0.08, 0.1] {
        for chips in [false, true] {
            let mut m = Model::new(block(chips, s)).unwrap();
            let mut last = ([0.0; 3], 0.0, 0.0);
            for n in 0..4 {
                last = pass(&mut m, -(n as f64) * s, p);
            }
            let (f, vol, work) = last;
            println!(
                "{:5.1}  {:5}  {:6.1}  {:6.2}  {:6.2}  {:8.1}",
                s / p,
                chips,
                f[0] / 1e3,
                f[1] / 1e3,
                f[2] / 1e3,
                work / vol / 1e6
            );
        }
    }
}

//! A rolling disc's cut stops half a sweep step (plus a cell) ahead of its
//! lowest point (`cut_cutter_heightmap::Front`): its next cuts take the
//! front arc again. Held here against whole cuts, which carve the disc's
//! whole front arc at every sub-step: behind the disc the two leave the
//! same rock, on every kind of path a cutterhead makes.

use kerf::core::params::Params;
use kerf::core::{Model, Pose, Twist};
use kerf::scenes::*;

/// Length of every pass \[m\].
const LENGTH: f64 = 0.6;

/// A straight pass along +x whose lowest point goes from `d0` deep down
/// (`slope` > 0) or up (`slope` < 0) by `slope` per metre: its twist moves
/// the disc along that slope.
struct Sloped {
    prm: Params,
    d0: f64,
    slope: f64,
}

impl Track for Sloped {
    fn pose(&self, s: f64) -> Pose {
        pose_with_lowest_point(&self.prm, s - 0.3, 0.0, self.d0 + self.slope * s, 0.0, 0.0)
    }
    fn twist(&self, _s: f64) -> Twist {
        let r = self.prm.cutter.radius;
        Twist::new([1.0, 0.0, -self.slope], [0.0, 1.0 / r, 0.0])
    }
}

/// The scene's map after rolling `track` for 0.6 m in 1 mm steps, with
/// whole cuts or not, and the disc's last pose.
fn rolled(prm: &Params, whole: bool, track: &dyn Fn(Params) -> Box<dyn Track>) -> (Model, Pose) {
    let mut p = prm.clone();
    p.numerics.cut_ahead = whole;
    let t = track(p.clone());
    let mut m = Model::new(p).unwrap();
    roll(&mut m, t.as_ref(), LENGTH, 1e-3, 0.0, LENGTH);
    (m, t.pose(LENGTH))
}

/// Largest height difference of the two maps outside `reach` (plan distance)
/// of the last disc centre, and how many nodes the two cuts lowered there.
fn compare(prm: &Params, track: &dyn Fn(Params) -> Box<dyn Track>) -> (f64, usize) {
    let (a, end) = rolled(prm, true, track);
    let (b, _) = rolled(prm, false, track);
    let (ma, mb) = (a.map(), b.map());
    let g = *ma.grid();
    let reach = prm.cutter.radius + 2e-3;
    let (mut worst, mut cut) = (0.0f64, 0);
    for j in 0..g.ny {
        for i in 0..g.nx {
            let (x, y) = g.node_xy(i, j);
            if (x - end.position.x).hypot(y - end.position.y) <= reach {
                continue;
            }
            let (za, zb) = (ma.node(i, j), mb.node(i, j));
            if (za - zb).abs() > worst && std::env::var_os("SHOW").is_some() {
                eprintln!("  ({x:.3}, {y:.3}): whole {za:e}, front {zb:e}");
            }
            worst = worst.max((za - zb).abs());
            if za < 0.0 {
                cut += 1;
            }
        }
    }
    (worst, cut)
}

/// The grooves behind the disc agree within `tol` \[m\].
fn check(name: &str, prm: &Params, tol: f64, track: &dyn Fn(Params) -> Box<dyn Track>) {
    let (worst, cut) = compare(prm, track);
    eprintln!("{name}: {cut} nodes cut behind the disc, worst difference {worst:e} m");
    assert!(cut > 1000, "{name}: the scene cut only {cut} nodes");
    assert!(worst <= tol, "{name}: the grooves differ by {worst:e} m");
}

#[test]
fn cuts_that_stop_ahead_leave_the_groove_whole_cuts_leave() {
    let prm = face(1e-3, -0.6, 0.6, -0.6, 0.6);
    // bit for bit but round-off (measured: 0 on every scene here)
    let exact = 1e-12;
    check("straight", &prm, exact, &|p| {
        Box::new(Straight {
            prm: p,
            x0: -0.3,
            y: 0.0,
            depth: 3.8e-3,
            roll: 0.0,
        })
    });
    check("tilted 30 deg, straight", &prm, exact, &|p| {
        Box::new(Straight {
            prm: p,
            x0: -0.3,
            y: 0.0,
            depth: 3.8e-3,
            roll: 30f64.to_radians(),
        })
    });
    // On a tight track a disc's leading and trailing halves both scrape
    // the outer wall (its plane comes closer to the wall ahead and behind);
    // whole cuts sample that scrape from both halves, the others from the
    // trailing half alone, a sub-step apart: the wall differs by a sampling
    // error that falls with the sub-steps' spacing along the track, both
    // converging on the swept solid's wall. Measured 21.9 / 16.2 / 10.0 um
    // at 1 / 0.5 / 0.25 mm sweep steps (2, 3 and 5 sub-steps a 1 ms step:
    // the turn counts at the reach of the part in the rock, `RimReach`; it
    // was 16.2 / 10.0 / 5.0 um with 3, 5 and 9 when the turn counted at the
    // whole radius). The mean forces on the scene do not move by 0.01 % of
    // a fresh cut's normal force (`examples/sweep_steps`).
    for (sweep, tol) in [(1e-3, 2.5e-5), (0.25e-3, 1.2e-5)] {
        let mut q = prm.clone();
        q.numerics.sweep_step = sweep;
        check(
            &format!("upright, 0.2 m track, sweep {sweep}"),
            &q,
            tol,
            &|p| {
                Box::new(Circle {
                    prm: p,
                    cx: 0.0,
                    cy: 0.0,
                    radius: 0.2,
                    a0: 0.0,
                    depth: 3.8e-3,
                })
            },
        );
    }
    for (roll, radius) in [(-60.0f64, 4.83), (-30.0, 0.5)] {
        check(
            &format!("gauge {roll} deg, {radius} m track"),
            &prm,
            exact,
            &|p| {
                Box::new(TiltedArc {
                    prm: p,
                    yaw: 30f64.to_radians(),
                    roll: roll.to_radians(),
                    depth: 6e-3,
                    radius,
                    speed: 1.0,
                })
            },
        );
    }
    // going deeper and climbing out (1 in 100: the cut reaches 2 R slope,
    // 4.3 mm, further ahead; without that reach the climbing groove differs
    // by 0.95 um)
    for slope in [0.01, -0.01] {
        check(&format!("slope {slope}"), &prm, exact, &|p| {
            Box::new(Sloped {
                prm: p,
                d0: if slope > 0.0 { 1e-3 } else { 7e-3 },
                slope,
            })
        });
    }
}

//! A rolling disc's cut leaves out the box behind it where its last cut
//! already lies below it (`cut_cutter_heightmap::Back`). Held here against
//! cuts that walk their whole window (`numerics.cut_behind`): the face must
//! be the same bit for bit, node heights, cut marks and height bounds, and
//! so must the volume cut, on every kind of path a cutterhead makes. The
//! box is a claim of geometry, not an approximation: any difference fails.

use kerf::core::head::{DiscSpec, Head, Mount};
use kerf::core::params::{CutterParams, Params};
use kerf::core::{Model, Pose, Twist};
use kerf::scenes::*;

/// A straight pass heading `yaw`, moving along `yaw + crab` (a disc
/// crabbing sideways when `crab != 0`), its lowest point going from `d0`
/// deep down by `slope` per metre, rolled by `roll`, forwards or backwards.
struct Line {
    prm: Params,
    yaw: f64,
    crab: f64,
    d0: f64,
    slope: f64,
    roll: f64,
    backwards: bool,
}

impl Track for Line {
    fn pose(&self, s: f64) -> Pose {
        let s = if self.backwards { 0.25 - s } else { s - 0.25 };
        let m = self.yaw + self.crab;
        let depth = self.d0 + self.slope * (s + 0.25);
        pose_with_lowest_point(
            &self.prm,
            s * m.cos(),
            s * m.sin(),
            depth,
            self.yaw,
            self.roll,
        )
    }
    fn twist(&self, s: f64) -> Twist {
        let sign = if self.backwards { -1.0 } else { 1.0 };
        let p = self.pose(s);
        let m = self.yaw + self.crab;
        let mut t = rolling_twist(&self.prm, &p, sign, 0.0);
        t.velocity = [sign * m.cos(), sign * m.sin(), -sign * self.slope].into();
        t
    }
}

fn line(prm: Params) -> Line {
    Line {
        prm,
        yaw: 0.0,
        crab: 0.0,
        d0: 3.8e-3,
        slope: 0.0,
        roll: 0.0,
        backwards: false,
    }
}

/// The model after rolling `track` `length` m in Model Exchange steps of
/// `h` m, then Co-Simulation steps of `5 h` (cut in sub-steps) as far again,
/// walking the whole window behind or not.
fn rolled(prm: &Params, whole: bool, length: f64, h: f64, track: &dyn Track) -> Model {
    let mut p = prm.clone();
    p.numerics.cut_behind = whole;
    let mut m = Model::new(p).unwrap();
    roll(&mut m, track, length, h, 0.0, length);
    // Co-Simulation: the model moves the pose along the twist itself
    let mut pose = track.pose(length);
    let tw = track.twist(length);
    for _ in 0..(length / (5.0 * h)).round() as usize {
        pose = m.advance(&pose, &tw, 5.0 * h).unwrap();
    }
    m
}

/// How many nodes a cut has lowered.
fn cut_nodes(m: &kerf::core::heightmap::HeightMap) -> usize {
    let g = *m.grid();
    (0..g.ny)
        .flat_map(|j| (0..g.nx).map(move |i| (i, j)))
        .filter(|&(i, j)| m.is_cut(i, j))
        .count()
}

/// Nodes whose heights or cut marks differ, and the largest difference.
fn differ(
    a: &kerf::core::heightmap::HeightMap,
    b: &kerf::core::heightmap::HeightMap,
) -> (usize, f64) {
    let g = *a.grid();
    let (mut n, mut worst) = (0, 0.0f64);
    for j in 0..g.ny {
        for i in 0..g.nx {
            let (za, zb) = (a.node(i, j), b.node(i, j));
            if za.to_bits() != zb.to_bits() || a.is_cut(i, j) != b.is_cut(i, j) {
                n += 1;
                worst = worst.max((za - zb).abs());
                if n < 4 {
                    let (x, y) = g.node_xy(i, j);
                    eprintln!("  ({x:.4}, {y:.4}): {za:e} against {zb:e}");
                }
            }
        }
    }
    (n, worst)
}

/// The two faces are the same bit for bit (and cut something).
fn check(name: &str, prm: &Params, length: f64, h: f64, track: &dyn Track) {
    let a = rolled(prm, true, length, h, track);
    let b = rolled(prm, false, length, h, track);
    let cut = cut_nodes(a.map());
    eprintln!("{name}: {cut} nodes cut");
    assert!(cut > 500, "{name}: the scene cut only {cut} nodes");
    assert_eq!(differ(a.map(), b.map()), (0, 0.0), "{name}: nodes differ");
    assert!(a.map() == b.map(), "{name}: the faces differ");
    // and the rest of the state: volume and energy booked, last cut
    assert!(a.state() == b.state(), "{name}: the states differ");
}

/// A lap of a track of `radius` through the face's centre region, the
/// lowest point `depth` deep (about the centre up to 0.45 m; a larger
/// track's arc passes through the centre).
fn circle(p: &Params, radius: f64, depth: f64) -> Circle {
    let (cy, a0) = if radius > 0.45 {
        (-radius, std::f64::consts::FRAC_PI_2 - 0.2 / radius)
    } else {
        (0.0, 0.0)
    };
    Circle {
        prm: p.clone(),
        cx: 0.0,
        cy,
        radius,
        a0,
        depth,
    }
}

/// A tilted disc's arc (a gauge cutter's path): heading 30 deg to the
/// grid, rolled by `roll` deg, 6 mm deep, on a track of `radius`, 1 m/s.
fn tilted_arc(p: &Params, roll: f64, radius: f64) -> TiltedArc {
    TiltedArc {
        prm: p.clone(),
        yaw: 30f64.to_radians(),
        roll: roll.to_radians(),
        depth: 6e-3,
        radius,
        speed: 1.0,
    }
}

/// A disc's arc sinking by `rate` per metre of travel.
struct Sinking {
    arc: TiltedArc,
    rate: f64,
}

impl Track for Sinking {
    fn pose(&self, s: f64) -> Pose {
        let mut p = self.arc.pose(s);
        p.position.z -= self.rate * s;
        p
    }
    fn twist(&self, s: f64) -> Twist {
        let mut t = self.arc.twist(s);
        t.velocity.z -= self.rate * self.arc.speed;
        t
    }
}

/// A square grid of `cell` over `disc`'s plan, 1 cm beyond its radius.
fn plan_grid(disc: &kerf::core::cutter::PosedDisc, cell: f64) -> kerf::core::heightmap::Grid {
    let (cx, cy, r) = (disc.centre.x, disc.centre.y, disc.radius + 0.01);
    let n = (2.0 * r / cell).round() as usize + 1;
    kerf::core::heightmap::Grid::new(cx - r, cx + r, cy - r, cy + r, n, n)
}

/// The claim a box rests on, at every node of `g` it leaves out: the last
/// pose's solid `d0` lies over the node and the solid now `d1` nowhere
/// lower there (to round-off). The nodes left out, and how many of them lie
/// under the last solid's side face; or the first node where it fails.
fn left_out_where_risen(
    back: &kerf::core::cut_cutter_heightmap::Back,
    d0: &kerf::core::cutter::PosedDisc,
    d1: &kerf::core::cutter::PosedDisc,
    g: &kerf::core::heightmap::Grid,
) -> Result<(usize, usize), String> {
    let (mut left_out, mut over_face) = (0, 0);
    for j in 0..g.ny {
        for i in 0..g.nx {
            if !back.leaves_out(g, i, j) {
                continue;
            }
            left_out += 1;
            let (x, y) = g.node_xy(i, j);
            let Some((z0, face)) = d0.lower_boundary(x, y) else {
                return Err(format!(
                    "({x:.5}, {y:.5}) left out, not under the last solid"
                ));
            };
            if let Some((z1, _)) = d1.lower_boundary(x, y) {
                if z1 < z0 - 1e-12 {
                    return Err(format!(
                        "({x:.5}, {y:.5}) left out, the disc fell {:e} m there",
                        z0 - z1
                    ));
                }
            }
            over_face += usize::from(matches!(face, kerf::core::cutter::Face::Side(_)));
        }
    }
    Ok((left_out, over_face))
}

fn prm() -> Params {
    face(1e-3, -0.5, 0.5, -0.5, 0.5)
}

#[test]
fn straight_sloped_crabbing_and_backward_passes_cut_the_same_face() {
    let p = prm();
    check("straight", &p, 0.3, 1e-3, &line(p.clone()));
    check("straight, 0.3 mm steps", &p, 0.3, 0.3e-3, &line(p.clone()));
    check(
        "heading 30 deg to the grid",
        &p,
        0.3,
        1e-3,
        &Line {
            yaw: 30f64.to_radians(),
            ..line(p.clone())
        },
    );
    check(
        "12 mm deep",
        &p,
        0.3,
        1e-3,
        &Line {
            d0: 12e-3,
            ..line(p.clone())
        },
    );
    for slope in [0.1, 0.01, -0.01, -0.1] {
        check(
            &format!("slope {slope}"),
            &p,
            0.3,
            1e-3,
            &Line {
                d0: if slope > 0.0 { 1e-3 } else { 9e-3 },
                slope,
                ..line(p.clone())
            },
        );
    }
    for crab in [2.0f64, 10.0, -20.0] {
        check(
            &format!("crabbing {crab} deg"),
            &p,
            0.3,
            1e-3,
            &Line {
                crab: crab.to_radians(),
                ..line(p.clone())
            },
        );
    }
    check(
        "backwards",
        &p,
        0.3,
        1e-3,
        &Line {
            backwards: true,
            ..line(p.clone())
        },
    );
    check(
        "tilted 20 deg",
        &p,
        0.3,
        1e-3,
        &Line {
            roll: 20f64.to_radians(),
            ..line(p.clone())
        },
    );
    for (roll, crab, slope) in [
        (45.0f64, 0.0f64, -0.05),
        (-45.0, 0.0, 0.05),
        (30.0, 5.0, 0.0),
        (-30.0, 5.0, 0.0),
    ] {
        check(
            &format!("tilted {roll} deg, crabbing {crab} deg, slope {slope}"),
            &p,
            0.3,
            1e-3,
            &Line {
                roll: roll.to_radians(),
                crab: crab.to_radians(),
                d0: 6e-3,
                slope,
                ..line(p.clone())
            },
        );
    }
}

#[test]
fn curved_tracks_from_the_centre_to_the_gauge_cut_the_same_face() {
    let p = prm();
    // the tightest tracks swing the disc's back out of its groove faster
    // than the back rises, deep cuts the most
    for radius in [0.05f64, 0.1, 0.2, 0.45, 2.0] {
        for depth in [3.8e-3, 12e-3] {
            // (the 2 m track passes through the face's centre)
            check(
                &format!("{radius} m track, {} mm deep", depth * 1e3),
                &p,
                0.4,
                1e-3,
                &circle(&p, radius, depth),
            );
        }
    }
    // tilted discs turning either way (the gauge cutter: -60 deg on its
    // 4.83 m track)
    for (roll, radius) in [
        (-60.0f64, 4.83),
        (60.0, 4.83),
        (-30.0, 0.5),
        (30.0, 0.5),
        (10.0, 1.0),
        (-10.0, 1.0),
    ] {
        check(
            &format!("tilted {roll} deg, {radius} m track"),
            &p,
            0.3,
            1e-3,
            &tilted_arc(&p, roll, radius),
        );
    }
}

#[test]
fn a_disc_with_flanks_cuts_the_same_face() {
    let mut p = prm();
    p.cutter = CutterParams {
        flank_angle: 20f64.to_radians(),
        hub_width: 0.05,
        ..head_disc()
    };
    check(
        "19 in, 20 deg flanks, 14 mm deep",
        &p,
        0.3,
        1e-3,
        &Line {
            d0: 14e-3,
            ..line(p.clone())
        },
    );
    check(
        "19 in, 20 deg flanks, 0.3 m track",
        &p,
        0.4,
        1e-3,
        &circle(&p, 0.3, 8e-3),
    );
}

/// A second pass beside the groove of a first, and over it again.
#[test]
fn passes_beside_and_over_an_old_groove_cut_the_same_face() {
    let p = prm();
    let run = |whole: bool| {
        let mut q = p.clone();
        q.numerics.cut_behind = whole;
        let mut m = Model::new(q.clone()).unwrap();
        for (y, d) in [(0.0, 3.8e-3), (4e-3, 3.8e-3), (0.0, 6e-3), (-9e-3, 2e-3)] {
            let t = Line {
                yaw: 0.0,
                ..line(q.clone())
            };
            let t = Shifted { t, y, d };
            roll(&mut m, &t, 0.3, 1e-3, 0.0, 0.3);
        }
        m
    };
    let (a, b) = (run(true), run(false));
    assert!(a.state() == b.state(), "the states differ");
}

/// A [`Line`] moved `y` across and cut `d` deep.
struct Shifted {
    t: Line,
    y: f64,
    d: f64,
}

impl Track for Shifted {
    fn pose(&self, s: f64) -> Pose {
        let x = s - 0.25;
        pose_with_lowest_point(&self.t.prm, x, self.y, self.d, 0.0, 0.0)
    }
    fn twist(&self, s: f64) -> Twist {
        rolling_twist(&self.t.prm, &self.pose(s), 1.0, 0.0)
    }
}

/// A small head (face discs on 0.1-0.55 m tracks, one tilted), boring a
/// revolution and a half in 2 ms steps (sub-stepped) at 60 rpm.
#[test]
fn a_cutterhead_bores_the_same_face() {
    let disc = |track: f64, angle: f64, tilt: f64| DiscSpec {
        mount: Mount {
            track,
            angle: angle.to_radians(),
            tilt: tilt.to_radians(),
            setback: 0.0,
        },
        cutter: CutterParams::default(),
        spacing: 0.08,
    };
    let specs = vec![
        disc(0.10, 0.0, 0.0),
        disc(0.18, 180.0, 0.0),
        disc(0.25, 100.0, 0.0),
        disc(0.40, 200.0, 0.0),
        disc(0.55, 300.0, 15.0),
        // (leaning out 45 deg, as a head's outer gauge cutters do: its
        // lower face turns into the wall)
        disc(0.60, 60.0, 45.0),
    ];
    let bore = |whole: bool| {
        let mut p = face(1e-3, -0.75, 0.75, -0.75, 0.75);
        p.numerics.cut_behind = whole;
        let mut head = Head::new(p, specs.clone()).unwrap();
        let w = std::f64::consts::TAU;
        let twist = Twist::boring(w, 0.006);
        let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for _ in 0..750 {
            pose = head.advance_head(&pose, &twist, 2e-3).unwrap();
        }
        head
    };
    let (a, b) = (bore(true), bore(false));
    let cut = cut_nodes(a.map());
    assert!(cut > 20_000, "the head cut only {cut} nodes");
    assert_eq!(differ(a.map(), b.map()), (0, 0.0), "nodes differ");
    assert!(a.face() == b.face(), "the faces differ");
}

/// The box is there on the paths a face disc and a tilted disc run (so the
/// tests above hold something), and not where the argument fails: a track
/// too tight for the tip's slope, a tilted disc's lower face turning into
/// the rock, a jump.
#[test]
fn the_box_leaves_out_most_of_a_rolling_discs_window() {
    use kerf::core::cut_cutter_heightmap::{node_window, Back, Front};
    use kerf::core::cutter::PosedDisc;
    let p = prm();
    let posed = |pose: &Pose| PosedDisc::new(&p.cutter, pose);
    // the window on the face a straight pass has cut, 1 mm further on
    let mut m = Model::new(p.clone()).unwrap();
    let track = line(p.clone());
    roll(&mut m, &track, 0.2, 1e-3, 0.0, 0.2);
    let (d0, d1) = (posed(&track.pose(0.2)), posed(&track.pose(0.201)));
    let back = Back::of(&d0, None, &d1).expect("rolling on: a box");
    let tw = track.twist(0.201);
    let g = m.map().grid();
    let front = Front::of(&d1, &tw.velocity, &tw.omega, g, &p.numerics, 1.0);
    let nodes = |b| node_window(m.map(), &d1, front, b).map_or(0, |w| w.nodes());
    let (all, left) = (nodes(None), nodes(Some(back)));
    eprintln!("straight: {left} of {all} nodes walked");
    assert!(left * 4 < all, "{left} of {all}");
    // on tracks of 0.5 m down to 0.05 m, 12 mm deep, on the face a lap has
    // cut: a box, which leaves out much of the window. On the tight tracks
    // the back swings out, away from the track's centre, faster than the
    // section's edge rises, and the box stops short of that edge on the
    // outer side only (to within the 0.1 mm grid it is read on)
    for (radius, walked) in [(0.5, 0.5), (0.1, 0.6), (0.05, 0.75)] {
        let c = circle(&p, radius, 12e-3);
        let mut m = Model::new(p.clone()).unwrap();
        roll(&mut m, &c, 0.2, 1e-3, 0.0, 0.2);
        let (d0, d1) = (posed(&c.pose(0.2)), posed(&c.pose(0.201)));
        let back = Back::of(&d0, None, &d1).unwrap_or_else(|| panic!("{radius} m track: no box"));
        let tw = c.twist(0.201);
        let front = Front::of(&d1, &tw.velocity, &tw.omega, g, &p.numerics, 1.0);
        let nodes = |b| node_window(m.map(), &d1, front, b).map_or(0, |w| w.nodes());
        let (all, left) = (nodes(None), nodes(Some(back)));
        eprintln!("{radius} m track: {left} of {all} nodes walked");
        assert!(
            (left as f64) < walked * all as f64,
            "{radius} m: {left} of {all}"
        );
        // the box's reach either side of the last pose's mid-plane, on a
        // 0.1 mm grid, in the tip's half widths
        let gp = plan_grid(&d0, 0.1e-3);
        let axle = d0.rot.column(1);
        let (ax, ay) = (axle.x / axle.x.hypot(axle.y), axle.y / axle.x.hypot(axle.y));
        let (mut inner, mut outer) = (0.0f64, 0.0f64);
        for j in 0..gp.ny {
            for i in 0..gp.nx {
                if back.leaves_out(&gp, i, j) {
                    let (x, y) = gp.node_xy(i, j);
                    let l = ((x - d0.centre.x) * ax + (y - d0.centre.y) * ay) / d0.half_width;
                    let to_centre = (c.cx - d0.centre.x) * ax + (c.cy - d0.centre.y) * ay;
                    if l * to_centre > 0.0 {
                        inner = inner.max(l.abs());
                    } else {
                        outer = outer.max(l.abs());
                    }
                }
            }
        }
        eprintln!("{radius} m track: the box reaches {inner:.3} inside, {outer:.3} outside");
        assert!(inner > 0.97 && inner <= 1.0, "{radius} m: {inner} inside");
        if radius < 0.2 {
            assert!(outer < 0.9 * inner, "{radius} m: {outer} outside");
        } else {
            assert!(outer > 0.97, "{radius} m: {outer} outside");
        }
    }
    // a tilted disc rolling straight: a box, which leaves out most of the
    // window behind the disc on the face the pass has cut
    let tilted = Line {
        roll: 30f64.to_radians(),
        ..line(p.clone())
    };
    let mut m = Model::new(p.clone()).unwrap();
    roll(&mut m, &tilted, 0.2, 1e-3, 0.0, 0.2);
    let (t0, t1) = (posed(&tilted.pose(0.2)), posed(&tilted.pose(0.201)));
    let back = Back::of(&t0, None, &t1).expect("a tilted disc rolling on: a box");
    let tw = tilted.twist(0.201);
    let front = Front::of(&t1, &tw.velocity, &tw.omega, g, &p.numerics, 1.0);
    let nodes = |b| node_window(m.map(), &t1, front, b).map_or(0, |w| w.nodes());
    let (all, left) = (nodes(None), nodes(Some(back)));
    eprintln!("tilted 30 deg: {left} of {all} nodes walked");
    assert!(left * 2 < all, "{left} of {all}");
    // a gauge disc's arc (-60 deg on 4.83 m) gives a box that leaves out
    // nodes over the lower side face too; the same arc the other way round
    // turns that face into the rock behind it (a head's gauge cutters turn
    // so), and its box leaves out only nodes over the tip
    for (roll, over_face) in [(-60.0f64, true), (60.0, false)] {
        let arc = tilted_arc(&p, roll, 4.83);
        let last = posed(&arc.pose(0.1));
        let b = Back::of(&last, None, &posed(&arc.pose(0.101)))
            .unwrap_or_else(|| panic!("tilted {roll} deg on a 4.83 m arc: no box"));
        let g = plan_grid(&last, 0.5e-3);
        let n = g.nx;
        let (mut face, mut tip) = (0, 0);
        for j in 0..n {
            for i in 0..n {
                if b.leaves_out(&g, i, j) {
                    let (x, y) = g.node_xy(i, j);
                    match last.lower_boundary(x, y) {
                        Some((_, kerf::core::cutter::Face::Side(_))) => face += 1,
                        _ => tip += 1,
                    }
                }
            }
        }
        eprintln!("tilted {roll} deg: {face} nodes over the face and {tip} over the tip left out");
        assert_eq!(
            face > 0,
            over_face,
            "tilted {roll} deg: {face} over the face"
        );
        assert!(tip > 1000, "tilted {roll} deg: {tip} over the tip");
    }
    let mut beside = track.pose(0.201);
    beside.position.y += 7e-3;
    assert!(Back::of(&d0, None, &posed(&beside)).is_none());
}

/// A state restored is another history: the disc's last cut (made after
/// the state was taken, further on) gives no box for the next cut, which
/// walks its whole window. A host that rolls back and steps on from a pose
/// past the rock this history has cut gets the face of whole-window cuts,
/// bit for bit.
#[test]
fn a_restored_state_forgets_the_last_cut() {
    let p = prm();
    let track = line(p.clone());
    let run = |whole: bool| {
        let mut q = p.clone();
        q.numerics.cut_behind = whole;
        let mut m = Model::new(q).unwrap();
        roll(&mut m, &track, 0.1, 1e-3, 0.0, 0.1);
        let saved = m.state();
        // on to 0.15 m, then back to the state and on from 0.16 m: the rock
        // under the disc's back arc there was never cut in this history
        for k in 101..=150 {
            let s = k as f64 * 1e-3;
            m.commit(&track.pose(s), &track.twist(s), 1e-3).unwrap();
        }
        m.set_state(&saved).unwrap();
        let mut pose = track.pose(0.16);
        let tw = track.twist(0.16);
        for _ in 0..20 {
            pose = m.advance(&pose, &tw, 1e-3).unwrap();
        }
        m
    };
    let (a, b) = (run(true), run(false));
    assert_eq!(differ(a.map(), b.map()), (0, 0.0), "nodes differ");
    assert!(a.state() == b.state(), "the states differ");
}

/// The claim a box rests on, held node by node against the solids
/// themselves (no map): at every node a box leaves out, the last pose's
/// solid lies over the node and the solid now lies nowhere lower there
/// (`PosedDisc::lower_boundary`, to round-off). On a 0.25 mm grid, for
/// steps of 1 mm along tilted passes that climb, dive and crab (one tilted
/// by a millionth of a degree, which takes the tilted disc's argument), and
/// along arcs turning either way, upright and tilted.
#[test]
fn a_box_leaves_out_only_nodes_the_disc_has_risen_from() {
    use kerf::core::cut_cutter_heightmap::Back;
    use kerf::core::cutter::PosedDisc;
    let p = prm();
    let posed = |pose: &Pose| PosedDisc::new(&p.cutter, pose);
    let lines = [
        (0.0f64, 0.0f64, 0.0),
        (20.0, 0.0, 0.0),
        (45.0, 0.0, -0.05),
        (-45.0, 0.0, 0.05),
        (30.0, 5.0, 0.0),
        (-30.0, 5.0, 0.0),
        (60.0, 2.0, 0.01),
        (1e-6, 0.0, 0.0),
        (0.5, 0.0, -0.01),
    ]
    .map(|(roll, crab, slope)| {
        Box::new(Line {
            roll: roll.to_radians(),
            crab: crab.to_radians(),
            d0: 6e-3,
            slope,
            ..line(p.clone())
        }) as Box<dyn Track>
    });
    let arcs = [
        (-60.0f64, 4.83),
        (60.0, 4.83),
        (45.0, 4.5),
        (-30.0, 0.5),
        (30.0, 0.5),
        (10.0, 1.0),
        (0.0, 0.5),
        // face discs on centre tracks, turning either way (the back swings
        // out faster than the section's edge rises)
        (0.0, 0.05),
        (0.0, -0.05),
        (0.0, 0.1),
        (0.0, -0.2),
    ]
    .map(|(roll, radius)| Box::new(tilted_arc(&p, roll, radius)) as Box<dyn Track>);
    // and sinking as a head bores, 10 mm a metre of travel (a face disc on
    // a 0.1 m track at 6 mm a revolution sinks 10 mm a metre)
    let sinking = [0.05f64, -0.1, 0.3].map(|radius| {
        Box::new(Sinking {
            arc: tilted_arc(&p, 0.0, radius),
            rate: 0.01,
        }) as Box<dyn Track>
    });
    let mut boxes = 0;
    let mut left_out = 0;
    for (k, track) in lines.iter().chain(&arcs).chain(&sinking).enumerate() {
        let (d0, d1) = (posed(&track.pose(0.1)), posed(&track.pose(0.101)));
        let Some(back) = Back::of(&d0, None, &d1) else {
            eprintln!("track {k}: no box");
            continue;
        };
        boxes += 1;
        // a 0.25 mm grid over the disc's plan
        let g = plan_grid(&d1, 0.25e-3);
        let (n, _) =
            left_out_where_risen(&back, &d0, &d1, &g).unwrap_or_else(|e| panic!("track {k}: {e}"));
        left_out += n;
    }
    eprintln!("{boxes} boxes, {left_out} nodes left out");
    assert!(
        boxes >= 7 && left_out > 1_000_000,
        "{boxes} boxes, {left_out} nodes"
    );
}

/// Tilted discs on tracks of metres, descending as a head bores (6 mm a
/// revolution), leaning either way. Leaning out from the track's centre (a
/// head's gauge disc; roll -60 deg here) the lower side face turns into the
/// wall just behind the lowest point and away from it further back, so the
/// box is shortened at its near end to where the face turns away and leaves
/// out the whole core, the face's plan too (the hole that a box of the whole
/// length must walk is most of a gauge disc's window); leaning in, the face
/// turns into the wall along the whole box and is walked. Node by node on a
/// 0.25 mm grid, every node left out lies where the disc rose, and nodes
/// over the lower face are left out (so the shortened box is what is held:
/// without it, none are).
#[test]
fn a_descending_gauge_discs_box_leaves_out_its_lower_face_only_where_it_rose() {
    use kerf::core::cut_cutter_heightmap::Back;
    use kerf::core::cutter::PosedDisc;
    let p = prm();
    let posed = |pose: &Pose| PosedDisc::new(&p.cutter, pose);
    let mut over_face = 0usize;
    for (roll, radius) in [
        (60.0f64, 4.83),
        (52.0, 4.73),
        (45.0, 4.6),
        (-60.0, 4.83),
        (30.0, 4.4),
    ] {
        let track = tilted_arc(&p, roll, radius);
        // 1 mm of travel, the head boring 6 mm a revolution of this track
        let descent = 0.006 * 1e-3 / (std::f64::consts::TAU * radius);
        let p1 = track.pose(0.101);
        let p1 = Pose::from_rotation(
            p1.position - nalgebra::Vector3::z() * descent,
            &p1.rotation(),
        );
        let (d0, d1) = (posed(&track.pose(0.1)), posed(&p1));
        let back = Back::of(&d0, None, &d1).expect("a box");
        let g = plan_grid(&d1, 0.25e-3);
        let (_, face) = left_out_where_risen(&back, &d0, &d1, &g)
            .unwrap_or_else(|e| panic!("roll {roll}: {e}"));
        over_face += face;
    }
    assert!(
        over_face > 100_000,
        "{over_face} nodes over a side face left out"
    );
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: 96,
        failure_persistence: None,
        ..proptest::prelude::ProptestConfig::default()
    })]

    /// The upright disc's box against the two solids, node by node, for
    /// random moves between two poses: any heading, a turn of up to 2.6 deg
    /// either way, a step along the heading of up to 3 mm (forwards or
    /// backwards), a crab and a rise or sink of up to 1 mm, any spin about
    /// the axle; flat-sided and flanked discs. Every node a box leaves out
    /// on a 0.5 mm grid lies under the last solid, and the solid now lies
    /// nowhere lower there (to round-off).
    #[test]
    fn an_upright_discs_box_holds_for_random_moves(
        yaw in 0.0..std::f64::consts::TAU,
        turn in -0.045..0.045f64,
        step in -3e-3..3e-3f64,
        crab in -1e-3..1e-3f64,
        rise in -1e-3..1e-3f64,
        spin in (0.0..std::f64::consts::TAU, 0.0..std::f64::consts::TAU),
        flanked in proptest::bool::ANY,
    ) {
        use kerf::core::cut_cutter_heightmap::Back;
        use kerf::core::cutter::PosedDisc;
        let mut p = prm();
        if flanked {
            p.cutter = CutterParams {
                flank_angle: 20f64.to_radians(),
                hub_width: 0.05,
                ..p.cutter
            };
        }
        let (s, c) = yaw.sin_cos();
        let a = Pose::new(0.0, 0.0, 0.2, yaw, spin.0, 0.0);
        let b = Pose::new(
            step * c - crab * s,
            step * s + crab * c,
            0.2 + rise,
            yaw + turn,
            spin.1,
            0.0,
        );
        let (d0, d1) = (PosedDisc::new(&p.cutter, &a), PosedDisc::new(&p.cutter, &b));
        if let Some(back) = Back::of(&d0, None, &d1) {
            let g = plan_grid(&d1, 0.5e-3);
            let held = left_out_where_risen(&back, &d0, &d1, &g);
            proptest::prop_assert!(held.is_ok(), "{}", held.unwrap_err());
        }
    }
}

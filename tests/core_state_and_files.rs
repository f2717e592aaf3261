//! Surface files, sparse memory, the frame convention, the state blob and
//! friction: the core's contracts from interface.md.

use std::f64::consts::FRAC_PI_2;

use kerf::core::heightmap::{Grid, HeightMap};
use kerf::core::{rsf, KerfError, Model, ModelState, Params, Pose, Twist};
use nalgebra::{Matrix3, Vector3};

const R: f64 = 0.2159;

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("kerf-core-tests-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn small_params() -> Params {
    let mut p = Params::default();
    (p.rock.x_min, p.rock.x_max, p.rock.y_min, p.rock.y_max) = (-0.1, 0.3, -0.05, 0.05);
    (p.rock.nx, p.rock.ny) = (401, 101);
    p
}

fn roll_some(m: &mut Model, from: f64, steps: usize) -> Pose {
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut pose = Pose::new(from, 0.0, R - 0.0038, 0.0, 0.0, 0.0);
    for _ in 0..steps {
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
    }
    pose
}

#[test]
fn rsf_round_trip_is_exact_and_loads_as_the_initial_surface() {
    let params = small_params();
    let mut m = Model::new(params.clone()).unwrap();
    roll_some(&mut m, 0.0, 150);
    let path = tmp("roundtrip.rsf");
    m.write_surface(&path).unwrap();
    let mut p2 = params.clone();
    p2.rock.initial_surface = path.display().to_string();
    let m2 = Model::new(p2).unwrap();
    let g = *m.map().grid();
    for j in 0..g.ny {
        for i in 0..g.nx {
            assert_eq!(m.map().node(i, j), m2.map().node(i, j), "node {i} {j}");
        }
    }
    // the file is what interface.md says: `L K x y z`, comments with '#'
    let text = std::fs::read_to_string(&path).unwrap();
    let first = text.lines().find(|l| !l.starts_with('#')).unwrap();
    let f: Vec<f64> = first
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    assert_eq!((f[0], f[1], f[2], f[3]), (1.0, 1.0, -0.1, -0.05));
}

fn expect_file_error(body: &str, line: usize, needle: &str) {
    let path = tmp(&format!("bad-{line}-{}.rsf", needle.len()));
    std::fs::write(&path, body).unwrap();
    let g = Grid::new(0.0, 1.0, 0.0, 1.0, 2, 2);
    match rsf::read(&path, g, 0.0) {
        Err(KerfError::SurfaceFile {
            file,
            line: l,
            what,
        }) => {
            assert!(file.ends_with(path.file_name().unwrap().to_str().unwrap()));
            assert_eq!(l, line, "{what}");
            assert!(what.contains(needle), "{what}");
            // the message names the file and the line
            let msg = KerfError::SurfaceFile {
                file,
                line: l,
                what,
            }
            .to_string();
            assert!(
                msg.contains(".rsf") && (line == 0 || msg.contains(&format!("line {line}"))),
                "{msg}"
            );
        }
        other => panic!("expected a surface-file error, got {other:?}"),
    }
}

#[test]
fn malformed_surface_files_are_errors_that_name_file_and_line() {
    let good = "1 1 0 0 0\n2 1 1 0 0\n1 2 0 1 0\n2 2 1 1 0\n";
    let g = Grid::new(0.0, 1.0, 0.0, 1.0, 2, 2);
    let path = tmp("good.rsf");
    std::fs::write(&path, format!("# comment\n{good}")).unwrap();
    assert!(rsf::read(&path, g, 0.0).is_ok());
    expect_file_error("1 1 0 0 0\n2 1 1 0\n", 2, "5 fields");
    expect_file_error("1 1 0 0 0\n2 1 1 0 zz\n", 2, "not a number");
    expect_file_error("1 1 0 0 0\n3 1 1 0 0\n", 2, "node index");
    expect_file_error("1 1 0 0 0\n2 1 1.5 0 0\n", 2, "declared grid");
    expect_file_error("1 1 0 0 0\n1 1 0 0 0\n", 2, "twice");
    expect_file_error("1 1 0 0 0\n2 1 1 0 nan\n", 2, "not finite");
    expect_file_error("1 1 0 0 0\n", 0, "needs 4");
    let missing = tmp("does-not-exist.rsf");
    assert!(matches!(
        rsf::read(&missing, g, 0.0),
        Err(KerfError::SurfaceFile { line: 0, .. })
    ));
    // and Model::new refuses a bad initial surface with that error
    let mut p = Params::default();
    p.rock.initial_surface = missing.display().to_string();
    assert!(matches!(Model::new(p), Err(KerfError::SurfaceFile { .. })));
}

#[test]
fn a_ten_metre_face_at_one_millimetre_allocates_only_what_is_cut() {
    let mut p = Params::default();
    (p.rock.x_min, p.rock.x_max, p.rock.y_min, p.rock.y_max) = (0.0, 10.0, 0.0, 10.0);
    (p.rock.nx, p.rock.ny) = (10_001, 10_001); // 1e8 nodes
    let mut m = Model::new(p).unwrap();
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut pose = Pose::new(4.5, 5.0, R - 0.0038, 0.0, 0.0, 0.0);
    pose = m.advance(&pose, &tw, 1.0).unwrap(); // 1 m in one swept step
    assert!((pose.position.x - 5.5).abs() < 1e-9);
    let bytes = m.map().memory_bytes();
    // a dense map would be 800 MB; the cut touches a strip 1 m x 13 mm
    assert!(bytes < 200_000_000 / 20, "{bytes} bytes");
    let o = m.evaluate(&pose, &tw).unwrap();
    assert!(o.excavated_volume > 3e-5 && o.in_contact);
}

#[test]
fn orientation_is_rz_ry_rx_with_active_right_handed_matrices() {
    let (yaw, pitch, roll): (f64, f64, f64) = (0.3, -0.2, 0.7);
    let rz = Matrix3::new(
        yaw.cos(),
        -yaw.sin(),
        0.0,
        yaw.sin(),
        yaw.cos(),
        0.0,
        0.0,
        0.0,
        1.0,
    );
    let ry = Matrix3::new(
        pitch.cos(),
        0.0,
        pitch.sin(),
        0.0,
        1.0,
        0.0,
        -pitch.sin(),
        0.0,
        pitch.cos(),
    );
    let rx = Matrix3::new(
        1.0,
        0.0,
        0.0,
        0.0,
        roll.cos(),
        -roll.sin(),
        0.0,
        roll.sin(),
        roll.cos(),
    );
    let expect = rz * ry * rx;
    let got = Pose::new(0.0, 0.0, 0.0, yaw, pitch, roll).rotation();
    assert!((got.matrix() - expect).norm() < 1e-14);
    // yaw 90 deg: the rolling direction (cutter x) is rock +y
    let r = Pose::new(0.0, 0.0, 0.0, FRAC_PI_2, 0.0, 0.0).rotation();
    assert!((r * Vector3::x() - Vector3::y()).norm() < 1e-15);
    // pitch > 0 turns cutter x towards rock -z (nose down)
    let r = Pose::new(0.0, 0.0, 0.0, 0.0, 0.3, 0.0).rotation();
    assert!((r * Vector3::x()).z < 0.0);
}

#[test]
fn state_blob_round_trips_and_replays_bit_for_bit() {
    let params = small_params();
    let mut m = Model::new(params.clone()).unwrap();
    let pose = roll_some(&mut m, 0.0, 80);
    let saved = ModelState::from_bytes(&m.state().to_bytes(), &params).unwrap();
    assert_eq!(saved, m.state());
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let run = |m: &mut Model| {
        let mut p = pose;
        let mut out = Vec::new();
        for _ in 0..60 {
            p = m.advance(&p, &tw, 1e-3).unwrap();
            out.push(m.evaluate(&p, &tw).unwrap());
        }
        out
    };
    let a = run(&mut m);
    m.set_state(&saved).unwrap();
    let b = run(&mut m);
    assert_eq!(a, b);
    // corrupt, truncated, foreign blobs are rejected
    let blob = saved.to_bytes();
    assert!(matches!(
        ModelState::from_bytes(&blob[..blob.len() - 3], &params),
        Err(KerfError::BadState(_))
    ));
    let mut bad = blob.clone();
    bad[0] ^= 0xff;
    assert!(ModelState::from_bytes(&bad, &params).is_err());
    let mut bad = blob.clone();
    bad[9] = 99; // version
    assert!(ModelState::from_bytes(&bad, &params).is_err());
    assert!(ModelState::from_bytes(b"hello", &params).is_err());
    let mut other = params.clone();
    other.rock.nx += 1;
    assert!(ModelState::from_bytes(&blob, &other).is_err());
}

#[test]
fn friction_is_zero_at_pure_rolling_finite_at_zero_slip_and_resists_side_slide() {
    let p = 3.8e-3;
    let mut m = Model::new(small_params()).unwrap();
    let pose = Pose::new(0.1, 0.0, R - p, 0.0, 0.0, 0.0);
    m.commit(&pose, &Twist::default(), 0.0).unwrap();
    let still = m.evaluate(&pose, &Twist::default()).unwrap();
    // spinning without moving: skid at the contact, friction resists it
    let spin = m
        .evaluate(&pose, &Twist::new([0.0; 3], [0.0, 1.0 / R, 0.0]))
        .unwrap();
    assert!(spin.force.iter().all(|f| f.is_finite()));
    // the rim bottom moves towards -x when spinning with wy > 0: friction on the cutter is +x
    assert!(spin.force[0] > 0.2 * still.normal_force, "{:?}", spin.force);
    // sliding sideways at 0.1 m/s: full friction towards -y, on top of the
    // cutting force of the groove wall the tip is pushed into
    let tw = Twist::new([0.0, 0.1, 0.0], [0.0; 3]);
    let side = m.evaluate(&pose, &tw).unwrap();
    let c = m.contact(&pose, &tw);
    let friction_y = side.force[1] - (c.rim_force + c.side_force).y;
    let load = c.rim_force.norm();
    assert!(
        (friction_y / load + 0.3).abs() < 0.01,
        "{}",
        friction_y / load
    );
    // vanishing slip: friction vanishes linearly (slope 1.5 mu / vs of the
    // cubic STEP at zero), no 0/0
    for v in [1e-12, 1e-9, 1e-6] {
        let tw = Twist::new([0.0, v, 0.0], [0.0; 3]);
        let tiny = m.evaluate(&pose, &tw).unwrap();
        let c = m.contact(&pose, &tw);
        let load = c.rim_force.norm();
        let expect = -load * 1.5 * 0.3 * v / 0.01;
        let friction = tiny.side_force - c.rim_force.y - c.side_force.y;
        assert!(
            ((friction - expect) / expect).abs() < 1e-3,
            "v={v}: {friction} vs {expect}"
        );
    }
    let zero = m.evaluate(&pose, &Twist::default()).unwrap();
    assert!(zero.side_force.abs() < 1e-12 * load, "{}", zero.side_force);
}

#[test]
fn non_finite_and_absurd_inputs_are_errors_not_panics() {
    let m = Model::new(small_params()).unwrap();
    let ok = Twist::default();
    for pose in [
        Pose::new(f64::NAN, 0.0, 0.2, 0.0, 0.0, 0.0),
        Pose::new(0.0, f64::INFINITY, 0.2, 0.0, 0.0, 0.0),
        Pose::new(0.0, 0.0, 1e9, 0.0, 0.0, 0.0),
        Pose::new(0.0, 0.0, 0.2, f64::NAN, 0.0, 0.0),
    ] {
        assert!(matches!(
            m.evaluate(&pose, &ok),
            Err(KerfError::BadInput { .. })
        ));
    }
    let pose = Pose::new(0.0, 0.0, 0.2, 0.0, 0.0, 0.0);
    assert!(m
        .evaluate(&pose, &Twist::new([f64::NAN, 0.0, 0.0], [0.0; 3]))
        .is_err());
    let mut m = m;
    assert!(m.advance(&pose, &ok, f64::NAN).is_err());
    assert!(m.advance(&pose, &ok, -1.0).is_err());
    assert!(m.commit(&pose, &ok, f64::INFINITY).is_err());
    // a cutter buried deeper than its diameter stays finite
    let deep = m
        .evaluate(&Pose::new(0.1, 0.0, -1.0, 0.0, 0.0, 0.0), &ok)
        .unwrap();
    assert!(deep
        .force
        .iter()
        .chain(deep.moment.iter())
        .all(|f| f.is_finite()));
    assert!(deep.contact_angle <= std::f64::consts::PI);
}

#[test]
fn bad_parameters_are_rejected_by_name() {
    type Case = (Box<dyn Fn(&mut Params)>, &'static str);
    let cases: Vec<Case> = vec![
        (Box::new(|p| p.cutter.radius = -1.0), "cutter.radius"),
        (Box::new(|p| p.cutter.tip_width = 0.03), "cutter.tipWidth"),
        (Box::new(|p| p.rock.nx = 1), "rock.nx"),
        (Box::new(|p| p.rock.ny = 0), "rock.ny"),
        (
            Box::new(|p| p.rock.plastic_fraction = 0.0),
            "rock.plasticFraction",
        ),
        (Box::new(|p| p.csm.ucs = f64::NAN), "rock.ucs"),
        (Box::new(|p| p.rock.x_max = p.rock.x_min), "rock.xMax"),
        (
            Box::new(|p| p.numerics.tip_slices = 4),
            "numerics.tipSlices",
        ),
    ];
    for (f, name) in cases {
        let mut p = Params::default();
        f(&mut p);
        match Model::new(p) {
            Err(e @ KerfError::BadParameter { .. }) => assert!(e.to_string().contains(name), "{e}"),
            Err(e) => panic!("{name}: wrong error {e}"),
            Ok(_) => panic!("{name}: accepted"),
        }
    }
}

#[test]
fn half_plastic_rock_follows_appendix_b() {
    // plasticFraction 0.5: one commit removes half the excess beyond the elastic layer
    let mut p = small_params();
    p.rock.plastic_fraction = 0.5;
    let mut m = Model::new(p).unwrap();
    let pose = Pose::new(0.1, 0.0, R - 0.002, 0.0, 0.0, 0.0);
    m.commit(&pose, &Twist::default(), 0.0).unwrap();
    let g = *m.map().grid();
    let i = ((0.1 - g.x_min) / g.dx).round() as usize;
    let j = ((0.0 - g.y_min) / g.dy).round() as usize;
    let expect = -0.5 * (0.002 - m.params().numerics.elastic_depth);
    assert!(
        (m.map().node(i, j) - expect).abs() < 1e-12,
        "{}",
        m.map().node(i, j)
    );
    let _ = HeightMap::flat(g, 0.0);
}

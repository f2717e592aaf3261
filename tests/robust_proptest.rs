//! Property tests (proptest) for issue 11: parameter validation against the
//! bounds table, and the core state's serialization round trip, including
//! corrupt blobs.

use kerf::core::params::{bounds, PARAMETER_BOUNDS};
use kerf::core::{KerfError, Model, ModelState, Params, Pose, Twist};
use proptest::prelude::*;

/// Sets the parameter called `name` (a row of the table) to `v`.
fn set(p: &mut Params, name: &str, v: f64) {
    let u = |v: f64| {
        if (0.0..1e18).contains(&v) {
            v as usize
        } else {
            usize::MAX
        }
    };
    match name {
        "cutter.radius" => p.cutter.radius = v,
        "cutter.tipWidth" => p.cutter.tip_width = v,
        "cutter.tipRadius" => p.cutter.tip_radius = v,
        "cutter.flankAngle" => p.cutter.flank_angle = v,
        "cutter.hubWidth" => p.cutter.hub_width = v,
        "rock.ucs" => p.csm.ucs = v,
        "rock.bts" => p.csm.bts = v,
        "csm.C" => p.csm.c = v,
        "csm.spacing" => p.csm.spacing = v,
        "csm.psi" => p.csm.psi = v,
        "friction.mu" => p.friction.mu = v,
        "friction.vs" => p.friction.vs = v,
        "rock.xMin" => p.rock.x_min = v,
        "rock.xMax" => p.rock.x_max = v,
        "rock.yMin" => p.rock.y_min = v,
        "rock.yMax" => p.rock.y_max = v,
        "rock.nx" => p.rock.nx = u(v),
        "rock.ny" => p.rock.ny = u(v),
        "rock.z0" => p.rock.z0 = v,
        "rock.plasticFraction" => p.rock.plastic_fraction = v,
        "numerics.tipSlices" => p.numerics.tip_slices = u(v),
        "numerics.arcStepCells" => p.numerics.arc_step_cells = v,
        "numerics.ringStepCells" => p.numerics.ring_step_cells = v,
        "numerics.elasticDepth" => p.numerics.elastic_depth = v,
        "numerics.pReg" => p.numerics.p_reg = v,
        "numerics.sweepStep" => p.numerics.sweep_step = v,
        "chipping.kappa" => p.chipping.kappa = v,
        "chipping.length" => p.chipping.length = v,
        "chipping.lengthSpread" => p.chipping.length_spread = v,
        "chipping.pressureScale" => p.chipping.pressure_scale = v,
        other => panic!("no setter for {other}"),
    }
}

fn any_value() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>(),
        -1e4..1e4f64,
        -2.0..2.0f64,
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(0.0),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    /// Any value of any one parameter: validation never panics; outside the
    /// table's range it is refused naming the parameter and its range;
    /// inside, a refusal comes from a rule between parameters.
    #[test]
    fn validation_follows_the_bounds_table(row in 0..PARAMETER_BOUNDS.len(), v in any_value()) {
        let (name, lo, hi) = PARAMETER_BOUNDS[row];
        let mut p = Params::default();
        set(&mut p, name, v);
        let integer = matches!(name, "rock.nx" | "rock.ny" | "numerics.tipSlices");
        let stored = if integer { v.trunc() } else { v };
        let inside = stored >= lo && stored <= hi;
        match p.validate() {
            Ok(()) => prop_assert!(inside, "{name} = {v} accepted outside [{lo}, {hi}]"),
            Err(e @ KerfError::BadParameter { .. }) => {
                let msg = e.to_string();
                if inside {
                    prop_assert!(!msg.contains("allowed range"), "{msg}");
                } else {
                    prop_assert!(msg.contains(name) && msg.contains("allowed range"), "{msg}");
                }
            }
            Err(e) => prop_assert!(false, "{name} = {v}: wrong error {e}"),
        }
    }

    /// Values inside their range, all at once: every accepted set builds a
    /// model (nothing panics in the rules either).
    #[test]
    fn accepted_parameters_build_a_model(fs in proptest::collection::vec(0.0..=1.0f64, PARAMETER_BOUNDS.len())) {
        let mut p = Params::default();
        for (&(name, lo, hi), f) in PARAMETER_BOUNDS.iter().zip(&fs) {
            if matches!(name, "rock.nx" | "rock.ny" | "rock.xMin" | "rock.xMax" | "rock.yMin" | "rock.yMax") {
                continue; // keep the default face (building huge ones is slow, not wrong)
            }
            // log-uniform for positive ranges spanning decades
            let v = if lo > 0.0 && hi / lo > 100.0 {
                (lo.ln() + f * (hi.ln() - lo.ln())).exp().clamp(lo, hi)
            } else {
                lo + f * (hi - lo)
            };
            set(&mut p, name, if name == "numerics.tipSlices" { (2.0 * (v / 2.0).floor() + 1.0).min(hi) } else { v });
        }
        if p.validate().is_ok() {
            prop_assert!(Model::new(p).is_ok());
        }
    }
}

fn small() -> Params {
    let mut p = Params::default();
    p.rock.x_min = -0.1;
    p.rock.x_max = 0.3;
    p.rock.y_min = -0.05;
    p.rock.y_max = 0.05;
    p.rock.nx = 201;
    p.rock.ny = 51;
    p
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// A state after random cuts serializes and reads back equal; a second
    /// model restored from it is bit-identical in what it computes next.
    #[test]
    fn state_round_trip(steps in proptest::collection::vec((-0.05..0.25f64, -0.03..0.03f64, 0.0..0.006f64, -0.3..0.3f64, 0.0..0.02f64), 1..6), chips in any::<bool>()) {
        let mut p = small();
        p.chipping.enabled = chips;
        let mut m = Model::new(p.clone()).unwrap();
        let r = p.cutter.radius;
        let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / r, 0.0]);
        for &(x, y, d, yaw, h) in &steps {
            let pose = Pose::new(x, y, r - d, yaw, 0.0, 0.0);
            m.advance(&pose, &tw, h).unwrap();
        }
        let s = m.state();
        let b = s.to_bytes();
        let back = ModelState::from_bytes(&b, &p).unwrap();
        prop_assert!(back == s);
        prop_assert_eq!(back.to_bytes(), b);
        let mut m2 = Model::new(p.clone()).unwrap();
        m2.set_state(&back).unwrap();
        let pose = Pose::new(0.1, 0.0, r - 0.004, 0.0, 0.0, 0.0);
        let (a, c) = (m.evaluate(&pose, &tw).unwrap(), m2.evaluate(&pose, &tw).unwrap());
        prop_assert_eq!(format!("{a:?}"), format!("{c:?}"));
    }

    /// Corrupt blobs (flipped, truncated, extended, overwritten bytes) are
    /// refused or read; never a panic, never a state with another grid.
    #[test]
    fn corrupt_state_blobs_never_panic(flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..4), cut in any::<usize>(), mode in 0..3u8) {
        let p = small();
        let mut m = Model::new(p.clone()).unwrap();
        let r = p.cutter.radius;
        let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / r, 0.0]);
        m.advance(&Pose::new(0.0, 0.0, r - 0.004, 0.0, 0.0, 0.0), &tw, 0.02).unwrap();
        let mut b = m.state().to_bytes();
        for &(k, x) in &flips {
            let n = b.len();
            b[k % n] = x;
        }
        match mode {
            0 => b.truncate(cut % (b.len() + 1)),
            1 => b.extend(std::iter::repeat_n(0u8, cut % 64)),
            _ => {}
        }
        if let Ok(s) = ModelState::from_bytes(&b, &p) {
            prop_assert!(m.set_state(&s).is_ok());
        }
    }
}

/// The table the property tests above draw from holds: each parameter has
/// one row (so `bounds` finds that row), the defaults lie inside every
/// range, and this file's setter for a row reaches the field
/// `Params::validate` checks under that row's name: a value past either
/// end of the range is refused naming that parameter and its range, and
/// each end itself is not refused for its range.
#[test]
fn every_row_has_a_setter_and_a_range() {
    Params::default().validate().unwrap();
    let mut seen = std::collections::HashSet::new();
    for &(name, lo, hi) in PARAMETER_BOUNDS {
        assert!(seen.insert(name), "{name} has two rows");
        assert!(lo <= hi, "{name}");
        assert_eq!(bounds(name), Some((lo, hi)));
        for v in [lo - 1.0 - lo.abs(), hi + 1.0 + hi.abs()] {
            let mut p = Params::default();
            set(&mut p, name, v);
            let msg = p.validate().expect_err(name).to_string();
            assert!(
                msg.contains(name) && msg.contains("allowed range"),
                "{name} = {v}: {msg}"
            );
        }
        for v in [lo, hi] {
            let mut p = Params::default();
            set(&mut p, name, v);
            if let Err(e) = p.validate() {
                assert!(
                    !e.to_string().contains("allowed range"),
                    "{name} = {v}: {e}"
                );
            }
        }
    }
}

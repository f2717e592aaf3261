//! Issue 11, part 2: every parameter the issue's fuzzer found to abort, hang
//! or give nonsense is refused at fmi2ExitInitializationMode with its allowed
//! range in the message, and the modelDescription mirrors the core's table.

#[path = "fmi_support.rs"]
mod support;

use support::*;

enum V {
    R(u32, f64),
    I(u32, i32),
}

/// Sets `vals` in initialization mode; exit must fail naming `needle`.
fn refused(tag: &str, vals: &[V], needle: &str, range: bool) {
    let fmu = Fmu::new(&format!("robust-param-{tag}"), Kind::Cs);
    assert_eq!(fmu.setup(0.0), OK);
    assert_eq!(fmu.enter_init(), OK);
    for v in vals {
        match *v {
            V::R(r, x) => assert_eq!(fmu.set_real(r, x), OK),
            V::I(r, x) => assert_eq!(fmu.set_int(r, x), OK),
        }
    }
    assert_eq!(fmu.exit_init(), ERROR, "{tag} accepted");
    let e = fmu.last_error();
    assert!(e.contains(needle), "{tag}: {e}");
    if range {
        assert!(e.contains("allowed range ["), "{tag}: {e}");
    }
}

#[test]
fn the_issues_parameters_are_refused_with_their_range() {
    use V::*;
    refused(
        "arc",
        &[R(vr::NUMERICS_ARC_STEP_CELLS, 1e-9)],
        "numerics.arcStepCells",
        true,
    );
    refused(
        "arc6",
        &[R(vr::NUMERICS_ARC_STEP_CELLS, 1e-6)],
        "numerics.arcStepCells",
        true,
    );
    refused(
        "ring",
        &[R(vr::NUMERICS_RING_STEP_CELLS, 1e-3)],
        "numerics.ringStepCells",
        true,
    );
    refused(
        "radius",
        &[R(vr::CUTTER_RADIUS, 1e9)],
        "cutter.radius",
        true,
    );
    refused(
        "radius6",
        &[R(vr::CUTTER_RADIUS, 1e6)],
        "cutter.radius",
        true,
    );
    refused(
        "radius308",
        &[R(vr::CUTTER_RADIUS, 1e308)],
        "cutter.radius",
        true,
    );
    refused(
        "sweep",
        &[R(vr::NUMERICS_SWEEP_STEP, 1e-300)],
        "numerics.sweepStep",
        true,
    );
    refused("ucs", &[R(vr::ROCK_UCS, 1e308)], "rock.ucs", true);
    refused(
        "elastic",
        &[R(vr::NUMERICS_ELASTIC_DEPTH, 1e300)],
        "numerics.elasticDepth",
        true,
    );
    refused("psi", &[R(vr::CSM_PSI, 1e308)], "csm.psi", true);
    refused("z0", &[R(vr::ROCK_Z0, 1e308)], "rock.z0", true);
    refused("xmax", &[R(vr::ROCK_X_MAX, 1e308)], "rock.xMax", true);
    refused(
        "plastic",
        &[R(vr::ROCK_PLASTIC_FRACTION, 0.0)],
        "rock.plasticFraction",
        true,
    );
    // 2.5 nm cells under the old 1e10-node check
    refused(
        "nx",
        &[I(vr::ROCK_NX, 713_261_102), I(vr::ROCK_NY, 3)],
        "rock.nx",
        true,
    );
    // rules between parameters
    refused(
        "thin-face",
        &[R(vr::ROCK_X_MIN, 0.0), R(vr::ROCK_X_MAX, 1e-300)],
        "rock.xMax",
        false,
    );
    refused(
        "tiny-cells",
        &[
            I(vr::ROCK_NX, 30_001),
            R(vr::ROCK_X_MIN, 0.0),
            R(vr::ROCK_X_MAX, 0.01),
        ],
        "under the smallest",
        false,
    );
    refused(
        "budget",
        &[I(vr::ROCK_NX, 100_000), I(vr::ROCK_NY, 100_000)],
        "budget",
        false,
    );
    refused(
        "sweep-cells",
        &[R(vr::NUMERICS_SWEEP_STEP, 5e-6)],
        "numerics.sweepStep",
        false,
    );
}

/// Every bound of the core's table is the min/max of its variable in the
/// XML (build.rs fails otherwise; this checks the shipped file too), and
/// the defaults lie inside.
#[test]
fn model_description_mirrors_the_bounds_table() {
    let xml = include_str!("../modelDescription/modelDescription.xml");
    let doc = roxmltree::Document::parse(xml).unwrap();
    for &(name, lo, hi) in kerf::core::params::PARAMETER_BOUNDS {
        let sv = doc
            .descendants()
            .find(|n| n.has_tag_name("ScalarVariable") && n.attribute("name") == Some(name))
            .unwrap_or_else(|| panic!("{name} missing"));
        let ty = sv.children().find(|n| n.is_element()).unwrap();
        let get = |a: &str| ty.attribute(a).map(|s| s.parse::<f64>().unwrap());
        assert_eq!((get("min"), get("max")), (Some(lo), Some(hi)), "{name}");
        let start = get("start").unwrap();
        assert!(lo <= start && start <= hi, "{name}: start {start}");
    }
    assert!(kerf::core::Params::default().validate().is_ok());
}

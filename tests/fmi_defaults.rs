//! The start values of modelDescription.xml are `Params::default()`: parsed
//! straight from the XML here (independent of build.rs), and read back
//! through the FMI functions.

#[path = "fmi_support.rs"]
mod support;

use std::collections::HashMap;

use kerf::core::{CsmVariant, DirectionRule, Params};
use support::*;

fn xml_starts() -> HashMap<String, String> {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/modelDescription/modelDescription.xml"
    ))
    .unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("ScalarVariable"))
        .filter_map(|sv| {
            let ty = sv.children().find(|n| n.is_element())?;
            Some((
                sv.attribute("name")?.to_string(),
                ty.attribute("start")?.to_string(),
            ))
        })
        .collect()
}

#[test]
fn xml_start_values_equal_params_default() {
    let s = xml_starts();
    let real = |n: &str| -> f64 {
        s.get(n)
            .unwrap_or_else(|| panic!("{n} has no start"))
            .parse()
            .unwrap()
    };
    let int = |n: &str| -> i64 {
        s.get(n)
            .unwrap_or_else(|| panic!("{n} has no start"))
            .parse()
            .unwrap()
    };
    let d = Params::default();
    let checks: &[(&str, f64, f64)] = &[
        ("cutter.radius", real("cutter.radius"), d.cutter.radius),
        (
            "cutter.tipWidth",
            real("cutter.tipWidth"),
            d.cutter.tip_width,
        ),
        (
            "cutter.tipRadius",
            real("cutter.tipRadius"),
            d.cutter.tip_radius,
        ),
        (
            "cutter.flankAngle",
            real("cutter.flankAngle"),
            d.cutter.flank_angle,
        ),
        (
            "cutter.hubWidth",
            real("cutter.hubWidth"),
            d.cutter.hub_width,
        ),
        ("rock.ucs", real("rock.ucs"), d.csm.ucs),
        ("rock.bts", real("rock.bts"), d.csm.bts),
        ("csm.C", real("csm.C"), d.csm.c),
        ("csm.spacing", real("csm.spacing"), d.csm.spacing),
        ("csm.psi", real("csm.psi"), d.csm.psi),
        (
            "csm.variant",
            int("csm.variant") as f64,
            d.csm.variant as i32 as f64,
        ),
        ("friction.mu", real("friction.mu"), d.friction.mu),
        ("friction.vs", real("friction.vs"), d.friction.vs),
        ("rock.xMin", real("rock.xMin"), d.rock.x_min),
        ("rock.xMax", real("rock.xMax"), d.rock.x_max),
        ("rock.yMin", real("rock.yMin"), d.rock.y_min),
        ("rock.yMax", real("rock.yMax"), d.rock.y_max),
        ("rock.nx", int("rock.nx") as f64, d.rock.nx as f64),
        ("rock.ny", int("rock.ny") as f64, d.rock.ny as f64),
        ("rock.z0", real("rock.z0"), d.rock.z0),
        (
            "rock.plasticFraction",
            real("rock.plasticFraction"),
            d.rock.plastic_fraction,
        ),
        (
            "numerics.tipSlices",
            int("numerics.tipSlices") as f64,
            d.numerics.tip_slices as f64,
        ),
        (
            "numerics.arcStepCells",
            real("numerics.arcStepCells"),
            d.numerics.arc_step_cells,
        ),
        (
            "numerics.ringStepCells",
            real("numerics.ringStepCells"),
            d.numerics.ring_step_cells,
        ),
        (
            "numerics.elasticDepth",
            real("numerics.elasticDepth"),
            d.numerics.elastic_depth,
        ),
        ("numerics.pReg", real("numerics.pReg"), d.numerics.p_reg),
        (
            "numerics.sweepStep",
            real("numerics.sweepStep"),
            d.numerics.sweep_step,
        ),
        (
            "numerics.directionRule",
            int("numerics.directionRule") as f64,
            d.numerics.direction as i32 as f64,
        ),
        (
            "chipping.seed",
            int("chipping.seed") as f64,
            d.chipping.seed as f64,
        ),
        ("chipping.kappa", real("chipping.kappa"), d.chipping.kappa),
        (
            "chipping.length",
            real("chipping.length"),
            d.chipping.length,
        ),
        (
            "chipping.lengthSpread",
            real("chipping.lengthSpread"),
            d.chipping.length_spread,
        ),
        (
            "chipping.pressureScale",
            real("chipping.pressureScale"),
            d.chipping.pressure_scale,
        ),
    ];
    assert_eq!(s["chipping.enabled"], d.chipping.enabled.to_string());
    for (name, xml, core) in checks {
        assert_eq!(
            xml.to_bits(),
            core.to_bits(),
            "{name}: modelDescription.xml says {xml}, Params::default() {core}"
        );
    }
    assert_eq!(s["rock.initialSurface"], d.rock.initial_surface);
    assert_eq!(s["rock.finalSurface"], d.rock.final_surface);
    assert_eq!(
        d.csm.variant,
        CsmVariant::from_index(int("csm.variant") as i32).unwrap()
    );
    assert_eq!(d.numerics.direction, DirectionRule::Kerf);
    // Every parameter of the XML was compared above (or is one of the two strings).
    let params: Vec<_> = md_parameter_names();
    for p in &params {
        assert!(
            checks.iter().any(|(n, _, _)| n == p)
                || p == "rock.initialSurface"
                || p == "rock.finalSurface",
            "parameter {p} is not compared with Params::default()"
        );
    }
    // The interface fixes the start of z: R - 3.8 mm.
    assert_eq!(real("z"), 0.2121);
}

fn md_parameter_names() -> Vec<String> {
    let g = |c| {
        kerf::fmi2::md::REALS
            .iter()
            .filter(move |v| v.causality == c)
            .map(|v| v.name.to_string())
    };
    let c = kerf::fmi2::md::Causality::Parameter;
    g(c).chain(
        kerf::fmi2::md::INTEGERS
            .iter()
            .filter(|v| v.causality == c)
            .map(|v| v.name.to_string()),
    )
    .chain(
        kerf::fmi2::md::STRINGS
            .iter()
            .filter(|v| v.causality == c)
            .map(|v| v.name.to_string()),
    )
    .collect()
}

#[test]
fn fmi_reads_back_the_start_values() {
    let s = xml_starts();
    let fmu = Fmu::new("defaults-readback", Kind::Cs);
    assert_eq!(fmu.enter_init(), OK);
    for v in kerf::fmi2::md::REALS {
        if let Some(start) = v.start {
            assert_eq!(fmu.real(v.vr), start, "{}", v.name);
            assert_eq!(start, s[v.name].parse::<f64>().unwrap(), "{}", v.name);
        }
    }
    for v in kerf::fmi2::md::INTEGERS {
        if v.causality == kerf::fmi2::md::Causality::Output {
            continue;
        }
        let (st, got) = fmu.get_int(v.vr);
        assert_eq!(st, OK);
        assert_eq!(got.to_string(), s[v.name], "{}", v.name);
    }
    for v in kerf::fmi2::md::STRINGS {
        let (st, got) = fmu.get_string(v.vr);
        assert_eq!(st, OK);
        assert_eq!(got, s[v.name], "{}", v.name);
    }
}

#[test]
fn every_output_is_readable_and_finite_in_initialization_mode() {
    for kind in [Kind::Me, Kind::Cs] {
        let fmu = Fmu::new(&format!("defaults-outputs-{kind:?}"), kind);
        assert_eq!(fmu.enter_init(), OK);
        let outs = real_outputs();
        assert_eq!(outs.len(), 15);
        let (s, v) = fmu.get_reals(&outs);
        assert_eq!(s, OK, "{:?}", fmu.errors());
        assert!(v.iter().all(|x| x.is_finite()), "{v:?}");
        let (s, in_contact) = fmu.get_bool(vr::IN_CONTACT);
        assert_eq!(s, OK);
        // Default z = R - 3.8 mm over the flat face at z0 = 0: pressed.
        assert!(in_contact);
        assert!(fmu.real(vr::NORMAL_FORCE) > 0.0);
        assert_eq!(fmu.exit_init(), OK);
    }
}

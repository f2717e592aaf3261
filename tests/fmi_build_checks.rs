//! build.rs refuses a broken modelDescription.xml: each case below breaks
//! the real file in one way and expects the build-time check to fail with a
//! message that names the problem.

#[allow(dead_code)]
#[path = "../build.rs"]
mod build_script;

const XML: &str = include_str!("../modelDescription/modelDescription.xml");

fn fails_with(xml: &str, needle: &str) {
    assert_ne!(
        xml, XML,
        "the mutation did not apply (expecting \"{needle}\")"
    );
    let r = std::panic::catch_unwind(|| build_script::check_and_generate(xml));
    let err = r.expect_err(&format!(
        "build.rs accepted a description that should fail with \"{needle}\""
    ));
    let msg = err
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| err.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_default();
    assert!(msg.contains(needle), "expected \"{needle}\" in: {msg}");
}

/// `XML` with the first occurrence of `from` replaced.
fn edit(from: &str, to: &str) -> String {
    assert!(XML.contains(from), "{from} not in the XML");
    XML.replacen(from, to, 1)
}

#[test]
fn the_real_description_passes() {
    let code = build_script::check_and_generate(XML);
    assert!(code.contains("pub const GUID"));
    assert!(code.contains("pub const CUTTER_RADIUS: u32 = 201;"));
}

#[test]
fn duplicate_value_references() {
    fails_with(
        &edit(r#"valueReference="202""#, r#"valueReference="201""#),
        "duplicate Real value reference 201",
    );
    // Integer and Enumeration share fmi2GetInteger: rock.nx (2) against csm.variant (1).
    fails_with(
        &edit(
            r#"name="rock.nx" valueReference="2""#,
            r#"name="rock.nx" valueReference="1""#,
        ),
        "duplicate Integer value reference 1",
    );
}

#[test]
fn illegal_causality_variability_initial() {
    fails_with(
        &edit(
            r#"name="cutter.radius" valueReference="201" causality="parameter" variability="fixed""#,
            r#"name="cutter.radius" valueReference="201" causality="parameter" variability="continuous""#,
        ),
        "not a legal FMI 2.0 combination",
    );
    fails_with(
        &edit(
            r#"name="x" valueReference="1" causality="input" variability="continuous""#,
            r#"name="x" valueReference="1" causality="input" variability="continuous" initial="exact""#,
        ),
        "initial=\"exact\" is not allowed",
    );
    fails_with(
        &edit(
            r#"name="cutter.radius" valueReference="201" causality="parameter" variability="fixed" initial="exact""#,
            r#"name="cutter.radius" valueReference="201" causality="parameter" variability="fixed" initial="calculated""#,
        ),
        "initial=\"calculated\" is not allowed",
    );
    fails_with(
        &edit(
            r#"<Real unit="N" displayUnit="kN"/>"#,
            r#"<Real unit="N" displayUnit="kN" start="1"/>"#,
        ),
        "start value is not allowed",
    );
    fails_with(
        &edit(
            r#"<Real unit="m" displayUnit="mm" start="0"/>"#,
            r#"<Real unit="m" displayUnit="mm"/>"#,
        ),
        "start value is required",
    );
    fails_with(
        &edit(
            r#"name="inContact" valueReference="1" causality="output" variability="discrete""#,
            r#"name="inContact" valueReference="1" causality="output" variability="continuous""#,
        ),
        "only Real variables may have variability=\"continuous\"",
    );
}

#[test]
fn units() {
    fails_with(
        &edit(r#"<Real unit="N" displayUnit="kN"/>"#, r#"<Real/>"#),
        "a Real needs a unit",
    );
    fails_with(
        &edit(
            r#"<Real unit="N" displayUnit="kN"/>"#,
            r#"<Real unit="lbf"/>"#,
        ),
        "unit \"lbf\" is not in <UnitDefinitions>",
    );
    fails_with(
        &edit(
            r#"<Real unit="N" displayUnit="kN"/>"#,
            r#"<Real unit="N" displayUnit="MN"/>"#,
        ),
        "displayUnit \"MN\"",
    );
    fails_with(
        &edit(
            r#"<Real unit="N" displayUnit="kN"/>"#,
            r#"<Real unit="Pa" displayUnit="MPa"/>"#,
        ),
        "must have unit \"N\"",
    );
}

#[test]
fn interface_variables() {
    fails_with(
        &edit(r#"name="sideForce""#, r#"name="lateralForce""#),
        "interface variable \"sideForce\"",
    );
    fails_with(
        &edit(
            r#"name="numerics.pReg""#,
            r#"name="numerics.regularization""#,
        ),
        "interface variable \"numerics.pReg\"",
    );
    fails_with(
        &edit(r#"start="0.2121""#, r#"start="0.2""#),
        "must start at 0.2121",
    );
    fails_with(
        &edit(
            r#"name="friction.mu" valueReference="209" causality="parameter" variability="fixed" initial="exact""#,
            r#"name="friction.mu" valueReference="209" causality="calculatedParameter" variability="fixed" initial="approx""#,
        ),
        "must have causality parameter",
    );
}

#[test]
fn enumerations() {
    fails_with(
        &edit(
            r#"<Enumeration declaredType="CsmVariant" start="1"/>"#,
            r#"<Enumeration declaredType="CsmVariant" start="6"/>"#,
        ),
        "start 6 is not an item",
    );
    fails_with(
        &edit(
            r#"<Enumeration declaredType="DirectionRule" start="1"/>"#,
            r#"<Enumeration declaredType="Direction" start="1"/>"#,
        ),
        "declaredType \"Direction\"",
    );
}

#[test]
fn model_structure() {
    fails_with(
        &edit(
            r#"    <Outputs>
      <Unknown index="13"/>
"#,
            "    <Outputs>\n",
        ),
        "<Outputs> must list each output once",
    );
    fails_with(
        &edit(
            r#"    <InitialUnknowns>
      <Unknown index="13"/>
"#,
            "    <InitialUnknowns>\n      <Unknown index=\"28\"/>\n",
        ),
        "<InitialUnknowns> must be exactly",
    );
    fails_with(
        &edit(
            "  <ModelStructure>\n",
            "  <ModelStructure>\n    <Derivatives/>\n",
        ),
        "<Derivatives>",
    );
}

#[test]
fn capabilities() {
    fails_with(
        &edit(
            r#"canGetAndSetFMUstate="true""#,
            r#"canGetAndSetFMUstate="false""#,
        ),
        "canGetAndSetFMUstate",
    );
    fails_with(
        &edit(r#"modelIdentifier="kerf""#, r#"modelIdentifier="kerf2""#),
        "modelIdentifier",
    );
}

#[test]
fn event_indicator_count_and_default_experiment_tolerance() {
    fails_with(
        &edit(
            r#"numberOfEventIndicators="1""#,
            r#"numberOfEventIndicators="0""#,
        ),
        "numberOfEventIndicators must be 1",
    );
    fails_with(
        &edit(r#" tolerance="1e-6""#, ""),
        "<DefaultExperiment> needs a tolerance",
    );
    fails_with(
        &edit(r#"tolerance="1e-6""#, r#"tolerance="0""#),
        "<DefaultExperiment> needs a tolerance",
    );
    let code = build_script::check_and_generate(XML);
    assert!(code.contains("pub const NUMBER_OF_EVENT_INDICATORS: usize = 1;"));
}

#[test]
fn a_start_outside_its_range_and_a_range_upside_down() {
    let radius = r#"<Real unit="m" displayUnit="mm" min="0.02" max="2" start="0.2159"/>"#;
    fails_with(
        &edit(
            radius,
            r#"<Real unit="m" displayUnit="mm" min="0.02" max="2" start="3"/>"#,
        ),
        "cutter.radius: start 3 outside [Some(0.02), Some(2.0)]",
    );
    fails_with(
        &edit(
            radius,
            r#"<Real unit="m" displayUnit="mm" min="2" max="0.02" start="0.2159"/>"#,
        ),
        "cutter.radius: min 2 > max 0.02",
    );
    let nx = r#"<Integer min="2" max="100000000" start="1501"/>"#;
    fails_with(
        &edit(nx, r#"<Integer min="2" max="100000000" start="1"/>"#),
        "rock.nx: start 1 outside [Some(2), Some(100000000)]",
    );
    fails_with(
        &edit(nx, r#"<Integer min="100000000" max="2" start="1501"/>"#),
        "rock.nx: min 100000000 > max 2",
    );
}

//! Layout files: the contract's example parses; bad files are rejected with
//! messages that name the file, the cutter and the key.

use kerf::core::head::{default_params, default_rock, DiscSpec, Head};
use kerf::core::layout::{load, parse};
use kerf::core::Params;

const EXAMPLE: &str = r#"{
  "name": "head-demo",
  "disc": {"radius": 0.2159, "tipWidth": 0.013, "tipRadius": 0.0127},
  "cutters": [
    {"track": 0.30, "angleDeg": 0,   "tiltDeg": 0,  "setback": 0.0, "spacing": 0.085},
    {"track": 2.95, "angleDeg": 137, "tiltDeg": 35, "setback": 0.02, "spacing": 0.06,
     "disc": {"radius": 0.2413}}
  ]
}"#;

#[test]
fn the_contract_example_parses() {
    let l = parse(EXAMPLE, "x.json").unwrap();
    assert_eq!(l.name, "head-demo");
    assert_eq!(l.cutters.len(), 2);
    let c = &l.cutters[1];
    assert_eq!(
        (c.track, c.angle_deg, c.tilt_deg, c.setback, c.spacing),
        (2.95, 137.0, 35.0, 0.02, 0.06)
    );
    // the cutter's own disc overrides the default key by key
    assert_eq!(c.disc.radius, 0.2413);
    assert_eq!(c.disc.tip_width, 0.013);
    assert_eq!(l.cutters[0].disc.radius, 0.2159);
    // reach: the tilted gauge disc leans out by R sin(35 deg)
    let want = 2.95 + 0.2413 * 35f64.to_radians().sin() + 0.0065 * 35f64.to_radians().cos();
    assert!((l.reach() - want).abs() < 1e-12);
    let (half, n) = default_rock(&l);
    assert!(half >= want + 0.02 && half < want + 0.021, "{half}");
    assert_eq!(n, (2000.0 * half).round() as usize + 1);
}

fn err(text: &str) -> String {
    parse(text, "bad.json").unwrap_err().to_string()
}

fn with_cutter(c: &str) -> String {
    format!(
        r#"{{"name": "h", "disc": {{"radius": 0.2159, "tipWidth": 0.013, "tipRadius": 0.0127}},
        "cutters": [{{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08}}, {c}]}}"#
    )
}

#[test]
fn bad_layouts_name_file_cutter_and_key() {
    let cases: &[(&str, &str)] = &[
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0}"#,
            "layout bad.json: cutter 2: key \"spacing\": missing",
        ),
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08, "tilt": 3}"#,
            "layout bad.json: cutter 2: key \"tilt\": unknown key",
        ),
        (
            r#"{"track": -0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08}"#,
            "layout bad.json: cutter 2: key \"track\": -0.3 is out of range [0, 10]",
        ),
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 95, "setback": 0, "spacing": 0.08}"#,
            "layout bad.json: cutter 2: key \"tiltDeg\": 95 is out of range [-75, 75]",
        ),
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0}"#,
            "layout bad.json: cutter 2: key \"spacing\": 0 is out of range [0.001, 1]",
        ),
        // (the disc's own ranges are kerf.fmu's, `bounds.rs`: a layout that
        // loads packages a head FMU that builds)
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.0001}"#,
            "layout bad.json: cutter 2: key \"spacing\": 0.0001 is out of range [0.001, 1]",
        ),
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08, "disc": {"radius": 0.01}}"#,
            "layout bad.json: cutter 2: key \"disc.radius\": 0.01 is out of range [0.02, 2]",
        ),
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08, "disc": {"radius": 0.03, "tipRadius": 0.05, "tipWidth": 0.01}}"#,
            "layout bad.json: cutter 2: key \"disc.tipRadius\": 0.05 must be smaller than radius = 0.03",
        ),
        (
            r#"{"track": 0.3, "angleDeg": "east", "tiltDeg": 0, "setback": 0, "spacing": 0.08}"#,
            "layout bad.json: cutter 2: key \"angleDeg\": must be a number",
        ),
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08, "disc": {"radius": -1}}"#,
            "layout bad.json: cutter 2: key \"disc.radius\": -1 is out of range [0.02, 2]",
        ),
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08, "disc": {"tipWidth": 0.03}}"#,
            "layout bad.json: cutter 2: key \"disc.tipWidth\": 0.03 exceeds 2 * tipRadius",
        ),
        (
            r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08, "disc": {"rim": 0.03}}"#,
            "layout bad.json: cutter 2: key \"disc.rim\": unknown key",
        ),
    ];
    for (c, want) in cases {
        let got = err(&with_cutter(c));
        assert!(got.starts_with(want), "\n got: {got}\nwant: {want}...");
    }
    // a key given twice (serde_json's Value would keep the last silently)
    let got = err(&with_cutter(
        r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08, "spacing": 0.09}"#,
    ));
    assert!(
        got.starts_with("layout bad.json: not valid JSON: key \"spacing\" given twice at line"),
        "{got}"
    );
    let got = err(&with_cutter(
        r#"{"track": 0.3, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08, "disc": {"radius": 0.2, "radius": 0.3}}"#,
    ));
    assert!(got.contains("key \"radius\" given twice"), "{got}");
    // a number past f64's range
    let got = err(&with_cutter(
        r#"{"track": 1e400, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.08}"#,
    ));
    assert!(
        got.starts_with("layout bad.json: not valid JSON: number out of range at line"),
        "{got}"
    );
    // head-level keys
    assert!(
        err(r#"{"disc": {}, "cutters": []}"#).starts_with("layout bad.json: key \"name\": missing")
    );
    assert!(err(r#"{"name": "a b", "disc": {}, "cutters": []}"#)
        .starts_with("layout bad.json: key \"name\": \"a b\" must be"));
    assert!(err(r#"{"name": "a", "cutters": []}"#)
        .starts_with("layout bad.json: key \"disc\": missing"));
    assert!(
        err(r#"{"name": "a", "disc": {"radius": 0.2}, "cutters": []}"#)
            .starts_with("layout bad.json: key \"disc.tipWidth\": missing")
    );
    assert!(err(r#"{"name": "a", "disc": {"radius": 0.2, "tipWidth": 0.01, "tipRadius": 0.01}, "cutters": []}"#)
        .starts_with("layout bad.json: key \"cutters\": must hold 1 to 500 cutters, holds 0"));
    assert!(err(r#"{"name": "a", "disc": {"radius": 0.2, "tipWidth": 0.01, "tipRadius": 0.01}, "cutters": [], "rpm": 3}"#)
        .starts_with("layout bad.json: key \"rpm\": unknown key"));
    assert!(err("{").starts_with("layout bad.json: not valid JSON"));
    let e = load(std::path::Path::new("/nonexistent/h.json"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("layout /nonexistent/h.json: cannot read"),
        "{e}"
    );
}

#[test]
fn bad_disc_parameters_name_the_cutter() {
    let l = parse(EXAMPLE, "x.json").unwrap();
    let mut specs: Vec<DiscSpec> = l.cutters.iter().map(DiscSpec::from_layout).collect();
    specs[1].cutter.tip_radius = 0.3;
    let e = Head::new(Params::default(), specs.clone())
        .err()
        .unwrap()
        .to_string();
    assert!(e.starts_with("parameter cutter[2].tipRadius = 0.3"), "{e}");
    specs[1].cutter.tip_radius = 0.0127;
    specs[0].mount.tilt = 2.0;
    let e = Head::new(Params::default(), specs)
        .err()
        .unwrap()
        .to_string();
    assert!(e.starts_with("parameter cutter[1].tilt = 2"), "{e}");
}

#[test]
fn shipped_layouts_parse() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("layouts");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "json") {
            let l = load(&p).unwrap();
            let specs: Vec<DiscSpec> = l.cutters.iter().map(DiscSpec::from_layout).collect();
            Head::new(Params::default(), specs).unwrap();
            n += 1;
        }
    }
    assert!(n >= 2, "layouts/ holds {n} layouts");
}

#[test]
fn default_params_keep_the_default_rock_square_at_any_dividing_cell() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("layouts");
    let mut n_layouts = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "json") {
            let l = load(&p).unwrap();
            let (half, n) = default_rock(&l);
            for (cell, nodes) in [(1e-3, n), (0.5e-3, 2 * n - 1), (2e-3, (n - 1) / 2 + 1)] {
                let r = default_params(&l, cell).rock;
                assert_eq!(
                    (r.nx, r.ny, r.x_min, r.x_max, r.y_min, r.y_max),
                    (nodes, nodes, -half, half, -half, half),
                    "{} at {cell} m",
                    p.display()
                );
            }
            n_layouts += 1;
        }
    }
    assert!(n_layouts >= 2, "layouts/ holds {n_layouts} layouts");
}

/// The head FMU's modelDescription gives each disc's own parameters the
/// range the head checks them against (kerf.fmu's, `bounds.rs`), which is
/// also what a layout may hold; no range of any parameter is missing a
/// bound or NaN.
#[test]
fn the_head_fmus_disc_parameter_ranges_are_the_ones_it_accepts() {
    use kerf::core::head::Drive;
    use kerf::core::params::bounds;
    use kerf::fmi2::head_md::{self, Ty};
    let l = parse(EXAMPLE, "x.json").unwrap();
    for drive in [Drive::Head, Drive::Discs] {
        let vars = head_md::variables(&l, drive);
        let mut checked = 0;
        for (key, kerf) in [
            ("radius", "cutter.radius"),
            ("tipWidth", "cutter.tipWidth"),
            ("tipRadius", "cutter.tipRadius"),
            ("spacing", "csm.spacing"),
        ] {
            let (lo, hi) = bounds(kerf).unwrap();
            for i in 1..=l.cutters.len() {
                let name = format!("cutter[{i}].{key}");
                let v = vars.iter().find(|v| v.name == name).expect(&name);
                assert_eq!((v.min, v.max), (Some(lo), Some(hi)), "{name}");
                checked += 1;
            }
        }
        assert_eq!(checked, 4 * l.cutters.len());
        for v in vars.iter().filter(|v| v.ty == Ty::Real) {
            for b in [v.min, v.max].into_iter().flatten() {
                assert!(!b.is_nan(), "{}: NaN bound", v.name);
            }
        }
    }
    // and a layout at those ends builds a head
    let at = |r: f64, s: f64| {
        let json = EXAMPLE
            .replace("\"radius\": 0.2413", &format!("\"radius\": {r}"))
            .replace("\"spacing\": 0.06", &format!("\"spacing\": {s}"));
        let l = parse(&json, "x.json").unwrap();
        let specs: Vec<DiscSpec> = l.cutters.iter().map(DiscSpec::from_layout).collect();
        Head::new(Params::default(), specs).map(|_| ())
    };
    at(
        bounds("cutter.radius").unwrap().0,
        bounds("csm.spacing").unwrap().0,
    )
    .unwrap();
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 2000, ..Default::default() })]

    /// Any corruption of a layout file (bytes overwritten, cut short or
    /// repeated) is read or refused, never a panic, and every refusal names
    /// the file; whatever is read holds only cutters a head accepts.
    #[test]
    fn corrupt_layouts_are_refused_naming_the_file(
        edits in proptest::collection::vec((0usize..10_000, proptest::prelude::any::<u8>()), 0..6),
        cut in 0usize..10_000,
        mode in 0u8..3,
    ) {
        let mut b = EXAMPLE.as_bytes().to_vec();
        for &(k, x) in &edits {
            let n = b.len();
            b[k % n] = x;
        }
        match mode {
            0 => b.truncate(cut % (b.len() + 1)),
            1 => {
                let n = b.len();
                let s = cut % n;
                let piece = b[s..(s + 40).min(n)].to_vec();
                b.splice(s..s, piece);
            }
            _ => {}
        }
        let text = String::from_utf8_lossy(&b);
        match parse(&text, "x.json") {
            Err(e) => proptest::prop_assert!(e.to_string().starts_with("layout x.json: "), "{e}"),
            Ok(l) => {
                let specs: Vec<DiscSpec> = l.cutters.iter().map(DiscSpec::from_layout).collect();
                proptest::prop_assert!(Head::new(Params::default(), specs).is_ok());
            }
        }
    }
}

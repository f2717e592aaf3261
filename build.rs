//! Build script: reads `modelDescription/modelDescription.xml` (the single
//! source of truth for the FMU's variables), checks it against FMI 2.0 and the
//! interface contract (`interface.md`), and generates the Rust tables of the
//! FMI layer (value references, names, start values, GUID) into
//! `$OUT_DIR/model_description.rs`, which `src/fmi2/md.rs` includes.
//!
//! Any inconsistency fails the build with a message naming the variable.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fmt::Write as _;
use std::path::PathBuf;

/// The interface of `interface.md` (name, FMI type, causality, unit) plus the
/// numerical parameters whose names are fixed. The XML may declare more
/// variables, but never fewer.
const INTERFACE: &[(&str, &str, &str, &str)] = &[
    ("x", "Real", "input", "m"),
    ("y", "Real", "input", "m"),
    ("z", "Real", "input", "m"),
    ("yaw", "Real", "input", "rad"),
    ("pitch", "Real", "input", "rad"),
    ("roll", "Real", "input", "rad"),
    ("vx", "Real", "input", "m/s"),
    ("vy", "Real", "input", "m/s"),
    ("vz", "Real", "input", "m/s"),
    ("wx", "Real", "input", "rad/s"),
    ("wy", "Real", "input", "rad/s"),
    ("wz", "Real", "input", "rad/s"),
    ("Fx", "Real", "output", "N"),
    ("Fy", "Real", "output", "N"),
    ("Fz", "Real", "output", "N"),
    ("Mx", "Real", "output", "N.m"),
    ("My", "Real", "output", "N.m"),
    ("Mz", "Real", "output", "N.m"),
    ("normalForce", "Real", "output", "N"),
    ("rollingForce", "Real", "output", "N"),
    ("sideForce", "Real", "output", "N"),
    ("penetration", "Real", "output", "m"),
    ("contactAngle", "Real", "output", "rad"),
    ("inContact", "Boolean", "output", ""),
    ("excavatedVolume", "Real", "output", "m3"),
    ("cuttingEnergy", "Real", "output", "J"),
    ("specificEnergy", "Real", "output", "J/m3"),
    ("cutter.radius", "Real", "parameter", "m"),
    ("cutter.tipWidth", "Real", "parameter", "m"),
    ("cutter.tipRadius", "Real", "parameter", "m"),
    ("cutter.flankAngle", "Real", "parameter", "rad"),
    ("cutter.hubWidth", "Real", "parameter", "m"),
    ("rock.ucs", "Real", "parameter", "Pa"),
    ("rock.bts", "Real", "parameter", "Pa"),
    ("csm.C", "Real", "parameter", "1"),
    ("csm.spacing", "Real", "parameter", "m"),
    ("csm.psi", "Real", "parameter", "1"),
    ("csm.variant", "Enumeration", "parameter", ""),
    ("friction.mu", "Real", "parameter", "1"),
    ("friction.vs", "Real", "parameter", "m/s"),
    ("rock.xMin", "Real", "parameter", "m"),
    ("rock.xMax", "Real", "parameter", "m"),
    ("rock.yMin", "Real", "parameter", "m"),
    ("rock.yMax", "Real", "parameter", "m"),
    ("rock.nx", "Integer", "parameter", ""),
    ("rock.ny", "Integer", "parameter", ""),
    ("rock.z0", "Real", "parameter", "m"),
    ("rock.initialSurface", "String", "parameter", ""),
    ("rock.finalSurface", "String", "parameter", ""),
    ("rock.plasticFraction", "Real", "parameter", "1"),
    ("numerics.tipSlices", "Integer", "parameter", ""),
    ("numerics.arcStepCells", "Real", "parameter", "1"),
    ("numerics.ringStepCells", "Real", "parameter", "1"),
    ("numerics.elasticDepth", "Real", "parameter", "m"),
    ("numerics.pReg", "Real", "parameter", "m"),
    ("numerics.sweepStep", "Real", "parameter", "m"),
    ("numerics.directionRule", "Enumeration", "parameter", ""),
    ("chipping.enabled", "Boolean", "parameter", ""),
    ("chipping.seed", "Integer", "parameter", ""),
    ("chippedVolume", "Real", "output", "m3"),
    ("chipCount", "Integer", "output", ""),
];

// The parameter bounds of the core (`PARAMETER_BOUNDS` and the rules between
// parameters), shared with src/core/params.rs so the numbers exist once.
include!(concat!(env!("CARGO_MANIFEST_DIR"), "/src/core/bounds.rs"));

/// Every row of `PARAMETER_BOUNDS` is mirrored exactly by its variable's
/// `min` and `max`, and every parameter start value lies inside it.
fn check_bounds(vars: &[Var]) {
    let _ = (
        MIN_CELL,
        MAX_NODES,
        MAX_DISC_NODES,
        MAX_ARC_STEPS,
        MIN_SWEEP_STEP_CELLS,
        MAX_SUBSTEPS_PER_CALL,
        MAX_NODE_VISITS_PER_CALL,
        TILTED_NODE_WEIGHT,
        MAX_SURFACE_LINES,
        MAX_SURFACE_LINE_BYTES,
    );
    for &(name, lo, hi) in PARAMETER_BOUNDS {
        let v = vars.iter().find(|v| v.name == name).unwrap_or_else(|| {
            fail(format!(
                "src/core/bounds.rs bounds \"{name}\", which is not a variable"
            ))
        });
        let parse = |what: &str, s: Option<&str>| -> Option<f64> {
            s.map(|s| parse_f64(&format!("{name} {what}"), s))
        };
        let (min, max) = (
            parse("min", v.min.as_deref()),
            parse("max", v.max.as_deref()),
        );
        if min != Some(lo) || max != Some(hi) {
            fail(format!(
                "{name}: min/max must mirror src/core/bounds.rs: min=\"{lo:e}\" max=\"{hi:e}\" (found {:?} / {:?})",
                v.min, v.max
            ));
        }
    }
}

/// Inputs whose start value interface.md fixes.
const FIXED_STARTS: &[(&str, f64)] = &[("z", 0.2121)];

fn fail(msg: String) -> ! {
    panic!("\n\nmodelDescription/modelDescription.xml: {msg}\n\n");
}

#[derive(Debug, Clone)]
struct Var {
    index: usize,
    name: String,
    vr: u32,
    causality: String,
    variability: String,
    initial: Option<String>,
    /// "Real", "Integer", "Boolean", "String", "Enumeration".
    ty: String,
    start: Option<String>,
    unit: Option<String>,
    min: Option<String>,
    max: Option<String>,
    declared_type: Option<String>,
}

fn attr_bool(node: roxmltree::Node, name: &str) -> Option<bool> {
    node.attribute(name).map(|v| match v {
        "true" => true,
        "false" => false,
        other => fail(format!(
            "<{}> attribute {name}=\"{other}\" is not a boolean",
            node.tag_name().name()
        )),
    })
}

fn child<'a, 'input>(
    parent: roxmltree::Node<'a, 'input>,
    tag: &str,
) -> Option<roxmltree::Node<'a, 'input>> {
    parent.children().find(|n| n.has_tag_name(tag))
}

fn parse_f64(what: &str, s: &str) -> f64 {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => v,
        _ => fail(format!("{what}: \"{s}\" is not a finite real number")),
    }
}

fn parse_i32(what: &str, s: &str) -> i32 {
    s.trim()
        .parse::<i32>()
        .unwrap_or_else(|_| fail(format!("{what}: \"{s}\" is not a 32-bit integer")))
}

/// The allowed `initial` values of a causality/variability pair (FMI 2.0,
/// section 2.2.7, the two tables), with the default first; `None` if the
/// combination itself is illegal.
fn allowed_initial(causality: &str, variability: &str) -> Option<&'static [&'static str]> {
    const NONE: &[&str] = &[];
    Some(match (causality, variability) {
        ("output" | "local", "constant") => &["exact"],
        ("parameter", "fixed" | "tunable") => &["exact"],
        ("calculatedParameter", "fixed" | "tunable") => &["calculated", "approx"],
        ("local", "fixed" | "tunable") => &["calculated", "approx"],
        ("input", "discrete" | "continuous") => NONE,
        ("output" | "local", "discrete" | "continuous") => &["calculated", "exact", "approx"],
        ("independent", "continuous") => NONE,
        _ => return None,
    })
}

/// `ROCK_X_MIN` from `rock.xMin`.
fn const_name(name: &str) -> String {
    let mut out = String::new();
    let mut prev_lower = false;
    for ch in name.chars() {
        if ch == '.' || ch == '_' {
            out.push('_');
            prev_lower = false;
        } else if ch.is_ascii_alphanumeric() {
            if ch.is_ascii_uppercase() && prev_lower {
                out.push('_');
            }
            out.push(ch.to_ascii_uppercase());
            prev_lower = ch.is_ascii_lowercase() || ch.is_ascii_digit();
        } else {
            fail(format!("variable name \"{name}\" has a character ('{ch}') that cannot become a Rust identifier"));
        }
    }
    if out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, '_');
    }
    out
}

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let xml_path = root.join("modelDescription").join("modelDescription.xml");
    println!("cargo:rerun-if-changed={}", xml_path.display());
    println!("cargo:rerun-if-changed=build.rs");

    let text = std::fs::read_to_string(&xml_path)
        .unwrap_or_else(|e| fail(format!("cannot read {}: {e}", xml_path.display())));
    std::fs::write(
        PathBuf::from(std::env::var("OUT_DIR").unwrap()).join("model_description.rs"),
        check_and_generate(&text),
    )
    .expect("cannot write model_description.rs into OUT_DIR");
}

/// Checks modelDescription.xml (panics with a message naming the problem) and
/// returns the generated Rust. Separate from `main` so that
/// `tests/fmi_build_checks.rs` can feed it broken descriptions. The steps
/// run in this order, each failing on the first problem it meets.
pub fn check_and_generate(text: &str) -> String {
    let doc = roxmltree::Document::parse(text)
        .unwrap_or_else(|e| fail(format!("not well-formed XML: {e}")));
    let md = doc.root_element();
    let (guid, event_indicators) = check_root(md);
    check_interfaces(md);
    let units = read_units(md);
    let enums = read_enums(md);
    let categories = read_categories(md);
    let vars = read_variables(md, &units, &enums);
    check_unique(&vars);
    check_contract(&vars);
    check_bounds(&vars);
    check_structure(md, &vars);
    generate(guid, event_indicators, &categories, &vars, &enums)
}

/// The root element's attributes and the default experiment; returns the
/// guid and the number of event indicators.
fn check_root<'a>(md: roxmltree::Node<'a, '_>) -> (&'a str, &'a str) {
    if md.tag_name().name() != "fmiModelDescription" {
        fail("the root element must be <fmiModelDescription>".into());
    }
    if md.attribute("fmiVersion") != Some("2.0") {
        fail("fmiVersion must be \"2.0\"".into());
    }
    if md.attribute("modelName") != Some("kerf") {
        fail("modelName must be \"kerf\"".into());
    }
    if md.attribute("variableNamingConvention") != Some("structured") {
        fail("variableNamingConvention must be \"structured\"".into());
    }
    let guid = md
        .attribute("guid")
        .filter(|g| !g.trim().is_empty())
        .unwrap_or_else(|| fail("no guid".into()));
    // One event indicator: numerics.sweepStep minus the rim travel since the
    // last committed cut (src/fmi2/generic.rs, Fmi::event_indicator).
    let event_indicators = md.attribute("numberOfEventIndicators").unwrap_or("0");
    if event_indicators != "1" {
        fail(format!(
            "numberOfEventIndicators must be 1 (the cut event: sweepStep minus the travel since the last cut), not \"{event_indicators}\""
        ));
    }
    // A tolerance for the hosts' variable-step solvers (PyFMI warns without).
    let de = child(md, "DefaultExperiment")
        .unwrap_or_else(|| fail("no <DefaultExperiment> element".into()));
    match de.attribute("tolerance").map(|t| t.trim().parse::<f64>()) {
        Some(Ok(t)) if t > 0.0 && t < 1.0 => {}
        _ => fail("<DefaultExperiment> needs a tolerance in (0, 1)".into()),
    }
    (guid, event_indicators)
}

/// Both interfaces, same identifier, the capability flags of interface.md.
fn check_interfaces(md: roxmltree::Node) {
    for tag in ["ModelExchange", "CoSimulation"] {
        let el = child(md, tag).unwrap_or_else(|| fail(format!("no <{tag}> element")));
        if el.attribute("modelIdentifier") != Some("kerf") {
            fail(format!("<{tag}> modelIdentifier must be \"kerf\""));
        }
        for (flag, want) in [
            ("canGetAndSetFMUstate", true),
            ("canSerializeFMUstate", true),
            ("canBeInstantiatedOnlyOncePerProcess", false),
            ("needsExecutionTool", false),
            ("providesDirectionalDerivative", false),
        ] {
            if attr_bool(el, flag).unwrap_or(false) != want {
                fail(format!("<{tag}> must have {flag}=\"{want}\""));
            }
        }
        if tag == "ModelExchange"
            && attr_bool(el, "completedIntegratorStepNotNeeded").unwrap_or(false)
        {
            fail(
                "<ModelExchange> needs fmi2CompletedIntegratorStep (it asks for the cut events)"
                    .into(),
            );
        }
        if tag == "CoSimulation"
            && !attr_bool(el, "canHandleVariableCommunicationStepSize").unwrap_or(false)
        {
            fail("<CoSimulation> must have canHandleVariableCommunicationStepSize=\"true\"".into());
        }
    }
}

/// Units and their display units.
fn read_units(md: roxmltree::Node) -> HashMap<String, BTreeSet<String>> {
    let mut units: HashMap<String, BTreeSet<String>> = HashMap::new();
    if let Some(ud) = child(md, "UnitDefinitions") {
        for u in ud.children().filter(|n| n.has_tag_name("Unit")) {
            let name = u
                .attribute("name")
                .unwrap_or_else(|| fail("<Unit> without a name".into()));
            let displays = u
                .children()
                .filter(|n| n.has_tag_name("DisplayUnit"))
                .map(|d| {
                    d.attribute("name")
                        .unwrap_or_else(|| {
                            fail(format!("unit {name}: <DisplayUnit> without a name"))
                        })
                        .to_string()
                })
                .collect();
            if units.insert(name.to_string(), displays).is_some() {
                fail(format!("unit \"{name}\" is defined twice"));
            }
        }
    }
    units
}

/// Enumeration types.
fn read_enums(md: roxmltree::Node) -> HashMap<String, Vec<(String, i32)>> {
    let mut enums: HashMap<String, Vec<(String, i32)>> = HashMap::new();
    if let Some(td) = child(md, "TypeDefinitions") {
        for st in td.children().filter(|n| n.has_tag_name("SimpleType")) {
            let name = st
                .attribute("name")
                .unwrap_or_else(|| fail("<SimpleType> without a name".into()));
            if let Some(e) = child(st, "Enumeration") {
                let mut items = Vec::new();
                for it in e.children().filter(|n| n.has_tag_name("Item")) {
                    let iname = it.attribute("name").unwrap_or_else(|| {
                        fail(format!("enumeration {name}: <Item> without a name"))
                    });
                    let v = parse_i32(
                        &format!("enumeration {name}, item {iname}"),
                        it.attribute("value").unwrap_or_else(|| {
                            fail(format!("enumeration {name}, item {iname}: no value"))
                        }),
                    );
                    if items.iter().any(|(n, x)| n == iname || *x == v) {
                        fail(format!(
                            "enumeration {name}: item {iname} = {v} repeats a name or value"
                        ));
                    }
                    items.push((iname.to_string(), v));
                }
                if items.is_empty() {
                    fail(format!("enumeration {name} has no items"));
                }
                enums.insert(name.to_string(), items);
            }
        }
    }
    enums
}

/// The log categories, which must hold those the FMI layer logs under.
fn read_categories(md: roxmltree::Node) -> Vec<String> {
    let categories: Vec<String> = child(md, "LogCategories")
        .map(|lc| {
            lc.children()
                .filter(|n| n.has_tag_name("Category"))
                .map(|c| {
                    c.attribute("name")
                        .unwrap_or_else(|| fail("<Category> without a name".into()))
                        .to_string()
                })
                .collect()
        })
        .unwrap_or_default();
    for need in ["logEvents", "logStatusWarning", "logStatusError", "logAll"] {
        if !categories.iter().any(|c| c == need) {
            fail(format!(
                "<LogCategories> lacks {need} (the FMI layer logs under it)"
            ));
        }
    }
    categories
}

/// The variables, each checked on its own ([`check_variable`]).
fn read_variables(
    md: roxmltree::Node,
    units: &HashMap<String, BTreeSet<String>>,
    enums: &HashMap<String, Vec<(String, i32)>>,
) -> Vec<Var> {
    let mv = child(md, "ModelVariables").unwrap_or_else(|| fail("no <ModelVariables>".into()));
    let mut vars: Vec<Var> = Vec::new();
    for (i, sv) in mv.children().filter(|n| n.is_element()).enumerate() {
        if !sv.has_tag_name("ScalarVariable") {
            fail(format!(
                "unexpected <{}> in <ModelVariables>",
                sv.tag_name().name()
            ));
        }
        let name = sv
            .attribute("name")
            .unwrap_or_else(|| fail(format!("variable #{} has no name", i + 1)))
            .to_string();
        let vr_text = sv
            .attribute("valueReference")
            .unwrap_or_else(|| fail(format!("{name}: no valueReference")));
        let vr: u32 = vr_text.parse().unwrap_or_else(|_| {
            fail(format!(
                "{name}: valueReference \"{vr_text}\" is not an unsigned 32-bit integer"
            ))
        });
        let ty_node = sv.children().find(|n| n.is_element()).unwrap_or_else(|| {
            fail(format!(
                "{name}: no type element (Real, Integer, Boolean, String, Enumeration)"
            ))
        });
        let ty = ty_node.tag_name().name().to_string();
        if !["Real", "Integer", "Boolean", "String", "Enumeration"].contains(&ty.as_str()) {
            fail(format!("{name}: unknown type element <{ty}>"));
        }
        let var = Var {
            index: i + 1,
            name: name.clone(),
            vr,
            causality: sv.attribute("causality").unwrap_or("local").to_string(),
            variability: sv
                .attribute("variability")
                .unwrap_or("continuous")
                .to_string(),
            initial: sv.attribute("initial").map(str::to_string),
            ty,
            start: ty_node.attribute("start").map(str::to_string),
            unit: ty_node.attribute("unit").map(str::to_string),
            min: ty_node.attribute("min").map(str::to_string),
            max: ty_node.attribute("max").map(str::to_string),
            declared_type: ty_node.attribute("declaredType").map(str::to_string),
        };
        check_variable(&var, ty_node, units, enums);
        vars.push(var);
    }
    vars
}

/// Unique names; unique value references per base type (Integer and
/// Enumeration share fmi2GetInteger/fmi2SetInteger, so they share references).
fn check_unique(vars: &[Var]) {
    let mut names = BTreeSet::new();
    let mut consts = BTreeSet::new();
    let mut refs: BTreeMap<(&str, u32), &str> = BTreeMap::new();
    for v in vars {
        if !names.insert(v.name.as_str()) {
            fail(format!("variable name \"{}\" is declared twice", v.name));
        }
        if !consts.insert(const_name(&v.name)) {
            fail(format!(
                "variable \"{}\" maps to the Rust constant {} of another variable",
                v.name,
                const_name(&v.name)
            ));
        }
        let base = if v.ty == "Enumeration" {
            "Integer"
        } else {
            v.ty.as_str()
        };
        if let Some(other) = refs.insert((base, v.vr), &v.name) {
            fail(format!(
                "duplicate {base} value reference {}: \"{}\" and \"{other}\"",
                v.vr, v.name
            ));
        }
    }
}

/// The interface of interface.md, all of it, and its fixed start values.
fn check_contract(vars: &[Var]) {
    for (name, ty, causality, unit) in INTERFACE {
        let v = vars.iter().find(|v| v.name == *name).unwrap_or_else(|| {
            fail(format!(
                "interface variable \"{name}\" ({causality} {ty}) is missing"
            ))
        });
        if v.ty != *ty {
            fail(format!(
                "interface variable \"{name}\" must be of type {ty}, not {}",
                v.ty
            ));
        }
        if v.causality != *causality {
            fail(format!(
                "interface variable \"{name}\" must have causality {causality}, not {}",
                v.causality
            ));
        }
        if !unit.is_empty() && v.unit.as_deref() != Some(*unit) {
            fail(format!(
                "interface variable \"{name}\" must have unit \"{unit}\", not {:?}",
                v.unit
            ));
        }
    }
    for (name, want) in FIXED_STARTS {
        let v = vars.iter().find(|v| v.name == *name).unwrap();
        let got = v.start.as_deref().map(|s| parse_f64(name, s));
        if got != Some(*want) {
            fail(format!(
                "interface variable \"{name}\" must start at {want}, not {got:?}"
            ));
        }
    }
}

fn check_variable(
    v: &Var,
    ty_node: roxmltree::Node,
    units: &HashMap<String, BTreeSet<String>>,
    enums: &HashMap<String, Vec<(String, i32)>>,
) {
    let name = &v.name;
    let Some(allowed) = allowed_initial(&v.causality, &v.variability) else {
        fail(format!(
            "{name}: causality=\"{}\" with variability=\"{}\" is not a legal FMI 2.0 combination",
            v.causality, v.variability
        ));
    };
    if v.variability == "continuous" && v.ty != "Real" {
        fail(format!(
            "{name}: only Real variables may have variability=\"continuous\""
        ));
    }
    let initial = match (&v.initial, allowed.first()) {
        (Some(i), _) if allowed.contains(&i.as_str()) => Some(i.as_str()),
        (Some(i), _) => fail(format!(
            "{name}: initial=\"{i}\" is not allowed with causality=\"{}\", variability=\"{}\" (allowed: {allowed:?})",
            v.causality, v.variability
        )),
        (None, d) => d.copied(),
    };
    let needs_start = v.causality == "input" || matches!(initial, Some("exact" | "approx"));
    let forbids_start = v.causality == "independent" || initial == Some("calculated");
    if needs_start && v.start.is_none() {
        fail(format!(
            "{name}: a start value is required (causality {}, initial {initial:?})",
            v.causality
        ));
    }
    if forbids_start && v.start.is_some() {
        fail(format!(
            "{name}: a start value is not allowed (causality {}, initial {initial:?})",
            v.causality
        ));
    }
    match v.ty.as_str() {
        "Real" => {
            let unit = v
                .unit
                .as_deref()
                .unwrap_or_else(|| fail(format!("{name}: a Real needs a unit")));
            let displays = units.get(unit).unwrap_or_else(|| {
                fail(format!(
                    "{name}: unit \"{unit}\" is not in <UnitDefinitions>"
                ))
            });
            if let Some(d) = ty_node.attribute("displayUnit") {
                if !displays.contains(d) {
                    fail(format!(
                        "{name}: displayUnit \"{d}\" is not a <DisplayUnit> of unit \"{unit}\""
                    ));
                }
            }
            check_range(v, parse_f64);
        }
        "Integer" => check_range(v, parse_i32),
        "Enumeration" => {
            let t = v
                .declared_type
                .as_deref()
                .unwrap_or_else(|| fail(format!("{name}: an Enumeration needs a declaredType")));
            let items = enums.get(t).unwrap_or_else(|| {
                fail(format!(
                    "{name}: declaredType \"{t}\" is not an enumeration of <TypeDefinitions>"
                ))
            });
            if let Some(s) = v.start.as_deref() {
                let s = parse_i32(&format!("{name} start"), s);
                if !items.iter().any(|(_, x)| *x == s) {
                    fail(format!(
                        "{name}: start {s} is not an item of enumeration {t} (items: {:?})",
                        items.iter().map(|(_, x)| *x).collect::<Vec<_>>()
                    ));
                }
            }
        }
        "Boolean" => {
            if let Some(s) = v.start.as_deref() {
                if s != "true" && s != "false" {
                    fail(format!(
                        "{name}: Boolean start \"{s}\" is neither true nor false"
                    ));
                }
            }
        }
        _ => {}
    }
    if v.ty != "Real" && v.unit.is_some() {
        fail(format!("{name}: only Real variables carry a unit here"));
    }
}

/// A Real's or an Integer's `min`, `max` and `start`, read by `parse`:
/// `min <= max`, and the start between them.
fn check_range<T: PartialOrd + std::fmt::Debug + std::fmt::Display>(
    v: &Var,
    parse: fn(&str, &str) -> T,
) {
    let name = &v.name;
    let min = v.min.as_deref().map(|s| parse(&format!("{name} min"), s));
    let max = v.max.as_deref().map(|s| parse(&format!("{name} max"), s));
    if let (Some(lo), Some(hi)) = (&min, &max) {
        if lo > hi {
            fail(format!("{name}: min {lo} > max {hi}"));
        }
    }
    if let Some(s) = v.start.as_deref() {
        let s = parse(&format!("{name} start"), s);
        if min.as_ref().is_some_and(|lo| s < *lo) || max.as_ref().is_some_and(|hi| s > *hi) {
            fail(format!("{name}: start {s} outside [{min:?}, {max:?}]"));
        }
    }
}

/// `<ModelStructure>` as FMI 2.0 demands for a model without continuous
/// states: every output once in `<Outputs>`; `<InitialUnknowns>` exactly the
/// outputs with initial calculated/approx and the calculated parameters; no
/// `<Derivatives>`; no empty elements.
fn check_structure(md: roxmltree::Node, vars: &[Var]) {
    let ms = md
        .children()
        .find(|n| n.has_tag_name("ModelStructure"))
        .unwrap_or_else(|| fail("no <ModelStructure>".into()));
    let list = |tag: &str| -> Option<Vec<usize>> {
        let el = ms.children().find(|n| n.has_tag_name(tag))?;
        let idx: Vec<usize> = el
            .children()
            .filter(|n| n.has_tag_name("Unknown"))
            .map(|u| {
                let s = u
                    .attribute("index")
                    .unwrap_or_else(|| fail(format!("<{tag}>: <Unknown> without index")));
                let i: usize = s
                    .parse()
                    .unwrap_or_else(|_| fail(format!("<{tag}>: index \"{s}\" is not a number")));
                if i == 0 || i > vars.len() {
                    fail(format!(
                        "<{tag}>: index {i} is not a variable (1..{})",
                        vars.len()
                    ));
                }
                i
            })
            .collect();
        if idx.is_empty() {
            fail(format!("<{tag}> is empty: omit the element instead"));
        }
        Some(idx)
    };
    if ms.children().any(|n| n.has_tag_name("Derivatives")) {
        fail("<Derivatives> present, but the model has no continuous states".into());
    }
    let initial_of = |v: &Var| {
        v.initial.clone().unwrap_or_else(|| {
            allowed_initial(&v.causality, &v.variability)
                .and_then(|a| a.first())
                .unwrap_or(&"")
                .to_string()
        })
    };
    let want_outputs: Vec<usize> = vars
        .iter()
        .filter(|v| v.causality == "output")
        .map(|v| v.index)
        .collect();
    let got_outputs = list("Outputs").unwrap_or_default();
    let mut sorted = got_outputs.clone();
    sorted.sort_unstable();
    sorted.dedup();
    if sorted.len() != got_outputs.len() || sorted != want_outputs {
        fail(format!("<Outputs> must list each output once: want indices {want_outputs:?}, got {got_outputs:?}"));
    }
    let want_initial: Vec<usize> = vars
        .iter()
        .filter(|v| {
            (v.causality == "output" && matches!(initial_of(v).as_str(), "calculated" | "approx"))
                || v.causality == "calculatedParameter"
        })
        .map(|v| v.index)
        .collect();
    let got_initial = list("InitialUnknowns").unwrap_or_default();
    let mut sorted = got_initial.clone();
    sorted.sort_unstable();
    sorted.dedup();
    if sorted.len() != got_initial.len() || sorted != want_initial {
        fail(format!(
            "<InitialUnknowns> must be exactly {want_initial:?}, got {got_initial:?}"
        ));
    }
}

fn rust_str(s: &str) -> String {
    format!("{s:?}")
}

fn causality_ident(c: &str) -> &'static str {
    match c {
        "parameter" => "Causality::Parameter",
        "calculatedParameter" => "Causality::CalculatedParameter",
        "input" => "Causality::Input",
        "output" => "Causality::Output",
        "local" => "Causality::Local",
        "independent" => "Causality::Independent",
        other => fail(format!("unknown causality \"{other}\"")),
    }
}

fn variability_ident(c: &str) -> &'static str {
    match c {
        "constant" => "Variability::Constant",
        "fixed" => "Variability::Fixed",
        "tunable" => "Variability::Tunable",
        "discrete" => "Variability::Discrete",
        "continuous" => "Variability::Continuous",
        other => fail(format!("unknown variability \"{other}\"")),
    }
}

fn generate(
    guid: &str,
    event_indicators: &str,
    categories: &[String],
    vars: &[Var],
    enums: &HashMap<String, Vec<(String, i32)>>,
) -> String {
    let mut s = String::new();
    let w = &mut s;
    writeln!(
        w,
        "// @generated by build.rs from modelDescription/modelDescription.xml. Do not edit."
    )
    .unwrap();
    writeln!(
        w,
        "/// The GUID of modelDescription.xml; fmi2Instantiate must receive it."
    )
    .unwrap();
    writeln!(w, "pub const GUID: &str = {};", rust_str(guid)).unwrap();
    writeln!(w, "/// `numberOfEventIndicators` of modelDescription.xml.").unwrap();
    writeln!(
        w,
        "pub const NUMBER_OF_EVENT_INDICATORS: usize = {event_indicators};"
    )
    .unwrap();
    writeln!(w, "/// The log categories of `<LogCategories>`, in order.").unwrap();
    writeln!(
        w,
        "pub const LOG_CATEGORIES: &[&str] = &[{}];",
        categories
            .iter()
            .map(|c| rust_str(c))
            .collect::<Vec<_>>()
            .join(", ")
    )
    .unwrap();

    writeln!(
        w,
        "/// Value references, one constant per variable (name in SCREAMING_SNAKE_CASE)."
    )
    .unwrap();
    writeln!(w, "pub mod vr {{").unwrap();
    for v in vars {
        writeln!(w, "    /// `{}` ({}, {}).", v.name, v.ty, v.causality).unwrap();
        writeln!(w, "    pub const {}: u32 = {};", const_name(&v.name), v.vr).unwrap();
    }
    writeln!(w, "}}").unwrap();

    write_table(
        w,
        vars,
        &["Real"],
        ("Real variables", "REALS", "RealVar"),
        &|v| {
            let start = v.start.as_deref().map(|x| parse_f64(&v.name, x));
            format!(
                "start: {}, unit: {}",
                match start {
                    Some(x) => format!("Some(f64::from_bits({:#018x}))", x.to_bits()),
                    None => "None".into(),
                },
                rust_str(v.unit.as_deref().unwrap_or("")),
            )
        },
    );
    write_table(
        w,
        vars,
        &["Integer", "Enumeration"],
        (
            "Integer and Enumeration variables",
            "INTEGERS",
            "IntegerVar",
        ),
        &|v| {
            let start = v.start.as_deref().map(|x| parse_i32(&v.name, x));
            let items = match v.declared_type.as_deref().and_then(|t| enums.get(t)) {
                Some(items) if v.ty == "Enumeration" => format!(
                    "Some(&[{}])",
                    items
                        .iter()
                        .map(|(_, x)| x.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                _ => "None".into(),
            };
            format!("start: {start:?}, items: {items}")
        },
    );
    write_table(
        w,
        vars,
        &["Boolean"],
        ("Boolean variables", "BOOLEANS", "BooleanVar"),
        &|v| format!("start: {:?}", v.start.as_deref().map(|x| x == "true")),
    );
    write_table(
        w,
        vars,
        &["String"],
        ("String variables", "STRINGS", "StringVar"),
        &|v| {
            let start = match v.start.as_deref() {
                Some(x) => format!("Some({})", rust_str(x)),
                None => "None".into(),
            };
            format!("start: {start}")
        },
    );
    s
}

/// One table of the generated code: the variables of `types`, sorted by
/// value reference, as `ty` rows (name, value reference, index, causality,
/// variability, then `rest`) of the static `name`, documented `doc`.
fn write_table(
    w: &mut String,
    vars: &[Var],
    types: &[&str],
    (doc, name, ty): (&str, &str, &str),
    rest: &dyn Fn(&Var) -> String,
) {
    let mut rows: Vec<&Var> = vars
        .iter()
        .filter(|v| types.contains(&v.ty.as_str()))
        .collect();
    rows.sort_by_key(|v| v.vr);
    writeln!(w, "/// {doc}, sorted by value reference.").unwrap();
    writeln!(w, "pub static {name}: &[{ty}] = &[").unwrap();
    for v in rows {
        writeln!(
            w,
            "    {ty} {{ name: {}, vr: {}, index: {}, causality: {}, variability: {}, {} }},",
            rust_str(&v.name),
            v.vr,
            v.index,
            causality_ident(&v.causality),
            variability_ident(&v.variability),
            rest(v),
        )
        .unwrap();
    }
    writeln!(w, "];").unwrap();
}

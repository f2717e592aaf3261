//! The cutterhead FMU's modelDescription.xml: kerf's header, units, types
//! and log categories copied from modelDescription/modelDescription.xml
//! (the single source of truth), the variables from
//! `kerf::fmi2::head_md::variables` (the table the binary itself uses),
//! the shared parameters' units, ranges and descriptions from kerf's XML.

use std::fmt::Write as _;

use kerf::core::head::Drive;
use kerf::core::layout::Layout;
use kerf::fmi2::head_md::{variables, HeadVar, Ty};
use kerf::fmi2::md::{Causality, Variability};

use super::{escape, Res};

fn fnv(seed: u64, bytes: &[u8]) -> u64 {
    let mut h = seed;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// A GUID that changes with everything the head FMU declares.
fn guid_of(text: &str) -> String {
    let a = fnv(0xcbf2_9ce4_8422_2325, text.as_bytes());
    let b = fnv(0x8422_2325_cbf2_9ce4, text.as_bytes());
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

fn causality(c: Causality) -> &'static str {
    match c {
        Causality::Parameter => "parameter",
        Causality::CalculatedParameter => "calculatedParameter",
        Causality::Input => "input",
        Causality::Output => "output",
        Causality::Local => "local",
        Causality::Independent => "independent",
    }
}

fn variability(v: Variability) -> &'static str {
    match v {
        Variability::Constant => "constant",
        Variability::Fixed => "fixed",
        Variability::Tunable => "tunable",
        Variability::Discrete => "discrete",
        Variability::Continuous => "continuous",
    }
}

fn num(x: f64) -> String {
    format!("{x:?}")
}

/// One `<ScalarVariable>`; `kerf_sv` is kerf's element of the same name for
/// shared parameters.
fn scalar(v: &HeadVar, kerf_sv: Option<roxmltree::Node>) -> Res<String> {
    let mut s = String::new();
    let initial = match (v.causality, v.variability) {
        (Causality::Parameter, _) => " initial=\"exact\"",
        (Causality::Output, _) => " initial=\"calculated\"",
        _ => "",
    };
    let (desc, ty_attrs) = match kerf_sv {
        Some(sv) => {
            let ty = sv
                .children()
                .find(|n| n.is_element())
                .ok_or_else(|| format!("kerf variable {} without a type", v.name))?;
            let mut attrs: Vec<(String, String)> = ty
                .attributes()
                .map(|a| (a.name().to_string(), a.value().to_string()))
                .collect();
            if let Some(st) = &v.start {
                for a in attrs.iter_mut() {
                    if a.0 == "start" {
                        a.1 = st.clone();
                    }
                }
            }
            (sv.attribute("description").unwrap_or("").to_string(), attrs)
        }
        None => {
            let mut attrs = Vec::new();
            if let Some(u) = v.unit {
                attrs.push(("unit".to_string(), u.to_string()));
            }
            if let Some(d) = v.display_unit {
                attrs.push(("displayUnit".to_string(), d.to_string()));
            }
            if let Some(x) = v.min {
                attrs.push(("min".to_string(), num(x)));
            }
            if let Some(x) = v.max {
                attrs.push(("max".to_string(), num(x)));
            }
            if let Some(st) = &v.start {
                attrs.push(("start".to_string(), st.clone()));
            }
            (v.description.clone().unwrap_or_default(), attrs)
        }
    };
    let tag = match v.ty {
        Ty::Real => "Real",
        Ty::Integer => "Integer",
        Ty::Enumeration => "Enumeration",
        Ty::Boolean => "Boolean",
        Ty::String => "String",
    };
    write!(
        s,
        "    <ScalarVariable name=\"{}\" valueReference=\"{}\" causality=\"{}\" variability=\"{}\"{} description=\"{}\">\n      <{tag}",
        escape(&v.name),
        v.vr,
        causality(v.causality),
        variability(v.variability),
        initial,
        escape(&desc)
    )
    .unwrap();
    for (k, x) in ty_attrs {
        write!(s, " {k}=\"{}\"", escape(&x)).unwrap();
    }
    s.push_str("/>\n    </ScalarVariable>\n");
    Ok(s)
}

/// (modelDescription.xml, guid) of the head FMU of `layout`.
pub fn model_description(
    kerf_xml: &str,
    layout: &Layout,
    drive: Drive,
    file: &str,
) -> Res<(String, String)> {
    let doc =
        roxmltree::Document::parse(kerf_xml).map_err(|e| format!("modelDescription.xml: {e}"))?;
    let md = doc.root_element();
    let raw = |tag: &str| -> Res<&str> {
        let n = md
            .children()
            .find(|n| n.has_tag_name(tag))
            .ok_or_else(|| format!("modelDescription.xml has no <{tag}>"))?;
        Ok(&kerf_xml[n.range()])
    };
    let kerf_vars: std::collections::HashMap<&str, roxmltree::Node> = md
        .descendants()
        .filter(|n| n.has_tag_name("ScalarVariable"))
        .filter_map(|n| n.attribute("name").map(|a| (a, n)))
        .collect();
    let vars = variables(layout, drive);
    let mut body = String::new();
    body.push_str("  <ModelVariables>\n");
    for v in &vars {
        let k = if v.slot == kerf::fmi2::head_md::Slot::Kerf {
            Some(
                *kerf_vars
                    .get(v.name.as_str())
                    .ok_or_else(|| format!("kerf has no variable {}", v.name))?,
            )
        } else {
            None
        };
        body.push_str(&scalar(v, k)?);
    }
    body.push_str("  </ModelVariables>\n\n  <ModelStructure>\n");
    for tag in ["Outputs", "InitialUnknowns"] {
        writeln!(body, "    <{tag}>").unwrap();
        for (i, v) in vars.iter().enumerate() {
            if v.causality == Causality::Output {
                writeln!(body, "      <Unknown index=\"{}\"/>", i + 1).unwrap();
            }
        }
        writeln!(body, "    </{tag}>").unwrap();
    }
    body.push_str("  </ModelStructure>\n</fmiModelDescription>\n");

    let drive_name = match drive {
        Drive::Head => "head",
        Drive::Discs => "discs",
    };
    let description = format!(
        "kerf cutterhead {}: {} discs on one rock face (layout {}, drive {}). {}",
        layout.name,
        layout.cutters.len(),
        file,
        drive_name,
        layout.description
    );
    let head = |guid: &str| {
        format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Generated by kerf packaging from modelDescription/modelDescription.xml and the layout {}. Do not edit. -->\n<fmiModelDescription\n  fmiVersion=\"2.0\"\n  modelName=\"{}\"\n  guid=\"{guid}\"\n  description=\"{}\"\n  version=\"{}\"\n  generationTool=\"kerf packaging --layout\"\n  variableNamingConvention=\"structured\"\n  numberOfEventIndicators=\"{}\">\n\n  ",
            escape(&file.replace("--", "- -")),
            escape(&layout.name),
            escape(&description),
            md.attribute("version").unwrap_or("0"),
            kerf::fmi2::head_md::NUMBER_OF_EVENT_INDICATORS,
        )
    };
    let middle = format!(
        "{}\n\n  {}\n\n  {}\n\n  {}\n\n  {}\n\n  {}\n\n",
        raw("ModelExchange")?,
        raw("CoSimulation")?,
        raw("UnitDefinitions")?,
        raw("TypeDefinitions")?,
        raw("LogCategories")?,
        // kerf.fmu's, tolerance included (PyFMI warned without one)
        raw("DefaultExperiment")?,
    );
    let kerf_guid = md.attribute("guid").unwrap_or("");
    let guid = guid_of(&format!("{kerf_guid}\n{}{middle}{body}", head("")));
    Ok((format!("{}{middle}{body}", head(&guid)), guid))
}

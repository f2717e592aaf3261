//! Cutterhead layout files (JSON), as interface.md "Layout file" defines:
//!
//! ```json
//! {
//!   "name": "head-demo",
//!   "disc": {"radius": 0.2159, "tipWidth": 0.013, "tipRadius": 0.0127},
//!   "cutters": [
//!     {"track": 0.30, "angleDeg": 0, "tiltDeg": 0, "setback": 0.0, "spacing": 0.085},
//!     {"track": 2.95, "angleDeg": 137, "tiltDeg": 35, "setback": 0.02, "spacing": 0.06,
//!      "disc": {"radius": 0.2413}}
//!   ]
//! }
//! ```
//!
//! Lengths in metres, angles in degrees. `disc` is the default of every
//! cutter; a cutter's own `disc` overrides it key by key. One optional key
//! beyond the contract: `"description"` (a string, JSON has no comments).
//! Unknown keys, missing keys, non-finite or out-of-range numbers are errors
//! whose message names the file, the cutter (1-based) and the key.

use serde_json::{Map, Value};

use super::error::{KerfError, Result};
use super::params::CutterParams;

/// One cutter of a layout, as written (angles in degrees).
#[derive(Debug, Clone, PartialEq)]
pub struct CutterSpec {
    /// Distance of the disc tip from the head axis \[m\].
    pub track: f64,
    /// Angle of the tip about the axis from head +x towards +y \[deg\].
    pub angle_deg: f64,
    /// Tilt of the disc, tip leaning outwards \[deg\].
    pub tilt_deg: f64,
    /// Tip set back from the face-cutter plane along head +z \[m\].
    pub setback: f64,
    /// Spacing `S` of the CSM law for this disc \[m\].
    pub spacing: f64,
    pub disc: CutterParams,
}

/// A parsed, checked layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    pub name: String,
    pub description: String,
    pub cutters: Vec<CutterSpec>,
}

/// Ranges of the numbers (inclusive).
struct Range {
    lo: f64,
    hi: f64,
}

const TRACK: Range = Range { lo: 0.0, hi: 10.0 };
const ANGLE: Range = Range {
    lo: -720.0,
    hi: 720.0,
};
const TILT: Range = Range {
    lo: -75.0,
    hi: 75.0,
};
const SETBACK: Range = Range { lo: -0.5, hi: 0.5 };

/// The range of the disc's own parameter `name` in [`PARAMETER_BOUNDS`]
/// (`cutter.radius`, `csm.spacing`, ...): a layout takes what a kerf.fmu of
/// the disc would, so a head FMU it packages builds.
///
/// [`PARAMETER_BOUNDS`]: crate::core::params::PARAMETER_BOUNDS
fn disc_range(name: &str) -> Range {
    let (lo, hi) = crate::core::params::bounds(name).expect("a disc parameter has a bounds row");
    Range { lo, hi }
}

/// The largest head a layout may describe (cutters).
pub const MAX_CUTTERS: usize = 500;

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn err(&self, cutter: Option<usize>, key: &str, what: impl std::fmt::Display) -> KerfError {
        KerfError::Layout(match cutter {
            Some(i) => format!("layout {}: cutter {i}: key \"{key}\": {what}", self.file),
            None if key.is_empty() => format!("layout {}: {what}", self.file),
            None => format!("layout {}: key \"{key}\": {what}", self.file),
        })
    }

    fn number(
        &self,
        obj: &Map<String, Value>,
        cutter: Option<usize>,
        key: &str,
        r: &Range,
    ) -> Result<f64> {
        let v = obj
            .get(key)
            .ok_or_else(|| self.err(cutter, key, "missing"))?;
        let x = v
            .as_f64()
            .ok_or_else(|| self.err(cutter, key, format!("must be a number, got {v}")))?;
        if !(x.is_finite() && x >= r.lo && x <= r.hi) {
            return Err(self.err(
                cutter,
                key,
                format!("{x} is out of range [{}, {}]", r.lo, r.hi),
            ));
        }
        Ok(x)
    }

    fn only_keys(
        &self,
        obj: &Map<String, Value>,
        cutter: Option<usize>,
        prefix: &str,
        allowed: &[&str],
    ) -> Result<()> {
        for k in obj.keys() {
            if !allowed.contains(&k.as_str()) {
                return Err(self.err(
                    cutter,
                    &format!("{prefix}{k}"),
                    format!("unknown key (known: {})", allowed.join(", ")),
                ));
            }
        }
        Ok(())
    }

    /// A `disc` object: every key when `base` is None, any subset otherwise.
    fn disc(
        &self,
        v: &Value,
        cutter: Option<usize>,
        base: Option<CutterParams>,
    ) -> Result<CutterParams> {
        let obj = v
            .as_object()
            .ok_or_else(|| self.err(cutter, "disc", "must be an object"))?;
        const KEYS: [&str; 3] = ["radius", "tipWidth", "tipRadius"];
        self.only_keys(obj, cutter, "disc.", &KEYS)?;
        let get = |key: &str, r: &Range, dflt: Option<f64>| -> Result<f64> {
            match (obj.contains_key(key), dflt) {
                (false, Some(d)) => Ok(d),
                _ => self
                    .number(obj, cutter, key, r)
                    .map_err(|e| rename(e, key, &format!("disc.{key}"))),
            }
        };
        let c = CutterParams {
            radius: get(
                "radius",
                &disc_range("cutter.radius"),
                base.map(|b| b.radius),
            )?,
            tip_width: get(
                "tipWidth",
                &disc_range("cutter.tipWidth"),
                base.map(|b| b.tip_width),
            )?,
            tip_radius: get(
                "tipRadius",
                &disc_range("cutter.tipRadius"),
                base.map(|b| b.tip_radius),
            )?,
            ..CutterParams::default()
        };
        if c.tip_radius >= c.radius {
            return Err(self.err(
                cutter,
                "disc.tipRadius",
                format!(
                    "{} must be smaller than radius = {}",
                    c.tip_radius, c.radius
                ),
            ));
        }
        if c.tip_width > 2.0 * c.tip_radius {
            return Err(self.err(
                cutter,
                "disc.tipWidth",
                format!(
                    "{} exceeds 2 * tipRadius = {} (the tip profile is a circle of that radius)",
                    c.tip_width,
                    2.0 * c.tip_radius
                ),
            ));
        }
        if c.tip_radius >= c.radius {
            return Err(self.err(
                cutter,
                "disc.tipRadius",
                format!("{} must be smaller than radius {}", c.tip_radius, c.radius),
            ));
        }
        Ok(c)
    }
}

/// `key "radius"` -> `key "disc.radius"` in a message.
fn rename(e: KerfError, from: &str, to: &str) -> KerfError {
    match e {
        KerfError::Layout(m) => {
            KerfError::Layout(m.replacen(&format!("\"{from}\""), &format!("\"{to}\""), 1))
        }
        other => other,
    }
}

/// A JSON value whose objects hold no key twice: serde_json's `Value`
/// keeps the last of a repeated key and drops the rest without a word, so
/// a layout that gave a cutter's `spacing` twice would take one silently.
struct NoRepeats(Value);

impl<'de> serde::Deserialize<'de> for NoRepeats {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(NoRepeatsVisitor).map(NoRepeats)
    }
}

struct NoRepeatsVisitor;

impl<'de> serde::de::Visitor<'de> for NoRepeatsVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> std::result::Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> std::result::Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_u64<E>(self, v: u64) -> std::result::Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_f64<E>(self, v: f64) -> std::result::Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_str<E>(self, v: &str) -> std::result::Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }
    fn visit_unit<E>(self) -> std::result::Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(
        self,
        mut seq: A,
    ) -> std::result::Result<Value, A::Error> {
        let mut v = Vec::new();
        while let Some(NoRepeats(x)) = seq.next_element()? {
            v.push(x);
        }
        Ok(Value::Array(v))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> std::result::Result<Value, A::Error> {
        let mut m = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            let NoRepeats(x) = map.next_value()?;
            if m.contains_key(&key) {
                return Err(serde::de::Error::custom(format_args!(
                    "key \"{key}\" given twice"
                )));
            }
            m.insert(key, x);
        }
        Ok(Value::Object(m))
    }
}

/// Parses and checks a layout; `file` names it in the messages.
pub fn parse(text: &str, file: &str) -> Result<Layout> {
    let cx = Ctx { file };
    let NoRepeats(root) =
        serde_json::from_str(text).map_err(|e| cx.err(None, "", format!("not valid JSON: {e}")))?;
    let obj = root
        .as_object()
        .ok_or_else(|| cx.err(None, "", "the top level must be an object"))?;
    cx.only_keys(obj, None, "", &["name", "description", "disc", "cutters"])?;
    let name = obj
        .get("name")
        .ok_or_else(|| cx.err(None, "name", "missing"))?
        .as_str()
        .ok_or_else(|| cx.err(None, "name", "must be a string"))?
        .to_string();
    if name.is_empty()
        || name.len() > 64
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        return Err(cx.err(
            None,
            "name",
            format!("\"{name}\" must be 1-64 characters of A-Z, a-z, 0-9, '-', '_' (it names the FMU file)"),
        ));
    }
    let description = match obj.get("description") {
        None => String::new(),
        Some(v) => v
            .as_str()
            .ok_or_else(|| cx.err(None, "description", "must be a string"))?
            .to_string(),
    };
    let disc = cx.disc(
        obj.get("disc")
            .ok_or_else(|| cx.err(None, "disc", "missing"))?,
        None,
        None,
    )?;
    let list = obj
        .get("cutters")
        .ok_or_else(|| cx.err(None, "cutters", "missing"))?
        .as_array()
        .ok_or_else(|| cx.err(None, "cutters", "must be an array"))?;
    if list.is_empty() || list.len() > MAX_CUTTERS {
        return Err(cx.err(
            None,
            "cutters",
            format!("must hold 1 to {MAX_CUTTERS} cutters, holds {}", list.len()),
        ));
    }
    let mut cutters = Vec::with_capacity(list.len());
    for (k, c) in list.iter().enumerate() {
        let i = Some(k + 1);
        let o = c
            .as_object()
            .ok_or_else(|| cx.err(i, "", "must be an object").to_string())
            .map_err(|m| KerfError::Layout(m.replace(": key \"\"", "")))?;
        cx.only_keys(
            o,
            i,
            "",
            &["track", "angleDeg", "tiltDeg", "setback", "spacing", "disc"],
        )?;
        cutters.push(CutterSpec {
            track: cx.number(o, i, "track", &TRACK)?,
            angle_deg: cx.number(o, i, "angleDeg", &ANGLE)?,
            tilt_deg: cx.number(o, i, "tiltDeg", &TILT)?,
            setback: cx.number(o, i, "setback", &SETBACK)?,
            spacing: cx.number(o, i, "spacing", &disc_range("csm.spacing"))?,
            disc: match o.get("disc") {
                None => disc,
                Some(v) => cx.disc(v, i, Some(disc))?,
            },
        });
    }
    Ok(Layout {
        name,
        description,
        cutters,
    })
}

/// Reads and parses a layout file.
pub fn load(path: &std::path::Path) -> Result<Layout> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| KerfError::Layout(format!("layout {file}: cannot read: {e}")))?;
    parse(&text, &file)
}

impl Layout {
    /// Largest distance from the head axis that any disc reaches \[m\]: the
    /// tip's track plus the disc's extent outwards (tilted discs lean out).
    pub fn reach(&self) -> f64 {
        self.cutters
            .iter()
            .map(|c| {
                let g = c.tilt_deg.to_radians();
                let r = c.disc.radius;
                let h = 0.5 * c.disc.tip_width;
                // a tilted disc leans out by up to R sin(tilt) above its tip,
                // and its tip is T/2 wide across
                c.track + r * g.sin().abs() + h * g.cos().abs()
            })
            .fold(0.0, f64::max)
    }
}

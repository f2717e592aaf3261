//! The variables of a cutterhead FMU, generated from a layout and the drive:
//! one table that both `packaging` (to write modelDescription.xml) and the
//! head instance (to map value references) use, so they cannot disagree.
//!
//! The shared parameters (`rock.*`, `csm.C`, `csm.psi`, `csm.variant`,
//! `friction.*`, `numerics.*`, `chipping.*`) are kerf.fmu's own variables,
//! with kerf's value references (build.rs tables, from
//! modelDescription/modelDescription.xml, the single source of truth);
//! packaging copies their unit, range and description from there. Everything
//! per disc is numbered `1_000_000 + 100 i + k` (`i` 1-based).

use crate::core::head::{default_rock, place_all, DiscSpec, Drive};
use crate::core::layout::{CutterSpec, Layout};
use crate::core::{Pose, Twist};

use super::md::{self, Causality, Variability};

/// FMI type of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ty {
    Real,
    Integer,
    Enumeration,
    Boolean,
    String,
}

/// What a variable stands for in the head instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// A shared parameter: kerf.fmu's variable of the same name and value
    /// reference.
    Kerf,
    /// Head input `k` of [`INPUTS`] (head drive).
    HeadInput(usize),
    /// Total `k` of [`TOTALS`].
    Total(usize),
    /// `chipCount`.
    ChipCount,
    /// Head parameter `k` of [`HEAD_PARAMS`].
    HeadParam(usize),
    /// Disc `i` (0-based), parameter `k` of [`DISC_PARAMS`].
    DiscParam(usize, usize),
    /// Disc `i`, input `k` of [`INPUTS`] (disc drive).
    DiscInput(usize, usize),
    /// Disc `i`, output `k` of [`DISC_OUTPUTS`].
    DiscOutput(usize, usize),
    /// Disc `i`'s `inContact`.
    DiscInContact(usize),
}

/// One variable of the head FMU. For [`Slot::Kerf`] variables, `None`
/// fields (description, range, display unit) come from kerf's
/// modelDescription.xml.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadVar {
    pub name: String,
    pub vr: u32,
    pub ty: Ty,
    pub causality: Causality,
    pub variability: Variability,
    pub start: Option<String>,
    pub unit: Option<&'static str>,
    pub display_unit: Option<&'static str>,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub description: Option<String>,
    pub slot: Slot,
}

/// Pose and velocity inputs: name, unit, display unit, meaning.
pub const INPUTS: [(&str, &str, Option<&str>, &str); 12] = [
    ("x", "m", Some("mm"), "position x, rock frame"),
    ("y", "m", Some("mm"), "position y, rock frame"),
    ("z", "m", Some("mm"), "position z, rock frame"),
    (
        "yaw",
        "rad",
        Some("deg"),
        "yaw (intrinsic 3-2-1: Rz(yaw) Ry(pitch) Rx(roll))",
    ),
    ("pitch", "rad", Some("deg"), "pitch (intrinsic 3-2-1)"),
    ("roll", "rad", Some("deg"), "roll (intrinsic 3-2-1)"),
    ("vx", "m/s", None, "velocity along rock x"),
    ("vy", "m/s", None, "velocity along rock y"),
    ("vz", "m/s", None, "velocity along rock z"),
    ("wx", "rad/s", None, "angular velocity about rock x"),
    ("wy", "rad/s", None, "angular velocity about rock y"),
    ("wz", "rad/s", None, "angular velocity about rock z"),
];

/// A parameter's name, unit, display unit, range and meaning.
type ParamRow = (
    &'static str,
    &'static str,
    Option<&'static str>,
    ParamRange,
    &'static str,
);

/// A head parameter's `[min, max]`: its own, or kerf.fmu's row in
/// `bounds.rs` for the parameter of that name (a disc's own parameters,
/// which the head checks each disc against and a layout may hold).
#[derive(Debug, Clone, Copy)]
pub enum ParamRange {
    Own(f64, f64),
    Kerf(&'static str),
}

impl ParamRange {
    fn bounds(self) -> (f64, f64) {
        match self {
            ParamRange::Own(lo, hi) => (lo, hi),
            ParamRange::Kerf(name) => {
                crate::core::params::bounds(name).expect("a kerf parameter has a bounds row")
            }
        }
    }
}

/// Per-disc parameters: name, unit, display unit, range, meaning. The
/// disc's own parameters (`spacing`, `radius`, `tipWidth`, `tipRadius`) take
/// kerf.fmu's range of the same parameter ([`ParamRange::Kerf`]): they are
/// kerf.fmu's parameters that are per disc in a head.
pub const DISC_PARAMS: [ParamRow; 8] = [
    (
        "track",
        "m",
        Some("mm"),
        ParamRange::Own(0.0, 10.0),
        "distance of the disc tip from the head axis",
    ),
    (
        "angle",
        "rad",
        Some("deg"),
        ParamRange::Own(-4.0 * std::f64::consts::PI, 4.0 * std::f64::consts::PI),
        "angle of the tip about the head axis, from head +x towards +y",
    ),
    (
        "tilt",
        "rad",
        Some("deg"),
        ParamRange::Own(-1.3089969389957472, 1.3089969389957472),
        "tilt of the disc, tip leaning outwards (gauge cutters), within +-75 deg",
    ),
    (
        "setback",
        "m",
        Some("mm"),
        ParamRange::Own(-0.5, 0.5),
        "tip set back from the face-cutter plane along head +z",
    ),
    (
        "spacing",
        "m",
        Some("mm"),
        ParamRange::Kerf("csm.spacing"),
        "spacing S of this disc's CSM law",
    ),
    (
        "radius",
        "m",
        Some("mm"),
        ParamRange::Kerf("cutter.radius"),
        "disc radius R",
    ),
    (
        "tipWidth",
        "m",
        Some("mm"),
        ParamRange::Kerf("cutter.tipWidth"),
        "tip width T (must not exceed 2 * tipRadius)",
    ),
    (
        "tipRadius",
        "m",
        Some("mm"),
        ParamRange::Kerf("cutter.tipRadius"),
        "radius r of the tip profile (smaller than radius)",
    ),
];

/// Per-disc outputs: name, unit, display unit, meaning.
pub const DISC_OUTPUTS: [(&str, &str, Option<&str>, &str); 11] = [
    (
        "Fx",
        "N",
        Some("kN"),
        "force of the rock on the disc at its centre, rock x",
    ),
    (
        "Fy",
        "N",
        Some("kN"),
        "force of the rock on the disc at its centre, rock y",
    ),
    (
        "Fz",
        "N",
        Some("kN"),
        "force of the rock on the disc at its centre, rock z",
    ),
    (
        "Mx",
        "N.m",
        Some("kN.m"),
        "moment of the rock on the disc about its centre, rock x",
    ),
    (
        "My",
        "N.m",
        Some("kN.m"),
        "moment of the rock on the disc about its centre, rock y",
    ),
    (
        "Mz",
        "N.m",
        Some("kN.m"),
        "moment of the rock on the disc about its centre, rock z",
    ),
    (
        "normalForce",
        "N",
        Some("kN"),
        "the disc's force along its cutter +z",
    ),
    (
        "rollingForce",
        "N",
        Some("kN"),
        "the disc's force along its cutter -x",
    ),
    (
        "sideForce",
        "N",
        Some("kN"),
        "the disc's force along its cutter +y",
    ),
    (
        "penetration",
        "m",
        Some("mm"),
        "the disc's depth of contact (thesis eq. 54)",
    ),
    (
        "contactAngle",
        "rad",
        Some("deg"),
        "angle phi of the disc's contact arc",
    ),
];

/// Head totals: name, value reference, unit, display unit, meaning.
pub const TOTALS: [(&str, u32, &str, Option<&str>, &str); 12] = [
    ("Fx", 101, "N", Some("kN"), "total force of the rock on the head, rock x"),
    ("Fy", 102, "N", Some("kN"), "total force of the rock on the head, rock y"),
    ("Fz", 103, "N", Some("kN"), "total force of the rock on the head, rock z"),
    ("Mx", 104, "N.m", Some("kN.m"), "total moment of the rock on the head about the head origin (disc drive: the rock origin), rock x"),
    ("My", 105, "N.m", Some("kN.m"), "total moment about the head origin (disc drive: the rock origin), rock y"),
    ("Mz", 106, "N.m", Some("kN.m"), "total moment about the head origin (disc drive: the rock origin), rock z"),
    ("thrust", 130, "N", Some("kN"), "total force along head +z (disc drive: rock +z): what the thrust cylinders must supply"),
    ("torque", 131, "N.m", Some("kN.m"), "total moment about head -z (disc drive: rock -z): what the drive must supply while wz > 0"),
    ("excavatedVolume", 112, "m3", Some("cm3"), "rock removed so far by all discs (committed only)"),
    ("cuttingEnergy", 113, "J", Some("kJ"), "work of all discs on the rock so far"),
    ("specificEnergy", 114, "J/m3", Some("MJ/m3"), "cuttingEnergy / excavatedVolume, 0 while nothing was removed"),
    ("chippedVolume", 115, "m3", Some("cm3"), "the part of excavatedVolume that left as chips (committed only)"),
];

/// Head-only parameters: value reference and the parameter.
pub const HEAD_PARAMS: [(u32, ParamRow); 1] = [(
    140,
    (
        "head.steadyPenetration",
        "m",
        Some("mm"),
        ParamRange::Own(0.0, 0.05),
        "Steady start: 0 starts from the flat face; p > 0 pre-cuts the face as if the head had bored at p per revolution (wz > 0) for ever, ridges fully relieved, each track's annulus on the helix its last disc left (docs/head.md)",
    ),
)];

/// Whether kerf.fmu's parameter `name` is per disc in a head (one of
/// [`DISC_PARAMS`], by its kerf range).
fn per_disc(name: &str) -> bool {
    DISC_PARAMS
        .iter()
        .any(|row| matches!(row.3, ParamRange::Kerf(n) if n == name))
}

/// Value reference of disc `i` (0-based), entry `k`.
pub fn disc_vr(i: usize, k: usize) -> u32 {
    1_000_000 + 100 * (i as u32 + 1) + k as u32
}

/// Offsets of the per-disc groups in [`disc_vr`].
pub const PARAM_BASE: usize = 0;
pub const INPUT_BASE: usize = 10;
pub const OUTPUT_BASE: usize = 30;
pub const IN_CONTACT: usize = 50;

/// `numberOfEventIndicators` of every head FMU: one, kerf.fmu's cut event
/// over all discs (`numerics.sweepStep` minus the largest rim travel of any
/// disc since the last committed cut; `src/fmi2/head.rs`).
pub const NUMBER_OF_EVENT_INDICATORS: usize = 1;

fn fmt(x: f64) -> String {
    // shortest round-trip form, as Rust prints f64
    format!("{x:?}")
}

/// The rock-extent starts of a layout (the default face: a square about the
/// axis that holds every disc's reach, at 1 mm cells).
pub fn rock_starts(layout: &Layout) -> Vec<(&'static str, String)> {
    let (half, nodes) = default_rock(layout);
    vec![
        ("rock.xMin", fmt(-half)),
        ("rock.xMax", fmt(half)),
        ("rock.yMin", fmt(-half)),
        ("rock.yMax", fmt(half)),
        ("rock.nx", nodes.to_string()),
        ("rock.ny", nodes.to_string()),
    ]
}

impl HeadVar {
    /// A continuous Real variable with `unit` (and its display unit) and a
    /// description, without start or range ([`HeadVar::start`],
    /// [`HeadVar::range`], [`HeadVar::variability`] set those).
    fn real(
        name: impl Into<String>,
        vr: u32,
        slot: Slot,
        causality: Causality,
        (unit, display_unit): (&'static str, Option<&'static str>),
        description: impl Into<String>,
    ) -> Self {
        Self {
            name: name.into(),
            vr,
            ty: Ty::Real,
            causality,
            variability: Variability::Continuous,
            start: None,
            unit: Some(unit),
            display_unit,
            min: None,
            max: None,
            description: Some(description.into()),
            slot,
        }
    }

    /// A variable without unit, range or description (the head's own
    /// Integer and Boolean outputs add a description; kerf's shared
    /// parameters take theirs from kerf's modelDescription.xml).
    fn plain(
        name: impl Into<String>,
        vr: u32,
        ty: Ty,
        (causality, variability): (Causality, Variability),
        slot: Slot,
    ) -> Self {
        Self {
            name: name.into(),
            vr,
            ty,
            causality,
            variability,
            start: None,
            unit: None,
            display_unit: None,
            min: None,
            max: None,
            description: None,
            slot,
        }
    }

    fn variability(self, variability: Variability) -> Self {
        Self {
            variability,
            ..self
        }
    }

    fn start(self, start: impl Into<String>) -> Self {
        Self {
            start: Some(start.into()),
            ..self
        }
    }

    fn range(self, lo: f64, hi: f64) -> Self {
        Self {
            min: Some(lo),
            max: Some(hi),
            ..self
        }
    }

    fn describe(self, description: impl Into<String>) -> Self {
        Self {
            description: Some(description.into()),
            ..self
        }
    }
}

/// Every variable of the head FMU of `layout` with `drive`, in
/// modelDescription order: the head's inputs (head drive), the totals and
/// `chipCount`, the head parameters, kerf's shared parameters, then each
/// disc's parameters, inputs (disc drive) and outputs.
pub fn variables(layout: &Layout, drive: Drive) -> Vec<HeadVar> {
    let mut v = Vec::new();
    if drive == Drive::Head {
        v.extend(head_inputs());
    }
    v.extend(totals());
    v.extend(head_parameters());
    v.extend(shared_parameters(layout));
    let specs: Vec<DiscSpec> = layout.cutters.iter().map(DiscSpec::from_layout).collect();
    let rest = place_all(
        &specs,
        &Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        &Twist::default(),
    );
    for (i, (c, s)) in layout.cutters.iter().zip(&specs).enumerate() {
        v.extend(disc_parameters(i, c, s));
        if drive == Drive::Discs {
            v.extend(disc_inputs(i, &rest[i].0));
        }
        v.extend(disc_outputs(i));
    }
    v
}

/// The head frame's pose and velocity inputs (head drive).
fn head_inputs() -> impl Iterator<Item = HeadVar> {
    INPUTS
        .iter()
        .enumerate()
        .map(|(k, (name, unit, du, what))| {
            HeadVar::real(
                *name,
                k as u32 + 1,
                Slot::HeadInput(k),
                Causality::Input,
                (unit, *du),
                format!("Head frame {what} (boring: z decreasing, wz > 0)"),
            )
            .start("0")
        })
}

/// The totals over the discs, then `chipCount`.
fn totals() -> impl Iterator<Item = HeadVar> {
    let totals = TOTALS
        .iter()
        .enumerate()
        .map(|(k, (name, vr, unit, du, what))| {
            let var = HeadVar::real(
                *name,
                *vr,
                Slot::Total(k),
                Causality::Output,
                (unit, *du),
                *what,
            );
            // (the totals after the forces, moments, thrust and torque:
            // the excavation's, which change at commits only)
            if k >= 8 {
                var.variability(Variability::Discrete)
            } else {
                var
            }
        });
    totals.chain(std::iter::once(
        HeadVar::plain(
            "chipCount",
            md::vr::CHIP_COUNT,
            Ty::Integer,
            (Causality::Output, Variability::Discrete),
            Slot::ChipCount,
        )
        .describe("chips broken out so far by all discs (committed only)"),
    ))
}

/// The head's own parameters (`HEAD_PARAMS`).
fn head_parameters() -> impl Iterator<Item = HeadVar> {
    HEAD_PARAMS.iter().enumerate().map(|(k, (vr, row))| {
        parameter(
            row,
            row.0.to_string(),
            *vr,
            Slot::HeadParam(k),
            row.4.to_string(),
        )
        .start("0")
    })
}

/// Disc `i`'s mount and disc parameters, starting from the layout's cutter
/// `c` (placed as `s`).
fn disc_parameters(i: usize, c: &CutterSpec, s: &DiscSpec) -> impl Iterator<Item = HeadVar> {
    let n = i + 1;
    let values = [
        s.mount.track,
        s.mount.angle,
        s.mount.tilt,
        s.mount.setback,
        c.spacing,
        c.disc.radius,
        c.disc.tip_width,
        c.disc.tip_radius,
    ];
    DISC_PARAMS.iter().enumerate().map(move |(k, row)| {
        let name = format!("cutter[{n}].{}", row.0);
        let what = format!("Disc {n}: {}", row.4);
        parameter(
            row,
            name,
            disc_vr(i, PARAM_BASE + k),
            Slot::DiscParam(i, k),
            what,
        )
        .start(fmt(values[k]))
    })
}

/// Disc `i`'s pose and velocity inputs (disc drive), starting from its pose
/// `p` on its mount with the head at rest.
fn disc_inputs(i: usize, p: &Pose) -> impl Iterator<Item = HeadVar> {
    let n = i + 1;
    let start = p.to_array();
    INPUTS
        .iter()
        .enumerate()
        .map(move |(k, (name, unit, du, what))| {
            let what = match k {
                0..=2 => format!("disc centre {what}"),
                3..=5 => format!("cutter frame {what}"),
                6..=8 => format!("disc centre {what}"),
                _ => format!("disc {what} (spin about the axle included)"),
            };
            HeadVar::real(
                format!("cutter[{n}].{name}"),
                disc_vr(i, INPUT_BASE + k),
                Slot::DiscInput(i, k),
                Causality::Input,
                (unit, *du),
                format!(
                    "Disc {n}: {what} (kerf.fmu's meaning; start: its mount with the head at rest)"
                ),
            )
            .start(fmt(if k < 6 { start[k] } else { 0.0 }))
        })
}

/// Disc `i`'s outputs, then its `inContact`.
fn disc_outputs(i: usize) -> impl Iterator<Item = HeadVar> {
    let n = i + 1;
    let outputs = DISC_OUTPUTS
        .iter()
        .enumerate()
        .map(move |(k, (name, unit, du, what))| {
            HeadVar::real(
                format!("cutter[{n}].{name}"),
                disc_vr(i, OUTPUT_BASE + k),
                Slot::DiscOutput(i, k),
                Causality::Output,
                (unit, *du),
                format!("Disc {n}: {what}"),
            )
        });
    outputs.chain(std::iter::once(
        HeadVar::plain(
            format!("cutter[{n}].inContact"),
            disc_vr(i, IN_CONTACT),
            Ty::Boolean,
            (Causality::Output, Variability::Discrete),
            Slot::DiscInContact(i),
        )
        .describe(format!(
            "Disc {n}: some rim point below the rock surface bears load"
        )),
    ))
}

/// A fixed Real parameter of `row` (name, unit, display unit, range,
/// meaning) as `name`, described `what`.
fn parameter(row: &ParamRow, name: String, vr: u32, slot: Slot, what: String) -> HeadVar {
    let (_, unit, du, range, _) = *row;
    let (lo, hi) = range.bounds();
    HeadVar::real(name, vr, slot, Causality::Parameter, (unit, du), what)
        .variability(Variability::Fixed)
        .range(lo, hi)
}

/// kerf.fmu's parameters that every disc of a head shares, in kerf's order
/// (not the per-disc ones, [`per_disc`]), with kerf's value references; the
/// rock's extent starts from the layout's default face.
fn shared_parameters(layout: &Layout) -> Vec<HeadVar> {
    let rock = rock_starts(layout);
    let mut shared: Vec<(usize, HeadVar)> = Vec::new();
    let mut add = |index: usize, name: &str, vr: u32, ty: Ty, c: Causality| {
        if c != Causality::Parameter || per_disc(name) {
            return;
        }
        let mut var = HeadVar::plain(name, vr, ty, (c, Variability::Fixed), Slot::Kerf);
        if let Some((_, s)) = rock.iter().find(|(n, _)| *n == name) {
            var = var.start(s.clone());
        }
        shared.push((index, var));
    };
    for x in md::REALS {
        add(x.index, x.name, x.vr, Ty::Real, x.causality);
    }
    for x in md::INTEGERS {
        let ty = if x.items.is_some() {
            Ty::Enumeration
        } else {
            Ty::Integer
        };
        add(x.index, x.name, x.vr, ty, x.causality);
    }
    for x in md::BOOLEANS {
        add(x.index, x.name, x.vr, Ty::Boolean, x.causality);
    }
    for x in md::STRINGS {
        add(x.index, x.name, x.vr, Ty::String, x.causality);
    }
    shared.sort_by_key(|(i, _)| *i);
    shared.into_iter().map(|(_, x)| x).collect()
}

/// What the head FMU packs in `resources/head.json`: the layout, the drive
/// and the GUID, so the binary knows it is a head and which one.
pub fn manifest(layout_json: &str, drive: Drive, guid: &str) -> String {
    format!(
        "{{\"guid\": {}, \"drive\": \"{}\", \"layout\": {}}}\n",
        serde_json::Value::String(guid.to_string()),
        match drive {
            Drive::Head => "head",
            Drive::Discs => "discs",
        },
        layout_json.trim()
    )
}

/// Reads `resources/head.json`: (guid, drive, layout).
pub fn read_manifest(text: &str, file: &str) -> Result<(String, Drive, Layout), String> {
    let v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("{file}: not valid JSON: {e}"))?;
    let guid = v["guid"]
        .as_str()
        .ok_or_else(|| format!("{file}: no guid"))?
        .to_string();
    let drive = match v["drive"].as_str() {
        Some("head") => Drive::Head,
        Some("discs") => Drive::Discs,
        _ => return Err(format!("{file}: drive must be \"head\" or \"discs\"")),
    };
    let layout =
        crate::core::layout::parse(&v["layout"].to_string(), file).map_err(|e| e.to_string())?;
    Ok((guid, drive, layout))
}

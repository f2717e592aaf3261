//! kerf.fmu's model (one disc on its own rock) behind the generic FMI
//! instance of `generic.rs`: the variable values, the parameters they stand
//! for, and the calls into the physics core.
//!
//! Safe Rust only: the C boundary (pointers, callbacks) lives in `api.rs` and
//! `log.rs`. Every call either succeeds or returns an error message that
//! leaves the instance as it was.

use std::ffi::{CStr, CString};
use std::path::{Path, PathBuf};

use crate::core::params::{
    ChipParams, CsmParams, CutterParams, FrictionParams, Numerics, RockParams,
};
use crate::core::{
    rim_speed, rim_spin_speed, CsmVariant, DirectionRule, Model, ModelState, Outputs, Params, Pose,
    RimReach, Twist,
};

use super::generic::{self, restore_core, Class, Ctx, Fmi, FmuModel, StepError, VarInfo};
use super::log::Logger;
pub use super::machine::{mask, EventInfo, Kind, Mode, Res};
use super::md::{self, vr, Causality};
use super::state;

/// The values of every variable that has one (inputs and parameters; the
/// outputs are computed), in the order of the generated tables.
#[derive(Debug, Clone, PartialEq)]
pub struct Values {
    pub real: Vec<f64>,
    pub int: Vec<i32>,
    pub boolean: Vec<bool>,
    pub string: Vec<CString>,
}

impl Values {
    /// The start values of modelDescription.xml (0 / false / "" where none).
    pub fn start() -> Self {
        Self {
            real: md::REALS.iter().map(|v| v.start.unwrap_or(0.0)).collect(),
            int: md::INTEGERS.iter().map(|v| v.start.unwrap_or(0)).collect(),
            boolean: md::BOOLEANS
                .iter()
                .map(|v| v.start.unwrap_or(false))
                .collect(),
            string: md::STRINGS
                .iter()
                .map(|v| {
                    CString::new(v.start.unwrap_or("")).expect("build.rs: start value with a NUL")
                })
                .collect(),
        }
    }

    pub(crate) fn real(&self, r: u32) -> f64 {
        self.real[md::position(md::REALS, r, |v| v.vr).expect("generated value reference")]
    }

    fn int(&self, r: u32) -> i32 {
        self.int[md::position(md::INTEGERS, r, |v| v.vr).expect("generated value reference")]
    }

    fn boolean(&self, r: u32) -> bool {
        self.boolean[md::position(md::BOOLEANS, r, |v| v.vr).expect("generated value reference")]
    }

    fn string(&self, r: u32) -> &str {
        self.string[md::position(md::STRINGS, r, |v| v.vr).expect("generated value reference")]
            .to_str()
            .unwrap_or("")
    }

    pub fn pose(&self) -> Pose {
        Pose::new(
            self.real(vr::X),
            self.real(vr::Y),
            self.real(vr::Z),
            self.real(vr::YAW),
            self.real(vr::PITCH),
            self.real(vr::ROLL),
        )
    }

    pub fn twist(&self) -> Twist {
        Twist::new(
            [self.real(vr::VX), self.real(vr::VY), self.real(vr::VZ)],
            [self.real(vr::WX), self.real(vr::WY), self.real(vr::WZ)],
        )
    }

    /// The core parameters these values stand for. Every field is written
    /// explicitly, so a new field of `Params` fails the build here until it
    /// gets its FMI variable. `resources` resolves relative surface paths.
    ///
    /// `files`: whether `rock.initialSurface` must be readable now (building
    /// a model) or may be missing (restoring a state, which holds the surface).
    pub fn params(&self, resources: Option<&Path>, files: Files) -> Res<Params> {
        let count = |name: &str, r: u32| -> Res<usize> {
            let v = self.int(r);
            usize::try_from(v).map_err(|_| format!("parameter {name} = {v}: must not be negative"))
        };
        let variant = self.int(vr::CSM_VARIANT);
        let direction = self.int(vr::NUMERICS_DIRECTION_RULE);
        Ok(Params {
            cutter: CutterParams {
                radius: self.real(vr::CUTTER_RADIUS),
                tip_width: self.real(vr::CUTTER_TIP_WIDTH),
                tip_radius: self.real(vr::CUTTER_TIP_RADIUS),
                flank_angle: self.real(vr::CUTTER_FLANK_ANGLE),
                hub_width: self.real(vr::CUTTER_HUB_WIDTH),
            },
            csm: CsmParams {
                ucs: self.real(vr::ROCK_UCS),
                bts: self.real(vr::ROCK_BTS),
                c: self.real(vr::CSM_C),
                spacing: self.real(vr::CSM_SPACING),
                psi: self.real(vr::CSM_PSI),
                variant: CsmVariant::from_index(variant).ok_or_else(|| {
                    format!("parameter csm.variant = {variant}: not an item (1..5)")
                })?,
            },
            friction: FrictionParams {
                mu: self.real(vr::FRICTION_MU),
                vs: self.real(vr::FRICTION_VS),
            },
            rock: RockParams {
                x_min: self.real(vr::ROCK_X_MIN),
                x_max: self.real(vr::ROCK_X_MAX),
                y_min: self.real(vr::ROCK_Y_MIN),
                y_max: self.real(vr::ROCK_Y_MAX),
                nx: count("rock.nx", vr::ROCK_NX)?,
                ny: count("rock.ny", vr::ROCK_NY)?,
                z0: self.real(vr::ROCK_Z0),
                initial_surface: resolve_input_path(
                    self.string(vr::ROCK_INITIAL_SURFACE),
                    resources,
                    files,
                )?,
                final_surface: resolve_output_path(self.string(vr::ROCK_FINAL_SURFACE))?,
                plastic_fraction: self.real(vr::ROCK_PLASTIC_FRACTION),
            },
            numerics: Numerics {
                tip_slices: count("numerics.tipSlices", vr::NUMERICS_TIP_SLICES)?,
                arc_step_cells: self.real(vr::NUMERICS_ARC_STEP_CELLS),
                ring_step_cells: self.real(vr::NUMERICS_RING_STEP_CELLS),
                elastic_depth: self.real(vr::NUMERICS_ELASTIC_DEPTH),
                p_reg: self.real(vr::NUMERICS_P_REG),
                sweep_step: self.real(vr::NUMERICS_SWEEP_STEP),
                direction: match direction {
                    1 => DirectionRule::Kerf,
                    2 => DirectionRule::Thesis,
                    _ => {
                        return Err(format!(
                            "parameter numerics.directionRule = {direction}: not an item (1, 2)"
                        ))
                    }
                },
                ..Numerics::default()
            },
            chipping: ChipParams {
                enabled: self.boolean(vr::CHIPPING_ENABLED),
                seed: self.int(vr::CHIPPING_SEED),
                kappa: self.real(vr::CHIPPING_KAPPA),
                length: self.real(vr::CHIPPING_LENGTH),
                length_spread: self.real(vr::CHIPPING_LENGTH_SPREAD),
                pressure_scale: self.real(vr::CHIPPING_PRESSURE_SCALE),
            },
        })
    }
}

/// Whether [`Values::params`] requires the initial surface file to exist.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Files {
    MustExist,
    MayBeMissing,
}

/// `file:///a%20b` -> `/a b`; plain paths unchanged.
fn uri_to_path(s: &str) -> Res<PathBuf> {
    let Some(rest) = s.strip_prefix("file:") else {
        return Ok(PathBuf::from(s));
    };
    // file:///path, file://localhost/path, file:/path
    let rest = if let Some(r) = rest.strip_prefix("//") {
        let slash = r
            .find('/')
            .ok_or_else(|| format!("\"{s}\" is not a file URI with a path"))?;
        let host = &r[..slash];
        if !(host.is_empty() || host == "localhost") {
            return Err(format!(
                "\"{s}\": file URIs on other hosts are not supported"
            ));
        }
        &r[slash..]
    } else {
        rest
    };
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok());
            match hex {
                Some(b) => {
                    out.push(b);
                    i += 3;
                    continue;
                }
                None => return Err(format!("\"{s}\": bad percent escape")),
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    let path =
        String::from_utf8(out).map_err(|_| format!("\"{s}\": not UTF-8 after unescaping"))?;
    Ok(PathBuf::from(path))
}

/// The FMU's resources folder from fmi2Instantiate's `fmuResourceLocation`.
pub fn resource_dir(location: Option<&str>) -> Option<PathBuf> {
    let loc = location?.trim();
    if loc.is_empty() {
        return None;
    }
    uri_to_path(loc).ok()
}

/// `rock.initialSurface`: "" stays ""; a path or file URI; a relative path is
/// taken from the working directory, else from the FMU's resources folder. The
/// file must be readable (the core parses it), unless `files` says it may be
/// missing, when the first candidate is returned.
fn resolve_input_path(s: &str, resources: Option<&Path>, files: Files) -> Res<String> {
    if s.is_empty() {
        return Ok(String::new());
    }
    let p = uri_to_path(s).map_err(|e| format!("parameter rock.initialSurface: {e}"))?;
    let mut candidates = vec![p.clone()];
    if p.is_relative() {
        if let Some(r) = resources {
            candidates.push(r.join(&p));
        }
    }
    let mut why = String::new();
    for c in &candidates {
        // the type first, without opening: opening a FIFO blocks
        match std::fs::metadata(c) {
            Ok(m) if m.is_file() => return Ok(c.to_string_lossy().into_owned()),
            Ok(_) => why = format!("{} is not a regular file", c.display()),
            Err(e) => {
                if why.is_empty() {
                    why = format!("{}: {e}", c.display());
                }
            }
        }
    }
    if files == Files::MayBeMissing {
        return Ok(p.to_string_lossy().into_owned());
    }
    Err(format!(
        "parameter rock.initialSurface = \"{s}\": cannot read the surface file ({why})"
    ))
}

/// `rock.finalSurface`: "" stays ""; a path or file URI (relative: from the
/// working directory).
fn resolve_output_path(s: &str) -> Res<String> {
    if s.is_empty() {
        return Ok(String::new());
    }
    let p = uri_to_path(s).map_err(|e| format!("parameter rock.finalSurface: {e}"))?;
    Ok(p.to_string_lossy().into_owned())
}

/// kerf.fmu's model: one disc on its own rock, behind the generic
/// [`Fmi`] instance.
pub struct DiscModel {
    pub(crate) resources: Option<PathBuf>,
    pub(crate) values: Values,
    /// Built at fmi2ExitInitializationMode (or earlier, when outputs are read
    /// during initialization), from `model_params`.
    pub(crate) model: Option<Model>,
    model_params: Option<Params>,
    /// Co-Simulation: the pose the FMU reached at the end of the last step.
    pub(crate) cs_pose: Pose,
    /// Co-Simulation: a pose input was set since the last step.
    pub(crate) pose_inputs_set: bool,
    cache: Option<Outputs>,
}

/// kerf.fmu's instance.
pub type Instance = Fmi<DiscModel>;

impl Instance {
    pub fn new(
        name: CString,
        kind: Kind,
        logger: Logger,
        resources: Option<PathBuf>,
        logging_on: bool,
    ) -> Self {
        let model = DiscModel {
            resources,
            values: Values::start(),
            model: None,
            model_params: None,
            cs_pose: Values::start().pose(),
            pose_inputs_set: false,
            cache: None,
        };
        Fmi::with_model(name, kind, logger, logging_on, model)
    }
}

/// The single disc's part of a captured FMU state.
pub struct DiscSnap {
    pub values: Values,
    pub cs_pose: Pose,
    pub pose_inputs_set: bool,
    /// The core's discrete state, after initialization.
    pub model: Option<ModelState>,
}

/// A captured FMU state (what `fmi2FMUstate` points to).
pub type Snapshot = generic::Snapshot<DiscSnap>;

impl DiscModel {
    /// The pose the outputs are for: the pose inputs, except in Co-Simulation
    /// after a step when the host has not set a pose input since.
    fn current_pose(&self, cx: Ctx) -> Pose {
        if cx.cs_after_step() && !self.pose_inputs_set {
            self.cs_pose
        } else {
            self.values.pose()
        }
    }

    fn outputs(&mut self, cx: Ctx) -> Res<Outputs> {
        if let Some(o) = self.cache {
            return Ok(o);
        }
        if cx.mode == Mode::InitializationMode {
            self.build()?;
        }
        let pose = self.current_pose(cx);
        let twist = self.values.twist();
        let model = self
            .model
            .as_ref()
            .ok_or("the model was never initialized")?;
        let o = model.evaluate(&pose, &twist).map_err(|e| e.to_string())?;
        self.cache = Some(o);
        Ok(o)
    }

    fn radius(&self) -> f64 {
        self.values.real(vr::CUTTER_RADIUS)
    }
}

impl FmuModel for DiscModel {
    type State = DiscSnap;
    const EVENT_INDICATORS: usize = md::NUMBER_OF_EVENT_INDICATORS;
    const COMMITTED: &'static str = "rock cut committed";
    const INITIALIZED: &'static str = "initialized";
    const FATAL_STEP_FAILURE: bool = false;

    fn var(&self, class: Class, r: u32) -> Option<VarInfo<'_>> {
        let info = |name, causality, items| VarInfo {
            name,
            causality,
            items,
        };
        match class {
            Class::Real => md::position(md::REALS, r, |v| v.vr)
                .map(|i| info(md::REALS[i].name, md::REALS[i].causality, None)),
            Class::Integer => md::position(md::INTEGERS, r, |v| v.vr).map(|i| {
                let v = &md::INTEGERS[i];
                info(v.name, v.causality, v.items)
            }),
            Class::Boolean => md::position(md::BOOLEANS, r, |v| v.vr)
                .map(|i| info(md::BOOLEANS[i].name, md::BOOLEANS[i].causality, None)),
            Class::String => md::position(md::STRINGS, r, |v| v.vr)
                .map(|i| info(md::STRINGS[i].name, md::STRINGS[i].causality, None)),
        }
    }

    fn get_real(&mut self, cx: Ctx, r: u32) -> Res<f64> {
        let i = md::position(md::REALS, r, |v| v.vr).expect("checked value reference");
        Ok(if md::REALS[i].causality == Causality::Output {
            output_value(&self.outputs(cx)?, r)
        } else {
            self.values.real[i]
        })
    }

    fn get_integer(&mut self, cx: Ctx, r: u32) -> Res<i32> {
        Ok(if r == vr::CHIP_COUNT {
            i32::try_from(self.outputs(cx)?.chip_count).unwrap_or(i32::MAX)
        } else {
            self.values.int(r)
        })
    }

    fn get_boolean(&mut self, cx: Ctx, r: u32) -> Res<bool> {
        Ok(if r == vr::IN_CONTACT {
            self.outputs(cx)?.in_contact
        } else {
            self.values.boolean(r)
        })
    }

    fn get_string(&self, r: u32) -> &CStr {
        &self.values.string
            [md::position(md::STRINGS, r, |v| v.vr).expect("checked value reference")]
    }

    fn set_real(&mut self, r: u32, x: f64) {
        let i = md::position(md::REALS, r, |v| v.vr).expect("checked value reference");
        self.values.real[i] = x;
        if md::REALS[i].causality == Causality::Input {
            self.cache = None;
            if matches!(r, vr::X | vr::Y | vr::Z | vr::YAW | vr::PITCH | vr::ROLL) {
                self.pose_inputs_set = true;
            }
        }
    }

    fn set_integer(&mut self, r: u32, x: i32) {
        let i = md::position(md::INTEGERS, r, |v| v.vr).expect("checked value reference");
        self.values.int[i] = x;
    }

    fn set_boolean(&mut self, r: u32, x: bool) {
        let i = md::position(md::BOOLEANS, r, |v| v.vr).expect("checked value reference");
        self.values.boolean[i] = x;
    }

    fn set_string(&mut self, r: u32, x: CString) {
        let i = md::position(md::STRINGS, r, |v| v.vr).expect("checked value reference");
        self.values.string[i] = x;
    }

    /// Builds the core model from the parameters unless the current one was
    /// built from the same; returns its warnings when it builds.
    fn build(&mut self) -> Res<Vec<String>> {
        let params = self
            .values
            .params(self.resources.as_deref(), Files::MustExist)?;
        if self.model.is_some() && self.model_params.as_ref() == Some(&params) {
            return Ok(Vec::new());
        }
        let model = Model::new(params.clone()).map_err(|e| e.to_string())?;
        let warnings = model.warnings();
        self.model = Some(model);
        self.model_params = Some(params);
        self.cache = None;
        Ok(warnings)
    }

    fn begin(&mut self) {
        self.cs_pose = self.values.pose();
        self.pose_inputs_set = false;
        self.cache = None;
    }

    fn reset(&mut self) {
        self.values = Values::start();
        self.model = None;
        self.model_params = None;
        self.cs_pose = self.values.pose();
        self.pose_inputs_set = false;
        self.cache = None;
    }

    fn final_surface(&self) -> String {
        match (&self.model, &self.model_params) {
            (Some(_), Some(p)) => p.rock.final_surface.clone(),
            _ => String::new(),
        }
    }

    fn write_surface(&self, path: &Path) -> Res<()> {
        let m = self.model.as_ref().ok_or("no model")?;
        m.write_surface(path).map_err(|e| e.to_string())
    }

    fn sweep_step(&self) -> f64 {
        self.values.real(vr::NUMERICS_SWEEP_STEP)
    }

    fn has_core(&self) -> bool {
        self.model.is_some()
    }

    fn travel_since_cut(&self) -> Option<f64> {
        let pose = self.values.pose();
        self.model.as_ref()?.travel_since_cut(&pose)
    }

    fn spin_speed(&self) -> f64 {
        rim_spin_speed(&self.values.pose(), &self.values.twist(), self.radius())
    }

    fn rim_speed(&self) -> f64 {
        let (pose, twist) = (self.values.pose(), self.values.twist());
        let radius = self.radius();
        let reach = self
            .model
            .as_ref()
            .map_or(RimReach::whole(radius), |m| m.rim_reach());
        rim_speed(&pose, &twist, &reach).max(rim_spin_speed(&pose, &twist, radius))
    }

    fn commit(&mut self, dt: f64) -> Res<bool> {
        let pose = self.values.pose();
        let twist = self.values.twist();
        pose.validate().map_err(|e| e.to_string())?;
        twist.validate().map_err(|e| e.to_string())?;
        let model = self.model.as_mut().ok_or("no model")?;
        let changed = model
            .commit(&pose, &twist, dt)
            .map_err(|e| format!("committing the cut failed: {e}"))?;
        self.cache = None;
        Ok(changed)
    }

    fn works(&mut self, _cx: Ctx) -> Res<bool> {
        let pose = self.values.pose();
        let twist = self.values.twist();
        let model = self.model.as_ref().ok_or("no model")?;
        Ok(model.power(&pose, &twist).map_err(|e| e.to_string())? != 0.0)
    }

    fn advance(&mut self, _cx: Ctx, h: f64) -> Result<(), StepError> {
        let start = if self.pose_inputs_set {
            self.values.pose()
        } else {
            self.cs_pose
        };
        let twist = self.values.twist();
        start
            .validate()
            .map_err(|e| StepError::Refused(format!("start pose: {e}")))?;
        twist
            .validate()
            .map_err(|e| StepError::Refused(e.to_string()))?;
        let model = self
            .model
            .as_mut()
            .ok_or(StepError::Refused("no model".into()))?;
        let (end, outputs) = model
            .advance(&start, &twist, h)
            .and_then(|end| Ok((end, model.evaluate(&end, &twist)?)))
            .map_err(|e| StepError::Failed(e.to_string()))?;
        self.cs_pose = end;
        self.pose_inputs_set = false;
        self.cache = Some(outputs);
        Ok(())
    }

    fn state(&self, core: bool) -> DiscSnap {
        DiscSnap {
            values: self.values.clone(),
            cs_pose: self.cs_pose,
            pose_inputs_set: self.pose_inputs_set,
            model: if core {
                self.model.as_ref().map(Model::state)
            } else {
                None
            },
        }
    }

    fn restore(&mut self, s: &DiscSnap) -> Res<()> {
        let (model, params) = match &s.model {
            None => (None, None),
            Some(ms) => {
                let params = s
                    .values
                    .params(self.resources.as_deref(), Files::MayBeMissing)?;
                let model = restore_core(
                    &mut self.model,
                    self.model_params.as_ref(),
                    &params,
                    || {
                        // The state holds the whole surface: the initial
                        // surface file is not read (it may be gone, or, in a
                        // forged state, name something that never ends).
                        let mut flat = params.clone();
                        flat.rock.initial_surface.clear();
                        Model::new(flat).map_err(|e| e.to_string())
                    },
                    |m| m.set_state(ms).map_err(|e| e.to_string()),
                )?;
                (Some(model), Some(params))
            }
        };
        self.values = s.values.clone();
        self.cs_pose = s.cs_pose;
        self.pose_inputs_set = s.pose_inputs_set;
        // Before initialization (no model state) the model is rebuilt from the
        // parameters on demand.
        self.model = model;
        self.model_params = params;
        self.cache = None;
        Ok(())
    }

    fn encode(&self, s: &Snapshot) -> Vec<u8> {
        state::encode(s)
    }

    fn decode(&self, bytes: &[u8]) -> Res<Snapshot> {
        state::decode(bytes, self.resources.as_deref())
    }
}

fn output_value(o: &Outputs, r: u32) -> f64 {
    match r {
        vr::FX => o.force[0],
        vr::FY => o.force[1],
        vr::FZ => o.force[2],
        vr::MX => o.moment[0],
        vr::MY => o.moment[1],
        vr::MZ => o.moment[2],
        vr::NORMAL_FORCE => o.normal_force,
        vr::ROLLING_FORCE => o.rolling_force,
        vr::SIDE_FORCE => o.side_force,
        vr::PENETRATION => o.penetration,
        vr::CONTACT_ANGLE => o.contact_angle,
        vr::EXCAVATED_VOLUME => o.excavated_volume,
        vr::CUTTING_ENERGY => o.cutting_energy,
        vr::SPECIFIC_ENERGY => o.specific_energy,
        vr::CHIPPED_VOLUME => o.chipped_volume,
        // build.rs guarantees that the outputs are exactly the names above.
        _ => unreachable!("Real output {r} without a mapping"),
    }
}

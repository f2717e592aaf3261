//! One FMU instance: the FMI 2.0 state machine shared by Model Exchange and
//! Co-Simulation, the variable values, and the calls into the physics core.
//!
//! Safe Rust only: the C boundary (pointers, callbacks) lives in `api.rs` and
//! `log.rs`. Every method checks the state machine first and either succeeds
//! or returns an error message that leaves the instance as it was (unless the
//! message says the instance went to the error state).

use std::ffi::CString;
use std::path::{Path, PathBuf};

use crate::core::params::{
    ChipParams, CsmParams, CutterParams, FrictionParams, Numerics, RockParams,
};
use crate::core::{
    rim_speed, rim_spin_speed, CsmVariant, DirectionRule, Model, ModelState, Outputs, Params, Pose,
    Twist,
};

use super::log::{Category, Logger, Status};
use super::machine::{check_kind, check_mode, mode_name, LogSwitches};
use super::md::{self, vr, Causality};

/// Which interface the instance was instantiated for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    ModelExchange,
    CoSimulation,
}

/// The states of the FMI 2.0 state machines (ME and CS in one). Co-Simulation
/// steps are synchronous and never fail softly, so `stepInProgress`,
/// `stepFailed` and `stepCanceled` are never reached.
// The names are the standard's.
#[allow(clippy::enum_variant_names)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Instantiated,
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    StepComplete,
    Terminated,
    Error,
}

impl Mode {
    pub(crate) const fn bit(self) -> u32 {
        1 << (self as u32)
    }

    pub(crate) fn to_u8(self) -> u8 {
        self as u8
    }

    pub(crate) fn from_u8(v: u8) -> Option<Self> {
        Some(match v {
            0 => Self::Instantiated,
            1 => Self::InitializationMode,
            2 => Self::EventMode,
            3 => Self::ContinuousTimeMode,
            4 => Self::StepComplete,
            5 => Self::Terminated,
            6 => Self::Error,
            _ => return None,
        })
    }

    /// Whether an instance of `kind` can be in this mode.
    pub(crate) fn fits(self, kind: Kind) -> bool {
        match self {
            Self::EventMode | Self::ContinuousTimeMode => kind == Kind::ModelExchange,
            Self::StepComplete => kind == Kind::CoSimulation,
            _ => true,
        }
    }
}

use Mode::*;

/// Masks of the modes in which each function may be called (FMI 2.0,
/// sections 3.2.3 and 4.2.4).
pub mod mask {
    use super::Mode::{self, *};
    const fn m(modes: &[Mode]) -> u32 {
        let mut r = 0;
        let mut i = 0;
        while i < modes.len() {
            r |= modes[i].bit();
            i += 1;
        }
        r
    }
    pub const ANY: u32 = m(&[
        Instantiated,
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        StepComplete,
        Terminated,
        Error,
    ]);
    pub const SETUP_EXPERIMENT: u32 = m(&[Instantiated]);
    pub const ENTER_INITIALIZATION_MODE: u32 = m(&[Instantiated]);
    pub const EXIT_INITIALIZATION_MODE: u32 = m(&[InitializationMode]);
    pub const TERMINATE: u32 = m(&[EventMode, ContinuousTimeMode, StepComplete]);
    pub const GET: u32 = m(&[
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        StepComplete,
        Terminated,
        Error,
    ]);
    pub const SET_REAL: u32 = m(&[
        Instantiated,
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        StepComplete,
    ]);
    pub const SET_OTHER: u32 = m(&[Instantiated, InitializationMode, EventMode, StepComplete]);
    pub const DIRECTIONAL_DERIVATIVE: u32 = m(&[
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        StepComplete,
        Terminated,
        Error,
    ]);
    pub const ENTER_EVENT_MODE: u32 = m(&[EventMode, ContinuousTimeMode]);
    pub const NEW_DISCRETE_STATES: u32 = m(&[EventMode]);
    pub const ENTER_CONTINUOUS_TIME_MODE: u32 = m(&[EventMode]);
    pub const COMPLETED_INTEGRATOR_STEP: u32 = m(&[ContinuousTimeMode]);
    pub const SET_TIME: u32 = m(&[EventMode, ContinuousTimeMode]);
    pub const SET_CONTINUOUS_STATES: u32 = m(&[ContinuousTimeMode]);
    pub const GET_EVENT_INDICATORS: u32 = m(&[
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        Terminated,
        Error,
    ]);
    pub const GET_CONTINUOUS_STATES: u32 = GET_EVENT_INDICATORS;
    pub const GET_DERIVATIVES: u32 = m(&[EventMode, ContinuousTimeMode, Terminated, Error]);
    pub const GET_NOMINALS: u32 = m(&[
        Instantiated,
        EventMode,
        ContinuousTimeMode,
        Terminated,
        Error,
    ]);
    pub const SET_REAL_INPUT_DERIVATIVES: u32 =
        m(&[Instantiated, InitializationMode, StepComplete]);
    pub const GET_REAL_OUTPUT_DERIVATIVES: u32 = m(&[StepComplete, Terminated, Error]);
    pub const DO_STEP: u32 = m(&[StepComplete]);
    /// `stepInProgress` is never reached: fmi2CancelStep is never legal.
    pub const CANCEL_STEP: u32 = 0;
    pub const GET_STATUS: u32 = m(&[StepComplete, Terminated]);
}

/// Relative tolerance between the host's communication point and the FMU's time.
const TIME_TOLERANCE: f64 = 1e-9;

/// Model Exchange: fmi2CompletedIntegratorStep asks for an event when the
/// event indicator is at or below this fraction of `numerics.sweepStep`. It
/// covers round-off for hosts whose fixed steps travel exactly one sweep step,
/// and is far too small for a variable-step solver's internal steps to land
/// in by chance (their events come from the indicator's zero crossing).
pub const EVENT_SLACK: f64 = 1e-6;

/// Model Exchange: the time event fmi2NewDiscreteStates schedules comes after
/// this many sweep steps of travel at the current speed. It is a backstop for
/// hosts that act on neither the event indicator nor the step-event flag:
/// every other host has its event at one sweep step, which schedules the next.
pub const TIME_EVENT_SWEEPS: f64 = 2.0;

pub type Res<T> = Result<T, String>;

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
            },
            chipping: ChipParams {
                enabled: self.boolean(vr::CHIPPING_ENABLED),
                seed: self.int(vr::CHIPPING_SEED),
                kappa: self.real(vr::CHIPPING_KAPPA),
                length: self.real(vr::CHIPPING_LENGTH),
                length_spread: self.real(vr::CHIPPING_LENGTH_SPREAD),
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

/// What fmi2NewDiscreteStates reports.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EventInfo {
    pub new_discrete_states_needed: bool,
    pub terminate_simulation: bool,
    pub nominals_changed: bool,
    pub values_changed: bool,
    pub next_event_time: Option<f64>,
}

pub struct Instance {
    pub(crate) name: CString,
    pub(crate) kind: Kind,
    pub(crate) logger: Logger,
    /// Per category of `md::LOG_CATEGORIES`: enabled?
    log_on: LogSwitches,
    pub(crate) resources: Option<PathBuf>,
    pub(crate) mode: Mode,
    pub(crate) values: Values,
    pub(crate) start_time: f64,
    pub(crate) time: f64,
    /// Built at fmi2ExitInitializationMode (or earlier, when outputs are read
    /// during initialization), from `model_params`.
    pub(crate) model: Option<Model>,
    model_params: Option<Params>,
    /// Co-Simulation: the pose the FMU reached at the end of the last step.
    pub(crate) cs_pose: Pose,
    /// Co-Simulation: a pose input was set since the last step.
    pub(crate) pose_inputs_set: bool,
    /// Model Exchange: time of the last commit of the rock.
    pub(crate) last_commit_time: f64,
    /// Model Exchange: the rock was committed in this event.
    pub(crate) event_committed: bool,
    cache: Option<Outputs>,
}

impl Instance {
    pub fn new(
        name: CString,
        kind: Kind,
        logger: Logger,
        resources: Option<PathBuf>,
        logging_on: bool,
    ) -> Self {
        let log_on = LogSwitches::new(logging_on);
        Self {
            name,
            kind,
            logger,
            log_on,
            resources,
            mode: Instantiated,
            values: Values::start(),
            start_time: 0.0,
            time: 0.0,
            model: None,
            model_params: None,
            cs_pose: Values::start().pose(),
            pose_inputs_set: false,
            last_commit_time: 0.0,
            event_committed: false,
            cache: None,
        }
    }

    // ---- logging ------------------------------------------------------

    pub fn log_enabled(&self, cat: Category) -> bool {
        self.log_on.enabled(cat)
    }

    pub fn log(&self, status: Status, cat: Category, msg: &str) {
        if self.log_enabled(cat) {
            self.logger.emit(&self.name, status, cat, msg);
        }
    }

    pub fn log_error(&self, msg: &str) {
        self.log(Status::Error, Category::Error, msg);
    }

    fn log_event(&self, msg: impl FnOnce() -> String) {
        if self.log_enabled(Category::Events) {
            self.logger
                .emit(&self.name, Status::Ok, Category::Events, &msg());
        }
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Res<Status> {
        self.check("fmi2SetDebugLogging", mask::ANY)?;
        self.log_on.set(on, categories)?;
        Ok(Status::Ok)
    }

    // ---- state machine ------------------------------------------------

    pub fn check(&self, func: &str, mask: u32) -> Res<()> {
        check_mode(self.mode, func, mask)
    }

    pub fn check_kind(&self, func: &str, kind: Kind) -> Res<()> {
        check_kind(self.kind, func, kind)
    }

    pub fn mode_name(&self) -> &'static str {
        mode_name(self.mode)
    }

    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> Res<Status> {
        self.check("fmi2SetupExperiment", mask::SETUP_EXPERIMENT)?;
        if !start.is_finite() {
            return Err(format!(
                "fmi2SetupExperiment: startTime = {start} is not finite"
            ));
        }
        if let Some(stop) = stop {
            if !(stop.is_finite() && stop >= start) {
                return Err(format!("fmi2SetupExperiment: stopTime = {stop} is not a finite time >= startTime = {start}"));
            }
        }
        let _ = tolerance; // no internal solver: nothing to tune
        self.start_time = start;
        self.time = start;
        Ok(Status::Ok)
    }

    pub fn enter_initialization_mode(&mut self) -> Res<Status> {
        self.check(
            "fmi2EnterInitializationMode",
            mask::ENTER_INITIALIZATION_MODE,
        )?;
        self.mode = InitializationMode;
        self.log_event(|| "entered initialization mode".into());
        Ok(Status::Ok)
    }

    /// Builds the core model from the parameters unless the current one was
    /// built from the same; logs its warnings when it builds.
    fn ensure_model(&mut self) -> Res<Status> {
        let params = self
            .values
            .params(self.resources.as_deref(), Files::MustExist)?;
        if self.model.is_some() && self.model_params.as_ref() == Some(&params) {
            return Ok(Status::Ok);
        }
        let model = Model::new(params.clone()).map_err(|e| e.to_string())?;
        let warnings = model.warnings();
        for w in &warnings {
            self.log(Status::Warning, Category::Warning, w);
        }
        self.model = Some(model);
        self.model_params = Some(params);
        self.cache = None;
        Ok(if warnings.is_empty() {
            Status::Ok
        } else {
            Status::Warning
        })
    }

    pub fn exit_initialization_mode(&mut self) -> Res<Status> {
        self.check("fmi2ExitInitializationMode", mask::EXIT_INITIALIZATION_MODE)?;
        let status = self
            .ensure_model()
            .map_err(|e| format!("fmi2ExitInitializationMode: {e}"))?;
        self.last_commit_time = self.time;
        self.cs_pose = self.values.pose();
        self.pose_inputs_set = false;
        self.event_committed = false;
        self.cache = None;
        self.mode = match self.kind {
            Kind::ModelExchange => EventMode,
            Kind::CoSimulation => StepComplete,
        };
        self.log_event(|| format!("initialized at t = {}", self.time));
        Ok(status)
    }

    pub fn terminate(&mut self) -> Res<Status> {
        self.check("fmi2Terminate", mask::TERMINATE)?;
        let path = self
            .model_params
            .as_ref()
            .map(|p| p.rock.final_surface.clone())
            .unwrap_or_default();
        if !path.is_empty() {
            if let Some(m) = &self.model {
                m.write_surface(Path::new(&path))
                    .map_err(|e| format!("fmi2Terminate: writing rock.finalSurface: {e}"))?;
                self.log_event(|| format!("rock surface written to {path}"));
            }
        }
        // after the file: a refused write leaves the instance as it was
        self.mode = Terminated;
        Ok(Status::Ok)
    }

    pub fn reset(&mut self) -> Res<Status> {
        self.check("fmi2Reset", mask::ANY)?;
        self.mode = Instantiated;
        self.values = Values::start();
        self.start_time = 0.0;
        self.time = 0.0;
        self.model = None;
        self.model_params = None;
        self.cs_pose = self.values.pose();
        self.pose_inputs_set = false;
        self.last_commit_time = 0.0;
        self.event_committed = false;
        self.cache = None;
        Ok(Status::Ok)
    }

    // ---- values -------------------------------------------------------

    /// The pose the outputs are for: the pose inputs, except in Co-Simulation
    /// after a step when the host has not set a pose input since.
    fn current_pose(&self) -> Pose {
        if self.kind == Kind::CoSimulation
            && !self.pose_inputs_set
            && self.mode != Instantiated
            && self.mode != InitializationMode
        {
            self.cs_pose
        } else {
            self.values.pose()
        }
    }

    fn outputs(&mut self) -> Res<Outputs> {
        if let Some(o) = self.cache {
            return Ok(o);
        }
        if self.mode == InitializationMode {
            self.ensure_model()?;
        }
        let pose = self.current_pose();
        let twist = self.values.twist();
        let model = self
            .model
            .as_ref()
            .ok_or("the model was never initialized")?;
        let o = model.evaluate(&pose, &twist).map_err(|e| e.to_string())?;
        self.cache = Some(o);
        Ok(o)
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Res<Status> {
        self.check("fmi2GetReal", mask::GET)?;
        let mut outputs = None;
        for (k, &r) in vrs.iter().enumerate() {
            let i = md::position(md::REALS, r, |v| v.vr)
                .ok_or_else(|| format!("fmi2GetReal: {r} is not the value reference of a Real"))?;
            let var = &md::REALS[i];
            out[k] = if var.causality == Causality::Output {
                if outputs.is_none() {
                    outputs = Some(
                        self.outputs()
                            .map_err(|e| format!("fmi2GetReal({}): {e}", var.name))?,
                    );
                }
                output_value(outputs.as_ref().unwrap(), r)
            } else {
                self.values.real[i]
            };
        }
        Ok(Status::Ok)
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> Res<Status> {
        self.check("fmi2GetInteger", mask::GET)?;
        for (k, &r) in vrs.iter().enumerate() {
            let i = md::position(md::INTEGERS, r, |v| v.vr).ok_or_else(|| {
                format!(
                    "fmi2GetInteger: {r} is not the value reference of an Integer or Enumeration"
                )
            })?;
            out[k] = if r == vr::CHIP_COUNT {
                let n = self
                    .outputs()
                    .map_err(|e| format!("fmi2GetInteger(chipCount): {e}"))?
                    .chip_count;
                i32::try_from(n).unwrap_or(i32::MAX)
            } else {
                self.values.int[i]
            };
        }
        Ok(Status::Ok)
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> Res<Status> {
        self.check("fmi2GetBoolean", mask::GET)?;
        for (k, &r) in vrs.iter().enumerate() {
            let i = md::position(md::BOOLEANS, r, |v| v.vr).ok_or_else(|| {
                format!("fmi2GetBoolean: {r} is not the value reference of a Boolean")
            })?;
            out[k] = if r == vr::IN_CONTACT {
                self.outputs()
                    .map_err(|e| format!("fmi2GetBoolean(inContact): {e}"))?
                    .in_contact
            } else {
                self.values.boolean[i]
            };
        }
        Ok(Status::Ok)
    }

    /// The strings stay owned by the instance (valid until they are set again
    /// or the instance is reset or freed, as FMI 2.0 allows).
    pub fn get_string(&mut self, vrs: &[u32], out: &mut [*const std::ffi::c_char]) -> Res<Status> {
        self.check("fmi2GetString", mask::GET)?;
        for (o, &r) in out.iter_mut().zip(vrs) {
            let i = md::position(md::STRINGS, r, |v| v.vr).ok_or_else(|| {
                format!("fmi2GetString: {r} is not the value reference of a String")
            })?;
            *o = self.values.string[i].as_ptr();
        }
        Ok(Status::Ok)
    }

    /// May a variable of this causality be set now?
    fn settable(&self, func: &str, name: &str, causality: Causality, continuous: bool) -> Res<()> {
        match causality {
            Causality::Parameter => {
                if matches!(self.mode, Instantiated | InitializationMode) {
                    Ok(())
                } else {
                    Err(format!(
                        "{func}: parameter {name} is fixed: it can only be set before fmi2ExitInitializationMode (now in {})",
                        self.mode_name()
                    ))
                }
            }
            Causality::Input => {
                if self.mode == ContinuousTimeMode && !continuous {
                    Err(format!(
                        "{func}: {name} is a discrete input: not settable in continuous-time mode"
                    ))
                } else {
                    Ok(())
                }
            }
            _ => Err(format!(
                "{func}: {name} is not an input or a parameter and cannot be set"
            )),
        }
    }

    /// All-or-nothing: checks every value first, then sets them (two passes
    /// over the host's arrays: nothing is allocated from `nvr`).
    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Res<Status> {
        self.check("fmi2SetReal", mask::SET_REAL)?;
        let find = |r: u32| {
            md::position(md::REALS, r, |v| v.vr)
                .ok_or_else(|| format!("fmi2SetReal: {r} is not the value reference of a Real"))
        };
        for (&r, &v) in vrs.iter().zip(vals) {
            let var = &md::REALS[find(r)?];
            self.settable("fmi2SetReal", var.name, var.causality, true)?;
            if !v.is_finite() {
                return Err(format!(
                    "fmi2SetReal: {} = {v} is not finite; the value was not set",
                    var.name
                ));
            }
        }
        for (&r, &v) in vrs.iter().zip(vals) {
            let i = find(r)?;
            let var = &md::REALS[i];
            self.values.real[i] = v;
            if var.causality == Causality::Input {
                self.cache = None;
                if matches!(
                    var.vr,
                    vr::X | vr::Y | vr::Z | vr::YAW | vr::PITCH | vr::ROLL
                ) {
                    self.pose_inputs_set = true;
                }
            }
        }
        Ok(Status::Ok)
    }

    pub fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status> {
        self.check("fmi2SetInteger", mask::SET_OTHER)?;
        let find = |r: u32| {
            md::position(md::INTEGERS, r, |v| v.vr).ok_or_else(|| {
                format!(
                    "fmi2SetInteger: {r} is not the value reference of an Integer or Enumeration"
                )
            })
        };
        for (&r, &v) in vrs.iter().zip(vals) {
            let var = &md::INTEGERS[find(r)?];
            self.settable("fmi2SetInteger", var.name, var.causality, false)?;
            if let Some(items) = var.items {
                if !items.contains(&v) {
                    return Err(format!(
                        "fmi2SetInteger: {} = {v} is not an item of its enumeration {items:?}",
                        var.name
                    ));
                }
            }
        }
        for (&r, &v) in vrs.iter().zip(vals) {
            let i = find(r)?;
            self.values.int[i] = v;
        }
        Ok(Status::Ok)
    }

    /// `vals`: fmi2Boolean values (0 is false).
    pub fn set_boolean(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status> {
        self.check("fmi2SetBoolean", mask::SET_OTHER)?;
        let find = |r: u32| {
            md::position(md::BOOLEANS, r, |v| v.vr).ok_or_else(|| {
                format!("fmi2SetBoolean: {r} is not the value reference of a Boolean")
            })
        };
        for &r in vrs {
            let var = &md::BOOLEANS[find(r)?];
            self.settable("fmi2SetBoolean", var.name, var.causality, false)?;
        }
        for (&r, &v) in vrs.iter().zip(vals) {
            let i = find(r)?;
            self.values.boolean[i] = v != 0;
        }
        Ok(Status::Ok)
    }

    /// `val(k)`: the k-th value (`None`: the host passed NULL).
    pub fn set_string<'a>(
        &mut self,
        vrs: &[u32],
        val: impl Fn(usize) -> Option<&'a std::ffi::CStr>,
    ) -> Res<Status> {
        self.check("fmi2SetString", mask::SET_OTHER)?;
        let find = |r: u32| {
            md::position(md::STRINGS, r, |v| v.vr)
                .ok_or_else(|| format!("fmi2SetString: {r} is not the value reference of a String"))
        };
        for (k, &r) in vrs.iter().enumerate() {
            let var = &md::STRINGS[find(r)?];
            self.settable("fmi2SetString", var.name, var.causality, false)?;
            let v = val(k)
                .ok_or_else(|| format!("fmi2SetString: the value of {} is NULL", var.name))?;
            if v.to_str().is_err() {
                return Err(format!(
                    "fmi2SetString: the value of {} is not UTF-8",
                    var.name
                ));
            }
        }
        for (k, &r) in vrs.iter().enumerate() {
            let i = find(r)?;
            if let Some(v) = val(k) {
                self.values.string[i] = v.to_owned();
            }
        }
        Ok(Status::Ok)
    }

    // ---- Model Exchange -------------------------------------------------

    /// The event indicator: `numerics.sweepStep` minus the rim travel since
    /// the last committed cut. Positive while the cutter is within one sweep
    /// step of the cut, zero when it has travelled a sweep step. The travel is
    /// the larger of the pose's (from the last cut's pose to the current pose
    /// inputs) and the rim's spin about the axle since the last commit (which
    /// the pose does not show: a disc spinning in place does friction work
    /// that the energy must book). Evaluated without changing anything;
    /// `sweepStep` itself before the first cut.
    pub fn event_indicator(&self) -> f64 {
        let step = self.values.real(vr::NUMERICS_SWEEP_STEP);
        let pose = self.values.pose();
        let Some(travel) = self.model.as_ref().and_then(|m| m.travel_since_cut(&pose)) else {
            return step;
        };
        let radius = self.values.real(vr::CUTTER_RADIUS);
        let spin = rim_spin_speed(&pose, &self.values.twist(), radius)
            * (self.time - self.last_commit_time);
        step - travel.max(spin)
    }

    pub fn get_event_indicators(&self, out: &mut [f64]) -> Res<Status> {
        const F: &str = "fmi2GetEventIndicators";
        self.check_kind(F, Kind::ModelExchange)?;
        self.check(F, mask::GET_EVENT_INDICATORS)?;
        if out.len() != md::NUMBER_OF_EVENT_INDICATORS {
            return Err(format!(
                "{F}: ni = {}, but the model has {}",
                out.len(),
                md::NUMBER_OF_EVENT_INDICATORS
            ));
        }
        out[0] = self.event_indicator();
        Ok(Status::Ok)
    }

    /// Commits the cut of the current pose (the rock, the energy since the
    /// last commit), once per event.
    fn commit_cut(&mut self, func: &str) -> Res<()> {
        if self.event_committed {
            return Ok(());
        }
        let pose = self.values.pose();
        let twist = self.values.twist();
        pose.validate().map_err(|e| format!("{func}: {e}"))?;
        twist.validate().map_err(|e| format!("{func}: {e}"))?;
        let dt = self.time - self.last_commit_time;
        let model = self.model.as_mut().ok_or(format!("{func}: no model"))?;
        match model.commit(&pose, &twist, dt) {
            Ok(changed) => {
                self.last_commit_time = self.time;
                self.event_committed = true;
                self.cache = None;
                if changed {
                    self.log_event(|| format!("t = {}: rock cut committed (dt = {dt})", self.time));
                }
                Ok(())
            }
            // the commit is all or nothing: the instance is as it was
            Err(e) => Err(format!("{func}: committing the cut failed: {e}")),
        }
    }

    /// The backstop time event (see [`TIME_EVENT_SWEEPS`]): when the cutter,
    /// at the current speed, will have travelled that many sweep steps since
    /// the last cut. None when it does not move. If the speed changes the
    /// time is only early (an event that commits a shorter path) or late (the
    /// commit cuts the longer path in sweep-step sub-steps): the cuts stay on
    /// the path either way.
    fn backstop_event_time(&self) -> Option<f64> {
        let step = self.values.real(vr::NUMERICS_SWEEP_STEP);
        let radius = self.values.real(vr::CUTTER_RADIUS);
        let (pose, twist) = (self.values.pose(), self.values.twist());
        let speed = rim_speed(&pose, &twist, radius).max(rim_spin_speed(&pose, &twist, radius));
        let left = self.event_indicator() + (TIME_EVENT_SWEEPS - 1.0) * step;
        let t = self.time + left / speed;
        (speed > 0.0 && left > 0.0 && t.is_finite() && t > self.time).then_some(t)
    }

    pub fn enter_event_mode(&mut self) -> Res<Status> {
        self.check_kind("fmi2EnterEventMode", Kind::ModelExchange)?;
        self.check("fmi2EnterEventMode", mask::ENTER_EVENT_MODE)?;
        if self.mode != EventMode {
            self.event_committed = false;
        }
        self.mode = EventMode;
        Ok(Status::Ok)
    }

    /// Commits the cut of the current pose, once per event.
    pub fn new_discrete_states(&mut self) -> Res<EventInfo> {
        self.check_kind("fmi2NewDiscreteStates", Kind::ModelExchange)?;
        self.check("fmi2NewDiscreteStates", mask::NEW_DISCRETE_STATES)?;
        self.commit_cut("fmi2NewDiscreteStates")?;
        Ok(EventInfo {
            next_event_time: self.backstop_event_time(),
            ..EventInfo::default()
        })
    }

    pub fn enter_continuous_time_mode(&mut self) -> Res<Status> {
        self.check_kind("fmi2EnterContinuousTimeMode", Kind::ModelExchange)?;
        self.check(
            "fmi2EnterContinuousTimeMode",
            mask::ENTER_CONTINUOUS_TIME_MODE,
        )?;
        // A host that skipped fmi2NewDiscreteStates in the initial event:
        // the event indicator counts from the first cut, so make it now.
        if self
            .model
            .as_ref()
            .is_some_and(|m| m.travel_since_cut(&self.values.pose()).is_none())
        {
            self.commit_cut("fmi2EnterContinuousTimeMode")?;
        }
        self.mode = ContinuousTimeMode;
        Ok(Status::Ok)
    }

    /// Returns (enterEventMode, terminateSimulation).
    pub fn completed_integrator_step(&mut self) -> Res<(bool, bool)> {
        self.check_kind("fmi2CompletedIntegratorStep", Kind::ModelExchange)?;
        self.check(
            "fmi2CompletedIntegratorStep",
            mask::COMPLETED_INTEGRATOR_STEP,
        )?;
        let pose = self.values.pose();
        let twist = self.values.twist();
        let model = self
            .model
            .as_ref()
            .ok_or("fmi2CompletedIntegratorStep: no model")?;
        let works = model
            .power(&pose, &twist)
            .map_err(|e| format!("fmi2CompletedIntegratorStep: {e}"))?
            != 0.0;
        if !works {
            // no work on the rock since the last event: the energy of the
            // next commit counts from here
            self.last_commit_time = self.time;
        }
        // An event once per sweep step of travel, not once per solver step:
        // the indicator's zero crossing, which hosts locate themselves, or
        // this step ending on it (a fixed step that travels one sweep step).
        let step = self.values.real(vr::NUMERICS_SWEEP_STEP);
        Ok((self.event_indicator() <= EVENT_SLACK * step, false))
    }

    pub fn set_time(&mut self, t: f64) -> Res<Status> {
        self.check_kind("fmi2SetTime", Kind::ModelExchange)?;
        self.check("fmi2SetTime", mask::SET_TIME)?;
        if !t.is_finite() {
            return Err(format!("fmi2SetTime: time = {t} is not finite"));
        }
        // The time may go backwards in continuous-time mode (a solver's trial
        // steps); the outputs do not depend on it.
        self.time = t;
        Ok(Status::Ok)
    }

    /// The functions of the (empty) continuous state vector: `n` must be 0.
    pub fn no_states(&self, func: &str, mask: u32, n: usize, what: &str) -> Res<Status> {
        self.check_kind(func, Kind::ModelExchange)?;
        self.check(func, mask)?;
        if n != 0 {
            return Err(format!("{func}: {what} = {n}, but the model has none (0)"));
        }
        Ok(Status::Ok)
    }

    // ---- Co-Simulation ------------------------------------------------

    pub fn do_step(&mut self, t: f64, h: f64) -> Res<Status> {
        self.check_kind("fmi2DoStep", Kind::CoSimulation)?;
        self.check("fmi2DoStep", mask::DO_STEP)?;
        if !t.is_finite() {
            return Err(format!(
                "fmi2DoStep: currentCommunicationPoint = {t} is not finite"
            ));
        }
        if !(h.is_finite() && h >= 0.0) {
            return Err(format!(
                "fmi2DoStep: communicationStepSize = {h} must be finite and >= 0"
            ));
        }
        let tol = TIME_TOLERANCE * 1f64.max(t.abs()).max(self.time.abs());
        if (t - self.time).abs() > tol {
            return Err(format!(
                "fmi2DoStep: currentCommunicationPoint = {t} does not match the FMU's time {}",
                self.time
            ));
        }
        let start = if self.pose_inputs_set {
            self.values.pose()
        } else {
            self.cs_pose
        };
        let twist = self.values.twist();
        start
            .validate()
            .map_err(|e| format!("fmi2DoStep: start pose: {e}"))?;
        twist.validate().map_err(|e| format!("fmi2DoStep: {e}"))?;
        let model = self.model.as_mut().ok_or("fmi2DoStep: no model")?;
        let result = model
            .advance(&start, &twist, h)
            .and_then(|end| Ok((end, model.evaluate(&end, &twist)?)));
        match result {
            Ok((end, outputs)) => {
                self.cs_pose = end;
                self.pose_inputs_set = false;
                self.time = t + h;
                self.cache = Some(outputs);
                self.log_event(|| format!("fmi2DoStep: t = {t}, h = {h} done"));
                Ok(Status::Ok)
            }
            // the step is all or nothing: the instance is as it was, and a
            // shorter step may follow
            Err(e) => Err(format!("fmi2DoStep(t = {t}, h = {h}) failed: {e}")),
        }
    }

    pub fn last_successful_time(&self) -> f64 {
        self.time
    }

    // ---- FMU state ------------------------------------------------------

    pub fn snapshot(&self) -> Snapshot {
        let keeps_model = !matches!(self.mode, Instantiated | InitializationMode);
        Snapshot {
            kind: self.kind,
            mode: self.mode,
            values: self.values.clone(),
            start_time: self.start_time,
            time: self.time,
            last_commit_time: self.last_commit_time,
            event_committed: self.event_committed,
            cs_pose: self.cs_pose,
            pose_inputs_set: self.pose_inputs_set,
            model: if keeps_model {
                self.model.as_ref().map(Model::state)
            } else {
                None
            },
            encoded: std::cell::OnceCell::new(),
        }
    }

    /// Replaces the whole state by `s`; on error nothing changed.
    pub fn restore(&mut self, s: &Snapshot) -> Res<Status> {
        if s.kind != self.kind {
            return Err(format!(
                "fmi2SetFMUstate: the state was taken from a {} instance, this one is {}",
                kind_name(s.kind),
                kind_name(self.kind)
            ));
        }
        let (model, params) = match &s.model {
            None => (None, None),
            Some(ms) => {
                let params = s
                    .values
                    .params(self.resources.as_deref(), Files::MayBeMissing)
                    .map_err(|e| format!("fmi2SetFMUstate: {e}"))?;
                let reuse = self.model.is_some() && self.model_params.as_ref() == Some(&params);
                let mut model = if reuse {
                    self.model.take().unwrap()
                } else {
                    // The state holds the whole surface: the initial surface
                    // file is not read (it may be gone, or, in a forged
                    // state, name something that never ends).
                    let mut flat = params.clone();
                    flat.rock.initial_surface.clear();
                    Model::new(flat).map_err(|e| format!("fmi2SetFMUstate: {e}"))?
                };
                if let Err(e) = model.set_state(ms) {
                    if reuse {
                        self.model = Some(model);
                    }
                    return Err(format!("fmi2SetFMUstate: {e}"));
                }
                (Some(model), Some(params))
            }
        };
        self.mode = s.mode;
        self.values = s.values.clone();
        self.start_time = s.start_time;
        self.time = s.time;
        self.last_commit_time = s.last_commit_time;
        self.event_committed = s.event_committed;
        self.cs_pose = s.cs_pose;
        self.pose_inputs_set = s.pose_inputs_set;
        // Before initialization (no model state) the model is rebuilt from the
        // parameters on demand.
        self.model = model;
        self.model_params = params;
        self.cache = None;
        Ok(Status::Ok)
    }
}

pub fn kind_name(k: Kind) -> &'static str {
    match k {
        Kind::ModelExchange => "Model Exchange",
        Kind::CoSimulation => "Co-Simulation",
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

/// A captured FMU state (what `fmi2FMUstate` points to).
pub struct Snapshot {
    pub kind: Kind,
    pub mode: Mode,
    pub values: Values,
    pub start_time: f64,
    pub time: f64,
    pub last_commit_time: f64,
    pub event_committed: bool,
    pub cs_pose: Pose,
    pub pose_inputs_set: bool,
    /// The core's discrete state, after initialization.
    pub model: Option<ModelState>,
    /// The serialized form, made on demand (fmi2SerializedFMUstateSize).
    pub encoded: std::cell::OnceCell<Vec<u8>>,
}

//! One cutterhead FMU instance: the FMI 2.0 state machine of
//! [`super::instance`] (same modes, same masks, same rules) over a
//! [`Head`] instead of a single-disc model, with the variable table of
//! [`super::head_md`] generated from the layout packed in the FMU.
//!
//! Safe Rust only, like `instance.rs`.

use std::cell::OnceCell;
use std::collections::HashMap;
use std::ffi::CString;
use std::path::{Path, PathBuf};

use crate::core::head::{place_all, DiscSpec, Drive, Head, HeadOutputs, HeadState, Mount};
use crate::core::layout::Layout;
use crate::core::params::CutterParams;
use crate::core::{rim_speed, rim_spin_speed, Params, Pose, Twist};

use super::head_md::{self, HeadVar, Slot, Ty};
use super::instance::{
    kind_name, mask, EventInfo, Files, Kind, Mode, Res, Values, EVENT_SLACK, TIME_EVENT_SWEEPS,
};
use super::log::{Category, Logger, Status};
use super::machine::{check_kind, check_mode, mode_name, LogSwitches};
use super::md::{self, vr, Causality};
use super::state::fnv1a64;
use super::state::Reader;

use Mode::*;

/// Relative tolerance between the host's communication point and the FMU's time.
const TIME_TOLERANCE: f64 = 1e-9;

/// Values of everything settable: kerf's table for the shared parameters,
/// the head inputs, the per-disc parameters and inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadValues {
    pub kerf: Values,
    pub head_in: [f64; 12],
    /// Head-only parameters (`head_md::HEAD_PARAMS`).
    pub head_par: [f64; 1],
    pub disc_par: Vec<[f64; 8]>,
    pub disc_in: Vec<[f64; 12]>,
}

fn pose_of(a: &[f64; 12]) -> Pose {
    Pose::new(a[0], a[1], a[2], a[3], a[4], a[5])
}

fn twist_of(a: &[f64; 12]) -> Twist {
    Twist::new([a[6], a[7], a[8]], [a[9], a[10], a[11]])
}

impl HeadValues {
    fn specs(&self) -> Vec<DiscSpec> {
        self.disc_par
            .iter()
            .map(|p| DiscSpec {
                mount: Mount {
                    track: p[0],
                    angle: p[1],
                    tilt: p[2],
                    setback: p[3],
                },
                spacing: p[4],
                cutter: CutterParams {
                    radius: p[5],
                    tip_width: p[6],
                    tip_radius: p[7],
                },
            })
            .collect()
    }
}

/// A captured head FMU state.
pub struct HeadSnapshot {
    pub kind: Kind,
    pub mode: Mode,
    pub values: HeadValues,
    pub start_time: f64,
    pub time: f64,
    pub last_commit_time: f64,
    pub event_committed: bool,
    /// Co-Simulation: head pose (head drive) or disc poses (disc drive)
    /// reached at the end of the last step.
    pub cs_head: Pose,
    pub cs_discs: Vec<Pose>,
    pub pose_set: Vec<bool>,
    pub head: Option<HeadState>,
    pub encoded: OnceCell<Vec<u8>>,
}

pub struct HeadInstance {
    pub(crate) name: CString,
    pub(crate) kind: Kind,
    pub(crate) logger: Logger,
    log_on: LogSwitches,
    pub(crate) resources: Option<PathBuf>,
    pub(crate) mode: Mode,
    guid: String,
    drive: Drive,
    vars: Vec<HeadVar>,
    /// (type class, value reference) -> index in `vars`.
    lookup: HashMap<(u8, u32), usize>,
    start_values: HeadValues,
    values: HeadValues,
    start_time: f64,
    time: f64,
    head: Option<Head>,
    head_key: Option<(Params, Vec<DiscSpec>, [f64; 1])>,
    cs_head: Pose,
    cs_discs: Vec<Pose>,
    /// Co-Simulation: pose inputs set since the last step (head drive: one
    /// flag; disc drive: one per disc).
    pose_set: Vec<bool>,
    last_commit_time: f64,
    event_committed: bool,
    cache: Option<HeadOutputs>,
}

fn class(ty: Ty) -> u8 {
    match ty {
        Ty::Real => 0,
        Ty::Integer | Ty::Enumeration => 1,
        Ty::Boolean => 2,
        Ty::String => 3,
    }
}

impl HeadInstance {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: CString,
        kind: Kind,
        logger: Logger,
        resources: Option<PathBuf>,
        logging_on: bool,
        guid: String,
        layout: &Layout,
        drive: Drive,
    ) -> Res<Self> {
        let vars = head_md::variables(layout, drive);
        let lookup = vars
            .iter()
            .enumerate()
            .map(|(k, v)| ((class(v.ty), v.vr), k))
            .collect();
        let n = layout.cutters.len();
        let mut values = HeadValues {
            kerf: Values::start(),
            head_in: [0.0; 12],
            head_par: [0.0; 1],
            disc_par: vec![[0.0; 8]; n],
            disc_in: vec![[0.0; 12]; n],
        };
        for v in &vars {
            let Some(s) = &v.start else { continue };
            match v.slot {
                Slot::Kerf => match v.ty {
                    Ty::Real => {
                        let i = md::position(md::REALS, v.vr, |x| x.vr).unwrap();
                        values.kerf.real[i] = s.parse().map_err(|_| format!("bad start {s}"))?;
                    }
                    Ty::Integer | Ty::Enumeration => {
                        let i = md::position(md::INTEGERS, v.vr, |x| x.vr).unwrap();
                        values.kerf.int[i] = s.parse().map_err(|_| format!("bad start {s}"))?;
                    }
                    _ => {}
                },
                Slot::HeadInput(k) => values.head_in[k] = s.parse().unwrap_or(0.0),
                Slot::HeadParam(k) => values.head_par[k] = s.parse().unwrap_or(0.0),
                Slot::DiscParam(i, k) => values.disc_par[i][k] = s.parse().unwrap_or(0.0),
                Slot::DiscInput(i, k) => values.disc_in[i][k] = s.parse().unwrap_or(0.0),
                _ => {}
            }
        }
        let log_on = LogSwitches::new(logging_on);
        let pose_flags = match drive {
            Drive::Head => 1,
            Drive::Discs => n,
        };
        let mut inst = Self {
            name,
            kind,
            logger,
            log_on,
            resources,
            mode: Instantiated,
            guid,
            drive,
            vars,
            lookup,
            start_values: values.clone(),
            values,
            start_time: 0.0,
            time: 0.0,
            head: None,
            head_key: None,
            cs_head: Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            cs_discs: Vec::new(),
            pose_set: vec![false; pose_flags],
            last_commit_time: 0.0,
            event_committed: false,
            cache: None,
        };
        inst.reset_cs_poses();
        Ok(inst)
    }

    fn reset_cs_poses(&mut self) {
        self.cs_head = pose_of(&self.values.head_in);
        self.cs_discs = self.values.disc_in.iter().map(pose_of).collect();
        self.pose_set.iter_mut().for_each(|b| *b = false);
    }

    // ---- logging ------------------------------------------------------

    fn log_enabled(&self, cat: Category) -> bool {
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

    pub fn setup_experiment(
        &mut self,
        _tol: Option<f64>,
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
        Ok(Status::Ok)
    }

    fn params(&self, files: Files) -> Res<(Params, Vec<DiscSpec>, [f64; 1])> {
        let params = self.values.kerf.params(self.resources.as_deref(), files)?;
        Ok((params, self.values.specs(), self.values.head_par))
    }

    fn ensure_head(&mut self) -> Res<Status> {
        let key = self.params(Files::MustExist)?;
        if self.head.is_some() && self.head_key.as_ref() == Some(&key) {
            return Ok(Status::Ok);
        }
        let mut head = Head::new(key.0.clone(), key.1.clone()).map_err(|e| e.to_string())?;
        head.steady_start(key.2[0]).map_err(|e| e.to_string())?;
        self.head = Some(head);
        self.head_key = Some(key);
        self.cache = None;
        Ok(Status::Ok)
    }

    pub fn exit_initialization_mode(&mut self) -> Res<Status> {
        self.check("fmi2ExitInitializationMode", mask::EXIT_INITIALIZATION_MODE)?;
        let status = self
            .ensure_head()
            .map_err(|e| format!("fmi2ExitInitializationMode: {e}"))?;
        self.last_commit_time = self.time;
        self.reset_cs_poses();
        self.event_committed = false;
        self.cache = None;
        self.mode = match self.kind {
            Kind::ModelExchange => EventMode,
            Kind::CoSimulation => StepComplete,
        };
        self.log_event(|| format!("head initialized at t = {}", self.time));
        Ok(status)
    }

    pub fn terminate(&mut self) -> Res<Status> {
        self.check("fmi2Terminate", mask::TERMINATE)?;
        self.mode = Terminated;
        let path = self
            .head_key
            .as_ref()
            .map(|(p, _, _)| p.rock.final_surface.clone())
            .unwrap_or_default();
        if !path.is_empty() {
            if let Some(h) = &self.head {
                h.write_surface(Path::new(&path))
                    .map_err(|e| format!("fmi2Terminate: writing rock.finalSurface: {e}"))?;
            }
        }
        Ok(Status::Ok)
    }

    pub fn reset(&mut self) -> Res<Status> {
        self.check("fmi2Reset", mask::ANY)?;
        self.mode = Instantiated;
        self.values = self.start_values.clone();
        self.start_time = 0.0;
        self.time = 0.0;
        self.head = None;
        self.head_key = None;
        self.reset_cs_poses();
        self.last_commit_time = 0.0;
        self.event_committed = false;
        self.cache = None;
        Ok(Status::Ok)
    }

    // ---- motions and outputs --------------------------------------------

    fn cs_after_step(&self) -> bool {
        self.kind == Kind::CoSimulation && !matches!(self.mode, Instantiated | InitializationMode)
    }

    /// The head pose the outputs are for (head drive).
    fn head_pose(&self) -> Pose {
        if self.cs_after_step() && !self.pose_set[0] {
            self.cs_head
        } else {
            pose_of(&self.values.head_in)
        }
    }

    /// Every disc's pose and twist now.
    fn motions(&self) -> Vec<(Pose, Twist)> {
        match self.drive {
            Drive::Head => place_all(
                &self.values.specs(),
                &self.head_pose(),
                &twist_of(&self.values.head_in),
            ),
            Drive::Discs => self
                .values
                .disc_in
                .iter()
                .enumerate()
                .map(|(i, a)| {
                    let p = if self.cs_after_step() && !self.pose_set[i] {
                        self.cs_discs[i]
                    } else {
                        pose_of(a)
                    };
                    (p, twist_of(a))
                })
                .collect(),
        }
    }

    fn outputs(&mut self) -> Res<&HeadOutputs> {
        if self.cache.is_none() {
            if self.mode == InitializationMode {
                self.ensure_head()?;
            }
            let pose = self.head_pose();
            let twist = twist_of(&self.values.head_in);
            let motions = match self.drive {
                Drive::Head => Vec::new(),
                Drive::Discs => self.motions(),
            };
            let head = self.head.as_mut().ok_or("the head was never initialized")?;
            let o = match self.drive {
                Drive::Head => head.evaluate_head(&pose, &twist),
                Drive::Discs => head.evaluate_discs(&motions),
            }
            .map_err(|e| e.to_string())?;
            self.cache = Some(o);
        }
        Ok(self.cache.as_ref().unwrap())
    }

    fn var(&self, func: &str, cls: u8, r: u32, what: &str) -> Res<&HeadVar> {
        self.lookup
            .get(&(cls, r))
            .map(|&k| &self.vars[k])
            .ok_or_else(|| format!("{func}: {r} is not the value reference of {what}"))
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Res<Status> {
        self.check("fmi2GetReal", mask::GET)?;
        for (k, &r) in vrs.iter().enumerate() {
            let v = self.var("fmi2GetReal", 0, r, "a Real")?;
            let (slot, name) = (v.slot, v.name.clone());
            out[k] = match slot {
                Slot::Kerf => self.values.kerf.real[md::position(md::REALS, r, |x| x.vr).unwrap()],
                Slot::HeadInput(j) => self.values.head_in[j],
                Slot::HeadParam(j) => self.values.head_par[j],
                Slot::DiscParam(i, j) => self.values.disc_par[i][j],
                Slot::DiscInput(i, j) => self.values.disc_in[i][j],
                Slot::Total(j) => {
                    let o = self
                        .outputs()
                        .map_err(|e| format!("fmi2GetReal({name}): {e}"))?;
                    match j {
                        0..=2 => o.force[j],
                        3..=5 => o.moment[j - 3],
                        6 => o.thrust,
                        7 => o.torque,
                        8 => o.excavated_volume,
                        9 => o.cutting_energy,
                        10 => o.specific_energy,
                        _ => o.chipped_volume,
                    }
                }
                Slot::DiscOutput(i, j) => {
                    let o = &self
                        .outputs()
                        .map_err(|e| format!("fmi2GetReal({name}): {e}"))?
                        .discs[i];
                    match j {
                        0..=2 => o.force[j],
                        3..=5 => o.moment[j - 3],
                        6 => o.normal_force,
                        7 => o.rolling_force,
                        8 => o.side_force,
                        9 => o.penetration,
                        _ => o.contact_angle,
                    }
                }
                _ => unreachable!("a Real slot"),
            };
        }
        Ok(Status::Ok)
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> Res<Status> {
        self.check("fmi2GetInteger", mask::GET)?;
        for (k, &r) in vrs.iter().enumerate() {
            let slot = self
                .var("fmi2GetInteger", 1, r, "an Integer or Enumeration")?
                .slot;
            out[k] = match slot {
                Slot::ChipCount => {
                    let n = self
                        .outputs()
                        .map_err(|e| format!("fmi2GetInteger(chipCount): {e}"))?
                        .chip_count;
                    i32::try_from(n).unwrap_or(i32::MAX)
                }
                _ => self.values.kerf.int[md::position(md::INTEGERS, r, |x| x.vr).unwrap()],
            };
        }
        Ok(Status::Ok)
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> Res<Status> {
        self.check("fmi2GetBoolean", mask::GET)?;
        for (k, &r) in vrs.iter().enumerate() {
            let v = self.var("fmi2GetBoolean", 2, r, "a Boolean")?;
            let (slot, name) = (v.slot, v.name.clone());
            out[k] = match slot {
                Slot::DiscInContact(i) => {
                    self.outputs()
                        .map_err(|e| format!("fmi2GetBoolean({name}): {e}"))?
                        .discs[i]
                        .in_contact
                }
                _ => self.values.kerf.boolean[md::position(md::BOOLEANS, r, |x| x.vr).unwrap()],
            };
        }
        Ok(Status::Ok)
    }

    pub fn get_string(&mut self, vrs: &[u32], out: &mut [*const std::ffi::c_char]) -> Res<Status> {
        self.check("fmi2GetString", mask::GET)?;
        for (k, &r) in vrs.iter().enumerate() {
            self.var("fmi2GetString", 3, r, "a String")?;
            let i = md::position(md::STRINGS, r, |x| x.vr).unwrap();
            out[k] = self.values.kerf.string[i].as_ptr();
        }
        Ok(Status::Ok)
    }

    fn settable(&self, func: &str, v: &HeadVar, continuous: bool) -> Res<()> {
        match v.causality {
            Causality::Parameter => {
                if matches!(self.mode, Instantiated | InitializationMode) {
                    Ok(())
                } else {
                    Err(format!(
                        "{func}: parameter {} is fixed: it can only be set before fmi2ExitInitializationMode (now in {})",
                        v.name,
                        mode_name(self.mode)
                    ))
                }
            }
            Causality::Input => {
                if self.mode == ContinuousTimeMode && !continuous {
                    Err(format!(
                        "{func}: {} is a discrete input: not settable in continuous-time mode",
                        v.name
                    ))
                } else {
                    Ok(())
                }
            }
            _ => Err(format!(
                "{func}: {} is not an input or a parameter and cannot be set",
                v.name
            )),
        }
    }

    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Res<Status> {
        self.check("fmi2SetReal", mask::SET_REAL)?;
        let mut idx = Vec::with_capacity(vrs.len());
        for (&r, &x) in vrs.iter().zip(vals) {
            let v = self.var("fmi2SetReal", 0, r, "a Real")?;
            self.settable("fmi2SetReal", v, true)?;
            if !x.is_finite() {
                return Err(format!(
                    "fmi2SetReal: {} = {x} is not finite; the value was not set",
                    v.name
                ));
            }
            idx.push(v.slot);
        }
        for (slot, (&r, &x)) in idx.into_iter().zip(vrs.iter().zip(vals)) {
            match slot {
                Slot::Kerf => {
                    self.values.kerf.real[md::position(md::REALS, r, |x| x.vr).unwrap()] = x;
                    self.cache = None;
                }
                Slot::HeadInput(j) => {
                    self.values.head_in[j] = x;
                    self.cache = None;
                    if j < 6 {
                        self.pose_set[0] = true;
                    }
                }
                Slot::DiscParam(i, j) => {
                    self.values.disc_par[i][j] = x;
                    self.cache = None;
                }
                Slot::HeadParam(j) => {
                    self.values.head_par[j] = x;
                    self.cache = None;
                }
                Slot::DiscInput(i, j) => {
                    self.values.disc_in[i][j] = x;
                    self.cache = None;
                    if j < 6 {
                        self.pose_set[i] = true;
                    }
                }
                _ => {}
            }
        }
        Ok(Status::Ok)
    }

    pub fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status> {
        self.check("fmi2SetInteger", mask::SET_OTHER)?;
        let mut idx = Vec::new();
        for (&r, &x) in vrs.iter().zip(vals) {
            let v = self.var("fmi2SetInteger", 1, r, "an Integer or Enumeration")?;
            self.settable("fmi2SetInteger", v, false)?;
            let i = md::position(md::INTEGERS, r, |x| x.vr).unwrap();
            if let Some(items) = md::INTEGERS[i].items {
                if !items.contains(&x) {
                    return Err(format!(
                        "fmi2SetInteger: {} = {x} is not an item of its enumeration {items:?}",
                        v.name
                    ));
                }
            }
            idx.push(i);
        }
        for (i, &x) in idx.into_iter().zip(vals) {
            self.values.kerf.int[i] = x;
        }
        self.cache = None;
        Ok(Status::Ok)
    }

    pub fn set_boolean(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status> {
        self.check("fmi2SetBoolean", mask::SET_OTHER)?;
        let mut idx = Vec::new();
        for &r in vrs {
            let v = self.var("fmi2SetBoolean", 2, r, "a Boolean")?;
            self.settable("fmi2SetBoolean", v, false)?;
            idx.push(md::position(md::BOOLEANS, r, |x| x.vr).unwrap());
        }
        for (i, &x) in idx.into_iter().zip(vals) {
            self.values.kerf.boolean[i] = x != 0;
        }
        self.cache = None;
        Ok(Status::Ok)
    }

    /// `val(k)`: the k-th value (`None`: the host passed NULL).
    pub fn set_string<'a>(
        &mut self,
        vrs: &[u32],
        val: &dyn Fn(usize) -> Option<&'a std::ffi::CStr>,
    ) -> Res<Status> {
        self.check("fmi2SetString", mask::SET_OTHER)?;
        let mut idx = Vec::new();
        for (k, &r) in vrs.iter().enumerate() {
            let v = self.var("fmi2SetString", 3, r, "a String")?;
            self.settable("fmi2SetString", v, false)?;
            let x =
                val(k).ok_or_else(|| format!("fmi2SetString: the value of {} is NULL", v.name))?;
            if x.to_str().is_err() {
                return Err(format!(
                    "fmi2SetString: the value of {} is not UTF-8",
                    v.name
                ));
            }
            idx.push((
                md::position(md::STRINGS, r, |x| x.vr).unwrap(),
                x.to_owned(),
            ));
        }
        for (i, x) in idx {
            self.values.kerf.string[i] = x;
        }
        self.cache = None;
        Ok(Status::Ok)
    }

    // ---- Model Exchange -------------------------------------------------

    /// The event indicator, as kerf.fmu's ([`super::instance::Instance::event_indicator`])
    /// over all discs: `numerics.sweepStep` minus the largest rim travel of
    /// any disc since the last committed cut. A disc's travel is the larger
    /// of its pose's (from its last cut to its pose now) and its rim's spin
    /// about the axle since the last commit. Zero when the disc that moved
    /// most has travelled a sweep step; `sweepStep` before the first cut.
    /// Changes nothing.
    pub fn event_indicator(&self) -> f64 {
        let step = self.values.kerf.real(vr::NUMERICS_SWEEP_STEP);
        let Some(head) = self.head.as_ref() else {
            return step;
        };
        let motions = self.motions();
        let Some(travel) = head.travel_since_cut(&motions) else {
            return step;
        };
        let dt = self.time - self.last_commit_time;
        let spin = motions
            .iter()
            .zip(head.specs())
            .map(|((p, t), s)| rim_spin_speed(p, t, s.cutter.radius) * dt)
            .fold(0.0, f64::max);
        step - travel.max(spin)
    }

    pub fn get_event_indicators(&self, out: &mut [f64]) -> Res<Status> {
        const F: &str = "fmi2GetEventIndicators";
        self.check_kind(F, Kind::ModelExchange)?;
        self.check(F, mask::GET_EVENT_INDICATORS)?;
        if out.len() != head_md::NUMBER_OF_EVENT_INDICATORS {
            return Err(format!(
                "{F}: ni = {}, but the head has {}",
                out.len(),
                head_md::NUMBER_OF_EVENT_INDICATORS
            ));
        }
        out[0] = self.event_indicator();
        Ok(Status::Ok)
    }

    /// Commits every disc's cut along its path from its last cut, once per
    /// event.
    fn commit_cut(&mut self, func: &str) -> Res<()> {
        if self.event_committed {
            return Ok(());
        }
        let motions = self.motions();
        let dt = self.time - self.last_commit_time;
        let head = self.head.as_mut().ok_or(format!("{func}: no head"))?;
        match head.commit(&motions, dt) {
            Ok(changed) => {
                self.last_commit_time = self.time;
                self.event_committed = true;
                self.cache = None;
                if changed {
                    self.log_event(|| format!("t = {}: cuts committed (dt = {dt})", self.time));
                }
                Ok(())
            }
            // the commit is all or nothing: the instance is as it was
            Err(e) => Err(format!("{func}: committing the cuts failed: {e}")),
        }
    }

    /// The backstop time event (kerf.fmu's, [`TIME_EVENT_SWEEPS`]): when the
    /// fastest rim, at the current speeds, will have travelled that many
    /// sweep steps since the last cut. None when no disc moves.
    fn backstop_event_time(&self) -> Option<f64> {
        let step = self.values.kerf.real(vr::NUMERICS_SWEEP_STEP);
        let motions = self.motions();
        let speed = motions
            .iter()
            .zip(self.values.specs())
            .map(|((p, t), s)| {
                let r = s.cutter.radius;
                rim_speed(p, t, r).max(rim_spin_speed(p, t, r))
            })
            .fold(0.0, f64::max);
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

    /// Commits every disc's cut along its path, once per event.
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
            .head
            .as_ref()
            .is_some_and(|h| h.travel_since_cut(&self.motions()).is_none())
        {
            self.commit_cut("fmi2EnterContinuousTimeMode")?;
        }
        self.mode = ContinuousTimeMode;
        Ok(Status::Ok)
    }

    /// Returns (enterEventMode, terminateSimulation): an event once per
    /// sweep step of travel (the indicator at zero, within the slack), as
    /// kerf.fmu.
    pub fn completed_integrator_step(&mut self) -> Res<(bool, bool)> {
        self.check_kind("fmi2CompletedIntegratorStep", Kind::ModelExchange)?;
        self.check(
            "fmi2CompletedIntegratorStep",
            mask::COMPLETED_INTEGRATOR_STEP,
        )?;
        let motions = self.motions();
        let o = self
            .outputs()
            .map_err(|e| format!("fmi2CompletedIntegratorStep: {e}"))?;
        let works = o
            .discs
            .iter()
            .zip(&motions)
            .any(|(d, (_, t))| d.work_on_rock(t, 1.0) != 0.0);
        if !works {
            // no work on the rock since the last event: the energy of the
            // next commit counts from here
            self.last_commit_time = self.time;
        }
        let step = self.values.kerf.real(vr::NUMERICS_SWEEP_STEP);
        Ok((self.event_indicator() <= EVENT_SLACK * step, false))
    }

    pub fn set_time(&mut self, t: f64) -> Res<Status> {
        self.check_kind("fmi2SetTime", Kind::ModelExchange)?;
        self.check("fmi2SetTime", mask::SET_TIME)?;
        if !t.is_finite() {
            return Err(format!("fmi2SetTime: time = {t} is not finite"));
        }
        self.time = t;
        Ok(Status::Ok)
    }

    pub fn no_states(&self, func: &str, m: u32, n: usize, what: &str) -> Res<Status> {
        self.check_kind(func, Kind::ModelExchange)?;
        self.check(func, m)?;
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
        let head_start = self.head_pose();
        let motions = self.motions();
        let twist = twist_of(&self.values.head_in);
        let head = self.head.as_mut().ok_or("fmi2DoStep: no head")?;
        let result = match self.drive {
            Drive::Head => head.advance_head(&head_start, &twist, h).map(|end| {
                self.cs_head = end;
            }),
            Drive::Discs => head.advance_discs(&motions, h).map(|ends| {
                self.cs_discs = ends;
            }),
        };
        match result {
            Ok(()) => {
                self.pose_set.iter_mut().for_each(|b| *b = false);
                self.time = t + h;
                self.cache = None;
                Ok(Status::Ok)
            }
            Err(e) => {
                self.mode = Error;
                Err(format!("fmi2DoStep(t = {t}, h = {h}) failed: {e}"))
            }
        }
    }

    pub fn last_successful_time(&self) -> f64 {
        self.time
    }

    // ---- FMU state ------------------------------------------------------

    pub fn snapshot(&self) -> HeadSnapshot {
        let keeps = !matches!(self.mode, Instantiated | InitializationMode);
        HeadSnapshot {
            kind: self.kind,
            mode: self.mode,
            values: self.values.clone(),
            start_time: self.start_time,
            time: self.time,
            last_commit_time: self.last_commit_time,
            event_committed: self.event_committed,
            cs_head: self.cs_head,
            cs_discs: self.cs_discs.clone(),
            pose_set: self.pose_set.clone(),
            head: if keeps {
                self.head.as_ref().map(Head::state)
            } else {
                None
            },
            encoded: OnceCell::new(),
        }
    }

    pub fn restore(&mut self, s: &HeadSnapshot) -> Res<Status> {
        if s.kind != self.kind {
            return Err(format!(
                "fmi2SetFMUstate: the state was taken from a {} instance, this one is {}",
                kind_name(s.kind),
                kind_name(self.kind)
            ));
        }
        if s.values.disc_par.len() != self.values.disc_par.len() {
            return Err("fmi2SetFMUstate: the state is for a head with another disc count".into());
        }
        let (head, key) = match &s.head {
            None => (None, None),
            Some(hs) => {
                let params = s
                    .values
                    .kerf
                    .params(self.resources.as_deref(), Files::MayBeMissing)
                    .map_err(|e| format!("fmi2SetFMUstate: {e}"))?;
                let key = (params, s.values.specs(), s.values.head_par);
                let reuse = self.head.is_some() && self.head_key.as_ref() == Some(&key);
                let mut head = if reuse {
                    self.head.take().unwrap()
                } else {
                    let mut p = key.0.clone();
                    p.rock.initial_surface.clear(); // the state holds the whole surface
                    Head::new(p, key.1.clone()).map_err(|e| format!("fmi2SetFMUstate: {e}"))?
                };
                if let Err(e) = head.set_state(hs) {
                    if reuse {
                        self.head = Some(head);
                    }
                    return Err(format!("fmi2SetFMUstate: {e}"));
                }
                (Some(head), Some(key))
            }
        };
        self.mode = s.mode;
        self.values = s.values.clone();
        self.start_time = s.start_time;
        self.time = s.time;
        self.last_commit_time = s.last_commit_time;
        self.event_committed = s.event_committed;
        self.cs_head = s.cs_head;
        self.cs_discs = s.cs_discs.clone();
        self.pose_set = s.pose_set.clone();
        self.head = head;
        self.head_key = key;
        self.cache = None;
        Ok(Status::Ok)
    }

    /// The serialized form of a snapshot of this head.
    pub fn encode(&self, s: &HeadSnapshot) -> Vec<u8> {
        let mut p = Vec::new();
        let put_f = |p: &mut Vec<u8>, x: f64| p.extend_from_slice(&x.to_le_bytes());
        let put_u = |p: &mut Vec<u8>, x: u64| p.extend_from_slice(&x.to_le_bytes());
        put_u(&mut p, self.guid.len() as u64);
        p.extend_from_slice(self.guid.as_bytes());
        p.push(match s.kind {
            Kind::ModelExchange => 0,
            Kind::CoSimulation => 1,
        });
        p.push(s.mode.to_u8());
        for x in [s.start_time, s.time, s.last_commit_time] {
            put_f(&mut p, x);
        }
        p.push(u8::from(s.event_committed));
        let v = &s.values;
        put_u(&mut p, v.kerf.real.len() as u64);
        v.kerf.real.iter().for_each(|&x| put_f(&mut p, x));
        put_u(&mut p, v.kerf.int.len() as u64);
        v.kerf
            .int
            .iter()
            .for_each(|&x| put_u(&mut p, x as i64 as u64));
        put_u(&mut p, v.kerf.boolean.len() as u64);
        v.kerf.boolean.iter().for_each(|&x| p.push(u8::from(x)));
        put_u(&mut p, v.kerf.string.len() as u64);
        for x in &v.kerf.string {
            put_u(&mut p, x.as_bytes().len() as u64);
            p.extend_from_slice(x.as_bytes());
        }
        v.head_in
            .iter()
            .chain(&v.head_par)
            .for_each(|&x| put_f(&mut p, x));
        put_u(&mut p, v.disc_par.len() as u64);
        for (a, b) in v.disc_par.iter().zip(&v.disc_in) {
            a.iter().chain(b.iter()).for_each(|&x| put_f(&mut p, x));
        }
        for q in std::iter::once(&s.cs_head).chain(&s.cs_discs) {
            for x in [
                q.position.x,
                q.position.y,
                q.position.z,
                q.yaw,
                q.pitch,
                q.roll,
            ] {
                put_f(&mut p, x);
            }
        }
        s.pose_set.iter().for_each(|&b| p.push(u8::from(b)));
        match &s.head {
            None => p.push(0),
            Some(h) => {
                p.push(1);
                let b = h.to_bytes();
                put_u(&mut p, b.len() as u64);
                p.extend_from_slice(&b);
            }
        }
        let mut out = Vec::with_capacity(p.len() + 28);
        out.extend_from_slice(STATE_MAGIC);
        out.extend_from_slice(&STATE_VERSION.to_le_bytes());
        out.extend_from_slice(&(p.len() as u64).to_le_bytes());
        out.extend_from_slice(&p);
        let sum = fnv1a64(&out);
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    /// Inverse of [`HeadInstance::encode`], for this head.
    pub fn decode(&self, bytes: &[u8]) -> Res<HeadSnapshot> {
        if bytes.len() < 28 || &bytes[..8] != STATE_MAGIC {
            return Err("not a kerf head FMU state".into());
        }
        let (body, sum) = bytes.split_at(bytes.len() - 8);
        if fnv1a64(body) != u64::from_le_bytes(sum.try_into().unwrap()) {
            return Err("checksum mismatch (corrupt state)".into());
        }
        let version = u32::from_le_bytes(body[8..12].try_into().unwrap());
        if version != STATE_VERSION {
            return Err(format!(
                "head state version {version}, this build reads {STATE_VERSION}"
            ));
        }
        let len = u64::from_le_bytes(body[12..20].try_into().unwrap());
        if len != (body.len() - 20) as u64 {
            return Err("length mismatch".into());
        }
        let mut r = Reader {
            b: &body[20..],
            at: 0,
        };
        let n = r.u64()? as usize;
        let guid = r.take(n)?;
        if guid != self.guid.as_bytes() {
            return Err("the state belongs to another FMU (GUID)".into());
        }
        let kind = match r.u8()? {
            0 => Kind::ModelExchange,
            1 => Kind::CoSimulation,
            _ => return Err("bad interface type".into()),
        };
        let mode = Mode::from_u8(r.u8()?)
            .filter(|m| m.fits(kind))
            .ok_or("bad mode")?;
        let (start_time, time, last_commit_time) = (r.f64()?, r.f64()?, r.f64()?);
        let event_committed = r.u8()? != 0;
        let mut values = self.start_values.clone();
        let expect = |r: &mut Reader, n: usize| -> Res<()> {
            if r.u64()? as usize != n {
                return Err("the state was saved by another build (value count)".into());
            }
            Ok(())
        };
        expect(&mut r, values.kerf.real.len())?;
        for x in values.kerf.real.iter_mut() {
            *x = r.f64()?;
        }
        expect(&mut r, values.kerf.int.len())?;
        for x in values.kerf.int.iter_mut() {
            *x = r.u64()? as i64 as i32;
        }
        expect(&mut r, values.kerf.boolean.len())?;
        for x in values.kerf.boolean.iter_mut() {
            *x = r.u8()? != 0;
        }
        expect(&mut r, values.kerf.string.len())?;
        for x in values.kerf.string.iter_mut() {
            let n = r.u64()? as usize;
            *x = CString::new(r.take(n)?.to_vec()).map_err(|_| "a string with NUL")?;
        }
        for x in values.head_in.iter_mut().chain(values.head_par.iter_mut()) {
            *x = r.f64()?;
        }
        expect(&mut r, values.disc_par.len())?;
        for (a, b) in values.disc_par.iter_mut().zip(values.disc_in.iter_mut()) {
            for x in a.iter_mut().chain(b.iter_mut()) {
                *x = r.f64()?;
            }
        }
        let mut poses = Vec::with_capacity(values.disc_par.len() + 1);
        for _ in 0..=values.disc_par.len() {
            let q = [r.f64()?, r.f64()?, r.f64()?, r.f64()?, r.f64()?, r.f64()?];
            poses.push(Pose::new(q[0], q[1], q[2], q[3], q[4], q[5]));
        }
        let mut pose_set = self.pose_set.clone();
        for b in pose_set.iter_mut() {
            *b = r.u8()? != 0;
        }
        let head = match r.u8()? {
            0 => None,
            1 => {
                let n = r.u64()? as usize;
                let blob = r.take(n)?;
                let params = values
                    .kerf
                    .params(self.resources.as_deref(), Files::MayBeMissing)?;
                Some(
                    HeadState::from_bytes(blob, &params, values.disc_par.len())
                        .map_err(|e| e.to_string())?,
                )
            }
            _ => return Err("bad head flag".into()),
        };
        if r.at != r.b.len() {
            return Err("trailing bytes".into());
        }
        let cs_head = poses[0];
        Ok(HeadSnapshot {
            kind,
            mode,
            values,
            start_time,
            time,
            last_commit_time,
            event_committed,
            cs_head,
            cs_discs: poses[1..].to_vec(),
            pose_set,
            head,
            encoded: OnceCell::new(),
        })
    }
}

const STATE_MAGIC: &[u8; 8] = b"KERFHFMU";
const STATE_VERSION: u32 = 1;

/// The head manifest in `resources`, if this FMU is a head: (guid, drive,
/// layout).
pub fn head_manifest(resources: Option<&Path>) -> Option<Res<(String, Drive, Layout)>> {
    let path = resources?.join("head.json");
    let text = std::fs::read_to_string(&path).ok()?;
    Some(head_md::read_manifest(&text, &path.display().to_string()))
}

//! One generic FMI 2.0 instance for every kind of kerf FMU, in the style of
//! modelica/Reference-FMUs: [`Fmi`] is the state machine (modes, masks,
//! time), the get/set rules (causality, all-or-nothing), the Model Exchange
//! cut events (indicator, step-event flag, backstop time event), the
//! Co-Simulation step's checks and the FMU state's common part; each model
//! (the single disc of `instance.rs`, the cutterhead of `head.rs`) answers
//! the narrow [`FmuModel`] contract: its variables, its outputs, how far it
//! travelled since its last cut, how it commits, steps and saves itself.
//!
//! Safe Rust only; the C boundary is `api.rs` and `head_dispatch.rs`.

use std::cell::OnceCell;
use std::ffi::{CStr, CString};
use std::path::Path;

use super::log::{Category, Logger, Status};
use super::machine::{
    check_kind, check_mode, kind_name, mask, mode_name, EventInfo, Kind, LogSwitches, Mode, Res,
    EVENT_SLACK, TIME_EVENT_SWEEPS, TIME_TOLERANCE,
};
use super::md::Causality;
use crate::core::error::Compact;

use Mode::*;

/// The FMI type class of a value reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Class {
    Real,
    /// Integer or Enumeration.
    Integer,
    Boolean,
    String,
}

impl Class {
    /// "a Real", ... (for "{vr} is not the value reference of ...").
    fn article(self) -> &'static str {
        match self {
            Class::Real => "a Real",
            Class::Integer => "an Integer or Enumeration",
            Class::Boolean => "a Boolean",
            Class::String => "a String",
        }
    }
}

/// What the generic layer needs to know of one variable.
#[derive(Debug, Clone, Copy)]
pub struct VarInfo<'a> {
    pub name: &'a str,
    pub causality: Causality,
    /// The items of an Enumeration.
    pub items: Option<&'static [i32]>,
}

/// Where the instance stands, for a model's outputs and motions.
#[derive(Debug, Clone, Copy)]
pub struct Ctx {
    pub kind: Kind,
    pub mode: Mode,
}

impl Ctx {
    /// Co-Simulation after initialization: the poses reached by the last
    /// step stand unless the host set pose inputs since.
    pub fn cs_after_step(self) -> bool {
        self.kind == Kind::CoSimulation && !matches!(self.mode, Instantiated | InitializationMode)
    }
}

/// A Co-Simulation step that did not happen.
pub enum StepError {
    /// Refused before it started ("fmi2DoStep: {msg}").
    Refused(String),
    /// Failed while cutting ("fmi2DoStep(t = .., h = ..) failed: {msg}").
    Failed(String),
}

/// The instance's part of a captured FMU state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Header {
    pub kind: Kind,
    pub mode: Mode,
    pub start_time: f64,
    pub time: f64,
    pub last_commit_time: f64,
    pub event_committed: bool,
}

impl Header {
    /// The whole state: this instance part with the model's part.
    pub fn with<S>(self, model: S) -> Snapshot<S> {
        Snapshot {
            header: self,
            model,
            encoded: OnceCell::new(),
        }
    }
}

/// A captured FMU state: the instance's part and the model's.
pub struct Snapshot<S> {
    pub header: Header,
    pub model: S,
    /// The serialized form, made on demand (fmi2SerializedFMUstateSize).
    pub encoded: OnceCell<Vec<u8>>,
}

/// What a kerf model answers to the generic instance. Error strings are
/// the part after "fmi2Function: " (or "fmi2GetReal(name): ").
pub trait FmuModel {
    /// The model's part of a captured FMU state.
    type State;

    // ---- variables ----
    fn var(&self, class: Class, vr: u32) -> Option<VarInfo<'_>>;
    /// A known Real (an output is computed for `cx`).
    fn get_real(&mut self, cx: Ctx, vr: u32) -> Res<f64>;
    fn get_integer(&mut self, cx: Ctx, vr: u32) -> Res<i32>;
    fn get_boolean(&mut self, cx: Ctx, vr: u32) -> Res<bool>;
    /// Owned by the model until it is set again, reset or freed.
    fn get_string(&self, vr: u32) -> &CStr;
    /// Sets a known, settable, checked value.
    fn set_real(&mut self, vr: u32, v: f64);
    fn set_integer(&mut self, vr: u32, v: i32);
    fn set_boolean(&mut self, vr: u32, v: bool);
    fn set_string(&mut self, vr: u32, v: CString);

    // ---- life cycle ----
    /// Builds the core model from the parameters unless it was built from
    /// the same; returns its warnings.
    fn build(&mut self) -> Res<Vec<String>>;
    /// At fmi2ExitInitializationMode: the Co-Simulation poses start at the
    /// inputs, the outputs are computed anew.
    fn begin(&mut self);
    /// fmi2Reset: the start values, no core model.
    fn reset(&mut self);
    /// `rock.finalSurface` of the built core ("" when unset or not built).
    fn final_surface(&self) -> String;
    /// Writes the core's rock surface to `path`.
    fn write_surface(&self, path: &Path) -> Res<()>;
    /// Log text of a committed cut ("rock cut committed").
    const COMMITTED: &'static str;
    /// Log text of fmi2ExitInitializationMode ("initialized").
    const INITIALIZED: &'static str;
    /// A failed Co-Simulation step leaves the instance in the error state.
    const FATAL_STEP_FAILURE: bool;

    // ---- Model Exchange ----
    /// `numberOfEventIndicators` (1: the cut event).
    const EVENT_INDICATORS: usize;
    /// `numerics.sweepStep`.
    fn sweep_step(&self) -> f64;
    /// Is the core model built?
    fn has_core(&self) -> bool;
    /// The largest rim travel (pose) since the last cut to the inputs now;
    /// `None` before the first cut (or without a core model).
    fn travel_since_cut(&self) -> Option<f64>;
    /// The largest rim speed of spin about an axle now.
    fn spin_speed(&self) -> f64;
    /// The largest rim speed now, pose or spin.
    fn rim_speed(&self) -> f64;
    /// Commits the cut(s) at the inputs, `dt` after the last commit
    /// (all or nothing); whether the rock changed.
    fn commit(&mut self, dt: f64) -> Res<bool>;
    /// Does the model do work on the rock now?
    fn works(&mut self, cx: Ctx) -> Res<bool>;

    // ---- Co-Simulation ----
    /// Moves for `h` seconds from where the last step ended (or the pose
    /// inputs set since), cutting.
    fn advance(&mut self, cx: Ctx, h: f64) -> Result<(), StepError>;

    // ---- FMU state ----
    /// `core`: whether the core's state is kept (after initialization).
    fn state(&self, core: bool) -> Self::State;
    /// Replaces the model's part by `s`; on error nothing changed.
    fn restore(&mut self, s: &Self::State) -> Res<()>;
    fn encode(&self, s: &Snapshot<Self::State>) -> Vec<u8>;
    fn decode(&self, bytes: &[u8]) -> Res<Snapshot<Self::State>>;
}

/// One FMU instance: the FMI 2.0 state machine over a model `M`.
pub struct Fmi<M> {
    pub(crate) name: CString,
    pub(crate) kind: Kind,
    pub(crate) logger: Logger,
    log_on: LogSwitches,
    pub(crate) mode: Mode,
    pub(crate) start_time: f64,
    pub(crate) time: f64,
    /// Model Exchange: time of the last commit of the rock.
    pub(crate) last_commit_time: f64,
    /// Model Exchange: the rock was committed in this event.
    pub(crate) event_committed: bool,
    /// `fmi2SetContinuousStates` has warned of a host's dummy state.
    dummy_state_warned: std::cell::Cell<bool>,
    /// An event has warned that it came before the last commit.
    past_event_warned: bool,
    pub(crate) model: M,
}

impl<M: FmuModel> Fmi<M> {
    pub fn with_model(
        name: CString,
        kind: Kind,
        logger: Logger,
        logging_on: bool,
        model: M,
    ) -> Self {
        Self {
            name,
            kind,
            logger,
            log_on: LogSwitches::new(logging_on),
            mode: Instantiated,
            start_time: 0.0,
            time: 0.0,
            last_commit_time: 0.0,
            event_committed: false,
            dummy_state_warned: std::cell::Cell::new(false),
            past_event_warned: false,
            model,
        }
    }

    fn cx(&self) -> Ctx {
        Ctx {
            kind: self.kind,
            mode: self.mode,
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

    pub fn log_warning(&self, msg: &str) {
        self.log(Status::Warning, Category::Warning, msg);
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
                return Err(format!(
                    "fmi2SetupExperiment: stopTime = {} is not a finite time >= startTime = {}",
                    Compact(stop),
                    Compact(start)
                ));
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

    pub fn exit_initialization_mode(&mut self) -> Res<Status> {
        self.check("fmi2ExitInitializationMode", mask::EXIT_INITIALIZATION_MODE)?;
        let warnings = self
            .model
            .build()
            .map_err(|e| format!("fmi2ExitInitializationMode: {e}"))?;
        for w in &warnings {
            self.log_warning(w);
        }
        self.last_commit_time = self.time;
        self.model.begin();
        self.event_committed = false;
        self.mode = match self.kind {
            Kind::ModelExchange => EventMode,
            Kind::CoSimulation => StepComplete,
        };
        self.log_event(|| format!("{} at t = {}", M::INITIALIZED, self.time));
        Ok(if warnings.is_empty() {
            Status::Ok
        } else {
            Status::Warning
        })
    }

    pub fn terminate(&mut self) -> Res<Status> {
        self.check("fmi2Terminate", mask::TERMINATE)?;
        let path = self.model.final_surface();
        if !path.is_empty() {
            self.model
                .write_surface(Path::new(&path))
                .map_err(|e| format!("fmi2Terminate: writing rock.finalSurface: {e}"))?;
            self.log_event(|| format!("rock surface written to {path}"));
        }
        // after the file: a refused write leaves the instance as it was
        self.mode = Terminated;
        Ok(Status::Ok)
    }

    pub fn reset(&mut self) -> Res<Status> {
        self.check("fmi2Reset", mask::ANY)?;
        self.mode = Instantiated;
        self.start_time = 0.0;
        self.time = 0.0;
        self.last_commit_time = 0.0;
        self.event_committed = false;
        self.model.reset();
        Ok(Status::Ok)
    }

    // ---- values -------------------------------------------------------

    fn var(&self, func: &str, class: Class, r: u32) -> Res<VarInfo<'_>> {
        self.model.var(class, r).ok_or_else(|| {
            format!(
                "{func}: {r} is not the value reference of {}",
                class.article()
            )
        })
    }

    /// "fmi2GetReal(name): e" for an output that could not be computed.
    fn named(&self, func: &str, class: Class, r: u32, e: String) -> String {
        let name = self.model.var(class, r).map_or("", |v| v.name);
        format!("{func}({name}): {e}")
    }

    /// fmi2Get{Real,Integer,Boolean}: `get` gives one value (an output is
    /// computed; its error is named after the variable).
    fn get<T>(
        &mut self,
        func: &str,
        class: Class,
        vrs: &[u32],
        out: &mut [T],
        get: fn(&mut M, Ctx, u32) -> Res<T>,
    ) -> Res<Status> {
        self.check(func, mask::GET)?;
        let cx = self.cx();
        for (o, &r) in out.iter_mut().zip(vrs) {
            self.var(func, class, r)?;
            *o = get(&mut self.model, cx, r).map_err(|e| self.named(func, class, r, e))?;
        }
        Ok(Status::Ok)
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Res<Status> {
        self.get("fmi2GetReal", Class::Real, vrs, out, M::get_real)
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> Res<Status> {
        self.get("fmi2GetInteger", Class::Integer, vrs, out, M::get_integer)
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> Res<Status> {
        self.get("fmi2GetBoolean", Class::Boolean, vrs, out, M::get_boolean)
    }

    /// The strings stay owned by the instance (valid until they are set again
    /// or the instance is reset or freed, as FMI 2.0 allows).
    pub fn get_string(&mut self, vrs: &[u32], out: &mut [*const std::ffi::c_char]) -> Res<Status> {
        const F: &str = "fmi2GetString";
        self.check(F, mask::GET)?;
        for (o, &r) in out.iter_mut().zip(vrs) {
            self.var(F, Class::String, r)?;
            *o = self.model.get_string(r).as_ptr();
        }
        Ok(Status::Ok)
    }

    /// May a variable of this causality be set now?
    fn settable(&self, func: &str, v: &VarInfo, continuous: bool) -> Res<()> {
        match v.causality {
            Causality::Parameter => {
                if matches!(self.mode, Instantiated | InitializationMode) {
                    Ok(())
                } else {
                    Err(format!(
                        "{func}: parameter {} is fixed: it can only be set before fmi2ExitInitializationMode (now in {})",
                        v.name,
                        self.mode_name()
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

    /// fmi2Set{Real,Integer,Boolean}, all-or-nothing: checks every value
    /// first (`ok`: the value's own check), then sets them with `set` (two
    /// passes over the host's arrays: nothing is allocated from `nvr`).
    #[allow(clippy::too_many_arguments)]
    fn set<T: Copy>(
        &mut self,
        func: &str,
        mask: u32,
        class: Class,
        vrs: &[u32],
        vals: &[T],
        ok: fn(&str, &VarInfo, T) -> Res<()>,
        set: fn(&mut M, u32, T),
    ) -> Res<Status> {
        self.check(func, mask)?;
        for (&r, &x) in vrs.iter().zip(vals) {
            let v = self.var(func, class, r)?;
            // only Reals are continuous inputs
            self.settable(func, &v, class == Class::Real)?;
            ok(func, &v, x)?;
        }
        for (&r, &x) in vrs.iter().zip(vals) {
            set(&mut self.model, r, x);
        }
        Ok(Status::Ok)
    }

    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Res<Status> {
        let finite = |f: &str, v: &VarInfo, x: f64| {
            if x.is_finite() {
                Ok(())
            } else {
                Err(format!(
                    "{f}: {} = {x} is not finite; the value was not set",
                    v.name
                ))
            }
        };
        let (m, c) = (mask::SET_REAL, Class::Real);
        self.set("fmi2SetReal", m, c, vrs, vals, finite, M::set_real)
    }

    pub fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status> {
        let item = |f: &str, v: &VarInfo, x: i32| match v.items {
            Some(items) if !items.contains(&x) => Err(format!(
                "{f}: {} = {x} is not an item of its enumeration {items:?}",
                v.name
            )),
            _ => Ok(()),
        };
        let (m, c) = (mask::SET_OTHER, Class::Integer);
        self.set("fmi2SetInteger", m, c, vrs, vals, item, M::set_integer)
    }

    /// `vals`: fmi2Boolean values (0 is false).
    pub fn set_boolean(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status> {
        let any = |_: &str, _: &VarInfo, _: i32| Ok(());
        let set = |m: &mut M, r: u32, x: i32| m.set_boolean(r, x != 0);
        let (m, c) = (mask::SET_OTHER, Class::Boolean);
        self.set("fmi2SetBoolean", m, c, vrs, vals, any, set)
    }

    /// `val(k)`: the k-th value (`None`: the host passed NULL).
    pub fn set_string<'a>(
        &mut self,
        vrs: &[u32],
        val: &dyn Fn(usize) -> Option<&'a CStr>,
    ) -> Res<Status> {
        const F: &str = "fmi2SetString";
        self.check(F, mask::SET_OTHER)?;
        for (k, &r) in vrs.iter().enumerate() {
            let v = self.var(F, Class::String, r)?;
            self.settable(F, &v, false)?;
            let x = val(k).ok_or_else(|| format!("{F}: the value of {} is NULL", v.name))?;
            if x.to_str().is_err() {
                return Err(format!("{F}: the value of {} is not UTF-8", v.name));
            }
        }
        for (k, &r) in vrs.iter().enumerate() {
            if let Some(x) = val(k) {
                self.model.set_string(r, x.to_owned());
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
    /// that the energy must book); for several discs, the largest. Evaluated
    /// without changing anything; `sweepStep` itself before the first cut.
    pub fn event_indicator(&self) -> f64 {
        let step = self.model.sweep_step();
        let Some(travel) = self.model.travel_since_cut() else {
            return step;
        };
        let spin = self.model.spin_speed() * (self.time - self.last_commit_time);
        step - travel.max(spin)
    }

    pub fn get_event_indicators(&self, out: &mut [f64]) -> Res<Status> {
        const F: &str = "fmi2GetEventIndicators";
        self.check_kind(F, Kind::ModelExchange)?;
        self.check(F, mask::GET_EVENT_INDICATORS)?;
        if out.len() != M::EVENT_INDICATORS {
            return Err(format!(
                "{F}: ni = {}, but the model has {}",
                out.len(),
                M::EVENT_INDICATORS
            ));
        }
        out[0] = self.event_indicator();
        Ok(Status::Ok)
    }

    /// Commits the cut of the current inputs (the rock, the energy since the
    /// last commit), once per event.
    fn commit_cut(&mut self, func: &str) -> Res<()> {
        if self.event_committed {
            return Ok(());
        }
        let dt = self.time - self.last_commit_time;
        if dt < 0.0 {
            // An event before the last commit: PyFMI 2.21 with Assimulo's
            // ExplicitEuler, when a state event fell just before the stop
            // time, goes back to the event before for one more (H6). The
            // rock already holds the later cut, and a negative interval has
            // no work to book: nothing is committed (refusing it stopped the
            // host's run).
            if !std::mem::replace(&mut self.past_event_warned, true) {
                self.log_warning(&format!(
                    "{func}: an event at t = {} comes before the last commit (t = {}); \
                     nothing is committed (the rock holds the later cut; said once)",
                    self.time, self.last_commit_time
                ));
            }
            self.event_committed = true;
            return Ok(());
        }
        // the commit is all or nothing: on error the instance is as it was
        let changed = self.model.commit(dt).map_err(|e| format!("{func}: {e}"))?;
        self.last_commit_time = self.time;
        self.event_committed = true;
        if changed {
            self.log_event(|| format!("t = {}: {} (dt = {dt})", self.time, M::COMMITTED));
        }
        Ok(())
    }

    /// The backstop time event (see [`TIME_EVENT_SWEEPS`]): when the fastest
    /// rim, at the current speed, will have travelled that many sweep steps
    /// since the last cut. None when nothing moves. If the speed changes the
    /// time is only early (an event that commits a shorter path) or late (the
    /// commit cuts the longer path in sweep-step sub-steps): the cuts stay on
    /// the path either way.
    fn backstop_event_time(&self) -> Option<f64> {
        let step = self.model.sweep_step();
        let speed = self.model.rim_speed();
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

    /// Commits the cut of the current inputs, once per event.
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
        const F: &str = "fmi2EnterContinuousTimeMode";
        self.check_kind(F, Kind::ModelExchange)?;
        self.check(F, mask::ENTER_CONTINUOUS_TIME_MODE)?;
        // A host that skipped fmi2NewDiscreteStates in the initial event:
        // the event indicator counts from the first cut, so make it now.
        if self.model.has_core() && self.model.travel_since_cut().is_none() {
            self.commit_cut(F)?;
        }
        self.mode = ContinuousTimeMode;
        Ok(Status::Ok)
    }

    /// Returns (enterEventMode, terminateSimulation).
    pub fn completed_integrator_step(&mut self) -> Res<(bool, bool)> {
        const F: &str = "fmi2CompletedIntegratorStep";
        self.check_kind(F, Kind::ModelExchange)?;
        self.check(F, mask::COMPLETED_INTEGRATOR_STEP)?;
        let cx = self.cx();
        let works = self.model.works(cx).map_err(|e| format!("{F}: {e}"))?;
        if !works {
            // no work on the rock since the last event: the energy of the
            // next commit counts from here
            self.last_commit_time = self.time;
        }
        // An event once per sweep step of travel, not once per solver step:
        // the indicator's zero crossing, which hosts locate themselves, or
        // this step ending on it (a fixed step that travels one sweep step).
        let step = self.model.sweep_step();
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

    /// `fmi2SetContinuousStates`: as [`Fmi::no_states`], but one value is
    /// ignored. fmusim-rs 0.8.0's CVode gives a model without states a
    /// one-element dummy state vector and sets it at every call of its root
    /// function (host bug H1, docs/hosts.md); one value where the model has
    /// none carries nothing, so it passes, with one warning an instance.
    pub fn set_continuous_states(&self, nx: usize) -> Res<Status> {
        const F: &str = "fmi2SetContinuousStates";
        if nx != 1 {
            return self.no_states(F, mask::SET_CONTINUOUS_STATES, nx, "nx");
        }
        self.no_states(F, mask::SET_CONTINUOUS_STATES, 0, "nx")?;
        if !self.dummy_state_warned.replace(true) {
            self.log_warning(&format!(
                "{F}: nx = 1, but the model has no continuous states; the value is \
                 ignored (a host's dummy state; said once)"
            ));
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
        let cx = self.cx();
        match self.model.advance(cx, h) {
            Ok(()) => {
                self.time = t + h;
                self.log_event(|| format!("fmi2DoStep: t = {t}, h = {h} done"));
                Ok(Status::Ok)
            }
            Err(StepError::Refused(e)) => Err(format!("fmi2DoStep: {e}")),
            // the step is all or nothing: the instance is as it was (a
            // shorter step may follow), unless the model says otherwise
            Err(StepError::Failed(e)) => {
                if M::FATAL_STEP_FAILURE {
                    self.mode = Error;
                }
                Err(format!("fmi2DoStep(t = {t}, h = {h}) failed: {e}"))
            }
        }
    }

    pub fn last_successful_time(&self) -> f64 {
        self.time
    }

    // ---- FMU state ------------------------------------------------------

    pub fn snapshot(&self) -> Snapshot<M::State> {
        let core = !matches!(self.mode, Instantiated | InitializationMode);
        Header {
            kind: self.kind,
            mode: self.mode,
            start_time: self.start_time,
            time: self.time,
            last_commit_time: self.last_commit_time,
            event_committed: self.event_committed,
        }
        .with(self.model.state(core))
    }

    /// Replaces the whole state by `s`; on error nothing changed.
    pub fn restore(&mut self, s: &Snapshot<M::State>) -> Res<Status> {
        let h = &s.header;
        if h.kind != self.kind {
            return Err(format!(
                "fmi2SetFMUstate: the state was taken from a {} instance, this one is {}",
                kind_name(h.kind),
                kind_name(self.kind)
            ));
        }
        self.model
            .restore(&s.model)
            .map_err(|e| format!("fmi2SetFMUstate: {e}"))?;
        self.mode = h.mode;
        self.start_time = h.start_time;
        self.time = h.time;
        self.last_commit_time = h.last_commit_time;
        self.event_committed = h.event_committed;
        Ok(Status::Ok)
    }

    /// The serialized form of `s` (made once, kept in the snapshot).
    pub fn encoded<'s>(&self, s: &'s Snapshot<M::State>) -> &'s [u8] {
        s.encoded.get_or_init(|| self.model.encode(s))
    }

    pub fn decode(&self, bytes: &[u8]) -> Res<Snapshot<M::State>> {
        self.model.decode(bytes)
    }
}

/// fmi2SetFMUstate's core: the current one (`current`, built from
/// `current_key`) when it was built from the same `key` as the state's, else
/// a new one from `build`; `set` then gives it the state. On error the
/// current core stays where it was.
pub fn restore_core<C, K: PartialEq>(
    current: &mut Option<C>,
    current_key: Option<&K>,
    key: &K,
    build: impl FnOnce() -> Res<C>,
    set: impl FnOnce(&mut C) -> Res<()>,
) -> Res<C> {
    let reuse = current.is_some() && current_key == Some(key);
    let mut core = if reuse {
        current.take().unwrap()
    } else {
        build()?
    };
    if let Err(e) = set(&mut core) {
        if reuse {
            *current = Some(core);
        }
        return Err(e);
    }
    Ok(core)
}

//! What every kerf FMU instance (one disc or a cutterhead) shares of the
//! FMI 2.0 machinery: the log-category switches and the state-machine checks.

use super::log::Category;
use super::md;

/// On/off per log category of `md::LOG_CATEGORIES`.
#[derive(Debug, Clone)]
pub struct LogSwitches(Vec<bool>);

impl LogSwitches {
    /// Errors and warnings always on; the rest as `fmi2Instantiate`'s
    /// `loggingOn` says.
    pub fn new(logging_on: bool) -> Self {
        Self(
            md::LOG_CATEGORIES
                .iter()
                .map(|c| match *c {
                    "logStatusError" | "logStatusWarning" => true,
                    _ => logging_on,
                })
                .collect(),
        )
    }

    pub fn enabled(&self, cat: Category) -> bool {
        let name = cat.name();
        md::LOG_CATEGORIES
            .iter()
            .position(|c| *c == name)
            .is_some_and(|i| self.0[i])
    }

    /// `fmi2SetDebugLogging`: all categories when `categories` is empty or
    /// names `logAll`; an unknown name changes nothing and is an error.
    pub fn set(&mut self, on: bool, categories: &[String]) -> Res<()> {
        if categories.is_empty() {
            self.0.iter_mut().for_each(|b| *b = on);
            return Ok(());
        }
        let mut idx = Vec::new();
        for c in categories {
            match md::LOG_CATEGORIES.iter().position(|k| k == c) {
                Some(i) => idx.push(i),
                None => {
                    return Err(format!(
                        "fmi2SetDebugLogging: unknown log category \"{c}\" (known: {})",
                        md::LOG_CATEGORIES.join(", ")
                    ))
                }
            }
        }
        for i in idx {
            if md::LOG_CATEGORIES[i] == "logAll" {
                self.0.iter_mut().for_each(|b| *b = on);
            } else {
                self.0[i] = on;
            }
        }
        Ok(())
    }
}

/// Is `func` allowed in `mode` (`mask`: the modes it is allowed in)?
pub fn check_mode(mode: Mode, func: &str, mask: u32) -> Res<()> {
    if mode.bit() & mask != 0 {
        Ok(())
    } else {
        Err(format!(
            "{func}: illegal call sequence: not allowed in {}",
            mode_name(mode)
        ))
    }
}

/// Is `func`, which only `want` instances may call, allowed in a `have` one?
pub fn check_kind(have: Kind, func: &str, want: Kind) -> Res<()> {
    if have == want {
        Ok(())
    } else {
        Err(format!(
            "{func}: only for {} instances; this one was instantiated for {}",
            kind_name(want),
            kind_name(have)
        ))
    }
}

pub fn mode_name(mode: Mode) -> &'static str {
    use Mode::*;
    match mode {
        Instantiated => "the instantiated state",
        InitializationMode => "initialization mode",
        EventMode => "event mode",
        ContinuousTimeMode => "continuous-time mode",
        StepComplete => "the step-complete state",
        Terminated => "the terminated state",
        Error => "the error state (call fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance)",
    }
}

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
pub const TIME_TOLERANCE: f64 = 1e-9;

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

/// What fmi2NewDiscreteStates reports.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EventInfo {
    pub new_discrete_states_needed: bool,
    pub terminate_simulation: bool,
    pub nominals_changed: bool,
    pub values_changed: bool,
    pub next_event_time: Option<f64>,
}

pub fn kind_name(k: Kind) -> &'static str {
    match k {
        Kind::ModelExchange => "Model Exchange",
        Kind::CoSimulation => "Co-Simulation",
    }
}

//! One binary, two kinds of FMU: kerf.fmu's single-disc instance and the
//! cutterhead's, both the generic [`Fmi`] over their model. `api.rs` talks
//! to either through [`Component`]; `fmi2Instantiate` picks the kind by the
//! GUID (kerf's, or the one in a head FMU's `resources/head.json`).

use std::any::Any;
use std::ffi::{c_char, CStr};

use super::generic::{Fmi, FmuModel, Snapshot};
use super::instance::{EventInfo, Kind, Mode, Res};
use super::log::Status;

/// A captured FMU state of either kind: a [`Snapshot`] of the instance's
/// model type, checked by type when it is set again.
pub struct AnySnapshot {
    kind: Kind,
    snap: Box<dyn Any + Send>,
}

impl AnySnapshot {
    pub fn kind(&self) -> Kind {
        self.kind
    }
}

/// The FMI calls of an instance, as `api.rs` makes them.
pub trait Component {
    fn set_error_mode(&mut self);
    fn check(&self, func: &str, mask: u32) -> Res<()>;
    fn check_kind(&self, func: &str, kind: Kind) -> Res<()>;
    fn log_error(&self, msg: &str);
    /// Logs `msg` at status Warning (category `logStatusWarning`).
    fn log_warning(&self, msg: &str);
    fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Res<Status>;
    fn setup_experiment(&mut self, tol: Option<f64>, start: f64, stop: Option<f64>) -> Res<Status>;
    fn enter_initialization_mode(&mut self) -> Res<Status>;
    fn exit_initialization_mode(&mut self) -> Res<Status>;
    fn terminate(&mut self) -> Res<Status>;
    fn reset(&mut self) -> Res<Status>;
    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Res<Status>;
    fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> Res<Status>;
    fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> Res<Status>;
    fn get_string(&mut self, vrs: &[u32], out: &mut [*const c_char]) -> Res<Status>;
    fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Res<Status>;
    fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status>;
    fn set_boolean(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status>;
    /// `val(k)`: the k-th value (`None`: the host passed NULL).
    fn set_string<'a>(
        &mut self,
        vrs: &[u32],
        val: &dyn Fn(usize) -> Option<&'a CStr>,
    ) -> Res<Status>;
    fn get_event_indicators(&self, out: &mut [f64]) -> Res<Status>;
    fn snapshot(&self) -> AnySnapshot;
    fn restore(&mut self, s: &AnySnapshot) -> Res<Status>;
    /// The serialized form of `s` (made once, kept in the snapshot).
    fn encoded<'s>(&self, s: &'s AnySnapshot) -> Res<&'s [u8]>;
    fn decode(&self, bytes: &[u8]) -> Res<AnySnapshot>;
    fn enter_event_mode(&mut self) -> Res<Status>;
    fn new_discrete_states(&mut self) -> Res<EventInfo>;
    fn enter_continuous_time_mode(&mut self) -> Res<Status>;
    fn completed_integrator_step(&mut self) -> Res<(bool, bool)>;
    fn set_time(&mut self, t: f64) -> Res<Status>;
    fn no_states(&self, func: &str, mask: u32, n: usize, what: &str) -> Res<Status>;
    fn set_continuous_states(&self, nx: usize) -> Res<Status>;
    fn do_step(&mut self, t: f64, h: f64) -> Res<Status>;
    fn last_successful_time(&self) -> f64;
}

const WRONG_KIND: &str = "the FMU state was taken from another kind of FMU (single disc / head)";

/// Every kerf instance, whatever its model.
impl<M> Component for Fmi<M>
where
    M: FmuModel,
    M::State: Send + 'static,
{
    fn set_error_mode(&mut self) {
        self.mode = Mode::Error;
    }
    fn check(&self, func: &str, mask: u32) -> Res<()> {
        Self::check(self, func, mask)
    }
    fn check_kind(&self, func: &str, kind: Kind) -> Res<()> {
        Self::check_kind(self, func, kind)
    }
    fn log_warning(&self, msg: &str) {
        Self::log_warning(self, msg)
    }
    fn log_error(&self, msg: &str) {
        Self::log_error(self, msg)
    }
    fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Res<Status> {
        Self::set_debug_logging(self, on, categories)
    }
    fn setup_experiment(&mut self, tol: Option<f64>, start: f64, stop: Option<f64>) -> Res<Status> {
        Self::setup_experiment(self, tol, start, stop)
    }
    fn enter_initialization_mode(&mut self) -> Res<Status> {
        Self::enter_initialization_mode(self)
    }
    fn exit_initialization_mode(&mut self) -> Res<Status> {
        Self::exit_initialization_mode(self)
    }
    fn terminate(&mut self) -> Res<Status> {
        Self::terminate(self)
    }
    fn reset(&mut self) -> Res<Status> {
        Self::reset(self)
    }
    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Res<Status> {
        Self::get_real(self, vrs, out)
    }
    fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> Res<Status> {
        Self::get_integer(self, vrs, out)
    }
    fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> Res<Status> {
        Self::get_boolean(self, vrs, out)
    }
    fn get_string(&mut self, vrs: &[u32], out: &mut [*const c_char]) -> Res<Status> {
        Self::get_string(self, vrs, out)
    }
    fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Res<Status> {
        Self::set_real(self, vrs, vals)
    }
    fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status> {
        Self::set_integer(self, vrs, vals)
    }
    fn set_boolean(&mut self, vrs: &[u32], vals: &[i32]) -> Res<Status> {
        Self::set_boolean(self, vrs, vals)
    }
    fn set_string<'a>(
        &mut self,
        vrs: &[u32],
        val: &dyn Fn(usize) -> Option<&'a CStr>,
    ) -> Res<Status> {
        Self::set_string(self, vrs, val)
    }
    fn get_event_indicators(&self, out: &mut [f64]) -> Res<Status> {
        Self::get_event_indicators(self, out)
    }
    fn snapshot(&self) -> AnySnapshot {
        AnySnapshot {
            kind: self.kind,
            snap: Box::new(Self::snapshot(self)),
        }
    }
    fn restore(&mut self, s: &AnySnapshot) -> Res<Status> {
        match s.snap.downcast_ref::<Snapshot<M::State>>() {
            Some(s) => Self::restore(self, s),
            None => Err(format!("fmi2SetFMUstate: {WRONG_KIND}")),
        }
    }
    fn encoded<'s>(&self, s: &'s AnySnapshot) -> Res<&'s [u8]> {
        match s.snap.downcast_ref::<Snapshot<M::State>>() {
            Some(s) => Ok(Self::encoded(self, s)),
            None => Err(WRONG_KIND.into()),
        }
    }
    fn decode(&self, bytes: &[u8]) -> Res<AnySnapshot> {
        let s = Self::decode(self, bytes)?;
        Ok(AnySnapshot {
            kind: s.header.kind,
            snap: Box::new(s),
        })
    }
    fn enter_event_mode(&mut self) -> Res<Status> {
        Self::enter_event_mode(self)
    }
    fn new_discrete_states(&mut self) -> Res<EventInfo> {
        Self::new_discrete_states(self)
    }
    fn enter_continuous_time_mode(&mut self) -> Res<Status> {
        Self::enter_continuous_time_mode(self)
    }
    fn completed_integrator_step(&mut self) -> Res<(bool, bool)> {
        Self::completed_integrator_step(self)
    }
    fn set_time(&mut self, t: f64) -> Res<Status> {
        Self::set_time(self, t)
    }
    fn no_states(&self, func: &str, mask: u32, n: usize, what: &str) -> Res<Status> {
        Self::no_states(self, func, mask, n, what)
    }
    fn set_continuous_states(&self, nx: usize) -> Res<Status> {
        Self::set_continuous_states(self, nx)
    }
    fn do_step(&mut self, t: f64, h: f64) -> Res<Status> {
        Self::do_step(self, t, h)
    }
    fn last_successful_time(&self) -> f64 {
        Self::last_successful_time(self)
    }
}

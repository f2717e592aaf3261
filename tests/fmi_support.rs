//! Helpers for the in-process FMI tests: an instance wrapper that calls the
//! exported `fmi2...` functions through the rlib, and a logger that captures
//! the messages per instance name.
//!
//! The logger is fmi-sys's C variadic handler (`callback_logger_handler`,
//! which formats with `vsnprintf`, exactly like a C host), forwarding to the
//! `log` crate; a process-wide `log::Log` records (instance, level, message).
//! Each test uses its own instance names, so tests can run in parallel.
//!
//! Included by the other `fmi_*.rs` tests with `#[path]`; it has no tests itself.
// FMU states are opaque handles made by the FMU; the helpers pass them on.
#![allow(dead_code, clippy::not_unsafe_ptr_arg_deref)]

use std::ffi::{c_char, CStr, CString};
use std::ptr;
use std::sync::{Mutex, Once};

use fmi_sys::fmi2::*;
use kerf::fmi2 as f;
use kerf::fmi2::md;

pub use md::vr;

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;

#[derive(Debug, Clone)]
pub struct Message {
    pub instance: String,
    pub level: log::Level,
    pub text: String,
}

struct Capture(Mutex<Vec<Message>>);

impl log::Log for Capture {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, r: &log::Record) {
        if r.module_path() == Some("logger") {
            self.0.lock().unwrap().push(Message {
                instance: r.target().to_string(),
                level: r.level(),
                text: r.args().to_string(),
            });
        }
    }
    fn flush(&self) {}
}

static CAPTURE: Capture = Capture(Mutex::new(Vec::new()));
static INIT: Once = Once::new();

fn install_logger() {
    INIT.call_once(|| {
        log::set_logger(&CAPTURE).expect("another logger is installed");
        log::set_max_level(log::LevelFilter::Trace);
    });
}

/// Messages logged so far by the instance named `name`.
pub fn messages_of(name: &str) -> Vec<Message> {
    CAPTURE
        .0
        .lock()
        .unwrap()
        .iter()
        .filter(|m| m.instance == name)
        .cloned()
        .collect()
}

pub fn callbacks() -> fmi2CallbackFunctions {
    fmi2CallbackFunctions {
        logger: Some(fmi_sys::fmi2::logger::callback_logger_handler),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: ptr::null_mut(),
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Me,
    Cs,
}

/// One FMU instance, freed on drop.
pub struct Fmu {
    pub c: fmi2Component,
    pub name: String,
    pub kind: Kind,
}

// The component is only used by one thread at a time (moved, not shared).
unsafe impl Send for Fmu {}

pub fn instantiate_raw(name: &str, kind: Kind, guid: &str, logging_on: bool) -> fmi2Component {
    instantiate_at(name, kind, guid, logging_on, None)
}

/// As a host does it: `resources` is the `file://` URI of the resources folder.
pub fn instantiate_at(
    name: &str,
    kind: Kind,
    guid: &str,
    logging_on: bool,
    resources: Option<&str>,
) -> fmi2Component {
    install_logger();
    let res_c = resources.map(|r| CString::new(r).unwrap());
    let res_p = res_c.as_ref().map_or(ptr::null(), |r| r.as_ptr());
    let name_c = CString::new(name).unwrap();
    let guid_c = CString::new(guid).unwrap();
    let cb = callbacks();
    let t = match kind {
        Kind::Me => fmi2Type_fmi2ModelExchange,
        Kind::Cs => fmi2Type_fmi2CoSimulation,
    };
    unsafe {
        f::fmi2Instantiate(
            name_c.as_ptr(),
            t,
            guid_c.as_ptr(),
            res_p,
            &cb,
            0,
            logging_on.into(),
        )
    }
}

impl Fmu {
    pub fn new(name: &str, kind: Kind) -> Self {
        let c = instantiate_raw(name, kind, md::GUID, false);
        assert!(
            !c.is_null(),
            "fmi2Instantiate failed: {:?}",
            messages_of(name)
        );
        Self {
            c,
            name: name.to_string(),
            kind,
        }
    }

    pub fn messages(&self) -> Vec<Message> {
        messages_of(&self.name)
    }

    /// The error messages so far.
    pub fn errors(&self) -> Vec<String> {
        self.messages()
            .into_iter()
            .filter(|m| m.level == log::Level::Error)
            .map(|m| m.text)
            .collect()
    }

    /// The last error message, which must exist.
    pub fn last_error(&self) -> String {
        self.errors().pop().expect("an error message was logged")
    }

    pub fn setup(&self, start: f64) -> fmi2Status {
        unsafe { f::fmi2SetupExperiment(self.c, 0, 0.0, start, 0, 0.0) }
    }
    pub fn enter_init(&self) -> fmi2Status {
        unsafe { f::fmi2EnterInitializationMode(self.c) }
    }
    pub fn exit_init(&self) -> fmi2Status {
        unsafe { f::fmi2ExitInitializationMode(self.c) }
    }
    /// Setup, enter and exit initialization, all expected to succeed.
    pub fn init(&self) {
        assert_eq!(self.setup(0.0), OK);
        assert_eq!(self.enter_init(), OK);
        assert_eq!(self.exit_init(), OK, "{:?}", self.errors());
    }
    pub fn terminate(&self) -> fmi2Status {
        unsafe { f::fmi2Terminate(self.c) }
    }
    pub fn reset(&self) -> fmi2Status {
        unsafe { f::fmi2Reset(self.c) }
    }

    pub fn set_reals(&self, vrs: &[u32], vals: &[f64]) -> fmi2Status {
        assert_eq!(vrs.len(), vals.len());
        unsafe { f::fmi2SetReal(self.c, vrs.as_ptr(), vrs.len(), vals.as_ptr()) }
    }
    pub fn set_real(&self, vr: u32, v: f64) -> fmi2Status {
        self.set_reals(&[vr], &[v])
    }
    pub fn get_reals(&self, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
        let mut out = vec![f64::NAN; vrs.len()];
        let s = unsafe { f::fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out)
    }
    /// One Real, which must be readable.
    pub fn real(&self, vr: u32) -> f64 {
        let (s, v) = self.get_reals(&[vr]);
        assert_eq!(s, OK, "fmi2GetReal({vr}): {:?}", self.errors());
        v[0]
    }
    pub fn set_int(&self, vr: u32, v: i32) -> fmi2Status {
        unsafe { f::fmi2SetInteger(self.c, &vr, 1, &v) }
    }
    pub fn get_int(&self, vr: u32) -> (fmi2Status, i32) {
        let mut v = -12345;
        let s = unsafe { f::fmi2GetInteger(self.c, &vr, 1, &mut v) };
        (s, v)
    }
    pub fn get_bool(&self, vr: u32) -> (fmi2Status, bool) {
        let mut v = -1;
        let s = unsafe { f::fmi2GetBoolean(self.c, &vr, 1, &mut v) };
        (s, v != 0)
    }
    pub fn set_string(&self, vr: u32, v: &str) -> fmi2Status {
        let v = CString::new(v).unwrap();
        let p: *const c_char = v.as_ptr();
        unsafe { f::fmi2SetString(self.c, &vr, 1, &p) }
    }
    pub fn get_string(&self, vr: u32) -> (fmi2Status, String) {
        let mut p: fmi2String = ptr::null();
        let s = unsafe { f::fmi2GetString(self.c, &vr, 1, &mut p) };
        let v = if p.is_null() {
            String::new()
        } else {
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        };
        (s, v)
    }

    pub fn do_step(&self, t: f64, h: f64) -> fmi2Status {
        unsafe { f::fmi2DoStep(self.c, t, h, 0) }
    }

    pub fn set_time(&self, t: f64) -> fmi2Status {
        unsafe { f::fmi2SetTime(self.c, t) }
    }
    pub fn enter_event_mode(&self) -> fmi2Status {
        unsafe { f::fmi2EnterEventMode(self.c) }
    }
    pub fn enter_ct_mode(&self) -> fmi2Status {
        unsafe { f::fmi2EnterContinuousTimeMode(self.c) }
    }
    pub fn new_discrete_states(&self) -> (fmi2Status, fmi2EventInfo) {
        let mut e = fmi2EventInfo {
            newDiscreteStatesNeeded: 7,
            ..Default::default()
        };
        let s = unsafe { f::fmi2NewDiscreteStates(self.c, &mut e) };
        (s, e)
    }
    /// (status, enterEventMode, terminateSimulation)
    pub fn completed_integrator_step(&self) -> (fmi2Status, bool, bool) {
        let (mut enter, mut term) = (-1, -1);
        let s = unsafe { f::fmi2CompletedIntegratorStep(self.c, 1, &mut enter, &mut term) };
        (s, enter != 0, term != 0)
    }
    /// The event iteration of a host: NewDiscreteStates until none is needed,
    /// then back to continuous-time mode.
    pub fn event_iteration(&self) {
        self.event_iteration_next();
    }
    /// fmi2GetEventIndicators with `ni` (the array holds at least one).
    pub fn event_indicators(&self, ni: usize) -> (fmi2Status, Vec<f64>) {
        let mut z = vec![f64::NAN; ni.max(1)];
        let s = unsafe { f::fmi2GetEventIndicators(self.c, z.as_mut_ptr(), ni) };
        (s, z)
    }
    /// The one event indicator, which must be readable.
    pub fn event_indicator(&self) -> f64 {
        let (s, z) = self.event_indicators(1);
        assert_eq!(s, OK, "{:?}", self.errors());
        z[0]
    }
    /// [`Fmu::event_iteration`]; returns nextEventTime.
    pub fn event_iteration_next(&self) -> Option<f64> {
        let next = loop {
            let (s, e) = self.new_discrete_states();
            assert_eq!(s, OK, "{:?}", self.errors());
            if e.newDiscreteStatesNeeded == 0 {
                break (e.nextEventTimeDefined != 0).then_some(e.nextEventTime);
            }
        };
        assert_eq!(self.enter_ct_mode(), OK);
        next
    }

    pub fn get_state(&self) -> fmi2FMUstate {
        let mut s: fmi2FMUstate = ptr::null_mut();
        assert_eq!(
            unsafe { f::fmi2GetFMUstate(self.c, &mut s) },
            OK,
            "{:?}",
            self.errors()
        );
        assert!(!s.is_null());
        s
    }
    pub fn set_state(&self, s: fmi2FMUstate) -> fmi2Status {
        unsafe { f::fmi2SetFMUstate(self.c, s) }
    }
    pub fn free_state(&self, mut s: fmi2FMUstate) {
        assert_eq!(unsafe { f::fmi2FreeFMUstate(self.c, &mut s) }, OK);
        assert!(s.is_null());
    }
    pub fn serialize(&self, s: fmi2FMUstate) -> Vec<u8> {
        let mut n = 0usize;
        assert_eq!(
            unsafe { f::fmi2SerializedFMUstateSize(self.c, s, &mut n) },
            OK
        );
        let mut buf = vec![0u8; n];
        assert_eq!(
            unsafe { f::fmi2SerializeFMUstate(self.c, s, buf.as_mut_ptr().cast(), n) },
            OK
        );
        buf
    }
    pub fn deserialize(&self, bytes: &[u8]) -> (fmi2Status, fmi2FMUstate) {
        let mut s: fmi2FMUstate = ptr::null_mut();
        let st = unsafe {
            f::fmi2DeSerializeFMUstate(self.c, bytes.as_ptr().cast(), bytes.len(), &mut s)
        };
        (st, s)
    }

    pub fn set_debug_logging(&self, on: bool, cats: &[&str]) -> fmi2Status {
        let owned: Vec<CString> = cats.iter().map(|c| CString::new(*c).unwrap()).collect();
        let ptrs: Vec<fmi2String> = owned.iter().map(|c| c.as_ptr()).collect();
        unsafe { f::fmi2SetDebugLogging(self.c, on.into(), ptrs.len(), ptrs.as_ptr()) }
    }

    /// A small rock face (cheap to build and copy): 0.4 m x 0.1 m, 2 mm cells.
    pub fn small_rock(&self) {
        let s = self.set_reals(
            &[
                vr::ROCK_X_MIN,
                vr::ROCK_X_MAX,
                vr::ROCK_Y_MIN,
                vr::ROCK_Y_MAX,
            ],
            &[-0.1, 0.3, -0.05, 0.05],
        );
        assert_eq!(s, OK);
        assert_eq!(self.set_int(vr::ROCK_NX, 201), OK);
        assert_eq!(self.set_int(vr::ROCK_NY, 51), OK);
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { f::fmi2FreeInstance(self.c) };
    }
}

/// Every Real output's value reference.
pub fn real_outputs() -> Vec<u32> {
    md::REALS
        .iter()
        .filter(|v| v.causality == md::Causality::Output)
        .map(|v| v.vr)
        .collect()
}

/// Radius of the default cutter.
pub const R: f64 = 0.2159;

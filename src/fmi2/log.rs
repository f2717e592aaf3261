//! The host's logger callback, and the guard that keeps panics inside the FMU.

use std::cell::{Cell, RefCell};
use std::ffi::{CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;

use fmi_sys::fmi2::{
    fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2Status_fmi2Discard,
    fmi2Status_fmi2Error, fmi2Status_fmi2OK, fmi2Status_fmi2Warning,
};

/// The statuses the FMU returns (never `fmi2Pending`: steps are synchronous;
/// never `fmi2Fatal`: instances share nothing that an error could corrupt).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok,
    Warning,
    Discard,
    Error,
}

impl Status {
    pub fn raw(self) -> fmi2Status {
        match self {
            Status::Ok => fmi2Status_fmi2OK,
            Status::Warning => fmi2Status_fmi2Warning,
            Status::Discard => fmi2Status_fmi2Discard,
            Status::Error => fmi2Status_fmi2Error,
        }
    }
}

/// The log categories of modelDescription.xml the FMU sends under.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Category {
    Events,
    Warning,
    Error,
}

impl Category {
    pub fn name(self) -> &'static str {
        match self {
            Category::Events => "logEvents",
            Category::Warning => "logStatusWarning",
            Category::Error => "logStatusError",
        }
    }

    fn cstr(self) -> &'static CStr {
        match self {
            Category::Events => c"logEvents",
            Category::Warning => c"logStatusWarning",
            Category::Error => c"logStatusError",
        }
    }
}

/// The logger of `fmi2CallbackFunctions`, with its component environment.
pub struct Logger {
    callback: fmi2CallbackLogger,
    env: fmi2ComponentEnvironment,
}

impl Logger {
    pub fn new(callback: fmi2CallbackLogger, env: fmi2ComponentEnvironment) -> Self {
        Self { callback, env }
    }

    /// Sends `msg` to the host. The message is always an argument of the
    /// fixed format "%s", so a `%` in it is printed, not interpreted.
    pub fn emit(&self, instance: &CStr, status: Status, category: Category, msg: &str) {
        let Some(cb) = self.callback else { return };
        let msg = CString::new(msg.replace('\0', " ")).unwrap_or_default();
        // SAFETY: `cb` is the host's logger from fmi2Instantiate, which the
        // standard requires to stay callable for the instance's lifetime; every
        // pointer passed is a NUL-terminated string that outlives the call; the
        // format "%s" consumes exactly the one variadic argument given, a
        // `const char*`.
        unsafe {
            cb(
                self.env,
                instance.as_ptr(),
                status.raw(),
                category.cstr().as_ptr(),
                c"%s".as_ptr(),
                msg.as_ptr(),
            );
        }
    }
}

thread_local! {
    /// How many FMI calls are running on this thread (calls may nest through
    /// the host's logger).
    static IN_FMI: Cell<u32> = const { Cell::new(0) };
    /// The message of the last panic inside an FMI call on this thread.
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

static HOOK: Once = Once::new();

/// Runs `f`, catching a panic and returning its message. While an FMI call
/// runs, the panic hook records the message instead of printing it to
/// stderr (an FMU prints nothing); outside FMI calls the previous hook runs
/// as before. The hook is installed once per process: it is the only
/// process-wide state of the FMU, and it holds no instance data.
pub fn guarded<R>(f: impl FnOnce() -> R) -> Result<R, String> {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if IN_FMI.with(Cell::get) > 0 {
                LAST_PANIC.with(|p| *p.borrow_mut() = Some(info.to_string()));
            } else {
                previous(info);
            }
        }));
    });
    IN_FMI.with(|d| d.set(d.get() + 1));
    let r = catch_unwind(AssertUnwindSafe(f));
    IN_FMI.with(|d| d.set(d.get() - 1));
    r.map_err(|payload| {
        LAST_PANIC
            .with(|p| p.borrow_mut().take())
            .unwrap_or_else(|| {
                payload
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "panic".into())
            })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_an_error_message() {
        let r = guarded(|| -> u32 { panic!("boom {}", 42) });
        let msg = r.unwrap_err();
        assert!(msg.contains("boom 42"), "{msg}");
        assert!(msg.contains("log.rs"), "the location is kept: {msg}");
        assert_eq!(guarded(|| 7), Ok(7));
        // Nested guards (a host logger calling back into the FMU) keep working.
        let r = guarded(|| guarded(|| -> u32 { panic!("inner") }).unwrap_err());
        assert!(r.unwrap().contains("inner"));
        assert_eq!(IN_FMI.with(Cell::get), 0);
    }
}

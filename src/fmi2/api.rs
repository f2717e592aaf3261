//! The 44 functions of FMI 2.0, exported with their C names.
//!
//! Every function: checks its pointers, runs inside [`guarded`] (a panic
//! becomes `fmi2Error` plus a logger message and puts the instance in the
//! error state), delegates to the safe [`Instance`] methods, and logs their
//! error message through the host's logger. Each signature is checked against
//! fmi-sys's `fmi2...TYPE` at compile time.
//!
//! Safety contract of every function (hence no per-function `# Safety`
//! section): the caller keeps the FMI 2.0 rules, i.e. `c` is a component
//! returned by `fmi2Instantiate` and not yet freed, used by one thread at a
//! time, and each array argument points to at least as many elements as its
//! length argument says (or is NULL, which the FMU rejects). A component or
//! FMU state pointer that was not made by this FMU is detected by a magic
//! number in most cases, but cannot be detected in all.
#![allow(clippy::missing_safety_doc, non_snake_case)]

use std::collections::BTreeMap;
use std::ffi::{c_char, c_void, CStr};
use std::ptr;
use std::sync::Mutex;

use fmi_sys::fmi2::*;

use super::head::{head_manifest, HeadInstance};
use super::head_dispatch::{AnySnapshot, Component};
use super::instance::{mask, resource_dir, Instance, Kind, Res};
use super::log::{guarded, Category, Logger, Status};
use super::md;

const INSTANCE_MAGIC: u64 = u64::from_le_bytes(*b"kerfInst");
const STATE_MAGIC: u64 = u64::from_le_bytes(*b"kerfStat");

/// What an `fmi2Component` points to.
struct InstanceBox {
    magic: u64,
    /// kerf.fmu's single-disc instance or a cutterhead instance.
    inst: Box<dyn Component>,
}

/// What an `fmi2FMUstate` points to.
struct StateBox {
    magic: u64,
    snap: AnySnapshot,
}

/// The instance behind `c`, if `c` looks like one of ours.
///
/// # Safety
/// `c` is NULL or a pointer from `fmi2Instantiate` that was not freed yet and
/// that no other thread uses during the call (FMI 2.0 rules).
unsafe fn instance<'a>(c: fmi2Component) -> Option<&'a mut InstanceBox> {
    let b = c.cast::<InstanceBox>();
    if b.is_null() || !b.is_aligned() {
        return None;
    }
    // SAFETY: by the contract above, `b` points to a live InstanceBox that
    // this call may use exclusively.
    let b = unsafe { &mut *b };
    (b.magic == INSTANCE_MAGIC).then_some(b)
}

/// Every FMU state this library made and has not freed yet (its address),
/// with the instance that made it: fmi2FreeInstance frees what its instance
/// left, and a pointer that is not here (freed, forged) is never read.
static STATES: Mutex<BTreeMap<usize, usize>> = Mutex::new(BTreeMap::new());

fn states() -> std::sync::MutexGuard<'static, BTreeMap<usize, usize>> {
    // the map stays consistent whatever panicked while it was held
    STATES.lock().unwrap_or_else(|e| e.into_inner())
}

/// A new FMU state owned by instance `c`.
fn new_state(c: fmi2Component, snap: AnySnapshot) -> fmi2FMUstate {
    let p = Box::into_raw(Box::new(StateBox {
        magic: STATE_MAGIC,
        snap,
    }));
    states().insert(p as usize, c as usize);
    p.cast::<c_void>()
}

/// Frees an FMU state made by [`new_state`] (and not freed since).
fn free_state(s: fmi2FMUstate) {
    if states().remove(&(s as usize)).is_some() {
        // SAFETY: it was in STATES, so it came from Box::into_raw in
        // `new_state` and was not freed (removal from STATES is the free).
        let mut b = unsafe { Box::from_raw(s.cast::<StateBox>()) };
        b.magic = 0;
    }
}

/// How many FMU states instance `c` made that are not freed yet (for tests
/// of fmi2FreeInstance; `c` is only compared, never read).
#[doc(hidden)]
pub fn fmu_states_of(c: fmi2Component) -> usize {
    states().values().filter(|&&o| o == c as usize).count()
}

/// The snapshot behind `s`, if it is a live one of ours.
///
/// # Safety
/// No other thread frees `s` during the call (FMI 2.0 rules).
unsafe fn snapshot<'a>(s: fmi2FMUstate) -> Option<&'a mut StateBox> {
    let b = s.cast::<StateBox>();
    if b.is_null() || !b.is_aligned() || !states().contains_key(&(s as usize)) {
        return None;
    }
    // SAFETY: by the contract above, `b` points to a live StateBox.
    let b = unsafe { &mut *b };
    (b.magic == STATE_MAGIC).then_some(b)
}

/// `n` elements at `p` (any pointer, even NULL, when `n` is 0).
///
/// # Safety
/// If `n > 0` and `p` is not NULL, `p` points to `n` initialized elements that
/// stay valid and unaliased by writes for `'a`.
unsafe fn input<'a, T>(p: *const T, n: usize, func: &str, what: &str) -> Res<&'a [T]> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() || !p.is_aligned() {
        return Err(format!("{func}: {what} is NULL or misaligned"));
    }
    // SAFETY: non-null, aligned, and the host guarantees `n` elements.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// `n` writable elements at `p`.
///
/// # Safety
/// As [`input`], and the elements are writable and not otherwise referenced.
unsafe fn output<'a, T>(p: *mut T, n: usize, func: &str, what: &str) -> Res<&'a mut [T]> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() || !p.is_aligned() {
        return Err(format!("{func}: {what} is NULL or misaligned"));
    }
    // SAFETY: non-null, aligned, and the host guarantees `n` writable elements.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// One writable element at `p`.
///
/// # Safety
/// `p` is NULL or points to a writable `T`.
unsafe fn out_one<'a, T>(p: *mut T, func: &str, what: &str) -> Res<&'a mut T> {
    if p.is_null() || !p.is_aligned() {
        return Err(format!("{func}: {what} is NULL or misaligned"));
    }
    // SAFETY: non-null and aligned; the host guarantees a writable `T`.
    Ok(unsafe { &mut *p })
}

/// A C string argument.
///
/// # Safety
/// `p` is NULL or a NUL-terminated string valid for the call.
unsafe fn c_str<'a>(p: *const c_char) -> Option<&'a CStr> {
    // SAFETY: non-null pointers are NUL-terminated strings by the contract.
    (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) })
}

/// Runs `f` on the instance behind `c` with the panic guard; logs its error.
fn with(
    c: fmi2Component,
    func: &str,
    f: impl FnOnce(&mut dyn Component) -> Res<Status>,
) -> fmi2Status {
    // SAFETY: `c` comes from the host under the FMI 2.0 contract (module docs).
    let Some(b) = (unsafe { instance(c) }) else {
        return Status::Error.raw();
    };
    match guarded(|| f(b.inst.as_mut())) {
        Ok(Ok(s)) => s.raw(),
        Ok(Err(msg)) => {
            b.inst.log_error(&msg);
            Status::Error.raw()
        }
        Err(panic) => {
            // The instance may be half-updated: only reset, restore or free are safe now.
            b.inst.set_error_mode();
            b.inst.log_error(&format!(
                "{func}: internal error, the instance is now in the error state: {panic}"
            ));
            Status::Error.raw()
        }
    }
}

fn kind_check(i: &dyn Component, func: &str, kind: Kind) -> Res<()> {
    i.check_kind(func, kind)
}

// ---------------------------------------------------------------------------
// Common functions
// ---------------------------------------------------------------------------

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}
const _: fmi2GetTypesPlatformTYPE = Some(fmi2GetTypesPlatform);

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}
const _: fmi2GetVersionTYPE = Some(fmi2GetVersion);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2SetDebugLogging";
    with(c, F, |i| {
        // SAFETY: `categories` has `nCategories` entries (FMI contract).
        let cats = unsafe { input(categories, nCategories, F, "categories") }?;
        // grows with what is read, never sized from nCategories
        let mut names = Vec::new();
        for &p in cats {
            // SAFETY: each entry is NULL or a NUL-terminated string.
            let s = unsafe { c_str(p) }.ok_or_else(|| format!("{F}: a category is NULL"))?;
            names.push(s.to_string_lossy().into_owned());
        }
        i.set_debug_logging(loggingOn != 0, &names)
    })
}
const _: fmi2SetDebugLoggingTYPE = Some(fmi2SetDebugLogging);

#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let _ = visible; // no user interface
    let made = guarded(|| -> Option<fmi2Component> {
        if functions.is_null() || !functions.is_aligned() {
            return None; // no logger to tell
        }
        // SAFETY: non-null, aligned; the host passes a valid struct.
        let f = unsafe { &*functions };
        let logger = Logger::new(f.logger, f.componentEnvironment);
        // SAFETY: NULL or NUL-terminated strings (FMI contract).
        let (name, guid, location) = unsafe {
            (
                c_str(instanceName),
                c_str(fmuGUID),
                c_str(fmuResourceLocation),
            )
        };
        let fail = |who: &CStr, msg: String| {
            logger.emit(
                who,
                Status::Error,
                Category::Error,
                &format!("fmi2Instantiate: {msg}"),
            );
            None
        };
        let Some(name) = name else {
            return fail(c"kerf", "instanceName is NULL".into());
        };
        if let Some(why) = super::cpu::unsupported() {
            return fail(name, why);
        }
        let kind = match fmuType {
            x if x == fmi2Type_fmi2ModelExchange => Kind::ModelExchange,
            x if x == fmi2Type_fmi2CoSimulation => Kind::CoSimulation,
            other => return fail(name, format!("unknown fmuType {other}")),
        };
        let resources = resource_dir(location.and_then(|l| l.to_str().ok()));
        let inst: Box<dyn Component> = match guid.map(CStr::to_bytes) {
            Some(g) if g == md::GUID.as_bytes() => Box::new(Instance::new(
                name.to_owned(),
                kind,
                Logger::new(f.logger, f.componentEnvironment),
                resources,
                loggingOn != 0,
            )),
            Some(g) => match head_manifest(resources.as_deref()) {
                // a cutterhead FMU: its GUID and layout are in resources/head.json
                Some(Ok((head_guid, drive, layout))) if g == head_guid.as_bytes() => {
                    match HeadInstance::new(
                        name.to_owned(),
                        kind,
                        Logger::new(f.logger, f.componentEnvironment),
                        resources,
                        loggingOn != 0,
                        head_guid,
                        &layout,
                        drive,
                    ) {
                        Ok(h) => Box::new(h),
                        Err(e) => return fail(name, e),
                    }
                }
                Some(Err(e)) => return fail(name, format!("head FMU resources: {e}")),
                _ => {
                    return fail(
                        name,
                        format!(
                            "GUID {} does not match this binary's {} (modelDescription.xml from another build?)",
                            String::from_utf8_lossy(g),
                            md::GUID
                        ),
                    )
                }
            },
            None => return fail(name, "fmuGUID is NULL".into()),
        };
        let b = Box::new(InstanceBox {
            magic: INSTANCE_MAGIC,
            inst,
        });
        Some(Box::into_raw(b).cast::<c_void>())
    });
    made.ok().flatten().unwrap_or(ptr::null_mut())
}
const _: fmi2InstantiateTYPE = Some(fmi2Instantiate);

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    // SAFETY: `c` is NULL or a live component (FMI contract); after this call
    // the host never uses it again, so taking the Box back is sound.
    if let Some(b) = unsafe { instance(c) } {
        b.magic = 0;
        // FMI 2.0: the instance frees everything it allocated, the FMU
        // states the host did not free included
        let left: Vec<usize> = states()
            .iter()
            .filter(|(_, &owner)| owner == c as usize)
            .map(|(&s, _)| s)
            .collect();
        let _ = guarded(|| left.into_iter().for_each(|s| free_state(s as fmi2FMUstate)));
        // SAFETY: made by Box::into_raw in fmi2Instantiate; `b` is not used after this.
        let b = unsafe { Box::from_raw(b as *mut InstanceBox) };
        let _ = guarded(move || drop(b));
    }
}
const _: fmi2FreeInstanceTYPE = Some(fmi2FreeInstance);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    with(c, "fmi2SetupExperiment", |i| {
        i.setup_experiment(
            (toleranceDefined != 0).then_some(tolerance),
            startTime,
            (stopTimeDefined != 0).then_some(stopTime),
        )
    })
}
const _: fmi2SetupExperimentTYPE = Some(fmi2SetupExperiment);

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2EnterInitializationMode", |i| {
        i.enter_initialization_mode()
    })
}
const _: fmi2EnterInitializationModeTYPE = Some(fmi2EnterInitializationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2ExitInitializationMode", |i| {
        i.exit_initialization_mode()
    })
}
const _: fmi2ExitInitializationModeTYPE = Some(fmi2ExitInitializationMode);

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2Terminate", |i| i.terminate())
}
const _: fmi2TerminateTYPE = Some(fmi2Terminate);

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2Reset", |i| i.reset())
}
const _: fmi2ResetTYPE = Some(fmi2Reset);

// ---------------------------------------------------------------------------
// Getting and setting values
// ---------------------------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetReal";
    with(c, F, |i| {
        // SAFETY: `vr` and `value` have `nvr` elements (FMI contract).
        let (vrs, out) = unsafe { (input(vr, nvr, F, "vr")?, output(value, nvr, F, "value")?) };
        i.get_real(vrs, out)
    })
}
const _: fmi2GetRealTYPE = Some(fmi2GetReal);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2GetInteger";
    with(c, F, |i| {
        // SAFETY: `vr` and `value` have `nvr` elements (FMI contract).
        let (vrs, out) = unsafe { (input(vr, nvr, F, "vr")?, output(value, nvr, F, "value")?) };
        i.get_integer(vrs, out)
    })
}
const _: fmi2GetIntegerTYPE = Some(fmi2GetInteger);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2GetBoolean";
    with(c, F, |i| {
        // SAFETY: `vr` and `value` have `nvr` elements (FMI contract).
        let (vrs, out) = unsafe { (input(vr, nvr, F, "vr")?, output(value, nvr, F, "value")?) };
        // in chunks on the stack: nothing is allocated from `nvr`
        let mut tmp = [false; 64];
        for (vrs, out) in vrs.chunks(64).zip(out.chunks_mut(64)) {
            i.get_boolean(vrs, &mut tmp[..vrs.len()])?;
            for (o, &b) in out.iter_mut().zip(&tmp) {
                *o = fmi2Boolean::from(b);
            }
        }
        Ok(Status::Ok)
    })
}
const _: fmi2GetBooleanTYPE = Some(fmi2GetBoolean);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2GetString";
    with(c, F, |i| {
        // SAFETY: `vr` and `value` have `nvr` elements (FMI contract).
        let (vrs, out) = unsafe { (input(vr, nvr, F, "vr")?, output(value, nvr, F, "value")?) };
        i.get_string(vrs, out)
    })
}
const _: fmi2GetStringTYPE = Some(fmi2GetString);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2SetReal";
    with(c, F, |i| {
        // SAFETY: `vr` and `value` have `nvr` elements (FMI contract).
        let (vrs, vals) = unsafe { (input(vr, nvr, F, "vr")?, input(value, nvr, F, "value")?) };
        i.set_real(vrs, vals)
    })
}
const _: fmi2SetRealTYPE = Some(fmi2SetReal);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2SetInteger";
    with(c, F, |i| {
        // SAFETY: `vr` and `value` have `nvr` elements (FMI contract).
        let (vrs, vals) = unsafe { (input(vr, nvr, F, "vr")?, input(value, nvr, F, "value")?) };
        i.set_integer(vrs, vals)
    })
}
const _: fmi2SetIntegerTYPE = Some(fmi2SetInteger);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2SetBoolean";
    with(c, F, |i| {
        // SAFETY: `vr` and `value` have `nvr` elements (FMI contract).
        let (vrs, vals) = unsafe { (input(vr, nvr, F, "vr")?, input(value, nvr, F, "value")?) };
        i.set_boolean(vrs, vals)
    })
}
const _: fmi2SetBooleanTYPE = Some(fmi2SetBoolean);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2SetString";
    with(c, F, |i| {
        // SAFETY: `vr` and `value` have `nvr` elements (FMI contract).
        let (vrs, vals) = unsafe { (input(vr, nvr, F, "vr")?, input(value, nvr, F, "value")?) };
        // SAFETY: each entry is NULL or a NUL-terminated string.
        i.set_string(vrs, &|k| unsafe { c_str(vals[k]) })
    })
}
const _: fmi2SetStringTYPE = Some(fmi2SetString);

// ---------------------------------------------------------------------------
// FMU state
// ---------------------------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2GetFMUstate";
    with(c, F, |i| {
        i.check(F, mask::ANY)?;
        // SAFETY: `FMUstate` points to one writable fmi2FMUstate.
        let slot = unsafe { out_one(FMUstate, F, "FMUstate") }?;
        let snap = i.snapshot();
        if slot.is_null() {
            *slot = new_state(c, snap);
        } else {
            // FMI 2.0: a non-NULL state from an earlier call is overwritten.
            // SAFETY: non-null states come from this FMU (FMI contract).
            let b = unsafe { snapshot(*slot) }
                .ok_or_else(|| format!("{F}: *FMUstate is not an FMU state of kerf"))?;
            b.snap = snap;
        }
        Ok(Status::Ok)
    })
}
const _: fmi2GetFMUstateTYPE = Some(fmi2GetFMUstate);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    const F: &str = "fmi2SetFMUstate";
    with(c, F, |i| {
        i.check(F, mask::ANY)?;
        // SAFETY: the state comes from this FMU and is still allocated (FMI contract).
        let b = unsafe { snapshot(FMUstate) }
            .ok_or_else(|| format!("{F}: FMUstate is NULL or not an FMU state of kerf"))?;
        i.restore(&b.snap)
    })
}
const _: fmi2SetFMUstateTYPE = Some(fmi2SetFMUstate);

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2FreeFMUstate";
    with(c, F, |i| {
        i.check(F, mask::ANY)?;
        // fmusim 0.0.39 (Reference-FMUs) frees the states of its FMU-state
        // files by passing the state itself, not the address of its
        // fmi2FMUstate (a host bug, docs/hosts.md). A pointer that is one of
        // this instance's live states is such a call: a host's own variable
        // never lies inside a state kerf allocated. It is freed as that
        // state, with a warning; the host's variable cannot be set to NULL.
        let itself: fmi2FMUstate = FMUstate.cast();
        if states().get(&(itself as usize)) == Some(&(c as usize)) {
            free_state(itself);
            i.log_warning(&format!(
                "{F}: FMUstate is an FMU state, not the address of one (FMI 2.0 \
                 passes a pointer to the host's fmi2FMUstate); freed that state, \
                 whose value the host still holds and must not use again"
            ));
            return Ok(Status::Ok);
        }
        // SAFETY: `FMUstate` points to one fmi2FMUstate.
        let slot = unsafe { out_one(FMUstate, F, "FMUstate") }?;
        if slot.is_null() {
            return Ok(Status::Ok);
        }
        // SAFETY: checked against the live states before it is read.
        unsafe { snapshot(*slot) }
            .ok_or_else(|| format!("{F}: *FMUstate is not a live FMU state of kerf"))?;
        free_state(*slot);
        *slot = ptr::null_mut();
        Ok(Status::Ok)
    })
}
const _: fmi2FreeFMUstateTYPE = Some(fmi2FreeFMUstate);

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializedFMUstateSize";
    with(c, F, |i| {
        i.check(F, mask::ANY)?;
        // SAFETY: state from this FMU; `size` points to a writable size_t.
        let b = unsafe { snapshot(FMUstate) }
            .ok_or_else(|| format!("{F}: FMUstate is NULL or not an FMU state of kerf"))?;
        let size = unsafe { out_one(size, F, "size") }?;
        *size = i.encoded(&b.snap)?.len();
        Ok(Status::Ok)
    })
}
const _: fmi2SerializedFMUstateSizeTYPE = Some(fmi2SerializedFMUstateSize);

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializeFMUstate";
    with(c, F, |i| {
        i.check(F, mask::ANY)?;
        // SAFETY: state from this FMU (FMI contract).
        let b = unsafe { snapshot(FMUstate) }
            .ok_or_else(|| format!("{F}: FMUstate is NULL or not an FMU state of kerf"))?;
        let bytes = i.encoded(&b.snap)?;
        if size < bytes.len() {
            return Err(format!(
                "{F}: size = {size}, but the state needs {} bytes (fmi2SerializedFMUstateSize)",
                bytes.len()
            ));
        }
        // SAFETY: the host provides `size` writable bytes.
        let out = unsafe {
            output(
                serializedState.cast::<u8>(),
                bytes.len(),
                F,
                "serializedState",
            )
        }?;
        out.copy_from_slice(bytes);
        Ok(Status::Ok)
    })
}
const _: fmi2SerializeFMUstateTYPE = Some(fmi2SerializeFMUstate);

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2DeSerializeFMUstate";
    with(c, F, |i| {
        i.check(F, mask::ANY)?;
        // SAFETY: `serializedState` has `size` bytes; `FMUstate` points to one
        // writable fmi2FMUstate, whose old value is not read.
        let (bytes, slot) = unsafe {
            (
                input(serializedState.cast::<u8>(), size, F, "serializedState")?,
                out_one(FMUstate, F, "FMUstate")?,
            )
        };
        let snap = i
            .decode(bytes)
            .map_err(|e| format!("{F}: state rejected: {e}"))?;
        kind_check(i, F, snap.kind()).map_err(|_| {
            format!("{F}: state rejected: it was taken from another interface type")
        })?;
        *slot = new_state(c, snap);
        Ok(Status::Ok)
    })
}
const _: fmi2DeSerializeFMUstateTYPE = Some(fmi2DeSerializeFMUstate);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetDirectionalDerivative";
    let _ = (
        vUnknown_ref,
        nUnknown,
        vKnown_ref,
        nKnown,
        dvKnown,
        dvUnknown,
    );
    with(c, F, |i| {
        i.check(F, mask::DIRECTIONAL_DERIVATIVE)?;
        Err(format!(
            "{F}: not provided (providesDirectionalDerivative=\"false\")"
        ))
    })
}
const _: fmi2GetDirectionalDerivativeTYPE = Some(fmi2GetDirectionalDerivative);

// ---------------------------------------------------------------------------
// Model Exchange
// ---------------------------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2EnterEventMode", |i| i.enter_event_mode())
}
const _: fmi2EnterEventModeTYPE = Some(fmi2EnterEventMode);

#[no_mangle]
pub unsafe extern "C" fn fmi2NewDiscreteStates(
    c: fmi2Component,
    fmi2eventInfo: *mut fmi2EventInfo,
) -> fmi2Status {
    const F: &str = "fmi2NewDiscreteStates";
    with(c, F, |i| {
        // SAFETY: `fmi2eventInfo` points to a writable fmi2EventInfo.
        let out = unsafe { out_one(fmi2eventInfo, F, "eventInfo") }?;
        let e = i.new_discrete_states()?;
        *out = fmi2EventInfo {
            newDiscreteStatesNeeded: e.new_discrete_states_needed.into(),
            terminateSimulation: e.terminate_simulation.into(),
            nominalsOfContinuousStatesChanged: e.nominals_changed.into(),
            valuesOfContinuousStatesChanged: e.values_changed.into(),
            nextEventTimeDefined: e.next_event_time.is_some().into(),
            nextEventTime: e.next_event_time.unwrap_or(0.0),
        };
        Ok(Status::Ok)
    })
}
const _: fmi2NewDiscreteStatesTYPE = Some(fmi2NewDiscreteStates);

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2EnterContinuousTimeMode", |i| {
        i.enter_continuous_time_mode()
    })
}
const _: fmi2EnterContinuousTimeModeTYPE = Some(fmi2EnterContinuousTimeMode);

#[no_mangle]
pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
    c: fmi2Component,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
    enterEventMode: *mut fmi2Boolean,
    terminateSimulation: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2CompletedIntegratorStep";
    let _ = noSetFMUStatePriorToCurrentPoint; // states are independent copies
    with(c, F, |i| {
        // SAFETY: both point to a writable fmi2Boolean.
        let (enter, term) = unsafe {
            (
                out_one(enterEventMode, F, "enterEventMode")?,
                out_one(terminateSimulation, F, "terminateSimulation")?,
            )
        };
        let (e, t) = i.completed_integrator_step()?;
        *enter = e.into();
        *term = t.into();
        Ok(Status::Ok)
    })
}
const _: fmi2CompletedIntegratorStepTYPE = Some(fmi2CompletedIntegratorStep);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    with(c, "fmi2SetTime", |i| i.set_time(time))
}
const _: fmi2SetTimeTYPE = Some(fmi2SetTime);

#[no_mangle]
pub unsafe extern "C" fn fmi2SetContinuousStates(
    c: fmi2Component,
    x: *const fmi2Real,
    nx: usize,
) -> fmi2Status {
    let _ = x; // kerf has no states: nothing to read (a host's one dummy value is ignored)
    with(c, "fmi2SetContinuousStates", |i| {
        i.set_continuous_states(nx)
    })
}
const _: fmi2SetContinuousStatesTYPE = Some(fmi2SetContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDerivatives(
    c: fmi2Component,
    derivatives: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let _ = derivatives;
    with(c, "fmi2GetDerivatives", |i| {
        i.no_states("fmi2GetDerivatives", mask::GET_DERIVATIVES, nx, "nx")
    })
}
const _: fmi2GetDerivativesTYPE = Some(fmi2GetDerivatives);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetEventIndicators(
    c: fmi2Component,
    eventIndicators: *mut fmi2Real,
    ni: usize,
) -> fmi2Status {
    const F: &str = "fmi2GetEventIndicators";
    with(c, F, |i| {
        // SAFETY: the host passes ni writable fmi2Reals (checked against the
        // model's count before anything is written).
        let out = unsafe { output(eventIndicators, ni, F, "eventIndicators") }?;
        i.get_event_indicators(out)
    })
}
const _: fmi2GetEventIndicatorsTYPE = Some(fmi2GetEventIndicators);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetContinuousStates(
    c: fmi2Component,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let _ = x;
    with(c, "fmi2GetContinuousStates", |i| {
        i.no_states(
            "fmi2GetContinuousStates",
            mask::GET_CONTINUOUS_STATES,
            nx,
            "nx",
        )
    })
}
const _: fmi2GetContinuousStatesTYPE = Some(fmi2GetContinuousStates);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
    c: fmi2Component,
    x_nominal: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let _ = x_nominal;
    with(c, "fmi2GetNominalsOfContinuousStates", |i| {
        i.no_states(
            "fmi2GetNominalsOfContinuousStates",
            mask::GET_NOMINALS,
            nx,
            "nx",
        )
    })
}
const _: fmi2GetNominalsOfContinuousStatesTYPE = Some(fmi2GetNominalsOfContinuousStates);

// ---------------------------------------------------------------------------
// Co-Simulation
// ---------------------------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2SetRealInputDerivatives";
    let _ = (vr, nvr, order, value);
    with(c, F, |i| {
        kind_check(i, F, Kind::CoSimulation)?;
        i.check(F, mask::SET_REAL_INPUT_DERIVATIVES)?;
        Err(format!(
            "{F}: not supported (canInterpolateInputs=\"false\")"
        ))
    })
}
const _: fmi2SetRealInputDerivativesTYPE = Some(fmi2SetRealInputDerivatives);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealOutputDerivatives";
    let _ = (vr, nvr, order, value);
    with(c, F, |i| {
        kind_check(i, F, Kind::CoSimulation)?;
        i.check(F, mask::GET_REAL_OUTPUT_DERIVATIVES)?;
        Err(format!(
            "{F}: not supported (maxOutputDerivativeOrder=\"0\")"
        ))
    })
}
const _: fmi2GetRealOutputDerivativesTYPE = Some(fmi2GetRealOutputDerivatives);

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    let _ = noSetFMUStatePriorToCurrentPoint; // states are independent copies
    with(c, "fmi2DoStep", |i| {
        i.do_step(currentCommunicationPoint, communicationStepSize)
    })
}
const _: fmi2DoStepTYPE = Some(fmi2DoStep);

#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    const F: &str = "fmi2CancelStep";
    with(c, F, |i| {
        kind_check(i, F, Kind::CoSimulation)?;
        i.check(F, mask::CANCEL_STEP)
            .map_err(|_| format!("{F}: no step in progress (fmi2DoStep is synchronous and never returns fmi2Pending)"))?;
        Ok(Status::Ok)
    })
}
const _: fmi2CancelStepTYPE = Some(fmi2CancelStep);

/// The status queries: `fmi2Discard` for what a synchronous slave that never
/// discards a step cannot report.
fn status_query(
    c: fmi2Component,
    func: &str,
    f: impl FnOnce(&mut dyn Component) -> Res<Status>,
) -> fmi2Status {
    with(c, func, |i| {
        kind_check(i, func, Kind::CoSimulation)?;
        i.check(func, mask::GET_STATUS)?;
        f(i)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Status,
) -> fmi2Status {
    const F: &str = "fmi2GetStatus";
    status_query(c, F, |_| {
        // SAFETY: `value` points to a writable fmi2Status.
        let _ = unsafe { out_one(value, F, "value") }?;
        let _ = s; // fmi2DoStepStatus/fmi2PendingStatus: only after fmi2Pending, never returned
        Ok(Status::Discard)
    })
}
const _: fmi2GetStatusTYPE = Some(fmi2GetStatus);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealStatus";
    status_query(c, F, |i| {
        // SAFETY: `value` points to a writable fmi2Real.
        let v = unsafe { out_one(value, F, "value") }?;
        if s == fmi2StatusKind_fmi2LastSuccessfulTime {
            *v = i.last_successful_time();
            Ok(Status::Ok)
        } else {
            Ok(Status::Discard)
        }
    })
}
const _: fmi2GetRealStatusTYPE = Some(fmi2GetRealStatus);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2GetIntegerStatus";
    status_query(c, F, |_| {
        // SAFETY: `value` points to a writable fmi2Integer.
        let _ = unsafe { out_one(value, F, "value") }?;
        let _ = s; // FMI 2.0 defines no Integer status
        Ok(Status::Discard)
    })
}
const _: fmi2GetIntegerStatusTYPE = Some(fmi2GetIntegerStatus);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2GetBooleanStatus";
    status_query(c, F, |_| {
        // SAFETY: `value` points to a writable fmi2Boolean.
        let v = unsafe { out_one(value, F, "value") }?;
        if s == fmi2StatusKind_fmi2Terminated {
            *v = 0; // the slave never asks to terminate
            Ok(Status::Ok)
        } else {
            Ok(Status::Discard)
        }
    })
}
const _: fmi2GetBooleanStatusTYPE = Some(fmi2GetBooleanStatus);

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2GetStringStatus";
    status_query(c, F, |_| {
        // SAFETY: `value` points to a writable fmi2String.
        let _ = unsafe { out_one(value, F, "value") }?;
        let _ = s; // fmi2PendingStatus: only after fmi2Pending, never returned
        Ok(Status::Discard)
    })
}
const _: fmi2GetStringStatusTYPE = Some(fmi2GetStringStatus);

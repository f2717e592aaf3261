//! Instantiation, the state machine, value access and logging, through the
//! exported functions.

#[path = "fmi_support.rs"]
mod support;

use std::ptr;

use fmi_sys::fmi2::*;
use kerf::fmi2 as f;
use support::*;

#[test]
fn version_and_platform() {
    let v = unsafe { std::ffi::CStr::from_ptr(f::fmi2GetVersion()) };
    assert_eq!(v.to_str().unwrap(), "2.0");
    let p = unsafe { std::ffi::CStr::from_ptr(f::fmi2GetTypesPlatform()) };
    assert_eq!(p.to_str().unwrap(), "default");
}

#[test]
fn instantiate_both_interfaces_and_reject_bad_arguments() {
    for kind in [Kind::Me, Kind::Cs] {
        let fmu = Fmu::new(&format!("sm-inst-{kind:?}"), kind);
        fmu.init();
        assert_eq!(fmu.terminate(), OK);
    }
    // Wrong GUID: NULL and a message that names the GUIDs.
    let c = instantiate_raw(
        "sm-badguid",
        Kind::Cs,
        "{00000000-0000-0000-0000-000000000000}",
        false,
    );
    assert!(c.is_null());
    let m = messages_of("sm-badguid");
    assert!(
        m.iter()
            .any(|m| m.level == log::Level::Error && m.text.contains("GUID")),
        "{m:?}"
    );
    // Unknown interface type, NULL callbacks, NULL name.
    let cb = callbacks();
    let guid = std::ffi::CString::new(kerf::fmi2::md::GUID).unwrap();
    let name = c"sm-badtype";
    assert!(
        unsafe { f::fmi2Instantiate(name.as_ptr(), 7, guid.as_ptr(), ptr::null(), &cb, 0, 0) }
            .is_null()
    );
    assert!(messages_of("sm-badtype")
        .iter()
        .any(|m| m.text.contains("fmuType")));
    assert!(unsafe {
        f::fmi2Instantiate(
            name.as_ptr(),
            1,
            guid.as_ptr(),
            ptr::null(),
            ptr::null(),
            0,
            0,
        )
    }
    .is_null());
    assert!(
        unsafe { f::fmi2Instantiate(ptr::null(), 1, guid.as_ptr(), ptr::null(), &cb, 0, 0) }
            .is_null()
    );
    // NULL component: an error, no crash.
    assert_eq!(
        unsafe { f::fmi2EnterInitializationMode(ptr::null_mut()) },
        ERROR
    );
    unsafe { f::fmi2FreeInstance(ptr::null_mut()) };
}

#[test]
fn out_of_order_calls_are_rejected_with_a_message_and_the_instance_stays_usable() {
    let fmu = Fmu::new("sm-order-cs", Kind::Cs);
    // Before initialization: no step, no exit, no get.
    assert_eq!(fmu.do_step(0.0, 0.1), ERROR);
    assert!(
        fmu.last_error().contains("fmi2DoStep"),
        "{:?}",
        fmu.errors()
    );
    assert_eq!(fmu.exit_init(), ERROR);
    assert!(fmu.last_error().contains("illegal call sequence"));
    assert_eq!(fmu.get_reals(&[vr::FX]).0, ERROR);
    assert_eq!(fmu.terminate(), ERROR);
    // Model Exchange functions on a Co-Simulation instance.
    assert_eq!(fmu.enter_event_mode(), ERROR);
    assert!(fmu.last_error().contains("Model Exchange"));
    let n = fmu.errors().len();
    // Still usable: the normal sequence works.
    fmu.init();
    assert_eq!(fmu.errors().len(), n);
    assert_eq!(fmu.setup(0.0), ERROR); // only before initialization
    assert_eq!(fmu.enter_init(), ERROR);
    // A parameter is fixed after initialization; an input is not.
    assert_eq!(fmu.set_real(vr::CUTTER_RADIUS, 0.2), ERROR);
    assert!(fmu.last_error().contains("cutter.radius"));
    assert_eq!(fmu.real(vr::CUTTER_RADIUS), R);
    assert_eq!(fmu.set_real(vr::VX, 0.5), OK);
    assert_eq!(fmu.do_step(0.0, 0.01), OK, "{:?}", fmu.errors());
    // Time must match the FMU's.
    assert_eq!(fmu.do_step(0.5, 0.01), ERROR);
    assert!(fmu.last_error().contains("does not match"));
    assert_eq!(fmu.do_step(0.01, -1.0), ERROR);
    assert_eq!(fmu.do_step(0.01, f64::NAN), ERROR);
    assert_eq!(fmu.do_step(0.01, 0.01), OK, "{:?}", fmu.errors());
    // No step in progress to cancel; status queries per the standard.
    assert_eq!(unsafe { f::fmi2CancelStep(fmu.c) }, ERROR);
    let mut t = -1.0;
    assert_eq!(
        unsafe { f::fmi2GetRealStatus(fmu.c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut t) },
        OK
    );
    assert!((t - 0.02).abs() < 1e-15);
    let mut b = -1;
    assert_eq!(
        unsafe { f::fmi2GetBooleanStatus(fmu.c, fmi2StatusKind_fmi2Terminated, &mut b) },
        OK
    );
    assert_eq!(b, 0);
    let mut st = 99;
    assert_eq!(
        unsafe { f::fmi2GetStatus(fmu.c, fmi2StatusKind_fmi2DoStepStatus, &mut st) },
        DISCARD
    );
    assert_eq!(fmu.terminate(), OK);
    assert_eq!(fmu.do_step(0.02, 0.01), ERROR);
    // Outputs stay readable after termination.
    assert!(fmu.real(vr::FZ).is_finite());
    // Reset brings back the instantiated state and the start values.
    assert_eq!(fmu.reset(), OK);
    assert_eq!(fmu.set_real(vr::CUTTER_RADIUS, 0.2), OK);
    assert_eq!(fmu.reset(), OK);
    fmu.init();
    assert_eq!(fmu.real(vr::CUTTER_RADIUS), R);
    assert_eq!(fmu.real(vr::VX), 0.0);
}

#[test]
fn model_exchange_sequence_and_zero_state_functions() {
    let fmu = Fmu::new("sm-order-me", Kind::Me);
    assert_eq!(fmu.new_discrete_states().0, ERROR);
    assert_eq!(fmu.do_step(0.0, 0.1), ERROR);
    fmu.init();
    // After initialization: event mode (the initial event).
    assert_eq!(fmu.completed_integrator_step().0, ERROR);
    assert!(fmu.last_error().contains("fmi2CompletedIntegratorStep"));
    fmu.event_iteration();
    // Continuous-time mode with nx = ni = 0: what fmpy's Euler solver calls.
    let mut x = [0.0; 1];
    unsafe {
        assert_eq!(f::fmi2GetContinuousStates(fmu.c, x.as_mut_ptr(), 0), OK);
        assert_eq!(f::fmi2GetDerivatives(fmu.c, x.as_mut_ptr(), 0), OK);
        assert_eq!(f::fmi2SetContinuousStates(fmu.c, x.as_ptr(), 0), OK);
        // one event indicator (the cut event): ni must be 1
        assert_eq!(f::fmi2GetEventIndicators(fmu.c, x.as_mut_ptr(), 1), OK);
        assert_eq!(f::fmi2GetEventIndicators(fmu.c, x.as_mut_ptr(), 0), ERROR);
        assert_eq!(
            f::fmi2GetNominalsOfContinuousStates(fmu.c, x.as_mut_ptr(), 0),
            OK
        );
        assert_eq!(f::fmi2GetContinuousStates(fmu.c, ptr::null_mut(), 0), OK);
        assert_eq!(f::fmi2GetDerivatives(fmu.c, x.as_mut_ptr(), 1), ERROR);
        // Co-Simulation functions on a Model Exchange instance.
        assert_eq!(f::fmi2CancelStep(fmu.c), ERROR);
    }
    // Time may go backwards in continuous-time mode (CVode does that).
    assert_eq!(fmu.set_time(0.2), OK);
    assert_eq!(fmu.set_time(0.1), OK);
    assert_eq!(fmu.set_time(f64::INFINITY), ERROR);
    let (s, _enter, term) = fmu.completed_integrator_step();
    assert_eq!(s, OK);
    assert!(!term);
    assert_eq!(fmu.new_discrete_states().0, ERROR); // not in event mode
    assert_eq!(fmu.enter_event_mode(), OK);
    let (s, e) = fmu.new_discrete_states();
    assert_eq!(s, OK);
    assert_eq!(
        (
            e.newDiscreteStatesNeeded,
            e.terminateSimulation,
            e.valuesOfContinuousStatesChanged,
            e.nextEventTimeDefined
        ),
        (0, 0, 0, 0)
    );
    assert_eq!(fmu.enter_ct_mode(), OK);
    assert_eq!(fmu.terminate(), OK);
    assert_eq!(fmu.enter_event_mode(), ERROR);
}

#[test]
fn null_pointers_and_bad_value_references_are_errors() {
    let fmu = Fmu::new("sm-null", Kind::Cs);
    assert_eq!(fmu.enter_init(), OK);
    let v = 1.0;
    let r = vr::X;
    unsafe {
        assert_eq!(f::fmi2SetReal(fmu.c, ptr::null(), 1, &v), ERROR);
        assert_eq!(f::fmi2SetReal(fmu.c, &r, 1, ptr::null()), ERROR);
        assert_eq!(f::fmi2GetReal(fmu.c, &r, 1, ptr::null_mut()), ERROR);
        assert!(fmu.last_error().contains("NULL"));
        // nvr = 0 with NULL arrays is fine.
        assert_eq!(f::fmi2GetReal(fmu.c, ptr::null(), 0, ptr::null_mut()), OK);
        let mut st: fmi2FMUstate = ptr::null_mut();
        assert_eq!(f::fmi2SetFMUstate(fmu.c, st), ERROR);
        assert_eq!(f::fmi2GetFMUstate(fmu.c, ptr::null_mut()), ERROR);
        assert_eq!(f::fmi2FreeFMUstate(fmu.c, &mut st), OK); // NULL state: nothing to free
        let p: fmi2String = ptr::null();
        let sr = vr::ROCK_INITIAL_SURFACE;
        assert_eq!(f::fmi2SetString(fmu.c, &sr, 1, &p), ERROR);
        let mut e = fmi2EventInfo::default();
        assert_eq!(f::fmi2NewDiscreteStates(fmu.c, &mut e), ERROR);
    }
    // Bad value references, per type; a batch with one bad reference changes nothing.
    assert_eq!(fmu.get_reals(&[9999]).0, ERROR);
    assert!(fmu.last_error().contains("9999"));
    assert_eq!(fmu.set_reals(&[vr::X, 9999], &[0.5, 1.0]), ERROR);
    assert_eq!(fmu.real(vr::X), 0.0);
    assert_eq!(fmu.get_int(4242).0, ERROR);
    assert_eq!(fmu.get_bool(4242).0, ERROR);
    assert_eq!(fmu.get_string(4242).0, ERROR);
    // Outputs cannot be set; enumerations only take their items.
    assert_eq!(fmu.set_real(vr::FX, 1.0), ERROR);
    assert!(fmu.last_error().contains("Fx"));
    assert_eq!(fmu.set_int(vr::CSM_VARIANT, 6), ERROR);
    assert_eq!(fmu.set_int(vr::NUMERICS_DIRECTION_RULE, 0), ERROR);
    assert_eq!(fmu.set_int(vr::CSM_VARIANT, 2), OK);
    assert_eq!(fmu.get_int(vr::CSM_VARIANT), (OK, 2));
    let b = 1;
    let br = vr::IN_CONTACT;
    assert_eq!(unsafe { f::fmi2SetBoolean(fmu.c, &br, 1, &b) }, ERROR);
    // Directional derivatives are not provided, but the function exists.
    let (mut d, k) = (0.0, 0.0);
    assert_eq!(
        unsafe { f::fmi2GetDirectionalDerivative(fmu.c, &vr::FX, 1, &vr::X, 1, &k, &mut d) },
        ERROR
    );
    assert!(fmu.last_error().contains("providesDirectionalDerivative"));
    // The instance is still fine.
    assert_eq!(fmu.exit_init(), OK, "{:?}", fmu.errors());
}

#[test]
fn strings_round_trip_and_messages_are_never_format_strings() {
    let fmu = Fmu::new("sm-strings", Kind::Cs);
    assert_eq!(
        fmu.set_string(vr::ROCK_FINAL_SURFACE, "/tmp/%s%n%d.rsf"),
        OK
    );
    assert_eq!(fmu.enter_init(), OK);
    assert_eq!(
        fmu.get_string(vr::ROCK_FINAL_SURFACE),
        (OK, "/tmp/%s%n%d.rsf".to_string())
    );
    // A message holding printf directives arrives verbatim (it is an argument of "%s").
    assert_eq!(fmu.set_debug_logging(true, &["no%s%n%such"]), ERROR);
    assert!(
        fmu.last_error().contains("\"no%s%n%such\""),
        "{:?}",
        fmu.errors()
    );
}

#[test]
fn debug_logging_categories_are_honoured() {
    let fmu = Fmu::new("sm-logging", Kind::Me);
    // Events are off by default, errors on.
    fmu.init();
    fmu.event_iteration();
    assert!(
        fmu.messages().iter().all(|m| m.level == log::Level::Error),
        "{:?}",
        fmu.messages()
    );
    assert_eq!(fmu.set_debug_logging(true, &["logEvents"]), OK);
    assert_eq!(fmu.terminate(), OK);
    assert_eq!(fmu.reset(), OK);
    assert_eq!(fmu.setup(0.0), OK);
    assert_eq!(fmu.enter_init(), OK);
    assert!(fmu
        .messages()
        .iter()
        .any(|m| m.level == log::Level::Info && m.text.contains("initialization")));
    // Errors switched off: the call still fails, silently.
    assert_eq!(fmu.set_debug_logging(false, &["logStatusError"]), OK);
    let n = fmu.messages().len();
    assert_eq!(fmu.do_step(0.0, 0.1), ERROR);
    assert_eq!(fmu.messages().len(), n);
    // logAll switches every category.
    assert_eq!(fmu.set_debug_logging(true, &["logAll"]), OK);
    assert_eq!(fmu.do_step(0.0, 0.1), ERROR);
    assert_eq!(fmu.messages().len(), n + 1);
    // No categories: all of them.
    assert_eq!(fmu.set_debug_logging(false, &[]), OK);
    assert_eq!(fmu.do_step(0.0, 0.1), ERROR);
    assert_eq!(fmu.messages().len(), n + 1);
}

#[test]
fn logging_on_at_instantiation_reports_events() {
    let c = instantiate_raw("sm-logging-on", Kind::Cs, kerf::fmi2::md::GUID, true);
    let fmu = Fmu {
        c,
        name: "sm-logging-on".into(),
        kind: Kind::Cs,
    };
    fmu.init();
    assert_eq!(fmu.do_step(0.0, 0.01), OK);
    assert!(
        fmu.messages().iter().any(|m| m.text.contains("fmi2DoStep")),
        "{:?}",
        fmu.messages()
    );
}

/// fmusim-rs 0.8.0's CVode sets a one-element dummy state on a model
/// without states at every root-function call (host bug H1,
/// docs/hosts.md). kerf ignores that one value with one warning an
/// instance and stays strict everywhere else: two values, or a dummy read
/// of states or derivatives, are errors, and the outputs do not move.
#[test]
fn a_hosts_one_element_dummy_state_is_ignored_with_one_warning() {
    let fmu = Fmu::new("sm-dummy-state", Kind::Me);
    fmu.init();
    fmu.event_iteration();
    let before = fmu.get_reals(&real_outputs()).1;
    let warnings = |f: &Fmu| {
        f.messages()
            .into_iter()
            .filter(|m| m.level == log::Level::Warn && m.text.contains("dummy state"))
            .count()
    };
    let mut x = [123.0; 2];
    unsafe {
        assert_eq!(f::fmi2SetContinuousStates(fmu.c, x.as_ptr(), 1), OK);
        assert_eq!(warnings(&fmu), 1);
        x[0] = -7.0;
        assert_eq!(f::fmi2SetContinuousStates(fmu.c, x.as_ptr(), 1), OK);
        assert_eq!(warnings(&fmu), 1, "said once an instance");
        assert_eq!(f::fmi2SetContinuousStates(fmu.c, x.as_ptr(), 2), ERROR);
        assert!(fmu.last_error().contains("nx = 2"));
        assert_eq!(f::fmi2GetContinuousStates(fmu.c, x.as_mut_ptr(), 1), ERROR);
        assert_eq!(f::fmi2GetDerivatives(fmu.c, x.as_mut_ptr(), 1), ERROR);
    }
    assert_eq!(fmu.get_reals(&real_outputs()).1, before);
    // a Co-Simulation instance has no continuous-time functions at all
    let cs = Fmu::new("sm-dummy-state-cs", Kind::Cs);
    cs.init();
    let x = [0.0];
    assert_eq!(
        unsafe { f::fmi2SetContinuousStates(cs.c, x.as_ptr(), 1) },
        ERROR
    );
}

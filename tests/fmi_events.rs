//! Model Exchange events: the event indicator (numerics.sweepStep minus the
//! rim travel since the last committed cut), the step-event flag, the backstop
//! time event, and what they commit, driven by in-process host loops that act
//! on each kind of event as real hosts do (CVode locates the indicator's zero
//! crossing; PyFMI calls fmi2CompletedIntegratorStep after every internal
//! step; OMSimulator ignores the step-event flag).

#[path = "fmi_support.rs"]
mod support;

use fmi_sys::fmi2::*;
use support::*;

const SWEEP: f64 = 1e-3; // numerics.sweepStep start value
const V: f64 = 1.0; // rolling speed [m/s]

fn indicators(fmu: &Fmu, ni: usize) -> (fmi2Status, Vec<f64>) {
    fmu.event_indicators(ni)
}

fn indicator(fmu: &Fmu) -> f64 {
    fmu.event_indicator()
}

/// The rolling cut's inputs at time t (x = V t, rolling without slip).
fn roll_to(fmu: &Fmu, t: f64) {
    assert_eq!(fmu.set_time(t), OK);
    assert_eq!(
        fmu.set_reals(&[vr::X, vr::VX, vr::WY], &[V * t, V, V / R]),
        OK
    );
}

/// One event: NewDiscreteStates until none is needed; returns nextEventTime.
fn event(fmu: &Fmu) -> Option<f64> {
    fmu.event_iteration_next()
}

/// A Model Exchange instance on the small rock, rolling from x = 0,
/// initialized and through its initial event; returns it and nextEventTime.
fn me_roller(name: &str) -> (Fmu, Option<f64>) {
    let fmu = Fmu::new(name, Kind::Me);
    fmu.small_rock();
    assert_eq!(
        fmu.set_reals(&[vr::X, vr::VX, vr::WY], &[0.0, V, V / R]),
        OK
    );
    fmu.init();
    let next = event(&fmu);
    (fmu, next)
}

/// Which events a host acts on.
#[derive(Clone, Copy)]
struct Honours {
    /// Sign change of the indicator, located by a secant step (as CVode's
    /// root finding does).
    indicator: bool,
    /// enterEventMode from fmi2CompletedIntegratorStep.
    step_flag: bool,
    /// nextEventTime from fmi2NewDiscreteStates.
    time_events: bool,
}

const ALL: Honours = Honours {
    indicator: true,
    step_flag: true,
    time_events: true,
};

/// A host's continuous-time loop from `t0` to `t1` with steps of `h`; returns
/// the number of events it had (the final one at `t1` included when `final_event`).
fn run(
    fmu: &Fmu,
    mut next: Option<f64>,
    t0: f64,
    t1: f64,
    h: f64,
    hon: Honours,
    final_event: bool,
) -> usize {
    let mut events = 0;
    let mut t = t0;
    let mut z_prev = indicator(fmu);
    while t < t1 - 1e-12 {
        let mut t_next = (t + h).min(t1);
        if let (true, Some(te)) = (hon.time_events, next) {
            t_next = t_next.min(te);
        }
        roll_to(fmu, t_next);
        let mut z = indicator(fmu);
        let mut state_event = false;
        if hon.indicator && z_prev > 0.0 && z <= 0.0 {
            // the indicator is linear in t here: one secant step finds the root
            t_next = t + (t_next - t) * z_prev / (z_prev - z);
            roll_to(fmu, t_next);
            z = indicator(fmu);
            state_event = true;
        }
        let (s, enter, _) = fmu.completed_integrator_step();
        assert_eq!(s, OK, "{:?}", fmu.errors());
        let time_event = hon.time_events && next.is_some_and(|te| t_next >= te);
        if state_event || time_event || (hon.step_flag && enter) {
            assert_eq!(fmu.enter_event_mode(), OK);
            next = event(fmu);
            events += 1;
            z = indicator(fmu);
        }
        z_prev = z;
        t = t_next;
    }
    if final_event {
        assert_eq!(fmu.enter_event_mode(), OK);
        event(fmu);
        events += 1;
    }
    events
}

/// The reference: the same roll in Co-Simulation with 1 mm steps.
fn cs_roll(name: &str, t1: f64) -> Fmu {
    let fmu = Fmu::new(name, Kind::Cs);
    fmu.small_rock();
    assert_eq!(
        fmu.set_reals(&[vr::X, vr::VX, vr::WY], &[0.0, V, V / R]),
        OK
    );
    fmu.init();
    let h = SWEEP / V;
    let n = (t1 / h).round() as usize;
    for k in 0..n {
        let t = k as f64 * h;
        assert_eq!(fmu.set_real(vr::X, V * t), OK);
        assert_eq!(fmu.do_step(t, h), OK, "{:?}", fmu.errors());
    }
    fmu
}

#[test]
fn indicator_is_sweep_step_minus_travel_and_reading_it_changes_nothing() {
    let fmu = Fmu::new("ev-sign", Kind::Me);
    fmu.small_rock();
    assert_eq!(fmu.enter_init(), OK);
    // before the first cut: the sweep step itself
    assert_eq!(indicator(&fmu), SWEEP);
    assert_eq!(fmu.exit_init(), OK);
    let next = event(&fmu);
    assert_eq!(next, None, "no velocity inputs: no time event");
    assert_eq!(indicator(&fmu), SWEEP);

    // translation
    let v0 = fmu.real(vr::EXCAVATED_VOLUME);
    assert!(v0 > 0.0, "the initial event cuts the imprint");
    for (x, want) in [(4e-4, 6e-4), (1e-3, 0.0), (1.5e-3, -5e-4), (4e-4, 6e-4)] {
        assert_eq!(fmu.set_real(vr::X, x), OK);
        let z = indicator(&fmu);
        assert!(
            (z - want).abs() < 1e-15,
            "x = {x}: indicator {z}, want {want}"
        );
    }
    // reading the indicator (and the outputs) committed nothing
    assert_eq!(fmu.real(vr::EXCAVATED_VOLUME), v0);
    // a turn of the disc's frame counts as the travel of the rim in the
    // rock: a tilt as the angle times R; a yaw as the angle times the reach
    // of the part below the face (z0 = 0) from the vertical through the
    // centre, sqrt(reach^2 - z^2) with reach = hypot(R, T/2)
    assert_eq!(fmu.set_reals(&[vr::X, vr::ROLL], &[0.0, 2e-3]), OK);
    let z = indicator(&fmu);
    assert!((z - (SWEEP - 2e-3 * R)).abs() < 1e-15, "tilt: {z}");
    assert_eq!(fmu.set_reals(&[vr::ROLL, vr::YAW], &[0.0, 2e-3]), OK);
    let zc = fmu.real(vr::Z);
    let lever = (R * R + 0.0065f64.powi(2) - zc * zc).sqrt();
    assert!(lever > 0.03 && lever < 0.05, "{lever}");
    let z = indicator(&fmu);
    assert!((z - (SWEEP - 2e-3 * lever)).abs() < 1e-15, "yaw: {z}");
    assert_eq!(fmu.set_reals(&[vr::X, vr::YAW], &[0.0, 0.0]), OK);

    // the wrong count is an error and writes nothing
    let (s, z) = indicators(&fmu, 2);
    assert_eq!(s, ERROR);
    assert!(z.iter().all(|v| v.is_nan()));
    assert!(fmu.last_error().contains("ni = 2"), "{}", fmu.last_error());
    assert_eq!(indicators(&fmu, 0).0, ERROR);
}

#[test]
fn step_event_flag_only_within_the_slack_of_a_sweep_step() {
    let (fmu, next) = me_roller("ev-flag");
    assert_eq!(
        next,
        Some(2.0 * SWEEP / V),
        "backstop: two sweep steps ahead"
    );
    let slack = 1e-6 * SWEEP; // src/fmi2/instance.rs EVENT_SLACK
    for (x, want) in [
        (0.5e-3, false),
        (1e-3 - 2.0 * slack, false),
        (1e-3 - 0.5 * slack, true),
        (1e-3, true),
        (3e-3, true),
    ] {
        assert_eq!(fmu.set_time(x / V), OK);
        assert_eq!(fmu.set_real(vr::X, x), OK);
        let (s, enter, term) = fmu.completed_integrator_step();
        assert_eq!((s, term), (OK, false));
        assert_eq!(enter, want, "x = {x}");
    }
    // after the event the indicator starts again from the new cut
    assert_eq!(fmu.enter_event_mode(), OK);
    let next = event(&fmu);
    assert_eq!(indicator(&fmu), SWEEP);
    let te = next.expect("moving: a time event");
    assert!((te - (3e-3 + 2.0 * SWEEP) / V).abs() < 1e-15, "{te}");
}

#[test]
fn events_per_metre_do_not_depend_on_the_solver_step() {
    // 50 mm of travel: 50 events, whatever the step, for a host that locates
    // the zero crossing; PyFMI-like 20 um steps with the flag read after each
    // one no longer make an event per step.
    let travel = 0.05;
    let t1 = travel / V;
    for h in [2e-5, 1e-4, 3e-4, 1e-3, 2.5e-3, 1e-2] {
        let (fmu, next) = me_roller(&format!("ev-count-{h}"));
        let n = run(&fmu, next, 0.0, t1, h, ALL, false);
        let want = (travel / SWEEP).round() as usize;
        assert!(
            n == want || n == want - 1,
            "h = {h}: {n} events for {want} sweep steps of travel"
        );
    }
}

#[test]
fn no_cut_is_lost_whichever_events_the_host_acts_on() {
    // The rock after 40 mm: Co-Simulation with 1 mm steps, and Model Exchange
    // hosts that act on every kind of event, on the time events only (2 mm
    // apart: each commit cuts its path in 1 mm sub-steps), on the step flag
    // only, and on none but a final event (one commit for the whole path).
    let t1 = 0.04 / V;
    let cs = cs_roll("ev-lost-cs", t1);
    let v_cs = cs.real(vr::EXCAVATED_VOLUME);
    assert!(v_cs > 0.0);
    let none = Honours {
        indicator: false,
        step_flag: false,
        time_events: false,
    };
    let cases = [
        ("all", ALL, 3e-4, 40),
        (
            "time events only",
            Honours {
                time_events: true,
                ..none
            },
            3e-4,
            20,
        ),
        (
            "step flag only",
            Honours {
                step_flag: true,
                ..none
            },
            2.5e-4,
            40,
        ),
        ("final event only", none, 1e-3, 1),
    ];
    for (what, hon, h, want_events) in cases {
        let (fmu, next) = me_roller(&format!("ev-lost-{what}"));
        let n = run(&fmu, next, 0.0, t1, h, hon, true);
        assert!(
            n.abs_diff(want_events + usize::from(want_events > 1)) <= 1,
            "{what}: {n} events, expected about {want_events}"
        );
        let v = fmu.real(vr::EXCAVATED_VOLUME);
        assert!(
            (v / v_cs - 1.0).abs() < 1e-9,
            "{what}: excavated {v:e} m3 vs Co-Simulation {v_cs:e} m3"
        );
    }
}

#[test]
fn cutting_energy_of_model_exchange_equals_co_simulation_from_the_first_step() {
    // Events at the Co-Simulation host's communication points (1 mm): the
    // same cuts and the same trapezoidal work, so the same energy at every
    // point, the first steps included (it differed by half a step of rolling
    // force for the whole run).
    let h = SWEEP / V;
    let cs = Fmu::new("ev-energy-cs", Kind::Cs);
    cs.small_rock();
    assert_eq!(cs.set_reals(&[vr::X, vr::VX, vr::WY], &[0.0, V, V / R]), OK);
    cs.init();
    let (me, _) = me_roller("ev-energy-me");
    let mut fr = 0.0;
    for k in 1..=40 {
        let t = k as f64 * h;
        assert_eq!(cs.set_real(vr::X, V * (t - h)), OK);
        assert_eq!(cs.do_step(t - h, h), OK);
        roll_to(&me, t);
        let (s, enter, _) = me.completed_integrator_step();
        assert_eq!(s, OK);
        assert!(enter, "t = {t}: a 1 mm step ends on the sweep step");
        assert_eq!(me.enter_event_mode(), OK);
        event(&me);
        let (e_cs, e_me) = (cs.real(vr::CUTTING_ENERGY), me.real(vr::CUTTING_ENERGY));
        fr = cs.real(vr::ROLLING_FORCE);
        assert!(
            (e_me - e_cs).abs() <= 1e-9 * e_cs.abs().max(1.0),
            "step {k}: ME {e_me} J, CS {e_cs} J"
        );
        let (x_cs, x_me) = (cs.real(vr::EXCAVATED_VOLUME), me.real(vr::EXCAVATED_VOLUME));
        assert!((x_me / x_cs - 1.0).abs() < 1e-12, "step {k}: volumes");
    }
    // the case the old bookkeeping got wrong had a rolling force to miss
    assert!(fr > 1000.0, "rolling force {fr} N: not cutting");
}

#[test]
fn standing_still_books_no_work_when_the_cutter_starts_moving() {
    // The cutter rests in its imprint for 1 s (the host steps and calls
    // fmi2CompletedIntegratorStep), then rolls 10 mm: the same energy as a
    // roll that starts at once, not the rest time times the rolling power.
    let roll = |name: &str, rest: f64| -> f64 {
        let fmu = Fmu::new(name, Kind::Me);
        fmu.small_rock();
        fmu.init();
        event(&fmu);
        let mut t = 0.0;
        while t < rest - 1e-12 {
            t += 0.1;
            assert_eq!(fmu.set_time(t), OK);
            let (s, enter, _) = fmu.completed_integrator_step();
            assert_eq!((s, enter), (OK, false));
        }
        for k in 1..=10 {
            let tk = rest + k as f64 * 1e-3;
            assert_eq!(fmu.set_time(tk), OK);
            assert_eq!(
                fmu.set_reals(&[vr::X, vr::VX, vr::WY], &[V * (tk - rest), V, V / R]),
                OK
            );
            let (s, enter, _) = fmu.completed_integrator_step();
            assert_eq!((s, enter), (OK, true));
            assert_eq!(fmu.enter_event_mode(), OK);
            event(&fmu);
        }
        fmu.real(vr::CUTTING_ENERGY)
    };
    let (e0, e1) = (roll("ev-rest-0", 0.0), roll("ev-rest-1", 1.0));
    assert!(e0 > 0.0);
    assert!(
        (e1 / e0 - 1.0).abs() < 1e-9,
        "{e1} J after a rest vs {e0} J"
    );
}

#[test]
fn a_disc_spinning_in_place_has_events_per_sweep_step_of_rim_skid() {
    // wy = 5 rad/s, v = 0: the pose never moves, but the rim skids over the
    // rock at R wy = 1.08 m/s doing friction work; the indicator counts that
    // travel too, so the energy is booked once per sweep step of skid.
    let fmu = Fmu::new("ev-spin", Kind::Me);
    fmu.small_rock();
    let wy = 5.0;
    assert_eq!(fmu.set_real(vr::WY, wy), OK);
    fmu.init();
    let next = event(&fmu);
    let te = next.expect("spinning: a backstop time event");
    assert!((te - 2.0 * SWEEP / (wy * R)).abs() < 1e-15, "{te}");
    let (t1, h) = (0.02, 1e-4);
    let mut events = 0;
    let mut z_prev = indicator(&fmu);
    let mut t = 0.0;
    while t < t1 - 1e-12 {
        t += h;
        assert_eq!(fmu.set_time(t), OK);
        let z = indicator(&fmu);
        let (s, enter, _) = fmu.completed_integrator_step();
        assert_eq!(s, OK);
        if (z_prev > 0.0 && z <= 0.0) || enter {
            assert_eq!(fmu.enter_event_mode(), OK);
            event(&fmu);
            events += 1;
        }
        z_prev = indicator(&fmu);
    }
    let skid = t1 * wy * R;
    // one event per sweep step of skid, rounded up to a whole solver step
    let want = skid / (SWEEP / (wy * R) / h).ceil() / (h * wy * R);
    assert!(
        (events as f64 - want).abs() <= 1.0,
        "{events} events for {skid} m of skid (expected {want:.1})"
    );
    let my = fmu.real(vr::MY);
    let e = fmu.real(vr::CUTTING_ENERGY);
    assert!(my * wy < 0.0);
    // booked up to the last event: within one event interval of the power's work
    let rate = -my * wy;
    assert!(
        e > rate * (t1 - 2.0 * SWEEP / (wy * R)) && e <= rate * t1 * (1.0 + 1e-9),
        "energy {e} J vs {} J of friction work",
        rate * t1
    );
}

/// PyFMI 2.21 with Assimulo's ExplicitEuler, when a state event falls just
/// before the stop time, goes back to its last grid point for one more
/// event (at 1.1-1.7 m/s in 1 ms steps every run ended in an error there).
/// An event before the last commit commits nothing, with one warning an
/// instance, and the roll goes on as if it had not come: the next commit
/// cuts and books what a host that never went back has, bit for bit.
#[test]
fn an_event_before_the_last_commit_commits_nothing_with_one_warning() {
    let forward = |name: &str, back: bool| {
        let (fmu, _) = me_roller(name);
        for k in 1..=3 {
            roll_to(&fmu, k as f64 * 1e-3);
            assert_eq!(fmu.enter_event_mode(), OK);
            event(&fmu);
        }
        if back {
            let (v, e) = (fmu.real(vr::EXCAVATED_VOLUME), fmu.real(vr::CUTTING_ENERGY));
            for t in [2e-3, 2.5e-3] {
                roll_to(&fmu, t);
                assert_eq!(fmu.enter_event_mode(), OK);
                let (s, info) = fmu.new_discrete_states();
                assert_eq!(s, OK, "{:?}", fmu.errors());
                assert_eq!(info.newDiscreteStatesNeeded, 0);
                assert_eq!(fmu.real(vr::EXCAVATED_VOLUME), v, "t = {t}: nothing cut");
                assert_eq!(fmu.real(vr::CUTTING_ENERGY), e, "t = {t}: no work booked");
                assert_eq!(fmu.enter_ct_mode(), OK);
            }
            let warned: Vec<String> = fmu
                .messages()
                .into_iter()
                .filter(|m| m.level == log::Level::Warn)
                .map(|m| m.text)
                .collect();
            assert_eq!(warned.len(), 1, "said once an instance: {warned:?}");
            assert!(warned[0].contains("before the last commit"), "{warned:?}");
            assert!(fmu.errors().is_empty(), "{:?}", fmu.errors());
        }
        roll_to(&fmu, 4e-3);
        assert_eq!(fmu.enter_event_mode(), OK);
        event(&fmu);
        (fmu.real(vr::EXCAVATED_VOLUME), fmu.real(vr::CUTTING_ENERGY))
    };
    let (v, e) = forward("ev-back-no", false);
    let (vb, eb) = forward("ev-back-yes", true);
    assert!(v > 0.0 && e > 0.0);
    assert_eq!((vb, eb), (v, e));
}

//! Bad inputs and bad parameters: fmi2Error with a message, the instance
//! left as it was, and (for parameters) fixable before a second try.

#[path = "fmi_support.rs"]
mod support;

use support::*;

#[test]
fn nan_input_is_rejected_and_the_instance_stays_usable_and_restorable() {
    for kind in [Kind::Me, Kind::Cs] {
        let fmu = Fmu::new(&format!("err-nan-{kind:?}"), kind);
        fmu.small_rock();
        fmu.init();
        if kind == Kind::Me {
            fmu.event_iteration();
        }
        let before = fmu.get_reals(&real_outputs()).1;
        let state = fmu.get_state();
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(fmu.set_reals(&[vr::VX, vr::Z], &[0.5, bad]), ERROR);
            let e = fmu.last_error();
            assert!(e.contains('z') && e.contains("not finite"), "{e}");
        }
        // Nothing was set: neither the bad value nor its batch companion.
        assert_eq!(fmu.real(vr::Z), 0.2121);
        assert_eq!(fmu.real(vr::VX), 0.0);
        let after = fmu.get_reals(&real_outputs()).1;
        assert_eq!(
            before.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            after.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        // Usable: it goes on.
        match kind {
            Kind::Cs => assert_eq!(fmu.do_step(0.0, 0.01), OK, "{:?}", fmu.errors()),
            Kind::Me => {
                assert_eq!(fmu.set_time(0.01), OK);
                assert_eq!(fmu.completed_integrator_step().0, OK);
            }
        }
        // Restorable.
        assert_eq!(fmu.set_state(state), OK, "{:?}", fmu.errors());
        let restored = fmu.get_reals(&real_outputs()).1;
        assert_eq!(
            before.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            restored.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        fmu.free_state(state);
    }
}

#[test]
fn absurd_pose_fails_the_step_without_changing_anything() {
    let fmu = Fmu::new("err-absurd", Kind::Cs);
    fmu.small_rock();
    fmu.init();
    assert_eq!(fmu.set_real(vr::X, 1e9), OK); // finite: accepted as a value
    assert_eq!(fmu.do_step(0.0, 0.01), ERROR);
    assert!(fmu.last_error().contains("fmi2DoStep"));
    assert_eq!(fmu.set_real(vr::X, 0.0), OK);
    assert_eq!(fmu.do_step(0.0, 0.01), OK, "{:?}", fmu.errors());
}

/// Sets one bad parameter, expects fmi2ExitInitializationMode to fail with a
/// message containing `needle`, then fixes it and expects success.
fn bad_parameter(name: &str, set_bad: impl Fn(&Fmu), set_good: impl Fn(&Fmu), needle: &str) {
    for kind in [Kind::Me, Kind::Cs] {
        let fmu = Fmu::new(&format!("err-param-{name}-{kind:?}"), kind);
        fmu.small_rock();
        assert_eq!(fmu.setup(0.0), OK);
        assert_eq!(fmu.enter_init(), OK);
        set_bad(&fmu);
        assert_eq!(fmu.exit_init(), ERROR, "{name} accepted");
        let e = fmu.last_error();
        assert!(
            e.contains("fmi2ExitInitializationMode") && e.contains(needle),
            "{name}: {e}"
        );
        // Still in initialization mode: fix the parameter and go on.
        assert_eq!(fmu.do_step(0.0, 0.01), ERROR);
        set_good(&fmu);
        assert_eq!(fmu.exit_init(), OK, "{name}: {:?}", fmu.errors());
    }
}

#[test]
fn negative_radius() {
    bad_parameter(
        "radius",
        |f| assert_eq!(f.set_real(vr::CUTTER_RADIUS, -0.2), OK),
        |f| assert_eq!(f.set_real(vr::CUTTER_RADIUS, R), OK),
        "cutter.radius",
    );
}

#[test]
fn tip_wider_than_its_profile() {
    bad_parameter(
        "tipWidth",
        |f| assert_eq!(f.set_real(vr::CUTTER_TIP_WIDTH, 2.0 * 0.0127 + 1e-4), OK),
        |f| assert_eq!(f.set_real(vr::CUTTER_TIP_WIDTH, 0.013), OK),
        "cutter.tipWidth",
    );
}

#[test]
fn one_node_rock() {
    bad_parameter(
        "nx",
        |f| assert_eq!(f.set_int(vr::ROCK_NX, 1), OK),
        |f| assert_eq!(f.set_int(vr::ROCK_NX, 201), OK),
        "rock.nx",
    );
    bad_parameter(
        "nx-negative",
        |f| assert_eq!(f.set_int(vr::ROCK_NX, -3), OK),
        |f| assert_eq!(f.set_int(vr::ROCK_NX, 201), OK),
        "rock.nx",
    );
}

#[test]
fn missing_initial_surface_file() {
    let missing = std::env::temp_dir().join("kerf-test-no-such-surface.rsf");
    let _ = std::fs::remove_file(&missing);
    let path = missing.to_string_lossy().into_owned();
    bad_parameter(
        "initialSurface",
        |f| assert_eq!(f.set_string(vr::ROCK_INITIAL_SURFACE, &path), OK),
        |f| assert_eq!(f.set_string(vr::ROCK_INITIAL_SURFACE, ""), OK),
        "kerf-test-no-such-surface.rsf",
    );
}

#[test]
fn force_is_zero_far_above_the_rock_and_positive_when_pressed() {
    for kind in [Kind::Me, Kind::Cs] {
        let fmu = Fmu::new(&format!("err-physics-{kind:?}"), kind);
        fmu.small_rock();
        assert_eq!(fmu.setup(0.0), OK);
        assert_eq!(fmu.enter_init(), OK);
        assert_eq!(fmu.set_real(vr::Z, 1.0), OK);
        assert_eq!(fmu.exit_init(), OK);
        let (s, v) = fmu.get_reals(&real_outputs());
        assert_eq!(s, OK);
        for (r, x) in real_outputs().iter().zip(&v) {
            assert_eq!(*x, 0.0, "output {r} far above the rock");
        }
        assert_eq!(fmu.get_bool(vr::IN_CONTACT), (OK, false));
        // Pressed 3.8 mm into the flat face.
        assert_eq!(fmu.set_real(vr::Z, R - 0.0038), OK);
        let (s, v) = fmu.get_reals(&real_outputs());
        assert_eq!(s, OK);
        assert!(v.iter().all(|x| x.is_finite()), "{v:?}");
        assert!(fmu.real(vr::NORMAL_FORCE) > 0.0);
        assert!(fmu.real(vr::FZ) > 0.0);
        assert!(fmu.real(vr::PENETRATION) > 0.0);
        assert_eq!(fmu.get_bool(vr::IN_CONTACT), (OK, true));
    }
}

#[test]
fn final_surface_write_failure_is_reported_at_terminate() {
    let fmu = Fmu::new("err-final-surface", Kind::Cs);
    fmu.small_rock();
    assert_eq!(
        fmu.set_string(vr::ROCK_FINAL_SURFACE, "/nonexistent-dir-kerf/x/final.rsf"),
        OK
    );
    fmu.init();
    assert_eq!(fmu.do_step(0.0, 0.01), OK);
    assert_eq!(fmu.terminate(), ERROR);
    assert!(
        fmu.last_error().contains("rock.finalSurface"),
        "{:?}",
        fmu.errors()
    );
}

#[test]
fn final_surface_is_written_at_terminate() {
    let path = std::env::temp_dir().join(format!("kerf-test-final-{}.rsf", std::process::id()));
    let _ = std::fs::remove_file(&path);
    let fmu = Fmu::new("err-final-ok", Kind::Cs);
    fmu.small_rock();
    assert_eq!(
        fmu.set_string(vr::ROCK_FINAL_SURFACE, &path.to_string_lossy()),
        OK
    );
    fmu.init();
    assert_eq!(fmu.do_step(0.0, 0.01), OK);
    assert_eq!(fmu.terminate(), OK, "{:?}", fmu.errors());
    let text = std::fs::read_to_string(&path).expect("final surface written");
    assert!(
        text.lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
            .count()
            > 0
    );
    // It can be read back as an initial surface.
    let again = Fmu::new("err-final-reread", Kind::Cs);
    again.small_rock();
    assert_eq!(
        again.set_string(
            vr::ROCK_INITIAL_SURFACE,
            &format!("file://{}", path.display())
        ),
        OK
    );
    again.init();
    let _ = std::fs::remove_file(&path);
}

#[test]
fn questionable_parameters_are_logged_as_warnings() {
    // Ozdemir & Rostami's regressions (imperial units) used far outside
    // their Table 1 range: legal, but worth a warning.
    let fmu = Fmu::new("err-warnings", Kind::Cs);
    fmu.small_rock();
    assert_eq!(fmu.set_int(vr::CSM_VARIANT, 4), OK);
    assert_eq!(
        fmu.set_reals(&[vr::ROCK_UCS, vr::ROCK_BTS], &[400e6, 40e6]),
        OK
    );
    assert_eq!(fmu.setup(0.0), OK);
    assert_eq!(fmu.enter_init(), OK);
    assert_eq!(fmu.exit_init(), WARNING);
    let warnings: Vec<_> = fmu
        .messages()
        .into_iter()
        .filter(|m| m.level == log::Level::Warn)
        .collect();
    assert!(!warnings.is_empty());
    assert!(fmu.errors().is_empty());
    // The reference scene with the thesis law warns about nothing.
    let quiet = Fmu::new("err-no-warnings", Kind::Cs);
    quiet.small_rock();
    quiet.init();
    assert!(quiet.messages().is_empty(), "{:?}", quiet.messages());
}

#[test]
fn relative_surface_paths_are_found_in_the_resources_folder() {
    // A resources folder with a space in its name (percent-encoded in the URI).
    let dir = std::env::temp_dir().join(format!("kerf test resources {}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("start.rsf");
    let maker = Fmu::new("err-res-maker", Kind::Cs);
    maker.small_rock();
    assert_eq!(
        maker.set_string(vr::ROCK_FINAL_SURFACE, &file.to_string_lossy()),
        OK
    );
    maker.init();
    assert_eq!(maker.terminate(), OK, "{:?}", maker.errors());
    let uri = format!("file://{}", dir.to_string_lossy().replace(' ', "%20"));

    let c = instantiate_at(
        "err-res-user",
        Kind::Cs,
        kerf::fmi2::md::GUID,
        false,
        Some(&uri),
    );
    let fmu = Fmu {
        c,
        name: "err-res-user".into(),
        kind: Kind::Cs,
    };
    fmu.small_rock();
    assert_eq!(fmu.set_string(vr::ROCK_INITIAL_SURFACE, "start.rsf"), OK);
    fmu.init();
    assert_eq!(fmu.do_step(0.0, 0.01), OK);

    let c = instantiate_at(
        "err-res-missing",
        Kind::Cs,
        kerf::fmi2::md::GUID,
        false,
        Some(&uri),
    );
    let fmu = Fmu {
        c,
        name: "err-res-missing".into(),
        kind: Kind::Cs,
    };
    fmu.small_rock();
    assert_eq!(fmu.set_string(vr::ROCK_INITIAL_SURFACE, "other.rsf"), OK);
    assert_eq!(fmu.enter_init(), OK);
    assert_eq!(fmu.exit_init(), ERROR);
    assert!(
        fmu.last_error().contains("other.rsf"),
        "{}",
        fmu.last_error()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

//! FMU state: get/set/serialize/deserialize replay bit for bit; corrupt,
//! truncated and foreign blobs are rejected and change nothing.

#[path = "fmi_support.rs"]
mod support;

use kerf::fmi2 as f;
use support::*;

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Co-Simulation: a rolling cut, driven by velocities only.
fn cs_cutter(name: &str) -> Fmu {
    let fmu = Fmu::new(name, Kind::Cs);
    fmu.small_rock();
    assert_eq!(fmu.set_reals(&[vr::VX, vr::WY], &[1.0, 1.0 / R]), OK);
    fmu.init();
    fmu
}

fn cs_run(fmu: &Fmu, t0: f64, steps: usize, h: f64) -> Vec<Vec<f64>> {
    (0..steps)
        .map(|k| {
            let t = t0 + k as f64 * h;
            assert_eq!(fmu.do_step(t, h), OK, "{:?}", fmu.errors());
            fmu.get_reals(&real_outputs()).1
        })
        .collect()
}

#[test]
fn co_simulation_state_replays_bit_for_bit() {
    let h = 0.002;
    let fmu = cs_cutter("state-cs");
    cs_run(&fmu, 0.0, 20, h);
    let s = fmu.get_state();
    let blob = fmu.serialize(s);
    let reference = cs_run(&fmu, 20.0 * h, 30, h);
    // Something happened: the cutter moved and cut.
    assert!(reference.last().unwrap() != reference.first().unwrap());
    assert!(fmu.real(vr::EXCAVATED_VOLUME) > 0.0, "no rock was cut");

    // Set the state back on the same instance.
    assert_eq!(fmu.set_state(s), OK, "{:?}", fmu.errors());
    assert_eq!(
        bits(&cs_run(&fmu, 20.0 * h, 30, h).concat()),
        bits(&reference.concat())
    );

    // Deserialize into the same instance.
    let (st, s2) = fmu.deserialize(&blob);
    assert_eq!(st, OK, "{:?}", fmu.errors());
    assert_eq!(fmu.set_state(s2), OK);
    assert_eq!(
        bits(&cs_run(&fmu, 20.0 * h, 30, h).concat()),
        bits(&reference.concat())
    );
    // Serializing the deserialized state gives the same bytes.
    assert_eq!(fmu.serialize(s2), blob);

    // Deserialize into a fresh instance, before initialization.
    let other = Fmu::new("state-cs-other", Kind::Cs);
    let (st, s3) = other.deserialize(&blob);
    assert_eq!(st, OK, "{:?}", other.errors());
    assert_eq!(other.set_state(s3), OK, "{:?}", other.errors());
    assert_eq!(
        bits(&cs_run(&other, 20.0 * h, 30, h).concat()),
        bits(&reference.concat())
    );

    // fmi2GetFMUstate with an existing state overwrites it.
    let mut again = s;
    assert_eq!(
        unsafe { kerf::fmi2::fmi2GetFMUstate(fmu.c, &mut again) },
        OK
    );
    assert_eq!(again, s);
    for st in [s, s2] {
        fmu.free_state(st);
    }
    other.free_state(s3);
}

#[test]
fn co_simulation_state_keeps_whether_a_pose_was_set() {
    // A host that sets positions is obeyed after a restore too.
    let fmu = cs_cutter("state-cs-pose");
    cs_run(&fmu, 0.0, 5, 0.002);
    assert_eq!(fmu.set_real(vr::Z, 1.0), OK); // lift the cutter
    let s = fmu.get_state();
    assert_eq!(fmu.do_step(0.01, 0.002), OK);
    let lifted = fmu.get_reals(&real_outputs()).1;
    assert_eq!(fmu.real(vr::NORMAL_FORCE), 0.0);
    assert_eq!(fmu.set_state(s), OK);
    assert_eq!(fmu.do_step(0.01, 0.002), OK);
    assert_eq!(bits(&fmu.get_reals(&real_outputs()).1), bits(&lifted));
    fmu.free_state(s);
}

/// Model Exchange: a host loop with explicit Euler steps and step events.
fn me_run(fmu: &Fmu, t0: f64, steps: usize, h: f64) -> Vec<Vec<f64>> {
    (1..=steps)
        .map(|k| {
            let t = t0 + k as f64 * h;
            assert_eq!(fmu.set_time(t), OK);
            assert_eq!(
                fmu.set_reals(&[vr::X, vr::VX, vr::WY], &[t, 1.0, 1.0 / R]),
                OK
            );
            let out = fmu.get_reals(&real_outputs()).1;
            let (s, enter, _) = fmu.completed_integrator_step();
            assert_eq!(s, OK, "{:?}", fmu.errors());
            if enter {
                assert_eq!(fmu.enter_event_mode(), OK);
                fmu.event_iteration();
            }
            [out, fmu.get_reals(&real_outputs()).1].concat()
        })
        .collect()
}

#[test]
fn model_exchange_state_replays_bit_for_bit() {
    let h = 0.002;
    let fmu = Fmu::new("state-me", Kind::Me);
    fmu.small_rock();
    fmu.init();
    fmu.event_iteration();
    me_run(&fmu, 0.0, 20, h);
    let s = fmu.get_state();
    let blob = fmu.serialize(s);
    let reference = me_run(&fmu, 20.0 * h, 30, h);
    assert!(fmu.real(vr::EXCAVATED_VOLUME) > 0.0, "no rock was cut");
    assert_eq!(fmu.set_state(s), OK, "{:?}", fmu.errors());
    assert_eq!(
        bits(&me_run(&fmu, 20.0 * h, 30, h).concat()),
        bits(&reference.concat())
    );
    let other = Fmu::new("state-me-other", Kind::Me);
    let (st, s2) = other.deserialize(&blob);
    assert_eq!(st, OK, "{:?}", other.errors());
    assert_eq!(other.set_state(s2), OK, "{:?}", other.errors());
    assert_eq!(
        bits(&me_run(&other, 20.0 * h, 30, h).concat()),
        bits(&reference.concat())
    );
    fmu.free_state(s);
    other.free_state(s2);
}

#[test]
fn state_taken_before_initialization_restores_parameters() {
    let fmu = Fmu::new("state-init", Kind::Cs);
    fmu.small_rock();
    assert_eq!(fmu.enter_init(), OK);
    assert_eq!(fmu.set_real(vr::CUTTER_RADIUS, 0.2), OK);
    let s = fmu.get_state();
    let blob = fmu.serialize(s);
    assert_eq!(fmu.set_real(vr::CUTTER_RADIUS, 0.1), OK);
    fmu.init_exit_only();
    assert_eq!(fmu.set_state(s), OK);
    // Back in initialization mode with the radius of then.
    assert_eq!(fmu.real(vr::CUTTER_RADIUS), 0.2);
    assert_eq!(fmu.exit_init(), OK);
    let other = Fmu::new("state-init-other", Kind::Cs);
    let (st, s2) = other.deserialize(&blob);
    assert_eq!(st, OK);
    assert_eq!(other.set_state(s2), OK);
    assert_eq!(other.real(vr::CUTTER_RADIUS), 0.2);
    fmu.free_state(s);
    other.free_state(s2);
}

trait ExitOnly {
    fn init_exit_only(&self);
}
impl ExitOnly for Fmu {
    fn init_exit_only(&self) {
        assert_eq!(self.exit_init(), OK);
    }
}

#[test]
fn corrupt_truncated_and_foreign_blobs_are_rejected() {
    let fmu = cs_cutter("state-corrupt");
    cs_run(&fmu, 0.0, 5, 0.002);
    let s = fmu.get_state();
    let blob = fmu.serialize(s);
    let before = fmu.get_reals(&real_outputs()).1;

    let mut cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty", vec![]),
        ("truncated", blob[..blob.len() - 1].to_vec()),
        ("half", blob[..blob.len() / 2].to_vec()),
        ("padded", [blob.clone(), vec![0]].concat()),
        (
            "garbage",
            (0..blob.len()).map(|i| (i * 31 % 251) as u8).collect(),
        ),
    ];
    for i in [0, 9, 13, 30, blob.len() / 2, blob.len() - 9, blob.len() - 1] {
        let mut b = blob.clone();
        b[i] ^= 0x40;
        cases.push(("flipped", b));
    }
    for (what, bytes) in &cases {
        let n = fmu.errors().len();
        let (st, p) = fmu.deserialize(bytes);
        assert_eq!(st, ERROR, "{what} accepted");
        assert!(p.is_null());
        assert!(fmu.errors().len() > n, "{what}: no message");
        assert!(
            fmu.last_error().contains("fmi2DeSerializeFMUstate"),
            "{}",
            fmu.last_error()
        );
    }
    // A Co-Simulation state is foreign to a Model Exchange instance.
    let me = Fmu::new("state-corrupt-me", Kind::Me);
    let (st, _) = me.deserialize(&blob);
    assert_eq!(st, ERROR);
    // The instance was not changed by any of this.
    assert_eq!(bits(&fmu.get_reals(&real_outputs()).1), bits(&before));
    assert_eq!(fmu.do_step(0.01, 0.002), OK);
    // Well-formed blobs (valid checksum) of another FMU or format version.
    let reseal = |mut b: Vec<u8>| {
        let n = b.len() - 8;
        let sum = fnv1a64(&b[..n]);
        b[n..].copy_from_slice(&sum.to_le_bytes());
        b
    };
    let mut foreign = blob.clone();
    foreign[8 + 4 + 8 + 4 + 1] ^= 0x01; // a character of the GUID
    let (st, _) = fmu.deserialize(&reseal(foreign));
    assert_eq!(st, ERROR);
    assert!(fmu.last_error().contains("GUID"), "{}", fmu.last_error());
    let mut version = blob.clone();
    version[8] = 99;
    let (st, _) = fmu.deserialize(&reseal(version));
    assert_eq!(st, ERROR);
    assert!(fmu.last_error().contains("version"), "{}", fmu.last_error());
    // The unmodified blob still works.
    let (st, ok) = fmu.deserialize(&reseal(blob.clone()));
    assert_eq!(st, OK);
    fmu.free_state(ok);
    fmu.free_state(s);
}

fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

#[test]
fn a_state_restores_without_its_initial_surface_file() {
    // Make a surface file: cut a little and write it at termination.
    let path = std::env::temp_dir().join(format!(
        "kerf-test-state-surface-{}.rsf",
        std::process::id()
    ));
    let maker = Fmu::new("state-file-maker2", Kind::Cs);
    maker.small_rock();
    assert_eq!(
        maker.set_string(vr::ROCK_FINAL_SURFACE, &path.to_string_lossy()),
        OK
    );
    assert_eq!(maker.set_reals(&[vr::VX, vr::WY], &[1.0, 1.0 / R]), OK);
    maker.init();
    cs_run(&maker, 0.0, 10, 0.002);
    assert_eq!(maker.terminate(), OK, "{:?}", maker.errors());

    // Start from it, cut on, capture the state.
    let fmu = Fmu::new("state-file-user", Kind::Cs);
    fmu.small_rock();
    assert_eq!(
        fmu.set_string(vr::ROCK_INITIAL_SURFACE, &path.to_string_lossy()),
        OK
    );
    assert_eq!(fmu.set_reals(&[vr::VX, vr::WY], &[1.0, 1.0 / R]), OK);
    fmu.init();
    cs_run(&fmu, 0.0, 5, 0.002);
    let s = fmu.get_state();
    let blob = fmu.serialize(s);
    let reference = cs_run(&fmu, 0.01, 10, 0.002);
    std::fs::remove_file(&path).unwrap();

    // The file is gone; the state still restores, in a fresh instance too.
    let other = Fmu::new("state-file-other", Kind::Cs);
    let (st, s2) = other.deserialize(&blob);
    assert_eq!(st, OK, "{:?}", other.errors());
    assert_eq!(other.set_state(s2), OK, "{:?}", other.errors());
    assert_eq!(
        bits(&cs_run(&other, 0.01, 10, 0.002).concat()),
        bits(&reference.concat())
    );
    fmu.free_state(s);
    other.free_state(s2);
}

/// fmusim 0.0.39 frees the states of its FMU-state files by passing the
/// state itself to `fmi2FreeFMUstate`, not the address of its
/// `fmi2FMUstate`. kerf frees that state (it is one of the instance's own)
/// with a warning, so the host's run goes on; another instance's state
/// passed so is refused and stays alive, as does everything else.
#[test]
fn a_state_passed_to_free_as_itself_is_freed_with_a_warning() {
    let a = cs_cutter("fs-itself-a");
    let b = cs_cutter("fs-itself-b");
    let sa = a.get_state();
    let sb = b.get_state();
    assert_eq!(f::fmu_states_of(a.c), 1);
    // another instance's state: not this instance's to free
    let s = unsafe { f::fmi2FreeFMUstate(a.c, sb.cast()) };
    assert_eq!(s, ERROR);
    assert!(
        a.last_error().contains("not a live FMU state"),
        "{:?}",
        a.errors()
    );
    assert_eq!(f::fmu_states_of(b.c), 1);
    // its own: freed, OK, with a warning that says what the host did
    let s = unsafe { f::fmi2FreeFMUstate(a.c, sa.cast()) };
    assert_eq!(s, OK);
    assert_eq!(f::fmu_states_of(a.c), 0);
    let warned = a
        .messages()
        .into_iter()
        .any(|m| m.level == log::Level::Warn && m.text.contains("not the address of one"));
    assert!(warned, "{:?}", a.messages());
    // the instance goes on, and b's state still restores b
    assert_eq!(a.do_step(0.0, 1e-3), OK);
    assert_eq!(b.set_state(sb), OK);
    b.free_state(sb);
    assert_eq!(f::fmu_states_of(b.c), 0);
}

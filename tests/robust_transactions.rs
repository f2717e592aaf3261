//! Issue 11, part 1: a step or event that fails changes nothing. The
//! committed state (FMU state and its serialized form), the outputs and the
//! cache read back exactly as before the call, and the instance goes on.

#[path = "fmi_support.rs"]
mod support;

use support::*;

/// Everything observable: every Real output's bits and the serialized state.
fn observe(fmu: &Fmu) -> (Vec<u64>, Vec<u8>) {
    let (s, out) = fmu.get_reals(&real_outputs());
    assert_eq!(s, OK, "{:?}", fmu.errors());
    let st = fmu.get_state();
    let bytes = fmu.serialize(st);
    fmu.free_state(st);
    (out.iter().map(|v| v.to_bits()).collect(), bytes)
}

/// The repro: CS, x = 0.1, vx = 1, wy = 1/R set in initialization,
/// then fmi2DoStep(0, 1e6). Before the fix it returned fmi2Error after
/// cutting 2.3e-5 m3 that the FMU state showed and fmi2GetReal did not.
#[test]
fn a_refused_step_leaves_state_outputs_and_cache_as_they_were() {
    let fmu = Fmu::new("robust-tx-repro", Kind::Cs);
    assert_eq!(fmu.setup(0.0), OK);
    assert_eq!(fmu.enter_init(), OK);
    assert_eq!(
        fmu.set_reals(&[vr::X, vr::VX, vr::WY], &[0.1, 1.0, 1.0 / R]),
        OK
    );
    assert_eq!(fmu.exit_init(), OK, "{:?}", fmu.errors());
    // the outputs are cached before the call
    let before = observe(&fmu);
    assert_eq!(fmu.do_step(0.0, 1e6), ERROR);
    let e = fmu.last_error();
    assert!(e.contains("fmi2DoStep") && e.contains("split"), "{e}");
    let after = observe(&fmu);
    assert_eq!(before.0, after.0, "outputs changed by a failed step");
    assert!(before.1 == after.1, "FMU state changed by a failed step");
    assert_eq!(fmu.real(vr::EXCAVATED_VOLUME), 0.0);
    // and the instance goes on with the step split as the message says
    assert_eq!(fmu.do_step(0.0, 0.01), OK, "{:?}", fmu.errors());
    assert!(fmu.real(vr::EXCAVATED_VOLUME) > 0.0);
    let st = fmu.get_state();
    assert_eq!(fmu.real(vr::EXCAVATED_VOLUME), {
        // the FMU state and fmi2GetReal agree: restore and read back
        assert_eq!(fmu.set_state(st), OK);
        fmu.real(vr::EXCAVATED_VOLUME)
    });
    fmu.free_state(st);
}

/// A step that would sweep a spinning cutter through 1e4 s (the issue's
/// 56 s call) is refused up front, with the split in the message.
#[test]
fn an_unbounded_spinning_step_is_refused_before_it_starts() {
    let fmu = Fmu::new("robust-tx-spin", Kind::Cs);
    fmu.small_rock();
    fmu.init();
    assert_eq!(fmu.set_reals(&[vr::WZ], &[10.0]), OK);
    let before = observe(&fmu);
    assert_eq!(fmu.do_step(0.0, 1e4), ERROR);
    let e = fmu.last_error();
    assert!(e.contains("split it into at least"), "{e}");
    assert_eq!(before, observe(&fmu));
}

/// Model Exchange: an event whose path since the last commit is too long
/// for one call is refused and leaves everything as it was.
#[test]
fn a_refused_event_commit_changes_nothing() {
    let fmu = Fmu::new("robust-tx-me2", Kind::Me);
    fmu.small_rock();
    assert_eq!(fmu.setup(0.0), OK);
    assert_eq!(fmu.enter_init(), OK);
    assert_eq!(fmu.set_real(vr::NUMERICS_SWEEP_STEP, 2e-5), OK);
    assert_eq!(fmu.exit_init(), OK, "{:?}", fmu.errors());
    fmu.event_iteration();
    // 2.5 m of path at sweepStep 20 um: 125 000 sub-steps, over the bound
    assert_eq!(fmu.set_reals(&[vr::X, vr::VX], &[2.5, 1.0]), OK);
    assert_eq!(fmu.set_time(2.0), OK);
    assert_eq!(fmu.enter_event_mode(), OK);
    let before = observe(&fmu);
    assert_eq!(fmu.new_discrete_states().0, ERROR);
    let e = fmu.last_error();
    assert!(e.contains("split it into at least"), "{e}");
    assert_eq!(before, observe(&fmu));
}

/// The height map's undo record: a rollback puts back exactly the tiles
/// written since `begin_undo` (new ones and shared ones alike), a commit
/// keeps the writes, and a snapshot taken before is untouched either way.
#[test]
fn height_map_rollback_restores_what_was_written() {
    use kerf::core::heightmap::{Grid, HeightMap};
    let g = Grid::new(0.0, 1.0, 0.0, 1.0, 101, 101);
    let mut m = HeightMap::flat(g, 0.0);
    m.set_node(3, 3, -0.5);
    let before = m.clone();
    m.begin_undo();
    m.set_node(3, 3, -1.0); // a tile that existed (shared with `before`)
    m.set_node(4, 3, -1.0);
    m.set_node(90, 90, -2.0); // a tile that did not
    assert_ne!(m, before);
    m.rollback();
    assert_eq!(m, before);
    assert_eq!(m.node(3, 3), -0.5);
    assert_eq!(m.node(90, 90), 0.0);
    assert_eq!(m.allocated_tiles(), before.allocated_tiles());
    m.begin_undo();
    m.set_node(50, 50, -3.0);
    m.commit_undo();
    m.rollback(); // nothing recorded any more
    assert_eq!(m.node(50, 50), -3.0);
    assert_eq!(before.node(50, 50), 0.0);
}

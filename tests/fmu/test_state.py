"""FMU state: get/set and (de)serialization replay bit-for-bit; corrupt blobs are
rejected with fmi2Error and leave the instance usable; Model Exchange trial
evaluations never change the rock."""

import numpy as np
import pytest

import kerfhost as kh
from conftest import H, assert_error_logged, col, start_line, steps

N0, N = 60, 40  # steps before the snapshot (the contact arc is ~41 mm long), steps replayed


def cuts(a):
    """The replayed stretch really cuts rock (so a state that is not restored shows)."""
    v = a[:, col("excavatedVolume")]
    return v[-1] > v[0] and np.all(np.isfinite(a))


def test_get_set_state_replays_bit_for_bit(make):
    inst = make("CS")
    t = start_line(inst, n=N0)
    s = inst.f.getFMUstate()
    a = steps(inst, t, N)
    assert cuts(a)
    inst.f.setFMUstate(s)
    b = steps(inst, t, N)
    assert np.array_equal(a, b), "replay after setFMUstate differs"
    # (a cuts rock, so excavatedVolume and the FMU's time would differ had s not been restored)
    inst.f.freeFMUstate(s)


def test_state_survives_further_snapshots_and_can_be_reused(make):
    inst = make("CS")
    t = start_line(inst, n=N0)
    s1 = inst.f.getFMUstate()
    a = steps(inst, t, N)
    s2 = inst.f.getFMUstate()  # taking another snapshot must not disturb s1
    a2 = steps(inst, t + N * H, 10)
    for _ in range(2):  # a state can be set more than once
        inst.f.setFMUstate(s1)
        assert np.array_equal(steps(inst, t, N), a)
    inst.f.setFMUstate(s2)
    assert np.array_equal(steps(inst, t + N * H, 10), a2)
    inst.f.freeFMUstate(s1)
    inst.f.freeFMUstate(s2)


def test_serialize_round_trip_replays_bit_for_bit(make):
    inst = make("CS")
    t = start_line(inst, n=N0)
    s = inst.f.getFMUstate()
    blob = inst.f.serializeFMUstate(s)
    assert isinstance(blob, bytes) and len(blob) > 0
    assert inst.f.serializeFMUstate(s) == blob, "serializing the same state twice differs"
    a = steps(inst, t, N)
    assert cuts(a)
    s2 = inst.f.deSerializeFMUstate(blob)
    inst.f.setFMUstate(s2)
    b = steps(inst, t, N)
    assert np.array_equal(a, b), "replay after deSerializeFMUstate differs"


def test_serialized_state_restores_in_another_instance(make):
    one = make("CS", name="one")
    t = start_line(one, n=N0)
    blob = one.f.serializeFMUstate(one.f.getFMUstate())
    a = steps(one, t, N)
    other = make("CS", name="other")
    start_line(other, n=0)
    other.f.setFMUstate(other.f.deSerializeFMUstate(blob))
    b = steps(other, t, N)
    assert np.array_equal(a, b), "state moved to another instance replays differently"


CORRUPTIONS = {
    "flip first byte": lambda b: bytes([b[0] ^ 0xFF]) + b[1:],
    "flip a byte in the middle": lambda b: b[:len(b) // 2] + bytes([b[len(b) // 2] ^ 0x5A]) + b[len(b) // 2 + 1:],
    "flip last byte": lambda b: b[:-1] + bytes([b[-1] ^ 0x01]),
    "truncate by one byte": lambda b: b[:-1],
    "truncate to half": lambda b: b[:len(b) // 2],
    "truncate to 4 bytes": lambda b: b[:4],
    "one byte appended": lambda b: b + b"\x00",
}


@pytest.mark.parametrize("how", list(CORRUPTIONS))
def test_corrupt_blob_is_rejected_and_instance_stays_usable(make, how):
    inst = make("CS")
    t = start_line(inst, n=N0)
    good = inst.f.getFMUstate()
    blob = inst.f.serializeFMUstate(good)
    a = steps(inst, t, N)
    bad = CORRUPTIONS[how](blob)
    assert bad != blob
    before = len(inst.log)
    with pytest.raises(kh.FMICallException) as e:
        inst.f.deSerializeFMUstate(bad)
    assert e.value.status == kh.FMI2_ERROR, f"status {e.value.status}, want fmi2Error"
    assert_error_logged(inst, before=before)
    # still usable: restore the good state and replay
    inst.f.setFMUstate(good)
    assert np.array_equal(steps(inst, t, N), a)
    # and the good blob still deserializes
    inst.f.setFMUstate(inst.f.deSerializeFMUstate(blob))
    assert np.array_equal(steps(inst, t, N), a)


def test_state_from_an_instance_with_another_grid(make):
    """A blob made by an instance with other parameters (another height-map grid)
    is either rejected (fmi2Error, message, instance unchanged) or taken whole:
    then the instance replays exactly what the source instance does. Never a mix."""
    sv = {"rock.nx": 301, "rock.ny": 41}
    src = make("CS", name="small")
    ts = start_line(src, sv, n=N0)
    blob = src.f.serializeFMUstate(src.f.getFMUstate())
    ref_src = steps(src, ts, N)
    inst = make("CS")
    t = start_line(inst, n=N0)
    good = inst.f.getFMUstate()
    a = steps(inst, t, N)
    assert not np.array_equal(a, ref_src), "the two grids must give different runs for this test"
    before = len(inst.log)
    try:
        inst.f.setFMUstate(inst.f.deSerializeFMUstate(blob))
    except kh.FMICallException as e:
        assert e.status == kh.FMI2_ERROR
        assert_error_logged(inst, before=before)
        inst.f.setFMUstate(good)
        assert np.array_equal(steps(inst, t, N), a)
    else:
        assert np.array_equal(steps(inst, ts, N), ref_src), \
            "foreign state accepted but the instance does not behave like its source"


# --------------------------------------------------------------------------- Model Exchange

def me_start(inst, start_values=None):
    fixed, _ = kh.line_inputs(inst.fmu_file, start_values)
    inst.initialize(start_values, inputs=dict(fixed, x=0.0))


def me_step(inst, t, x):
    """One accepted ME step to time t with the cutter at x; handles the step event."""
    inst.f.setTime(t)
    inst.set_reals(["x"], [x])
    enter_event, terminate = inst.f.completedIntegratorStep()
    assert not terminate
    if enter_event:
        inst.f.enterEventMode()
        inst.event_iteration()
        inst.f.enterContinuousTimeMode()
    return list(inst.get_reals(kh.REAL_OUTPUTS))


def test_me_trial_evaluations_do_not_change_the_rock(make):
    inst = make("ME")
    me_start(inst)
    for k in range(1, N0 + 1):
        me_step(inst, k * H, k * H)
    t = N0 * H
    base = list(inst.get_reals(kh.REAL_OUTPUTS))
    # trial evaluations at poses ahead and deeper (as a solver would try and reject)
    for dx, dz in [(0.01, 0.0), (0.05, -0.002), (0.2, 0.0)]:
        inst.f.setTime(t + 1e-4)
        inst.set_reals(["x", "z"], [t + dx, kh.REFERENCE["R"] - kh.REFERENCE["p"] + dz])
        trial = inst.get_reals(kh.REAL_OUTPUTS)
        assert np.all(np.isfinite(trial))
    inst.f.setTime(t)
    inst.set_reals(["x", "z"], [t, kh.REFERENCE["R"] - kh.REFERENCE["p"]])
    assert list(inst.get_reals(kh.REAL_OUTPUTS)) == base, "a trial evaluation changed the state"


def test_me_events_commit_the_cut_and_state_replays(make):
    inst = make("ME")
    me_start(inst)
    for k in range(1, N0 + 1):
        me_step(inst, k * H, k * H)
    s = inst.f.getFMUstate()
    a = [me_step(inst, (N0 + k) * H, (N0 + k) * H) for k in range(1, N + 1)]
    vol = [r[kh.REAL_OUTPUTS.index("excavatedVolume")] for r in a]
    assert vol[-1] > vol[0], "ME step events did not commit any cut"
    inst.f.setFMUstate(s)
    b = [me_step(inst, (N0 + k) * H, (N0 + k) * H) for k in range(1, N + 1)]
    assert a == b

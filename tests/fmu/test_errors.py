"""Errors (interface.md): bad parameters, non-finite inputs and calls out of the
FMI state machine return fmi2Error with a logged message, the process survives,
and the instance's committed state is unchanged (restorable, usable)."""

import ctypes
import math

import numpy as np
import pytest

import kerfhost as kh
from conftest import H, assert_error_logged, start_line, steps


def init_expecting_error(inst, start_values):
    """Set parameters and initialise; returns the name of the call that returned
    fmi2Error (parameter errors may show at the setter or at exitInitializationMode)."""
    inst.f.setupExperiment(startTime=0.0)
    try:
        inst.set(start_values)
    except kh.FMICallException as e:
        assert e.status == kh.FMI2_ERROR
        return "set"
    inst.f.enterInitializationMode()
    with pytest.raises(kh.FMICallException) as e:
        inst.f.exitInitializationMode()
    assert e.value.status == kh.FMI2_ERROR, f"status {e.value.status}, want fmi2Error"
    return "exitInitializationMode"


BAD_PARAMETERS = {
    "negative radius": ({"cutter.radius": -1.0}, ["cutter.radius"]),
    "tip wider than its profile": ({"cutter.tipWidth": 0.03}, ["cutter.tipWidth"]),
    "one node along x": ({"rock.nx": 1}, ["rock.nx"]),
    "one node along y": ({"rock.ny": 1}, ["rock.ny"]),
    "missing surface file": ({"rock.initialSurface": "/nonexistent/kerf-test/missing.rsf"},
                             ["/nonexistent/kerf-test/missing.rsf"]),
    "NaN UCS": ({"rock.ucs": float("nan")}, ["rock.ucs"]),
}


@pytest.mark.parametrize("kind", ["CS", "ME"])
@pytest.mark.parametrize("case", list(BAD_PARAMETERS))
def test_bad_parameter_is_an_error_with_a_message(make, case, kind):
    sv, needles = BAD_PARAMETERS[case]
    inst = make(kind)
    where = init_expecting_error(inst, sv)
    assert where in ("set", "exitInitializationMode")
    assert_error_logged(inst, *needles)
    # the instance survives: reset, then a good initialisation works
    inst.f.reset()
    fixed, _ = kh.line_inputs(inst.fmu_file)
    inst.initialize({}, inputs=dict(fixed, x=0.0))
    fn = inst.get("normalForce")
    assert math.isfinite(fn)


def write_rsf(path, nx, ny, x0, x1, y0, y1, z=0.0, bad_line=None):
    xs, ys = np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)
    lines = ["# kerf test surface", "# L K x y z"]
    for i, x in enumerate(xs, 1):
        for j, y in enumerate(ys, 1):
            lines.append(f"{i} {j} {x:.17g} {y:.17g} {z:.17g}")
    if bad_line is not None:
        lines[bad_line - 1] = "1 1 0.0 zero 0.0"
    path.write_text("\n".join(lines) + "\n")


SMALL = {"rock.xMin": -0.05, "rock.xMax": 0.05, "rock.yMin": -0.02, "rock.yMax": 0.02,
         "rock.nx": 11, "rock.ny": 5}


def test_malformed_surface_file_names_file_and_line(make, tmp_path):
    f = tmp_path / "malformed.rsf"
    write_rsf(f, 11, 5, -0.05, 0.05, -0.02, 0.02, bad_line=7)
    inst = make("CS")
    init_expecting_error(inst, {**SMALL, "rock.initialSurface": str(f)})
    msgs = assert_error_logged(inst, str(f))
    assert any("7" in m for m in msgs), f"no message names line 7: {msgs}"


def test_surface_file_of_another_grid_is_an_error(make, tmp_path):
    f = tmp_path / "wronggrid.rsf"
    write_rsf(f, 21, 5, -0.05, 0.05, -0.02, 0.02)  # 21 x 5 nodes, the FMU declares 11 x 5
    inst = make("CS")
    init_expecting_error(inst, {**SMALL, "rock.initialSurface": str(f)})
    assert_error_logged(inst, str(f))


def test_valid_surface_file_is_accepted(make, tmp_path):
    """Control for the two tests above: the same grid, well formed, initialises."""
    f = tmp_path / "good.rsf"
    write_rsf(f, 11, 5, -0.05, 0.05, -0.02, 0.02, z=0.0)
    inst = make("CS")
    inst.initialize({**SMALL, "rock.initialSurface": str(f)}, inputs={"x": 0.0})
    assert not inst.errors()


# --------------------------------------------------------------------------- non-finite inputs

NONFINITE = [("x", float("nan")), ("z", float("inf")), ("vx", float("nan")), ("wy", float("-inf")),
             ("yaw", float("nan")), ("vz", float("inf"))]


@pytest.mark.parametrize("name,value", NONFINITE, ids=[f"{n}={v}" for n, v in NONFINITE])
def test_nonfinite_input_cs_is_an_error_and_state_restorable(make, name, value):
    inst = make("CS")
    t = start_line(inst, n=50)
    s = inst.f.getFMUstate()
    ref = steps(inst, t, 20)
    inst.f.setFMUstate(s)
    before = len(inst.log)
    failed_at = None
    try:
        inst.set_reals([name], [value])
    except kh.FMICallException as e:
        assert e.status == kh.FMI2_ERROR
        failed_at = "setReal"
    if failed_at is None:
        with pytest.raises(kh.FMICallException) as e:
            inst.f.doStep(currentCommunicationPoint=t, communicationStepSize=H)
        assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst, before=before)
    # the committed state is unchanged and restorable
    inst.f.setFMUstate(s)
    fixed, _ = kh.line_inputs(inst.fmu_file)
    inst.set(dict(fixed, y=0.0, yaw=0.0, vz=0.0))
    assert np.array_equal(steps(inst, t, 20), ref)


@pytest.mark.parametrize("name,value", NONFINITE[:3], ids=[f"{n}={v}" for n, v in NONFINITE[:3]])
def test_nonfinite_input_me_is_an_error(make, name, value):
    inst = make("ME")
    fixed, _ = kh.line_inputs(inst.fmu_file)
    inst.initialize({}, inputs=dict(fixed, x=0.0))
    s = inst.f.getFMUstate()
    good = inst.get_reals(kh.REAL_OUTPUTS)
    before = len(inst.log)
    with pytest.raises(kh.FMICallException) as e:
        inst.set_reals([name], [value])
        inst.get_reals(["normalForce"])
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst, before=before)
    inst.f.setFMUstate(s)
    inst.set(dict(fixed, x=0.0))
    assert inst.get_reals(kh.REAL_OUTPUTS) == good


@pytest.mark.parametrize("name,value,shown,allowed", [
    ("vx", 1e300, "1e300", "at most 1e4 m/s"),
    ("z", -1e30, "-1e30", "at most 1e6 m from the origin"),
    ("roll", 5e3, "5000", "at most 1e3 rad"),
])
def test_absurd_finite_input_names_its_value_and_range(make, name, value, shown, allowed):
    """A finite but absurd input is refused at the step, with a message a user
    can read: the input, its value in short form (not 301 digits) and the
    values it may take."""
    inst = make("CS")
    t = start_line(inst, n=5)
    inst.set_reals([name], [value])
    before = len(inst.log)
    with pytest.raises(kh.FMICallException) as e:
        inst.f.doStep(currentCommunicationPoint=t, communicationStepSize=H)
    assert e.value.status == kh.FMI2_ERROR
    msgs = assert_error_logged(inst, f"input {name} = {shown} ", allowed, before=before)
    assert all(len(m) < 200 for m in msgs), msgs


# --------------------------------------------------------------------------- state machine

def raw(inst, fname, argtypes, *args):
    """Call an exported fmi2 function that fmpy does not bind for this interface."""
    fn = getattr(inst.f.dll, fname)
    fn.argtypes = [ctypes.c_void_p] + argtypes
    fn.restype = ctypes.c_int
    return fn(inst.f.component, *args)


def clean_run(make, n=5):
    inst = make("CS", name="clean")
    t = start_line(inst, n=0)
    return steps(inst, t, n)


def test_do_step_before_initialization(make):
    ref = clean_run(make)
    inst = make("CS")
    with pytest.raises(kh.FMICallException) as e:
        inst.f.doStep(currentCommunicationPoint=0.0, communicationStepSize=H)
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst, "doStep")
    # nothing changed: the normal sequence still works and gives the clean result
    t = start_line(inst, n=0)
    assert np.array_equal(steps(inst, t, 5), ref)


def test_do_step_in_initialization_mode(make):
    inst = make("CS")
    inst.f.setupExperiment(startTime=0.0)
    inst.f.enterInitializationMode()
    with pytest.raises(kh.FMICallException) as e:
        inst.f.doStep(currentCommunicationPoint=0.0, communicationStepSize=H)
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst, "doStep")


def test_exit_initialization_without_enter(make):
    inst = make("CS")
    inst.f.setupExperiment(startTime=0.0)
    with pytest.raises(kh.FMICallException) as e:
        inst.f.exitInitializationMode()
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst)


def test_enter_initialization_twice(make):
    inst = make("CS")
    inst.f.setupExperiment(startTime=0.0)
    inst.f.enterInitializationMode()
    with pytest.raises(kh.FMICallException) as e:
        inst.f.enterInitializationMode()
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst)


def test_get_real_after_terminate_is_legal_and_do_step_is_not(make):
    inst = make("CS")
    t = start_line(inst, n=5)
    last = inst.get_reals(kh.REAL_OUTPUTS)
    inst.f.terminate()
    assert inst.get_reals(kh.REAL_OUTPUTS) == last, "getReal after terminate must return the last values"
    with pytest.raises(kh.FMICallException) as e:
        inst.f.doStep(currentCommunicationPoint=t, communicationStepSize=H)
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst)
    # reset brings it back to Instantiated; a new run works
    inst.f.reset()
    start_line(inst, n=2)


def test_unknown_value_reference(make):
    inst = make("CS")
    start_line(inst, n=0)
    bad = max(v.valueReference for v in inst.fmu_file.md.modelVariables if v.type == "Real") + 1000
    with pytest.raises(kh.FMICallException) as e:
        inst.f.getReal([bad])
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst)


def test_fixed_parameter_cannot_change_after_initialization(make):
    inst = make("CS")
    start_line(inst, n=0)
    fixed = [v.name for v in inst.fmu_file.md.modelVariables
             if v.causality == "parameter" and v.variability == "fixed" and v.type == "Real"]
    assert "cutter.radius" in fixed, "the disc geometry is a fixed parameter"
    r = inst.get("cutter.radius")
    with pytest.raises(kh.FMICallException) as e:
        inst.set({"cutter.radius": 0.3})
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst, "cutter.radius")
    assert inst.get("cutter.radius") == r


def test_model_exchange_call_on_a_cosimulation_instance(make):
    inst = make("CS")
    start_line(inst, n=0)
    assert raw(inst, "fmi2SetTime", [ctypes.c_double], 0.5) == kh.FMI2_ERROR
    ev, term = ctypes.c_int(0), ctypes.c_int(0)
    rc = raw(inst, "fmi2CompletedIntegratorStep", [ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p],
             1, ctypes.addressof(ev), ctypes.addressof(term))
    assert rc == kh.FMI2_ERROR
    assert_error_logged(inst)
    steps(inst, 0.0, 2)  # still usable


def test_cosimulation_call_on_a_model_exchange_instance(make):
    inst = make("ME")
    fixed, _ = kh.line_inputs(inst.fmu_file)
    inst.initialize({}, inputs=dict(fixed, x=0.0))
    assert raw(inst, "fmi2DoStep", [ctypes.c_double, ctypes.c_double, ctypes.c_int], 0.0, H, 1) == kh.FMI2_ERROR
    assert_error_logged(inst)
    assert math.isfinite(inst.get("normalForce"))


def test_negative_step_size_is_an_error(make):
    inst = make("CS")
    t = start_line(inst, n=3)
    with pytest.raises(kh.FMICallException) as e:
        inst.f.doStep(currentCommunicationPoint=t, communicationStepSize=-H)
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst)

"""Issue 11 through a real host (fmpy): a refused step changes nothing and the
run goes on; out-of-range parameters name their range; a FIFO as surface file
is refused instead of blocking; a sparse surface written for a large face
loads with numpy.loadtxt and kerfhost.load_rsf."""

import os
import threading

import numpy as np
import pytest

import kerfhost as kh
from conftest import assert_error_logged

R = kh.REFERENCE["R"]


def snapshot(inst):
    s = inst.f.getFMUstate()
    b = bytes(inst.f.serializeFMUstate(s))
    inst.f.freeFMUstate(s)
    return b


def test_refused_step_leaves_state_and_outputs_as_they_were(make):
    """The issue's repro: CS, x = 0.1, vx = 1, wy = 1/R, doStep(0, 1e6)."""
    inst = make("CS")
    inst.initialize(inputs={"x": 0.1, "vx": 1.0, "wy": 1.0 / R})
    outs = ["Fx", "Fz", "rollingForce", "excavatedVolume", "cuttingEnergy"]
    before, state = inst.get_reals(outs), snapshot(inst)
    n = len(inst.log)
    with pytest.raises(kh.FMICallException) as e:
        inst.f.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e6)
    assert e.value.status == kh.FMI2_ERROR
    assert_error_logged(inst, "doStep", "split", before=n)
    assert inst.get_reals(outs) == before
    assert snapshot(inst) == state
    assert inst.get("excavatedVolume") == 0.0
    # split as the message says: the run goes on
    inst.f.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    assert inst.get("excavatedVolume") > 0.0


@pytest.mark.parametrize("name,value", [
    ("cutter.radius", 1e9),
    ("numerics.arcStepCells", 1e-9),
    ("numerics.ringStepCells", 0.0),
    ("numerics.sweepStep", 1e-300),
    ("rock.ucs", 1e308),
    ("numerics.elasticDepth", 1e300),
])
def test_out_of_range_parameter_names_its_range(make, fmu, name, value):
    inst = make("CS")
    lo, hi = float(fmu.var(name).min), float(fmu.var(name).max)
    assert not lo <= value <= hi
    inst.f.setupExperiment(startTime=0.0)
    inst.set({name: value})
    inst.f.enterInitializationMode()
    with pytest.raises(kh.FMICallException):
        inst.f.exitInitializationMode()
    assert_error_logged(inst, name, "allowed range")


def test_fifo_as_initial_surface_is_refused_without_blocking(make, tmp_path):
    fifo = tmp_path / "surface.fifo"
    os.mkfifo(fifo)
    inst = make("CS")
    done = {}

    def run():
        inst.f.setupExperiment(startTime=0.0)
        inst.set({"rock.initialSurface": str(fifo)})
        inst.f.enterInitializationMode()
        try:
            inst.f.exitInitializationMode()
            done["status"] = "ok"
        except kh.FMICallException as e:
            done["status"] = e.status

    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(60)
    if t.is_alive():
        # unblock the FMU so the process can end, then fail
        with open(fifo, "w"):
            pass
        pytest.fail("fmi2ExitInitializationMode blocked on a FIFO")
    assert done["status"] == kh.FMI2_ERROR
    assert_error_logged(inst, "not a regular file")


def test_large_face_writes_a_sparse_surface(make, tmp_path):
    f = tmp_path / "large.rsf"
    grid = {"rock.xMin": -0.25, "rock.xMax": 0.75, "rock.yMin": -0.2, "rock.yMax": 0.2,
            "rock.nx": 2001, "rock.ny": 801, "rock.finalSurface": str(f)}  # 1.6e6 nodes
    inst = make("CS")
    fixed, _ = kh.line_inputs(inst.fmu_file)
    inst.initialize(grid, inputs=dict(fixed, x=0.0))
    for k in range(20):
        inst.f.doStep(currentCommunicationPoint=k * 2e-3, communicationStepSize=2e-3)
    vol = inst.get("excavatedVolume")
    inst.f.terminate()
    text = f.read_text()
    assert "# sparse: unlisted nodes are at z0 = 0" in text
    a = np.loadtxt(f, comments="#", ndmin=2)
    assert a.shape[1] == 5 and 1000 < a.shape[0] < 2001 * 801 // 10
    X, Y, Z = kh.load_rsf(f)
    assert Z.shape == (2001, 801) and np.all(np.isfinite(Z))
    assert np.allclose(X[:, 0], np.linspace(-0.25, 0.75, 2001), atol=1e-12)
    removed = -np.sum(Z) * 0.5e-3 * 0.5e-3
    assert removed == pytest.approx(vol, rel=0.05)

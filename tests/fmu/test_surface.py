"""Surface files (.rsf): the surface written at fmi2Terminate loads with
numpy.loadtxt, has the declared grid, shows the groove, and starts a new run
(rock.initialSurface) from the same rock."""

import numpy as np
import pytest

import kerfhost as kh
from conftest import start_line, steps

GRID = {"rock.xMin": -0.1, "rock.xMax": 0.2, "rock.yMin": -0.03, "rock.yMax": 0.03,
        "rock.nx": 301, "rock.ny": 61}  # 1 mm cells
N = 100


@pytest.fixture
def cut_surface(make, tmp_path):
    f = tmp_path / "after-cut.rsf"
    inst = make("CS")
    start_line(inst, {**GRID, "rock.finalSurface": str(f)}, n=N)
    vol = inst.get("excavatedVolume")
    inst.f.terminate()
    assert f.is_file(), "rock.finalSurface was not written at fmi2Terminate"
    return f, vol


def test_final_surface_has_the_declared_grid(cut_surface):
    f, _ = cut_surface
    a = np.loadtxt(f, comments="#", ndmin=2)
    assert a.shape == (301 * 61, 5)
    X, Y, Z = kh.load_rsf(f)
    assert np.allclose(X[:, 0], np.linspace(-0.1, 0.2, 301), atol=1e-12)
    assert np.allclose(Y[0, :], np.linspace(-0.03, 0.03, 61), atol=1e-12)
    assert np.all(np.isfinite(Z))


def test_final_surface_shows_the_groove(cut_surface):
    f, vol = cut_surface
    X, Y, Z = kh.load_rsf(f)
    p = kh.REFERENCE["p"]
    j0 = int(np.argmin(np.abs(Y[0])))
    mid = (X[:, 0] > 0.02) & (X[:, 0] < 0.08)
    # the centre line of the groove is at the full depth, the rock far aside is untouched
    assert np.allclose(Z[mid, j0], -p, atol=0.02 * p)
    assert np.all(Z[:, np.abs(Y[0]) > 0.02] == 0.0)
    assert np.all(Z <= 0.0)
    # the excavated volume is what the surface shows (trapezoid-free: 1 mm^2 per node)
    removed = -np.sum(Z) * 1e-3 * 1e-3
    assert removed == pytest.approx(vol, rel=0.05)


def test_initial_surface_round_trip(make, cut_surface, tmp_path):
    f, _ = cut_surface
    g = tmp_path / "again.rsf"
    inst = make("CS")
    inst.initialize({**GRID, "rock.initialSurface": str(f), "rock.finalSurface": str(g)},
                    inputs={"x": -0.09, "z": 0.5})  # cutter far above the rock: no cutting
    assert inst.get("inContact") is False
    inst.f.terminate()
    a, b = np.loadtxt(f, comments="#"), np.loadtxt(g, comments="#")
    assert np.array_equal(a, b), "reading and writing back a surface changed it"


def test_initial_surface_carries_the_groove(make, cut_surface):
    """A cutter placed in the groove read from file feels less than one on fresh rock."""
    f, _ = cut_surface
    fresh, grooved = make("CS", name="fresh"), make("CS", name="grooved")
    fixed, _ = kh.line_inputs(fresh.fmu_file)
    at = dict(fixed, x=0.05)
    fresh.initialize(GRID, t0=0.05, inputs=at)
    grooved.initialize({**GRID, "rock.initialSurface": str(f)}, t0=0.05, inputs=at)
    i = kh.REAL_OUTPUTS.index("normalForce")
    f_fresh, f_groove = steps(fresh, 0.05, 1)[0, i], steps(grooved, 0.05, 1)[0, i]
    assert f_fresh > 0
    assert f_groove < 0.5 * f_fresh, f"in the groove {f_groove:.0f} N, on fresh rock {f_fresh:.0f} N"

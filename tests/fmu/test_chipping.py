"""Chipping through the FMU (issue 9, contract "Rock breaking out between grooves").

The scene is thesis Table 3's LCM row as a relieved cut: a groove 3.8 mm deep
and 13 mm wide along x at y = 0 (an initial .rsf surface), and the reference
cut at y = -51 mm beside it. The face is widened to y = -0.2 so that the
unrelieved side has no free edge within the crack reach (kappa p = 57 mm).
"""
import numpy as np
import pytest

import kerfhost as kh

S = 0.051
GRID = {"rock.yMin": -0.2, "rock.yMax": 0.1, "rock.ny": 301}


@pytest.fixture(scope="module")
def grooved(tmp_path_factory, fmu):
    nx = int(fmu.start("rock.nx"))
    x0, x1 = float(fmu.start("rock.xMin")), float(fmu.start("rock.xMax"))
    ny = GRID["rock.ny"]
    xs = np.linspace(x0, x1, nx)
    ys = np.linspace(GRID["rock.yMin"], GRID["rock.yMax"], ny)
    L, K = np.meshgrid(np.arange(1, nx + 1), np.arange(1, ny + 1), indexing="ij")
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    Z = np.where(np.abs(Y) <= 0.0065 + 1e-9, -0.0038, 0.0)
    path = tmp_path_factory.mktemp("chips") / "groove.rsf"
    np.savetxt(path, np.column_stack([L.ravel(), K.ravel(), X.ravel(), Y.ravel(), Z.ravel()]),
               fmt=["%d", "%d", "%.9g", "%.9g", "%.9g"], header="L K x y z")
    return str(path)


def scene(grooved, chipping=True, seed=1):
    sv = dict(GRID, **{"rock.initialSurface": grooved, "y": -S})
    if chipping is not None:
        sv["chipping.enabled"] = chipping
    sv["chipping.seed"] = seed
    return sv


OUT = kh.REAL_OUTPUTS + ["chippedVolume"]


def cs_run(make, sv, n=800):
    inst = make("CS")
    res = kh.run_line_cs(inst, start_values=sv, n_steps=n, outputs=OUT)
    res["chipCount"] = inst.get("chipCount")
    return res, inst


def test_a_relieved_cs_pass_chips_and_is_pushed_towards_the_relieved_side(make, grooved):
    res, _ = cs_run(make, scene(grooved))
    assert res["chipCount"] > 0
    vol, chips = res["excavatedVolume"][-1], res["chippedVolume"][-1]
    assert 0 < chips < vol
    # chipped and excavated volume only grow
    assert np.all(np.diff(res["chippedVolume"]) >= 0)
    w = (res["x"] >= 0.2) & (res["x"] <= 0.7)
    side, normal = res["sideForce"][w].mean(), res["normalForce"][w].mean()
    # the old groove is at +y (cutter +y): the intact rock at -y pushes the
    # disc towards it (LCM row: 11.2 kN, 14 % of the normal force)
    assert side > 0.05 * normal, (side, normal)


def test_chipping_is_off_by_default(make, grooved):
    res, _ = cs_run(make, scene(grooved, chipping=None), n=300)
    assert res["chipCount"] == 0
    assert np.all(res["chippedVolume"] == 0.0)
    assert abs(res["sideForce"][100:].mean()) < 1.0  # N: a cut beside a groove, no chips


def test_model_exchange_commits_the_same_chips_as_co_simulation(make, grooved, fmu):
    sv = scene(grooved)
    cs, _ = cs_run(make, sv, n=500)
    me = kh.run_line_me(fmu, solver="CVode", start_values=sv, stop=0.5,
                        outputs=["chippedVolume", "excavatedVolume"])
    # chips are places on the path: the same ones break out whatever the host's
    # steps; their volume follows the grooves (cut in other sub-steps): 2 %
    assert me["chippedVolume"][-1] == pytest.approx(cs["chippedVolume"][-1], rel=0.02)


def test_fmu_state_replays_chips_bit_for_bit(make, grooved):
    inst = make("CS")
    sv = scene(grooved, seed=5)
    fixed, _ = kh.line_inputs(inst.fmu_file, sv)
    inst.initialize(sv, inputs=dict(fixed, x=0.0))

    def run(t0, n):
        rows = []
        for k in range(n):
            t = t0 + k * 1e-3
            inst.set_reals(["x"], [t])
            inst.f.doStep(currentCommunicationPoint=t, communicationStepSize=1e-3)
            rows.append(list(inst.get_reals(OUT)) + [inst.get("chipCount")])
        return rows

    run(0.0, 150)
    blob = inst.f.serializeFMUstate(inst.f.getFMUstate())
    a = run(0.15, 200)
    inst.f.setFMUstate(inst.f.deSerializeFMUstate(blob))
    b = run(0.15, 200)
    assert a == b
    assert a[-1][-1] > a[0][-1]  # chips broke out in the replayed stretch

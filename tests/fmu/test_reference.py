"""The thesis reference scene (Table 2): 17 in disc, p = 3.8 mm, 1 m at 1 m/s,
rolling without slip, 1 ms communication / output step.  Steady means over the
middle of the cut (0.2 m <= x <= 0.8 m) against the CSM closed form (thesis
eqs 13-17), and Model Exchange (CVode, Euler) against Co-Simulation."""

import numpy as np
import pytest

import kerfhost as kh

pytestmark = pytest.mark.physics

LO, HI = 0.2, 0.8


def test_cs_reference_outputs_are_finite_and_in_contact(cs_reference):
    for name in kh.REAL_OUTPUTS:
        assert np.all(np.isfinite(cs_reference[name])), f"{name} has non-finite values"
    assert len(cs_reference["time"]) == 1001


def test_cs_normal_force_matches_csm(cs_reference, theory):
    fn = kh.steady_mean(cs_reference, "normalForce", LO, HI)
    assert fn == pytest.approx(theory["FN"], rel=1e-3), \
        f"normal {fn / 1e3:.4f} kN vs CSM {theory['FN'] / 1e3:.4f} kN ({fn / theory['FN'] - 1:+.3%})"


def test_cs_rolling_force_matches_csm(cs_reference, theory):
    fr = kh.steady_mean(cs_reference, "rollingForce", LO, HI)
    assert fr == pytest.approx(theory["FR"], rel=1e-3), \
        f"rolling {fr / 1e3:.5f} kN vs CSM {theory['FR'] / 1e3:.5f} kN ({fr / theory['FR'] - 1:+.3%})"


def test_cs_side_force_vanishes_on_a_straight_symmetric_cut(cs_reference):
    fn = kh.steady_mean(cs_reference, "normalForce", LO, HI)
    fs = kh.steady_mean(cs_reference, "sideForce", LO, HI)
    assert abs(fs) < 1e-3 * abs(fn), f"side {fs:.3f} N vs normal {fn:.1f} N"


def test_cs_every_sample_of_the_steady_cut_is_near_csm(cs_reference, theory):
    """Not only the mean: no sample in the steady window strays more than 1 %."""
    sel = (cs_reference["x"] >= LO) & (cs_reference["x"] <= HI)
    fn = cs_reference["normalForce"][sel]
    worst = np.max(np.abs(fn / theory["FN"] - 1))
    assert worst < 1e-2, f"normal force strays {worst:.2%} from CSM inside the steady window"


def test_cs_penetration_and_contact_angle(cs_reference, theory):
    p = kh.steady_mean(cs_reference, "penetration", LO, HI)
    phi = kh.steady_mean(cs_reference, "contactAngle", LO, HI)
    assert p == pytest.approx(kh.REFERENCE["p"], rel=1e-3)
    assert phi == pytest.approx(theory["phi"], rel=1e-3)


def test_cs_rock_record_grows_with_the_cut(cs_reference):
    vol = cs_reference["excavatedVolume"]
    energy = cs_reference["cuttingEnergy"]
    sel = cs_reference["x"] >= LO
    assert np.all(np.diff(vol[sel]) > 0), "excavatedVolume must grow while cutting fresh rock"
    assert np.all(np.diff(energy[sel]) > 0), "cuttingEnergy must grow while cutting"
    se = cs_reference["specificEnergy"][-1]
    assert se == pytest.approx(energy[-1] / vol[-1], rel=1e-9)


@pytest.fixture(scope="module")
def me_runs(fmu):
    return {solver: kh.run_line_me(fmu, solver=solver, stop=1.0, output_interval=1e-3)
            for solver in ("CVode", "Euler")}


@pytest.mark.parametrize("solver", ["CVode", "Euler"])
@pytest.mark.parametrize("name", ["normalForce", "rollingForce"])
def test_model_exchange_agrees_with_cosimulation(me_runs, cs_reference, solver, name):
    me = me_runs[solver]
    assert np.all(np.isfinite(me[name]))
    assert me["time"][-1] == pytest.approx(1.0)
    m, c = kh.steady_mean(me, name, LO, HI), kh.steady_mean(cs_reference, name, LO, HI)
    assert m == pytest.approx(c, rel=5e-3), f"ME/{solver} {m:.1f} N vs CS {c:.1f} N ({m / c - 1:+.3%})"


@pytest.mark.parametrize("solver", ["CVode", "Euler"])
def test_model_exchange_side_force_small(me_runs, solver):
    me = me_runs[solver]
    fn = kh.steady_mean(me, "normalForce", LO, HI)
    fs = kh.steady_mean(me, "sideForce", LO, HI)
    assert abs(fs) < 5e-3 * abs(fn)


@pytest.mark.parametrize("solver", ["CVode", "Euler"])
def test_model_exchange_cuts_the_rock(me_runs, cs_reference, solver):
    """The ME events commit the cut: after 1 m about as much rock is gone as in CS."""
    v_me = me_runs[solver]["excavatedVolume"][-1]
    v_cs = cs_reference["excavatedVolume"][-1]
    assert v_cs > 0
    assert v_me == pytest.approx(v_cs, rel=2e-2)


def test_cs_integrates_the_pose_when_the_host_sets_only_velocities(fmu, cs_reference):
    """Velocity inputs only (x never set after initialisation): the FMU carries the
    pose itself, so the run matches the one where the host feeds x(t) = v t."""
    inst = fmu.instance("CS", name="velocity-only")
    try:
        res = kh.run_line_cs(inst, n_steps=400, h=1e-3, feed_x=False)
    finally:
        inst.free()
    for name in ("normalForce", "rollingForce", "excavatedVolume"):
        a, b = res[name], cs_reference[name][:401]
        assert np.allclose(a, b, rtol=1e-6, atol=1e-6 * np.max(np.abs(b))), \
            f"{name}: velocity-only run differs from the fed-x run by {np.max(np.abs(a - b)):.3g}"


@pytest.mark.parametrize("h", [0.005, 0.02])
def test_cs_long_steps_leave_no_uncut_rock(fmu, cs_reference, theory, h):
    """CS cuts along the whole path of a step: 5 mm and 20 mm steps remove the
    same rock as 1 mm steps and see the same steady forces."""
    inst = fmu.instance("CS", name=f"h{h}")
    try:
        res = kh.run_line_cs(inst, n_steps=round(1.0 / h), h=h)
    finally:
        inst.free()
    v, v_ref = res["excavatedVolume"][-1], cs_reference["excavatedVolume"][-1]
    assert v == pytest.approx(v_ref, rel=1e-2), f"h = {h}: {v * 1e6:.3f} cm3 vs {v_ref * 1e6:.3f} cm3 at 1 ms"
    fn = kh.steady_mean(res, "normalForce", LO, HI)
    assert fn == pytest.approx(theory["FN"], rel=1e-3)

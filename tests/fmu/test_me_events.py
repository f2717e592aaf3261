"""Model Exchange events through fmpy: one event per numerics.sweepStep of
travel (the event indicator), whatever the solver's steps, and the same cut,
forces and cutting energy as Co-Simulation.

The PyFMI-like host loop (CVode in one-step mode with
fmi2CompletedIntegratorStep after every internal step, as PyFMI 2.21 does)
is tools/me_events.py's; with a step event after every step it made an event
per internal step (1.39 million events for 20 mm of roll).
"""

import numpy as np
import pytest

import kerfhost as kh
import me_events
from conftest import H

STOP = 0.1  # s = 0.1 m at 1 m/s
SWEEP = 1e-3


@pytest.fixture(scope="module")
def reference(fmu):
    inst = fmu.instance("CS", name="me-events-reference")
    try:
        return kh.run_line_cs(inst, n_steps=round(STOP / H), h=H)
    finally:
        inst.free()


def me_run(fmu, solver="CVode", start_values=None, step_size=None, stop=STOP):
    n = {"events": 0, "cis": 0}

    def calls(line):
        if line.startswith("fmi2EnterEventMode"):
            n["events"] += 1
        elif line.startswith("fmi2CompletedIntegratorStep"):
            n["cis"] += 1

    fixed, _ = kh.line_inputs(fmu, start_values)
    sig = np.array([(0.0, 0.0, fixed["z"], fixed["vx"], fixed["wy"]),
                    (stop, fixed["vx"] * stop, fixed["z"], fixed["vx"], fixed["wy"])],
                   dtype=[("time", float), ("x", float), ("z", float), ("vx", float), ("wy", float)])
    kw = {"step_size": step_size} if step_size else {}
    r = kh.fmpy.simulate_fmu(str(fmu.path), fmi_type="ModelExchange", solver=solver,
                             start_values=dict(start_values or {}), input=sig, stop_time=stop,
                             output_interval=H, output=["rollingForce", "normalForce",
                                                        "cuttingEnergy", "excavatedVolume"],
                             fmi_call_logger=calls, **kw)
    res = {k: np.asarray(r[k], dtype=float) for k in r.dtype.names}
    res["x"] = fixed["vx"] * res["time"]
    return res, n


def test_fmpy_cvode_one_event_per_sweep_step_and_agrees_with_cs(fmu, reference):
    res, n = me_run(fmu, "CVode")
    travel = STOP  # m
    assert abs(n["events"] - travel / SWEEP) <= 1, n
    for name in ("normalForce", "rollingForce"):
        m = kh.steady_mean(res, name, 0.02, 0.09)
        c = kh.steady_mean(reference, name, 0.02, 0.09)
        assert m == pytest.approx(c, rel=5e-3), name
    # the same cut and the same energy (they differed by 1.5 F_R h = 8.6 J)
    for name in ("excavatedVolume", "cuttingEnergy"):
        assert res[name][-1] == pytest.approx(reference[name][-1], rel=1e-9), name


@pytest.mark.parametrize("h", [2.5e-4, 1e-3])
def test_fmpy_euler_event_count_does_not_depend_on_the_step(fmu, reference, h):
    res, n = me_run(fmu, "Euler", step_size=h)
    assert abs(n["events"] - STOP / SWEEP) <= 1, (h, n)
    assert res["excavatedVolume"][-1] == pytest.approx(reference["excavatedVolume"][-1], rel=1e-9)
    assert res["cuttingEnergy"][-1] == pytest.approx(reference["cuttingEnergy"][-1], rel=1e-9)


def test_events_follow_the_sweep_step_parameter(fmu):
    _, n = me_run(fmu, "CVode", start_values={"numerics.sweepStep": 2e-3}, stop=0.05)
    assert abs(n["events"] - 0.05 / 2e-3) <= 1, n


def test_pyfmi_like_cvode_makes_one_event_per_sweep_step_not_per_internal_step(fmu, reference):
    r = me_events.run_pyfmi_like(fmu.path, stop=STOP, tol=1e-6, max_events=10 * round(STOP / SWEEP))
    assert r["t"] == pytest.approx(STOP)
    assert abs(r["events"] - STOP / SWEEP) <= 1, r
    # CVode's root finding or a step ending on the crossing; the backstop
    # time event (two sweep steps ahead) is never reached
    assert r["kinds"]["state"] > 0 and r["kinds"]["time"] == 0, r
    assert r["steps"] > r["events"]  # more internal steps than events: not one event per step
    assert r["rollingForce"] == pytest.approx(reference["rollingForce"][-1], rel=5e-3)
    assert r["excavatedVolume"] == pytest.approx(reference["excavatedVolume"][-1], rel=1e-6)
    assert r["cuttingEnergy"] == pytest.approx(reference["cuttingEnergy"][-1], rel=1e-6)


def test_an_event_back_in_time_commits_nothing_and_the_roll_goes_on(fmu):
    """A host that goes back in time for one more event (PyFMI 2.21's
    ExplicitEuler, near its stop time: host bug H6, docs/hosts.md) gets
    fmi2OK, one warning and no cut; the next event forward cuts and books
    what a host that never went back gets."""
    R = kh.REFERENCE["R"]

    def roll(name, back):
        inst = fmu.instance("ME", name=name)
        try:
            inst.initialize({}, inputs={"vx": 1.0, "wy": 1.0 / R})
            f = inst.f

            def event_at(t):
                f.setTime(t)
                inst.set_reals(["x"], [t])
                f.enterEventMode()
                inst.event_iteration()
                f.enterContinuousTimeMode()

            for k in (1, 2, 3):
                event_at(k * 1e-3)
            if back:
                v, e = inst.get_reals(["excavatedVolume", "cuttingEnergy"])
                for t in (2e-3, 2.5e-3):
                    event_at(t)
                    assert list(inst.get_reals(["excavatedVolume", "cuttingEnergy"])) == [v, e]
                warnings = [r.message for r in inst.log if r.status == 1]  # fmi2Warning
                assert len(warnings) == 1 and "before the last commit" in warnings[0], warnings
                assert not inst.errors(), inst.errors()
            event_at(4e-3)
            return list(inst.get_reals(["excavatedVolume", "cuttingEnergy"]))
        finally:
            inst.free()

    straight = roll("me-back-no", back=False)
    assert straight[0] > 0 and straight[1] > 0
    assert roll("me-back-yes", back=True) == straight

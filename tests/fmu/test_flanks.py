"""The flanked CCS section through a real host (fmpy; docs/flanks.md): the two
parameters are in the model description with the units of the other angles
and lengths, flanks make a deep cut bear on them (the core's table: 30 deg
flanks give 1.33x the normal force at 8 mm), and a flank shallower than the
tip's edge is refused naming the rule."""

import math

import pytest

import kerfhost as kh
from conftest import H, assert_error_logged


def test_flank_parameters_are_declared(fmu):
    f = fmu.var("cutter.flankAngle")
    assert (f.causality, f.variability, f.unit, f.displayUnit) == ("parameter", "fixed", "rad", "deg")
    assert float(f.start) == 0.0 and float(f.min) == 0.0 and float(f.max) == 1.4
    w = fmu.var("cutter.hubWidth")
    assert (w.causality, w.unit, w.displayUnit) == ("parameter", "m", "mm")
    assert float(w.start) == 0.0762


def test_a_deep_cut_bears_on_the_flanks(make):
    means = {}
    for f in (0.0, 30.0):
        inst = make("CS", name=f"flank{f}")
        res = kh.run_line_cs(inst, {"cutter.flankAngle": math.radians(f)}, n_steps=150, h=H,
                             depth=8e-3)
        means[f] = (kh.steady_mean(res, "normalForce", 0.06, 0.14),
                    kh.steady_mean(res, "rollingForce", 0.06, 0.14))
    n0, r0 = means[0.0]
    n1, r1 = means[30.0]
    # the core's fresh 8 mm cut: 87.9 -> 116.7 kN normal, 12.1 -> 14.8 kN rolling
    assert 1.25 < n1 / n0 < 1.42, means
    assert 1.1 < r1 / r0 < 1.35, means


def test_a_flank_shallower_than_the_tip_edge_is_refused(make):
    inst = make("CS")
    inst.f.setupExperiment(startTime=0.0)
    # the thesis's tip: the edge normal leans asin(6.5 / 12.7) = 30.8 deg, so
    # flanks may lean at most 59.2 deg
    inst.set({"cutter.flankAngle": math.radians(60.0)})
    inst.f.enterInitializationMode()
    with pytest.raises(kh.FMICallException):
        inst.f.exitInitializationMode()
    assert_error_logged(inst, "cutter.flankAngle", "non-convex")

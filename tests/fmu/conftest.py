"""Fixtures of the black-box harness against kerf.fmu.

The FMU is built once per session with `cargo run --release -p packaging`
unless KERF_FMU points at an existing file (scripts/test sets it after its own
packaging step).  Helpers live in tools/kerfhost.py (on pythonpath, pytest.ini).
"""

import os
from pathlib import Path

import numpy as np
import pytest

import kerfhost as kh

H = 1e-3  # communication step [s] = 1 mm of travel at 1 m/s


@pytest.fixture(scope="session")
def fmu_path() -> Path:
    env = os.environ.get("KERF_FMU")
    if env:
        p = Path(env).resolve()
        if not p.is_file():
            pytest.exit(f"KERF_FMU={env} does not exist", returncode=2)
        return p
    return kh.build_fmu()


@pytest.fixture(scope="session")
def fmu(fmu_path) -> kh.FMU:
    """The extracted FMU and its model description (one extraction per session)."""
    return kh.FMU(fmu_path)


@pytest.fixture
def make(fmu):
    """Factory for instances that are freed at teardown: make("CS"|"ME", name=...)."""
    made = []

    def _make(kind="CS", name="kerf", logging_on=True):
        inst = fmu.instance(kind, name=name, logging_on=logging_on)
        made.append(inst)
        return inst

    yield _make
    for inst in made:
        try:
            inst.free(terminate=False)
        except Exception:
            pass


@pytest.fixture(scope="session")
def cs_reference(fmu):
    """The reference cut in CS (default parameters, 1000 steps of 1 mm), run once."""
    inst = fmu.instance("CS", name="cs-reference")
    try:
        return kh.run_line_cs(inst, n_steps=1000, h=H)
    finally:
        inst.free()


@pytest.fixture(scope="session")
def theory():
    ref = kh.REFERENCE
    th = kh.csm_theory(ref["R"], ref["T"], ref["ucs"], ref["bts"], ref["S"], ref["C"], ref["p"])
    kh.check_theory_against_notes(th)
    return th


# --------------------------------------------------------------------------- helpers

def start_line(inst, start_values=None, n=0, h=H):
    """Initialise `inst` (CS) for the reference cut and take n steps; returns t."""
    fixed, _ = kh.line_inputs(inst.fmu_file, start_values)
    inst.initialize(start_values, inputs=dict(fixed, x=0.0))
    steps(inst, 0.0, n, h)
    return n * h


ALL = kh.REAL_OUTPUTS


def steps(inst, t, n, h=H, v=1.0):
    """n CS steps of the line cut from time t (host feeds x = v t); outputs after each step
    as an (n, len(ALL)) array, plus inContact as a last column (0/1)."""
    rows = []
    for k in range(n):
        tk = t + k * h
        inst.set_reals(["x"], [v * tk])
        inst.f.doStep(currentCommunicationPoint=tk, communicationStepSize=h)
        rows.append(list(inst.get_reals(ALL)) + [float(inst.get("inContact"))])
    return np.array(rows, dtype=float).reshape(n, len(ALL) + 1)


def col(name):
    return ALL.index(name)


def error_messages(inst):
    return [r.message for r in inst.errors()]


def assert_error_logged(inst, *needles, before=0):
    """An fmi2Error-level message was logged (after log index `before`) containing every needle."""
    msgs = [r.message for r in inst.log[before:] if r.status >= kh.FMI2_ERROR]
    assert msgs, "fmi2Error returned but nothing was logged with status Error " \
                 f"(log: {[str(r) for r in inst.log[before:]]})"
    for n in needles:
        assert any(n.lower() in m.lower() for m in msgs), \
            f"no error message mentions {n!r}; messages: {msgs}"
    return msgs


# Hard cases the area-based contact law of issue 7 does not meet yet (known
# gaps, listed in README "Contact law: known gaps"). Each is a strict xfail
# with its reason: a fix shows as an XPASS, which fails the run until the
# entry here is removed, and only a failed assertion counts as the known gap
# (a crash, an FMI error or a NaN fails the run). (The cases whose old
# expectations the law changed by design now test the law's own physics.)
_CONTACT_LAW_XFAIL = {
    # known gaps of the area law at shallow contact and on face edges
    "test_first_contact_while_rolling_force_follows_the_csm_law_from_0_2_mm":
        "known gap: below 1 mm the pressure level is held at its 1 mm value (55 % below "
        "F_N(p) at 0.2 mm, 15 % at 0.8 mm), and an off-node tip slice joins the contact a "
        "whole arc at a time (a side force of 0.2 % of F_N at 0.34 mm)",
    "test_vanishing_penetration_rolls_with_a_small_finite_force":
        "known gap: the 'rock still there' test cannot resolve a cut shallower than its "
        "tolerance (cell^2 / 8 r, 10 um at 1 mm cells): 1-10 um cuts read as re-rolls",
    "test_stepped_initial_face_from_rsf_steps_the_force_once_per_edge":
        "known gap: a step of the initial face is met by the tip slices one at a time",
}


def _xfail_reason(item):
    """The reason a hard case is an xfail: by test name, or by test name
    and a parameter id part (`name[part]`) for the parametrisations that fail."""
    name = item.originalname or item.name
    if name in _CONTACT_LAW_XFAIL:
        return _CONTACT_LAW_XFAIL[name]
    ids = item.name[len(name):].strip("[]").split("-")
    for part in ids:
        reason = _CONTACT_LAW_XFAIL.get(f"{name}[{part}]")
        if reason:
            return reason
    return None


def pytest_collection_modifyitems(config, items):
    for item in items:
        reason = _xfail_reason(item)
        if reason and item.module.__name__.endswith("test_hard_cases"):
            item.add_marker(pytest.mark.xfail(reason=reason, strict=True,
                                              raises=AssertionError))

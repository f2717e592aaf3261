"""Hard cases (issue 4, section 2): the packaged FMU driven through fmpy, in
Co-Simulation (FMU2Slave, a host loop that feeds the pose each step, or the
velocities only) and Model Exchange (fmpy.simulate_fmu with CVode and an input
table; a hand-written FMU2Model loop where the host closes a loop).

Every case asserts
  * every output stays finite;
  * the forces have the sign and rough size the physics demands (stated at
    each case);
  * the force history has no jump larger than the physics of the case explains.

The jump rule (`check_history`): between consecutive samples each of
normalForce, rollingForce and sideForce may change by at most

    |F_csm(p_k) - F_csm(p_{k-1})|  +  5 % of the case's CSM force,

where p_k is the geometric penetration of the leading arc at sample k
(computed here from the commanded pose and the known rock face, not read from
the FMU) and F_csm the CSM resultant T R phi P' as the FMU regularises it below
p_reg = 50 um.  The 5 % is what a 1 mm height map can explain: the end of the
contact arc is known to a cell (T P' dx = 1.5 kN, 2.5 % of the reference
force), and the elastic contact behind the lowest point (p- ~ 10 um, up to
2.4 kN) may vanish in one step where the leading arc vanishes.  Real
discontinuities are exempt, and say so where they occur:
  * the first START samples of a cutter that starts to move out of the pit it
    was pressed into at rest (the trailing side of the pit unloads within the
    2 um elastic layer, i.e. within the first step), also where the host puts
    the cutter back into its start pit for a second pass;
  * the moment a rim reaches a vertical step in the face (the depth of the
    contact zone, eq. 54, grows by the step height at once);
  * a second pass stops short of the end wall of the first groove, which has
    the rim's own shape and would be met by the whole leading arc at once.

Cases that reveal a defect of the FMU are kept and marked xfail(strict=True,
raises=AssertionError) by conftest.py, with the gap in the reason (README,
"Contact law: known gaps"): the force below 1 mm deep, cuts of 1-10 um, and a
step in the initial face. A fix then fails the run as an XPASS until its entry
is removed. (Earlier defects found here, since fixed and passing: contact
starting late when rolling into the rock's end face, the force not scaling
with the tip's width on the rock when sliding off its side edge, ME's
cuttingEnergy missing a skidding cutter's friction work, and the trailing
side of a rest pit driving a cutter that rolls away.)

Reference numbers (interface.md, thesis eqs 13-17): R = 0.2159 m, T = 0.013 m,
p = 3.8 mm: F_N = 60795 N, F_R = 5728.5 N, F_t = 61065 N; friction mu = 0.3
reached at a slip speed of 0.01 m/s.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import kerfhost as kh
import hard_cases_util as u

pytestmark = pytest.mark.physics

KINDS = ["CS", "ME"]
H = 1e-3                                  # 1 ms = 1 mm of travel at 1 m/s
R, T, P_REF, Z_REF = u.R, u.T, u.P_REF, u.Z_REF
REF = u.csm_force(P_REF)                  # FN 60795, FR 5728.5, Ft 61065
FN_REF, FR_REF, FT_REF = REF["FN"], REF["FR"], REF["Ft"]
P_PRIME = u.base_pressure()               # 115.79 MPa
MU = u.MU
START = 3                                 # samples of the start-from-rest transient (3 mm at 1 m/s)
FORCES = ("normalForce", "rollingForce", "sideForce")
ROLL = u.rolling_twist(1.0)               # vx = 1, wy = 1/R


def flat(x, y):
    """Default rock: flat at z = 0 on x in [-0.25, 1.25]; outside it there is no rock."""
    return 0.0 if u.ROCK_X[0] <= x <= u.ROCK_X[1] and u.ROCK_Y[0] <= y <= u.ROCK_Y[1] else -np.inf


def law(p):
    return u.law_ft(p)


def check_history(res, where, p_geo=None, scale=FN_REF, skip=START, allowed=(),
                  names=FORCES):
    """The checks every case makes: finite outputs; force zero exactly when not in
    contact; rock record monotone; no jump beyond |dF_csm(p_geo)| + 5 % of `scale`
    after sample `skip`, except at sample indices in `allowed` (real
    discontinuities, checked by the caller)."""
    u.assert_finite(res, where)
    # no rock can be un-removed
    dv = np.diff(res["excavatedVolume"])
    assert np.all(dv >= -1e-15), f"{where}: excavatedVolume decreases by {-dv.min():.3g} m3"
    # the rock is passive (plastic, with friction): the cutter's work on it never
    # decreases (an elastic give-back is at most F x 2 um, < 0.2 J here); the
    # start transient is left to test_starting_to_roll_downhill_*
    de = np.diff(res["cuttingEnergy"])
    bad = [k + 1 for k in range(skip, de.size) if de[k] < -0.2 and (k + 1) not in set(allowed)]
    assert not bad, (f"{where}: cuttingEnergy decreases by {-de[bad[0] - 1]:.3g} J at "
                     f"x = {res['x'][bad[0]]:.4f} (the rock does work on the cutter)")
    # out of contact, the rock exerts nothing
    free = res["inContact"] == 0
    for name in ("Fx", "Fy", "Fz", "Mx", "My", "Mz") + FORCES:
        assert np.all(res[name][free] == 0.0), f"{where}: {name} nonzero while not in contact"
    if p_geo is None:
        p_geo = np.zeros_like(res["time"])
    f_law = np.array([law(p) for p in p_geo])
    bound = np.abs(np.diff(f_law)) + 0.05 * scale
    for name in names:
        u.assert_no_jump(res, name, bound, lo=skip, where=where, allowed=set(allowed))


def window(res, lo, hi, key="x"):
    sel = (res[key] >= lo) & (res[key] <= hi)
    assert sel.sum() >= 3, f"too few samples with {lo} <= {key} <= {hi}"
    return sel


# =========================================================================== first contact

def descend_rolling(fmu, kind):
    """The cutter starts 1 mm above the face, rolls at 1 m/s and descends at
    20 mm/s (20 um per mm of travel) to 4 mm deep: the run and the depth of
    its lowest point."""
    ks = u.knots_line(dict(x=0.0, z=R + 1e-3), dict(ROLL, vz=-0.02), 0.25)
    res = u.run(kind, fmu, ks, H)
    return res, R - res["z"]


@pytest.mark.parametrize("kind", KINDS)
def test_first_contact_while_rolling_loads_the_rim_from_first_touch(fmu, kind):
    """Descending while rolling (`descend_rolling`).  Physics: no force while
    the rim is above the face; from first touch the leading arc is in fresh
    rock and loaded (F_N > 0, rising from 0 with the law's finite slope,
    regularised below 50 um) and resists rolling (rollingForce >= 0); from
    1 mm deep, where the pressure level is the CSM calibration's own, F_N is
    the CSM law F_N(p) of the lowest point's depth p, within 2.5 % (it dips
    by 2.0 % at 1.4 mm, while the tip's outer slices join the contact, and
    is within 0.02 % from 1.6 mm on; 4 mm deep at the end, within 0.5 %)."""
    res, depth = descend_rolling(fmu, kind)
    check_history(res, f"{kind} descend rolling", np.maximum(depth, 0.0), skip=0)
    above = depth < -1e-9
    assert above.sum() >= 40
    assert np.all(res["inContact"][above] == 0) and np.all(res["normalForce"][above] == 0)
    touching = depth > 2e-6
    assert touching.sum() >= 150
    assert np.all(res["normalForce"][touching] > 0)
    assert np.all(res["rollingForce"][touching] >= -1e-6 * res["normalForce"][touching])
    deep = depth >= 1e-3
    assert deep.sum() >= 100
    fn_csm = np.array([u.csm_force(p)["FN"] for p in depth[deep]])
    err = np.max(np.abs(res["normalForce"][deep] / fn_csm - 1))
    assert err < 0.025, f"{kind}: normal force strays {err:.2%} from CSM F_N(depth) from 1 mm"
    assert res["normalForce"][-1] == pytest.approx(u.csm_force(depth[-1])["FN"], rel=5e-3)


@pytest.mark.parametrize("kind", KINDS)
def test_first_contact_while_rolling_force_follows_the_csm_law_from_0_2_mm(fmu, kind):
    """Descending while rolling (`descend_rolling`).  Physics: after first
    touch the leading arc is in fresh rock as deep as the lowest point, so F_N
    follows the CSM law F_N(p) with p the depth of the lowest point from
    0.2 mm on; symmetric tip, no side force.  A known gap (conftest.py)."""
    res, depth = descend_rolling(fmu, kind)
    assert np.all(np.abs(res["sideForce"]) <= 1e-3 * np.abs(res["normalForce"]) + 1e-6)
    deep = depth > 0.2e-3
    fn_csm = np.array([u.csm_force(p)["FN"] for p in depth[deep]])
    err = np.max(np.abs(res["normalForce"][deep] / fn_csm - 1))
    assert err < 0.03, f"{kind}: normal force strays {err:.2%} from CSM F_N(depth) while descending"


@pytest.mark.parametrize("kind", KINDS)
def test_first_contact_pressing_straight_down_pushes_straight_up(fmu, kind):
    """At rest in x, the cutter descends at vz = -20 mm/s from 1 mm above the face
    to 4 mm deep.  Physics (the area law): the pit it presses is symmetric and
    both of its arcs drive into the rock.  Each arc's CSM resultant F_t(p) leans
    phi/2 off the vertical, one forwards and one backwards, and the side blend
    weighs the two alike, so the resultant is vertical and equals
    F_t cos(phi/2) = F_N(p) (the thesis's law pushed with F_t).  No rolling or
    side force; the rock takes work (cuttingEnergy grows).  Below 1 mm the
    pressure level is held at its 1 mm value (README, "Contact law: known
    gaps"), so the size is checked from 1 mm on."""
    ks = u.knots_line(dict(x=0.5, z=R + 1e-3), dict(vz=-0.02), 0.25)
    res = u.run(kind, fmu, ks, H)
    depth = R - res["z"]
    p_geo = np.maximum(depth, 0.0)
    check_history(res, f"{kind} press down", p_geo, skip=0)
    above = depth < -1e-9
    assert np.all(res["normalForce"][above] == 0)
    deep = depth >= 1e-3 - 1e-9
    fn = np.array([u.csm_force(p)["FN"] for p in depth[deep]])
    err = np.max(np.abs(res["normalForce"][deep] / fn - 1))
    assert err < 0.02, f"{kind}: pressing down, normal force strays {err:.2%} from F_N(depth)"
    for name in ("rollingForce", "sideForce", "Fx", "Fy"):
        assert np.all(np.abs(res[name]) <= 1e-3 * res["normalForce"] + 1e-6), name
    e = res["cuttingEnergy"]
    assert e[-1] > 0 and np.all(np.diff(e) >= -1e-9 * e[-1])


# =========================================================================== penetration extremes

@pytest.mark.parametrize("p", [1e-6, 10e-6], ids=["1um", "10um"])
@pytest.mark.parametrize("kind", KINDS)
def test_vanishing_penetration_rolls_with_a_small_finite_force(fmu, kind, p):
    """Rolling 0.1 m at 1 um and 10 um.  Physics: a touching rim is loaded, by at
    most the (regularised, finite-slope) CSM force at that depth: 0 < F_N <=
    F_t(p); at 10 um the leading arc carries nearly all of it (>= 80 %), at 1 um
    the rim is inside the 2 um elastic layer, so the rock does not yield
    (excavatedVolume stays 0) and the load is faded in; the rolling force is
    that of an arc of angle phi(p) (0 <= F_R <= F_N tan phi)."""
    ks = u.knots_line(dict(x=0.0, z=R - p), ROLL, 0.1)
    res = u.run(kind, fmu, ks, H)
    f = law(p)
    check_history(res, f"{kind} p = {p}", np.full_like(res["time"], p), scale=f)
    fn = res["normalForce"]
    assert np.all(fn > 0) and np.all(res["inContact"] == 1)
    assert np.all(fn <= 1.02 * f), f"{fn.max():.2f} N > F_t({p}) = {f:.2f} N"
    phi = math.acos((R - p) / R)
    assert np.all(res["penetration"] > 0) and np.all(res["penetration"] < 2e-5)
    assert np.all(res["contactAngle"] > 0) and np.all(res["contactAngle"] < 0.02)
    assert np.all(res["rollingForce"] >= -1e-6 * fn)
    assert np.all(res["rollingForce"] <= fn * math.tan(phi) + 1e-6 * f)
    if p < 2e-6:
        assert np.all(fn >= 0.2 * f)
        assert np.all(res["excavatedVolume"] == 0.0), "a rim inside the elastic layer removed rock"
    else:
        steady = res["x"] >= 0.01
        assert np.all(fn[steady] >= 0.8 * f)
        assert res["excavatedVolume"][-1] > 0


@pytest.mark.parametrize("kind", KINDS)
def test_deep_penetration_20mm_past_the_tip_profile_follows_csm(fmu, kind):
    """Rolling at 20 mm, past the 1.8 mm tall tip profile: at roll 0 the flat side
    faces are vertical, they are the groove walls and push only sideways, the
    two equally.  Physics: F_N and F_R are the CSM values at 20 mm (the law has
    no depth limit below 2R), no side force, and the groove's cross-section is
    the tip profile 20 mm deep (width T): dV/dx = integral of the depth profile."""
    p = 20e-3
    ks = u.knots_line(dict(x=0.0, z=R - p), ROLL, 0.2)
    res = u.run(kind, fmu, ks, H)
    th = u.csm_force(p)
    check_history(res, f"{kind} 20 mm", np.full_like(res["time"], p), scale=th["FN"])
    st = window(res, 0.02, 0.2)
    assert np.mean(res["normalForce"][st]) == pytest.approx(th["FN"], rel=0.02)
    assert np.mean(res["rollingForce"][st]) == pytest.approx(th["FR"], rel=0.03)
    assert np.all(np.abs(res["sideForce"]) <= 1e-3 * res["normalForce"])
    assert np.all(res["penetration"][st] == pytest.approx(p, rel=1e-3))
    assert np.all(res["contactAngle"][st] == pytest.approx(th["phi"], rel=1e-3))
    y = np.linspace(-T / 2, T / 2, 20001)
    area = np.trapezoid(kh.tip_depth_profile(y, kh.REFERENCE["r"], T, p), y)
    x, v = res["x"][st], res["excavatedVolume"][st]
    rate = (v[-1] - v[0]) / (x[-1] - x[0])
    assert rate == pytest.approx(area, rel=0.02), \
        f"groove cross-section {rate * 1e6:.2f} mm2 vs tip profile {area * 1e6:.2f} mm2"


def segment_area(radius, h):
    """Area of the segment of height h (0 <= h <= 2 radius) cut off a circle."""
    return (radius * radius * math.acos(1 - h / radius)
            - (radius - h) * math.sqrt(max(2 * radius * h - h * h, 0.0)))


def side_face_segment_area(roll, depth_low, R=R, T=T, r=kh.REFERENCE["r"]):
    """Area of the lower side face (local y = -T/2, a disc of radius rho_edge) of
    a disc with roll `roll` below the plane z = 0, when the face's lowest point
    is depth_low below it: a circular segment of height depth_low / cos(roll)
    measured in the face's plane."""
    rho = R - r + math.sqrt(r * r - (T / 2) ** 2)
    if depth_low <= 0:
        return 0.0
    return segment_area(rho, min(depth_low / math.cos(roll), 2 * rho))


def face_depth(pose):
    """Depth below z = 0 of the lowest point of the lower side face's rim edge."""
    rho = R - kh.REFERENCE["r"] + math.sqrt(kh.REFERENCE["r"] ** 2 - (T / 2) ** 2)
    c, s = math.cos(pose["roll"]), math.sin(pose["roll"])
    return -(pose["z"] + s * (-T / 2) + c * (-rho))


def rolled_cut(fmu, kind, roll, depth, length=0.2):
    """A disc rolled by `roll`, its lowest tip point `depth` below the flat
    face, rolling at 1 m/s for `length`; the run and its work per volume of
    rock removed from x = 5 mm on [J/m3]."""
    pose = u.tilted_pose(roll, depth)
    res = u.run(kind, fmu, u.knots_line(pose, u.rolling_twist(1.0, roll), length), H)
    st = res["x"] >= 0.005
    e, v = res["cuttingEnergy"][st], res["excavatedVolume"][st]
    return res, (e[-1] - e[0]) / (v[-1] - v[0])


@pytest.mark.parametrize("kind", KINDS)
def test_deep_tilted_cutter_rolling_side_face_carries_no_pressure(fmu, kind):
    """Roll 30 deg, lowest point 20 mm deep, rolling: the lower flat side face is
    deep in the rock.  Physics (the area law): the roll is about the heading and
    the spin about the face's normal, so every point of the rolling face moves
    in the face's own plane; it drives into no rock and carries no cutting
    pressure.  The tip carries the load: F_N >= 0.8 F_N,csm(20 mm),
    rollingForce > 0, and a small side force from its tilted profile
    (0 < sideForce < 5 % of F_N); in the rock frame that force leans with the
    tilt (Fy < 0, Fz > 0).  The cut removes the rock under the face as well
    (325 mm2 a metre against 253 upright), which the tip's work pays for: the
    work per volume removed stays within 30 % of the upright cut's at the same
    depth (the bound issue 7 sets for partial cuts; 0.82 here).  The total is
    bounded by the tip's CSM force plus the base pressure P' over the face
    below the rock."""
    roll, p = math.radians(30), 20e-3
    pose = u.tilted_pose(roll, p)
    res, wv = rolled_cut(fmu, kind, roll, p)
    _, wv_upright = rolled_cut(fmu, kind, 0.0, p)
    f_bound = law(p) + P_PRIME * side_face_segment_area(roll, face_depth(pose))
    check_history(res, f"{kind} deep tilted", np.full_like(res["time"], p), scale=f_bound)
    st = res["x"] >= 0.005
    fn, fs = res["normalForce"][st], res["sideForce"][st]
    assert np.all(fs > 0) and np.all(fs < 0.05 * fn)
    assert np.all(res["Fy"][st] < 0) and np.all(res["Fz"][st] > 0)
    assert np.all(fn >= 0.8 * u.csm_force(p)["FN"])
    assert np.all(res["rollingForce"][st] > 0)
    assert 0.7 < wv / wv_upright < 1.3, f"work per volume {wv / wv_upright:.3f} of the upright cut's"
    fmag = np.sqrt(res["Fx"] ** 2 + res["Fy"] ** 2 + res["Fz"] ** 2)
    assert np.all(fmag <= f_bound), f"|F| {fmag.max():.0f} N > bound {f_bound:.0f} N"


@pytest.mark.parametrize("roll_deg", [30, 60])
@pytest.mark.parametrize("kind", KINDS)
def test_strong_tilt_pushes_the_cutter_up_and_resists_rolling(fmu, kind, roll_deg):
    """Roll 30 and 60 deg, the lowest tip point 3.8 mm below the face (at roll 60
    it is ~0.19 m sideways from the centre, so the centre is shifted in y),
    rolling without slip about the tilted axle.  Physics: the face of the rock
    pushes the cutter out of the rock (Fz > 0, more up than sideways: |Fy| <
    Fz), the rim's leading arc resists rolling (rollingForce > 0), the up-force
    has a positive share along the up-tilted axle (sideForce > 0).  Size (the
    area law): at the same lowest-point depth a tilted disc removes less rock
    (28.6 mm2 a metre at 30 deg, 21.8 at 60, against 41.9 upright), and its
    force follows the rock removed: the work per volume removed is the upright
    cut's within 5 % (measured 0.1 % and 2.3 %).  At most F_t plus P' over the
    part of the lower side face that dips below the face of the rock."""
    roll = math.radians(roll_deg)
    pose = u.tilted_pose(roll, P_REF)
    res, wv = rolled_cut(fmu, kind, roll, P_REF)
    _, wv_upright = rolled_cut(fmu, kind, 0.0, P_REF)
    f_bound = law(P_REF) + P_PRIME * side_face_segment_area(roll, face_depth(pose))
    check_history(res, f"{kind} roll {roll_deg}", np.full_like(res["time"], P_REF), scale=FN_REF)
    st = res["x"] >= 0.005
    fz, fy = res["Fz"][st], res["Fy"][st]
    assert np.all(fz > 0) and np.all(np.abs(fy) < fz)
    assert np.all(res["normalForce"][st] > 0)
    assert np.all(res["rollingForce"][st] > 0)
    assert np.all(res["sideForce"][st] > 0)
    assert wv / wv_upright == pytest.approx(1.0, abs=0.05), \
        f"work per volume {wv / wv_upright:.3f} of the upright cut's"
    fmag = np.sqrt(res["Fx"] ** 2 + res["Fy"] ** 2 + res["Fz"] ** 2)
    assert np.all(fmag <= f_bound), f"|F| {fmag.max():.0f} N > bound {f_bound:.0f} N"


# =========================================================================== kinematics

@pytest.mark.parametrize("kind", KINDS)
def test_starting_to_roll_downhill_the_rock_never_drives_the_cutter(fmu, kind, tmp_path):
    """Pressed 3.8 mm into a face sloping down 5 % in +x, at rest, then rolled
    forwards (downhill) at 1 m/s.  Physics: at rest the uphill rear of the pit
    is deeper and pushes the cutter forwards (allowed: no motion, no work); once
    the cutter moves forwards, the rim recedes from that wall (by up to 0.19 mm
    per mm of travel) and it unloads within the 2 um elastic layer, so after the
    first step the leading arc alone resists rolling: rollingForce >= 0, and the
    rock, being passive, never does work on the cutter: cuttingEnergy never
    decreases.  (Held still for three steps, then set rolling: the inputs
    step from rest to the rolling twist at t = 3 ms.)"""
    sv = rsf_start(tmp_path, lambda x, y: -0.05 * x, "slope")
    t_go = 3 * H
    rest = u.knots_line(dict(x=0.0, z=Z_REF), {}, t_go)
    ks = rest + u.knots_line(dict(x=0.0, z=Z_REF), ROLL, 0.02, t0=t_go)
    res = u.run(kind, fmu, ks, H, start_values=sv)
    u.assert_finite(res, f"{kind} downhill start")
    at_rest = res["time"] < t_go
    assert np.all(res["rollingForce"][at_rest] < 0), \
        "at rest the deeper uphill wall pushes forwards"
    moving = res["time"] >= t_go + H
    assert np.all(res["rollingForce"][moving] >= 0), \
        f"rollingForce {res['rollingForce'][moving].min():.0f} N: the rock drives the cutter"
    assert np.all(np.diff(res["cuttingEnergy"]) >= -0.2), \
        f"cuttingEnergy falls to {res['cuttingEnergy'].min():.2f} J"


@pytest.mark.parametrize("kind", KINDS)
def test_cutter_at_rest_holds_its_load_unchanged(fmu, kind):
    """Pressed 3.8 mm in and held still for 0.1 s.  Physics: the pit is symmetric,
    the force is vertical and equals the full CSM F_t(3.8 mm) = 61065 N; the
    elastic layer keeps the load (it does not drop to 0 after the first cut);
    nothing moves, so nothing changes: no rolling or side force, constant
    outputs, no work after the first sample."""
    ks = u.knots_line(dict(x=0.5, z=Z_REF), {}, 0.1)
    res = u.run(kind, fmu, ks, H)
    check_history(res, f"{kind} rest", skip=0)
    fn = res["normalForce"]
    assert fn == pytest.approx(np.full_like(fn, FT_REF), rel=5e-3)
    assert np.ptp(fn) < 1e-6 * FT_REF
    for name in ("rollingForce", "sideForce", "Fx", "Fy", "Mx", "My", "Mz"):
        assert np.all(np.abs(res[name]) < 1e-6 * FT_REF), name
    assert np.ptp(res["excavatedVolume"][1:]) == 0.0
    assert np.ptp(res["cuttingEnergy"]) == 0.0


@pytest.mark.parametrize("kind", KINDS)
def test_rolling_backwards_mirrors_rolling_forwards(fmu, kind):
    """vx = -1 m/s, wy = -1/R from x = 0.8.  Physics: the leading arc is now
    behind (-x): same F_N, the rolling resistance pushes +x, i.e. rollingForce
    (along cutter -x) = -F_R; no side force; the rock takes work."""
    ks = u.knots_line(dict(x=0.8, z=Z_REF), u.rolling_twist(-1.0), 0.2)
    res = u.run(kind, fmu, ks, H)
    check_history(res, f"{kind} backwards")
    st = res["x"] <= 0.79
    assert np.mean(res["normalForce"][st]) == pytest.approx(FN_REF, rel=5e-3)
    assert np.mean(res["rollingForce"][st]) == pytest.approx(-FR_REF, rel=1e-2)
    assert np.all(np.abs(res["sideForce"]) <= 1e-3 * res["normalForce"])
    assert np.all(np.diff(res["cuttingEnergy"]) >= 0)


@pytest.mark.parametrize("kind", KINDS)
def test_sliding_sideways_cuts_a_trench_against_friction_and_the_wall(fmu, kind):
    """vy = 0.1 m/s with wy = 0 (a skidding cutter), 3.8 mm deep at x = 0.5.
    Physics (the area law): the slip at the lowest point is vy >> vs, so
    friction is full, mu |F_rim| against the slide; and the disc's +y side
    drives into the rock beside it and cuts it, so the wall pushes back too:
    sideForce < -mu F_N from the first sample on (0.61 F_N here, against
    mu = 0.3), and no more than friction plus the base pressure P' over the
    disc's cross-section below the face.  The slide removes a trench of that
    cross-section (the rim's segment 3.8 mm deep, 205 mm2) at vy, and the
    rock takes the work of the slide: d(cuttingEnergy)/dt = -Fy vy."""
    vy = 0.1
    ks = u.knots_line(dict(x=0.5, z=Z_REF), dict(vy=vy), 0.2)
    res = u.run(kind, fmu, ks, H)
    check_history(res, f"{kind} sideways")
    fn, fs = res["normalForce"], res["sideForce"]
    area = segment_area(R, P_REF)  # the disc's cross-section below the face
    assert np.all(fs < -MU * fn)
    assert np.all(fs > -(MU * fn + P_PRIME * area))
    assert np.all(res["Fy"] < 0)
    st = res["time"] >= 0.01
    e, t, v = res["cuttingEnergy"], res["time"], res["excavatedVolume"]
    rate = (e[-1] - e[st][0]) / (t[-1] - t[st][0])
    assert rate == pytest.approx(-np.mean(res["Fy"][st]) * vy, rel=0.02)
    trench = (v[-1] - v[st][0]) / (t[-1] - t[st][0]) / vy
    assert trench == pytest.approx(area, rel=0.01), \
        f"trench {trench * 1e6:.2f} mm2 against the rim's segment {area * 1e6:.2f} mm2"


@pytest.mark.parametrize("kind", KINDS)
def test_spinning_in_place_friction_resists_the_skid(fmu, kind):
    """wy = 5 rad/s, v = 0, 3.8 mm deep.  Physics: the lowest rim point slips
    backwards at R wy = 1.08 m/s >> vs, so friction is full and pushes the cutter
    forwards: rollingForce (along -x) = -mu F_t; its moment about the centre,
    -R mu F_t about y, opposes the spin (My wy < 0); the load is the at-rest
    F_t; the rock takes the work -My wy; everything stays finite and constant."""
    wy = 5.0
    ks = u.knots_line(dict(x=0.5, z=Z_REF), dict(wy=wy), 0.1)
    res = u.run(kind, fmu, ks, H)
    check_history(res, f"{kind} spin", skip=0)
    fn = res["normalForce"]
    assert fn == pytest.approx(np.full_like(fn, FT_REF), rel=5e-3)
    assert res["rollingForce"] == pytest.approx(-MU * fn, rel=1e-2)
    assert np.all(res["My"] * wy < 0)
    assert res["My"] == pytest.approx(-R * MU * fn, rel=1e-2)


@pytest.mark.parametrize("kind", KINDS)
def test_spinning_in_place_friction_work_goes_into_cutting_energy(fmu, kind):
    """Same spin.  Physics: friction on the skidding rim is work done by the
    cutter on the rock: cuttingEnergy grows at -My wy = R mu F_t wy = 19.8 kW
    in both interfaces."""
    wy = 5.0
    ks = u.knots_line(dict(x=0.5, z=Z_REF), dict(wy=wy), 0.1)
    res = u.run(kind, fmu, ks, H)
    e, t = res["cuttingEnergy"], res["time"]
    assert (e[-1] - e[1]) / (t[-1] - t[1]) == pytest.approx(-np.mean(res["My"]) * wy, rel=1e-2)


# =========================================================================== edges of the face

def edge_surface(x, y):
    return flat(x, y)


def leave_run(kind, fmu):
    """Rolling from x = 1.1 to 1.35, past the end of the rock at x = 1.25."""
    ks = u.knots_line(dict(x=1.1, z=Z_REF), ROLL, 0.25)
    return u.run(kind, fmu, ks, H)


@pytest.mark.parametrize("kind", KINDS)
def test_leaving_the_face_unloads_to_zero_without_nan(fmu, kind):
    """Same run.  Physics: while the lowest point approaches the edge the
    leading arc shortens to the rock that is left, so the force falls with it,
    with no jump beyond the law's own change plus the slack (the look-ahead
    of the "rock still there" test used to drop its three samples one at a
    time past the rock's end: 15.5 kN jumps 16 and 8 mm before it); once the
    lowest point is past the edge there is no rock under the rim: every force
    and moment is exactly 0 and inContact is false, with no NaN."""
    res = leave_run(kind, fmu)
    p_geo = np.array([u.front_depth(x, z, edge_surface) for x, z in zip(res["x"], res["z"])])
    check_history(res, f"{kind} leave", p_geo)
    gone = res["x"] > 1.25 + 2e-3
    assert gone.sum() > 50
    assert np.all(res["inContact"][gone] == 0)
    for name in kh.REAL_OUTPUTS[:9]:
        assert np.all(res[name][gone] == 0.0), name
    # the last millimetres of rock still load the rim
    last = (res["x"] > 1.245) & (res["x"] < 1.2485)
    assert last.sum() >= 3 and np.all(res["normalForce"][last] > 0.02 * FN_REF)
    st = window(res, 1.1 + START * 1e-3, 1.2)
    assert np.mean(res["normalForce"][st]) == pytest.approx(FN_REF, rel=5e-3)


@pytest.mark.parametrize("kind", KINDS)
def test_leaving_the_face_force_falls_as_the_arc_shortens(fmu, kind):
    """Same run.  Physics: the rock ahead ends, so the leading arc only
    shortens: the normal force never rises by more than 1 % of F_N."""
    res = leave_run(kind, fmu)
    gone = res["x"] > 1.25 + 2e-3
    near = (res["x"] >= 1.15) & ~gone
    rise = np.diff(res["normalForce"][near])
    assert np.all(rise <= 0.01 * FN_REF), f"normal force rises by {rise.max():.0f} N near the edge"


X_OUTSIDE = u.ROCK_X[0] - R - 0.02       # the whole disc 20 mm short of the rock


@pytest.mark.parametrize("kind", KINDS)
def test_entering_the_face_from_outside_starts_at_zero_and_reaches_the_steady_cut(fmu, kind):
    """Rolling from x = -0.25 - R - 0.02 (no rock under the disc) into the face.
    Physics: no force until the rim's front meets the rock's end face (x + R
    sin(phi) >= -0.25); after the lowest point is well inside, the steady CSM
    cut (F_N = 60795 N, F_R = 5728.5 N); outputs finite throughout."""
    ks = u.knots_line(dict(x=X_OUTSIDE, z=Z_REF), ROLL, 0.3)
    res = u.run(kind, fmu, ks, H)
    u.assert_finite(res, f"{kind} enter")
    reach = res["x"] + R * math.sin(REF["phi"])
    before = reach < u.ROCK_X[0] - 1e-3
    assert before.sum() > 100
    assert np.all(res["inContact"][before] == 0) and np.all(res["normalForce"][before] == 0)
    assert np.all(res["excavatedVolume"][before] == 0)
    st = res["x"] >= u.ROCK_X[0] + 0.05
    assert st.sum() >= 10
    assert np.mean(res["normalForce"][st]) == pytest.approx(FN_REF, rel=5e-3)
    assert np.mean(res["rollingForce"][st]) == pytest.approx(FR_REF, rel=1e-2)


@pytest.mark.parametrize("kind", KINDS)
def test_entering_the_face_force_grows_without_a_jump(fmu, kind):
    """Same run.  Physics: the contact arc begins at the rock's end face with zero
    depth and deepens continuously (depth = how far the rim is below z = 0 where
    it crosses x = -0.25), so the force follows F_csm(p_geo) with no jump
    larger than the law's own change plus the slack."""
    ks = u.knots_line(dict(x=X_OUTSIDE, z=Z_REF), ROLL, 0.3)
    res = u.run(kind, fmu, ks, H)
    p_geo = np.array([u.front_depth(x, z, edge_surface) for x, z in zip(res["x"], res["z"])])
    check_history(res, f"{kind} enter", p_geo, skip=0)


SIDE_EDGE_VY = 0.1                        # 0.1 mm sideways per 1 mm of rolling


def side_edge_run(kind, fmu):
    """Rolling at 1 m/s and sliding at vy = 0.1 m/s from y = 0.09 (the 13 mm tip
    wholly on the rock) across the side edge of the face at y = 0.1."""
    ks = u.knots_line(dict(x=0.3, y=0.09, z=Z_REF), dict(vy=SIDE_EDGE_VY, **ROLL), 0.2)
    return u.run(kind, fmu, ks, H)


@pytest.mark.parametrize("kind", KINDS)
def test_sliding_off_the_side_edge_ends_at_zero_without_nan(fmu, kind):
    """Same run.  Physics: once the whole tip is past y = 0.1 (centre beyond
    0.1 + T/2) there is no rock under the rim: every force exactly 0, not in
    contact, no NaN; while the whole tip is on the rock the cutter is loaded
    about as in the reference cut, and with its centre on the edge, by half
    of that."""
    res = side_edge_run(kind, fmu)
    u.assert_finite(res, f"{kind} side edge")
    off = res["y"] > u.ROCK_Y[1] + T / 2 + 1e-4
    assert off.sum() > 10
    assert np.all(res["inContact"][off] == 0)
    for name in kh.REAL_OUTPUTS[:9]:
        assert np.all(res[name][off] == 0.0), name
    on = (res["y"] <= u.ROCK_Y[1] - T / 2) & (res["time"] >= 0.01)
    assert on.sum() >= 3
    assert np.all(res["normalForce"][on] > 0.9 * FN_REF)
    # the law is per area: with half the tip past the edge, half the load
    # (the tip is symmetric; sliding adds a little side-face load)
    half = np.argmin(np.abs(res["y"] - u.ROCK_Y[1]))
    assert abs(res["y"][half] - u.ROCK_Y[1]) < 1e-6
    share = res["normalForce"][half] / np.mean(res["normalForce"][on])
    assert 0.45 < share < 0.55, share


@pytest.mark.parametrize("kind", KINDS)
def test_sliding_off_the_side_edge_unloads_without_a_jump(fmu, kind):
    """Same run.  Physics: per sample a strip of tip 0.1 mm wide leaves the
    rock; by the CSM law per unit tip width (F_t / T = R phi P') such a strip
    carries at most R phi(3.8 mm) P' x 0.1 mm = 0.47 kN, so no sample may
    change by more than that plus the slack: the force decays gradually
    to 0 as the tip slides off.  The slack is the share of the tip's last
    slice (9 slices across 13 mm): it carries the last millimetre of tip on
    the rock and leaves it at once.  That remainder was 2.6 kN (4.2 % of F_N)
    while each cut carved the disc's whole front arc and is 3.2-3.6 kN
    (6.0 %) since cuts stop short of it: the strip then reads the rock ahead
    as it stands, 3.6 kN for a 1 mm strip against the CSM's 4.7 kN (it read
    3.3 kN); hence 6.5 %."""
    res = side_edge_run(kind, fmu)
    strip = R * REF["phi"] * P_PRIME * SIDE_EDGE_VY * H
    bound = np.full(res["time"].size - 1, strip + 0.065 * FN_REF)
    for name in FORCES:
        u.assert_no_jump(res, name, bound, lo=START, where=f"{kind} side edge")


# =========================================================================== initial surfaces

RSF_GRID = {"rock.xMin": -0.05, "rock.xMax": 0.35, "rock.yMin": -0.03, "rock.yMax": 0.03,
            "rock.nx": 401, "rock.ny": 61}
RSF_X = np.linspace(-0.05, 0.35, 401)
RSF_Y = np.linspace(-0.03, 0.03, 61)
LEDGE = (0.1, 0.2, 2e-3)                  # a 2 mm ledge on 0.1 <= x < 0.2


def rough(x, y):
    """Long-wave roughness, +-0.7 mm: the rim's slope ahead exceeds the face's,
    so the leading arc stays one contiguous arc."""
    return (4e-4 * math.sin(2 * math.pi * x / 0.06) + 2e-4 * math.sin(2 * math.pi * x / 0.023 + 1)
            + 1e-4 * math.cos(2 * math.pi * y / 0.05))


def ledge(x, y):
    return LEDGE[2] if LEDGE[0] <= x < LEDGE[1] else 0.0


def on_grid(f):
    def g(x, y):
        if RSF_X[0] <= x <= RSF_X[-1] and RSF_Y[0] <= y <= RSF_Y[-1]:
            return f(x, y)
        return -np.inf
    return g


def rsf_start(tmp_path, f, name):
    path = u.write_rsf(tmp_path / f"{name}.rsf", RSF_X, RSF_Y, f)
    return dict(RSF_GRID, **{"rock.initialSurface": str(path)})


@pytest.mark.parametrize("kind", KINDS)
def test_rough_initial_face_from_rsf_follows_the_local_depth(fmu, kind, tmp_path):
    """A rough face (+-0.7 mm, wavelengths 23-60 mm) loaded from an .rsf file;
    the cutter rolls 0.3 m with its centre at the reference height.  Physics:
    the leading arc's depth follows the face ahead (p_geo between ~3.1 and
    4.5 mm), F_N follows the CSM F_N(p_geo) within 5 % (the FMU reads the
    deepest of its tip slices and a 1 mm map of the face) and moves only as
    fast as the law does.  Measured 4.87 % since cuts stop short of the front
    arc (5.05 % before, a known gap)."""
    sv = rsf_start(tmp_path, rough, "rough")
    ks = u.knots_line(dict(x=0.0, z=Z_REF), ROLL, 0.3)
    res = u.run(kind, fmu, ks, H, start_values=sv)
    surf = on_grid(rough)
    p_geo = np.array([u.front_depth(x, z, surf) for x, z in zip(res["x"], res["z"])])
    check_history(res, f"{kind} rough", p_geo)
    st = res["x"] >= 0.01
    fn_csm = np.array([u.csm_force(p)["FN"] for p in p_geo[st]])
    err = np.max(np.abs(res["normalForce"][st] / fn_csm - 1))
    assert err < 0.05, f"normal force strays {err:.2%} from CSM F_N(p_geo) on the rough face"
    assert np.all(res["rollingForce"][st] > 0)
    assert np.ptp(p_geo[st]) > 0.8e-3, "the roughness should matter"


@pytest.mark.parametrize("kind", KINDS)
def test_stepped_initial_face_from_rsf_steps_the_force_once_per_edge(fmu, kind, tmp_path):
    """A 2 mm ledge (0.1 <= x < 0.2) loaded from an .rsf file.  Physics: before
    and after it the cut is the reference one (F_N(3.8 mm)); with the ledge
    ahead of the lowest point the leading arc runs up to the ledge's top, so
    F_N = F_N(5.8 mm) = 75.0 kN; the rim reaching the ledge's vertical face is a
    real discontinuity (the contact zone's depth grows by 2 mm at once): one
    jump of at most F_N(5.8) - F_N(3.8) + slack, once; stepping down is
    continuous (the rim leaves the ledge's top gradually)."""
    sv = rsf_start(tmp_path, ledge, "ledge")
    ks = u.knots_line(dict(x=0.0, z=Z_REF), ROLL, 0.3)
    res = u.run(kind, fmu, ks, H, start_values=sv)
    surf = on_grid(ledge)
    p_geo = np.array([u.front_depth(x, z, surf) for x, z in zip(res["x"], res["z"])])
    hi, lo = u.csm_force(P_REF + LEDGE[2])["FN"], FN_REF
    # the step up: where the rim first reaches the ledge's face (within the
    # chord of the rim at the ledge's top, 40-50 mm before the ledge)
    fn = res["normalForce"]
    d = np.abs(np.diff(fn))
    bound = np.abs(np.diff([u.csm_force(p)["FN"] for p in p_geo])) + 0.05 * FN_REF
    over = [k + 1 for k in range(START, d.size) if d[k] > bound[k]]
    assert len(over) <= 1, f"{len(over)} jumps beyond the law at x = {res['x'][over]}"
    for k in over:
        assert LEDGE[0] - 0.06 <= res["x"][k] <= LEDGE[0] - 0.035, \
            f"the step in the force at x = {res['x'][k]:.3f} is not where the rim meets the ledge"
        assert d[k - 1] <= (hi - lo) + 0.05 * FN_REF
    check_history(res, f"{kind} ledge", p_geo, allowed=over)
    assert np.mean(fn[window(res, 0.01, 0.05)]) == pytest.approx(lo, rel=1e-2)
    assert np.mean(fn[window(res, 0.07, 0.14)]) == pytest.approx(hi, rel=1e-2)
    assert np.mean(fn[window(res, 0.21, 0.3)]) == pytest.approx(lo, rel=1e-2)


# =========================================================================== existing grooves

def two_passes(offset):
    """Pass 1: 0.25 m from x = 0 at y = 0; then the host puts the cutter back at
    x = 0, y = offset (a step in the pose inputs) and rolls it 0.2 m again, so
    pass 2 stops short of the end wall of groove 1 (the rim would meet that
    rim-shaped wall over its whole leading arc at once, a real discontinuity)."""
    return (u.knots_line(dict(x=0.0, z=Z_REF), ROLL, 0.25)
            + [dict(t=0.25, x=0.0, y=offset), dict(t=0.45, x=0.2, y=offset)])


def pass2_start(res):
    """Sample indices of the host's jump back to x = 0 and the start transient of
    pass 2 (leaving the pit the cutter was pressed into at x = 0 before pass 1)."""
    t = res["time"]
    return set(np.flatnonzero((t >= 0.25 - H / 2) & (t <= 0.25 + (START + 2) * H)).tolist())


def pass_windows(res):
    """Samples with 0.05 <= x <= 0.2 in pass 1 and in pass 2, and the volume each
    pass removed over that stretch."""
    t, v = res["time"], res["excavatedVolume"]
    p1 = (t >= 0.05) & (t <= 0.2)
    p2 = (t >= 0.30) & (t <= 0.45)
    dv1 = v[p1][-1] - v[p1][0]
    dv2 = v[p2][-1] - v[p2][0]
    return p1, p2, dv1, dv2


@pytest.mark.parametrize("kind", KINDS)
def test_recutting_the_same_groove_takes_far_less_force(fmu, kind):
    """Second pass in the groove of the first, same depth.  Physics: the groove
    already has the rim's shape; only the 2 um elastic layer touches, so the
    force is a small fraction of the first pass (< 10 %), no rock is removed
    (< 1 % of pass 1 over the same stretch), and the force is steady.  The first
    5 mm of pass 2 are the cutter leaving the pit it was pressed into at x = 0
    (real: that pit's rear wall bears until the cutter has moved off it)."""
    res = u.run(kind, fmu, two_passes(0.0), H)
    t = res["time"]
    p1, p2, dv1, dv2 = pass_windows(res)
    check_history(res, f"{kind} recut", allowed=pass2_start(res),
                  p_geo=np.where(t <= 0.25, P_REF, 0.0))
    f1, f2 = np.mean(res["normalForce"][p1]), np.mean(res["normalForce"][p2])
    assert f1 == pytest.approx(FN_REF, rel=5e-3)
    assert 0 <= f2 < 0.1 * f1, f"re-cut {f2:.0f} N vs first cut {f1:.0f} N"
    assert 0 <= dv2 < 0.01 * dv1, "the second pass removed rock from a groove already cut"
    # pass 2 past its start pit: steady, jumps bounded by 5 % of its own force
    check_history({k: (a[t > 0.255] if isinstance(a, np.ndarray) else a) for k, a in res.items()},
                  f"{kind} recut pass 2", scale=max(f2, 0.01 * f1), skip=0)


@pytest.mark.parametrize("kind", KINDS)
def test_cutting_10mm_beside_a_groove_pushes_towards_the_free_side(fmu, kind):
    """Second pass 10 mm beside the first groove (the 13 mm tips overlap by 3 mm
    at the face).  Physics: the tip's side towards the old groove has less rock
    to bear on, the side in intact rock pushes the cutter towards the groove:
    sideForce < 0 (cutter +y points away from the groove), clearly nonzero yet
    below tan 31 deg of F_N; F_N a little below the fresh cut's; less rock is
    removed than in the first pass, but most of a groove."""
    res = u.run(kind, fmu, two_passes(0.01), H)
    t = res["time"]
    p1, p2, dv1, dv2 = pass_windows(res)
    check_history(res, f"{kind} beside", p_geo=np.full_like(t, P_REF), allowed=pass2_start(res))
    fn2, fs2 = np.mean(res["normalForce"][p2]), np.mean(res["sideForce"][p2])
    assert fs2 < -0.02 * fn2, f"side force {fs2:.0f} N does not push towards the groove"
    assert fs2 > -math.tan(math.radians(31)) * fn2
    assert 0.8 * FN_REF < fn2 <= 1.001 * FN_REF
    assert 0.5 * dv1 < dv2 < 0.95 * dv1


@pytest.mark.parametrize("kind", KINDS)
def test_cutting_20mm_beside_a_groove_is_a_fresh_cut(fmu, kind):
    """Control: 20 mm apart the grooves (13 mm wide) do not overlap, so the
    second pass is the reference cut: no side force, F_N and volume as pass 1."""
    res = u.run(kind, fmu, two_passes(0.02), H)
    t = res["time"]
    p1, p2, dv1, dv2 = pass_windows(res)
    check_history(res, f"{kind} 20 mm beside", p_geo=np.full_like(t, P_REF), allowed=pass2_start(res))
    assert np.mean(res["normalForce"][p2]) == pytest.approx(FN_REF, rel=5e-3)
    assert np.all(np.abs(res["sideForce"][p2]) < 1e-3 * FN_REF)
    assert dv2 == pytest.approx(dv1, rel=0.01)


# =========================================================================== communication steps

WARMUP = 0.05                               # 50 mm at 1 ms before the step size changes


def cs_with_step(fmu, h, travel):
    """CS, velocity inputs only (the FMU carries the pose): 50 mm at 1 ms from rest
    at x = 0, then steps of h for `travel` metres.  Returns the outputs after
    each step of h and the volume removed during them."""
    host = u.CSHost(fmu, None, dict(x=0.0, z=Z_REF, **ROLL), name=f"h{h}")
    try:
        for _ in range(round(WARMUP / H)):
            host.step(H)
        v0 = host.outputs()[kh.REAL_OUTPUTS.index("excavatedVolume")]
        rows = []
        for _ in range(round(travel / h)):
            host.step(h)
            rows.append(host.outputs())
    finally:
        host.free()
    a = np.asarray(rows, dtype=float)
    res = {name: a[:, i] for i, name in enumerate(u.OUTPUTS)}
    res["inContact"] = a[:, len(u.OUTPUTS)]
    res["time"] = WARMUP + h * np.arange(1, len(rows) + 1)
    res["x"] = res["time"] * 1.0
    res["z"] = np.full_like(res["time"], Z_REF)
    return res, res["excavatedVolume"][-1] - v0, v0


@pytest.fixture(scope="module")
def cs_1ms(fmu):
    """The 1 ms reference of the step-size sweep, 1.0 m past the warm-up: its
    outputs and the volume removed since the warm-up after each millimetre."""
    res, _, v0 = cs_with_step(fmu, H, 1.0)
    return res, res["excavatedVolume"] - v0


STEPS = [(1e-6, 5e-3), (1e-5, 5e-3), (1e-4, 0.05), (1e-3, 0.2), (1e-2, 0.2), (0.05, 0.2),
         (0.1, 0.5), (0.5, 1.0)]


@pytest.mark.parametrize("h,travel", STEPS, ids=[f"h={h:g}s" for h, _ in STEPS])
def test_cs_step_size_from_1us_to_half_a_second_gives_the_same_cut(fmu, cs_1ms, h, travel):
    """CS at 1 m/s with communication steps from 1 us to 0.5 s (1 um to 0.5 m of
    travel per step).  Physics: the cut does not depend on how the host samples
    it: outputs finite; for steps up to 50 mm every sample of F_N is the steady
    CSM value within 0.5 % and the mean of F_N and F_R within 0.2 % of the 1 ms
    run; for every step the rock removed over the same travel matches the 1 ms
    run within 0.5 % (CS cuts along the whole path of a step)."""
    res, dv, _ = cs_with_step(fmu, h, travel)
    u.assert_finite(res, f"h = {h}")
    ref, vref = cs_1ms
    k = round(travel / H) - 1
    assert dv == pytest.approx(vref[k], rel=5e-3), \
        f"h = {h}: removed {dv * 1e6:.4f} cm3 over {travel} m vs {vref[k] * 1e6:.4f} cm3 at 1 ms"
    if h * 1.0 <= 0.05 + 1e-12:
        fn = res["normalForce"]
        assert np.max(np.abs(fn / FN_REF - 1)) < 5e-3
        for name in ("normalForce", "rollingForce"):
            m, mref = np.mean(res[name]), np.mean(ref[name])
            assert m == pytest.approx(mref, rel=2e-3), f"{name}: {m:.1f} vs {mref:.1f} at 1 ms"
        check_history(res, f"h = {h}", np.full_like(res["time"], P_REF), skip=0)


# =========================================================================== thrust-driven host

@pytest.mark.parametrize("motion,zeta,h", [("rest", 1.0, 1e-3), ("rolling", 1.0, 1e-3),
                                           ("rolling", 0.3, 5e-4)],
                         ids=["rest-critical", "rolling-critical", "rolling-underdamped"])
@pytest.mark.parametrize("kind", KINDS)
def test_thrust_driven_cutter_settles_at_the_csm_depth(fmu, kind, motion, zeta, h):
    """A host that drives the cutter by a thrust of 50 kN: m z'' = normalForce -
    thrust - c z' (m = 100 kg, c = zeta times critical for the law's stiffness
    F/(2p)), semi-implicit Euler at h, starting at rest touching the face;
    CS feeds the pose each step, ME is a hand-written FMU2Model loop with step
    events.  Physics: the cutter sinks until the rock carries the thrust and
    stays there: finite depth, no sinking through and no flying off (in contact
    from the first touch on), depth = the CSM inverse of the thrust (at rest the
    symmetric pit carries F_t; rolling, the leading arc carries F_N) within 3 %,
    and N = thrust at the end within 0.5 %.

    The underdamped host takes 0.5 ms steps. A disc that drives down into the
    rock bears on its whole lower arc, far stiffer than F/(2p): its force rises
    by some 70 kN over a few tenths of a millimetre. At 1 ms an explicit host
    with zeta 0.3 (or 0.6) cannot follow that: the disc plunges, rebounds
    clear of the rock its plunge cut, and falls into it again, a three-step
    cycle that ratchets it to 5-6 mm (README, "Driving the cutter by thrust");
    at 0.5 and 0.25 ms it settles at the CSM depth to 3e-7 m."""
    thrust = 50e3
    vx = 0.0 if motion == "rest" else 1.0
    res = u.thrust_host(kind, fmu, thrust, vx=vx, n=int(round(0.4 / h)), h=h, zeta=zeta)
    u.assert_finite(res, f"{kind} thrust {motion}")
    for name in ("z", "vz"):
        assert np.all(np.isfinite(res[name]))
    depth = R - res["z"]
    p_expect = u.csm_inverse(thrust, "Ft" if motion == "rest" else "FN")
    first = np.argmax(res["inContact"] > 0)
    assert np.all(res["inContact"][first:] == 1), "the cutter left the rock"
    assert np.max(depth) < 2 * p_expect, f"sank to {np.max(depth) * 1e3:.2f} mm"
    tail = slice(-100, None)
    assert np.ptp(depth[tail]) < 1e-6, "the cutter did not settle"
    assert np.mean(depth[tail]) == pytest.approx(p_expect, rel=0.03), \
        f"settled at {np.mean(depth[tail]) * 1e3:.3f} mm vs CSM inverse {p_expect * 1e3:.3f} mm"
    assert np.mean(res["normalForce"][tail]) == pytest.approx(thrust, rel=5e-3)

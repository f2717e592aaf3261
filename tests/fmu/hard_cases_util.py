"""Hosts and checks for tests/fmu/test_hard_cases.py (issue 4 section 2).

Everything goes through the FMI 2.0 API as fmpy exposes it (black box):

* `run_cs`  - a Co-Simulation host loop (FMU2Slave through kerfhost.Instance)
  that either feeds the whole pose before every step (pose(t) = pose0 + v t)
  or leaves the pose to the FMU (velocity inputs only);
* `run_me`  - Model Exchange through `fmpy.simulate_fmu(..., solver='CVode')`
  with a two-row input table (pose linear in time, velocities constant);
* `run` - either of the two, by interface name;
* `MEHost` - a hand-written ME host loop (FMU2Model) for closed-loop hosts
  (the thrust-driven cutter): explicit steps, step events committed in
  fmi2NewDiscreteStates;
* `csm_force` - the CSM closed form of thesis eqs 13-17 at penetration p;
* `assert_finite`, `max_jump`, `write_rsf`.
"""

from __future__ import annotations

import math

import numpy as np

import fmpy

import kerfhost as kh

R = kh.REFERENCE["R"]          # 0.2159 m
T = kh.REFERENCE["T"]          # 0.013 m
P_REF = kh.REFERENCE["p"]      # 3.8 mm
Z_REF = R - P_REF              # 0.2121: centre height of the reference cut
MU = 0.3                       # friction.mu default (fmi-notes / brief)
VS = 0.01                      # friction.vs default

OUTPUTS = kh.REAL_OUTPUTS
POSE = ["x", "y", "z", "yaw", "pitch", "roll"]
VEL = ["vx", "vy", "vz", "wx", "wy", "wz"]
INPUTS = POSE + VEL

#: Default rock of the FMU (interface.md): x in [-0.25, 1.25], y in [-0.1, 0.1].
ROCK_X = (-0.25, 1.25)
ROCK_Y = (-0.1, 0.1)


def csm_force(p, R=R, T=T, ucs=158e6, bts=6.78e6, S=0.051, C=2.12):
    """CSM closed form (thesis eqs 13-17) at penetration p: dict Ft, FN, FR, phi."""
    if p <= 0:
        return dict(Ft=0.0, FN=0.0, FR=0.0, phi=0.0)
    return kh.csm_theory(R, T, ucs, bts, S, C, min(p, 2 * R))


P_REG = 5e-5                   # numerics.pReg default: below it the law is a quadratic


def base_pressure(R=R, T=T, ucs=158e6, bts=6.78e6, S=0.051, C=2.12):
    """CSM base pressure P' (thesis eq. 15)."""
    return C * (ucs ** 2 * bts * S / math.sqrt(R * T)) ** (1.0 / 3.0)


def law_ft(p, R=R, T=T, p_reg=P_REG):
    """Resultant CSM force F_t(p) = T R phi P' as the FMU evaluates it: regularised
    below p_reg by the quadratic a p + b p^2 with the same value and slope there."""
    def raw(q):
        return T * R * math.acos(max(-1.0, min(1.0, (R - q) / R))) * base_pressure(R, T)
    if p <= 0:
        return 0.0
    if p >= p_reg:
        return raw(p)
    h = p_reg * 1e-4
    f0, f1 = raw(p_reg), (raw(p_reg + h) - raw(p_reg - h)) / (2 * h)
    a = (2 * f0 - f1 * p_reg) / p_reg
    b = (f1 * p_reg - f0) / p_reg ** 2
    return max(0.0, a * p + b * p * p)


def front_depth(xc, zc, surface, y=0.0, R=R, dx=5e-5):
    """Geometric penetration of an upright disc (centre xc, zc, pitch 0) rolling
    towards +x into the rock z < surface(x, y): the vertical depth of the first
    contiguous stretch of rim inside the rock met when walking forwards from the
    lowest point (thesis eq. 54 for the leading arc); 0 if the rim is nowhere in
    the rock ahead."""
    xs = xc + np.arange(0.0, R, dx)
    zr = zc - np.sqrt(np.maximum(R * R - (xs - xc) ** 2, 0.0))
    zs = np.array([surface(x, y) for x in xs])
    inside = zs > zr
    first = np.flatnonzero(inside)
    if first.size == 0:
        return 0.0
    i0 = first[0]
    out = np.flatnonzero(~inside[i0:])
    i1 = i0 + out[0] - 1 if out.size else len(xs) - 1
    return float(zr[i1] - zr[i0])


def csm_inverse(f, component="FN", R=R, T=T):
    """Penetration p at which the CSM force component (FN = F_t cos(phi/2) of a
    rolling cutter, or Ft of a cutter pressed straight down at rest) equals f."""
    lo, hi = 0.0, 0.5 * R
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if csm_force(mid, R, T)[component] < f:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def csm_inverse_normal(fn, R=R, T=T):
    return csm_inverse(fn, "FN", R, T)


def rolling_twist(v, roll=0.0, R=R):
    """Angular velocity of a disc rolling without slip at speed v (rock +x) with
    roll angle `roll`: spin v/R about the axle (0, cos roll, sin roll), so the
    slip of the lowest rim point vanishes and the fork frame does not turn."""
    w = v / R
    return dict(vx=v, wy=w * math.cos(roll), wz=w * math.sin(roll))


# --------------------------------------------------------------------------- scenarios

def knots_line(pose0: dict, twist: dict, t1: float, t0: float = 0.0):
    """Two knots of a constant-velocity motion from pose0 at t0 to t1."""
    p0 = _full(pose0, POSE)
    tw = _full(twist, VEL)
    p1 = dict(p0, x=p0["x"] + tw["vx"] * (t1 - t0), y=p0["y"] + tw["vy"] * (t1 - t0),
              z=p0["z"] + tw["vz"] * (t1 - t0))
    return [dict(p0, t=t0, **tw), dict(p1, t=t1, **tw)]


def _full(d, names):
    return {n: float(d.get(n, 0.0)) for n in names}


def normalise(knots):
    """Complete every knot: inputs missing from a knot carry over from the previous one."""
    out, last = [], {n: 0.0 for n in INPUTS}
    for k in knots:
        last = dict(last, **{n: float(v) for n, v in k.items() if n != "t"})
        out.append(dict(last, t=float(k["t"])))
    return out


def inputs_at(knots, t):
    """Inputs at time t: linear between knots, right-continuous at a repeated time (a step)."""
    ks = knots
    if t <= ks[0]["t"]:
        i = max(j for j in range(len(ks)) if ks[j]["t"] == ks[0]["t"])
        return {n: ks[i][n] for n in INPUTS}
    for j in range(len(ks) - 1):
        a, b = ks[j], ks[j + 1]
        if a["t"] <= t < b["t"]:
            # the last knot at time a.t is the right limit
            s = (t - a["t"]) / (b["t"] - a["t"])
            return {n: a[n] + s * (b[n] - a[n]) for n in INPUTS}
    return {n: ks[-1][n] for n in INPUTS}


# --------------------------------------------------------------------------- hosts

class CSHost:
    """A Co-Simulation host (FMU2Slave via kerfhost.Instance) that records every output."""

    def __init__(self, fmu: kh.FMU, start_values=None, inputs=None, name="hard-cs"):
        self.inst = fmu.instance("CS", name=name)
        self.inst.initialize(start_values, inputs=inputs)
        self.t = 0.0

    def set(self, values: dict):
        self.inst.set_reals(list(values), list(values.values()))

    def step(self, h, inputs: dict | None = None):
        if inputs:
            self.set(inputs)
        self.inst.f.doStep(currentCommunicationPoint=self.t, communicationStepSize=h)
        self.t += h

    def outputs(self):
        return list(self.inst.get_reals(OUTPUTS)) + [float(self.inst.get("inContact"))]

    def free(self):
        self.inst.free()


def run_cs(fmu: kh.FMU, knots, h: float = 1e-3, start_values=None, feed_pose=True,
           name="hard-cs"):
    """Co-Simulation along a knot table: initialise with the inputs at t = 0, then
    before every fmi2DoStep(t, h) set the velocities of [t, t + h) and (feed_pose)
    the whole pose at t; without feed_pose the FMU carries the pose itself.
    Returns a dict of arrays: time, the commanded pose (x, y, z, roll) at each
    sample, every Real output and inContact (0/1), sampled after initialisation
    and after each step."""
    ks = normalise(knots)
    stop = ks[-1]["t"]
    n = int(round(stop / h))
    host = CSHost(fmu, start_values, inputs_at(ks, 0.0), name=name)
    try:
        rows, times = [host.outputs()], [0.0]
        for k in range(n):
            t = k * h
            u = inputs_at(ks, t)
            host.step(h, u if feed_pose else {q: u[q] for q in VEL})
            rows.append(host.outputs())
            times.append((k + 1) * h)
        log = list(host.inst.log)
    finally:
        host.free()
    res = _table(rows, times, ks)
    res["log"] = log
    return res


def _table(rows, times, ks):
    a = np.asarray(rows, dtype=float)
    res = {name: a[:, i] for i, name in enumerate(OUTPUTS)}
    res["inContact"] = a[:, len(OUTPUTS)]
    t = np.asarray(times, dtype=float)
    res["time"] = t
    # the pose the cutter is at when the sample is taken (left limit at a step)
    for q in POSE:
        res[q] = np.array([_left(ks, tt)[q] for tt in t])
    return res


def _left(ks, t):
    """Inputs at t as the left limit (the pose reached at the end of a step)."""
    for j in range(len(ks) - 1):
        a, b = ks[j], ks[j + 1]
        if a["t"] < t <= b["t"]:
            s = (t - a["t"]) / (b["t"] - a["t"])
            return {n: a[n] + s * (b[n] - a[n]) for n in INPUTS}
    return inputs_at(ks, t)


def run_me(fmu: kh.FMU, knots, output_interval: float = 1e-3, start_values=None):
    """Model Exchange with fmpy's CVode: the knot table is the input signal (linear
    between rows, a repeated time is a step), outputs every output_interval."""
    ks = normalise(knots)
    stop = ks[-1]["t"]
    sig = np.array([tuple([k["t"]] + [k[n] for n in INPUTS]) for k in ks],
                   dtype=[("time", np.float64)] + [(n, np.float64) for n in INPUTS])
    r = fmpy.simulate_fmu(fmu.unzipdir, model_description=fmu.md, fmi_type="ModelExchange",
                          solver="CVode", start_values=dict(start_values or {}), input=sig,
                          output=list(OUTPUTS) + ["inContact"], stop_time=stop,
                          output_interval=output_interval, record_events=False)
    rows = [[float(r[n][i]) for n in OUTPUTS] + [float(r["inContact"][i])] for i in range(len(r))]
    return _table(rows, list(np.asarray(r["time"], dtype=float)), ks)


def run(kind, fmu, knots, h=1e-3, start_values=None, **kw):
    """The same scenario through either interface: CS steps of h, or ME (CVode)
    with outputs every h."""
    if kind == "CS":
        return run_cs(fmu, knots, h, start_values, **kw)
    if kind == "ME":
        return run_me(fmu, knots, h, start_values)
    raise ValueError(kind)


def thrust_host(kind, fmu, thrust, vx=0.0, n=400, h=1e-3, m=100.0, zeta=1.0, k_est=None,
                start_values=None):
    """A host that drives the cutter by thrust: the disc centre height z follows
    m z'' = normalForce - thrust - c z' (semi-implicit Euler, step h), the cutter
    rolls at vx (wy = vx / R).  c is zeta times the critical damping of a spring as
    stiff as the CSM law around the expected depth (k_est).  Works through either
    interface: CS (FMU2Slave, the whole pose fed each step) or ME (FMU2Model, an
    explicit host loop with step events).  Returns time, z, vz, and the outputs."""
    if k_est is None:
        p = csm_inverse_normal(thrust)
        k_est = thrust / (2 * p)               # dF/dp ~ F / (2p) (F ~ sqrt(p))
    c = 2 * zeta * math.sqrt(k_est * m)
    z, vz, x = R, 0.0, 0.0                     # start touching the face, at rest
    tw = dict(vx=vx, wy=vx / R)
    u0 = dict(x=x, z=z, vz=vz, **tw)
    host = CSHost(fmu, start_values, u0) if kind == "CS" else MEHost(fmu, start_values, u0)
    ts, zs, vs, rows = [], [], [], []
    try:
        t = 0.0
        for k in range(n):
            if kind == "CS":
                host.step(h, dict(x=x, z=z, vz=vz, **tw))
            else:
                host.step(t, dict(x=x, z=z, vz=vz, **tw))
            out = host.outputs()
            ts.append(t + h if kind == "CS" else t)
            zs.append(z + h * vz if kind == "CS" else z)   # the pose the outputs belong to
            vs.append(vz)
            rows.append(out)
            fn = out[OUTPUTS.index("normalForce")]
            # semi-implicit Euler of the host's dynamics
            vz += h * (fn - thrust - c * vz) / m
            z += h * vz
            x += h * vx
            t += h
    finally:
        host.free()
    a = np.asarray(rows, dtype=float)
    res = {name: a[:, i] for i, name in enumerate(OUTPUTS)}
    res["inContact"] = a[:, len(OUTPUTS)]
    res.update(time=np.array(ts), z=np.array(zs), vz=np.array(vs), x=vx * np.array(ts))
    return res


class MEHost:
    """A hand-written Model Exchange host (FMU2Model): the host owns time and the
    inputs; after every accepted step it calls fmi2CompletedIntegratorStep and,
    when the FMU asks, runs the event iteration that commits the cut."""

    def __init__(self, fmu: kh.FMU, start_values=None, inputs=None, name="hard-me"):
        self.inst = fmu.instance("ME", name=name)
        self.inst.initialize(start_values, inputs=inputs)
        self.t = 0.0
        self.events = 0

    def step(self, t, inputs: dict):
        f = self.inst.f
        f.setTime(t)
        self.inst.set_reals(list(inputs), list(inputs.values()))
        step_event, terminate = f.completedIntegratorStep()
        if step_event:
            f.enterEventMode()
            self.inst.event_iteration()
            f.enterContinuousTimeMode()
            self.events += 1
        self.t = t

    def outputs(self):
        return list(self.inst.get_reals(OUTPUTS)) + [float(self.inst.get("inContact"))]

    def free(self):
        self.inst.free()


# --------------------------------------------------------------------------- checks

def assert_finite(res, where=""):
    for name in OUTPUTS + ["inContact"]:
        v = res[name]
        bad = ~np.isfinite(v)
        assert not bad.any(), (f"{where}: {name} non-finite at t = {res['time'][bad][:5]} "
                               f"(x = {res['x'][bad][:5]})")


def max_jump(values, lo=0):
    """Largest |difference| between consecutive samples from index lo on, and its index."""
    d = np.abs(np.diff(np.asarray(values, dtype=float)[lo:]))
    if d.size == 0:
        return 0.0, lo
    k = int(np.argmax(d))
    return float(d[k]), lo + k + 1


def assert_no_jump(res, name, bound, lo=0, where="", allowed=None):
    """|F[k] - F[k-1]| <= bound (a number or an array aligned with the differences)
    for every k > lo, except indices in `allowed` (a set of sample indices)."""
    f = np.asarray(res[name], dtype=float)
    d = np.abs(np.diff(f))
    b = np.broadcast_to(np.asarray(bound, dtype=float), d.shape)
    bad = [k + 1 for k in range(lo, d.size) if d[k] > b[k] and not (allowed and (k + 1) in allowed)]
    if bad:
        k = bad[0]
        raise AssertionError(
            f"{where}: {name} jumps by {d[k - 1]:.1f} N between samples {k - 1} and {k} "
            f"(t = {res['time'][k - 1]:.6g} -> {res['time'][k]:.6g}, x = {res['x'][k]:.4f}, "
            f"z = {res['z'][k]:.6f}: {f[k - 1]:.1f} -> {f[k]:.1f}), bound {b[k - 1]:.1f} N; "
            f"{len(bad)} such jumps")


def write_rsf(path, xs, ys, zfun):
    """Write a `.rsf` surface: one node a line `L K x y z`, 1-based, every node of the grid."""
    lines = ["# kerf surface written by test_hard_cases.py", "# L K x y z"]
    for L, x in enumerate(xs, start=1):
        for K, y in enumerate(ys, start=1):
            lines.append(f"{L} {K} {x:.9g} {y:.9g} {zfun(x, y):.9g}")
    path.write_text("\n".join(lines) + "\n")
    return path


def lowest_point(roll, R=R, T=T, r=kh.REFERENCE["r"], n=2001):
    """Offset (dy, dz) from the disc centre of the lowest point of the tip of an
    upright-yawed disc with roll angle `roll` (pitch 0), by sampling the tip
    profile R(y) = R - r + sqrt(r^2 - y^2), |y| <= T/2 (cutter frame)."""
    yl = np.linspace(-T / 2, T / 2, n)
    rho = R - r + np.sqrt(r * r - yl * yl)
    # the lowest point of each rim circle is at theta = 0 (x_local = 0), z_local = -rho
    c, s = math.cos(roll), math.sin(roll)
    wy = c * yl - s * (-rho)
    wz = s * yl + c * (-rho)
    k = int(np.argmin(wz))
    return float(wy[k]), float(wz[k])


def tilted_pose(roll, depth, x=0.0, y_low=0.0):
    """Pose of a disc with roll `roll` whose lowest tip point is `depth` below the
    face z = 0 at (x, y_low)."""
    dy, dz = lowest_point(roll)
    return dict(x=x, y=y_low - dy, z=-dz - depth, roll=roll)

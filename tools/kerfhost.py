"""A small fmpy host for kerf.fmu, shared by scripts/reference_scene.py and tests/fmu.

It knows nothing about kerf's internals: everything goes through the FMI 2.0
C API as fmpy exposes it (black box).  What it adds on top of fmpy:

* get/set by variable *name* with the right FMI type (Real, Integer,
  Enumeration, Boolean, String);
* a logger callback that records every message the FMU logs, so tests can
  check that an error came with a message;
* the reference line cut in Co-Simulation (`run_line_cs`) and in Model
  Exchange (`run_line_me`);
* the CSM closed form of thesis eqs 13-17 (`csm_theory`);
* reading `.rsf` surface files (`load_rsf`).
"""

from __future__ import annotations

import math
import os
import re
import subprocess
from ctypes import byref
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import fmpy
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException  # noqa: F401  (re-exported for callers)
from fmpy.fmi2 import (
    FMU2Model,
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_FMU = ROOT / "target" / "fmu" / "kerf.fmu"

#: Real outputs of interface.md (inContact is Boolean and handled apart).
REAL_OUTPUTS = [
    "Fx", "Fy", "Fz", "Mx", "My", "Mz",
    "normalForce", "rollingForce", "sideForce",
    "penetration", "contactAngle",
    "excavatedVolume", "cuttingEnergy", "specificEnergy",
]
INPUTS = ["x", "y", "z", "yaw", "pitch", "roll", "vx", "vy", "vz", "wx", "wy", "wz"]

STATUS = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]
FMI2_ERROR = 3

#: Thesis reference scene (Table 2) and the cut of ch. 9.
REFERENCE = dict(R=0.2159, T=0.013, r=0.0127, ucs=158e6, bts=6.78e6, S=0.051, C=2.12,
                 p=3.8e-3, v=1.0, length=1.0)

#: What thesis-notes.md gives for the reference scene (eqs 13-17, SI units).
THESIS_NOTES_CSM = dict(phi=0.187897, P=115.79e6, Ft=61.065e3, FN=60.795e3, FR=5.7285e3)

#: Thesis Table 3 (kN): normal, rolling, side (None: not given).
TABLE3 = {
    "CSM theory (thesis Table 3)": (60.8, 5.8, None),
    "Adams simulation (thesis Table 3)": (60.9, 13.4, 12.6),
    "LCM test, Gertsch et al. 2007 (Table 3)": (81.0, 7.3, 11.2),
}


# --------------------------------------------------------------------------- theory

def csm_theory(R, T, ucs, bts, S, C, p, psi=0.0):
    """CSM force for a cutter at penetration p (thesis eqs 13-17, Rostami 1997).

    phi = acos((R-p)/R); P' = C cbrt(ucs^2 bts S / sqrt(R T));
    F_t = T R phi P' / (1+psi); F_N = F_t cos(beta); F_R = F_t sin(beta),
    beta = phi / (2+psi)  (= phi/2 for the uniform pressure of the thesis).
    """
    phi = math.acos((R - p) / R)
    P = C * (ucs ** 2 * bts * S / math.sqrt(R * T)) ** (1.0 / 3.0)
    Ft = T * R * phi * P / (1.0 + psi)
    beta = phi / (2.0 + psi)
    return dict(phi=phi, P=P, Ft=Ft, FN=Ft * math.cos(beta), FR=Ft * math.sin(beta), beta=beta)


def check_theory_against_notes(th, rel=5e-5):
    """Assert that our closed form reproduces the numbers of thesis-notes.md."""
    for k, want in THESIS_NOTES_CSM.items():
        got = th[k]
        # the notes round to 5-6 significant digits
        assert abs(got - want) <= rel * abs(want), f"CSM {k}: computed {got!r}, thesis-notes.md {want!r}"


# --------------------------------------------------------------------------- build

def build_fmu(root: Path = ROOT) -> Path:
    """`cargo run --release -p packaging`; returns target/fmu/kerf.fmu."""
    subprocess.run(["cargo", "run", "--release", "-p", "packaging"], cwd=root, check=True)
    fmu = root / "target" / "fmu" / "kerf.fmu"
    if not fmu.is_file():
        raise FileNotFoundError(f"packaging finished but {fmu} does not exist")
    return fmu


def fmu_path_from_env(build_if_missing=True) -> Path:
    """KERF_FMU if set (must exist), else target/fmu/kerf.fmu (built if absent)."""
    env = os.environ.get("KERF_FMU")
    if env:
        p = Path(env).resolve()
        if not p.is_file():
            raise FileNotFoundError(f"KERF_FMU={env} does not exist")
        return p
    if DEFAULT_FMU.is_file() or not build_if_missing:
        return DEFAULT_FMU
    return build_fmu()


# --------------------------------------------------------------------------- host

@dataclass
class LogRecord:
    instance: str
    status: int
    category: str
    message: str

    def __str__(self):
        s = STATUS[self.status] if 0 <= self.status < len(STATUS) else str(self.status)
        return f"[{s}] {self.instance} {self.category}: {self.message}"


class FMU:
    """An extracted kerf.fmu plus its model description; makes instances."""

    def __init__(self, path, unzipdir=None):
        self.path = Path(path)
        self.md = read_model_description(str(self.path))
        self.unzipdir = unzipdir or extract(str(self.path))
        self.vars = {v.name: v for v in self.md.modelVariables}

    def var(self, name):
        try:
            return self.vars[name]
        except KeyError:
            raise KeyError(f"kerf.fmu has no variable {name!r}") from None

    def start(self, name):
        v = self.var(name)
        if v.start is None:
            return None
        if v.type == "Real":
            return float(v.start)
        if v.type in ("Integer", "Enumeration"):
            return int(v.start)
        if v.type == "Boolean":
            return v.start in (True, "true", "1", 1)
        return v.start

    def instance(self, kind="CS", name="kerf", logging_on=True):
        return Instance(self, kind=kind, name=name, logging_on=logging_on)


class Instance:
    """One FMI instance (CS: FMU2Slave, ME: FMU2Model) with a capturing logger."""

    def __init__(self, fmu: FMU, kind="CS", name="kerf", logging_on=True):
        self.fmu_file = fmu
        self.kind = kind
        self.log: list[LogRecord] = []
        md = fmu.md
        if kind == "CS":
            cls, ident = FMU2Slave, md.coSimulation.modelIdentifier
        elif kind == "ME":
            cls, ident = FMU2Model, md.modelExchange.modelIdentifier
        else:
            raise ValueError(kind)

        def logger(env, instance_name, status, category, message):
            def dec(b):
                return b.decode("utf-8", "replace") if b is not None else ""
            self.log.append(LogRecord(dec(instance_name), int(status), dec(category), dec(message)))

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(fmpy.calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(fmpy.free)
        from fmpy.logging import addLoggerProxy  # formats the variadic message in C
        addLoggerProxy(byref(cb))
        self._logger, self._callbacks = logger, cb  # keep alive while the FMU may call back
        self.f = cls(guid=md.guid, unzipDirectory=fmu.unzipdir, modelIdentifier=ident,
                     instanceName=name)
        self.f.instantiate(visible=False, callbacks=cb, loggingOn=logging_on)
        self.freed = False

    # -- values by name
    def _vr(self, name):
        return self.fmu_file.var(name).valueReference

    def set(self, values: dict):
        for name, value in values.items():
            v = self.fmu_file.var(name)
            vr = [v.valueReference]
            if v.type == "Real":
                self.f.setReal(vr, [float(value)])
            elif v.type in ("Integer", "Enumeration"):
                self.f.setInteger(vr, [int(value)])
            elif v.type == "Boolean":
                self.f.setBoolean(vr, [bool(value)])
            elif v.type == "String":
                self.f.setString(vr, [str(value)])
            else:
                raise TypeError(f"{name}: type {v.type}")

    def set_reals(self, names, values):
        self.f.setReal([self._vr(n) for n in names], [float(x) for x in values])

    def get_reals(self, names):
        return self.f.getReal([self._vr(n) for n in names])

    def get(self, name):
        v = self.fmu_file.var(name)
        vr = [v.valueReference]
        if v.type == "Real":
            return self.f.getReal(vr)[0]
        if v.type in ("Integer", "Enumeration"):
            return self.f.getInteger(vr)[0]
        if v.type == "Boolean":
            return bool(self.f.getBoolean(vr)[0])
        return self.f.getString(vr)[0]

    # -- life cycle
    def initialize(self, start_values=None, t0=0.0, stop=None, inputs=None):
        """setupExperiment, parameters in Instantiated, inputs in InitializationMode, exit."""
        self.f.setupExperiment(startTime=t0, stopTime=stop)
        if start_values:
            self.set(start_values)
        self.f.enterInitializationMode()
        if inputs:
            self.set(inputs)
        self.f.exitInitializationMode()
        if self.kind == "ME":
            self.event_iteration()
            self.f.enterContinuousTimeMode()

    def event_iteration(self):
        for _ in range(100):
            need, terminate, *_ = self.f.newDiscreteStates()
            if terminate:
                raise RuntimeError("kerf asked to terminate")
            if not need:
                return
        raise RuntimeError("kerf never converged in event iteration")

    def errors(self):
        return [r for r in self.log if r.status >= FMI2_ERROR]

    def free(self, terminate=True):
        if self.freed:
            return
        if terminate:
            try:
                self.f.terminate()
            except Exception:
                pass
        self.f.freeInstance()
        self.freed = True


# --------------------------------------------------------------------------- runs

def line_inputs(fmu: FMU, start_values=None, depth=None, v=None):
    """Constant inputs of the reference cut: z = R - depth, vx = v, wy = v / R."""
    sv = start_values or {}
    R = float(sv.get("cutter.radius", fmu.start("cutter.radius")))
    depth = REFERENCE["p"] if depth is None else depth
    v = REFERENCE["v"] if v is None else v
    z0 = float(sv.get("rock.z0", fmu.start("rock.z0") or 0.0))
    return dict(z=z0 + R - depth, vx=v, wy=v / R), R


def run_line_cs(inst: Instance, start_values=None, n_steps=1000, h=1e-3, depth=None, v=None,
                outputs=REAL_OUTPUTS, feed_x=True, initialize=True, t0=0.0, x0=0.0):
    """The reference linear cut in Co-Simulation.

    The cutter starts at x = x0, z = R - depth (pressed in at rest), moves at vx = v
    rolling without slip (wy = v/R); the host feeds x(t) before every doStep
    (feed_x) or leaves the pose to the FMU.  Returns a dict of numpy arrays: time,
    x, and every output, sampled at t0 and after each step.
    """
    fixed, _ = line_inputs(inst.fmu_file, start_values, depth, v)
    v = fixed["vx"]
    if initialize:
        inst.initialize(start_values, t0=t0, inputs=dict(fixed, x=x0))
    rows = [inst.get_reals(outputs)]
    times = [t0]
    t = t0
    for k in range(n_steps):
        if feed_x:
            inst.set_reals(["x"], [x0 + v * (t - t0)])
        inst.f.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t = t0 + (k + 1) * h
        rows.append(inst.get_reals(outputs))
        times.append(t)
    res = {name: np.array([r[i] for r in rows]) for i, name in enumerate(outputs)}
    res["time"] = np.array(times)
    res["x"] = x0 + v * (res["time"] - t0)
    return res


def run_line_me(fmu: FMU, solver="CVode", start_values=None, stop=1.0, depth=None, v=None,
                outputs=REAL_OUTPUTS, output_interval=1e-3, step_size=None):
    """The reference cut in Model Exchange via fmpy.simulate_fmu (x(t) = v t as input)."""
    fixed, _ = line_inputs(fmu, start_values, depth, v)
    sig = np.array(
        [(0.0, 0.0, fixed["z"], fixed["vx"], fixed["wy"]),
         (stop, fixed["vx"] * stop, fixed["z"], fixed["vx"], fixed["wy"])],
        dtype=[("time", np.float64), ("x", np.float64), ("z", np.float64),
               ("vx", np.float64), ("wy", np.float64)])
    kw = {}
    if solver == "Euler":
        kw["step_size"] = step_size or output_interval
    r = fmpy.simulate_fmu(str(fmu.path), fmi_type="ModelExchange", solver=solver,
                          start_values=dict(start_values or {}), input=sig, output=list(outputs),
                          stop_time=stop, output_interval=output_interval, record_events=False,
                          **kw)
    res = {name: np.asarray(r[name], dtype=float) for name in outputs}
    res["time"] = np.asarray(r["time"], dtype=float)
    res["x"] = fixed["vx"] * res["time"]
    return res


def steady_mean(res, name, lo=0.2, hi=0.8):
    sel = (res["x"] >= lo) & (res["x"] <= hi)
    if not sel.any():
        raise ValueError(f"no samples with {lo} <= x <= {hi}")
    return float(np.mean(res[name][sel]))


# --------------------------------------------------------------------------- surfaces

def load_rsf(path):
    """Read a `.rsf` surface: returns (X, Y, Z) as (nx, ny) arrays indexed [L-1, K-1]."""
    a = np.loadtxt(path, comments="#", ndmin=2)
    if a.shape[1] != 5:
        raise ValueError(f"{path}: expected 5 columns `L K x y z`, got {a.shape[1]}")
    L = a[:, 0].astype(int)
    K = a[:, 1].astype(int)
    nx, ny = L.max(), K.max()
    # the comment lines: the grid, and (sparse files) the height of unlisted nodes
    grid, base = None, None
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                break
            m = re.match(r"# grid nx=(\d+) ny=(\d+) x=\[(\S+), (\S+)\] y=\[(\S+), (\S+)\]", line)
            if m:
                grid = (int(m[1]), int(m[2]), *map(float, m.groups()[2:]))
            if line.startswith("# sparse: unlisted nodes are at z0 ="):
                base = float(line.split("=")[-1])
    if base is not None:
        if grid is None:
            raise ValueError(f"{path}: a sparse surface without its `# grid` line")
        nx, ny, x0, x1, y0, y1 = grid
        xs, ys = np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        Z = np.full((nx, ny), base)
        Z[L - 1, K - 1] = a[:, 4]
        return X, Y, Z
    X = np.full((nx, ny), np.nan)
    Y = np.full((nx, ny), np.nan)
    Z = np.full((nx, ny), np.nan)
    X[L - 1, K - 1] = a[:, 2]
    Y[L - 1, K - 1] = a[:, 3]
    Z[L - 1, K - 1] = a[:, 4]
    return X, Y, Z


def tip_depth_profile(y, r, T, p):
    """Depth below the face of the rim's cross-section at penetration p (analytic).

    R(y) = R - r + sqrt(r^2 - y^2) for |y| <= T/2: the rim's lowest point at
    lateral offset y sits R - R(y) above the lowest point, so the depth of the
    groove it leaves is p - (r - sqrt(r^2 - y^2)), clipped at 0 and NaN outside the tip.
    """
    y = np.asarray(y, dtype=float)
    d = np.full_like(y, np.nan)
    inside = np.abs(y) <= T / 2
    d[inside] = p - (r - np.sqrt(r ** 2 - y[inside] ** 2))
    return np.maximum(d, 0.0)

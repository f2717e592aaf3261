"""Driving kerf's cutterhead FMUs from fmpy (scripts/head, tests/fmu/test_head.py).

* build_head_fmu(layout, drive): packages a layout (cargo run -p packaging -- --layout ...)
* HeadFMU(path): the extracted FMU, its variables by name, the layout it carries
* placements(layout, yaw, z, w, vz): every disc's pose and twist for a head pose, written
  from interface.md's placement convention independently of the FMU (tests compare them)
* HeadFMU.bore_cs(...): a Co-Simulation run of the head turning and advancing
"""

import json
import math
import os
import shutil
import subprocess
import tempfile
import zipfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def build_head_fmu(layout, drive="head", out=None):
    """Packages `layout` (path) into an FMU; returns its path. Uses the
    packaging binary scripts/test (or scripts/head) built, else cargo run."""
    exe = Path(os.environ.get("KERF_PACKAGING", ROOT / "target" / "release" / "packaging"))
    run = [str(exe)] if exe.is_file() else ["cargo", "run", "--release", "-q", "-p", "packaging", "--"]
    cmd = run + ["--layout", str(layout), "--drive", drive]
    if out:
        cmd += ["--out", str(out)]
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"packaging failed:\n{r.stderr}")
    return Path(r.stdout.strip().splitlines()[-1])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def euler_321(r):
    """(yaw, pitch, roll) of a rotation matrix, intrinsic 3-2-1."""
    pitch = -math.asin(max(-1.0, min(1.0, r[2, 0])))
    yaw = math.atan2(r[1, 0], r[0, 0])
    roll = math.atan2(r[2, 1], r[2, 2])
    return yaw, pitch, roll


def disc_frames(layout):
    """Per disc (head frame): tip, cutter x, y, z, radius (interface.md)."""
    base = layout["disc"]
    out = []
    for c in layout["cutters"]:
        d = dict(base, **c.get("disc", {}))
        a, g = math.radians(c["angleDeg"]), math.radians(c["tiltDeg"])
        e_r = np.array([math.cos(a), math.sin(a), 0.0])
        e_t = np.array([-math.sin(a), math.cos(a), 0.0])
        z = math.cos(g) * np.array([0.0, 0.0, 1.0]) - math.sin(g) * e_r
        x = e_t
        y = np.cross(z, x)
        tip = c["track"] * e_r + c["setback"] * np.array([0.0, 0.0, 1.0])
        out.append((tip, x, y, z, d["radius"]))
    return out


def placements(layout, yaw, zh, w, vz):
    """Each disc's (pose[6], twist[6]) for the head turned by `yaw` about z at
    height `zh`, turning at `w` rad/s and advancing at `vz` m/s: the disc
    centre follows its mount, and the disc spins freely so its tip does not
    slip along cutter x."""
    rh = rot_z(yaw)
    p0 = np.array([0.0, 0.0, zh])
    om = np.array([0.0, 0.0, w])
    res = []
    for tip, x, y, z, r in disc_frames(layout):
        rot = rh @ np.column_stack([x, y, z])
        c = p0 + rh @ (tip + r * z)
        v = np.array([0.0, 0.0, vz]) + np.cross(om, c - p0)
        xw, yw, zw = rot[:, 0], rot[:, 1], rot[:, 2]
        spin = np.dot(v + np.cross(om, -r * zw), xw) / r
        omega = om + spin * yw
        res.append((np.array([*c, *euler_321(rot)]), np.array([*v, *omega])))
    return res


class HeadFMU:
    """An extracted head FMU and its variables."""

    def __init__(self, path):
        from fmpy import read_model_description

        self.path = Path(path)
        self.md = read_model_description(str(self.path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.vars = {v.name: v for v in self.md.modelVariables}
        with zipfile.ZipFile(self.path) as z:
            manifest = json.loads(z.read("resources/head.json"))
        self.layout = manifest["layout"]
        self.drive = manifest["drive"]
        self.n = len(self.layout["cutters"])
        self.dir = tempfile.mkdtemp(prefix="kerf-head-")
        from fmpy import extract

        extract(str(self.path), self.dir)

    def close(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def grid_starts(self, cell):
        """Start values of `rock.nx` and `rock.ny` for cells of `cell` [m] over
        the FMU's own rock rectangle."""
        out = {}
        for ax, lo, hi in (("nx", "rock.xMin", "rock.xMax"), ("ny", "rock.yMin", "rock.yMax")):
            span = float(self.vars[hi].start) - float(self.vars[lo].start)
            out["rock." + ax] = int(round(span / cell)) + 1
        return out

    def instance(self, kind="CS", name="head", start_values=None):
        from fmpy.fmi2 import FMU2Model, FMU2Slave

        cls = FMU2Slave if kind == "CS" else FMU2Model
        f = cls(guid=self.md.guid, unzipDirectory=self.dir,
                modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        f.instantiate()
        f.setupExperiment(startTime=0.0)
        f.enterInitializationMode()
        for k, v in (start_values or {}).items():
            vr = [self.vr[k]]
            if isinstance(v, str):
                f.setString(vr, [v])
            elif isinstance(v, bool):
                f.setBoolean(vr, [v])
            elif isinstance(v, int):
                f.setInteger(vr, [v])
            else:
                f.setReal(vr, [float(v)])
        f.exitInitializationMode()
        return f

    def steady_instance(self, cell=None, p_rev=0.006):
        """A Co-Simulation instance on the steady face of `p_rev` per
        revolution, at cells and sweep steps of `cell` [m] (default: the
        FMU's)."""
        starts = {"head.steadyPenetration": p_rev}
        if cell:
            starts.update(self.grid_starts(cell))
            starts["numerics.sweepStep"] = cell
        return self.instance("CS", start_values=starts)

    def output_reader(self, f):
        """A function that reads every output `names()` lists into one numpy
        array (the same array at every call) with a raw fmi2GetReal into
        ctypes arrays made once: fmpy's getReal builds both from Python lists
        at every call (85 of its 127 us for the reference head's 571
        outputs)."""
        from fmpy.fmi2 import fmi2OK, fmi2Real, fmi2ValueReference

        vrs = [self.vr[k] for k in self.names()]
        vr_arr = (fmi2ValueReference * len(vrs))(*vrs)
        val_arr = (fmi2Real * len(vrs))()
        values = np.ctypeslib.as_array(val_arr)

        def read():
            if f.fmi2GetReal(f.component, vr_arr, len(vrs), val_arr) != fmi2OK:
                raise RuntimeError("fmi2GetReal failed")
            return values

        return read

    def names(self):
        """Output names recorded by `bore_cs`: totals then per disc."""
        tot = ["Fx", "Fy", "Fz", "Mx", "My", "Mz", "thrust", "torque", "excavatedVolume",
               "cuttingEnergy", "specificEnergy"]
        per = ["Fx", "Fy", "Fz", "Mx", "My", "Mz", "normalForce", "rollingForce", "sideForce",
               "penetration"]
        return tot + [f"cutter[{i + 1}].{k}" for i in range(self.n) for k in per]

    def set_motion(self, f, t, w, vz, twist_of=None):
        """Sets the head's motion at `t` (turning at `w`, advancing at
        `vz`); in the disc drive, each disc's placed pose and twist, the
        twist of disc `i` (0-based) replaced by `twist_of(i, twist)` if
        given."""
        yaw, zh = w * t, vz * t
        if self.drive == "head":
            names = ["yaw", "z", "wz", "vz"]
            f.setReal([self.vr[k] for k in names], [yaw, zh, w, vz])
        else:
            vrs, vals = [], []
            for i, (pose, tw) in enumerate(placements(self.layout, yaw, zh, w, vz)):
                if twist_of is not None:
                    tw = twist_of(i, tw)
                for k, val in zip(["x", "y", "z", "yaw", "pitch", "roll", "vx", "vy", "vz", "wx",
                                   "wy", "wz"], [*pose, *tw]):
                    vrs.append(self.vr[f"cutter[{i + 1}].{k}"])
                    vals.append(float(val))
            f.setReal(vrs, vals)

    def bore_cs(self, f, w, p_rev, t_end, h, t0=0.0, progress=None):
        """Turns the head at `w` rad/s advancing `p_rev` per revolution from
        t0 to t_end in steps h; returns (t, outputs[names()])."""
        vz = -p_rev * w / (2 * math.pi)
        read = self.output_reader(f)
        n = int(round((t_end - t0) / h))
        ts = np.empty(n)
        out = np.empty((n, len(self.names())))
        t = t0
        for k in range(n):
            self.set_motion(f, t, w, vz)
            f.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t = t0 + (k + 1) * h
            ts[k] = t
            out[k] = read()
            if progress and k % max(1, n // 20) == 0:
                progress(k, n)
        return ts, out


def col(fmu, name):
    return fmu.names().index(name)


def csm_force(R, T, ucs, bts, S, C, p, psi=0.0):
    """CSM (thesis eq. 15) normal and rolling force of one disc at depth p."""
    phi = math.acos((R - p) / R)
    P = C * (ucs ** 2 * bts * S / math.sqrt(R * T)) ** (1.0 / 3.0)
    F = P * phi * R * T / (1.0 + psi)
    beta = phi / (2.0 + psi)
    return F * math.cos(beta), F * math.sin(beta)

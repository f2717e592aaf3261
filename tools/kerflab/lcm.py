"""A virtual linear cutting machine (LCM) on kerf.fmu, in Co-Simulation.

The LCM protocol (Gertsch et al. 2007, Rostami 1997): a rock block is cut by
one disc in straight passes side by side, each one spacing `S` beside the
last, at a set penetration `p`. The first pass runs on the flat face with no
groove beside it (unrelieved); every later pass runs beside the groove, and the
chips, of the one before (relieved). The first `discard` passes are dropped as
unrelieved, or not yet in the steady pattern, and the rest are averaged.

Here the block is kerf's height map; pass k runs along +x at y = -k S from
x = 0 to `length`, the disc centre at z = z0 + R - p (the machine sets the
depth, as an LCM does), rolling without slip at `v`. A pass starts with a
jump of the pose (not travel: no cut along the jump). Each pass is measured
over `window` (0.1 <= x <= 0.5 m of a 0.6 m pass by default), away from the
entry and exit.

What one (S, p) block gives (`run_block(...)["row"]`, the columns of `COLUMNS`):
mean and peak normal, rolling and side force, the cutting coefficient
CC = Fr / Fn (of the means), the specific energy SE = Fr / (volume removed per
metre of cut) as an LCM report computes it, kerf's own SE (cutting energy over
volume), the volume removed and the part that left as chips, per metre.

The same table, with the measured columns filled, is the input of
`kerflab.calibrate`.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

_TOOLS = Path(__file__).resolve().parents[1]
if str(_TOOLS) not in sys.path:  # kerfhost.py lives in tools/
    sys.path.insert(0, str(_TOOLS))

import kerfhost as kh  # noqa: E402

#: Defaults of one block (the protocol above).
PASSES = 5
DISCARD = 2
LENGTH = 0.6
WINDOW = (0.1, 0.5)
STEP = 1e-3     # travel per communication step [m]
SPEED = 1.0     # cutting speed [m/s]
MARGIN = None   # intact rock beyond the first and the last pass [m]; None: automatic

OUTPUTS = ["normalForce", "rollingForce", "sideForce", "excavatedVolume", "cuttingEnergy",
           "chippedVolume"]

#: Scene columns: what the rock and the disc are (FMU parameter, scale to SI).
SCENE = {
    "R_mm": ("cutter.radius", 1e-3),
    "T_mm": ("cutter.tipWidth", 1e-3),
    "tip_radius_mm": ("cutter.tipRadius", 1e-3),
    "ucs_MPa": ("rock.ucs", 1e6),
    "bts_MPa": ("rock.bts", 1e6),
}
#: Result columns (observables), with their unit scale from SI.
RESULTS = {
    "Fn_kN": 1e-3, "Fr_kN": 1e-3, "Fs_kN": 1e-3,
    "Fn_peak_kN": 1e-3, "Fr_peak_kN": 1e-3, "Fs_peak_kN": 1e-3,
    "CC": 1.0, "SE_MJm3": 1e-6, "SE_energy_MJm3": 1e-6,
    "V_cm3_per_m": 1e6, "chip_cm3_per_m": 1e6, "chips_per_m": 1.0,
    "Fn_cv": 1.0, "Fn_pass_sd_kN": 1e-3,
}
#: Every column of an LCM table, in order (measured tables may leave any result empty).
COLUMNS = ["rock"] + list(SCENE) + ["S_mm", "p_mm", "S_over_p"] + list(RESULTS) + ["passes_kept"]

_FMU_CACHE: dict[str, kh.FMU] = {}


def open_fmu(path) -> kh.FMU:
    """The extracted FMU at `path`, once per process (extraction takes a moment)."""
    key = str(Path(path).resolve())
    if key not in _FMU_CACHE:
        _FMU_CACHE[key] = kh.FMU(key)
    return _FMU_CACHE[key]


def _param(fmu, params, name):
    v = params.get(name)
    return float(fmu.start(name) if v is None else v)


def _whole_cells(length, cell):
    """`length` rounded up to whole cells (kept as it is when it is whole already)."""
    n = length / cell
    return length if abs(n - round(n)) < 1e-6 else math.ceil(n) * cell


def block_parameters(fmu, S, p, passes=PASSES, length=LENGTH, chipping=True, params=None,
                     cell=1e-3, margin=MARGIN):
    """FMU start values of a block for `passes` passes at spacing S, depth p.

    The block reaches `margin` beyond the first and the last pass; by default
    (None) 0.1 m, or more if the chips' crack reach says so (2 kappa p + T), so
    that neither outer pass sees a free edge. Cells are `cell` square, with a
    node row on the first pass (y = 0).
    """
    params = dict(params or {})
    if margin is None:
        T = _param(fmu, params, "cutter.tipWidth")
        kappa = _param(fmu, params, "chipping.kappa") if "chipping.kappa" in fmu.vars else 0.0
        margin = max(0.1, 2.0 * kappa * p + T)
    x0, x1 = -0.25, length + 0.25
    y1 = _whole_cells(margin, cell)
    y0 = -_whole_cells((passes - 1) * S + margin, cell)
    sv = {"rock.xMin": x0, "rock.xMax": x1, "rock.nx": int(round((x1 - x0) / cell)) + 1,
          "rock.yMin": y0, "rock.yMax": y1, "rock.ny": int(round((y1 - y0) / cell)) + 1,
          "csm.spacing": S}
    if "chipping.enabled" in fmu.vars:
        sv["chipping.enabled"] = bool(chipping)
    elif chipping:
        raise ValueError(f"{fmu.path} has no chipping.enabled: rebuild it")
    sv.update(params)
    return sv


def run_block(fmu, S, p, *, passes=PASSES, discard=DISCARD, length=LENGTH, window=WINDOW,
              step=STEP, v=SPEED, chipping=True, params=None, cell=1e-3, margin=MARGIN,
              final_surface=None, traces=False, name=None):
    """Runs one LCM block (spacing S, penetration p, both in m) in a fresh instance.

    `params`: further FMU start values by name (csm.C, csm.psi, friction.mu,
    chipping.kappa, rock.ucs, ...). Returns a dict: `row` (the LCM table row of
    the kept passes), `passes` (one summary per pass, unrelieved ones
    included), `chipCount` (the whole block's), and with `traces` the samples of
    every pass (`x` and `OUTPUTS`).
    """
    if isinstance(fmu, (str, Path)):
        fmu = open_fmu(fmu)
    # to 0.1 nm: 51 mm read from a table (51 * 1e-3 = 0.051000000000000004) is the
    # block of S = 0.051 - chips break out or not on the exact geometry
    S, p = round(float(S), 10), round(float(p), 10)
    if not 0 <= discard < passes:
        raise ValueError(f"discard = {discard} must leave a pass of {passes}")
    if not 0 <= window[0] < window[1] <= length:
        raise ValueError(f"window {window} must lie inside the pass (0, {length})")
    params = dict(params or {})
    sv = block_parameters(fmu, S, p, passes, length, chipping, params, cell, margin)
    if final_surface:
        sv["rock.finalSurface"] = str(final_surface)
    R = float(sv.get("cutter.radius", fmu.start("cutter.radius")))
    z0 = float(sv.get("rock.z0", fmu.start("rock.z0") or 0.0))
    dt = step / v
    n = int(round(length / step))
    inst = fmu.instance("CS", name=name or f"lcm-S{S:g}-p{p:g}")
    per_pass, samples = [], []
    try:
        inst.initialize(sv, inputs=dict(x=0.0, y=0.0, z=z0 + R - p, vx=v, wy=v / R))
        vr = [inst.fmu_file.var(o).valueReference for o in OUTPUTS]
        vr_xy = [inst.fmu_file.var(o).valueReference for o in ("x", "y")]
        vr_chips = [inst.fmu_file.var("chipCount").valueReference]
        t = 0.0
        for k in range(passes):
            rows = np.empty((n, len(OUTPUTS) + 2))
            for i in range(n):
                inst.f.setReal(vr_xy, [i * step, -k * S])  # a jump starts each pass
                inst.f.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
                t += dt
                rows[i, 0] = (i + 1) * step
                rows[i, 1:-1] = inst.f.getReal(vr)
                rows[i, -1] = inst.f.getInteger(vr_chips)[0]
            res = {name: rows[:, j + 1] for j, name in enumerate(OUTPUTS)}
            res["x"] = rows[:, 0]
            res["chipCount"] = rows[:, -1]
            per_pass.append(pass_summary(res, window))
            if traces:
                samples.append(res)
        chips = int(inst.get("chipCount"))
        inst.f.terminate()
    except kh.FMICallException as e:
        msgs = "; ".join(r.message for r in inst.errors()) or "no message"
        raise ValueError(f"kerf.fmu refused the block S = {S}, p = {p}, parameters {params}: "
                         f"{e} ({msgs})") from None
    finally:
        inst.free(terminate=False)
    kept = per_pass[discard:]
    row = aggregate(kept)
    row.update(scene_columns(fmu, sv), S_mm=S * 1e3, p_mm=p * 1e3, S_over_p=S / p,
               passes_kept=len(kept))
    out = {"row": row, "passes": per_pass, "chipCount": chips, "start_values": sv}
    if traces:
        out["traces"] = samples
    return out


def pass_summary(res, window=WINDOW):
    """Means, peaks and increments of one pass over the window (SI units)."""
    x = res["x"]
    w = (x >= window[0]) & (x <= window[1])
    if w.sum() < 2:
        raise ValueError(f"fewer than 2 samples in window {window}")
    fn, fr, fs = (res[k][w] for k in ("normalForce", "rollingForce", "sideForce"))
    dx = float(x[w][-1] - x[w][0])
    dv = float(res["excavatedVolume"][w][-1] - res["excavatedVolume"][w][0])
    de = float(res["cuttingEnergy"][w][-1] - res["cuttingEnergy"][w][0])
    dc = float(res["chippedVolume"][w][-1] - res["chippedVolume"][w][0])
    dn = float(res["chipCount"][w][-1] - res["chipCount"][w][0])
    return {"Fn": float(fn.mean()), "Fr": float(fr.mean()), "Fs": float(fs.mean()),
            "Fn_peak": float(fn.max()), "Fr_peak": float(fr.max()), "Fs_peak": float(fs.max()),
            "Fn_cv": float(fn.std() / fn.mean()) if fn.mean() else math.nan,
            "dx": dx, "dV": dv, "dE": de, "dChip": dc, "dChips": dn}


def aggregate(kept):
    """The LCM table's result columns (display units) from the kept passes' summaries."""
    mean = lambda k: float(np.mean([s[k] for s in kept]))  # noqa: E731
    dx = sum(s["dx"] for s in kept)
    dv = sum(s["dV"] for s in kept)
    fn, fr, fs = mean("Fn"), mean("Fr"), mean("Fs")
    vpm = dv / dx  # m3 removed per m of cut
    si = {
        "Fn_kN": fn, "Fr_kN": fr, "Fs_kN": fs,
        "Fn_peak_kN": max(s["Fn_peak"] for s in kept),
        "Fr_peak_kN": max(s["Fr_peak"] for s in kept),
        "Fs_peak_kN": max(s["Fs_peak"] for s in kept),
        "CC": fr / fn if fn else math.nan,
        "SE_MJm3": fr / vpm if vpm > 0 else math.inf,
        "SE_energy_MJm3": sum(s["dE"] for s in kept) / dv if dv > 0 else math.inf,
        "V_cm3_per_m": vpm,
        "chip_cm3_per_m": sum(s["dChip"] for s in kept) / dx,
        "chips_per_m": sum(s["dChips"] for s in kept) / dx,
        "Fn_cv": mean("Fn_cv"),
        "Fn_pass_sd_kN": float(np.std([s["Fn"] for s in kept])),
    }
    return {k: v * RESULTS[k] for k, v in si.items()}


def scene_columns(fmu, sv):
    return {col: float(sv.get(name, fmu.start(name))) / scale for col, (name, scale) in SCENE.items()}


def scene_parameters(row):
    """FMU start values for the scene columns of a table row (empty cells: FMU defaults)."""
    out = {}
    for col, (name, scale) in SCENE.items():
        v = row.get(col)
        if v is not None and not (isinstance(v, float) and math.isnan(v)) and v != "":
            out[name] = float(v) * scale
    return out


def run_series(fmu, spacings, penetrations, *, params=None, rock="", progress=None, **kw):
    """The LCM grid: one block per (S, p); returns the table rows (dicts, `COLUMNS`)."""
    rows = []
    for p in penetrations:
        for S in spacings:
            r = run_block(fmu, S, p, params=params, **kw)["row"]
            r["rock"] = rock
            rows.append({c: r.get(c) for c in COLUMNS})
            if progress:
                progress(rows[-1])
    return rows


# --------------------------------------------------------------------------- tables

def read_table(path):
    """An LCM table (CSV, `#` comment lines allowed) as a pandas DataFrame."""
    import pandas as pd
    df = pd.read_csv(path, comment="#", skipinitialspace=True)
    missing = {"S_mm", "p_mm"} - set(df.columns)
    if missing:
        raise ValueError(f"{path}: an LCM table needs the columns {sorted(missing)}")
    return df


def write_table(rows, path, header_lines=()):
    """Writes rows (dicts) with the `COLUMNS` and `#` header lines."""
    import pandas as pd
    df = pd.DataFrame(rows)
    cols = [c for c in COLUMNS if c in df.columns] + [c for c in df.columns if c not in COLUMNS]
    path = Path(path)
    with path.open("w") as f:
        for line in header_lines:
            f.write(f"# {line}\n")
        df[cols].to_csv(f, index=False, float_format="%.6g")
    return df[cols]

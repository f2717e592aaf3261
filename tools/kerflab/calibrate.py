"""scripts/calibrate: fit kerf's constants to measured LCM rows with the virtual LCM.

Input: an LCM table (the columns of scripts/lcm's lcm_table.csv; `#` lines are
comments). Each row needs S_mm and p_mm; the scene columns R_mm, T_mm,
tip_radius_mm, ucs_MPa, bts_MPa set the disc and the rock where given (FMU
defaults elsewhere); every result column that is filled (by default Fn_kN,
Fr_kN, Fs_kN, SE_MJm3; --observables picks others) is an observation.

The fit: for parameters theta (C = csm.C, psi = csm.psi, mu = friction.mu,
pscale = chipping.pressureScale, or any FMU parameter by name), every row is run as an LCM block
(kerflab.lcm.run_block) and scipy.optimize.least_squares minimises
sum r^2 / 2, r = (model - measured) / (sigma |measured|): sigma is the
relative standard uncertainty of a measured mean (--sigma, default 0.1; LCM
means scatter by about that from pass to pass and block to block).

Confidence: from the Jacobian J of r at the optimum (central differences):
covariance (J^T J)^-1, i.e. the standard errors that follow from sigma alone;
with more observations than parameters also scaled by the residual variance.
The singular values of J say which parameter combinations the data fix;
parameters with no effect on any observation are named and left out.

chipping.kappa (`--fit kappa`) is not fitted by gradient: a ridge breaks or
stands (the forces jump at S - T = kappa p), and away from that kappa moves
only where single chips break. It is profiled instead: the other parameters
are fitted for every kappa of --kappa-grid, and the report gives the kappa
range whose cost is within 0.5 of the best (a 68 % profile interval, in sigma
units) and, the honest one, the range that breaks the same rows' ridges as
the best kappa.

Writes --out/calibration.json and calibration_residuals.csv.
Usage: scripts/calibrate [TABLE] [--fit C,psi] [--set csm.variant=2] [--sigma 0.1]
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from kerflab import lcm
from kerflab.lcm_report import add_block_args, block_kwargs, parse_set

ROOT = Path(__file__).resolve().parents[2]

#: Short names of the usual fit parameters: FMU name, bounds, finite-difference step.
ALIASES = {
    "C": ("csm.C", (0.05, 50.0), 0.01),
    "psi": ("csm.psi", (-0.5, 2.0), 0.01),
    "mu": ("friction.mu", (0.0, 2.0), 0.01),
    "kappa": ("chipping.kappa", (0.5, 200.0), None),
    # the factor on the CSM pressure with chips on; with csm.variant 1 or 2 it
    # acts as C does (both multiply P'), so fit one of the two
    "pscale": ("chipping.pressureScale", (0.1, 10.0), 0.01),
}
OBSERVABLES = ["Fn_kN", "Fr_kN", "Fs_kN", "SE_MJm3"]


def _name(p):
    return ALIASES[p][0] if p in ALIASES else p


def _finite(v):
    try:
        return v is not None and math.isfinite(float(v))
    except (TypeError, ValueError):
        return False


class Problem:
    """Rows x observables x parameters, and the virtual LCM that predicts them."""

    def __init__(self, fmu, table, fit, base=None, block=None, observables=OBSERVABLES, sigma=0.1):
        self.fmu = lcm.open_fmu(fmu) if isinstance(fmu, (str, Path)) else fmu
        self.rows = table.to_dict("records") if hasattr(table, "to_dict") else list(table)
        self.fit = list(fit)
        self.names = [_name(p) for p in self.fit]
        for n in self.names:
            self.fmu.var(n)  # KeyError if kerf has no such parameter
        self.base = dict(base or {})
        self.block = dict(block or {})
        self.sigma = float(sigma)
        # (row index, column, measured value) for every filled observable
        self.obs = [(i, c, float(r[c])) for i, r in enumerate(self.rows) for c in observables
                    if c in r and _finite(r[c])]
        if not self.obs:
            raise ValueError(f"no observations: the table fills none of {observables}")
        for _, c, m in self.obs:
            if m == 0:
                raise ValueError(f"a measured {c} of 0 cannot carry a relative uncertainty")
        self.cache: dict[tuple, list] = {}
        self.evaluations = 0

    def params(self, theta, extra=None):
        p = dict(self.base)
        p.update(extra or {})
        p.update({n: float(v) for n, v in zip(self.names, theta)})
        return p

    def predict(self, theta, extra=None):
        """The model's rows (dicts) at theta; cached."""
        key = tuple(float(v) for v in theta) + tuple(sorted((extra or {}).items()))
        if key not in self.cache:
            out = []
            for r in self.rows:
                pr = self.params(theta, extra)
                pr.update(lcm.scene_parameters(r))
                res = lcm.run_block(self.fmu, float(r["S_mm"]) * 1e-3, float(r["p_mm"]) * 1e-3,
                                    params=pr, **self.block)
                out.append(res["row"])
                self.evaluations += 1
            self.cache[key] = out
        return self.cache[key]

    def residuals(self, theta, extra=None):
        pred = self.predict(theta, extra)
        return np.array([(pred[i][c] - m) / (self.sigma * abs(m)) for i, c, m in self.obs])

    def jacobian(self, theta, steps, extra=None, lo=None, hi=None):
        """Central differences of the residuals (columns: parameters); one-sided
        where a bound (lo, hi) is nearer than the step."""
        J = np.empty((len(self.obs), len(theta)))
        for j, h in enumerate(steps):
            tp, tm = np.array(theta, float), np.array(theta, float)
            up = hi is None or tp[j] + h <= hi[j]
            down = lo is None or tm[j] - h >= lo[j]
            tp[j] += h if up else 0.0
            tm[j] -= h if down else 0.0
            J[:, j] = (self.residuals(tp, extra) - self.residuals(tm, extra)) / (tp[j] - tm[j])
        return J


def _bounds_steps(fit, theta0):
    lo, hi, steps = [], [], []
    for p, t in zip(fit, theta0):
        b, h = (ALIASES[p][1], ALIASES[p][2]) if p in ALIASES else ((-np.inf, np.inf), None)
        lo.append(b[0])
        hi.append(b[1])
        steps.append(h if h else max(1e-3, 0.01 * abs(t)))
    return np.array(lo), np.array(hi), np.array(steps)


def fit_continuous(prob: Problem, theta0, extra=None, max_nfev=40):
    """least_squares over prob.fit (no kappa); returns (theta, cost, J, dropped)."""
    from scipy.optimize import least_squares

    theta0 = np.asarray(theta0, float)
    lo, hi, steps = _bounds_steps(prob.fit, theta0)
    theta0 = np.clip(theta0, lo, hi)
    # parameters no observation depends on (e.g. friction in a pass that rolls without slip)
    J0 = prob.jacobian(theta0, steps, extra, lo, hi)
    active = np.abs(J0).max(axis=0) > 1e-9
    dropped = [prob.fit[j] for j in range(len(theta0)) if not active[j]]
    theta = theta0.copy()
    if active.any():
        idx = np.flatnonzero(active)

        def fun(x):
            t = theta0.copy()
            t[idx] = x
            return prob.residuals(t, extra)

        # the forces are smooth in C, psi and mu (chips follow the geometry, not the
        # force): forward differences of 1e-3 (relative, at least 1e-3) are plenty
        r = least_squares(fun, theta0[idx], bounds=(lo[idx], hi[idx]), x_scale=steps[idx] * 100,
                          diff_step=1e-3, xtol=1e-8, ftol=1e-10, gtol=1e-10, max_nfev=max_nfev)
        theta[idx] = r.x
    J = prob.jacobian(theta, steps, extra, lo, hi)
    cost = 0.5 * float(np.sum(prob.residuals(theta, extra) ** 2))
    return theta, cost, J, dropped


def confidence(J, cost, n_obs, fit, dropped):
    """Standard errors, correlations and what the data identify, from J."""
    keep = [j for j, p in enumerate(fit) if p not in dropped]
    Jk = J[:, keep]
    U, s, Vt = np.linalg.svd(Jk, full_matrices=False) if Jk.size else (None, np.array([]), None)
    out = {"singular_values": s.tolist(), "n_observations": n_obs, "n_parameters": len(keep),
           "dof": n_obs - len(keep), "not_identified": list(dropped), "weak_directions": []}
    if not keep:
        return out
    tol = max(Jk.shape) * np.finfo(float).eps * (s[0] if s.size else 0) * 1e6
    rank = int(np.sum(s > tol))
    out["rank"] = rank
    cov = Vt.T @ np.diag([1 / x ** 2 if x > tol else np.inf for x in s]) @ Vt if rank == len(keep) \
        else np.full((len(keep), len(keep)), np.inf)
    se = np.sqrt(np.diag(cov))
    out["stderr_sigma"] = {fit[j]: float(se[i]) for i, j in enumerate(keep)}
    if out["dof"] > 0:
        s2 = 2 * cost / out["dof"]
        out["residual_variance"] = s2
        out["stderr_scaled"] = {fit[j]: float(se[i] * math.sqrt(s2)) for i, j in enumerate(keep)}
    if np.all(np.isfinite(cov)):
        d = np.sqrt(np.diag(cov))
        out["correlation"] = (cov / np.outer(d, d)).tolist()
    for i, x in enumerate(s):
        if x < 1e-2 * s[0] or x <= tol:
            v = Vt[i]
            out["weak_directions"].append(
                " ".join(f"{v[k]:+.2f}*{fit[j]}" for k, j in enumerate(keep) if abs(v[k]) > 0.05))
    return out


def calibrate(fmu, table, fit=("C", "psi"), base=None, block=None, observables=OBSERVABLES,
              sigma=0.1, x0=None, kappa_grid=(6, 8, 10, 12, 15, 20, 25, 30), log=print):
    """Fits `fit` to the table; returns the report (dict)."""
    t_start = time.monotonic()
    fit = list(fit)
    profile_kappa = "kappa" in fit or "chipping.kappa" in fit
    cont = [p for p in fit if p not in ("kappa", "chipping.kappa")]
    prob = Problem(fmu, table, cont, base, block, observables, sigma)
    x0 = dict(x0 or {})
    theta0 = [float(x0.get(p, prob.base.get(_name(p), prob.fmu.start(_name(p))))) for p in cont]
    report = {"fit": fit, "sigma": sigma, "observables": [f"row {i}: {c}" for i, c, _ in prob.obs],
              "base_parameters": prob.base, "start": dict(zip(cont, theta0))}
    if profile_kappa:
        prof = []
        for k in kappa_grid:
            ex = {"chipping.kappa": float(k)}
            th, cost, J, dropped = fit_continuous(prob, theta0, ex)
            # which rows' ridges broke: the discrete outcome kappa decides
            broke = [bool(r["chip_cm3_per_m"] > 0) for r in prob.predict(th, ex)]
            prof.append({"kappa": float(k), "cost": cost, "ridges_broke": broke,
                         **dict(zip(cont, th.tolist()))})
            log(f"  kappa = {k:6.2f}: cost {cost:10.4g}  " + "  ".join(
                f"{p} = {v:.4g}" for p, v in zip(cont, th)) + f"  ridges broke: {broke}")
        best = min(prof, key=lambda d: d["cost"])
        inside = [d["kappa"] for d in prof if d["cost"] <= best["cost"] + 0.5]
        same = [d["kappa"] for d in prof if d["ridges_broke"] == best["ridges_broke"]]
        report["kappa_profile"] = prof
        report["kappa"] = {"best": best["kappa"], "interval_68": [min(inside), max(inside)],
                           "same_ridges": [min(same), max(same)],
                           "at_grid_edge": min(same) == min(kappa_grid) or max(same) == max(kappa_grid)}
        extra = {"chipping.kappa": best["kappa"]}
        theta0 = [best[p] for p in cont]
    else:
        extra = None
    theta, cost, J, dropped = fit_continuous(prob, theta0, extra)
    pred = prob.predict(theta, extra)
    res = prob.residuals(theta, extra)
    report["values"] = dict(zip(cont, theta.tolist()))
    if extra:
        report["values"]["kappa"] = extra["chipping.kappa"]
    report["fmu_parameters"] = {**prob.params(theta, extra)}
    report["cost"] = cost
    report["confidence"] = confidence(J, cost, len(prob.obs), cont, dropped)
    report["rows"] = [{"row": i, "S_mm": prob.rows[i]["S_mm"], "p_mm": prob.rows[i]["p_mm"],
                       "observable": c, "measured": m, "model": pred[i][c],
                       "residual_rel": (pred[i][c] - m) / abs(m), "residual_sigma": float(r)}
                      for (i, c, m), r in zip(prob.obs, res)]
    report["notes"] = identifiability_notes(report, cont, dropped, prob)
    lo, hi, steps = _bounds_steps(cont, theta)
    for p, t, a, b, h in zip(cont, theta, lo, hi, steps):
        if p not in dropped and (t - a < 1e-3 * h or b - t < 1e-3 * h):
            report["notes"].append(f"{p} = {t:.4g} sits on its bound [{a:g}, {b:g}]: the data push it "
                                   "past what is allowed, and its standard error means little")
    report["blocks_run"] = prob.evaluations
    report["seconds"] = time.monotonic() - t_start
    return report


def identifiability_notes(report, cont, dropped, prob):
    c = report["confidence"]
    notes = []
    for p in dropped:
        why = (" (kerf's friction acts on slip only, and an LCM pass rolls without slip)"
               if _name(p) == "friction.mu" else "")
        notes.append(f"{p} has no effect on any observation here{why}: not identified, kept at its start value")
    if c.get("dof", 0) < 0:
        notes.append(f"{c['n_observations']} observations for {c['n_parameters']} parameters: "
                     "under-determined, the fit is one of many")
    elif c.get("dof", 0) == 0:
        notes.append("as many observations as parameters: the fit is exact if the model can reach the data, "
                     "and the errors come from sigma alone (no residual to check the model with)")
    for w in c.get("weak_directions", []):
        notes.append(f"the data hardly fix the combination {w}")
    if "kappa" in report:
        lo, hi = report["kappa"]["same_ridges"]
        notes.append(f"every kappa of the grid in [{lo:g}, {hi:g}] breaks the same ridges as the best one"
                     + (" (the edge of the grid: the range is open there)"
                        if report["kappa"]["at_grid_edge"] else "")
                     + "; cost differences among them come from where single chips break, so these rows "
                     "fix kappa only to that range - an SE-against-S/p series (the optimum) is what pins it")
    return notes


def print_report(rep, log=print):
    c = rep["confidence"]
    log("\nfitted values (+- standard error from sigma; [scaled by the residual variance]):")
    for p, v in rep["values"].items():
        se = c.get("stderr_sigma", {}).get(p)
        sc = c.get("stderr_scaled", {}).get(p)
        extra = "" if se is None else f"  +- {se:.3g}"
        extra += "" if sc is None else f"  [+- {sc:.3g}]"
        if p == "kappa":
            extra = (f"  68 % profile interval {rep['kappa']['interval_68']}, same ridges broken "
                     f"for {rep['kappa']['same_ridges']}")
        log(f"  {p:8s} = {v:10.4g}{extra}")
    if "correlation" in c and len(c["correlation"]) > 1:
        log("correlation: " + json.dumps([[round(x, 3) for x in r] for r in c["correlation"]]))
    log(f"singular values of J: {[round(x, 4) for x in c['singular_values']]}; "
        f"{c['n_observations']} observations, {c['n_parameters']} parameters fitted")
    log("\nresidual per row (model - measured):")
    log(" row   S mm  p mm  observable   measured      model   rel     /sigma")
    for r in rep["rows"]:
        log(f"{r['row']:4d} {r['S_mm']:6.1f} {r['p_mm']:5.2f}  {r['observable']:10s} {r['measured']:9.4g} "
            f"{r['model']:10.4g} {100 * r['residual_rel']:+6.1f} % {r['residual_sigma']:+7.2f}")
    log(f"cost (sum r^2 / 2) = {rep['cost']:.4g}; {rep['blocks_run']} LCM blocks in {rep['seconds']:.0f} s")
    for n in rep["notes"]:
        log(f"note: {n}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("table", nargs="?", default=str(ROOT / "data" / "lcm" / "thesis_table3.csv"))
    ap.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "kerf.fmu"))
    ap.add_argument("--out", default=str(ROOT / "out"))
    ap.add_argument("--fit", default="C,psi",
                    help="parameters: C, psi, mu, kappa or FMU names (default %(default)s)")
    ap.add_argument("--observables", default=",".join(OBSERVABLES),
                    help="table columns fitted where filled (default %(default)s)")
    ap.add_argument("--sigma", type=float, default=0.1,
                    help="relative standard uncertainty of a measured mean (default %(default)s)")
    ap.add_argument("--start", action="append", metavar="NAME=VALUE", help="start value of a fit parameter")
    ap.add_argument("--kappa-grid", default="6,8,10,12,15,20,25,30", help="kappa values of the profile")
    add_block_args(ap)
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    table = lcm.read_table(a.table)
    fit = [p.strip() for p in a.fit.split(",") if p.strip()]
    print(f"calibrating {fit} to {len(table)} row(s) of {a.table} (sigma {a.sigma:.0%})")
    rep = calibrate(a.fmu, table, fit, base=parse_set(a.set), block=block_kwargs(a),
                    observables=[c.strip() for c in a.observables.split(",")], sigma=a.sigma,
                    x0=parse_set(a.start), kappa_grid=[float(k) for k in a.kappa_grid.split(",")])
    rep["table"] = str(a.table)
    print_report(rep)
    (out / "calibration.json").write_text(json.dumps(rep, indent=1, default=str))
    import pandas as pd
    pd.DataFrame(rep["rows"]).to_csv(out / "calibration_residuals.csv", index=False, float_format="%.6g")
    print(f"wrote {out / 'calibration.json'}, {out / 'calibration_residuals.csv'}")


if __name__ == "__main__":
    sys.exit(main())

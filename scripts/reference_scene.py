#!/usr/bin/env python3
"""Thesis reference scene (Ericsson 2010, Table 2 / ch. 9) with kerf.fmu in Co-Simulation.

A 17 in disc (R 0.2159 m, T 13 mm, r 12.7 mm) rolls without slip (wy = +v/R)
at v = 1 m/s over 1 m of flat rock (UCS 158 MPa, BTS 6.78 MPa), its centre
at z = R - 3.8 mm, communication step 1 ms; the host feeds x(t) = v t
(--velocity-only: it sets only vx and wy and the FMU carries the pose).

Runs it twice (numerics.directionRule = 1 kerf's rule, 2 the thesis's rule),
compares the steady mean forces (0.2 m <= x <= 0.8 m) with the CSM closed form
(thesis eqs 13-17, computed here) and thesis Table 3, and writes

  out/reference_forces.png   forces over travel
  out/reference_rock.png     the cut rock face and the groove cross-section
  out/reference_summary.json all numbers
  out/reference_final.rsf    the rock surface written at fmi2Terminate

Exit status is non-zero if a run fails or something could not be produced.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import numpy as np  # noqa: E402

import kerfhost as kh  # noqa: E402

LO, HI = 0.2, 0.8  # steady window of travel [m]


def run(fmu: kh.FMU, direction_rule: int, final_surface: Path | None, n_steps: int, h: float,
        feed_x: bool = True):
    sv = {}
    if "numerics.directionRule" in fmu.vars:
        sv["numerics.directionRule"] = direction_rule
    elif direction_rule != 1:
        raise KeyError("kerf.fmu has no parameter numerics.directionRule")
    if final_surface is not None:
        final_surface.unlink(missing_ok=True)
        sv["rock.finalSurface"] = str(final_surface)
    inst = fmu.instance("CS", name=f"reference-rule{direction_rule}")
    t0 = time.perf_counter()
    try:
        res = kh.run_line_cs(inst, sv, n_steps=n_steps, h=h, feed_x=feed_x)
        inst.f.terminate()  # writes rock.finalSurface
    except Exception:
        for r in inst.log:
            print("   ", r, file=sys.stderr)
        raise
    finally:
        inst.free(terminate=False)
    res["wall_s"] = time.perf_counter() - t0
    for r in inst.log:
        if r.status >= 1:
            print("    FMU:", r)
    return res


def steady(res):
    return {k: kh.steady_mean(res, k, LO, HI) for k in
            ("normalForce", "rollingForce", "sideForce", "penetration", "contactAngle")}


def print_table(theory, runs):
    rows = [("CSM theory, eqs 13-17 (computed here)", theory["FN"] / 1e3, theory["FR"] / 1e3, 0.0)]
    for name, (n, r, s) in kh.TABLE3.items():
        rows.append((name, n, r, s))
    for label, st in runs:
        rows.append((label, st["normalForce"] / 1e3, st["rollingForce"] / 1e3, st["sideForce"] / 1e3))

    def f(v):
        return f"{v:10.3f}" if v is not None else f"{'-':>10}"

    w = max(len(r[0]) for r in rows) + 2
    print()
    print(f"Steady mean forces, {LO} m <= x <= {HI} m (kN)")
    print(f"{'':{w}}{'normal':>10}{'rolling':>10}{'side':>10}")
    for name, n, r, s in rows:
        print(f"{name:{w}}{f(n)}{f(r)}{f(s)}")
    for label, st in runs:
        dn = st["normalForce"] / theory["FN"] - 1
        dr = st["rollingForce"] / theory["FR"] - 1
        print(f"  {label}: normal {dn:+.3%}, rolling {dr:+.3%} vs CSM; "
              f"side/normal {st['sideForce'] / st['normalForce'] if st['normalForce'] else float('nan'):+.2e}")
    print()


def plot_forces(path, theory, results, n_steps, h):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 2, figsize=(13, 10), sharex="col", constrained_layout=True,
                             gridspec_kw=dict(width_ratios=[1.5, 1.0]))
    spec = [("normalForce", "Normal force $F_N$ (along cutter +z)", theory["FN"], 0),
            ("rollingForce", "Rolling force $F_R$ (along cutter -x)", theory["FR"], 1),
            ("sideForce", "Side force $F_S$ (along cutter +y)", 0.0, 2)]
    # kerf default under the dashed CSM line, wide enough to show between the dashes
    styles = {1: dict(color="C0", lw=3.0, zorder=3), 2: dict(color="C1", lw=1.2, zorder=3)}
    handles = {}
    for row, (name, title, th, col) in enumerate(spec):
        full, zoom = axes[row]
        full.axvspan(LO, HI, color="0.92", zorder=0)
        zoom.set_facecolor("0.97")
        for rule, (label, res) in results.items():
            for ax in (full, zoom):
                sel = slice(None) if ax is full else (res["x"] >= LO) & (res["x"] <= HI)
                handles[label] = ax.plot(res["x"][sel], res[name][sel] / 1e3, **styles[rule])[0]
        for ax in (full, zoom):
            handles["CSM theory, eqs 13-17 (side: 0)"] = ax.axhline(th / 1e3, color="k", ls="--", lw=1.2,
                                                                   zorder=4)
        for (tname, vals), c in zip(list(kh.TABLE3.items())[1:], ("C2", "C3")):
            if vals[col] is not None:
                handles[tname] = full.axhline(vals[col], color=c, ls=":", lw=1.5)
                full.annotate(f"{vals[col]:.1f}", (1.0, vals[col]), xycoords=("axes fraction", "data"),
                              xytext=(3, 0), textcoords="offset points", va="center", fontsize=8, color=c)
        zoom.annotate(f"CSM {th / 1e3:.3f}", (1.0, th / 1e3), xycoords=("axes fraction", "data"),
                      xytext=(-3, 4), textcoords="offset points", ha="right", va="bottom", fontsize=8)
        full.set_ylabel(f"{title.split(' (')[0].split(' $')[0]} [kN]")
        full.set_title(title + ": whole cut, with thesis Table 3", fontsize=10, loc="left")
        devs = []
        for rule, (label, res) in sorted(results.items()):
            m = kh.steady_mean(res, name, LO, HI)
            if name == "sideForce":
                nm = kh.steady_mean(res, "normalForce", LO, HI)
                devs.append(f"rule {rule} {m / 1e3:.3f} kN ({m / nm:.0e} F_N)")
            else:
                devs.append(f"rule {rule} {m / th - 1:+.3%}")
        what = "means" if name == "sideForce" else "means vs CSM"
        zoom.set_title(f"zoom on {LO}-{HI} m\n{what}: " + ", ".join(devs), fontsize=9, loc="left")
        for ax in (full, zoom):
            ax.grid(True, alpha=0.3)
        zoom.ticklabel_format(axis="y", useOffset=False)
    handles[f"steady window {LO}-{HI} m (means)"] = plt.Rectangle((0, 0), 1, 1, color="0.92")
    axes[-1, 0].set_xlabel("travel x of the disc centre [m]   (time [s] = x / (1 m/s))")
    axes[-1, 1].set_xlabel("travel x [m]")
    fig.legend(list(handles.values()), list(handles.keys()), loc="outside lower center", ncol=3, fontsize=9)
    fig.suptitle("kerf, thesis reference cut: 17 in disc (R 215.9 mm, T 13 mm), p = 3.8 mm, "
                 f"1 m/s rolling, UCS 158 MPa, BTS 6.78 MPa, CS step {h * 1e3:g} ms", fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_rock(path, rsf, p, r, T, z0):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    X, Y, Z = kh.load_rsf(rsf)
    D = (z0 - Z) * 1e3  # depth below the initial face [mm]
    x = X[:, 0]
    y = Y[0, :]
    dy = (y[1] - y[0]) * 1e3
    dmax = max(float(np.nanmax(D)), 1e-3)

    fig = plt.figure(figsize=(14, 9), constrained_layout=True)
    gs = fig.add_gridspec(2, 3, height_ratios=[1.0, 1.3])
    wins = [("start of the cut", -0.08, 0.04), ("middle", 0.44, 0.56), ("end of the cut", 0.96, 1.08)]
    ysel = (y >= -0.025) & (y <= 0.025)
    im, top = None, []
    for i, (name, xa, xb) in enumerate(wins):
        ax = fig.add_subplot(gs[0, i])
        top.append(ax)
        xs = (x >= xa) & (x <= xb)
        if xs.sum() < 2 or ysel.sum() < 2:
            ax.text(0.5, 0.5, "window outside the rock", ha="center", transform=ax.transAxes)
            continue
        im = ax.pcolormesh(x[xs] * 1e3, y[ysel] * 1e3, D[np.ix_(xs, ysel)].T, shading="nearest",
                           cmap="magma_r", vmin=0.0, vmax=dmax)
        ax.set_aspect("equal")
        ax.set_title(f"{name} (plan view)\nx = {xa:g} .. {xb:g} m", fontsize=10)
        ax.set_xlabel("x [mm] (rolling direction)")
        if i == 0:
            ax.set_ylabel("y [mm] (axle)")
    if im is not None:
        cb = fig.colorbar(im, ax=top, location="right", shrink=0.8, pad=0.01)
        cb.set_label("depth below the initial face [mm]")

    ax = fig.add_subplot(gs[1, :])
    xs = (x >= LO) & (x <= HI)
    i_mid = int(np.argmin(np.abs(x - 0.5)))
    ax.fill_between(y * 1e3, np.nanmin(D[xs], axis=0), np.nanmax(D[xs], axis=0), color="C0", alpha=0.25,
                    step="mid", label=f"kerf: min..max over all node rows {LO} m <= x <= {HI} m")
    ax.plot(y * 1e3, D[i_mid], "o-", color="C0", ms=4, lw=1,
            label=f"kerf: rock nodes at x = {x[i_mid]:.3f} m ({dy:g} mm spacing)")
    yy = np.linspace(-T / 2, T / 2, 201)
    ax.plot(yy * 1e3, kh.tip_depth_profile(yy, r, T, p) * 1e3, "k--", lw=1.6,
            label=f"disc tip R(y) = R - r + sqrt(r² - y²), r = {r * 1e3:g} mm, |y| <= T/2 = {T * 500:g} mm, "
                  f"lowest point at p = {p * 1e3:g} mm")
    ax.axhline(p * 1e3, color="0.5", ls=":", lw=1, label=f"p = {p * 1e3:g} mm")
    groove = D[xs]
    jc = int(np.argmin(np.abs(y)))
    ax.text(0.01, 1.02, f"steady groove: centre depth {np.mean(groove[:, jc]):.3f} mm "
            f"(min {np.min(groove[:, jc]):.3f}, max {np.max(groove[:, jc]):.3f}), "
            f"width at 0.1 mm depth {np.mean(np.sum(groove > 0.1, axis=1)) * dy:.1f} mm",
            transform=ax.transAxes, fontsize=9)
    ax.set_xlim(-16, 16)
    ax.set_ylim(max(dmax, p * 1e3) * 1.12, -0.3)
    ax.set_aspect(3.0)
    ax.set_xlabel("y [mm] (across the groove)")
    ax.set_ylabel("depth below the initial face [mm]")
    ax.set_title("groove cross-section (depth downwards, vertical scale x3)", fontsize=10, loc="left", pad=16)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    fig.suptitle(f"kerf: rock face after the reference cut (surface written at fmi2Terminate: {rsf.name}, "
                 f"{X.shape[0]} x {X.shape[1]} nodes)", fontsize=11)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return dict(max_depth_mm=float(np.nanmax(groove)),
                mean_center_depth_mm=float(np.mean(groove[:, jc])),
                groove_width_mm_at_0_1mm=float(np.mean(np.sum(groove > 0.1, axis=1)) * dy))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default=None, help="kerf.fmu (default: $KERF_FMU or target/fmu/kerf.fmu)")
    ap.add_argument("--out", default=str(ROOT / "out"))
    ap.add_argument("--steps", type=int, default=1000, help="communication steps (default 1000 = 1 m)")
    ap.add_argument("--h", type=float, default=1e-3, help="communication step [s] (default 1 ms)")
    ap.add_argument("--velocity-only", action="store_true",
                    help="set only vx, wy (the FMU integrates the pose) instead of feeding x(t) = v t")
    a = ap.parse_args(argv)

    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    fmu_path = Path(a.fmu).resolve() if a.fmu else kh.fmu_path_from_env(build_if_missing=False)
    if not fmu_path.is_file():
        print(f"error: {fmu_path} does not exist (run `cargo run --release -p packaging`)", file=sys.stderr)
        return 2
    problems = []

    ref = kh.REFERENCE
    theory = kh.csm_theory(ref["R"], ref["T"], ref["ucs"], ref["bts"], ref["S"], ref["C"], ref["p"])
    kh.check_theory_against_notes(theory)
    print(f"CSM theory (eqs 13-17): phi = {theory['phi']:.6f} rad, P' = {theory['P'] / 1e6:.2f} MPa, "
          f"F_t = {theory['Ft'] / 1e3:.3f} kN, F_N = {theory['FN'] / 1e3:.3f} kN, "
          f"F_R = {theory['FR'] / 1e3:.4f} kN  (matches thesis-notes.md)")

    fmu = kh.FMU(fmu_path)
    # the FMU's defaults must be the reference scene
    for name, key in (("cutter.radius", "R"), ("cutter.tipWidth", "T"), ("cutter.tipRadius", "r"),
                      ("rock.ucs", "ucs"), ("rock.bts", "bts"), ("csm.spacing", "S"), ("csm.C", "C")):
        got = fmu.start(name)
        if got is None or not math.isclose(got, ref[key], rel_tol=1e-12):
            problems.append(f"default of {name} is {got}, the reference scene needs {ref[key]}")
    z0 = fmu.start("rock.z0") or 0.0

    rsf = out / "reference_final.rsf"
    results, steadies = {}, []
    for rule, label, surf in ((2, "kerf, thesis direction rule (directionRule 2)", None),
                              (1, "kerf default (directionRule 1)", rsf)):
        print(f"running: {label} ...", flush=True)
        try:
            res = run(fmu, rule, surf, a.steps, a.h, feed_x=not a.velocity_only)
        except Exception as e:
            traceback.print_exc()
            problems.append(f"{label}: {e}")
            continue
        print(f"  {a.steps} steps in {res['wall_s']:.1f} s")
        finite = all(np.all(np.isfinite(res[k])) for k in kh.REAL_OUTPUTS)
        if not finite:
            problems.append(f"{label}: non-finite outputs")
        results[rule] = (label, res)
        steadies.append((label, steady(res)))

    summary = dict(
        scene=dict(ref, h=a.h, steps=a.steps, steady_window_m=[LO, HI], fmu=str(fmu_path),
                   host_feeds_x=not a.velocity_only),
        csm_theory={k: theory[k] for k in ("phi", "P", "Ft", "FN", "FR")},
        thesis_table3_kN={k: dict(zip(("normal", "rolling", "side"), v)) for k, v in kh.TABLE3.items()},
        kerf={},
    )
    if steadies:
        print_table(theory, steadies)
    for rule, (label, res) in results.items():
        st = steady(res)
        end = {k: float(res[k][-1]) for k in ("excavatedVolume", "cuttingEnergy", "specificEnergy")}
        summary["kerf"][f"directionRule{rule}"] = dict(
            label=label, steady_mean=st,
            rel_to_csm=dict(normal=st["normalForce"] / theory["FN"] - 1,
                            rolling=st["rollingForce"] / theory["FR"] - 1),
            at_end=end, wall_s=res["wall_s"])
        print(f"{label}: penetration {st['penetration'] * 1e3:.4f} mm, contact angle "
              f"{st['contactAngle']:.6f} rad (CSM {theory['phi']:.6f}); at 1 m: excavated "
              f"{end['excavatedVolume'] * 1e6:.2f} cm3, energy {end['cuttingEnergy'] / 1e3:.3f} kJ, "
              f"specific energy {end['specificEnergy'] / 1e6:.2f} MJ/m3")

    if results:
        p = out / "reference_forces.png"
        plot_forces(p, theory, results, a.steps, a.h)
        print(f"wrote {p}")
    else:
        problems.append("no run succeeded: no force plot")

    if 1 in results and rsf.is_file():
        p = out / "reference_rock.png"
        try:
            summary["rock"] = plot_rock(p, rsf, ref["p"], ref["r"], ref["T"], z0)
            print(f"wrote {p}")
        except Exception as e:
            traceback.print_exc()
            problems.append(f"rock plot: {e}")
    elif 1 in results:
        problems.append(f"rock.finalSurface = {rsf} was not written at fmi2Terminate: no rock plot")

    summary["problems"] = problems
    (out / "reference_summary.json").write_text(json.dumps(summary, indent=2))
    print(f"wrote {out / 'reference_summary.json'}")
    if problems:
        print("\nREFERENCE SCENE INCOMPLETE:", *problems, sep="\n  - ", file=sys.stderr)
        return 1
    print("reference scene: done")
    return 0


if __name__ == "__main__":
    sys.exit(main())

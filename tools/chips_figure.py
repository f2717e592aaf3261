#!/usr/bin/env python3
"""Rock chips on a virtual LCM block, through kerf.fmu in Co-Simulation (issue 9).

An LCM series: passes 0.6 m long along x at depth p, side by side, each S
further towards -y, so every pass after the first runs beside the groove (and
the chips) of the one before: a relieved cut. The last of four passes is
measured over 0.1 m <= x <= 0.5 m, with chipping on and off. Writes

  out/chips_forces.png   the relieved pass's forces along the cut: saw-tooth vs chip-free, with
                         where each chip broke out
  out/chips_face.png     the block's surface with the chip craters (after the four passes, and
                         mid-way through a relieved pass), and cross-sections
  out/chips_se.png       specific energy against S/p, with and without chips, with the chip
                         curve's minimum marked against the published optimum (S/p 17-20)
  out/chips_summary.json all numbers: the rows and the SE minimum

Usage: scripts/chips [--fmu PATH] [--out DIR]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import numpy as np  # noqa: E402

import kerfhost as kh  # noqa: E402
from kerflab import lcm  # noqa: E402

P = 3.8e-3           # penetration [m]
LENGTH = 0.6         # pass length [m]
WINDOW = (0.1, 0.5)  # measured stretch of the last pass [m]
PASSES = 4
H = 1e-3             # communication step [s] at 1 m/s: 1 mm
# S [m]: S/p 7.9 .. 26.3, closer about the published optimum (S/p 17-20)
SPACINGS = [0.03, 0.04, 0.051, 0.058, 0.065, 0.068, 0.071, 0.074, 0.08, 0.1]
OPTIMUM = (17.0, 20.0)  # S/p of the SE minimum for Colorado Red Granite (issue 9's sources)


def series(fmu, S, chipping, final=None):
    """Runs the block (kerflab.lcm); returns the last pass's samples (x and the outputs)
    and the block's chip count."""
    res = lcm.run_block(fmu, S, P, passes=PASSES, discard=PASSES - 1, length=LENGTH, window=WINDOW,
                        step=H, chipping=chipping, margin=0.1, final_surface=final, traces=True,
                        name=f"lcm-{S}-{chipping}")
    last = dict(res["traces"][-1])
    last["chipTrace"] = last["chipCount"]  # the count after each step of the pass
    last["chipCount"] = res["chipCount"]
    return last


def midpass_surface(fmu, S, stop, path):
    """Two passes at spacing S, the second (relieved) one stopped at x = `stop`;
    writes the surface to `path`. Behind the disc the ridge has broken out chip
    by chip; the chip it broke last reaches one chip length ahead of it; past
    that the ridge stands."""
    sv = lcm.block_parameters(fmu, S, P, passes=2, length=LENGTH, chipping=True, margin=0.1)
    sv["rock.finalSurface"] = str(path)
    R = float(fmu.start("cutter.radius"))
    inst = fmu.instance("CS", name="midpass")
    try:
        inst.initialize(sv, inputs=dict(x=0.0, y=0.0, z=R - P, vx=1.0, wy=1.0 / R))
        vr_xy = [inst.fmu_file.var(o).valueReference for o in ("x", "y")]
        t = 0.0
        for k, end in ((0, LENGTH), (1, stop)):
            for i in range(int(round(end / H))):
                inst.f.setReal(vr_xy, [i * H, -k * S])
                inst.f.doStep(currentCommunicationPoint=t, communicationStepSize=H)
                t += H
        inst.f.terminate()
    finally:
        inst.free(terminate=False)


def summary(res):
    w = (res["x"] >= WINDOW[0]) & (res["x"] <= WINDOW[1])
    e, v = res["cuttingEnergy"][w], res["excavatedVolume"][w]
    fn = res["normalForce"][w]
    return {"normal": float(fn.mean()), "rolling": float(res["rollingForce"][w].mean()),
            "side": float(res["sideForce"][w].mean()),
            "normal_peak": float(fn.max()), "normal_cv": float(fn.std() / fn.mean()),
            "se": float((e[-1] - e[0]) / (v[-1] - v[0])), "chips": int(res["chipCount"])}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default=str(kh.DEFAULT_FMU))
    ap.add_argument("--out", default=str(ROOT / "out"))
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    fmu = kh.FMU(a.fmu)
    if "chipping.enabled" not in fmu.vars:
        sys.exit(f"{a.fmu} has no chipping.enabled: rebuild it")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows, traces = [], {}
    print(f"LCM series, p = {P * 1e3} mm, {PASSES} passes; the last one over x = {WINDOW} m")
    print(" S/p   S mm  chips   Fn kN  Fr kN  Fs kN  Fn peak  CV(Fn)  SE MJ/m3  chips in pass")
    for S in SPACINGS:
        for chipping in (False, True):
            final = out / "chips_face.rsf" if (chipping and S == 0.051) else None
            res = series(fmu, S, chipping, final)
            s = summary(res)
            s.update(S=S, ratio=S / P, chipping=chipping)
            rows.append(s)
            if S == 0.051:
                traces[chipping] = res
            print(f"{S / P:5.1f} {S * 1e3:5.0f}  {str(chipping):5}  {s['normal'] / 1e3:6.1f} "
                  f"{s['rolling'] / 1e3:6.2f} {s['side'] / 1e3:6.2f}  {s['normal_peak'] / 1e3:7.1f} "
                  f"{s['normal_cv']:6.3f}  {s['se'] / 1e6:8.1f}  {s['chips']}")
    print("LCM row (Gertsch et al. 2007, thesis Table 3; S/p 13.4): 81 / 7.3 / 11.2 kN; "
          "SE about 38 MJ/m3 if the whole ridge S x p left (inferred)")

    # forces along the relieved pass
    fig, ax = plt.subplots(3, 1, figsize=(9, 7), sharex=True)
    for chipping, style in ((False, "k--"), (True, "C3-")):
        res = traces[chipping]
        for i, name in enumerate(["normalForce", "rollingForce", "sideForce"]):
            ax[i].plot(res["x"], res[name] / 1e3, style, lw=0.9,
                       label="chips" if chipping else "no chips")
            ax[i].set_ylabel(f"{name} [kN]")
    # where chips broke out (the chip count steps; one chip per side of the groove)
    res = traces[True]
    broke = res["x"][1:][np.diff(res["chipTrace"]) > 0]
    for a_ in ax:
        for xb in broke:
            a_.axvline(xb, color="C0", lw=0.8, ls=":", zorder=0)
    ax[0].plot([], [], color="C0", lw=0.8, ls=":", label=f"a chip breaks out ({len(broke)} in the pass)")
    ax[0].legend(loc="lower right", fontsize=8)
    ax[0].set_title("Relieved pass beside a groove at S = 51 mm, p = 3.8 mm (thesis Table 3's LCM scene)")
    ax[2].set_xlabel("x [m]")
    fig.tight_layout()
    fig.savefig(out / "chips_forces.png", dpi=110)

    # the block's surface: after 4 passes, and mid-way through a relieved pass
    stop = 0.3
    midpass_surface(fmu, 0.051, stop, out / "chips_midpass.rsf")
    fig, ax = plt.subplots(3, 1, figsize=(9, 10), gridspec_kw={"height_ratios": [2, 2, 1]})
    X, Y, Z = kh.load_rsf(out / "chips_face.rsf")
    sel = (X[:, 0] >= 0.0) & (X[:, 0] <= LENGTH)
    im = ax[0].imshow(Z[sel].T * 1e3, origin="lower", aspect="auto", cmap="viridis",
                      extent=[X[sel][0, 0], X[sel][-1, 0], Y[0, 0], Y[0, -1]])
    fig.colorbar(im, ax=ax[0], label="surface height [mm]")
    ax[0].set_ylabel("y [m]")
    ax[0].set_title("The block after 4 passes with chips (S = 51 mm): the ridges between grooves broke out")
    X2, Y2, Z2 = kh.load_rsf(out / "chips_midpass.rsf")
    sel2 = (X2[:, 0] >= 0.0) & (X2[:, 0] <= LENGTH)
    im = ax[1].imshow(Z2[sel2].T * 1e3, origin="lower", aspect="auto", cmap="viridis",
                      extent=[X2[sel2][0, 0], X2[sel2][-1, 0], Y2[0, 0], Y2[0, -1]])
    fig.colorbar(im, ax=ax[1], label="surface height [mm]")
    ax[1].axvline(stop, color="w", ls=":", lw=1)
    ax[1].set_ylabel("y [m]")
    ax[1].set_title(f"Relieved pass stopped at x = {stop} m (dotted): ridge broken out chip by chip,\n"
                    "the last chip reaching ahead of the disc, intact rock beyond", fontsize=10)
    i = int(np.argmin(np.abs(X[:, 0] - 0.3)))
    ax[2].plot(Y[i] * 1e3, Z[i] * 1e3, "C3-", label="after 4 passes, x = 0.3 m")
    j = int(np.argmin(np.abs(X2[:, 0] - 0.45)))
    ax[2].plot(Y2[j] * 1e3, Z2[j] * 1e3, "k--", label="mid-way, x = 0.45 m (ahead of the disc)")
    ax[2].set_xlabel("y [mm]")
    ax[2].set_ylabel("z [mm]")
    ax[2].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "chips_face.png", dpi=110)

    # specific energy against S/p, and where the chip curve has its minimum
    best = min((r for r in rows if r["chipping"]), key=lambda r: r["se"])
    inside = OPTIMUM[0] <= best["ratio"] <= OPTIMUM[1]
    print(f"SE minimum with chips: {best['se'] / 1e6:.1f} MJ/m3 at S/p {best['ratio']:.1f} "
          f"(S {best['S'] * 1e3:.0f} mm); the sources put it at S/p {OPTIMUM[0]:g}-{OPTIMUM[1]:g}: "
          f"{'inside' if inside else 'OUTSIDE'}")
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for chipping, style in ((False, "ko--"), (True, "C3o-")):
        rr = [r for r in rows if r["chipping"] == chipping]
        ax.plot([r["ratio"] for r in rr], [r["se"] / 1e6 for r in rr], style,
                label="chips" if chipping else "no chips")
    ax.axvspan(*OPTIMUM, color="C2", alpha=0.2, label="published optimum, CRG (S/p 17-20)")
    ax.plot([best["ratio"]], [best["se"] / 1e6], "C3*", ms=14,
            label=f"kerf's minimum: S/p {best['ratio']:.1f}, {best['se'] / 1e6:.0f} MJ/m3")
    ax.plot([13.4], [37.7], "C0s", label="LCM row, whole ridge removed (inferred)")
    ax.set_xlabel("S / p")
    ax.set_ylabel("specific energy [MJ/m3]")
    ax.set_ylim(bottom=0)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "chips_se.png", dpi=110)

    (out / "chips_summary.json").write_text(json.dumps(
        {"p": P, "rows": rows, "se_minimum": {"ratio": best["ratio"], "S": best["S"], "se": best["se"],
                                              "published_optimum": list(OPTIMUM), "inside": inside}},
        indent=1))
    print(f"wrote {out}/chips_forces.png, chips_face.png, chips_se.png, chips_summary.json")


if __name__ == "__main__":
    main()

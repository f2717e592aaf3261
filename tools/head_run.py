#!/usr/bin/env python3
"""Bores with a cutterhead FMU through fmpy (Co-Simulation) from flat rock and
reports what a TBM designer reads: mean thrust and torque of the last revolution
against the CSM sums, per-disc loads by track radius, radial imbalance and
overturning moment. Plots to out/. Run through scripts/head."""

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import headhost as hh  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--fmu", required=True)
    ap.add_argument("--rpm", type=float, default=None, help="head speed (default: 10 for heads under 3 m, else 3)")
    ap.add_argument("--p-rev", type=float, default=0.006, help="advance per revolution [m]")
    ap.add_argument("--revs", type=float, default=2.5, help="revolutions from flat rock")
    ap.add_argument("--h", type=float, default=None, help="communication step [s] (default: 1/720 rev)")
    ap.add_argument("--steady", action="store_true",
                    help="start from the steady face (head.steadyPenetration = p-rev, docs/head.md) instead of flat rock")
    ap.add_argument("--cell", type=float, default=None,
                    help="height-map cell [m] (default: the FMU's, 1 mm; 2e-3 runs about twice as fast, "
                         "docs/head.md 'Speed at 1 kHz')")
    ap.add_argument("--sweep-step", type=float, default=None,
                    help="numerics.sweepStep [m] (default: the FMU's, 1 mm)")
    ap.add_argument("--ring-step", type=float, default=None,
                    help="numerics.ringStepCells: the width of the bands the gauge discs' side faces "
                         "are cut into, in cells "
                         "(default: the FMU's, 0.5; README 'Speed and accuracy')")
    ap.add_argument("--out", default="out")
    ap.add_argument("--ucs", type=float, default=158e6)
    ap.add_argument("--bts", type=float, default=6.78e6)
    ap.add_argument("--C", type=float, default=2.12)
    a = ap.parse_args()

    fmu = hh.HeadFMU(a.fmu)
    lay = fmu.layout
    n = fmu.n
    frames = hh.disc_frames(lay)
    tracks = np.array([c["track"] for c in lay["cutters"]])
    bore_d = 2 * (max(tracks) + 0.5 * lay["disc"]["tipWidth"])
    rpm = a.rpm if a.rpm is not None else (10.0 if bore_d < 3 else 3.0)
    w = rpm * 2 * math.pi / 60
    t_rev = 2 * math.pi / w
    h = a.h if a.h else t_rev / 720
    t_end = a.revs * t_rev
    out_dir = Path(a.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    surf = (out_dir / "head_face.rsf").resolve()
    # nodes over the FMU's own rock rectangle at the asked cell size
    grid = fmu.grid_starts(a.cell) if a.cell else {}
    nodes = (grid.get("rock.nx") or int(fmu.vars["rock.nx"].start)) * \
        (grid.get("rock.ny") or int(fmu.vars["rock.ny"].start))
    write_face = nodes <= 25_000_000
    print(f"head {lay['name']}: {n} discs, bore {bore_d:.2f} m, {rpm:g} rpm, {a.p_rev * 1000:g} mm/rev, "
          f"{a.revs:g} revolutions from {'the steady face' if a.steady else 'flat rock'} in steps of "
          f"{h * 1000:.2f} ms ({int(round(t_end / h))} steps)")
    starts = {"rock.ucs": a.ucs, "rock.bts": a.bts, "csm.C": a.C, **grid}
    if a.sweep_step:
        starts["numerics.sweepStep"] = a.sweep_step
    if a.ring_step:
        starts["numerics.ringStepCells"] = a.ring_step
    if a.steady:
        starts["head.steadyPenetration"] = a.p_rev
    if write_face:
        starts["rock.finalSurface"] = str(surf)
    f = fmu.instance("CS", start_values=starts)
    t0 = time.perf_counter()

    def progress(k, total):
        el = time.perf_counter() - t0
        print(f"  {100 * k / total:5.1f} %  {el:7.1f} s wall", flush=True)

    t, out = fmu.bore_cs(f, w, a.p_rev, t_end, h, progress=progress)
    wall = time.perf_counter() - t0
    print(f"bored {t_end:.1f} s of machine time in {wall:.1f} s wall ({wall / t_end:.2f} s per s)")
    f.terminate()
    f.freeInstance()
    c = lambda k: out[:, hh.col(fmu, k)]
    last = t > t_end - t_rev
    thrust, torque = c("thrust")[last].mean(), c("torque")[last].mean()

    # CSM sums at the depth per revolution, each disc with its own spacing
    fn = np.zeros(n)
    fr = np.zeros(n)
    for i, cu in enumerate(lay["cutters"]):
        d = dict(lay["disc"], **cu.get("disc", {}))
        fn[i], fr[i] = hh.csm_force(d["radius"], d["tipWidth"], a.ucs, a.bts, cu["spacing"], a.C, a.p_rev)
    sum_fn = fn.sum()
    sum_frr = (fr * tracks).sum()
    shortcut = 0.3 * bore_d * n * fr.mean()
    print(f"\nlast revolution (t > {t_end - t_rev:.1f} s), against the CSM law at p = {a.p_rev * 1000:g} mm/rev:")
    print(f"  thrust  {thrust / 1e3:10.1f} kN     CSM sum F_N       {sum_fn / 1e3:10.1f} kN   ratio {thrust / sum_fn:.2f}")
    print(f"  torque  {torque / 1e3:10.1f} kN.m   CSM sum F_R r     {sum_frr / 1e3:10.1f} kN.m ratio {torque / sum_frr:.2f}")
    print(f"                              0.3 D N F_R       {shortcut / 1e3:10.1f} kN.m ratio {torque / shortcut:.2f}")
    fxy = np.hypot(c("Fx"), c("Fy"))[last]
    mxy = np.hypot(c("Mx"), c("My"))[last]
    print(f"  radial imbalance |Fx, Fy|: mean {fxy.mean() / 1e3:.1f} kN, peak {fxy.max() / 1e3:.1f} kN")
    print(f"  overturning moment |Mx, My| about the head centre: mean {mxy.mean() / 1e3:.1f} kN.m, "
          f"peak {mxy.max() / 1e3:.1f} kN.m")
    tilted = any(cut["tiltDeg"] != 0 for cut in lay["cutters"])
    if tilted:
        print("  (the tilted discs' side forces enter both; they are the flat-sided thesis disc's\n"
              "   unless cutter.flankAngle gives the discs flanks: docs/head.md, 'Gauge cutters on curved tracks')")
    print("\nper disc, last revolution (by track radius):")
    print("  disc  track[m]  tilt  mean F_N[kN]  peak F_N[kN]  CSM F_N[kN]  mean F_R[kN]  mean F_S[kN]  mean p[mm]")
    order = np.argsort(tracks)
    rows = []
    for i in order:
        nf = c(f"cutter[{i + 1}].normalForce")[last]
        rf = c(f"cutter[{i + 1}].rollingForce")[last]
        sf = c(f"cutter[{i + 1}].sideForce")[last]
        pp = c(f"cutter[{i + 1}].penetration")[last]
        rows.append(dict(disc=int(i + 1), track=float(tracks[i]), tilt=lay["cutters"][i]["tiltDeg"],
                         mean_fn=float(nf.mean()), peak_fn=float(nf.max()), csm_fn=float(fn[i]),
                         mean_fr=float(rf.mean()), mean_fs=float(sf.mean()), mean_p=float(pp.mean())))
        print(f"  {i + 1:4d}  {tracks[i]:8.3f}  {lay['cutters'][i]['tiltDeg']:4g}  {nf.mean() / 1e3:12.1f}  "
              f"{nf.max() / 1e3:12.1f}  {fn[i] / 1e3:11.1f}  {rf.mean() / 1e3:12.2f}  {sf.mean() / 1e3:12.2f}  "
              f"{pp.mean() * 1e3:10.2f}")
    summary = dict(layout=lay["name"], steady_start=a.steady, discs=n, bore_diameter=bore_d, rpm=rpm, p_rev=a.p_rev, revs=a.revs,
                   step=h, wall_s=wall, thrust=thrust, torque=torque, csm_sum_fn=sum_fn,
                   csm_sum_fr_r=sum_frr, csm_shortcut=shortcut, imbalance_mean=float(fxy.mean()),
                   imbalance_peak=float(fxy.max()), overturning_mean=float(mxy.mean()),
                   overturning_peak=float(mxy.max()), discs_by_track=rows)
    (out_dir / "head_summary.json").write_text(json.dumps(summary, indent=1))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    ax[0].plot(t, c("thrust") / 1e3, lw=0.8, label="thrust (kerf)")
    ax[0].axhline(sum_fn / 1e3, ls="--", c="k", label="CSM sum F_N")
    ax[0].set_ylabel("thrust [kN]")
    ax[0].legend(loc="lower right")
    ax[1].plot(t, c("torque") / 1e3, lw=0.8, c="C1", label="torque (kerf)")
    ax[1].axhline(sum_frr / 1e3, ls="--", c="k", label="CSM sum F_R r")
    ax[1].axhline(shortcut / 1e3, ls=":", c="k", label="0.3 D N F_R")
    ax[1].set_ylabel("torque [kN.m]")
    ax[1].set_xlabel("time [s]")
    ax[1].legend(loc="lower right")
    fig.suptitle(f"{lay['name']}: {n} discs, {rpm:g} rpm, {a.p_rev * 1000:g} mm/rev from "
                 f"{'the steady face' if a.steady else 'flat rock'}")
    fig.tight_layout()
    fig.savefig(out_dir / "head_thrust_torque.png", dpi=120)

    fig, ax = plt.subplots(figsize=(9, 4.5))
    tr = np.array([r["track"] for r in rows])
    ax.plot(tr, [r["mean_fn"] / 1e3 for r in rows], "o", label="mean F_N, last rev")
    ax.plot(tr, [r["peak_fn"] / 1e3 for r in rows], "^", label="peak F_N, last rev")
    ax.plot(tr, [r["mean_fr"] / 1e3 for r in rows], "s", label="mean F_R, last rev")
    ax.plot(tr, [r["csm_fn"] / 1e3 for r in rows], "k_", ms=14, label="CSM F_N at p/rev")
    ax.set_xlabel("track radius [m]")
    ax.set_ylabel("force [kN]")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out_dir / "head_disc_loads.png", dpi=120)
    if write_face and surf.is_file():
        d = np.loadtxt(surf, comments="#", usecols=(0, 1, 2, 3, 4))
        nx, ny = int(d[:, 0].max()), int(d[:, 1].max())
        z = np.full((ny, nx), np.nan)
        z[d[:, 1].astype(int) - 1, d[:, 0].astype(int) - 1] = d[:, 4]
        x0, x1, y0, y1 = d[:, 2].min(), d[:, 2].max(), d[:, 3].min(), d[:, 3].max()
        surf.unlink()
        fig, ax = plt.subplots(1, 2, figsize=(12, 5.2), gridspec_kw=dict(width_ratios=[1, 1.3]))
        im = ax[0].imshow(z * 1e3, origin="lower", extent=[x0, x1, y0, y1], cmap="viridis")
        fig.colorbar(im, ax=ax[0], label="rock height [mm]")
        ax[0].set_xlabel("x [m]")
        ax[0].set_ylabel("y [m]")
        ax[0].set_title("bored face")
        j = int(round((0.0 - y0) / (y1 - y0) * (ny - 1)))
        xs = np.linspace(x0, x1, nx)
        sel = xs >= 0
        ax[1].plot(xs[sel], z[j, sel] * 1e3, lw=0.7)
        for r in tracks:
            ax[1].axvline(r, c="0.8", lw=0.5, zorder=0)
        ax[1].set_xlabel("radius along +x [m] (grey: disc tracks)")
        ax[1].set_ylabel("rock height [mm]")
        ax[1].set_title("cross-section y = 0 through the grooves")
        fig.tight_layout()
        fig.savefig(out_dir / "head_face.png", dpi=120)
        print(f"wrote {out_dir}/head_face.png")
    elif not write_face:
        print(f"face image skipped: {nodes / 1e6:.0f} M nodes is too many for a text surface file")
    print(f"\nwrote {out_dir}/head_thrust_torque.png, head_disc_loads.png, head_summary.json")
    plt.close("all")


if __name__ == "__main__":
    main()

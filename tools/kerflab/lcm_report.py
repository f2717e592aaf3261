"""scripts/lcm: an LCM test series on a virtual rock block (kerf.fmu, fmpy, Co-Simulation).

A grid of spacings S and penetrations p; per (S, p) one block of sequential
passes, the first ones discarded as unrelieved (kerflab/lcm.py says how).
Writes, in --out (default out/):

  lcm_table.csv        one row per (S, p): mean and peak Fn, Fr, Fs [kN], CC = Fr/Fn,
                       SE [MJ/m3] (Fr over volume removed per metre, as an LCM
                       report computes it; SE_energy: kerf's cutting energy over
                       volume), volume and chip volume per metre [cm3/m], chips
                       per metre. The same columns are the input of scripts/calibrate.
  lcm_forces.png       mean (and peak) forces against p, one line per S
  lcm_se.png           SE against S/p, one line per p
  lcm_passes.json      every pass's summary (the discarded ones too) and the settings

Usage: scripts/lcm [--spacings 40,51,65] [--penetrations 3,3.8,5] [--passes 4]
                   [--discard 2] [--set csm.C=2.5] [--no-chipping] [--compare data/lcm/thesis_table3.csv]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from kerflab import lcm

ROOT = Path(__file__).resolve().parents[2]


def floats(s):
    return [float(x) for x in s.split(",") if x.strip()]


def parse_set(items):
    """NAME=VALUE pairs (FMU parameters) -> dict; true/false for Booleans, numbers else."""
    out = {}
    for it in items or []:
        if "=" not in it:
            raise SystemExit(f"--set {it!r}: expected NAME=VALUE")
        k, v = it.split("=", 1)
        lv = v.strip().lower()
        if lv in ("true", "false"):
            out[k.strip()] = lv == "true"
        else:
            try:
                out[k.strip()] = int(v) if v.strip().lstrip("-").isdigit() else float(v)
            except ValueError:
                out[k.strip()] = v
    return out


def add_block_args(ap):
    """The options of one block, shared by scripts/lcm, scripts/calibrate and scripts/sweep."""
    ap.add_argument("--passes", type=int, default=lcm.PASSES, help="passes per block (default %(default)s)")
    ap.add_argument("--discard", type=int, default=lcm.DISCARD,
                    help="first passes discarded as unrelieved (default %(default)s)")
    ap.add_argument("--length", type=float, default=lcm.LENGTH, help="pass length [m] (default %(default)s)")
    ap.add_argument("--window", type=floats, default=list(lcm.WINDOW),
                    help="measured stretch of each pass, x0,x1 [m] (default 0.1,0.5)")
    ap.add_argument("--cell", type=float, default=1e-3, help="rock cell size [m] (default %(default)s)")
    ap.add_argument("--no-chipping", action="store_true", help="rock without chips")
    ap.add_argument("--set", action="append", metavar="NAME=VALUE",
                    help="an FMU parameter for every block (repeatable), e.g. csm.C=2.5, csm.variant=2")


def block_kwargs(a):
    return dict(passes=a.passes, discard=a.discard, length=a.length, window=tuple(a.window),
                cell=a.cell, chipping=not a.no_chipping)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "kerf.fmu"))
    ap.add_argument("--out", default=str(ROOT / "out"))
    ap.add_argument("--spacings", type=floats, default=[30, 40, 51, 65, 80, 100],
                    help="spacings S [mm] (default %(default)s)")
    ap.add_argument("--penetrations", type=floats, default=[2.5, 3.8, 5.0, 6.5],
                    help="penetrations p [mm] (default %(default)s)")
    ap.add_argument("--rock", default="", help="rock name for the table")
    ap.add_argument("--compare", help="an LCM table of measured rows to draw on the plots")
    ap.add_argument("--csv", default="lcm_table.csv", help="table file name in --out")
    add_block_args(ap)
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    params = parse_set(a.set)
    fmu = lcm.open_fmu(a.fmu)
    kw = block_kwargs(a)

    print(f"virtual LCM: {len(a.spacings)} spacings x {len(a.penetrations)} penetrations, "
          f"{a.passes} passes per block, first {a.discard} discarded, chipping "
          f"{'off' if a.no_chipping else 'on'}; parameters {params or 'FMU defaults'}")
    print("  S mm  p mm   S/p   Fn kN  Fr kN  Fs kN  Fn pk    CC   SE MJ/m3  V cm3/m  chip cm3/m")
    rows, passes = [], []
    t0 = time.monotonic()
    for p in a.penetrations:
        for S in a.spacings:
            res = lcm.run_block(fmu, S * 1e-3, p * 1e-3, params=params, **kw)
            r = res["row"]
            r["rock"] = a.rock
            rows.append({c: r.get(c) for c in lcm.COLUMNS})
            passes.append({"S_mm": S, "p_mm": p, "passes": res["passes"], "chipCount": res["chipCount"]})
            print(f"{S:6.1f} {p:5.2f} {r['S_over_p']:5.1f}  {r['Fn_kN']:6.1f} {r['Fr_kN']:6.2f} "
                  f"{r['Fs_kN']:6.2f} {r['Fn_peak_kN']:6.1f} {r['CC']:6.3f} {r['SE_MJm3']:9.1f} "
                  f"{r['V_cm3_per_m']:8.1f} {r['chip_cm3_per_m']:9.1f}", flush=True)
    secs = time.monotonic() - t0
    header = [f"kerf virtual LCM ({a.fmu}); {a.passes} passes per block, first {a.discard} discarded "
              f"as unrelieved, window {a.window[0]}-{a.window[1]} m of {a.length} m; chipping "
              f"{'off' if a.no_chipping else 'on'}; parameters: {json.dumps(params) if params else 'FMU defaults'}",
              "Fs > 0 pushes the disc towards the relieved side (the previous groove); SE = Fr / (volume per metre)"]
    table = lcm.write_table(rows, out / a.csv, header)
    (out / "lcm_passes.json").write_text(json.dumps(
        {"settings": {**vars(a), "params": params}, "blocks": passes}, indent=1, default=str))
    plots(table, out, a.compare)
    print(f"{len(rows)} blocks in {secs:.1f} s; wrote {out / a.csv}, lcm_forces.png, lcm_se.png, lcm_passes.json")


def plots(table, out, compare=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meas = lcm.read_table(compare) if compare else None
    fig, ax = plt.subplots(1, 3, figsize=(13, 4.2))
    for i, (col, label) in enumerate((("Fn", "normal"), ("Fr", "rolling"), ("Fs", "side"))):
        for j, (S, g) in enumerate(table.groupby("S_mm")):
            g = g.sort_values("p_mm")
            ax[i].plot(g["p_mm"], g[f"{col}_kN"], "o-", color=f"C{j}", label=f"S = {S:g} mm")
            ax[i].plot(g["p_mm"], g[f"{col}_peak_kN"], ":", color=f"C{j}", lw=0.8)
        if meas is not None and f"{col}_kN" in meas:
            ax[i].plot(meas["p_mm"], meas[f"{col}_kN"], "k*", ms=11, label="measured")
        ax[i].set_xlabel("penetration p [mm]")
        ax[i].set_ylabel(f"{label} force [kN]")
        ax[i].set_ylim(bottom=0)
    ax[0].legend(fontsize=8)
    fig.suptitle("Virtual LCM: mean forces (solid) and peaks (dotted) against penetration")
    fig.tight_layout()
    fig.savefig(out / "lcm_forces.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for j, (p, g) in enumerate(table.groupby("p_mm")):
        g = g.sort_values("S_over_p")
        ax.plot(g["S_over_p"], g["SE_MJm3"], "o-", color=f"C{j}", label=f"p = {p:g} mm")
    if meas is not None and "SE_MJm3" in meas and meas["SE_MJm3"].notna().any():
        ax.plot(meas["S_mm"] / meas["p_mm"], meas["SE_MJm3"], "k*", ms=11, label="measured")
    ax.axvspan(17, 20, color="C2", alpha=0.15, label="published optimum, CRG (S/p 17-20)")
    ax.set_xlabel("S / p")
    ax.set_ylabel("specific energy [MJ/m3]")
    ax.set_yscale("log")
    ax.legend(fontsize=8)
    ax.set_title("Virtual LCM: specific energy against S/p")
    fig.tight_layout()
    fig.savefig(out / "lcm_se.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())

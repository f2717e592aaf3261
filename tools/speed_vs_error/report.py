#!/usr/bin/env python3
"""Turns the rows written by `examples/speed-vs-error.rs` (and the C host's
result) into docs/speed-vs-error.md, docs/speed-vs-error.json,
docs/speed-vs-error.png and docs/convergence.png.

usage: report.py ROWS.json COSTS.jsonl|- DOCS_DIR
"""
import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

METRICS = [
    ("err_normal", "F_N vs CSM"),
    ("err_rolling", "F_R vs CSM"),
    ("err_side", "F_S / F_N(CSM)"),
    ("err_volume", "volume vs groove"),
    ("err_tilt", "tilted 30° vs converged, worst component / F_N"),
    ("err_groove", "beside groove vs converged, worst component / F_N"),
]


def worst(r):
    return max(r[k] for k, _ in METRICS)


def pct(x):
    if x is None:
        return "n/a"
    if x == 0:
        return "0 (ref)"
    p = 100 * x
    if p < 1e-6:
        return f"{p:.0e} %"
    if p < 0.01:
        return f"{p:.1e} %"
    if p < 10:
        return f"{p:.2f} %"
    return f"{p:.0f} %"


def us(x):
    if x >= 1e5:
        return f"{x / 1e3:,.0f} ms"
    if x >= 1e4:
        return f"{x:,.0f}"
    if x >= 100:
        return f"{x:.0f}"
    return f"{x:.1f}"


def mem(b):
    if b >= 1 << 20:
        return f"{b / (1 << 20):.1f} MiB"
    return f"{b / 1024:.0f} KiB"


def pareto(points):
    """Indices of the points not dominated in (cost, error), both minimised."""
    idx = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], math.inf
    for i in idx:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def is_default(r):
    return r["group"] == "defaults"


def setting_text(r):
    if r["model"] == "baseline":
        return (
            f"thesis baseline, n_alpha x n_y = {r['n_alpha']} x {r['n_y']}"
            + (", mu = 0" if "mu = 0" in r["label"] else "")
            + (f", {r['cell_mm']:g} mm cells" if r["cell_mm"] != 1.0 else "")
        )
    return r["label"]


TARGET_US = 5.0
TARGET_RATIO = 2.0
R_DISC = 0.2159


def scene_summary(data, costs):
    """Per scene: the forces at each cell size, the error of each component
    against the 0.25 mm run (or the finest run there is) relative to the
    fresh cut's normal force, the oracle's, and the cost from the core and
    the C host (median over rounds of each round's median)."""
    fn = data["csm"]["normal"]
    out = []
    scenes = data.get("scenes") or []
    for sc in scenes:
        cells = {float(k): v for k, v in sc["cells"].items()}
        ref_cell = min(cells)
        ref = cells[ref_cell]
        d = {"scene": sc["scene"], "kind": sc["kind"], "ref_cell_mm": ref_cell, "cells": {}}
        for c, m in sorted(cells.items(), reverse=True):
            e = {
                "force_kN": [x / 1e3 for x in m["force"]],
                "moment_kNm": [x / 1e3 for x in m["moment"]],
                "err_force": [(a - b) / fn for a, b in zip(m["force"], ref["force"])],
                "err_moment": [(a - b) / (fn * R_DISC) for a, b in zip(m["moment"], ref["moment"])],
                "volume_per_length_mm2": m["volume"] / m["length"] * 1e6 if m["length"] > 0 else None,
                "rolling_work_per_volume": m["cutting"][1] * m["length"] / m["volume"] if m["volume"] > 1e-12 else None,
            }
            e["worst"] = max(abs(x) for x in e["err_force"] + e["err_moment"])
            d["cells"][c] = e
        o = sc.get("oracle")
        if o:
            d["oracle"] = {
                "err": [(a - b) / fn for a, b in zip(o["fast"], o["brute"])],
                "brute_kN": [x / 1e3 for x in o["brute"]],
                "ms_brute": o["ms_brute"],
            }
        out.append(d)
    # the fresh cut's rolling work per volume, for the partial scenes
    fresh = next((d for d in out if d["kind"] == "fresh"), None)
    for d in out:
        for c, e in d["cells"].items():
            w0 = fresh["cells"].get(c, {}).get("rolling_work_per_volume") if fresh else None
            w = e["rolling_work_per_volume"]
            e["wv_vs_fresh"] = w / w0 if w and w0 else None
            f0 = fresh["cells"].get(c, {}).get("force_kN") if fresh else None
            e["normal_vs_fresh"] = e["force_kN"][0] / f0[0] if f0 else None
    # costs
    by = {}
    for r in costs:
        by.setdefault((r["kind"], r["scene"]), []).append(r)
    for d in out:
        core = by.get(("core", d["scene"]), [])
        host = by.get(("host", d["scene"]), [])
        d["cost"] = {
            "rounds_core": len(core),
            "rounds_host": len(host),
            "core_us": float(np.median([r["us_median"] for r in core])) if core else None,
            "core_us_rounds": [r["us_median"] for r in core],
            "host_dostep_us": float(np.median([r["dostep_us_median"] for r in host])) if host else None,
            "host_dostep_p25": float(np.median([r["dostep_us_p25"] for r in host])) if host else None,
            "host_dostep_p75": float(np.median([r["dostep_us_p75"] for r in host])) if host else None,
            "host_step_us": float(np.median([r["step_us_median"] for r in host])) if host else None,
            "host_dostep_us_rounds": [r["dostep_us_median"] for r in host],
            "host_mean_force_kN": [
                float(np.mean([r[k] for r in host])) / 1e3 for k in ("mean_normal", "mean_rolling", "mean_side")
            ] if host else None,
        }
    # each scene against the straight cut of the same round, the median
    # over the rounds: this machine switches between a fast and a slow
    # state, and a round's scenes are timed within seconds of each other
    st = next((d for d in out if d["kind"] == "fresh"), None)
    for d in out:
        c = d["cost"]
        for k, kind, field in (("core_us", "core", "us_median"),
                               ("host_dostep_us", "host", "dostep_us_median")):
            mine = {r["round"]: r[field] for r in by.get((kind, d["scene"]), [])}
            base = {r["round"]: r[field] for r in by.get((kind, st["scene"]), [])} if st else {}
            ratios = [mine[k2] / base[k2] for k2 in mine if base.get(k2)]
            c[k + "_vs_straight"] = float(np.median(ratios)) if ratios else None
    return out


def sgn_pct(x, digits=2):
    if x is None:
        return "—"
    return f"{100 * x:+.{digits}f}"


def scene_plots(summary, fig_axes):
    """Cost per scene (core and host, with the targets) and the worst
    component error at 1 mm per scene."""
    ax_c, ax_e = fig_axes
    names = [d["scene"] for d in summary]
    y = np.arange(len(names))
    core = [d["cost"]["core_us"] or 0 for d in summary]
    host = [d["cost"]["host_dostep_us"] or 0 for d in summary]
    ax_c.barh(y - 0.2, core, 0.4, label="core: cut + evaluate", color="tab:blue")
    ax_c.barh(y + 0.2, host, 0.4, label="C host: fmi2DoStep", color="tab:orange")
    ax_c.axvline(TARGET_US, color="k", ls="--", lw=1, label=f"target {TARGET_US:g} µs")
    st = next((d for d in summary if d["kind"] == "fresh"), None)
    if st and st["cost"]["host_dostep_us"]:
        ax_c.axvline(TARGET_RATIO * st["cost"]["host_dostep_us"], color="tab:orange", ls=":", lw=1,
                     label=f"{TARGET_RATIO:g}x straight (host)")
    ax_c.set_yticks(y)
    ax_c.set_yticklabels(names, fontsize=8)
    ax_c.invert_yaxis()
    ax_c.set_xscale("log")
    ax_c.set_xlabel("µs per 1 ms step at 1 m/s (median over rounds)")
    ax_c.set_title("cost per scene (1 mm cells)", fontsize=11)
    ax_c.legend(fontsize=8)
    ax_c.grid(True, axis="x", which="both", alpha=0.3)
    comps = ["normal", "rolling", "side"]
    for k, (cname, col) in enumerate(zip(comps, ["tab:blue", "tab:green", "tab:red"])):
        v = [abs(d["cells"].get(1.0, {}).get("err_force", [0, 0, 0])[k]) * 100 for d in summary]
        ax_e.barh(y + (k - 1) * 0.27, v, 0.27, label=cname, color=col)
    ax_e.plot([max(abs(x) for x in d["oracle"]["err"]) * 100 if d.get("oracle") else np.nan for d in summary],
              y, "kx", label="fast − oracle, worst comp.")
    ax_e.axvline(2.0, color="k", ls="--", lw=1, label="issue: 2 % at 1 mm")
    ax_e.set_yticks(y)
    ax_e.set_yticklabels(names, fontsize=8)
    ax_e.invert_yaxis()
    ax_e.set_xlabel(f"|1 mm − {summary[0]['ref_cell_mm']:g} mm| per component, % of the fresh cut's F_N")
    ax_e.set_title("error per scene and component (1 mm cells)", fontsize=11)
    ax_e.legend(fontsize=8)
    ax_e.grid(True, axis="x", alpha=0.3)


def scene_markdown(summary, data, L, offsets=()):
    fn = data["csm"]["normal"]
    if not summary:
        return
    ref_cell = summary[0]["ref_cell_mm"]
    L.append("## The cutterhead's scenes, per force component\n")
    L.append(
        "The scenes of `src/scenes.rs` (`kerf::scenes`, the same the contact-law tests use): "
        "the disc rolls free at 1 m/s, spinning about its own axle, in 1 ms steps, its lowest "
        "point 3.8 mm below the flat face, and the cutter-frame outputs are averaged over "
        "0.06–0.14 m of the measured pass. **fresh straight**: one cut on a flat face. "
        "**tilted g**: the same cut with the disc rolled by g. **beside groove, d**: a second "
        "pass d beside a 3.8 mm groove cut first (a partial cut). **re-roll**: a second pass "
        "over the pass's own groove (straight, or a second lap of a curved track). **curved r, "
        "fresh lap**: one lap of an r-radius track on fresh rock. **gauge g, r**: a gauge cutter, rolled by g "
        "with its tip leaning away from the centre of an r-radius track, heading 30° to the grid on fresh rock "
        "(its side face shaves a thin wedge off the wall; docs/head.md, \"Gauge cutters on curved tracks\"). "
        "**own groove, r**: a centre disc's second lap of an r-radius track, 7.6 mm deep in the 3.8 mm "
        "groove of its first lap, as a cutterhead's centre disc re-enters its groove a revolution later "
        "(on a track this tight the disc's plane leaves its curved groove, and its rear scrubs the groove's "
        "wall; README, \"Centre discs in their own grooves\").\n"
    )
    L.append(
        f"Forces (the FMU's outputs, friction included) at the default 1 mm cells, and the error of each component against the same "
        f"scene at {ref_cell:g} mm cells (the converged reference), in % of the fresh cut's "
        f"normal force F_N = {fn / 1e3:.1f} kN (CSM closed form; moments in % of F_N·R = "
        f"{fn * R_DISC / 1e3:.2f} kN·m). The errors are signed (1 mm minus reference); no column "
        "is a norm of several components. **fast − oracle**: the cutting force (friction left "
        "out) of the fast contact minus the brute-force oracle's (`Model::contact_brute`, "
        "0.05 mm arc steps, 101 slices) at one pose inside the window, same 1 mm map, % of F_N. "
        "(The reference is converged in the cell size, not in the side-face rings: the face "
        "is cut into bands half a cell wide, at most 24 a face (`MAX_RINGS`), sampled by the "
        "outermost band's ring and one graded ring for every 3 others (`face_rings`), so at "
        "0.25 mm the gauge scene's 7.2 mm band of face gets 24 bands 0.3 mm wide rather than "
        "58. Against rings converged in their spacing (0.25 mm cells, bands 0.01 mm wide, "
        "`MAX_RINGS` = 240, a throwaway build; 2026-11-28) its reference moves by "
        "-0.05 / -0.02 / +0.07 kN (N / R / S), and the gauge row's 1 mm errors would read "
        "+0.02 / +0.05 / -0.12 % (M_x -0.10 %) instead (with a ring a band, before the "
        "grading: -0.00 / +0.04 / -0.13 %, M_x -0.12 %, against `MAX_RINGS` = 200).)\n"
    )
    coarse = sorted((c for c in summary[0]["cells"] if c != 1.0 and c != ref_cell), reverse=True)
    hdr = ("| scene | F_N | F_R | F_S [kN] | ΔF_N | ΔF_R | ΔF_S | ΔM_x | ΔM_y | ΔM_z [%] | "
           + "".join(f"worst @{c:g} mm | " for c in coarse)
           + "fast − oracle N / R / S [%] | W/V ÷ fresh |")
    L.append(hdr)
    L.append("|" + "---|" * (hdr.count("|") - 1))
    for d in summary:
        e = d["cells"].get(1.0)
        if not e:
            continue
        o = d.get("oracle")
        ws = [pct(d["cells"][c]["worst"]) if c in d["cells"] else "—" for c in coarse]
        L.append(
            f"| {d['scene']} | {e['force_kN'][0]:.2f} | {e['force_kN'][1]:.2f} | {e['force_kN'][2]:.2f} | "
            + " | ".join(sgn_pct(x) for x in e["err_force"]) + " | "
            + " | ".join(sgn_pct(x) for x in e["err_moment"]) + " | "
            + "".join(w + " | " for w in ws)
            + (" / ".join(sgn_pct(x) for x in o["err"]) if o else "—") + " | "
            + (f"{e['wv_vs_fresh']:.2f}" if e.get("wv_vs_fresh") and d["kind"] != "reroll" else "—")
            + " |"
        )
    L.append("")
    worst1 = max(d["cells"][1.0]["worst"] for d in summary if 1.0 in d["cells"])
    wname = max((d for d in summary if 1.0 in d["cells"]), key=lambda d: d["cells"][1.0]["worst"])["scene"]
    L.append(
        f"Worst component error at 1 mm: **{100 * worst1:.2f} %** of F_N ({wname}); the issue "
        "asks for 2 % at 1 mm and 0.5 % at 0.5 mm."
        + (
            f" Worst at 0.5 mm: {100 * max(d['cells'][0.5]['worst'] for d in summary if 0.5 in d['cells']):.2f} %."
            if all(0.5 in d["cells"] for d in summary) and ref_cell < 0.5 else ""
        )
        + " `W/V ÷ fresh` is the rolling work of the cutting force per volume of rock removed, "
          "against the fresh cut's (the issue asks for ±30 % where a pass removes at least 20 % "
          "of a fresh groove). Re-rolls remove (almost) nothing; there the normal force as a "
          "share of the fresh cut's is the measure (issue: ≤ 5 %): "
        + ", ".join(
            f"{d['scene']} {100 * d['cells'][1.0]['normal_vs_fresh']:.1f} %"
            for d in summary if d["kind"] == "reroll" and d["cells"].get(1.0, {}).get("normal_vs_fresh") is not None
        )
        + ".\n"
    )
    cut = [o for o in offsets if o["measure"] == "cut"]
    if cut:
        o0 = cut[0]
        L.append(
            f"**Beside a groove at every offset** ({o0['from_mm']:g}–{o0['to_mm']:g} mm in "
            f"{o0['offsets']} offsets, `cargo run --release --example offset_convergence`; the "
            "worst cutting-force component against 0.25 mm cells, % of F_N): "
            + "; ".join(
                f"{o['cell_mm']:g} mm cells worst {o['worst_pct']:.2f} % (at {o['at_mm']:.1f} mm), "
                f"median {o['median_pct']:.2f} %, {o['over']} of {o['offsets']} offsets above the "
                f"issue's {o['target_pct']:g} %"
                for o in cut
            )
            + ". The table's beside-groove rows are three of these offsets. Where an older groove's wall (a one-cell "
            "ramp in the map) meets the tip's slices differs with the cell size, so the force "
            "steps with the offset by about 1 % of F_N at offsets that move with the cells: "
            + ("**not met** beside a groove." if any(o["over"] for o in cut) else "met.")
            + "\n"
        )

    # cost
    L.append("## Cost per scene\n")
    c0 = summary[0]["cost"]
    L.append(
        "Median µs per 1 ms step at 1 m/s over the measured window (80 steps), 1 mm cells, "
        f"median over {c0['rounds_core']} interleaved rounds of each round's median. **core**: "
        "`Model::commit` along the path + `Model::evaluate` (`kerf::scenes::roll`). **C host**: "
        "`host/kerf_host.c` replays the same passes through the FMU (the scene files written "
        "by `examples/speed-vs-error.rs --host-scenes`): fmi2SetReal of the 12 pose and "
        "velocity inputs, fmi2DoStep of 1 ms, fmi2GetReal of the forces, on a face set by "
        "the `rock.*` parameters. **÷ straight**: the median over the rounds of each round's "
        "ratio to the straight cut of that round (this machine switches between a fast and a "
        "slow state; a round's scenes run seconds apart). The issue's targets: every scene "
        "≤ 5 µs from the bare C host, and none more than 2x the straight cut.\n"
    )
    L.append("| scene | core µs | core ÷ straight | C host fmi2DoStep µs [IQR] | host ÷ straight | "
             "host SetReal+DoStep+GetReal µs | ≤ 5 µs | ≤ 2x straight |")
    L.append("|---|---|---|---|---|---|---|---|")

    def f1(x):
        return "—" if x is None else us(x)

    def rx(x):
        return "—" if x is None else f"{x:.2f}"

    met5 = met2 = True
    for d in summary:
        c = d["cost"]
        ref = c["host_dostep_us"] if c["host_dostep_us"] is not None else c["core_us"]
        ratio = c["host_dostep_us_vs_straight"] if c["host_dostep_us"] is not None else c["core_us_vs_straight"]
        ok5 = ref is not None and ref <= TARGET_US
        ok2 = ratio is not None and ratio <= TARGET_RATIO
        met5 &= ok5
        met2 &= ok2
        L.append(
            f"| {d['scene']} | {f1(c['core_us'])} | {rx(c['core_us_vs_straight'])} | "
            + (f"{f1(c['host_dostep_us'])} [{f1(c['host_dostep_p25'])}–{f1(c['host_dostep_p75'])}]"
               if c["host_dostep_us"] is not None else "—")
            + f" | {rx(c['host_dostep_us_vs_straight'])} | {f1(c['host_step_us'])} | "
            f"{'met' if ok5 else '**not met**'} | {'met' if ok2 else '**not met**'} |"
        )
    L.append("")
    L.append(
        f"Targets: ≤ {TARGET_US:g} µs on every scene **{'met' if met5 else 'not met'}**; "
        f"≤ {TARGET_RATIO:g}x the straight cut on every scene **{'met' if met2 else 'not met'}**. "
        "Timings are wall-clock on a shared 2-core machine; ratios between scenes of one "
        "round are steadier than the absolute figures.\n"
    )
    st = next((d for d in summary if d["kind"] == "fresh"), None)
    if st and st["cost"]["host_step_us"] and st["cost"]["core_us"]:
        ov = st["cost"]["host_step_us"] - st["cost"]["core_us"]
        hf = st["cost"]["host_mean_force_kN"]
        L.append(
            f"FMI layer on the straight cut: the host's whole step costs {ov:+.1f} µs against "
            f"the core's ({100 * ov / st['cost']['core_us']:+.0f} %; the two run in different "
            "processes a moment apart, so a few µs either way is noise). Mean forces the host "
            f"sees over the window: F_N {hf[0]:.2f}, F_R {hf[1]:.2f}, F_S {hf[2]:.2f} kN "
            f"(core at 1 mm: {st['cells'][1.0]['force_kN'][0]:.2f}, "
            f"{st['cells'][1.0]['force_kN'][1]:.2f}, {st['cells'][1.0]['force_kN'][2]:.2f}).\n"
        )


def main():
    rows_path, host_path, docs = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    # (optional) the offset sweep's summary, `offset_convergence --json`
    offsets = []
    if len(sys.argv) > 4 and Path(sys.argv[4]).exists():
        offsets = [json.loads(l) for l in Path(sys.argv[4]).read_text().splitlines() if l.strip()]
    data = json.loads(Path(rows_path).read_text())
    costs = []
    if host_path != "-" and Path(host_path).exists() and Path(host_path).stat().st_size:
        costs = [json.loads(l) for l in Path(host_path).read_text().splitlines() if l.strip()]
    summary = scene_summary(data, costs)
    rows = data["rows"]
    docs.mkdir(parents=True, exist_ok=True)

    kerf = [r for r in rows if r["model"] == "kerf"]
    base = [r for r in rows if r["model"] == "baseline"]
    default = next(r for r in rows if is_default(r))

    # ---------------- speed vs error plot
    panels = [
        ("worst of all six errors", worst),
        ("flat scene: worst of forces and volume", lambda r: max(r["err_normal"], r["err_rolling"], r["err_side"], r["err_volume"])),
        ("tilted 30° vs converged run (cost of the tilted cut)", lambda r: r["err_tilt"]),
        ("cut 10 mm beside a groove vs converged run", lambda r: r["err_groove"]),
    ]
    fig = plt.figure(figsize=(13, 16))
    top, bottom = fig.subfigures(2, 1, height_ratios=[2.15, 1])
    axes = top.subplots(2, 2)
    def short(r):
        if r["model"] == "baseline":
            t = f"{r['n_alpha']}x{r['n_y']}"
            if "mu = 0" in r["label"]:
                t += " mu=0"
            if r["cell_mm"] != 1.0:
                t += f" @{r['cell_mm']:g}mm"
            return "baseline " + t
        return r["label"].replace("_cells", "").replace("_slices", "")

    for k_panel, (ax, (title, fn)) in enumerate(zip(axes.flat, panels)):
        tilted = k_panel == 2
        cost_key = "us_tilt_median" if tilted else "us_median"
        pts = [(r[cost_key], fn(r), r) for r in rows if fn(r) > 0 and r.get(cost_key)]
        # the front over like-for-like evaluations (1 mm steps); longer
        # Co-Simulation steps are the host's choice and shown apart
        cand = [i for i, (_, _, r) in enumerate(pts) if r["model"] == "kerf" and r["step_mm"] == 1.0]
        sub = pareto([(pts[i][0], pts[i][1]) for i in cand])
        front = [cand[j] for j in sub]
        for c, e, r in pts:
            lo, hi = (c, c) if tilted else (r["us_p25"], r["us_p75"])
            if r["model"] == "baseline":
                style = dict(marker="s", color="tab:red", ms=8)
            elif r["group"] == "reference":
                style = dict(marker="D", color="tab:purple", ms=7)
            elif r["step_mm"] != 1.0:
                style = dict(marker="o", color="0.5", mfc="none", ms=6)
            else:
                style = dict(marker="o", color="tab:blue", ms=6)
            ax.errorbar([c], [e], xerr=[[c - lo], [hi - c]], capsize=2, lw=0.8, **style)
            if is_default(r):
                ax.plot([c], [e], marker="*", color="gold", ms=20, mec="k", zorder=5)
        fx = [pts[i][0] for i in front]
        fy = [pts[i][1] for i in front]
        ax.step(fx, fy, where="post", color="k", lw=1.2, ls="--", zorder=1)
        # label the front and the baselines, skipping points that sit on top
        # of one already labelled (the defaults first)
        placed = [(math.log10(c), math.log10(e)) for c, e, r in pts if is_default(r)]
        nb = 0
        for i in sorted(range(len(pts)), key=lambda i: pts[i][2]["model"] != "baseline"):
            c, e, r = pts[i]
            if is_default(r) or (i not in front and r["model"] != "baseline"):
                continue
            lc, le = math.log10(c), math.log10(e)
            if r["model"] != "baseline" and any(abs(lc - a) < 0.12 and abs(le - b) < 0.12 for a, b in placed):
                continue
            placed.append((lc, le))
            dy = 3
            if r["model"] == "baseline":
                dy = [3, -10, 12, -10, 3][nb % 5]
                nb += 1
            ax.annotate(short(r), (c, e), fontsize=7, xytext=(5, dy), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(
            "cost of the tilted cut [µs per mm] (median of one run)" if tilted
            else "cost [µs per mm of cut] (median; bars: interquartile range)"
        )
        ax.set_ylabel("relative error [-]")
        ax.set_title(title, fontsize=11)
        ax.grid(True, which="both", alpha=0.3)
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], marker="o", color="tab:blue", ls="", label="kerf setting (1 mm steps)"),
        Line2D([], [], marker="o", color="0.5", mfc="none", ls="", label="kerf, 0.1-50 mm steps"),
        Line2D([], [], marker="*", color="gold", mec="k", ms=14, ls="", label="kerf defaults"),
        Line2D([], [], marker="D", color="tab:purple", ls="", label="converged run (0.25 mm, finest)"),
        Line2D([], [], marker="s", color="tab:red", ls="", label="thesis-faithful baseline"),
        Line2D([], [], color="k", ls="--", label="Pareto front, 1 mm steps (labelled)"),
    ]
    top.legend(handles=handles, loc="lower center", ncol=3, fontsize=9)
    if summary:
        scene_plots(summary, bottom.subplots(1, 2))
    top.suptitle(
        "kerf: error against cost per evaluation (reference scene R 0.2159 m, p 3.8 mm, 1 m/s; "
        "face 0.8 m x 0.2 m)",
        fontsize=12,
    )
    top.subplots_adjust(left=0.08, right=0.97, top=0.93, bottom=0.12, hspace=0.3, wspace=0.25)
    bottom.subplots_adjust(left=0.17, right=0.97, top=0.9, bottom=0.14, wspace=0.45)
    fig.savefig(docs / "speed-vs-error.png", dpi=110)
    plt.close(fig)

    # ---------------- convergence plot
    cells = sorted(
        [r for r in kerf if r["group"] in ("cell", "defaults")], key=lambda r: -r["cell_mm"]
    )
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(16, 6.5))
    orders = {}
    for key, name, mk in [
        ("err_volume", "removed volume vs analytic groove", "o"),
        ("err_tilt", "tilted 30° cut vs converged run", "s"),
        ("err_groove", "cut beside a groove vs converged run", "^"),
    ]:
        h = np.array([r["cell_mm"] for r in cells])
        e = np.array([r[key] for r in cells])
        ok = e > 0
        label = name
        # observed order from the coarse end (4 .. 0.5 mm): the 0.25 mm runs
        # differ from the converged run only in their other settings
        fit = ok & (h >= 0.5)
        if fit.sum() >= 3 and e[fit].max() > 1e-9:
            k, _ = np.polyfit(np.log(h[fit]), np.log(e[fit]), 1)
            orders[key] = k
            label += f" (observed order {k:.1f})"
        ax.loglog(h[ok], e[ok], marker=mk, label=label)
    # the elastic layer left under the rim is a volume-error floor
    floor = default.get("elastic_depth_um", 2.0) * 1e-6 * 0.013 / data["csm"]["groove_area"]
    ax.axhline(floor, color="tab:blue", lw=0.8, ls="-.",
               label=f"elastic layer ({default.get('elastic_depth_um', 2.0):g} µm x T) / groove area")
    hh = np.array([4, 0.25])
    ax.loglog(hh, 0.02 * (hh / 4) ** 1, "k:", lw=0.8, label="slope 1")
    ax.loglog(hh, 0.02 * (hh / 4) ** 2, "k--", lw=0.8, label="slope 2")
    ax.invert_xaxis()
    ax.set_xticks([4, 2, 1, 0.5, 0.25])
    ax.set_xticklabels(["4", "2", "1", "0.5", "0.25"])
    ax.minorticks_off()
    fn_max = max(r["err_normal"] for r in cells)
    ax.text(0.02, 0.02, f"flat-face F_N, F_R vs CSM: exact to round-off at every cell size (<= {fn_max:.0e})",
            transform=ax.transAxes, fontsize=8)
    ax.set_xlabel("cell size [mm] (other numerics at their defaults)")
    ax.set_ylabel("relative error [-]")
    ax.set_title("settings table: convergence with cell size (1 mm steps)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=9)
    # the cutterhead's scenes: worst component against the finest run
    markers = "osD^v<>ph*X"
    for k, d in enumerate(summary):
        cs = sorted(c for c in d["cells"] if c != d["ref_cell_mm"])
        e = [max(d["cells"][c]["worst"], 1e-6) for c in cs]
        if cs:
            ax2.loglog(cs, e, marker=markers[k % len(markers)], label=d["scene"], lw=1)
    if summary:
        ax2.axhline(0.02, color="k", ls="--", lw=0.8)
        ax2.axhline(0.005, color="k", ls=":", lw=0.8)
        ax2.text(2.0, 0.021, "issue: 2 % at 1 mm", fontsize=8)
        ax2.text(2.0, 0.0052, "0.5 % at 0.5 mm", fontsize=8)
        ax2.invert_xaxis()
        ax2.set_xticks([2, 1, 0.5])
        ax2.set_xticklabels(["2", "1", "0.5"])
        ax2.minorticks_off()
        ax2.set_xlabel(f"cell size [mm] (against {summary[0]['ref_cell_mm']:g} mm)")
        ax2.set_ylabel("worst of F_N, F_R, F_S, M (÷ F_N, ÷ F_N R) [-]")
        ax2.set_title("cutterhead scenes: worst force-component error with cell size")
        ax2.grid(True, which="both", alpha=0.3)
        ax2.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(docs / "convergence.png", dpi=110)
    plt.close(fig)

    # ---------------- markdown
    L = []
    L.append("# Speed against error\n")
    L.append(
        "Generated by `scripts/speed-vs-error` (do not edit by hand): it builds in release, runs "
        "`examples/speed-vs-error.rs` and the bare C host `host/kerf_host.c`, then "
        "`tools/speed_vs_error/report.py`. Raw rows: `docs/speed-vs-error.json`. "
        f"This run: {data['reps']} timing rounds (each runs every row once), "
        f"{data['wall_s']:.0f} s of measurements. "
        "Timings are wall-clock on a shared 2-core machine: read the spread, not the digits; "
        "they are never a pass/fail test.\n"
    )
    scene_markdown(summary, data, L, offsets)
    L.append("## Numerical settings: scenes and measures\n")
    L.append(
        "Reference cutter and rock of thesis Table 2 (R = 0.2159 m, T = 13 mm, r = 12.7 mm, "
        "UCS 158 MPa, BTS 6.78 MPa, S = 51 mm, C = 2.12), p = 3.8 mm, 1 m/s, wy = v/R, on a "
        "flat 0.8 m x 0.2 m face.\n"
    )
    L.append(
        "* **F_N, F_R, F_S**: a 0.3 m cut along y = 0, outputs averaged over the steady middle "
        "x in [0.1, 0.25] m, against the CSM closed form "
        f"(F_N = {data['csm']['normal']:.1f} N, F_R = {data['csm']['rolling']:.1f} N; the side "
        "force against F_N).\n"
        "* **volume**: rock removed while the centre crossed that window against the analytic "
        "groove (integral over |y| <= T/2 of max(0, p - (r - sqrt(r^2 - y^2)))) times its length.\n"
        "* **tilted**: the cutter rolled 30 deg, its lowest point 3.8 mm deep, a 0.2 m cut; "
        "**beside groove**: a 0.2 m cut at y = 10 mm after one along y = 0. Both as the largest "
        "difference of one cutter-frame force component (normal, rolling, side) over the CSM "
        "normal force, the components averaged over "
        "x in [0.08, 0.18] m, against a converged run of the same scene (0.25 mm cells, "
        "17 tip slices, arc step 1 cell, sweep step 0.5 mm). **tilted µs/mm**: the cost of the tilted scene, median of one run. "
        "These two scenes are older than `kerf::scenes` (another face, window and reference, "
        "and they also run the baseline and other step lengths): they rank the numerical "
        "settings; the scene tables above give each scene's figures.\n"
        "* **µs/mm**: wall time of one `advance` plus one `evaluate`, per mm of travel (one "
        "evaluation at the default 1 mm step), over the flat window's steps of all repeats: "
        "median [interquartile range]. **µs/call**: the same per call (differs for other step "
        "lengths). **memory**: `HeightMap::memory_bytes()` after the flat cut.\n"
        "* **baseline**: `src/core/baseline.rs`, the thesis's algorithms on the same height map "
        "and CSM law: rim points on a fixed n_alpha x n_y grid over the lower half of the rim, "
        "eq. 54 penetration, mean normal of the distinct penetrated triangles, the friction of "
        "eqs 55-60 at the point f_p, and the rock cut at the end of each step by a loop over "
        "every node of the face (ch. 8).\n"
    )
    L.append("## Table\n")
    L.append(
        "| setting | cell | tip slices | arc step [cells] | sweep step | CS step | F_N | F_R | "
        "F_S | volume | tilted | beside groove | µs/mm median [IQR] | µs/call | tilted µs/mm | memory |"
    )
    L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        b = r["model"] == "baseline"
        name = setting_text(r)
        if is_default(r):
            name = "**defaults (chosen)**"
        L.append(
            "| {} | {} mm | {} | {} | {} | {} mm | {} | {} | {} | {} | {} | {} | {} [{}–{}] | {} | {} | {} |".format(
                name,
                r["cell_mm"],
                "—" if b else r["tip_slices"],
                "—" if b else f"{r['arc_step_cells']:g}",
                "cut at step end" if b else f"{r['sweep_step_mm']:g} mm",
                f"{r['step_mm']:g}",
                pct(r["err_normal"]),
                pct(r["err_rolling"]),
                pct(r["err_side"]),
                pct(r["err_volume"]),
                pct(r["err_tilt"]),
                pct(r["err_groove"]),
                us(r["us_median"]),
                us(r["us_p25"]),
                us(r["us_p75"]),
                us(r["us_per_call"]),
                us(r["us_tilt_median"]) if r.get("us_tilt_median") else "—",
                mem(r["memory_bytes"]),
            )
        )
    L.append("")

    # why the defaults
    by = {r["label"]: r for r in rows}

    def rel_cost(label):
        return by[label]["us_median"] / default["us_median"]

    def errs(label, keys=("err_tilt", "err_groove")):
        return " / ".join(pct(by[label][k]) for k in keys)

    L.append("## The defaults\n")
    same = [r for r in rows if is_default(r) or r["group"] == "p_reg"]
    if len(same) > 1:
        lo_, hi_ = min(r["us_median"] for r in same), max(r["us_median"] for r in same)
        iqr = max((r["us_p75"] - r["us_p25"]) / r["us_median"] for r in same)
        band = max(hi_ / lo_ - 1, iqr)
        L.append(
            "*Noise:* rows whose flat cut runs the very same numerics (the defaults and the two "
            f"p_reg rows) give medians from {us(lo_)} to {us(hi_)} µs/mm with interquartile "
            f"ranges up to {100 * iqr:.0f} % of the median; cost differences smaller than about "
            f"{100 * band:.0f} % are not significant on this machine.\n"
        )
    L.append(
        "**Chosen defaults: 1 mm cells, 9 tip slices, arc step 4 cells, sweep step 1 mm, "
        "elastic depth 2 µm, p_reg 50 µm** — each sits at the knee of its own trade: it is "
        "the cheapest value whose error is not clearly worse than the finer ones "
        f"(worst of the six errors {pct(worst(default))}, {us(default['us_median'])} µs per mm). "
        "Column by column (tilted / beside-groove errors unless said otherwise, cost relative "
        "to the defaults):\n"
    )
    notes = []
    if all(l in by for l in ("cell 2 mm", "cell 0.5 mm", "cell 0.25 mm")):
        notes.append(
            f"* cells: 2 mm costs {rel_cost('cell 2 mm'):.2f}x but gives {errs('cell 2 mm')} and "
            f"{pct(by['cell 2 mm']['err_volume'])} volume error (defaults {errs('defaults')}, "
            f"{pct(default['err_volume'])}); 0.5 mm costs {rel_cost('cell 0.5 mm'):.1f}x for "
            f"{errs('cell 0.5 mm')}, 0.25 mm {rel_cost('cell 0.25 mm'):.1f}x for {errs('cell 0.25 mm')}."
        )
    if all(l in by for l in ("tip_slices 3", "tip_slices 5", "tip_slices 17")):
        notes.append(
            f"* tip slices: 3 costs {rel_cost('tip_slices 3'):.2f}x for {errs('tip_slices 3')}, "
            f"5 costs {rel_cost('tip_slices 5'):.2f}x for {errs('tip_slices 5')}, 17 costs "
            f"{rel_cost('tip_slices 17'):.2f}x for {errs('tip_slices 17')}: at 1 mm cells the grid, "
            "not the slicing, limits past 9."
        )
    if all(l in by for l in ("arc_step_cells 1", "arc_step_cells 8")):
        notes.append(
            f"* arc step: 1 to 8 cells give the same errors in these scenes; 1 cell costs "
            f"{rel_cost('arc_step_cells 1'):.2f}x, 2 cells {rel_cost('arc_step_cells 2'):.2f}x, "
            f"8 cells {rel_cost('arc_step_cells 8'):.2f}x. 4 keeps a margin for contact features "
            "narrower than the step (which the walk can step over) where the saving beyond it "
            "is small."
        )
    sw = [l for l in by if l.startswith("step 50 mm, sweep_step")]
    if len(sw) == 4:
        notes.append(
            "* sweep step (at 50 mm Co-Simulation steps): 0.1 mm costs "
            f"{by['step 50 mm, sweep_step 0.1 mm']['us_median'] / by['step 50 mm, sweep_step 1 mm']['us_median']:.0f}x "
            "the 1 mm sweep with the same errors; 10 mm leaves scallops "
            f"({pct(by['step 50 mm, sweep_step 10 mm']['err_volume'])} volume error), 50 mm "
            f"{pct(by['step 50 mm, sweep_step 50 mm']['err_volume'])} volume and "
            f"{pct(by['step 50 mm, sweep_step 50 mm']['err_rolling'])} rolling force. 1 mm leaves "
            "scallops of 0.6 µm, inside the 2 µm elastic layer."
        )
    if all(l in by for l in ("step 0.1 mm", "step 10 mm", "step 50 mm")):
        notes.append(
            "* Co-Simulation step (the host's choice, not a default): the swept cut makes the "
            f"errors independent of it (0.1 mm: {errs('step 0.1 mm')}, 50 mm: {errs('step 50 mm')}); "
            f"per mm of travel a 50 mm step costs {rel_cost('step 50 mm'):.2f}x a 1 mm step and "
            f"a 0.1 mm step {rel_cost('step 0.1 mm'):.1f}x (one contact evaluation per call)."
        )
    if all(l in by for l in ("elastic_depth 0.5 um", "elastic_depth 10 um", "elastic_depth 50 um")):
        notes.append(
            "* elastic depth: the layer is rock left standing under the rim; volume error "
            f"0.5 µm {pct(by['elastic_depth 0.5 um']['err_volume'])}, 2 µm {pct(default['err_volume'])}, "
            f"10 µm {pct(by['elastic_depth 10 um']['err_volume'])}, 50 µm "
            f"{pct(by['elastic_depth 50 um']['err_volume'])}; no cost effect. 2 µm lies above "
            "the 0.6 µm scallops of the 1 mm sweep (so a cutter at rest keeps touching its "
            "groove) and keeps the volume error at its smallest here."
        )
    if all(l in by for l in ("p_reg 10 um", "p_reg 200 um")):
        notes.append(
            "* p_reg only shapes the force below 50 µm of penetration (first touch, lift-off): "
            "no column here moves with it; it is chosen for the smoothness of the force at first "
            "touch, which these steady scenes do not measure."
        )
    L.extend(notes)
    L.append("")
    cand = [
        r for r in kerf
        if r is not default and r["group"] not in ("reference", "step", "sweep_step")
        and r["step_mm"] == 1.0
    ]
    faster_as_good = [
        r for r in cand
        if r["us_median"] < 0.9 * default["us_median"]
        and all(r[k] <= default[k] * 1.05 + 1e-12 for k, _ in METRICS)
    ]
    if faster_as_good:
        L.append(
            "Settings at 1 mm steps more than 10 % faster than the defaults with no error worse "
            "by more than 5 %: "
            + ", ".join(f"{r['label']} ({us(r['us_median'])} µs/mm)" for r in faster_as_good)
            + ".\n"
        )
    else:
        L.append(
            "No setting at 1 mm steps is more than 10 % faster than the defaults without "
            "some error more than 5 % worse: the data do not call for other defaults."
            + (
                f" The closest, 5 tip slices with an 8-cell arc step, saves "
                f"{100 * (1 - rel_cost('tip 5, arc 8')):.0f} % of the cost for "
                f"{errs('tip 5, arc 8')} (defaults {errs('defaults')})."
                if "tip 5, arc 8" in by and rel_cost("tip 5, arc 8") < 1 else ""
            )
            + "\n"
        )
    L.append(
        "The dense memory a thesis-style matrix would need is 8 bytes a node (and as much "
        "again for the temporary copy); `memory` above is the tiled map's, which both models "
        "here share.\n"
    )

    # baseline comparison
    L.append("## Against the thesis-faithful baseline\n")
    for bsl in base:
        better = [
            r for r in kerf
            if r["group"] != "reference" and r["step_mm"] == 1.0
            and all(r[k] <= bsl[k] for k, _ in METRICS)
        ]
        if better:
            fast = min(better, key=lambda r: r["us_median"])
            L.append(
                f"* {setting_text(bsl)}: {us(bsl['us_median'])} µs/mm, worst error "
                f"{pct(worst(bsl))}. The fastest kerf setting at the same 1 mm steps with equal or "
                f"better accuracy in every column is *{fast['label']}* at {us(fast['us_median'])} µs/mm: "
                f"**{bsl['us_median'] / fast['us_median']:.0f}x faster**; the defaults are "
                f"{bsl['us_median'] / default['us_median']:.0f}x faster."
            )
        else:
            L.append(f"* {setting_text(bsl)}: no kerf setting is as accurate in every column.")
    L.append(
        "\nThe baseline's rolling force is far off although its penetration is close to 3.8 mm: "
        "the mean triangle normal leans less than phi/2 behind the vertical, and the friction "
        "of eqs 55-60, read at f_p (part-way up the contact arc, where a rolling rim slips "
        "against the rock), pushes the cutter forward (the mu = 0 row separates the two). Its "
        "tilted and grooved errors come from searching only the lower half of the rim and "
        "ignoring the side faces (thesis limitation 10.1), and from the penetrated plane.\n"
    )

    # the tilted cut's cost
    dt = default.get("us_tilt_median")
    bt = [r for r in base if r.get("us_tilt_median")]
    if dt and bt:
        cheapest = min(bt, key=lambda r: r["us_tilt_median"])
        L.append("## The tilted cut\n")
        L.append(
            f"At the defaults the tilted cut (roll 30°) costs {us(dt)} µs per mm, "
            f"{dt / default['us_median']:.0f}x the upright cut: the disc's lower boundary over "
            "a tilted axle needs an iterative solve per node, and the side face takes part in "
            "the contact. The cheapest baseline costs "
            f"{us(cheapest['us_tilt_median'])} µs/mm on the same scene "
            f"({setting_text(cheapest)}, {pct(cheapest['err_tilt'])} error against kerf's "
            f"{pct(default['err_tilt'])}); the baseline's whole-face node loop first tests "
            "whether a node lies inside the disc (cutter-frame coordinates: |y| <= T/2 and "
            "x^2 + z^2 < R(y)^2), which is exact for nodes below the disc's top "
            "(`baseline::tests` checks it against brute force at 0, 30 and 60 deg of roll) and "
            "leaves the iterative solve to the nodes that are cut.\n"
        )

    # faces
    L.append("## Cost against the size of the face\n")
    L.append(
        "Reference cut at 1 mm cells on a square face (x from -0.25 m), kerf defaults and the "
        "baseline (361 x 9), median [IQR] µs per 1 mm evaluation after a 50 mm lead-in "
        "(`benches/step.rs` measures the same with criterion):\n"
    )
    L.append("| model | face | nodes | µs/eval median [IQR] |")
    L.append("|---|---|---|---|")
    fc = {}
    for f in data["faces"]:
        side = math.sqrt(f["face_m2"])
        n = int(round(side / 1e-3)) + 1
        fc[(f["model"], f["face_m2"])] = f["us_median"]
        L.append(
            f"| {f['model']} | {f['face_m2']:g} m² | {n * n:,} | {us(f['us_median'])} "
            f"[{us(f['us_p25'])}–{us(f['us_p75'])}] |"
        )
    k1, k100 = fc.get(("kerf", 1.0)), fc.get(("kerf", 100.0))
    b1 = next((v for (m, a), v in fc.items() if m.startswith("baseline") and a == 1.0), None)
    b100 = next((v for (m, a), v in fc.items() if m.startswith("baseline") and a == 100.0), None)
    if k1 and k100:
        L.append(
            f"\nkerf: 100 m² costs **{k100 / k1:.2f}x** the 1 m² face (flat in the face size: "
            "only tiles under the disc are touched)"
            + (f"; the baseline: **{b100 / b1:.0f}x** (it visits every node every step)." if b1 and b100 else ".")
            + "\n"
        )
    if b100:
        ns = b100 * 1e3 / 10001**2
        L.append(
            f"The baseline's node loop costs about {ns:.1f} ns per node and step on the 100 m² face "
            "(tile lookup, transform into the cutter frame, shadow test). The Fortran's dense "
            "matrix would be cheaper per node, perhaps by 2-3x, and would also copy the whole "
            "matrix into the temporary one every step; either way the cost stays linear in the "
            "face.\n"
        )

    L.append("## Plots\n")
    L.append("![speed vs error](speed-vs-error.png)\n")
    L.append("![convergence](convergence.png)\n")
    if orders:
        L.append(
            "Observed convergence orders with cell size (least-squares slope over 4 to 0.5 mm; "
            "the curves are not monotone, so read them as indicative): "
            + ", ".join(f"{k[4:]} {v:.1f}" for k, v in orders.items())
            + ". The volume error stops falling at about 1 mm cells: the rock left standing in "
            "the elastic layer (elastic depth times the tip width, against the groove "
            "cross-section) is a floor of the same size. The flat-face forces are exact to round-off at every cell size (the contact "
            "finds the exact penetration of a rim on a flat face), so only the volume, the "
            "tilted cut and the cut beside a groove show the grid.\n"
        )
    (docs / "speed-vs-error.md").write_text("\n".join(L) + "\n")
    out = dict(data)
    out["scene_summary"] = summary
    out["costs"] = costs
    if offsets:
        out["offsets"] = offsets
    (docs / "speed-vs-error.json").write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {docs}/speed-vs-error.md, .json, .png and convergence.png")


if __name__ == "__main__":
    main()

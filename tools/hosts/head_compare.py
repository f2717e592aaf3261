#!/usr/bin/env python3
"""Compare head FMU Co-Simulation results of several hosts.

usage: head_compare.py [--tol REL] LABEL=FILE.csv ...   (the first one is the reference)
Reads `time` and the head totals (thrust, torque, Fx ... Mz, excavatedVolume,
cuttingEnergy; column names may be quoted or prefixed as "head.thrust",
"head::thrust"); at repeated time points the last row wins. Prints per host:
points, end time, thrust and torque at the end and their means over the run,
excavatedVolume and cuttingEnergy at the end, and the largest difference to
the reference at common time points, relative to the reference's largest
|value| of that column's group (forces thrust Fx Fy Fz; moments torque Mx My
Mz; excavatedVolume; cuttingEnergy), so that a small component such as Fx is
judged against the load it is part of. Exit status 1 if a host disagrees by more than REL
(default 1e-9) in any compared column, or stops early.
"""
import csv
import sys

COLS = ["thrust", "torque", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "excavatedVolume", "cuttingEnergy"]


def load(path):
    with open(path, newline="") as f:
        rd = csv.reader(f)
        head = [h.strip().strip('"') for h in next(rd)]

        def find(name):
            for i, h in enumerate(head):
                if h == name or h.endswith("." + name) and "[" not in h or h.endswith("::" + name):
                    return i
            return None

        it = find("time")
        it = 0 if it is None else it
        idx = {c: find(c) for c in COLS}
        data = {}
        for row in rd:
            try:
                t = float(row[it])
            except (ValueError, IndexError):
                continue
            vals = {}
            for c, i in idx.items():
                try:
                    vals[c] = float(row[i]) if i is not None else float("nan")
                except (ValueError, IndexError):
                    vals[c] = float("nan")
            data[round(t, 9)] = vals
    return data


def main(argv):
    tol = 1e-9
    if argv and argv[0] == "--tol":
        tol = float(argv[1])
        argv = argv[2:]
    runs = []
    for a in argv:
        label, path = a.split("=", 1)
        try:
            runs.append((label, load(path)))
        except Exception as e:  # noqa
            print(f"{label:26s} cannot read {path}: {e}")
    if not runs:
        return 1
    ref_label, ref = runs[0]
    rts = sorted(ref)
    groups = [["thrust", "Fx", "Fy", "Fz"], ["torque", "Mx", "My", "Mz"], ["excavatedVolume"], ["cuttingEnergy"]]
    scale = {}
    for g in groups:
        s = max((abs(ref[t][c]) for t in rts for c in g), default=0.0) or 1.0
        scale.update({c: s for c in g})
    bad = 0
    print(f"{'host/interface':26s} {'points':>6s} {'t_end':>6s} {'thrust_end[N]':>14s} {'torque_end[Nm]':>14s} "
          f"{'thrust_mean':>12s} {'torque_mean':>12s} {'excavatedVol[m3]':>16s} {'cuttingEnergy[J]':>16s}  "
          f"max rel diff vs {ref_label}: thrust torque (worst column) [common t]")
    for label, d in runs:
        ts = sorted(d)
        last = d[ts[-1]]
        mth = sum(d[t]["thrust"] for t in ts) / len(ts)
        mtq = sum(d[t]["torque"] for t in ts) / len(ts)
        common = [t for t in ts if t in ref]
        rel = {}
        for c in COLS:
            rel[c] = max((abs(d[t][c] - ref[t][c]) / scale[c] for t in common), default=float("nan"))
        worst = max(COLS, key=lambda c: -1 if rel[c] != rel[c] else rel[c])
        ok = len(common) > 0 and all(rel[c] <= tol for c in COLS) and abs(ts[-1] - rts[-1]) < 1e-9
        bad += not ok
        print(f"{label:26s} {len(ts):6d} {ts[-1]:6.3f} {last['thrust']:14.6f} {last['torque']:14.6f} "
              f"{mth:12.3f} {mtq:12.3f} {last['excavatedVolume']:16.9e} {last['cuttingEnergy']:16.6f}  "
              f"{rel['thrust']:.2e} {rel['torque']:.2e} ({worst} {rel[worst]:.2e}) [{len(common)}]"
              + ("" if ok else "   <-- differs"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

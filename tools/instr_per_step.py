#!/usr/bin/env python3
"""Instructions a step under callgrind: the measure the README and docs/head.md
quote for speed changes (instruction counts do not depend on the machine's
load; wall time here does).

Build the examples first, with LTO as the FMU is built:
    cargo build --release --example scene_cost --example head_cost

    tools/instr_per_step.py scene straight "beside 2" "gauge"
        the measured pass of each `kerf::scenes` scene alone
        (`--toggle-collect='*measured_pass*'`, 151 commits of 1 mm): the
        whole pass per step, and commit + evaluation per step (the inclusive
        cost of `disc::book_end` and `Disc::cut_at`, what a host's step pays;
        the pass also finds the contact again for the report's cutting force)
    tools/instr_per_step.py head [--fast] [--upright | --tilted] [--split] [--sweep-step S] [--ring-step X]
        the reference head from the steady start at 1 kHz on one thread:
        (12 steps - 2 steps) / 10; --fast at 2 mm cells and sweep steps;
        --upright / --tilted: its upright discs alone, or its tilted gauge
        discs alone (a layout written for the run), to split the cost;
        --split: also the inclusive instructions a step of the contacts,
        the cuts' node walks and the cut windows (SPLIT; a part LTO inlined
        away reads "inlined": count it on a build without LTO, e.g.
        CARGO_PROFILE_RELEASE_LTO=false CARGO_PROFILE_RELEASE_DEBUG=true);
        --sweep-step S: numerics.sweepStep S [m] (the default 1e-3; --fast
        sets 2e-3 and 2 mm cells);
        --ring-step X: side-face bands X cells wide (numerics.ringStepCells;
        the gauge scene takes it third: `"gauge -60 4.83 X"`)

    --cache (with scene or head, before the other arguments): callgrind's
        cache and branch simulation as well (32 kB L1 for code and data, as
        this machine's AMD EPYC has, and its 512 kB L2 as the last level),
        with the misses a step: L1 code, L1 data read and write, L2 data
        read and write, and mispredicted branches; for the head also the
        five functions with the most L2 data read misses. A model of the
        caches, not the machine: where wall time goes that instruction
        counts cannot see (docs/speed-log.md, "Caches, measured").

Needs valgrind (callgrind_annotate). Takes about 20 s a scene, 2 min for the
head (--cache: some 1 and 20 min).
"""
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
STEPS = 150


# callgrind's cache and branch simulation (`--cache`): L1 code and data
# 32 kB, 8-way, and the 512 kB L2 of one core as the last level
CACHE_SIM = ["--cache-sim=yes", "--branch-sim=yes", "--I1=32768,8,64",
             "--D1=32768,8,64", "--LL=524288,8,64"]
# the misses `--cache` prints: (callgrind event, what it is)
MISSES = [("I1mr", "L1 code"), ("D1mr", "L1 read"), ("D1mw", "L1 write"),
          ("DLmr", "L2 read"), ("DLmw", "L2 write"), ("Bcm", "branches mispredicted")]
cache = False


def callgrind(args, out, toggle=None, env=None):
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"]
    if cache:
        cmd += CACHE_SIM
    if toggle:
        cmd.append(f"--toggle-collect={toggle}")
    subprocess.run(cmd + args, check=True, cwd=ROOT, env=env,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def annotate(out, inclusive=False, extra=()):
    args = ["callgrind_annotate", "--threshold=100", "--auto=no", *extra]
    if inclusive:
        args.append("--inclusive=yes")
    return subprocess.run(args + [out], capture_output=True, text=True, check=True).stdout


def total(text):
    """The instructions (the first event) of the PROGRAM TOTALS line."""
    m = re.search(r"^\s*([\d,]+) \(100\.0%\).*PROGRAM TOTALS", text, re.M)
    return int(m.group(1).replace(",", ""))


def events(text):
    """Every event's program total, from `annotate`'s text (`--cache`)."""
    names = re.search(r"Events shown:\s+(.*)", text).group(1).split()
    line = next(l for l in text.splitlines() if "PROGRAM TOTALS" in l)
    values = [int(v.replace(",", "")) for v in re.findall(r"([\d,]+) \(", line)]
    return dict(zip(names, values))


def misses_line(per_step):
    return "; ".join(f"{what} {per_step.get(ev, 0) / 1e3:.2f} k" for ev, what in MISSES)


def top_l2_reads(out):
    """Each function's L2 data read misses (exclusive)."""
    text = annotate(out, extra=["--show=DLmr", "--sort=DLmr"])
    rows = {}
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+) \(.*?\)\s+\S*?:(\S+)", line)
        if m and "PROGRAM" not in line:
            rows[m.group(2)] = rows.get(m.group(2), 0) + int(m.group(1).replace(",", ""))
    return rows


def step_cost(text):
    """Inclusive instructions of disc::book_end and Disc::cut_at, each
    function's own entry (`file:function [binary]`)."""
    n = 0
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+) \(.*\)\s+\S*src/core/disc\.rs:"
                     r"kerf::core::disc::(book_end|Disc::cut_at) \[", line)
        if m:
            n += int(m.group(1).replace(",", ""))
    return n


def scenes(names):
    binary = os.path.join(TARGET, "release", "examples", "scene_cost")
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            out = os.path.join(tmp, "cg.out")
            callgrind([binary] + name.split(), out, toggle="*measured_pass*")
            text = annotate(out, inclusive=True)
            print(f"{name}: pass {total(text) / STEPS / 1e3:.1f} k a step, "
                  f"commit + evaluation {step_cost(text) / STEPS / 1e3:.1f} k a step")
            if cache:
                ev = events(text)
                print(f"  misses a step of the pass: "
                      f"{misses_line({k: v / STEPS for k, v in ev.items()})}")


# The parts of a head's step `--split` reports: a name and the function
# whose inclusive cost is that part (the largest entry of the function,
# whichever source file callgrind credits).
SPLIT = [
    ("contacts", "contact_cutter_heightmap::contact"),
    ("cuts' node walks", "cut_cutter_heightmap::cut_patch"),
    ("cut windows", "cut_cutter_heightmap::node_window"),
]


def inclusive(text, function):
    """The largest inclusive count of `function` (`...::name`, the whole
    path after the crate) in `callgrind_annotate --inclusive=yes` output,
    or None where it does not appear."""
    best = None
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+) \(.*?\)\s+\S*?:kerf::core::(\S+?)( \[.*\])?$", line)
        if m and m.group(2) == function:
            v = int(m.group(1).replace(",", ""))
            best = v if best is None else max(best, v)
    return best


def head(fast, part=None, split=False, ring_step=None, sweep_step=None):
    binary = os.path.join(TARGET, "release", "examples", "head_cost")
    extra = ["2e-3", "2e-3"] if fast else []
    if sweep_step is not None or ring_step is not None:
        # head_cost's sweep step, cell and ring step, in that order
        extra = [sweep_step or ("2e-3" if fast else "1e-3"), "2e-3" if fast else "1e-3",
                 ring_step or "0.5"]
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    counts = {}
    parts = {}
    evs = {}
    tops = {}
    with tempfile.TemporaryDirectory() as tmp:
        layout = os.path.join(ROOT, "layouts", "reference-9.72m.json")
        if part:
            with open(layout) as f:
                lay = json.load(f)
            lay["cutters"] = [c for c in lay["cutters"]
                              if bool(c.get("tiltDeg", 0.0)) == (part == "tilted")]
            layout = os.path.join(tmp, "part.json")
            with open(layout, "w") as f:
                json.dump(lay, f)
        for n in (2, 12):
            out = os.path.join(tmp, f"cg.{n}")
            callgrind([binary, layout, "1e-3", str(n), "3", "0.006"] + extra, out, env=env)
            # (the totals line is the same in the inclusive listing: one
            # annotation a run serves both)
            text = annotate(out, inclusive=split)
            counts[n] = total(text)
            if split:
                parts[n] = {name: inclusive(text, f) for name, f in SPLIT}
            if cache:
                evs[n] = events(text)
                tops[n] = top_l2_reads(out)
    per = (counts[12] - counts[2]) / 10
    what = f", its {part} discs alone" if part else ""
    if sweep_step is not None:
        what += f", sweep step {sweep_step} m"
    if ring_step is not None:
        what += f", side-face bands {ring_step} cells wide"
    print(f"reference head{' (fast setting)' if fast else ''}{what}: {per / 1e6:.2f} M a step")
    if cache:
        print("  misses a step: " + misses_line({k: (evs[12][k] - evs[2].get(k, 0)) / 10
                                                  for k in evs[12]}))
        l2 = {f: (v - tops[2].get(f, 0)) / 10 for f, v in tops[12].items()}
        for f, v in sorted(l2.items(), key=lambda kv: -kv[1])[:5]:
            print(f"    L2 read misses {v / 1e3:.2f} k a step: {f}")
    for name, _ in SPLIT if split else []:
        a, b = parts[2][name], parts[12][name]
        if a is None or b is None:
            print(f"  {name}: inlined")
        else:
            v = (b - a) / 10
            print(f"  {name}: {v / 1e6:.2f} M a step ({100 * v / per:.0f} %)")


def main():
    global cache
    if "--cache" in sys.argv:
        cache = True
        sys.argv.remove("--cache")
    if len(sys.argv) >= 3 and sys.argv[1] == "scene":
        scenes(sys.argv[2:])
    elif len(sys.argv) >= 2 and sys.argv[1] == "head":
        part = next((a[2:] for a in sys.argv[2:] if a in ("--upright", "--tilted")), None)
        rest = sys.argv[2:]
        def opt(name):
            return rest[rest.index(name) + 1] if name in rest else None
        head("--fast" in rest, part, "--split" in rest, opt("--ring-step"), opt("--sweep-step"))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()

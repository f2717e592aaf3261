#!/usr/bin/env python3
"""Co-Simulation of a head FMU with PyFMI's default CS algorithm (FMICSAlg,
communication step h, ncp = stop/h): the columns of IN.csv are given to
simulate() as PyFMI's input object (linear interpolation, set before each
step); the head totals are written to OUT.csv. The FMU/FMIL log (log_level 4)
is printed at the end.

usage: pyfmi_head.py FMU IN.csv|- OUT.csv [stop=0.2] [h=1e-3] [NAME=VALUE ...] [--kind me|cs]
IN.csv "-": no inputs (the FMU's start values: the head stands still).
NAME=VALUE: start values (parameters) set with model.set before simulate().
--kind me: Model Exchange with PyFMI's default solver (CVode) instead.
"""
import csv
import os
import sys

import numpy as np
from pyfmi import load_fmu

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fmu_io import head_totals, read_inputs, run_args  # noqa: E402

args = sys.argv[1:]
kind = "CS"
if "--kind" in args:
    i = args.index("--kind")
    kind = args[i + 1].upper()
    del args[i:i + 2]
sys.argv[1:] = args
fmu, inp, out = sys.argv[1:4]
stop, h, starts = run_args(sys.argv[4:])
OUTS = head_totals(fmu)
names, rows_in = read_inputs(inp) if inp != "-" else ([], None)
model = load_fmu(fmu, kind=kind, log_level=4)
for k, v in starts.items():
    model.set(k, v)
opts = model.simulate_options()
opts["ncp"] = int(round(stop / h))
opts["result_handling"] = "memory"
if kind == "ME":
    opts["CVode_options"]["maxh"] = h
inp_obj = (names, np.array(rows_in)) if rows_in else None
res = model.simulate(start_time=0.0, final_time=stop, input=inp_obj, options=opts)
with open(out, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["time"] + OUTS)
    for row in zip(*([res["time"]] + [res[n] for n in OUTS])):
        w.writerow([float(v) for v in row])
print("FMU/FMIL log:")
for line in model.get_log():
    print("  ", line if isinstance(line, str) else " | ".join(str(x) for x in line))
print(f"wrote {out}: {len(res['time'])} rows")

#!/usr/bin/env python3
"""Co-Simulation of a head FMU with Ecos (PyPI ecospy), as
/work/shared/hosts/drivers/ecos_roll.py drives kerf.fmu: the inputs of IN.csv
are set before each step to their value at the start of the step; the head
totals are read after each step.

usage: ecos_head.py FMU IN.csv OUT.csv [stop=0.2] [h=1e-3] [NAME=VALUE ...]
NAME=VALUE: start values (parameters) set before sim.init().
"""
import csv
import os
import sys

from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fmu_io import head_totals, read_inputs, run_args, value_at  # noqa: E402

fmu, inp, out = sys.argv[1:4]
stop, h, starts = run_args(sys.argv[4:])
OUTS = head_totals(fmu)
names, rows_in = read_inputs(inp)

EcosLib.set_log_level("debug")
print("ecos library", EcosLib.version())
with EcosSimulationStructure() as ss:
    ss.add_model("head", fmu)
    with EcosSimulation(structure=ss, step_size=h) as sim:
        def setin(t):
            for n, v in zip(names, value_at(rows_in, t)):
                sim.set_real("head::" + n, v)

        for k, v in starts.items():
            sim.set_real("head::" + k, v)
        setin(0.0)
        sim.init()
        rows = []

        def record():
            rows.append([sim.get_time()] + [sim.get_real("head::" + n) for n in OUTS])

        record()
        for k in range(int(round(stop / h))):
            setin(k * h)
            sim.step()
            record()
        sim.terminate()
with open(out, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["time"] + OUTS)
    w.writerows(rows)
print("wrote", out, len(rows), "rows")

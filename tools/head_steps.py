"""Steps a head FMU through fmpy as tools/head_run.py does, and times the
parts of each step; small enough to run under a profiler.

    .venv/bin/python tools/head_steps.py target/fmu/reference_972.fmu [--steps 1000] [--cell 0.002]

Each step sets the head's motion (fmpy setReal), calls doStep of 1 ms and
reads every output `head_run.py` records with a raw fmi2GetReal into arrays
made once, then copies them into a numpy row. Prints the mean µs of each
part and the wall per machine second. Under callgrind with the threads kept
apart (docs/head.md, "Speed at 1 kHz"), the difference of two step counts
gives the work of a step on the calling thread and on the pool's:

    RAYON_NUM_THREADS=1 valgrind --tool=callgrind --separate-threads=yes \\
        .venv/bin/python tools/head_steps.py target/fmu/reference_972.fmu --steps 11 --cell 0.002
"""
import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import headhost as hh  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu")
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--cell", type=float, default=None,
                    help="height-map cell and sweep step [m] (default: the FMU's)")
    ap.add_argument("--h", type=float, default=1e-3, help="communication step [s]")
    a = ap.parse_args()

    fmu = hh.HeadFMU(a.fmu)
    f = fmu.steady_instance(a.cell)
    read = fmu.output_reader(f)
    n_out = len(fmu.names())
    w = 3 * 2 * math.pi / 60
    vz = -0.006 * w / (2 * math.pi)
    out = np.empty((a.steps, n_out))
    spent = np.zeros(4)
    t = 0.0
    t0 = time.perf_counter()
    for k in range(a.steps):
        p0 = time.perf_counter()
        fmu.set_motion(f, t, w, vz)
        p1 = time.perf_counter()
        f.doStep(currentCommunicationPoint=t, communicationStepSize=a.h)
        p2 = time.perf_counter()
        t += a.h
        values = read()
        p3 = time.perf_counter()
        out[k] = values
        p4 = time.perf_counter()
        spent += (p1 - p0, p2 - p1, p3 - p2, p4 - p3)
    wall = time.perf_counter() - t0
    us = spent / a.steps * 1e6
    print(f"{a.steps} steps of {a.h * 1e3:g} ms: {wall / (a.steps * a.h):.2f} s wall per machine "
          f"second; mean us a step: set motion {us[0]:.1f}, doStep {us[1]:.1f}, "
          f"fmi2GetReal of {n_out} outputs {us[2]:.1f}, copy {us[3]:.1f}")
    f.terminate()
    f.freeInstance()


if __name__ == "__main__":
    main()

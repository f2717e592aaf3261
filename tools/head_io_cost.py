"""What a host pays per step to read a head FMU's outputs through fmpy.

    .venv/bin/python tools/head_io_cost.py target/fmu/reference_972.fmu [--cell 0.002]

Times (medians of 5 rounds of 200 calls, on the steady face after one step)
fmpy's `getReal` of every output `tools/head_run.py` records, the raw
`fmi2GetReal` into ctypes arrays made once (what `HeadFMU.bore_cs` does), and
one set-motion + doStep of 1 ms. Figures in docs/head.md ("Speed at 1 kHz").
"""
import argparse
import math
import statistics
import sys
import time
from pathlib import Path


sys.path.insert(0, str(Path(__file__).resolve().parent))
import headhost as hh  # noqa: E402


def median_us(f, n=200, rounds=5):
    out = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        for _ in range(n):
            f()
        out.append((time.perf_counter() - t0) / n * 1e6)
    return statistics.median(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu")
    ap.add_argument("--cell", type=float, default=None, help="height-map cell [m] (default: the FMU's)")
    a = ap.parse_args()

    fmu = hh.HeadFMU(a.fmu)
    f = fmu.steady_instance(a.cell)
    vrs = [fmu.vr[k] for k in fmu.names()]
    w = 3 * 2 * math.pi / 60
    vz = -0.006 * w / (2 * math.pi)
    fmu.set_motion(f, 0.0, w, vz)
    f.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
    read = fmu.output_reader(f)

    print(f"{len(vrs)} outputs: fmpy getReal {median_us(lambda: f.getReal(vrs)):.1f} us, "
          f"raw fmi2GetReal {median_us(lambda: read().copy()):.1f} us per call")
    t = [1e-3]

    def step():
        fmu.set_motion(f, t[0], w, vz)
        f.doStep(currentCommunicationPoint=t[0], communicationStepSize=1e-3)
        t[0] += 1e-3

    print(f"set motion + doStep of 1 ms: {median_us(step, n=50):.0f} us")
    f.terminate()
    f.freeInstance()


if __name__ == "__main__":
    main()

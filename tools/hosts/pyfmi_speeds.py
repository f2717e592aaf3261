#!/usr/bin/env python3
"""kerf.fmu's rolling cut in PyFMI's Model Exchange at several speeds: x = v t,
vx = v, wy = v / R from rest on the default face, 0.5 s, 500 output points,
Assimulo's ExplicitEuler with h = 1 ms (or CVode with maxh = 1 ms). At 1 m/s
the events land on the 1 ms grid (`run-all.sh`'s roll); at other speeds they
fall between grid points. One line a speed: `ok` with the final excavated
volume and cutting energy, or the exception and the FMU's last log line.
Needs PyFMI (`../shared/hosts/build-pyfmi.sh`; run it with that venv's python).

usage: pyfmi_speeds.py FMU [--solver ExplicitEuler|CVode] [v ...]
       (default speeds: 0.3 0.4 ... 1.5 1.7 2.0 m/s)
"""
import sys

import numpy as np
from pyfmi import load_fmu

R = 0.2159


def roll(fmu, v, solver):
    model = load_fmu(fmu, kind="ME", log_level=4)
    t = np.linspace(0.0, 0.5, 51)
    table = np.column_stack([t, v * t, np.full_like(t, v), np.full_like(t, v / R)])
    opts = model.simulate_options()
    opts["ncp"] = 500
    opts["result_handling"] = "memory"
    opts["solver"] = solver
    if solver == "ExplicitEuler":
        opts["ExplicitEuler_options"]["h"] = 1e-3
    else:
        opts["CVode_options"]["maxh"] = 1e-3
    try:
        res = model.simulate(start_time=0.0, final_time=0.5,
                             input=(["x", "vx", "wy"], table), options=opts)
    except Exception as e:  # the host's own error: report it, go on
        log = model.get_log()
        return f"{e}; {log[-1] if log else ''}"
    return f"ok volume {float(res['excavatedVolume'][-1])!r} m3, energy {float(res['cuttingEnergy'][-1])!r} J"


def main():
    args = sys.argv[1:]
    if not args:
        sys.exit(__doc__)
    solver = "ExplicitEuler"
    if "--solver" in args:
        i = args.index("--solver")
        solver = args[i + 1]
        del args[i:i + 2]
    fmu, speeds = args[0], [float(v) for v in args[1:]]
    if not speeds:
        speeds = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.7, 2.0]
    for v in speeds:
        print(f"{v} m/s {solver}: {roll(fmu, v, solver)}", flush=True)


if __name__ == "__main__":
    main()

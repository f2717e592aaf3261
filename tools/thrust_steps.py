#!/usr/bin/env python3
"""A cutter driven by thrust, against the host's step: the thrust host of the
hard cases (tests/fmu/hard_cases_util.py, `thrust_host`: 50 kN on 100 kg,
m z'' = normalForce - thrust - c z', c = zeta times critical for the CSM law's
stiffness F/(2p), semi-implicit Euler at h, rolling at 1 m/s from rest on the
face) for 0.4 s, in both interfaces. One line a run: the steps out of contact
after the first touch, the mean depth over the last 0.1 s and its spread, and
the mean normal force there, against the CSM inverse of the thrust.

usage: .venv/bin/python tools/thrust_steps.py path/to/kerf.fmu
       .venv/bin/python tools/thrust_steps.py path/to/kerf.fmu --trace KIND H ZETA FROM TO
(--trace: one run's steps FROM to TO: depth, vertical speed, normal force)
"""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests", "fmu"))
import kerfhost as kh  # noqa: E402
import hard_cases_util as u  # noqa: E402

R = kh.REFERENCE["R"]
THRUST = 50e3
RUNS = [(1e-3, 0.3), (5e-4, 0.3), (2.5e-4, 0.3), (1e-3, 0.6), (1e-3, 1.0)]


def trace(fmu, kind, h, zeta, first, last):
    res = u.thrust_host(kind, fmu, THRUST, vx=1.0, n=last + 1, h=h, zeta=zeta)
    print("step  depth [mm]  vz [m/s]  F_N [kN]  inContact")
    for k in range(first, last + 1):
        print(f"{k:4d}  {(R - res['z'][k]) * 1e3:10.4f}  {res['vz'][k]:+8.3f}  "
              f"{res['normalForce'][k] / 1e3:8.2f}  {res['inContact'][k]:9.0f}")


def main():
    if len(sys.argv) == 8 and sys.argv[2] == "--trace":
        kind, h, zeta, first, last = sys.argv[3:]
        trace(kh.FMU(sys.argv[1]), kind, float(h), float(zeta), int(first), int(last))
        return
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    fmu = kh.FMU(sys.argv[1])
    p = u.csm_inverse(THRUST, "FN")
    print(f"CSM inverse of {THRUST / 1e3:.0f} kN rolling: {p * 1e3:.3f} mm")
    print("kind  h [ms]  zeta  steps out of contact  depth, last 0.1 s [mm]  spread [m]  F_N [kN]")
    for kind in ("CS", "ME"):
        for h, zeta in RUNS:
            res = u.thrust_host(kind, fmu, THRUST, vx=1.0, n=int(round(0.4 / h)), h=h, zeta=zeta)
            depth, contact = R - res["z"], res["inContact"]
            first = int(np.argmax(contact > 0))
            tail = slice(-int(round(0.1 / h)), None)
            print(f"{kind:4}  {h * 1e3:6.2f}  {zeta:4.1f}  {int(np.sum(contact[first:] != 1)):20d}  "
                  f"{depth[tail].mean() * 1e3:22.3f}  {np.ptp(depth[tail]):10.1e}  "
                  f"{res['normalForce'][tail].mean() / 1e3:8.2f}", flush=True)


if __name__ == "__main__":
    main()

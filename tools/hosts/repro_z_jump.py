#!/usr/bin/env python3
"""usage: repro_z_jump.py HEAD.fmu BORE.csv [STEP=127] [DISC=2] [DZ,DZ,...]

A head FMU's outputs after one Co-Simulation step of the bore scenario
(BORE.csv from make_head_csv.py; flat face, exact row values as inputs) when
the input z at the start of step STEP (1-based; it runs from (STEP-1)*h to
STEP*h) moves by dz, every step taken from the same FMU state
(fmi2GetFMUstate / fmi2SetFMUstate). Prints thrust, torque, excavatedVolume
and disc DISC's normalForce, rollingForce, sideForce, penetration and
contactAngle for each dz (default: 0, 1e-15, -1e-15, 1e-12 m).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fmu_io import cs_slave, read_inputs  # noqa: E402

fmu, incsv = sys.argv[1], sys.argv[2]
K = int(sys.argv[3]) if len(sys.argv) > 3 else 127
disc = int(sys.argv[4]) if len(sys.argv) > 4 else 2
DZ = [float(x) for x in sys.argv[5].split(",")] if len(sys.argv) > 5 else [0.0, 1e-15, -1e-15, 1e-12]
names, data = read_inputs(incsv)
f, vr = cs_slave(fmu, names, data)
h = data[1][0] - data[0][0]
iz = names.index("z")
for k in range(K - 1):
    f.setReal([vr[x] for x in names], data[k][1:])
    f.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
s = f.getFMUstate()
O = ["thrust", "torque", "excavatedVolume"] + [f"cutter[{disc}].{q}" for q in
                                                ("normalForce", "rollingForce", "sideForce", "penetration",
                                                 "contactAngle")]
for dz in DZ:
    f.setFMUstate(s)
    u = list(data[K - 1][1:])
    u[iz] += dz
    f.setReal([vr[x] for x in names], u)
    f.doStep(currentCommunicationPoint=(K - 1) * h, communicationStepSize=h)
    v = f.getReal([vr[o] for o in O])
    print(f"step {K} (t {(K - 1) * h:.3f} -> {K * h:.3f}), dz {dz:+.0e}, z {u[iz]!r:24s}: "
          + ", ".join(f"{o} {x:.9g}" for o, x in zip(O, v)))
f.freeFMUstate(s)
f.terminate()
f.freeInstance()

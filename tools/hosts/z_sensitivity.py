#!/usr/bin/env python3
"""How much a head FMU's outputs move when the pose input z moves by a
femtometre: along the bore scenario (Co-Simulation, make_head_csv.py's
inputs, exact row values), at every step the step is taken twice from the
same FMU state, once with z and once with z + dz; the largest change of
thrust, torque and of any disc's normalForce is reported, relative to the
value, with the step where it happens.

usage: z_sensitivity.py HEAD.fmu BORE.csv [dz=1e-15] [NAME=VALUE ...]
   or: z_sensitivity.py kerf.fmu roll.csv [dz]   (run-all.sh's rolling scenario)
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fmu_io import cs_slave, parse_starts, read_inputs  # noqa: E402

fmu, incsv = sys.argv[1:3]
dz = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-15
names, data = read_inputs(incsv)
f, vr = cs_slave(fmu, names, data, parse_starts(sys.argv[4:]))
n = sum(1 for k in vr if k.startswith("cutter[") and k.endswith(".normalForce"))
O = [x for x in ("thrust", "torque", "normalForce", "rollingForce") if x in vr] + \
    [f"cutter[{i + 1}].normalForce" for i in range(n)]
h = data[1][0] - data[0][0]
iz = names.index("z")
worst = np.zeros(len(O))
where = [0] * len(O)
nstep = len(data) - 1
for k in range(nstep):
    s = f.getFMUstate()
    u = list(data[k][1:])
    u2 = list(u)
    u2[iz] += dz
    f.setReal([vr[x] for x in names], u2)
    f.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
    b = np.array(f.getReal([vr[o] for o in O]))
    f.setFMUstate(s)
    f.freeFMUstate(s)
    f.setReal([vr[x] for x in names], u)
    f.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
    a = np.array(f.getReal([vr[o] for o in O]))
    rel = np.abs(b - a) / np.maximum(np.abs(a), 1e-300)
    for j in range(len(O)):
        if rel[j] > worst[j]:
            worst[j], where[j] = rel[j], k + 1
print(f"dz = {dz:g} m at the start of each of {nstep} steps; largest relative change of the output after the step:")
for j, o in enumerate(O):
    print(f"  {o:24s} {worst[j]:.2e}  (step {where[j]})")
f.terminate()
f.freeInstance()

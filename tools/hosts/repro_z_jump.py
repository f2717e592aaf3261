#!/usr/bin/env python3
"""usage: repro_z_jump.py HEAD.fmu   (head_demo.fmu, head drive)

Disc 1's forces after step 125 of the bore scenario as z at the step start
moves by dz around -0.124 mm (its value at t = 0.124 s): a step or a slope?"""
import math, sys, numpy as np
from fmpy import read_model_description, extract
from fmpy.fmi2 import FMU2Slave
fmu = sys.argv[1]
md = read_model_description(fmu); d = extract(fmu)
vr = {v.name: v.valueReference for v in md.modelVariables}
w = 10 * 2 * math.pi / 60; vz = -0.006 * w / (2 * math.pi); h = 1e-3
f = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier='kerf', instanceName='h')
f.instantiate(); f.setupExperiment(startTime=0.0); f.enterInitializationMode(); f.exitInitializationMode()
names = ['yaw', 'z', 'wz', 'vz']
for k in range(124):
    t = round(k * h, 12)
    f.setReal([vr[n] for n in names], [w * t, vz * t, w, vz])
    f.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
s = f.getFMUstate()
t = 0.124
z0 = vz * t
o = ['cutter[1].normalForce', 'cutter[1].rollingForce', 'cutter[1].penetration', 'thrust', 'excavatedVolume']
print('z0 =', repr(z0))
for dz in [-1e-9, -1e-12, -1e-15, -1e-18, -2.7e-20, 0.0, 2.7e-20, 1e-18, 1e-15, 1e-12, 1e-9]:
    f.setFMUstate(s)
    f.setReal([vr[n] for n in names], [w * t, z0 + dz, w, vz])
    f.doStep(currentCommunicationPoint=t, communicationStepSize=h)
    v = f.getReal([vr[x] for x in o])
    print(f'dz {dz:+.1e} (z {z0 + dz!r:24s}) N1 {v[0]:.6f} Fr1 {v[1]:.6f} p1 {v[2]:.9e} thrust {v[3]:.4f} vol {v[4]:.12e}')

#!/usr/bin/env python3
"""usage: replay_fmucheck_cs.py HEAD.fmu BORE.csv   (BORE.csv: make_head_csv.py)

Replays fmuCheck's CS loop (tcur += h; inputs linearly interpolated at tcur
between the CSV rows as FMIL's checker does) in fmpy, against exact times."""
import csv, math, sys, numpy as np
from fmpy import read_model_description, extract
from fmpy.fmi2 import FMU2Slave
fmu, incsv = sys.argv[1], sys.argv[2]
md = read_model_description(fmu); d = extract(fmu)
vr = {v.name: v.valueReference for v in md.modelVariables}
rows = list(csv.reader(open(incsv))); names = rows[0][1:]; data = [[float(x) for x in r] for r in rows[1:]]
ts = [r[0] for r in data]
h = 1e-3
def interp(t):
    if t <= ts[0]: return data[0][1:]
    if t >= ts[-1]: return data[-1][1:]
    i2 = next(i for i, x in enumerate(ts) if x >= t)
    i1 = i2 - 1; lam = (t - ts[i1]) / (ts[i2] - ts[i1])
    return [a * (1.0 - lam) + b * lam for a, b in zip(data[i1][1:], data[i2][1:])]
def run(mode, only=None):
    f = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier='kerf', instanceName='h')
    f.instantiate(); f.setupExperiment(startTime=0.0); f.enterInitializationMode(); f.exitInitializationMode()
    t = 0.0; out = []; ins = []
    for k in range(200):
        use_checker = mode == 'checker' and (only is None or k in only)
        tc = t if use_checker else k * h
        u = interp(t) if use_checker else data[k][1:]
        ins.append(u)
        f.setReal([vr[n] for n in names], u)
        f.doStep(currentCommunicationPoint=tc, communicationStepSize=h)
        t = t + h
        out.append(f.getReal([vr['thrust'], vr['torque'], vr['excavatedVolume']]))
    f.terminate(); f.freeInstance()
    return np.array(out), np.array(ins)
A, ua = run('exact'); B, ub = run('checker')
ks = np.nonzero(np.abs(B[:, 0] - A[:, 0]) > 1e-9 * np.abs(A[:, 0]))[0]
print('steps whose thrust differs > 1e-9 rel (1-based):', ks + 1)
for k in ks:
    print(f' step {k+1}: t0 exact {k*h!r}; thrust {A[k,0]!r} vs {B[k,0]!r}; torque {A[k,1]!r} vs {B[k,1]!r}')
    for j, n in enumerate(names):
        if ua[k, j] != ub[k, j]:
            print(f'   input {n}: {ua[k,j]!r} vs {ub[k,j]!r}')

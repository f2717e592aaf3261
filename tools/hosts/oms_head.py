#!/usr/bin/env python3
"""Co-Simulation of a head FMU in OMSimulator through its C API
(libOMSimulator.so with ctypes), as /work/shared/hosts/drivers/oms_roll.py
drives kerf.fmu: a weakly coupled root system with the FMU imported as
Co-Simulation, fixed step h; the inputs of IN.csv are set before each step to
their value at the start of the step; the head totals are read after each
step.

usage: oms_head.py LIBOMSIMULATOR.so FMU IN.csv OUT.csv [stop=0.2] [h=1e-3] [NAME=VALUE ...]
NAME=VALUE: start values (parameters) set after instantiation, before
initialization.
"""
import ctypes as C
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fmu_io import head_totals, read_inputs, run_args, value_at  # noqa: E402

lib, fmu, inp, out = sys.argv[1:5]
stop, h, starts = run_args(sys.argv[5:])
OUTS = head_totals(fmu)
names, rows_in = read_inputs(inp)
STATUS = ["ok", "warning", "discard", "error", "fatal", "pending"]

oms = C.CDLL(lib)
oms.oms_getVersion.restype = C.c_char_p
for fn in ["oms_newModel", "oms_delete", "oms_instantiate", "oms_initialize", "oms_terminate"]:
    getattr(oms, fn).argtypes = [C.c_char_p]
oms.oms_addSystem.argtypes = [C.c_char_p, C.c_int]
oms.oms_addSubModel.argtypes = [C.c_char_p, C.c_char_p]
for fn in ["oms_setFixedStepSize", "oms_setStartTime", "oms_setStopTime", "oms_setReal", "oms_stepUntil"]:
    getattr(oms, fn).argtypes = [C.c_char_p, C.c_double]
oms.oms_getReal.argtypes = [C.c_char_p, C.POINTER(C.c_double)]
oms.oms_setResultFile.argtypes = [C.c_char_p, C.c_char_p, C.c_int]
oms.oms_setLoggingLevel.argtypes = [C.c_int]

bad = []


def call(name, *args):
    st = getattr(oms, name)(*[a.encode() if isinstance(a, str) else a for a in args])
    if st != 0:
        msg = f"{name}{args} -> {STATUS[st] if st < len(STATUS) else st}"
        bad.append(msg)
        print("[driver] " + msg, flush=True)
    return st


print("[driver] OMSimulator", oms.oms_getVersion().decode(), flush=True)
call("oms_setLoggingLevel", 1)
root = "model.root"
sub = root + ".head."
call("oms_newModel", "model")
call("oms_addSystem", root, 1)  # oms_system_wc
call("oms_addSubModel", root + ".head", fmu)
call("oms_setFixedStepSize", root, h)
call("oms_setStartTime", "model", 0.0)
call("oms_setStopTime", "model", stop)
call("oms_setResultFile", "model", "", 1)


def setin(t):
    for n, v in zip(names, value_at(rows_in, t)):
        call("oms_setReal", sub + n, v)


rows = []


def record(t):
    vals = []
    for n in OUTS:
        v = C.c_double()
        call("oms_getReal", sub + n, C.byref(v))
        vals.append(v.value)
    rows.append([t] + vals)


call("oms_instantiate", "model")
for k, v in starts.items():
    call("oms_setReal", sub + k, v)
setin(0.0)
call("oms_initialize", "model")
record(0.0)
n = int(round(stop / h))
for k in range(n):
    t0, t1 = k * h, (k + 1) * h
    setin(t0)
    if call("oms_stepUntil", "model", t1) not in (0, 1):
        break
    record(t1)
call("oms_terminate", "model")
call("oms_delete", "model")
with open(out, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["time"] + OUTS)
    w.writerows(rows)
print(f"[driver] wrote {out}: {len(rows)} rows; {len(bad)} non-ok API calls", flush=True)
sys.exit(1 if bad else 0)

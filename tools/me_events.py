#!/usr/bin/env python3
"""Model Exchange events and wall time of kerf.fmu under two CVode host loops.

* "fmpy": fmpy.simulate_fmu(solver='CVode'), which calls
  fmi2CompletedIntegratorStep once per output interval;
* "PyFMI-like": what PyFMI 2.21 (Assimulo CVode) does, rebuilt on fmpy's
  bundled SUNDIALS: CVode in one-step mode, fmi2CompletedIntegratorStep after
  EVERY internal step, the FMU's event indicators as CVode root functions, the
  time events from fmi2NewDiscreteStates as stop times, and at every event the
  FMI event iteration and a CVode re-initialisation.

The scenario is the reference roll (x = v t at 1 m/s, 3.8 mm deep, rolling
without slip) for --stop seconds. For each FMU given it prints (and with
--out writes as Markdown) events, internal steps, wall time and the final
rollingForce and cuttingEnergy. Before/after comparisons: build the old FMU
in a scratch worktree and pass both, e.g.

    git worktree add /tmp/kerf-old 8442466
    (cd /tmp/kerf-old && cargo run --release -p packaging)
    .venv/bin/python tools/me_events.py --fmu /tmp/kerf-old/target/fmu/kerf.fmu \
        --fmu target/fmu/kerf.fmu --stop 0.5 --out docs/me_events.md

Wall times depend on the machine (they are not used by any test).
"""

import argparse
import ctypes
import sys
import time
from ctypes import byref
from pathlib import Path

import numpy as np
import fmpy
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model
from fmpy.simulation import Input
from fmpy.sundials import CVodeSolver
from fmpy.sundials.cvode import CV_ROOT_RETURN, CVode, CVodeGetRootInfo
from fmpy.sundials.libraries import sundials_cvode
from fmpy.sundials.sundials_types import realtype

CV_ONE_STEP = 2
_set_stop_time = sundials_cvode.CVodeSetStopTime
_set_stop_time.argtypes = [ctypes.c_void_p, realtype]
_set_stop_time.restype = ctypes.c_int

R = 0.2159
Z = 0.2121
V = 1.0


def roll_signal(stop):
    return np.array([(0.0, 0.0, Z, V, V / R), (stop, V * stop, Z, V, V / R)],
                    dtype=[("time", np.float64), ("x", np.float64), ("z", np.float64),
                           ("vx", np.float64), ("wy", np.float64)])


class OneStepCVode(CVodeSolver):
    """fmpy's CVode wrapper, stepping one internal step at a time (as Assimulo)."""

    def step(self, t, tNext):
        if _set_stop_time(self.cvode_mem, tNext) != 0:
            raise RuntimeError("CVodeSetStopTime failed")
        tret = realtype(0.0)
        flag = CVode(self.cvode_mem, tNext, self.x, byref(tret), CV_ONE_STEP)
        roots = np.zeros(shape=(self.nz,), dtype=np.int32)
        if flag == CV_ROOT_RETURN:
            CVodeGetRootInfo(self.cvode_mem, np.ctypeslib.as_ctypes(roots))
        elif flag < 0:
            raise RuntimeError("CVode error %s: %s" % (flag, self.error_info))
        return flag == CV_ROOT_RETURN, roots, tret.value


def run_pyfmi_like(fmu_path, stop=0.5, tol=1e-6, output_interval=1e-3, max_events=None):
    """The PyFMI-like host loop; returns events, steps, wall time and final outputs."""
    md = read_model_description(str(fmu_path))
    unzip = extract(str(fmu_path))
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    outs = ["rollingForce", "cuttingEnergy", "excavatedVolume"]
    fmu = FMU2Model(guid=md.guid, unzipDirectory=unzip,
                    modelIdentifier=md.modelExchange.modelIdentifier, instanceName="me-events")
    t0 = time.perf_counter()
    fmu.instantiate()
    fmu.setupExperiment(tolerance=tol, startTime=0.0)
    fmu.enterInitializationMode()
    inputs = Input(fmu, md, roll_signal(stop))
    inputs.apply(0.0)
    fmu.exitInitializationMode()

    def event_iteration():
        while True:
            need, term, _, _, defined, te = fmu.newDiscreteStates()
            if term:
                raise RuntimeError("the FMU asked to terminate")
            if not need:
                break
        fmu.enterContinuousTimeMode()
        return te if defined else None

    next_te = event_iteration()
    solver = OneStepCVode(
        nx=md.numberOfContinuousStates, nz=md.numberOfEventIndicators,
        get_x=fmu.getContinuousStates, set_x=fmu.setContinuousStates,
        get_dx=fmu.getDerivatives, get_z=fmu.getEventIndicators,
        get_nominals=fmu.getNominalsOfContinuousStates, set_time=fmu.setTime,
        input=inputs, startTime=0.0, relativeTolerance=tol, maxNumSteps=10 ** 9)
    t, steps, events = 0.0, 0, 0
    k_out = 1
    kinds = {"state": 0, "step": 0, "time": 0}
    while t < stop - 1e-12:
        t_out = min(k_out * output_interval, stop)
        t_stop = t_out if next_te is None else min(t_out, next_te)
        root, _, t = solver.step(t, t_stop)
        steps += 1
        fmu.setTime(t)
        inputs.apply(t)
        step_event, term = fmu.completedIntegratorStep()
        time_event = next_te is not None and t >= next_te
        if root or step_event or time_event:
            kinds["state"] += bool(root)
            kinds["step"] += bool(step_event)
            kinds["time"] += bool(time_event)
            fmu.enterEventMode()
            next_te = event_iteration()
            events += 1
            solver.reset(t)
            if max_events is not None and events >= max_events:
                break
        if t >= t_out - 1e-12:
            k_out += 1
    wall = time.perf_counter() - t0
    final = dict(zip(outs, fmu.getReal([vrs[n] for n in outs])))
    fmu.terminate()
    fmu.freeInstance()
    del solver
    return dict(events=events, steps=steps, wall=wall, t=t, kinds=kinds, **final)


def run_fmpy(fmu_path, stop=0.5, tol=1e-6, output_interval=1e-3):
    """fmpy.simulate_fmu with CVode; events counted from the FMI call log."""
    n = {"events": 0, "cis": 0}

    def calls(line):
        if line.startswith("fmi2EnterEventMode"):
            n["events"] += 1
        elif line.startswith("fmi2CompletedIntegratorStep"):
            n["cis"] += 1

    t0 = time.perf_counter()
    r = fmpy.simulate_fmu(str(fmu_path), fmi_type="ModelExchange", solver="CVode",
                          relative_tolerance=tol, input=roll_signal(stop), stop_time=stop,
                          output_interval=output_interval,
                          output=["rollingForce", "cuttingEnergy", "excavatedVolume"],
                          fmi_call_logger=calls)
    wall = time.perf_counter() - t0
    return dict(events=n["events"], steps=n["cis"], wall=wall, t=float(r["time"][-1]),
                rollingForce=float(r["rollingForce"][-1]),
                cuttingEnergy=float(r["cuttingEnergy"][-1]),
                excavatedVolume=float(r["excavatedVolume"][-1]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", action="append", type=Path,
                    help="FMU to measure (repeatable; default target/fmu/kerf.fmu)")
    ap.add_argument("--stop", type=float, default=0.5, help="stop time [s] (default 0.5)")
    ap.add_argument("--tol", type=float, default=1e-6, help="CVode relative tolerance")
    ap.add_argument("--out", type=Path, help="also write the table (Markdown) here")
    ap.add_argument("--max-events", type=int, default=None,
                    help="stop the PyFMI-like loop after this many events (the old FMU makes "
                         "one per internal step); the table shows the time reached")
    a = ap.parse_args(argv)
    fmus = a.fmu or [Path(__file__).resolve().parents[1] / "target/fmu/kerf.fmu"]
    rows = []
    for f in fmus:
        md = read_model_description(str(f))
        for host, fn in (("fmpy CVode", run_fmpy), ("PyFMI-like CVode", run_pyfmi_like)):
            kw = {"max_events": a.max_events} if fn is run_pyfmi_like else {}
            r = fn(f, stop=a.stop, tol=a.tol, **kw)
            rows.append((str(f), md.numberOfEventIndicators, host, r))
            print(f"{f} (ni={md.numberOfEventIndicators}) {host:17s} t {r['t']:.6f} s  "
                  f"events {r['events']:7d}  "
                  f"steps {r['steps']:7d}  wall {r['wall']:7.2f} s  rollingForce "
                  f"{r['rollingForce']:8.1f} N  cuttingEnergy {r['cuttingEnergy']:9.3f} J", flush=True)
    if a.out:
        lines = [f"# Model Exchange events: {a.stop} s of the reference roll, CVode rtol {a.tol}", "",
                 "Produced by `.venv/bin/python tools/me_events.py "
                 + " ".join(f"--fmu {f}" for f in fmus) + f" --stop {a.stop}"
                 + (f" --max-events {a.max_events}" if a.max_events else "") + f" --out {a.out}`.", "",
                 "| FMU | event indicators | host loop | time reached [s] | events "
                 "| completedIntegratorStep calls | wall [s] | rollingForce [N] | cuttingEnergy [J] |",
                 "|---|---|---|---|---|---|---|---|---|"]
        for f, ni, host, r in rows:
            lines.append(f"| {f} | {ni} | {host} | {r['t']:.6g} | {r['events']} | {r['steps']} "
                         f"| {r['wall']:.2f} "
                         f"| {r['rollingForce']:.1f} | {r['cuttingEnergy']:.3f} |")
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

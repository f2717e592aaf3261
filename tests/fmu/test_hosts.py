"""kerf.fmu in the FMI hosts that install from PyPI, run as a user runs them.

* `fmpy simulate` on the command line with an input CSV file, Model Exchange
  (CVode and Euler) and Co-Simulation, against the fmpy-API Co-Simulation
  reference (the same steady forces, the same cut, the same energy);
* Ecos (PyPI `ecospy`, Co-Simulation only; needs Debian's libtbb12, which
  scripts/lib.sh installs): the same roll, the same numbers;
* `fmutool -input kerf.fmu -check` (PyPI `fmu-manipulation-toolbox`): the
  static XML/semantic checks pass.

All are pinned in requirements.txt. The scenario is the reference roll: x = v t
at v = 1 m/s rolling without slip, 3.8 mm deep (z start value), 0.3 s.
"""

import csv
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kerfhost as kh
from conftest import H

STOP = 0.3          # s: 0.3 m of cut at 1 m/s
LO, HI = 0.1, 0.28  # steady window [m]
BIN = Path(sys.executable).parent
OUTS = ["normalForce", "rollingForce", "sideForce", "excavatedVolume", "cuttingEnergy"]


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    assert len(rows) >= 3, f"{path}: {len(rows)} lines"
    header = [h.strip().strip('"') for h in rows[0]]
    cols = list(zip(*rows[1:]))
    return {h: np.array([float(v) for v in c]) for h, c in zip(header, cols)}


def sample(res, name, t):
    """res[name] at the last row with time <= t (hosts may add event rows)."""
    i = np.searchsorted(res["time"], t + 1e-9, side="right") - 1
    return float(res[name][i])


@pytest.fixture(scope="module")
def roll_csv(fmu, tmp_path_factory):
    """Input file: time, x, vx, wy (the others keep their start values); rows
    every 10 ms, all linear in t, so linear interpolation gives x = t exactly."""
    fixed, _ = kh.line_inputs(fmu)
    p = tmp_path_factory.mktemp("hosts") / "roll.csv"
    with open(p, "w") as f:
        f.write("time,x,vx,wy\n")
        for i in range(31):
            t = round(i * 0.01, 12)
            f.write(f"{t!r},{fixed['vx'] * t!r},{fixed['vx']!r},{fixed['wy']!r}\n")
    return p


@pytest.fixture(scope="module")
def reference(fmu):
    """fmpy-API Co-Simulation, 1 ms steps (what tests/fmu/test_reference.py checks)."""
    inst = fmu.instance("CS", name="hosts-reference")
    try:
        return kh.run_line_cs(inst, n_steps=round(STOP / H), h=H)
    finally:
        inst.free()


def fmpy_cli(fmu_path, roll_csv, out, interface, *opts):
    cmd = [str(BIN / "fmpy"), "simulate", str(fmu_path), "--validate",
           "--interface-type", interface, "--input-file", str(roll_csv),
           "--output-interval", str(H), "--stop-time", str(STOP),
           "--output-variables", *OUTS, "--output-file", str(out), *opts]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, f"{' '.join(cmd)} exited {p.returncode}\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
    return read_csv(out), p


def agrees(res, ref, what, rel_force=5e-3, rel_cut=2e-3):
    """Steady forces within the ME-vs-CS tolerance of test_reference.py; the
    excavated volume and the cutting energy at the end within rel_cut."""
    x = res["time"]  # x = v t with v = 1 m/s
    for name in ("normalForce", "rollingForce"):
        sel = (x >= LO) & (x <= HI)
        m = float(np.mean(res[name][sel]))
        c = kh.steady_mean(ref, name, LO, HI)
        assert m == pytest.approx(c, rel=rel_force), f"{what}: {name} {m:.1f} N vs {c:.1f} N"
    for name in ("excavatedVolume", "cuttingEnergy"):
        a, b = sample(res, name, STOP), sample(ref, name, STOP)
        assert b > 0
        assert a == pytest.approx(b, rel=rel_cut), f"{what}: {name} {a:.6g} vs {b:.6g}"


@pytest.mark.parametrize("solver", ["CVode", "Euler"])
def test_fmpy_command_line_model_exchange(fmu, roll_csv, reference, tmp_path, solver):
    opts = ["--solver", solver]
    if solver == "Euler":
        opts += ["--step-size", str(H)]
    res, _ = fmpy_cli(fmu.path, roll_csv, tmp_path / "me.csv", "ModelExchange", *opts)
    assert res["time"][-1] == pytest.approx(STOP)
    agrees(res, reference, f"fmpy CLI ME {solver}")


def test_fmpy_command_line_co_simulation(fmu, roll_csv, reference, tmp_path):
    res, _ = fmpy_cli(fmu.path, roll_csv, tmp_path / "cs.csv", "CoSimulation")
    assert res["time"][-1] == pytest.approx(STOP)
    # fmpy's CS host sets the inputs of each step at its start (x = v t fed,
    # like the reference): the same cut to round-off
    agrees(res, reference, "fmpy CLI CS", rel_force=1e-9, rel_cut=1e-9)


def test_ecos_co_simulation(fmu, reference):
    # pinned in requirements.txt; its libraries need libtbb.so.12 (scripts/lib.sh)
    from ecospy import EcosSimulation, EcosSimulationStructure
    fixed, _ = kh.line_inputs(fmu)
    rows = []
    with EcosSimulationStructure() as ss:
        ss.add_model("kerf", str(fmu.path))
        with EcosSimulation(structure=ss, step_size=H) as sim:
            def inputs(t):
                sim.set_real("kerf::x", fixed["vx"] * t)
                sim.set_real("kerf::vx", fixed["vx"])
                sim.set_real("kerf::wy", fixed["wy"])
            inputs(0.0)
            sim.init()
            rows.append([sim.get_time()] + [sim.get_real("kerf::" + n) for n in OUTS])
            for k in range(round(STOP / H)):
                inputs(k * H)
                sim.step()
                rows.append([sim.get_time()] + [sim.get_real("kerf::" + n) for n in OUTS])
            sim.terminate()
    a = np.array(rows)
    res = {"time": a[:, 0], **{n: a[:, i + 1] for i, n in enumerate(OUTS)}}
    assert res["time"][-1] == pytest.approx(STOP)
    agrees(res, reference, "Ecos CS", rel_force=1e-9, rel_cut=1e-9)


def test_ecos_command_line_default_run(fmu, tmp_path):
    """`ecos simulate` (the CLI in the ecospy wheel) with kerf's start values:
    the cutter pressed in at rest, 0.2 s. The wheel installs binaries/ecos
    without the executable bit (ecospy 0.7.2 packaging), so the test runs a
    copy made executable."""
    import shutil
    import stat
    import ecospy
    src = Path(ecospy.__file__).parent / "binaries" / "ecos"
    exe = tmp_path / "ecos"
    shutil.copy(src, exe)
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    p = subprocess.run([str(exe), "simulate", "--path", str(fmu.path), "--stepSize", str(H),
                        "--stopTime", "0.2"], capture_output=True, text=True, timeout=300,
                       cwd=tmp_path)
    log = p.stdout + p.stderr
    assert p.returncode == 0, log[-3000:]
    assert "[error]" not in log and "[warning]" not in log, log[-3000:]
    with open(tmp_path / "kerf.csv", newline="") as f:
        rows = list(csv.reader(f))
    head = [h.strip() for h in rows[0]]
    col = head.index("instance::normalForce[REAL]")
    fn = np.array([float(r[col]) for r in rows[1:]])
    assert len(fn) >= 200  # rows from t = 0 every 1 ms (Ecos writes 0 .. 0.199)
    inst = fmu.instance("CS", name="hosts-at-rest")
    try:
        inst.initialize()
        want = inst.get_reals(["normalForce"])[0]
    finally:
        inst.free()
    assert want > 0
    assert fn == pytest.approx(np.full_like(fn, want), rel=1e-6)  # CSV: 6 decimals


def test_fmutool_static_check(fmu):
    exe = BIN / "fmutool"
    assert exe.exists(), "fmutool (fmu-manipulation-toolbox, requirements.txt) not installed"
    p = subprocess.run([str(exe), "-input", str(fmu.path), "-check"],
                       capture_output=True, text=True, timeout=300)
    out = p.stdout + p.stderr
    assert p.returncode == 0, out[-3000:]
    assert "compliant with FMI-2.0" in out, out[-3000:]
    assert "No semantic error" in out, out[-3000:]
    assert "ERROR" not in out and "WARNING" not in out, out[-3000:]

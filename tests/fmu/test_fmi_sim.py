"""Second, independent FMI host: fmi-sim (Rust, `cargo install fmi-sim --locked`).

Runs kerf.fmu in Model Exchange and Co-Simulation with default inputs, then the
rolling cut with an input file, and compares with fmpy.  Skipped only when
KERF_SKIP_FMI_SIM=1; a missing fmi-sim binary is a failure (scripts/test installs it).
"""

import csv
import math
import os
import shutil
import subprocess

import numpy as np
import pytest

import kerfhost as kh
from conftest import H

pytestmark = pytest.mark.fmisim

if os.environ.get("KERF_SKIP_FMI_SIM") == "1":
    pytest.skip("KERF_SKIP_FMI_SIM=1: second host fmi-sim not run", allow_module_level=True)

STOP = 0.2  # s = 0.2 m of cut at 1 m/s


@pytest.fixture(scope="module")
def fmi_sim():
    exe = os.environ.get("KERF_FMI_SIM") or shutil.which("fmi-sim") or \
        shutil.which(os.path.expanduser("~/.cargo/bin/fmi-sim"))
    if not exe:
        pytest.fail("fmi-sim not found on PATH (scripts/test installs it with "
                    "`cargo install fmi-sim --locked`; KERF_SKIP_FMI_SIM=1 skips these tests)")
    return exe


def run_fmi_sim(exe, fmu_path, out, interface, *opts, inputs=None):
    cmd = [exe, "--model", str(fmu_path), "-o", str(out)]
    if inputs is not None:
        cmd += ["-i", str(inputs)]
    cmd += [interface, *opts]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, f"{' '.join(cmd)} exited {p.returncode}\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
    return read_csv(out)


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    assert len(rows) >= 3, f"{path}: {len(rows)} lines"
    header = [h.strip().strip('"') for h in rows[0]]
    data = {}
    for i, h in enumerate(header):
        col = []
        for r in rows[1:]:
            v = r[i].strip().lower()
            col.append(1.0 if v == "true" else 0.0 if v == "false" else float(v))
        data[h] = np.array(col)
    return data


@pytest.mark.parametrize("interface", ["model-exchange", "co-simulation"])
def test_fmi_sim_runs_defaults(fmi_sim, fmu_path, tmp_path, interface):
    """Default inputs: the cutter pressed 3.8 mm into the rock at rest."""
    d = run_fmi_sim(fmi_sim, fmu_path, tmp_path / "out.csv", interface, "-f", "0.1")
    assert "time" in d
    for name in kh.REAL_OUTPUTS:
        assert name in d, f"{name} missing from fmi-sim's output ({sorted(d)})"
        assert np.all(np.isfinite(d[name])), f"{name}: non-finite values from fmi-sim {interface}"
    assert d["time"][-1] == pytest.approx(0.1)
    assert np.all(d["penetration"] > 0), "the default pose presses the cutter into the rock"
    assert np.all(d["normalForce"] > 0)


@pytest.fixture(scope="module")
def line_input(tmp_path_factory):
    R = kh.REFERENCE["R"]
    f = tmp_path_factory.mktemp("fmisim") / "line.csv"
    f.write_text("time,x,vx,wy\n"
                 f"0.000000,0.000000,1.000000,{1 / R:.17f}\n"
                 f"1.000000,1.000000,1.000000,{1 / R:.17f}\n")
    return f


@pytest.fixture(scope="module")
def fmpy_line(fmu):
    inst = fmu.instance("CS", name="fmpy-line")
    try:
        return kh.run_line_cs(inst, n_steps=round(STOP / H), h=H)
    finally:
        inst.free()


def test_fmi_sim_cosimulation_matches_fmpy(fmi_sim, fmu_path, tmp_path, line_input, fmpy_line):
    d = run_fmi_sim(fmi_sim, fmu_path, tmp_path / "cs.csv", "co-simulation",
                    "-f", str(STOP), "--output-interval", str(H), "-n", "0", inputs=line_input)
    n = min(len(d["time"]), len(fmpy_line["time"]))
    assert n == round(STOP / H) + 1, f"fmi-sim wrote {len(d['time'])} rows"
    assert np.allclose(d["time"][:n], fmpy_line["time"][:n], rtol=0, atol=1e-12)
    for name in ("normalForce", "rollingForce", "sideForce", "excavatedVolume"):
        a, b = d[name][:n], fmpy_line[name][:n]
        scale = max(np.max(np.abs(b)), 1e-12)
        assert np.max(np.abs(a - b)) <= 1e-9 * scale + 1e-12, \
            f"{name}: fmi-sim and fmpy differ by {np.max(np.abs(a - b)):.3g} (scale {scale:.3g})"


def test_fmi_sim_model_exchange_agrees_with_cosimulation(fmi_sim, fmu_path, tmp_path, line_input, fmpy_line):
    d = run_fmi_sim(fmi_sim, fmu_path, tmp_path / "me.csv", "model-exchange",
                    "-f", str(STOP), "--step", str(H), "--output-interval", str(H), inputs=line_input)
    me = {"x": d["time"], **{k: d[k] for k in kh.REAL_OUTPUTS}}
    for name in ("normalForce", "rollingForce"):
        assert np.all(np.isfinite(me[name]))
        m, c = kh.steady_mean(me, name, 0.1, STOP), kh.steady_mean(fmpy_line, name, 0.1, STOP)
        assert math.isclose(m, c, rel_tol=5e-3), f"{name}: fmi-sim ME {m:.1f} N vs CS {c:.1f} N"
    assert me["excavatedVolume"][-1] > 0, "fmi-sim ME never committed a cut (step events)"

"""The virtual LCM (tools/kerflab/lcm.py, scripts/lcm) and the calibration
(tools/kerflab/calibrate.py, scripts/calibrate) against kerf.fmu.

No force value is hard-coded: the contact law may change. The tests hold the
table to its format, to invariants of an LCM series (forces positive, a chip
removes the whole ridge S x p, SE falls with S while ridges chip and jumps
where they stand, a symmetric groove has no side force) and to
self-consistency (the calibration finds the constants a table was made with;
its standard error follows from sigma exactly where the model is linear).
"""
import math

import numpy as np
import pytest

from kerflab import calibrate as cal
from kerflab import lcm, lcm_report

# a short block: 3 passes, the first discarded, 0.3 m long, measured over 0.2 m
FAST = dict(passes=3, discard=1, length=0.3, window=(0.05, 0.25))
P = 3.8e-3


@pytest.fixture(scope="module")
def series(fmu):
    """p = 3.8 mm at S = 30, 40, 51 mm (ridges chip) and 100 mm (the ridge stands)."""
    return {S: lcm.run_block(fmu, S, P, **FAST) for S in (0.03, 0.04, 0.051, 0.1)}


def test_the_table_has_the_lcm_columns_and_round_trips(series, tmp_path):
    rows = [dict(r["row"], rock="test") for r in series.values()]
    df = lcm.write_table(rows, tmp_path / "t.csv", ["a header comment"])
    assert list(df.columns) == lcm.COLUMNS
    back = lcm.read_table(tmp_path / "t.csv")
    assert list(back.columns) == lcm.COLUMNS
    assert len(back) == len(rows)
    np.testing.assert_allclose(back["Fn_kN"], [r["Fn_kN"] for r in rows], rtol=1e-5)


def test_forces_are_positive_and_peaks_bound_the_means(series):
    for S, res in series.items():
        r = res["row"]
        assert r["passes_kept"] == FAST["passes"] - FAST["discard"]
        assert r["S_mm"] == pytest.approx(S * 1e3) and r["p_mm"] == pytest.approx(P * 1e3)
        assert r["S_over_p"] == pytest.approx(S / P)
        assert r["Fn_kN"] > 0 and r["Fr_kN"] > 0, r
        for f in ("Fn", "Fr", "Fs"):
            assert r[f"{f}_peak_kN"] >= r[f"{f}_kN"] - 1e-9
        assert r["CC"] == pytest.approx(r["Fr_kN"] / r["Fn_kN"], rel=1e-12)
        assert r["SE_MJm3"] == pytest.approx(r["Fr_kN"] * 1e3 / (r["V_cm3_per_m"] * 1e-6) / 1e6,
                                             rel=1e-9)
        assert len(res["passes"]) == FAST["passes"]
        # the first pass is unrelieved: flat face on both sides, no side force
        assert abs(res["passes"][0]["Fs"]) < 1.0  # N


def test_a_chipped_ridge_removes_the_whole_s_by_p_and_pushes_towards_the_relief(series):
    for S in (0.03, 0.04, 0.051):
        r = series[S]["row"]
        assert r["chip_cm3_per_m"] > 0 and r["chips_per_m"] > 0, r
        # ridge + groove: S x p per metre of cut (the chip surface and the tip's
        # rounded profile take a little less)
        assert 0.8 < r["V_cm3_per_m"] / (S * P * 1e6) <= 1.05, r
        assert r["chip_cm3_per_m"] < r["V_cm3_per_m"]
        # intact rock on one side, the previous groove on the other (cutter +y)
        assert r["Fs_kN"] > 0.02 * r["Fn_kN"], r


def test_specific_energy_falls_with_spacing_while_ridges_chip_and_jumps_where_they_stand(series):
    se = {S: series[S]["row"]["SE_MJm3"] for S in series}
    assert se[0.03] > se[0.04] > se[0.051], se
    wide = series[0.1]["row"]
    # S/p = 26: beyond kappa + T/p, the ridge stands: no chips, only the groove leaves
    assert wide["chip_cm3_per_m"] == 0 and wide["chips_per_m"] == 0
    assert wide["V_cm3_per_m"] < 0.013 * P * 1e6  # the groove only: under T x p
    assert wide["SE_MJm3"] > 2 * se[0.051]


def test_without_chips_a_groove_beside_a_groove_is_symmetric(fmu):
    r = lcm.run_block(fmu, 0.051, P, chipping=False, **FAST)["row"]
    assert abs(r["Fs_kN"]) < 1e-3  # kN
    assert r["chip_cm3_per_m"] == 0
    assert r["V_cm3_per_m"] < 0.013 * P * 1e6  # the groove only: under T x p


def test_a_block_is_deterministic(fmu):
    a = lcm.run_block(fmu, 0.04, P, **FAST)["row"]
    b = lcm.run_block(fmu, 0.04, P, **FAST)["row"]
    assert a == b


def test_block_arguments_are_checked(fmu):
    with pytest.raises(ValueError, match="discard"):
        lcm.run_block(fmu, 0.04, P, passes=2, discard=2)
    with pytest.raises(ValueError, match="window"):
        lcm.run_block(fmu, 0.04, P, length=0.3, window=(0.1, 0.5))


def test_scripts_lcm_writes_the_table_and_the_plots(fmu_path, tmp_path):
    lcm_report.main(["--fmu", str(fmu_path), "--out", str(tmp_path), "--spacings", "40,100",
                     "--penetrations", "3.8", "--passes", "3", "--discard", "1", "--length", "0.3",
                     "--window", "0.05,0.25", "--set", "csm.C=2.5"])
    t = lcm.read_table(tmp_path / "lcm_table.csv")
    assert list(t.columns) == lcm.COLUMNS and len(t) == 2
    assert "csm.C" in (tmp_path / "lcm_table.csv").read_text().splitlines()[0]
    for f in ("lcm_forces.png", "lcm_se.png", "lcm_passes.json"):
        assert (tmp_path / f).stat().st_size > 0


# --------------------------------------------------------------------------- calibration

def synthetic_table(fmu, params, rows=((40, 3.8), (65, 5.0)), block=FAST):
    return [dict(lcm.run_block(fmu, S * 1e-3, p * 1e-3, params=params, **block)["row"])
            for S, p in rows]


def test_calibration_recovers_the_constants_a_synthetic_table_was_made_with(fmu, tmp_path):
    truth = {"csm.C": 2.6, "csm.psi": 0.15}
    rows = synthetic_table(fmu, truth)
    lcm.write_table(rows, tmp_path / "synthetic.csv")  # through the CSV (6 digits), as a user would
    table = lcm.read_table(tmp_path / "synthetic.csv")
    rep = cal.calibrate(fmu, table, ["C", "psi"], block=FAST, observables=["Fn_kN", "Fr_kN"],
                        log=lambda *a: None)
    # tolerance: the table's 6 significant digits and the optimiser's stop, well inside 0.2 %
    assert rep["values"]["C"] == pytest.approx(2.6, rel=2e-3)
    assert rep["values"]["psi"] == pytest.approx(0.15, abs=2e-3)
    assert all(abs(r["residual_rel"]) < 1e-4 for r in rep["rows"])
    assert rep["confidence"]["dof"] == 2 and rep["confidence"]["rank"] == 2


def test_a_parameter_no_observation_depends_on_is_named_not_fitted(fmu):
    # chip-free, rolling without slip: kerf's friction acts on slip only
    block = dict(FAST, chipping=False)
    row = synthetic_table(fmu, {"csm.C": 3.0}, rows=((51, 3.8),), block=block)[0]
    rep = cal.calibrate(fmu, [row], ["C", "mu"], block=block, observables=["Fn_kN"],
                        log=lambda *a: None)
    assert rep["confidence"]["not_identified"] == ["mu"]
    assert any("friction" in n for n in rep["notes"])
    assert rep["values"]["C"] == pytest.approx(3.0, rel=1e-4)
    assert rep["values"]["mu"] == pytest.approx(0.3)  # left at its start value


def test_the_standard_error_follows_from_sigma_where_the_model_is_linear(fmu):
    # Fn is proportional to C (P' = C ...): r = (Fn(C) - m) / (sigma m), dr/dC = 1 / (sigma C)
    # at the optimum, so the standard error of C is exactly sigma * C
    row = synthetic_table(fmu, {"csm.C": 2.4}, rows=((51, 3.8),))[0]
    rep = cal.calibrate(fmu, [row], ["C"], block=FAST, observables=["Fn_kN"], sigma=0.05,
                        log=lambda *a: None)
    c = rep["values"]["C"]
    assert c == pytest.approx(2.4, rel=1e-4)
    assert rep["confidence"]["stderr_sigma"]["C"] == pytest.approx(0.05 * c, rel=1e-3)
    assert rep["confidence"]["dof"] == 0
    assert any("as many observations as parameters" in n for n in rep["notes"])


def test_calibration_refuses_a_table_without_observations(fmu):
    with pytest.raises(ValueError, match="no observations"):
        cal.Problem(fmu, [{"S_mm": 51, "p_mm": 3.8, "Fn_kN": math.nan}], ["C"])
    with pytest.raises(KeyError, match="no variable"):
        cal.Problem(fmu, [{"S_mm": 51, "p_mm": 3.8, "Fn_kN": 80}], ["csm.nonsense"])


def test_kappa_is_profiled_and_bounded_by_the_ridges_it_breaks(fmu):
    # a row made with kappa = 15 at S/p = 13.4: the ridge (S - T = 38 mm) broke.
    # kappa = 6 (6 p = 23 mm) leaves it standing: no side force, a worse fit.
    row = synthetic_table(fmu, {"chipping.kappa": 15.0}, rows=((51, 3.8),))[0]
    rep = cal.calibrate(fmu, [row], ["C", "kappa"], block=FAST, observables=["Fn_kN", "Fs_kN"],
                        kappa_grid=(6, 15, 25), log=lambda *a: None)
    prof = {d["kappa"]: d for d in rep["kappa_profile"]}
    assert prof[6.0]["ridges_broke"] == [False] and prof[15.0]["ridges_broke"] == [True]
    assert prof[6.0]["cost"] > prof[15.0]["cost"] + 0.5
    assert rep["values"]["kappa"] == 15.0 and rep["values"]["C"] == pytest.approx(2.12, rel=1e-3)
    assert rep["kappa"]["same_ridges"][0] == 15.0 and rep["kappa"]["interval_68"][0] > 6.0
    assert any("kappa" in n for n in rep["notes"])

"""Sweeps on Dask (tools/kerflab/sweep.py, scripts/sweep).

A small sweep on a LocalCluster of 2 worker processes gives exactly what the
same tasks give run one after another in this process; a re-run skips the
tasks whose result file is there and runs only the missing ones; a task that
fails is reported, not written, and retried by the next run.
"""
import json
import os

import numpy as np
import pytest

from kerflab import lcm
from kerflab import sweep as sw

BLOCK = dict(passes=2, discard=1, length=0.25, window=(0.05, 0.2))
GRID = {"csm.C": [2.0, 2.5], "S_mm": [40.0, 65.0]}


@pytest.fixture(scope="module")
def client():
    from dask.distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def tasks():
    return sw.expand(GRID, fixed={"csm.psi": 0.1}, block=BLOCK)


def test_the_grid_expands_to_its_cartesian_product(tasks):
    assert len(tasks) == 4
    assert {(t["params"]["csm.C"], t["S_mm"]) for t in tasks} == {(2.0, 40.0), (2.0, 65.0),
                                                                    (2.5, 40.0), (2.5, 65.0)}
    assert all(t["p_mm"] == sw.DEFAULT_P_MM and t["params"]["csm.psi"] == 0.1 for t in tasks)
    assert sw.parse_values("1:2:3") == [1.0, 1.5, 2.0]
    assert sw.parse_values("2.12,true,3") == [2.12, True, 3]


def test_task_keys_follow_the_parameters_and_the_fmu():
    t = {"S_mm": 51.0, "p_mm": 3.8, "params": {"csm.C": 2.0, "csm.psi": 0.1}, "block": BLOCK}
    same = {"block": dict(BLOCK), "params": {"csm.psi": 0.1, "csm.C": 2.0}, "p_mm": 3.8, "S_mm": 51.0}
    assert sw.task_key(t, "a") == sw.task_key(same, "a")
    assert sw.task_key(t, "a") != sw.task_key(t, "b")  # another kerf.fmu
    other = dict(t, params={"csm.C": 2.0, "csm.psi": 0.2})
    assert sw.task_key(t, "a") != sw.task_key(other, "a")
    assert sw.task_key(t, "a") != sw.task_key(dict(t, block=dict(BLOCK, passes=3)), "a")


def test_a_sweep_on_two_workers_equals_serial_runs_and_resumes(client, tasks, fmu_path, tmp_path):
    df, stats = sw.run_sweep(tasks, fmu_path, tmp_path, client=client, progress=False)
    assert stats["executed"] == 4 and stats["skipped"] == 0 and stats["failed"] == 0
    assert len(df) == 4
    # the tasks ran in the worker processes, not here
    pids = {json.loads(f.read_text())["pid"] for f in (tmp_path / "tasks").glob("*.json")}
    assert pids and os.getpid() not in pids and len(pids) <= 2
    digest = sw.file_digest(fmu_path)
    for t in tasks:
        serial = sw.run_task(t, digest, fmu_path=str(fmu_path))
        assert "error" not in serial, serial.get("error")
        got = df[df["key"] == sw.task_key(t, digest)]
        assert len(got) == 1
        for col in lcm.RESULTS:
            assert got[col].iloc[0] == pytest.approx(serial["row"][col], rel=0, abs=0) or \
                (np.isnan(got[col].iloc[0]) and np.isnan(serial["row"][col])), col
    # the table holds the swept parameters beside the results
    assert set(GRID) | {"csm.psi", "Fn_kN", "SE_MJm3", "key"} <= set(df.columns)
    assert (tmp_path / "sweep.csv").is_file()

    # resume: one result lost (an interrupted run), one task added
    first = sorted((tmp_path / "tasks").glob("*.json"))
    mtimes = {f: f.stat().st_mtime_ns for f in first}
    first[0].unlink()
    more = tasks + sw.expand({"csm.C": [3.0], "S_mm": [40.0]}, fixed={"csm.psi": 0.1}, block=BLOCK)
    df2, stats2 = sw.run_sweep(more, fmu_path, tmp_path, client=client, progress=False)
    assert stats2["skipped"] == 3 and stats2["executed"] == 2 and len(df2) == 5
    for f in first[1:]:
        assert f.stat().st_mtime_ns == mtimes[f]  # done tasks are not run again
    # nothing left to do: no task runs, not even a cluster is needed
    df3, stats3 = sw.run_sweep(more, fmu_path, tmp_path, client=None, progress=False)
    assert stats3["executed"] == 0 and stats3["skipped"] == 5
    cols = [c for c in df2.columns if c != "task_seconds"]
    assert df3[cols].equals(df2[cols])


def test_a_failing_task_is_reported_and_retried(client, fmu_path, tmp_path):
    bad = sw.expand({"cutter.radius": [-1.0]}, block=BLOCK)
    df, stats = sw.run_sweep(bad, fmu_path, tmp_path, client=client, progress=False)
    assert stats["failed"] == 1 and stats["executed"] == 0 and len(df) == 0
    assert "refused" in stats["errors"][0]["error"]
    assert not list((tmp_path / "tasks").glob("*.json"))
    _, again = sw.run_sweep(bad, fmu_path, tmp_path, client=client, progress=False)
    assert again["failed"] == 1  # not marked done: tried again

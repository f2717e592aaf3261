"""scripts/sweep: parameter studies over many kerf.fmu runs, on Dask.

A sweep is the Cartesian product of --param lists; each combination is one
task: one virtual LCM block (kerflab.lcm.run_block) in one FMU instance of its
own, on one Dask worker. Any FMU parameter can be swept (csm.C, csm.psi,
chipping.kappa, rock.ucs, cutter.tipWidth, ...), and so can the block's
spacing S_mm and penetration p_mm.

* Cluster: a LocalCluster (one single-threaded worker process per core,
  --workers N) unless --scheduler ADDRESS names a running scheduler. Remote
  workers need kerf's Python packages (requirements.txt); kerf.fmu itself is
  sent to them (scattered once), and so are tools/kerfhost.py and
  tools/kerflab (Client.upload_file).
* Resumable: every finished task is written at once to
  OUT/tasks/<key>.json, the key a hash of the task (its parameters and block
  settings) and of kerf.fmu's bytes. A re-run skips the tasks whose file is
  there, so an interrupted sweep (Ctrl-C, a lost cluster) goes on where it
  stopped; a rebuilt kerf.fmu gives new keys, and everything runs again.
  A task that fails is reported and not written: the next run retries it.
* Result: OUT/sweep.csv, one row per task of this sweep (the task's
  parameters, then the LCM table's columns, then the key).

Usage: scripts/sweep --param csm.C=1.8,2.12,2.5 --param S_mm=40:80:5 [--param p_mm=3.8]
                     [--set csm.variant=2] [--scheduler tcp://host:8786] [--workers 2] [--out out/sweep]
(a:b:n is n values from a to b.)
"""
from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import sys
import tempfile
import time
import traceback
import zipfile
from pathlib import Path

import numpy as np

from kerflab import lcm
from kerflab.lcm_report import add_block_args, block_kwargs, parse_set

ROOT = Path(__file__).resolve().parents[2]
TOOLS = Path(__file__).resolve().parents[1]
DEFAULT_S_MM = 51.0
DEFAULT_P_MM = 3.8


# --------------------------------------------------------------------------- tasks

def parse_values(spec):
    """'1,2,3' -> [1, 2, 3]; 'a:b:n' -> n values from a to b; 'true'/'false' -> bool."""
    out = []
    for part in spec.split(","):
        part = part.strip()
        if not part:
            continue
        if part.count(":") == 2:
            a, b, n = part.split(":")
            out += [float(x) for x in np.linspace(float(a), float(b), int(n))]
        else:
            out.append(parse_set([f"v={part}"])["v"])
    return out


def expand(grid: dict, fixed: dict | None = None, block: dict | None = None):
    """Tasks of the Cartesian product of `grid` (name -> values), each a dict
    {"S_mm", "p_mm", "params": FMU start values, "block": run_block options}."""
    names = list(grid)
    tasks = []
    for combo in itertools.product(*(grid[n] for n in names)):
        params = dict(fixed or {})
        params.update(zip(names, combo))
        S = float(params.pop("S_mm", DEFAULT_S_MM))
        p = float(params.pop("p_mm", DEFAULT_P_MM))
        tasks.append({"S_mm": S, "p_mm": p, "params": params, "block": dict(block or {})})
    return tasks


def _canon(task):
    t = dict(task)
    t["block"] = {k: list(v) if isinstance(v, tuple) else v for k, v in task.get("block", {}).items()}
    return json.dumps(t, sort_keys=True, separators=(",", ":"))


def task_key(task, fmu_digest):
    """Hash of the task and of the FMU's bytes: the name of its result file."""
    return hashlib.sha256((fmu_digest + "\n" + _canon(task)).encode()).hexdigest()[:20]


def file_digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _local_fmu(digest, data):
    """kerf.fmu on this worker: written once per machine from the scattered bytes."""
    path = Path(tempfile.gettempdir()) / f"kerf-{digest[:16]}.fmu"
    if not path.is_file():
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_bytes(data)
        tmp.replace(path)
    return path


def run_task(task, digest, data=None, fmu_path=None):
    """One task in one fresh FMU instance; returns {"task", "row"} or {"task", "error"}.

    Runs on a Dask worker (or in-process): the FMU is `fmu_path` if given, else
    the scattered `data` written to a temporary file."""
    t0 = time.monotonic()
    try:
        path = fmu_path or _local_fmu(digest, data)
        block = dict(task.get("block", {}))
        if "window" in block:
            block["window"] = tuple(block["window"])
        res = lcm.run_block(lcm.open_fmu(path), task["S_mm"] * 1e-3, task["p_mm"] * 1e-3,
                            params=task["params"], **block)
        return {"task": task, "row": res["row"], "chipCount": res["chipCount"],
                "seconds": time.monotonic() - t0, "host": os.uname().nodename, "pid": os.getpid()}
    except Exception:
        return {"task": task, "error": traceback.format_exc()}


def table_row(result, key):
    t = result["task"]
    row = {"S_mm": t["S_mm"], "p_mm": t["p_mm"]}
    row.update(t["params"])
    row.update({k: v for k, v in result["row"].items() if k not in ("S_mm", "p_mm")})
    row["chipCount"] = result.get("chipCount")
    row["task_seconds"] = result.get("seconds")
    row["key"] = key
    return row


# --------------------------------------------------------------------------- runner

def _code_zip():
    """tools/kerfhost.py and tools/kerflab as a zip, for Client.upload_file."""
    path = Path(tempfile.gettempdir()) / f"kerflab-{os.getpid()}.zip"
    with zipfile.ZipFile(path, "w") as z:
        z.write(TOOLS / "kerfhost.py", "kerfhost.py")
        for f in sorted((TOOLS / "kerflab").glob("*.py")):
            z.write(f, f"kerflab/{f.name}")
    return path


def run_sweep(tasks, fmu_path, out_dir, *, client=None, scheduler=None, workers=None,
              progress=True, log=print):
    """Runs the tasks not yet done on Dask; returns (DataFrame of all tasks' rows, stats).

    `client`: a dask.distributed Client to use; else one is made for
    `scheduler` (an address) or for a new LocalCluster of `workers` processes."""
    import pandas as pd

    out_dir = Path(out_dir)
    (out_dir / "tasks").mkdir(parents=True, exist_ok=True)
    digest = file_digest(fmu_path)
    keys = [task_key(t, digest) for t in tasks]
    if len(set(keys)) != len(keys):
        raise ValueError("the sweep lists the same task twice")
    done = {k for k in keys if (out_dir / "tasks" / f"{k}.json").is_file()}
    todo = [(k, t) for k, t in zip(keys, tasks) if k not in done]
    stats = {"tasks": len(tasks), "skipped": len(done), "executed": 0, "failed": 0, "errors": []}
    log(f"{len(tasks)} tasks: {len(done)} done before, {len(todo)} to run")
    t0 = time.monotonic()
    if todo:
        own = client is None
        cluster = None
        if own:
            from dask.distributed import Client, LocalCluster
            if scheduler:
                client = Client(scheduler)
                code = _code_zip()
                try:
                    client.upload_file(str(code))
                finally:
                    code.unlink()
            else:
                cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                                       processes=True, dashboard_address=None)
                client = Client(cluster)
        try:
            _run_on(client, todo, digest, fmu_path, out_dir, stats, progress, local=not scheduler)
        finally:
            if own:
                client.close()
                if cluster is not None:
                    cluster.close()
    stats["seconds"] = time.monotonic() - t0
    rows = []
    for k in keys:
        f = out_dir / "tasks" / f"{k}.json"
        if f.is_file():
            rows.append(table_row(json.loads(f.read_text()), k))
    df = pd.DataFrame(rows)
    df.to_csv(out_dir / "sweep.csv", index=False, float_format="%.9g")
    return df, stats


def _run_on(client, todo, digest, fmu_path, out_dir, stats, progress, local):
    from dask.distributed import as_completed
    from tqdm import tqdm

    if local:  # the workers see this file system: no need to ship the FMU
        data, path = None, str(Path(fmu_path).resolve())
    else:
        data, path = client.scatter(Path(fmu_path).read_bytes(), broadcast=True), None
    futures = {}
    for k, t in todo:
        # pure=False: one submission per task; key names the task in the dashboard
        fut = client.submit(run_task, t, digest, data, path, key=f"kerf-{k}", pure=False)
        futures[fut] = k
    bar = tqdm(total=len(todo), desc="sweep", unit="task", disable=not progress, file=sys.stderr)
    try:
        for fut in as_completed(futures):
            k = futures[fut]
            res = fut.result()
            if "error" in res:
                stats["failed"] += 1
                stats["errors"].append({"key": k, "task": res["task"], "error": res["error"]})
                bar.write(f"task {k} failed:\n{res['error']}")
            else:
                f = out_dir / "tasks" / f"{k}.json"
                tmp = f.with_suffix(".tmp")
                tmp.write_text(json.dumps({"key": k, "fmu_sha256": digest, **res}))
                tmp.replace(f)  # atomic: a file that is there is whole
                stats["executed"] += 1
            bar.update(1)
    finally:
        bar.close()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "kerf.fmu"))
    ap.add_argument("--out", default=str(ROOT / "out" / "sweep"))
    ap.add_argument("--param", action="append", metavar="NAME=VALUES", default=[],
                    help="a swept parameter (repeatable): FMU name, S_mm or p_mm; values 1,2,3 or a:b:n")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, help="LocalCluster worker processes (default: one per core)")
    ap.add_argument("--no-progress", action="store_true")
    add_block_args(ap)
    a = ap.parse_args(argv)
    grid = {}
    for spec in a.param:
        if "=" not in spec:
            raise SystemExit(f"--param {spec!r}: expected NAME=VALUES")
        k, v = spec.split("=", 1)
        grid[k.strip()] = parse_values(v)
    fmu = lcm.open_fmu(a.fmu)
    for n in grid:
        if n not in ("S_mm", "p_mm"):
            fmu.var(n)  # KeyError: no such FMU parameter
    tasks = expand(grid, parse_set(a.set), block_kwargs(a))
    df, stats = run_sweep(tasks, a.fmu, a.out, scheduler=a.scheduler, workers=a.workers,
                          progress=not a.no_progress)
    print(f"ran {stats['executed']} tasks in {stats['seconds']:.1f} s, skipped {stats['skipped']} "
          f"done before, {stats['failed']} failed; {len(df)} rows in {Path(a.out) / 'sweep.csv'}")
    if len(df):
        cols = [c for c in list(grid) + ["Fn_kN", "Fr_kN", "Fs_kN", "CC", "SE_MJm3"] if c in df]
        with_pd_opts(lambda: print(df[cols].to_string(index=False, float_format=lambda x: f"{x:.4g}")))
    return 1 if stats["failed"] else 0


def with_pd_opts(fn):
    import pandas as pd
    with pd.option_context("display.max_rows", 60, "display.width", 160):
        fn()


if __name__ == "__main__":
    sys.exit(main())

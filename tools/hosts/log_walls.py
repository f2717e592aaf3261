#!/usr/bin/env python3
"""Approximate wall time of each run of /work/shared/hosts/run-all.sh (which
prints none): run-all.sh writes TAG.log for each run in turn, so a run took
about the time between the last write of the previous TAG.log and of its own
(this includes the verdict script, ~0.05 s). The first run's start is taken
from roll.csv, written just before it.

usage: log_walls.py RUNDIR     (e.g. $HOSTS/runs/all)
"""
import os
import sys

d = sys.argv[1]
logs = [f for f in os.listdir(d) if f.endswith(".log") and f.count(".") == 1]
logs.sort(key=lambda f: os.stat(os.path.join(d, f)).st_mtime)
prev = os.stat(os.path.join(d, "roll_dup1ms.csv")).st_mtime if os.path.exists(os.path.join(d, "roll_dup1ms.csv")) \
    else min(os.stat(os.path.join(d, f)).st_mtime for f in logs)
for f in logs:
    m = os.stat(os.path.join(d, f)).st_mtime
    print(f"{f[:-4]:34s} {m - prev:7.2f} s")
    prev = m

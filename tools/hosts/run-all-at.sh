#!/usr/bin/env bash
# The shared run-all.sh (kerf.fmu's rolling cut through every host built into
# $HOSTS) at another rolling speed. run-all.sh rolls at 1 m/s, where Model
# Exchange's events (one a sweep step, 1 mm) land on the 1 ms output grid; at
# other speeds they fall between grid points, which some hosts handle
# differently (docs/hosts.md, H6). The scripts are copied and their roll
# (x = t, vx = 1, wy = 1/R) set to x = V t, vx = V, wy = V/R; the forces the
# verdict checks do not depend on the speed. The shared scripts are not changed.
#
# usage: run-all-at.sh V path/to/kerf.fmu
# env:   SHARED_HOSTS (/work/shared/hosts), HOSTS (/tmp/kerf-hosts),
#        OUT ($HOSTS/runs/all-at-V)
set -eu
V=$1; FMU=$(readlink -f "$2")
SH=${SHARED_HOSTS:-/work/shared/hosts}
HOSTS=${HOSTS:-/tmp/kerf-hosts}
export HOSTS OUT=${OUT:-$HOSTS/runs/all-at-$V}
COPY=$(mktemp -d); trap 'rm -rf "$COPY"' EXIT
cp -r "$SH"/. "$COPY"/
cd "$COPY"
sub() {  # FILE FROM TO: replace a literal string, which must be there
  python3 - "$@" <<'PY'
import sys
path, old, new = sys.argv[1:]
s = open(path).read()
if old not in s:
    sys.exit(f"run-all-at.sh: {path} no longer holds {old!r}")
open(path, "w").write(s.replace(old, new))
PY
}
sub drivers/make_roll_csv.py '{"x": t, "z": 0.2121, "vx": 1.0, "wy": 1.0 / R}' "{\"x\": $V * t, \"z\": 0.2121, \"vx\": $V, \"wy\": $V / R}"
sub run-all.sh '{"x": t, "z": 0.2121, "vx": 1.0, "wy": 1.0 / R}' "{\"x\": $V * t, \"z\": 0.2121, \"vx\": $V, \"wy\": $V / R}"
sub drivers/oms_roll.py '".kerf.x", t)' "\".kerf.x\", $V * t)"
sub drivers/oms_roll.py '".kerf.vx", 1.0)' "\".kerf.vx\", $V)"
sub drivers/oms_roll.py '".kerf.wy", 1.0 / R)' "\".kerf.wy\", $V / R)"
sub drivers/ecos_roll.py '"kerf::x", t)' "\"kerf::x\", $V * t)"
sub drivers/ecos_roll.py '"kerf::vx", 1.0)' "\"kerf::vx\", $V)"
sub drivers/ecos_roll.py '"kerf::wy", 1.0 / R)' "\"kerf::wy\", $V / R)"
sub drivers/pyfmi_roll.py '[t, t, np.ones_like(t), np.full_like(t, 1.0 / R)]' "[t, $V * t, np.full_like(t, $V), np.full_like(t, $V / R)]"
sub drivers/fmpy_state.py '[t, 1.0, 1.0 / R]' "[$V * t, $V, $V / R]"
bash ./run-all.sh "$FMU"

#!/usr/bin/env bash
# Build every host that /work/shared/hosts/ knows, one after the other, into
# $HOSTS, logging each script's output and wall time to $HOSTS/buildlogs/.
# The shared scripts are run unmodified. A host whose build fails is noted and
# the next one is tried.
# usage: MIRROR=/work/.mirror HOSTS=/tmp/kerf-hosts tools/hosts/build-all.sh [names...]
#   names default to: fmucc fmusim pypi-hosts fmusim-rs omsimulator pyfmi fmi-sim
set -u
export MIRROR=${MIRROR:-/work/.mirror}
export HOSTS=${HOSTS:-/tmp/kerf-hosts}
SH=${SHARED_HOSTS:-/work/shared/hosts}
L=$HOSTS/buildlogs; mkdir -p "$L"
names=("$@"); ((${#names[@]})) || names=(fmucc fmusim pypi-hosts fmusim-rs omsimulator pyfmi fmi-sim)
for n in "${names[@]}"; do
  t0=$(date +%s)
  echo "$(date -u +%FT%TZ) start $n" >>"$L/summary.txt"
  bash "$SH/build-$n.sh" >"$L/build-$n.log" 2>&1; rc=$?
  echo "$(date -u +%FT%TZ) end $n rc=$rc wall=$(( $(date +%s) - t0 ))s" >>"$L/summary.txt"
  if [ "$n" = pypi-hosts ]; then
    # workaround outside the shared scripts: the ecospy 0.7.2 wheel installs
    # its `ecos` and `proxyfmu` binaries without the executable bit, so
    # run-all.sh's Ecos CLI line fails with "Permission denied"
    chmod +x "$HOSTS"/venv/lib/python3*/site-packages/ecospy/binaries/{ecos,proxyfmu}
  fi
done

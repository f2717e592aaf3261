#!/usr/bin/env bash
# Run a cutterhead FMU (head drive, e.g. head_demo.fmu) through every FMI host
# that /work/shared/hosts/build-*.sh built into $HOSTS, as run-all.sh does for
# kerf.fmu (whose rolling scenario does not fit a head):
#   (a) each host's default run: no inputs (the head stands still), the
#       DefaultExperiment's 1 s at 1 ms, ME and CS where the host has them,
#       plus fmuCheck's XML check, `validate` commands and fmutool -check;
#   (b) "bore": Co-Simulation, 0.2 s at h = 1 ms, the head turning at 10 rpm
#       and advancing 6 mm/rev from the flat face (make_head_csv.py); thrust,
#       torque and the other totals compared between hosts (head_compare.py,
#       reference: FMPy CS).
# One PASS/FAIL line per run from /work/shared/hosts/drivers/verdict.py (exit
# code and warning/error lines of the log; the kerf.fmu force check is not
# used), wall time per run in the label's line.
#
# usage: run-head.sh path/to/head.fmu
# env:   HOSTS (default /tmp/kerf-hosts), OUT (default $HOSTS/runs/head),
#        STOP (0.2), H (1e-3), RPM (10), PREV (0.006),
#        STARTS ("NAME=VALUE ..." start values for the bore run; fmuCheck has
#        no option for them, so its bore is skipped then)
set -u
HOSTS=${HOSTS:-/tmp/kerf-hosts}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
SD=${SHARED_DRIVERS:-/work/shared/hosts/drivers}
FMU=$(readlink -f "$1")
OUT=${OUT:-$HOSTS/runs/head}
STOP=${STOP:-0.2}; H=${H:-1e-3}; RPM=${RPM:-10}; PREV=${PREV:-0.006}
STARTS=${STARTS:-}
PY=$HOSTS/venv/bin/python
[ -f "$FMU" ] || { echo "no FMU at $FMU" >&2; exit 2; }
rm -rf "$OUT"; mkdir -p "$OUT"; cd "$OUT" || exit 2
python3 "$HERE/make_head_csv.py" bore.csv "$STOP" "$H" "$RPM" "$PREV"
NSTEP=$(python3 -c "print(int(round($STOP/$H)))")

NPASS=0; NFAIL=0; NSKIP=0; CSVS=()
skip() { echo "SKIP  $1  ($2)"; NSKIP=$((NSKIP+1)); }
run() {  # TAG LABEL CSV|- CMD...
  local tag=$1 label=$2 csv=$3; shift 3
  local t0; t0=$(date +%s.%N)
  "$@" >"$tag.log" 2>&1; local rc=$?
  local wall; wall=$(python3 -c "import time;print(f'{time.time()-$t0:.1f}')")
  for f in "$tag".*.log; do [ -f "$f" ] && { echo "=== $f"; cat "$f"; } >>"$tag.log"; done
  local line; line=$(python3 "$SD/verdict.py" "$label [${wall}s]" "$rc" "$tag.log" -)
  echo "$line"
  case "$line" in PASS*) NPASS=$((NPASS+1));; *) NFAIL=$((NFAIL+1));; esac
  [ "$csv" != - ] && CSVS+=("$tag=$csv")
}
# STARTS as each host spells it
FMUSIM_SV=(); FMUSIMRS_SV=(); FMPY_SV=(); DRV_SV=(); FMISIM_SV=()
for kv in $STARTS; do
  FMUSIM_SV+=(--start-value "${kv%%=*}" "${kv#*=}"); FMPY_SV+=("${kv%%=*}" "${kv#*=}"); DRV_SV+=("$kv"); FMISIM_SV+=(--init-values "$kv")
  FMUSIMRS_SV+=(--start-value "$kv")
done

echo "head FMU: $FMU ($(sha256sum "$FMU" | cut -c1-16))"
echo "results:  $OUT"
echo "bore: CS ${STOP} s at h = $H, $RPM rpm, $PREV m/rev${STARTS:+, starts: $STARTS}"
echo

C=$HOSTS/fmucc/install/fmuCheck.linux64
if [ -x "$C" ]; then
  run fmucc_xml "fmuCheck XML only" - "$C" -k xml -l 4 -e fmucc_xml.e.log "$FMU"
  run fmucc_me_default "fmuCheck ME default(-h1e-3 -s1)" - "$C" -k me -h 1e-3 -s 1 -l 4 -o fmucc_me_default.csv -e fmucc_me_default.e.log "$FMU"
  run fmucc_cs_default "fmuCheck CS default(-h1e-3 -s1)" - "$C" -k cs -h 1e-3 -s 1 -l 4 -o fmucc_cs_default.csv -e fmucc_cs_default.e.log "$FMU"
  if [ -z "$STARTS" ]; then
    run fmucc_bore "fmuCheck CS bore" fmucc_bore.csv "$C" -k cs -h "$H" -s "$STOP" -n 0 -l 4 -i bore.csv -o fmucc_bore.csv -e fmucc_bore.e.log "$FMU"
  else skip "fmuCheck CS bore" "no start values in fmuCheck"; fi
else skip "fmuCheck" "not built"; fi

F=$HOSTS/fmusim/fmusim
if [ -x "$F" ]; then
  for m in me cs; do
    run fmusim_${m}_default "fmusim 0.0.39 $m default" - "$F" --interface-type $m --output-file fmusim_${m}_default.csv \
      --logging-on --log-level ok --log-file fmusim_${m}_default.fmu.log "$FMU"
  done
  run fmusim_bore "fmusim 0.0.39 CS bore" fmusim_bore.csv "$F" --interface-type cs ${FMUSIM_SV[@]+"${FMUSIM_SV[@]}"} \
    --stop-time "$STOP" --output-interval "$H" --input-file bore.csv --output-file fmusim_bore.csv \
    --logging-on --log-level ok --log-file fmusim_bore.fmu.log "$FMU"
  # its FMU-state files: save half-way, restore in a new process, and the
  # restored half must be the uninterrupted bore's (fmusim frees those
  # states by passing the state itself; kerf frees it with a warning)
  HALF=$(python3 -c "print($STOP/2)")
  run fmusim_state_save "fmusim 0.0.39 CS bore, save state @$HALF" - "$F" --interface-type cs ${FMUSIM_SV[@]+"${FMUSIM_SV[@]}"} \
    --stop-time "$HALF" --output-interval "$H" --input-file bore.csv --output-file fmusim_state_a.csv \
    --final-fmu-state-file fmusim_state.bin --logging-on --log-level ok --log-file fmusim_state_save.fmu.log "$FMU"
  run fmusim_state_load "fmusim 0.0.39 CS bore, restore state" - "$F" --interface-type cs --start-time "$HALF" \
    --stop-time "$STOP" --output-interval "$H" --input-file bore.csv --output-file fmusim_state_b.csv \
    --initial-fmu-state-file fmusim_state.bin --logging-on --log-level ok --log-file fmusim_state_load.fmu.log "$FMU"
  run fmusim_state_cmp "fmusim 0.0.39 CS restored==uninterrupted" - python3 "$SD/split_check.py" fmusim_bore.csv fmusim_state_b.csv "$HALF"
else skip "fmusim (C)" "not built"; fi

F=$HOSTS/fmusim-rs/fmusim
if [ -x "$F" ]; then
  run fmusimrs_validate "fmusim-rs 0.8.0 validate" - "$F" validate "$FMU"
  for m in me cs; do
    run fmusimrs_${m}_default "fmusim-rs 0.8.0 $m default" - "$F" simulate --interface-type $m --output-file fmusimrs_${m}_default.csv --logging-on "$FMU"
  done
  run fmusimrs_bore "fmusim-rs 0.8.0 CS bore" fmusimrs_bore.csv "$F" simulate --interface-type cs ${FMUSIMRS_SV[@]+"${FMUSIMRS_SV[@]}"} \
    --stop-time "$STOP" --output-interval "$H" --input-file bore.csv --output-file fmusimrs_bore.csv --logging-on "$FMU"
else skip "fmusim-rs" "not built"; fi

P=$HOSTS/venv/bin/fmpy
if [ -x "$P" ]; then
  run fmpy_validate "FMPy validate" - "$P" validate "$FMU"
  run fmpy_me_default "FMPy ME default (CVode)" - "$P" simulate "$FMU" --interface-type ModelExchange --output-file fmpy_me_default.csv --fmi-logging
  run fmpy_cs_default "FMPy CS default" - "$P" simulate "$FMU" --interface-type CoSimulation --output-file fmpy_cs_default.csv --fmi-logging
  run fmpy_bore "FMPy CS bore" fmpy_bore.csv "$P" simulate "$FMU" --interface-type CoSimulation \
    ${FMPY_SV[@]+--start-values "${FMPY_SV[@]}"} \
    --output-interval "$H" --stop-time "$STOP" --input-file bore.csv --output-file fmpy_bore.csv
else skip "FMPy" "not installed"; fi

S=$HOSTS/fmi-sim/bin/fmi-sim
if [ -x "$S" ]; then
  run fmisim_me_default "fmi-sim 0.7.0 ME default" - env RUST_BACKTRACE=0 "$S" --model "$FMU" -o fmisim_me_default.csv model-exchange
  run fmisim_cs_default "fmi-sim 0.7.0 CS default" - env RUST_BACKTRACE=0 "$S" --model "$FMU" -o fmisim_cs_default.csv co-simulation
  run fmisim_bore "fmi-sim 0.7.0 CS bore" fmisim_bore.csv env RUST_BACKTRACE=0 "$S" --model "$FMU" -i bore.csv -o fmisim_bore.csv \
    co-simulation ${FMISIM_SV[@]+"${FMISIM_SV[@]}"} --step "$H" -f "$STOP" -n 0
else skip "fmi-sim" "not built"; fi

if [ -x "$PY" ] && "$PY" -c 'import ecospy' 2>/dev/null; then
  EC=$($PY -c 'import ecospy,os;print(os.path.join(os.path.dirname(ecospy.__file__),"binaries","ecos"))')
  run ecos_cli_default "Ecos 0.7.2 CS default(CLI)" - "$EC" simulate --path "$FMU" --stepSize 1e-3 --stopTime 1 --debugLogging -l debug --noCsv
  run ecos_bore "Ecos 0.7.2 CS bore (ecospy)" ecos_bore.csv "$PY" "$HERE/ecos_head.py" "$FMU" bore.csv ecos_bore.csv "$STOP" "$H" "${DRV_SV[@]}"
else skip "Ecos" "not installed"; fi

O=$HOSTS/omsimulator/install
if [ -x "$O/bin/OMSimulator" ]; then
  for m in me cs; do
    run oms_${m}_default "OMSimulator $m default(CLI)" - "$O/bin/OMSimulator" --mode=$m --solver=euler \
      --stopTime=1 --stepSize=1e-3 --intervals=1000 --logLevel=1 --resultFile=oms_${m}_default.csv "$FMU"
  done
  LIBOMS=$(find "$O" -name libOMSimulator.so | head -1)
  run oms_bore "OMSimulator CS bore (C API)" oms_bore.csv python3 "$HERE/oms_head.py" "$LIBOMS" "$FMU" bore.csv oms_bore.csv "$STOP" "$H" "${DRV_SV[@]}"
else skip "OMSimulator" "not built"; fi

PF=$HOSTS/venv-pyfmi/bin/python
if [ -x "$PF" ] && (cd /tmp && "$PF" -c 'import pyfmi') 2>/dev/null; then
  PV=$(cd /tmp && "$PF" -c 'import pyfmi;print(pyfmi.__version__)')
  for m in me cs; do
    run pyfmi_${m}_default "PyFMI $PV $m default" - "$PF" "$HERE/pyfmi_head.py" "$FMU" - pyfmi_${m}_default.csv 1 1e-3 --kind $m
  done
  run pyfmi_bore "PyFMI $PV CS bore" pyfmi_bore.csv "$PF" "$HERE/pyfmi_head.py" "$FMU" bore.csv pyfmi_bore.csv "$STOP" "$H" "${DRV_SV[@]}"
else skip "PyFMI" "not built"; fi

if [ -x "$HOSTS/venv/bin/fmutool" ]; then
  run fmutool_check "fmutool 2.0 -check" - "$HOSTS/venv/bin/fmutool" -input "$FMU" -check
fi

echo
echo "$NPASS PASS, $NFAIL FAIL, $NSKIP SKIP"
echo
echo "Bore (CS, $NSTEP steps), all hosts (reference: FMPy CS):"
REF=(); REST=()
for c in "${CSVS[@]}"; do case $c in fmpy_bore=*) REF=("$c");; *) REST+=("$c");; esac; done
python3 "$HERE/head_compare.py" "${REF[@]}" "${REST[@]}"; CMP=$?
echo
[ "$NFAIL" -eq 0 ] && [ "$CMP" -eq 0 ]

#!/usr/bin/env bash
# The head FMU's bore (make_head_csv.py: 0.2 s, 10 rpm, 6 mm/rev) in Model
# Exchange, in the hosts that read a CSV input file: FMPy (Euler h = 1 ms,
# CVode), fmusim C (euler, cvode), fmuCheck (Euler; only without STARTS) and
# fmi-sim (Euler). Compares the totals with FMPy CS's bore run by run-head.sh
# ($CSREF) and between the ME hosts (reference FMPy ME Euler), tolerance 1e-6.
# Not in run-head.sh: ME commits at events, so ME and CS outputs are expected
# to differ at single instants; the numbers are for reading, not a verdict.
#
# usage: run-head-me.sh path/to/head.fmu
# env:   HOSTS (/tmp/kerf-hosts), OUT ($HOSTS/runs/head-me), STARTS ("NAME=VALUE ..."),
#        CSREF (FMPy CS bore CSV of run-head.sh with the same STARTS)
set -u
HOSTS=${HOSTS:-/tmp/kerf-hosts}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
FMU=$(readlink -f "$1")
OUT=${OUT:-$HOSTS/runs/head-me}
STARTS=${STARTS:-}
CSREF=${CSREF:-$HOSTS/runs/head/fmpy_bore.csv}
rm -rf "$OUT"; mkdir -p "$OUT"; cd "$OUT" || exit 2
python3 "$HERE/make_head_csv.py" bore.csv 0.2 1e-3
FSV=(); PSV=(); MSV=()
for kv in $STARTS; do
  FSV+=(--start-value "${kv%%=*}" "${kv#*=}"); PSV+=("${kv%%=*}" "${kv#*=}"); MSV+=(--init-values "$kv")
done
t() {  # TAG CMD...
  local tag=$1; shift; local t0; t0=$(date +%s.%N)
  "$@" >"$tag.log" 2>&1; local rc=$?
  printf '%-20s rc=%d  %.2f s\n' "$tag" "$rc" "$(python3 -c "import time;print(time.time()-$t0)")"
}
P=$HOSTS/venv/bin/fmpy; F=$HOSTS/fmusim/fmusim; C=$HOSTS/fmucc/install/fmuCheck.linux64; S=$HOSTS/fmi-sim/bin/fmi-sim
t fmpy_me_euler "$P" simulate "$FMU" --interface-type ModelExchange --solver Euler --step-size 1e-3 --output-interval 1e-3 \
  --stop-time 0.2 --input-file bore.csv ${PSV[@]+--start-values "${PSV[@]}"} --output-file fmpy_me_euler.csv
t fmpy_me_cvode "$P" simulate "$FMU" --interface-type ModelExchange --solver CVode --output-interval 1e-3 \
  --stop-time 0.2 --input-file bore.csv ${PSV[@]+--start-values "${PSV[@]}"} --output-file fmpy_me_cvode.csv
for s in euler cvode; do
  t fmusim_me_$s "$F" --interface-type me --solver $s --stop-time 0.2 --output-interval 1e-3 ${FSV[@]+"${FSV[@]}"} \
    --input-file bore.csv --output-file fmusim_me_$s.csv "$FMU"
done
[ -z "$STARTS" ] && t fmucc_me "$C" -k me -h 1e-3 -s 0.2 -n 0 -l 3 -i bore.csv -o fmucc_me.csv "$FMU"
t fmisim_me env RUST_BACKTRACE=0 "$S" --model "$FMU" -i bore.csv -o fmisim_me.csv model-exchange ${MSV[@]+"${MSV[@]}"} \
  --step 1e-3 -f 0.2 -n 0
RUNS=(fmpy_me_euler=fmpy_me_euler.csv)
[ -f fmucc_me.csv ] && RUNS+=(fmucc_me=fmucc_me.csv)
RUNS+=(fmusim_me_euler=fmusim_me_euler.csv fmisim_me=fmisim_me.csv fmpy_me_cvode=fmpy_me_cvode.csv fmusim_me_cvode=fmusim_me_cvode.csv)
echo; echo "ME hosts against FMPy CS ($CSREF):"
python3 "$HERE/head_compare.py" --tol 1e-6 fmpy_cs="$CSREF" "${RUNS[@]}"
echo; echo "ME hosts against FMPy ME Euler:"
python3 "$HERE/head_compare.py" --tol 1e-6 "${RUNS[@]}"
exit 0

#!/usr/bin/env bash
# Times the LOGI release gate with an external client at several widths:
# `hil run scenarios/logi -j N --client-exec CLIENT`, run R times in a row
# for each N and each correct client (hil's logi-client --stdin-actions and
# the Python client tests/gate/clients/logi_good.py). Every run is a whole
# gate: its wall time is what a client team waits for, and any scenario that
# fails in any run counts as a flake (both clients are correct). Target: the
# gate in at most 60 s of wall time on 2 cores, with no flake in 20 runs.
# Usage: bench/gate_time.sh [--hil PATH] [--jobs "8 16 32"] [--repeats R]
#                           [--client logi|python|both] [--markdown FILE] [--keep DIR]
#   --hil PATH       the hil binary (default: build/apps/hil/hil)
#   --jobs LIST      the widths to time, -j values (default: "2 8 16 32 auto")
#   --repeats R      gate runs per width and client (default 20)
#   --client WHICH   which correct client (default: both)
#   --markdown FILE  also writes the results as a Markdown table to FILE
#   --keep DIR       keeps the report folder of every gate run that failed in
#                    DIR/<client>-j<N>-<run> (timelines of every scenario)
# Exits 1 when any run failed (the table says which scenarios).
set -euo pipefail
cd "$(dirname "$0")/.."

hil=build/apps/hil/hil
jobs_list="2 8 16 32 auto"
repeats=20
which=both
markdown=
keep=
while [ $# -gt 0 ]; do
  case $1 in
    --hil) hil=$2; shift 2 ;;
    --jobs) jobs_list=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --client) which=$2; shift 2 ;;
    --markdown) markdown=$2; shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    *) echo "bench/gate_time.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$hil" ] || { echo "bench/gate_time.sh: no hil binary at $hil (--hil PATH)" >&2; exit 2; }
case $repeats in '' | *[!0-9]* | 0) echo "bench/gate_time.sh: --repeats takes a number >= 1" >&2; exit 2 ;; esac
build_dir=$(dirname "$(dirname "$(dirname "$hil")")")
logi_client="$build_dir/apps/logi-client/logi-client"

clients=()
case $which in
  logi | both)
    [ -x "$logi_client" ] || { echo "bench/gate_time.sh: no logi-client at $logi_client" >&2; exit 2; }
    clients+=("logi-client|$logi_client --stdin-actions --host {host} --port {port}")
    ;;&
  python | both) clients+=("Python client|python3 tests/gate/clients/logi_good.py {host} {port}") ;;
  logi) ;;
  *) echo "bench/gate_time.sh: --client takes logi, python or both" >&2; exit 2 ;;
esac

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0
rows=()
for client in "${clients[@]}"; do
  name=${client%%|*}
  command=${client#*|}
  for jobs in $jobs_list; do
    walls=()
    bad_runs=0
    : >"$work/failures"
    for ((r = 1; r <= repeats; r++)); do
      out="$work/run.txt"
      t0=$(date +%s.%N)
      status=0
      report=()
      [ -z "$keep" ] || report=(--report-dir "$work/report")
      rm -rf "$work/report"
      "$hil" run scenarios/logi -j "$jobs" --client-exec "$command" "${report[@]}" >"$out" 2>&1 ||
        status=$?
      t1=$(date +%s.%N)
      walls+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')")
      if [ $status -ne 0 ]; then
        bad_runs=$((bad_runs + 1))
        failed=1
        awk '$2 == "FAIL" || $2 == "FLAKY" { print $1 }' "$out" >>"$work/failures"
        if [ -n "$keep" ]; then
          kept="$keep/${name// /-}-j$jobs-$r"
          mkdir -p "$keep" && rm -rf "$kept" && mv "$work/report" "$kept" && cp "$out" "$kept/output.txt"
          echo "bench/gate_time.sh: its report: $kept" >&2
        fi
        echo "bench/gate_time.sh: $name -j $jobs run $r failed:" >&2
        # Each failure's block: what was expected, what was seen, the repeat command.
        awk '/^(FAIL|FLAKY) / { show = 1 } show { print } /^  repeat: / { show = 0 }' "$out" >&2
      fi
      echo "bench/gate_time.sh: $name -j $jobs run $r/$repeats: ${walls[-1]} s, exit $status" >&2
    done
    stats=$(printf '%s\n' "${walls[@]}" | sort -n |
      awk '{ v[NR] = $1 } END { printf "%s / %s / %s", v[1], v[int((NR + 1) / 2)], v[NR] }')
    failures=$(sort "$work/failures" | uniq -c | awk '{ printf "%s%s x%s", (NR > 1 ? ", " : ""), $2, $1 }')
    rows+=("| $name | \`-j $jobs\` | $repeats | $stats s | $bad_runs | ${failures:--} |")
  done
done

table=$(
  echo "| client | width | gate runs | wall time min / median / max | runs with a failure | scenarios that failed |"
  echo "|---|---|---:|---:|---:|---|"
  printf '%s\n' "${rows[@]}"
  echo
  echo "Each run: \`hil run scenarios/logi -j N --client-exec CLIENT\`, $(ls scenarios/logi/*.yaml | wc -l) scenario files, one after another."
)
echo "$table"
[ -z "$markdown" ] || echo "$table" >"$markdown"
exit $failed

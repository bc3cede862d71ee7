#!/usr/bin/env bash
# Times the whole scenario library the way CI runs it: `hil run scenarios/
# -j 2`, the scenarios that run in virtual time apart from those that run in
# real time (real_time: true or an exec client), since only the first can be
# made faster by a faster machine or a faster hil. Target: under 60 s of
# wall time for the virtual-time ones on 2 cores.
# Usage: bench/suite_time.sh [--hil PATH] [--markdown FILE] [--jobs N]
#   --hil PATH       the hil binary (default: build/apps/hil/hil)
#   --markdown FILE  also writes the results as a Markdown table to FILE
#   --jobs N         runs at a time (default 2, the target's cores)
# Exits 1 when a scenario fails (the table says how many passed).
set -euo pipefail
cd "$(dirname "$0")/.."

hil=build/apps/hil/hil
markdown=
jobs=2
while [ $# -gt 0 ]; do
  case $1 in
    --hil) hil=$2; shift 2 ;;
    --markdown) markdown=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    *) echo "bench/suite_time.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$hil" ] || { echo "bench/suite_time.sh: no hil binary at $hil (--hil PATH)" >&2; exit 2; }

target_s=60
virtual=()
real=()
# The scenarios hil would run (--list), each sorted by how its client runs.
while read -r file _; do
  [ -f "$file" ] || continue
  if grep -Eq '^[[:space:]]*(real_time:[[:space:]]*true|exec:)' "$file" ||
    grep -Eq '(\{|,)[[:space:]]*(real_time:[[:space:]]*true|exec:)' "$file"; then
    real+=("$file")
  else
    virtual+=("$file")
  fi
done < <("$hil" run scenarios/ --list)

# Wall and CPU seconds (this shell's children: hil and what it started).
timed_run() {
  local out=$1
  shift
  local t0 t1 c0 c1
  t0=$(date +%s.%N)
  c0=$(awk '{print $14 + $15 + $16 + $17}' /proc/$$/stat)
  local status=0
  "$hil" run -j "$jobs" "$@" >"$out" 2>&1 || status=$?
  t1=$(date +%s.%N)
  c1=$(awk '{print $14 + $15 + $16 + $17}' /proc/$$/stat)
  local ticks
  ticks=$(getconf CLK_TCK)
  wall_s=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')
  cpu_s=$(awk -v a="$c0" -v b="$c1" -v t="$ticks" 'BEGIN { printf "%.2f", (b - a) / t }')
  passed=$(awk '$2 == "PASS"' "$out" | wc -l)
  ran=$(awk '$2 == "PASS" || $2 == "FAIL"' "$out" | wc -l)
  sim_s=$(awk '($2 == "PASS" || $2 == "FAIL") && $5 == "sim" { s += $3 } END { printf "%.0f", s }' "$out")
  return $status
}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0
timed_run "$work/virtual.txt" "${virtual[@]}" || failed=1
virtual_wall=$wall_s virtual_cpu=$cpu_s virtual_sim=$sim_s virtual_passed="$passed of $ran"
real_wall=- real_cpu=- real_passed=-
if [ ${#real[@]} -gt 0 ]; then
  timed_run "$work/real.txt" "${real[@]}" || failed=1
  real_wall=$wall_s real_cpu=$cpu_s real_passed="$passed of $ran"
fi
verdict=$(awk -v w="$virtual_wall" -v t="$target_s" 'BEGIN { print (w < t) ? "under" : "OVER" }')
table=$(
  echo "| scenarios | passed | wall time | CPU time (all processes) | simulated time |"
  echo "|---|---:|---:|---:|---:|"
  echo "| in virtual time | ${virtual_passed} | ${virtual_wall} s | ${virtual_cpu} s | ${virtual_sim} s |"
  echo "| in real time (not held to the target) | ${real_passed} | ${real_wall} s | ${real_cpu} s | - |"
  echo
  echo "The virtual-time library: ${virtual_wall} s of wall time with \`-j $jobs\`," \
    "$verdict the target of ${target_s} s."
)
echo "$table"
[ -z "$markdown" ] || echo "$table" >"$markdown"
if [ $failed -ne 0 ]; then
  cat "$work"/*.txt | grep -E '^FAIL' >&2 || true
  echo "bench/suite_time.sh: a scenario failed (above)" >&2
  exit 1
fi

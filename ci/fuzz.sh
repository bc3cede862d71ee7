#!/usr/bin/env bash
# The long fuzzing run: builds the libFuzzer targets (fuzz preset: clang,
# -O2, ASan + UBSan) and runs each in turn, keeping its corpus between runs.
#
#   ci/fuzz.sh [options] [MINUTES_PER_TARGET] [TARGET...]
#
#   MINUTES_PER_TARGET  default 3; TARGET is a name from tests/fuzz/ without
#                       "_fuzz" (logi, scenario, wr8_firmware, ...); default all.
#   --seconds=N         run each target N seconds instead (the CI smoke run).
#   --work=DIR          where corpora, logs and crash artifacts live
#                       (default TREE/fuzz-work; kept between runs).
#   --merge             afterwards, add the inputs that reach new coverage to
#                       the checked-in seeds in tests/fuzz/corpus/<target>/.
#   --preset=NAME       the tree whose targets run: fuzz (default, build-fuzz/,
#                       optimised) or asan (build-asan/, the Debug tree of the
#                       sanitizer stage, which builds them too).
#   --no-build          use the targets already in the tree.
#   --jobs=N            run N targets at a time (default 1; the CI smoke run
#                       uses one per core).
#
# Each target starts from tests/fuzz/corpus/<target>/ plus what earlier runs
# found. A crash, leak, timeout or out-of-memory input is saved as
# DIR/artifacts/<target>-<kind>-<sha1> and fails the run; replay one with
# TREE/tests/fuzz/<target>_fuzz DIR/artifacts/<file>. The last line is
# "fuzz: N target(s) passed, M failed".
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=""
minutes=3
work=""
preset=fuzz
merge=0
build=1
jobs=1
targets=()
for arg in "$@"; do
  case "$arg" in
    --seconds=*) seconds="${arg#*=}" ;;
    --work=*) work="${arg#*=}" ;;
    --merge) merge=1 ;;
    --preset=*) preset="${arg#*=}" ;;
    --no-build) build=0 ;;
    --jobs=*) jobs="${arg#*=}" ;;
    -h | --help) sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "ci/fuzz.sh: unknown option $arg" >&2; exit 2 ;;
    *)
      if [[ "$arg" =~ ^[0-9]+([.][0-9]+)?$ ]] && [ ${#targets[@]} -eq 0 ] && [ -z "${minutes_given:-}" ]; then
        minutes="$arg"; minutes_given=1
      else
        targets+=("$arg")
      fi ;;
  esac
done
[[ "$jobs" =~ ^[1-9][0-9]*$ ]] || { echo "ci/fuzz.sh: --jobs wants a positive number, got '$jobs'" >&2; exit 2; }
case "$preset" in
  fuzz | asan) tree="build-$preset" ;;
  *) echo "ci/fuzz.sh: --preset takes fuzz or asan, got '$preset'" >&2; exit 2 ;;
esac
[ -n "$work" ] || work="$tree/fuzz-work"
[ -n "$seconds" ] || seconds=$(awk -v m="$minutes" 'BEGIN { printf "%d", m * 60 }')

if [ "$build" = 1 ]; then
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" --target hil_fuzzers
fi

if [ ${#targets[@]} -eq 0 ]; then
  for fuzzer in "$tree"/tests/fuzz/*_fuzz; do
    [ -x "$fuzzer" ] && targets+=("$(basename "$fuzzer" _fuzz)")
  done
fi
[ ${#targets[@]} -gt 0 ] || { echo "ci/fuzz.sh: no fuzz targets were built" >&2; exit 1; }

mkdir -p "$work/corpus" "$work/logs" "$work/artifacts" "$work/rows"
summary="$work/summary.txt"
printf '%-18s %12s %9s %8s %8s %8s  %s\n' target runs execs/s cov ft corpus result >"$summary"

# run_target NAME: one fuzzer for $seconds; its console lines go to
# $work/rows/NAME.out, its summary row to NAME.row, and its exit status says
# whether it passed. Targets share nothing, so several run side by side.
run_target() {
  local name=$1 fuzzer="$tree/tests/fuzz/${1}_fuzz"
  local row="$work/rows/$name.row" out="$work/rows/$name.out"
  if [ ! -x "$fuzzer" ]; then
    echo "ci/fuzz.sh: no target $name (looked for $fuzzer)" >"$out"
    printf '%-18s %12s %9s %8s %8s %8s  %s\n' "$name" - - - - - "not built" >"$row"
    return 1
  fi
  local corpus="$work/corpus/$name" log="$work/logs/$name.log"
  mkdir -p "$corpus"
  # Seeds are copied in, so the source tree is only written with --merge.
  if [ -d "tests/fuzz/corpus/$name" ]; then cp -n tests/fuzz/corpus/"$name"/* "$corpus"/ 2>/dev/null || true; fi
  echo "-- $name: ${seconds}s" >"$out"
  local result=ok status=0
  # -timeout: one input taking 10 s is a hang; -rss_limit_mb: a leak-like
  # growth is a finding, not a machine brought to its knees.
  if ! "$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$work/artifacts/$name-" "$corpus" >"$log" 2>&1; then
    result="FAILED"
    local artifact
    artifact=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -1)
    [ -z "$artifact" ] || result="FAILED: $artifact"
    status=1
    { echo "FAILED: $name (last lines of $log follow)"; tail -40 "$log"; } >>"$out"
  fi
  local runs speed cov ft files
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -oE 'ft: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
  files=$(find "$corpus" -type f | wc -l)
  printf '%-18s %12s %9s %8s %8s %8s  %s\n' "$name" "${runs:--}" "${speed:--}" "${cov:--}" \
    "${ft:--}" "$files" "$result" >"$row"
  if [ "$merge" = 1 ] && [ "$result" = ok ]; then
    mkdir -p "tests/fuzz/corpus/$name"
    # -merge=1 adds to the first folder only inputs that reach new features.
    "$fuzzer" -merge=1 -timeout=10 "tests/fuzz/corpus/$name" "$corpus" >>"$log" 2>&1
  fi
  return "$status"
}

# At most $jobs targets at a time; each one's lines are printed when it ends.
declare -A name_of=()
passed=0
failed=0
reap_one() {
  local done_pid status=0
  wait -n -p done_pid || status=$?
  if [ "$status" -eq 0 ]; then passed=$((passed + 1)); else failed=$((failed + 1)); fi
  cat "$work/rows/${name_of[$done_pid]}.out"
  unset "name_of[$done_pid]"
}
for name in "${targets[@]}"; do
  while [ "${#name_of[@]}" -ge "$jobs" ]; do reap_one; done
  run_target "$name" &
  name_of[$!]=$name
done
while [ "${#name_of[@]}" -gt 0 ]; do reap_one; done
for name in "${targets[@]}"; do cat "$work/rows/$name.row" >>"$summary"; done

echo
cat "$summary"
echo "fuzz: $passed target(s) passed, $failed failed"
[ "$failed" -eq 0 ]

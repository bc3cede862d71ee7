#!/usr/bin/env bash
# Sets up this machine (Debian 12) and runs every test hil has:
#   1. the default RelWithDebInfo build (clang) and its whole CTest suite,
#   2. the same suite built with AddressSanitizer + UndefinedBehaviorSanitizer
#      (clang), in a tree that builds the libFuzzer targets too,
#   3. the tests that start threads, processes or real sockets and ptys
#      (label `threads`, from every source folder) built with ThreadSanitizer,
#   4. a short run of every libFuzzer target of that tree (ci/fuzz-smoke.sh).
# It ends with the wall time of each stage and of the whole run.
#
#   ci/run-tests.sh                 everything, as CI runs it
#   ci/run-tests.sh --default-only  stage 1 alone: the fast path while developing
#
# HIL_SKIP_ASAN=1, HIL_SKIP_TSAN=1 or HIL_SKIP_FUZZ=1 leave one stage out;
# HIL_FUZZ_SECONDS=N gives each fuzz target N seconds (default 10).
# docs/ci.md has the stages, what each one costs and why.
set -euo pipefail
cd "$(dirname "$0")/.."

default_only=0
for arg in "$@"; do
  case "$arg" in
    --default-only) default_only=1 ;;
    -h | --help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "ci/run-tests.sh: unknown argument '$arg' (try --help)" >&2; exit 2 ;;
  esac
done

run_start=$SECONDS
stage_names=()
stage_seconds=()
stage_start=$SECONDS
# stage NAME: ends the stage that was running (if any) and starts NAME.
current_stage=""
stage() {
  if [ -n "$current_stage" ]; then
    stage_names+=("$current_stage")
    stage_seconds+=($((SECONDS - stage_start)))
  fi
  current_stage=$1
  stage_start=$SECONDS
  [ -z "$1" ] || echo "== $1"
}
# The table of stage times: on success just before the closing line, on a
# failure on the way out, so a slow stage shows in every CI log.
print_times() {
  echo
  echo "stage times (wall):"
  local i total=$((SECONDS - run_start))
  for i in "${!stage_names[@]}"; do
    printf '  %-34s %5d s  (%d min %02d s)\n' "${stage_names[$i]}" "${stage_seconds[$i]}" \
      $((stage_seconds[i] / 60)) $((stage_seconds[i] % 60))
  done
  printf '  %-34s %5d s  (%d min %02d s)\n' "total" "$total" $((total / 60)) $((total % 60))
  local tree sizes=()
  for tree in build build-asan build-tsan; do
    [ ! -d "$tree" ] || sizes+=("$tree $(gib "$(tree_kib "$tree")")")
  done
  local joined="none"
  [ "${#sizes[@]}" = 0 ] || joined=$(printf '%s, ' "${sizes[@]}")
  echo "trees: ${joined%, }; disk: $(gib "$(free_kib)") free"
}
on_exit() {
  local status=$?
  if [ "$status" -ne 0 ]; then
    stage ""
    print_times
    local free
    free=$(free_kib)
    if [ "$free" -lt 1048576 ]; then
      echo "ci/run-tests.sh: the disk that holds $(pwd) has $(gib "$free") free: a build or" \
        "test that failed may have found it full (docs/ci.md, \"Disk\")" >&2
    fi
  fi
  rm -f "$log"
  exit "$status"
}
log=$(mktemp)
trap on_exit EXIT

# Disk: the trees a run builds need room on the disk that holds them
# (docs/ci.md, "Disk"). A disk with less free space than the run still
# needs gets a warning at the start; a failed run says how much was left.
gib() { awk -v k="$1" 'BEGIN { printf "%.1f GiB", k / 1048576 }'; }
free_kib() { df -Pk . | awk 'NR == 2 { print $4 }'; }
# The size of the trees that exist among "$@" (0 when none does).
tree_kib() { { du -sk "$@" 2>/dev/null || true; } | awk '{ s += $1 } END { print s + 0 }'; }
disk_check() {
  # The trees' sizes in KiB, as measured in docs/ci.md, with room for the
  # tests' scratch files.
  local need=$((2 * 1048576)) trees=(build)
  if [ "$default_only" = 0 ]; then
    [ "${HIL_SKIP_ASAN:-0}" = 1 ] || { need=$((need + 4 * 1048576)); trees+=(build-asan); }
    [ "${HIL_SKIP_TSAN:-0}" = 1 ] || { need=$((need + 1048576)); trees+=(build-tsan); }
  fi
  local have free
  have=$(tree_kib "${trees[@]}")
  free=$(free_kib)
  echo "disk: $(gib "$free") free; this run's trees need about $(gib "$need") ($(gib "$have") built already)"
  if [ $((free + have)) -lt "$need" ]; then
    echo "ci/run-tests.sh: warning: the disk that holds $(pwd) has $(gib "$free") free, and" \
      "this run needs about $(gib $((need - have))) more; a build may stop with 'Disk full'" >&2
  fi
}

stage "install dependencies"
bash ci/install-deps.sh
disk_check

# Number of tests CTest ran, from its closing line ("... out of N").
ran() { sed -n 's/.*tests failed out of \([0-9]*\).*/\1/p' "$log" | tail -1; }
passed=0

stage "default: build"
cmake --preset default
cmake --build --preset default
stage "default: tests"
ctest --preset default | tee "$log"
passed=$((passed + $(ran)))

if [ "$default_only" = 0 ] && [ "${HIL_SKIP_ASAN:-0}" != 1 ]; then
  stage "asan+ubsan: build"
  cmake --preset asan
  cmake --build --preset asan
  stage "asan+ubsan: tests"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    LSAN_OPTIONS=suppressions=$PWD/ci/lsan-suppressions.txt:print_suppressions=0 \
    ctest --preset asan | tee "$log"
  passed=$((passed + $(ran)))
fi

if [ "$default_only" = 0 ] && [ "${HIL_SKIP_TSAN:-0}" != 1 ]; then
  stage "tsan: build (threaded tests)"
  cmake --preset tsan
  cmake --build --preset tsan   # only hil_threaded_tests (CMakePresets.json)
  stage "tsan: tests"
  ctest --preset tsan | tee "$log"
  passed=$((passed + $(ran)))
fi

if [ "$default_only" = 0 ] && [ "${HIL_SKIP_FUZZ:-0}" != 1 ]; then
  stage "fuzz: smoke run (asan tree)"
  bash ci/fuzz-smoke.sh "${HIL_FUZZ_SECONDS:-10}" | tee "$log"
  passed=$((passed + $(sed -n 's/^fuzz smoke: \([0-9]*\) target.*/\1/p' "$log")))
fi

stage ""
print_times
# Reached only when every stage passed (set -e, pipefail).
echo "hil: $passed passed, 0 failed"

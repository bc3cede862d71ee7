#!/usr/bin/env bash
# Sets up this machine (Debian 12) and runs every test hil has:
#   1. the default RelWithDebInfo build and its CTest suite,
#   2. the same suite built with AddressSanitizer + UndefinedBehaviorSanitizer,
#   3. the same suite built with ThreadSanitizer,
#   4. a short smoke run of every libFuzzer target (ci/fuzz-smoke.sh).
# Set HIL_SKIP_ASAN=1, HIL_SKIP_TSAN=1 or HIL_SKIP_FUZZ=1 to leave a stage
# out locally.
set -euo pipefail
cd "$(dirname "$0")/.."

bash ci/install-deps.sh

log=$(mktemp)
trap 'rm -f "$log"' EXIT
# Number of tests CTest ran, from its closing line ("... out of N").
ran() { sed -n 's/.*tests failed out of \([0-9]*\).*/\1/p' "$log" | tail -1; }
passed=0

echo "== default build and tests"
cmake --preset default
cmake --build --preset default
ctest --preset default | tee "$log"
passed=$((passed + $(ran)))

if [ "${HIL_SKIP_ASAN:-0}" != 1 ]; then
  echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests"
  cmake --preset asan
  cmake --build --preset asan
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --preset asan | tee "$log"
  passed=$((passed + $(ran)))
fi

if [ "${HIL_SKIP_TSAN:-0}" != 1 ]; then
  echo "== ThreadSanitizer build and tests"
  cmake --preset tsan
  cmake --build --preset tsan
  ctest --preset tsan | tee "$log"
  passed=$((passed + $(ran)))
fi

if [ "${HIL_SKIP_FUZZ:-0}" != 1 ]; then
  echo "== fuzz smoke run"
  bash ci/fuzz-smoke.sh "${HIL_FUZZ_SECONDS:-20}" | tee "$log"
  passed=$((passed + $(sed -n 's/^fuzz smoke: \([0-9]*\) target.*/\1/p' "$log")))
fi

# Reached only when every stage passed (set -e, pipefail).
echo "hil: $passed passed, 0 failed"

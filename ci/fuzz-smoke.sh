#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) and runs each for a few
# seconds from its seed corpus. Usage: ci/fuzz-smoke.sh [SECONDS_PER_TARGET]
# A longer hunt: ci/fuzz-smoke.sh 3600 (opt-in; CI uses a short run).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-20}"

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0
ran=0
for fuzzer in build-fuzz/tests/fuzz/*_fuzz; do
  [ -x "$fuzzer" ] || continue
  name=$(basename "$fuzzer" _fuzz)
  corpus="$work/$name"
  mkdir -p "$corpus"
  # Copy the seed corpus so the run never writes into the source tree.
  if [ -d "tests/fuzz/corpus/$name" ]; then cp tests/fuzz/corpus/"$name"/* "$corpus"/ 2>/dev/null || true; fi
  echo "-- $name: ${seconds}s"
  if "$fuzzer" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$work/$name-" \
      "$corpus" >"$work/$name.log" 2>&1; then
    grep -E "stat::number_of_executed_units|Done [0-9]+ runs" "$work/$name.log" | head -2
    ran=$((ran + 1))
  else
    echo "FAILED: $name (last lines of its log follow)"
    tail -40 "$work/$name.log"
    failed=1
  fi
done
echo "fuzz smoke: $ran target(s) passed"
[ "$ran" -gt 0 ] || { echo "no fuzz targets were built"; exit 1; }
exit "$failed"

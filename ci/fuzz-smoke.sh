#!/usr/bin/env bash
# The CI fuzz run: every libFuzzer target for a few seconds from its seed
# corpus (ci/fuzz.sh with seconds instead of minutes, in a throw-away work
# folder), one target per core at a time (HIL_FUZZ_JOBS sets how many).
# The targets come from the asan tree (build-asan/), which the sanitizer
# stage has built already; HIL_FUZZ_PRESET=fuzz runs the optimised ones.
# Usage: ci/fuzz-smoke.sh [SECONDS_PER_TARGET]
# The long hunt is ci/fuzz.sh (minutes per target, corpora kept).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-10}"
preset="${HIL_FUZZ_PRESET:-asan}"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
bash ci/fuzz.sh --preset="$preset" --seconds="$seconds" --jobs="${HIL_FUZZ_JOBS:-$(nproc)}" --work="$work" | tee "$work/out" || status=$?
# Crash artifacts would vanish with the work folder; keep them for CI.
if compgen -G "$work/artifacts/*" >/dev/null; then
  mkdir -p "build-$preset/fuzz-artifacts"
  cp "$work"/artifacts/* "build-$preset/fuzz-artifacts/"
  echo "crash inputs kept in build-$preset/fuzz-artifacts/"
fi
ran=$(sed -n 's/^fuzz: \([0-9]*\) target(s) passed.*/\1/p' "$work/out")
echo "fuzz smoke: ${ran:-0} target(s) passed"
[ "${ran:-0}" -gt 0 ] || { echo "no fuzz targets were built"; exit 1; }
exit "$status"

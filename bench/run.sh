#!/usr/bin/env bash
# Runs the decoder, proxy, simulation, mock-car, random-session and
# whole-stack benchmarks and times the scenario suite on a RelWithDebInfo
# build, and rewrites their sections of docs/performance.md with the results.
# Usage: bench/run.sh [decoder] [proxy] [sim] [mock] [firmware] [session] [stack] [suite] [gate]
#   With no section named, runs them all but gate (the LOGI gate in real time
#   at several widths, 20 runs each: about 90 minutes; name it to run it). Each section is rewritten only when
#   its benchmark ran to the end, so one section can be refreshed alone
#   (bench/run.sh mock). Run on an otherwise idle machine.
#   HIL_BUILD_DIR=DIR builds and runs in an already configured build tree
#   instead of the default preset's build/.
set -euo pipefail
cd "$(dirname "$0")/.."

sections=("$@")
[ ${#sections[@]} -gt 0 ] || sections=(decoder proxy sim mock firmware session stack suite)
for section in "${sections[@]}"; do
  case $section in
    decoder | proxy | sim | mock | firmware | session | stack | suite | gate) ;;
    *)
      echo "bench/run.sh: unknown section '$section' (decoder, proxy, sim, mock, firmware, session, stack, suite, gate)" >&2
      exit 2
      ;;
  esac
done

build=${HIL_BUILD_DIR:-build}
[ -n "${HIL_BUILD_DIR:-}" ] || cmake --preset default >/dev/null
doc=docs/performance.md
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

today() { date -u +%Y-%m-%d; }
machine() {
  echo "$(nproc) core(s), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')"
}

# Replaces the lines between <!-- NAME:begin --> and <!-- NAME:end --> in the
# page with the contents of FILE.
splice() {
  local name=$1 file=$2
  local begin="<!-- $name:begin -->" end="<!-- $name:end -->"
  if ! grep -qxF "$begin" "$doc" || ! grep -qxF "$end" "$doc"; then
    echo "bench/run.sh: $doc has no '$begin' ... '$end' markers" >&2
    exit 1
  fi
  awk -v begin="$begin" -v end="$end" -v file="$file" '
    $0 == begin { print; while ((getline line < file) > 0) print line; skip = 1; next }
    $0 == end { skip = 0 }
    !skip { print }
  ' "$doc" >"$doc.new"
  mv "$doc.new" "$doc"
}

# Puts FILE in the page's NAME-bench section, under a line saying when, on
# what and how it was measured ("with `COMMAND` (HOW):"), with paths into
# this checkout made relative. A blank line closes the section unless the
# fifth argument is "no" (FILE ends with one).
write_section() {
  local name=$1 command=$2 how=$3 file=$4 blank_end=${5:-yes}
  {
    echo
    echo "Measured $(today) on $(machine),"
    echo "with \`$command\` ($how):"
    echo
    sed "s|$PWD/||" "$file"
    [ "$blank_end" = no ] || echo
  } >"$work/$name.section"
  splice "$name-bench" "$work/$name.section"
}

# Builds the Google Benchmark program TARGET, runs it with ARGS and
# --hil_markdown, and writes its table to the NAME-bench section.
#   run_benchmark NAME TARGET COMMAND HOW ARGS...
run_benchmark() {
  local name=$1 target=$2 command=$3 how=$4
  shift 4
  cmake --build "$build" --target "$target"
  "$build/bench/$target" "$@" --hil_markdown="$work/$name.md"
  write_section "$name" "$command" "$how" "$work/$name.md"
}

run_decoder() {
  run_benchmark decoder decoder_bench "bench/run.sh" \
    "best of 5 repetitions, 1 MiB stream per iteration" \
    --benchmark_min_time=0.5 --benchmark_repetitions=5 --hil_max_bytewise_ratio=5
}

run_proxy() {
  cmake --build "$build" --target proxy_bench
  "$build"/bench/proxy_bench --frames 20000 --mib 256 --protocol raw --markdown "$work/proxy.md"
  "$build"/bench/proxy_bench --frames 20000 --mib 128 --protocol logi --markdown "$work/proxy.md"
  write_section proxy "bench/run.sh proxy" \
    "20,000 round trips, 256 MiB raw / 128 MiB LOGI one way, wall time" "$work/proxy.md" no
}

run_sim() {
  run_benchmark sim sim_bench "bench/run.sh" \
    "best of 5 interleaved repetitions of at least 0.5 s, CPU time" \
    --benchmark_min_time=0.5 --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
}

run_mock() {
  run_benchmark mock mock_bench "bench/run.sh mock" \
    "best of 5 interleaved repetitions of at least 0.5 s, CPU time" \
    --benchmark_min_time=0.5 --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
}

# The emulated board in virtual time, then behind a pty in real time; both
# tables go to the firmware-bench section.
run_firmware() {
  cmake --build "$build" --target firmware_bench firmware_pty_bench
  "$build/bench/firmware_bench" --benchmark_min_time=0.5 --benchmark_repetitions=5 \
    --benchmark_enable_random_interleaving=true --hil_markdown="$work/firmware.md"
  "$build/bench/firmware_pty_bench" --elf "$build/firmware/hil_arduino.elf" --requests 300 \
    --markdown "$work/firmware-pty.md"
  { cat "$work/firmware.md"; echo; cat "$work/firmware-pty.md"; } >"$work/firmware-both.md"
  write_section firmware "bench/run.sh firmware" \
    "virtual time: best of 5 interleaved repetitions of at least 0.5 s, CPU time; real time: 300 PINGs one at a time" \
    "$work/firmware-both.md"
}

run_session() {
  run_benchmark session session_bench "bench/run.sh session" \
    "best of 5 repetitions of at least 0.5 s, CPU time" \
    --benchmark_min_time=0.5 --benchmark_repetitions=5 --hil_min_sessions_per_s=20
}

run_stack() {
  run_benchmark stack scenario_bench "bench/run.sh stack" \
    "best of 5 interleaved repetitions of at least 0.5 s, CPU time" \
    --benchmark_min_time=0.5 --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
}

run_suite() {
  cmake --build "$build" --target hil
  # A failing scenario still leaves a suite time; the table says how many
  # passed, and the failure is printed above it.
  bench/suite_time.sh --hil "$build"/apps/hil/hil --jobs 2 --markdown "$work/suite.md" ||
    echo "bench/run.sh: a scenario failed; the suite section says how many passed" >&2
  [ -s "$work/suite.md" ] || exit 1
  write_section suite "bench/run.sh suite" \
    '`hil run -j 2`, wall time of one run of the library' "$work/suite.md"
}

# The LOGI gate with each correct external client at several widths, 20
# whole runs each (bench/gate_time.sh). A flake fails the section's run but
# still writes the table, which says which scenarios failed.
run_gate() {
  cmake --build "$build" --target hil logi-client
  bench/gate_time.sh --hil "$build"/apps/hil/hil --jobs "${HIL_GATE_JOBS:-8 16 32 54}" \
    --repeats "${HIL_GATE_REPEATS:-20}" --markdown "$work/gate.md" ||
    echo "bench/run.sh: a gate run failed; the gate section says which scenarios" >&2
  [ -s "$work/gate.md" ] || exit 1
  write_section gate "bench/run.sh gate" \
    'wall time of whole gate runs one after another, each client alone' "$work/gate.md"
}

# Load average when the figures were taken: CPU times and in-run ratios are
# what stays fair on a shared machine, but the page says how busy it was.
load_note() {
  echo "Load average at the end of the run: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) core(s)."
}

for section in "${sections[@]}"; do
  "run_$section"
done
load_note
echo "updated $doc"

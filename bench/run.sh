#!/usr/bin/env bash
# Runs the decoder, proxy and simulation benchmarks on the default
# (RelWithDebInfo) build and rewrites their sections of docs/performance.md
# with the results.
# Usage: bench/run.sh   (run on an otherwise idle machine)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset default >/dev/null
cmake --build --preset default --target decoder_bench proxy_bench sim_bench
table=$(mktemp)
proxy_table=$(mktemp)
sim_table=$(mktemp)
trap 'rm -f "$table" "$proxy_table" "$sim_table"' EXIT
build/bench/decoder_bench --benchmark_min_time=0.5 --benchmark_repetitions=5 \
  --hil_max_bytewise_ratio=5 --hil_markdown="$table"

build/bench/proxy_bench --frames 20000 --mib 256 --protocol raw --markdown "$proxy_table"
build/bench/proxy_bench --frames 20000 --mib 128 --protocol logi --markdown "$proxy_table"

build/bench/sim_bench --benchmark_min_time=0.5 --benchmark_repetitions=5 \
  --benchmark_enable_random_interleaving=true --hil_markdown="$sim_table"

doc=docs/performance.md
begin='<!-- decoder-bench:begin -->'
end='<!-- decoder-bench:end -->'
{
  sed "/$begin/q" "$doc"
  echo
  echo "Measured $(date -u +%Y-%m-%d) on $(nproc) core(s), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'),"
  echo "with \`bench/run.sh\` (best of 5 repetitions, 1 MiB stream per iteration):"
  echo
  cat "$table"
  echo
  sed -n "/$end/,/proxy-bench:begin/p" "$doc"
  echo
  echo "Measured $(date -u +%Y-%m-%d) with \`bench/run.sh\` (20,000 round trips, 256 MiB raw / 128 MiB LOGI one way):"
  echo
  cat "$proxy_table"
  sed -n "/proxy-bench:end/,/sim-bench:begin/p" "$doc"
  echo
  echo "Measured $(date -u +%Y-%m-%d) on $(nproc) core(s), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'),"
  echo "with \`bench/run.sh\` (best of 5 interleaved repetitions of at least 0.5 s, CPU time):"
  echo
  cat "$sim_table"
  echo
  sed -n "/sim-bench:end/,\$p" "$doc"
} > "$doc.new"
mv "$doc.new" "$doc"
echo "updated $doc"

#!/usr/bin/env bash
# Runs the decoder benchmarks on the default (RelWithDebInfo) build and
# rewrites the decoder section of docs/performance.md with the results.
# Usage: bench/run.sh   (run on an otherwise idle machine)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset default >/dev/null
cmake --build --preset default --target decoder_bench
table=$(mktemp)
trap 'rm -f "$table"' EXIT
build/bench/decoder_bench --benchmark_min_time=0.5 --benchmark_repetitions=5 \
  --hil_max_bytewise_ratio=5 --hil_markdown="$table"

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
  sed -n "/$end/,\$p" "$doc"
} > "$doc.new"
mv "$doc.new" "$doc"
echo "updated $doc"

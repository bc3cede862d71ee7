#!/usr/bin/env bash
# The long soak (`ctest -C soak -L soak`) as shard K of N, so that N
# machines share it:
#
#   ci/soak-shard.sh K/N [--sessions TOTAL] [--seed BASE] [--build-dir DIR]
#                        [--properties-only] [--dry-run]
#
# - Each property program (the soak.property_* tests: thousands of random
#   sessions per property) runs TOTAL/N of TOTAL sessions per property
#   (the first TOTAL mod N shards one more), with rapidcheck seed
#   BASE*N + K-1: the N shards together run TOTAL sessions per property,
#   each shard from a seed of its own. The programs are run directly with
#   RC_PARAMS="seed=S max_success=M" (the soak tests' own RC_PARAMS, set
#   by CTest, would otherwise win).
# - The other soak tests (the gate's long real-time runs) are split by
#   CTest's stride: `ctest -C soak -L soak -E '^soak\.property_' -I K,,N`.
#
# The default TOTAL is 5000, the soak tests' own; the default BASE is
# $HIL_SOAK_SEED, else 1. Give every shard of one soak the same TOTAL and
# BASE (a pipeline number makes a fresh soak each time). --dry-run prints
# what would run and runs nothing; --properties-only leaves the other soak
# tests out. Exit 0 everything passed, 1 something failed, 2 bad usage.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//'
}

die_usage() {
  echo "soak-shard: $1" >&2
  echo "usage: ci/soak-shard.sh K/N [--sessions TOTAL] [--seed BASE] [--build-dir DIR] [--properties-only] [--dry-run]" >&2
  exit 2
}

is_count() { [[ "$1" =~ ^[1-9][0-9]*$ ]]; }

shard=
sessions=5000
base=${HIL_SOAK_SEED:-1}
build_dir=build
dry_run=0
properties_only=0
while [ $# -gt 0 ]; do
  case "$1" in
    -h | --help)
      usage
      exit 0
      ;;
    --sessions | --seed | --build-dir)
      [ $# -ge 2 ] || die_usage "$1 needs a value"
      case "$1" in
        --sessions) sessions=$2 ;;
        --seed) base=$2 ;;
        --build-dir) build_dir=$2 ;;
      esac
      shift 2
      ;;
    --dry-run)
      dry_run=1
      shift
      ;;
    --properties-only)
      properties_only=1
      shift
      ;;
    -*) die_usage "unknown option $1" ;;
    *)
      [ -z "$shard" ] || die_usage "one K/N only (got $shard and $1)"
      shard=$1
      shift
      ;;
  esac
done

[ -n "$shard" ] || die_usage "which shard? give K/N (shard K of N, 1 <= K <= N)"
[[ "$shard" =~ ^([0-9]+)/([0-9]+)$ ]] || die_usage "'$shard' is not K/N (shard K of N, e.g. 2/4)"
k=${BASH_REMATCH[1]}
n=${BASH_REMATCH[2]}
is_count "$k" && is_count "$n" || die_usage "'$shard': K and N must be whole numbers of at least 1"
[ "$k" -le "$n" ] || die_usage "'$shard' names shard $k of only $n"
is_count "$sessions" || die_usage "--sessions '$sessions' is not a whole number of at least 1"
[[ "$base" =~ ^[0-9]+$ ]] || die_usage "--seed '$base' is not a whole number"
[ -f "$build_dir/CTestTestfile.cmake" ] || die_usage "$build_dir is not a configured build tree"

# This shard's share: TOTAL/N, one more for the first TOTAL mod N shards.
share=$((sessions / n + (k <= sessions % n ? 1 : 0)))
seed=$((base * n + k - 1))

# The soak property programs, as CTest would start them: name, folder, command.
programs=$(ctest --test-dir "$build_dir" -C soak -L soak -R '^soak\.property_' --show-only=json-v1 |
  python3 -c '
import json, shlex, sys
for t in json.load(sys.stdin)["tests"]:
    folder = next((p["value"] for p in t.get("properties", []) if p["name"] == "WORKING_DIRECTORY"), ".")
    print(t["name"], shlex.quote(folder), shlex.join(t["command"]))
')
count=$(printf '%s' "$programs" | grep -c . || true)

echo "soak shard $k/$n: $share of $sessions sessions per property in each of $count property programs, seed $seed"
status=0
failed=()
if [ "$share" -eq 0 ]; then
  echo "soak shard $k/$n: no property sessions (fewer sessions than shards)"
else
  while read -r name folder command; do
    [ -n "$name" ] || continue
    echo "$name: (cd $folder && RC_PARAMS='seed=$seed max_success=$share' $command)"
    [ "$dry_run" -eq 1 ] && continue
    if ! (cd "$(eval echo "$folder")" && RC_PARAMS="seed=$seed max_success=$share" eval "$command"); then
      failed+=("$name")
      status=1
    fi
  done <<<"$programs"
fi

if [ "$properties_only" -eq 1 ]; then
  others=()
  echo "the other soak tests: left out (--properties-only)"
else
  others=(ctest --test-dir "$build_dir" -C soak -L soak -E '^soak\.property_' -I "$k,,$n" --output-on-failure)
  echo "the other soak tests: ${others[*]}"
fi
if [ "$dry_run" -eq 1 ]; then
  [ ${#others[@]} -eq 0 ] || "${others[@]}" -N | sed -n 's/^ *Test *#[0-9]*: /  would run: /p'
  exit 0
fi
[ ${#others[@]} -eq 0 ] || "${others[@]}" || status=1

if [ ${#failed[@]} -gt 0 ]; then
  echo "soak shard $k/$n: failed: ${failed[*]} (RC_PARAMS='seed=$seed max_success=$share' repeats them)"
fi
[ "$status" -eq 0 ] && echo "soak shard $k/$n: passed"
exit "$status"

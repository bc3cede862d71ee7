#!/usr/bin/env bash
# The release gate for a client team: runs hil's scenarios against your
# client program (docs/client-contract.md) and exits with hil's status, so a
# CI job that runs it fails when the client misbehaves.
#
#   ci/client-gate.sh [options] CLIENT_COMMAND SCENARIO_FILE_OR_FOLDER...
#
# Example:
#   ci/client-gate.sh --junit gate.xml --report-dir gate-report \
#       "./acme-client --host {host} --port {port}" scenarios/logi
set -euo pipefail

usage() {
  cat <<'EOF'
usage: ci/client-gate.sh [options] CLIENT_COMMAND SCENARIO...

Runs `hil run SCENARIO... --client-exec CLIENT_COMMAND` and exits with its
status: 0 every scenario passed or was skipped, 1 a scenario failed, 2 bad usage.

CLIENT_COMMAND  the client to test, one shell command; hil fills in {host},
                {port}, {endpoint}, {pty}, {actions}, {scenario}
                (docs/client-contract.md)
SCENARIO        scenario files or folders, e.g. scenarios/logi

options:
  --junit FILE       write JUnit XML here (default: client-gate/junit.xml)
  --report-dir DIR   write the report folder here (default: client-gate/report)
  --tags a,b         run only the scenarios with one of these tags
  --repeat N         run each scenario N times (flakiness hunting)
  -j N, --jobs N     scenarios at a time (default: hil's -j auto, 16 per core for
                     an external client)
  --hil PATH         the hil program (default: $HIL, else hil on PATH, else
                     build/apps/hil/hil next to this script)
  -h, --help         this text
EOF
}

junit=client-gate/junit.xml
report_dir=client-gate/report
tags=
repeat=
jobs=
hil=${HIL:-}
positional=()

need_value() {
  if [ "$2" -lt 2 ]; then
    echo "client-gate: $1 needs a value" >&2
    usage >&2
    exit 2
  fi
}

while [ $# -gt 0 ]; do
  case "$1" in
    -h | --help)
      usage
      exit 0
      ;;
    --junit)
      need_value "$1" $#
      junit=$2
      shift 2
      ;;
    --report-dir)
      need_value "$1" $#
      report_dir=$2
      shift 2
      ;;
    --tags)
      need_value "$1" $#
      tags=$2
      shift 2
      ;;
    --repeat)
      need_value "$1" $#
      repeat=$2
      shift 2
      ;;
    -j | --jobs)
      need_value "$1" $#
      jobs=$2
      shift 2
      ;;
    --hil)
      need_value "$1" $#
      hil=$2
      shift 2
      ;;
    --)
      shift
      positional+=("$@")
      break
      ;;
    -*)
      echo "client-gate: unknown option $1" >&2
      usage >&2
      exit 2
      ;;
    *)
      positional+=("$1")
      shift
      ;;
  esac
done

if [ ${#positional[@]} -lt 2 ]; then
  echo "client-gate: give the client command and at least one scenario file or folder" >&2
  usage >&2
  exit 2
fi
client=${positional[0]}
scenarios=("${positional[@]:1}")

if [ -z "$hil" ]; then
  if command -v hil >/dev/null 2>&1; then
    hil=$(command -v hil)
  else
    hil="$(cd "$(dirname "$0")/.." && pwd)/build/apps/hil/hil"
  fi
fi
if [ ! -x "$hil" ]; then
  echo "client-gate: hil not found at $hil (build it, put it on PATH, or give --hil PATH)" >&2
  exit 2
fi

mkdir -p "$(dirname "$junit")" "$report_dir"

args=(run "${scenarios[@]}" --client-exec "$client" --junit "$junit" --report-dir "$report_dir")
[ -n "$tags" ] && args+=(--tags "$tags")
[ -n "$repeat" ] && args+=(--repeat "$repeat")
[ -n "$jobs" ] && args+=(--jobs "$jobs")

echo "client-gate: $hil ${args[*]}"
status=0
"$hil" "${args[@]}" || status=$?

echo "client-gate: JUnit XML in $junit"
echo "client-gate: report in $report_dir (index.html)"
case $status in
  0) echo "client-gate: PASSED - no scenario failed against: $client (SKIP rows say which did not run)" ;;
  1) echo "client-gate: FAILED - see the table above and the report" ;;
  *) echo "client-gate: hil could not run the gate (status $status)" ;;
esac
exit "$status"

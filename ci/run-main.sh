#!/usr/bin/env bash
# Sets up this machine (Debian 12), builds hil, and runs its main job.
# The main job decodes the recorded wire captures in scenarios/captures/
# with the protocol calculator, printing every frame and every error, checks
# every world file in scenarios/worlds/ and draws each (and the built-in
# warehouse) to build/worlds/*.svg, and ends by running the scenario suite
# (scenarios/) against the reference clients: the table on the console,
# JUnit XML in build/hil-junit.xml and the report in build/hil-report/.
# Last, it packs hil, the four client programs and the scenario library
# into the Debian package build/hil_<version>_<arch>.deb (docs/install.md).
set -euo pipefail
cd "$(dirname "$0")/.."

bash ci/install-deps.sh
cmake --preset default >/dev/null
cmake --build --preset default --target hil

hil=build/apps/hil/hil
status=0
for capture in scenarios/captures/*.txt scenarios/captures/*.hex; do
  name=$(basename "$capture")
  protocol=${name%%-*}
  args=(decode "$protocol" --file "$capture" --no-raw --summary)
  case "$name" in *.hex) args+=(--hex) ;; esac
  # Recorded from the mock in the README's dialect (scenarios/captures/README.md).
  case "$name" in arduino-session.txt) args+=(--profile readme) ;; esac
  echo "== $name ($protocol)"
  rc=0
  "$hil" "${args[@]}" || rc=$?
  # 1 means the capture holds bad frames, which these captures are meant to show.
  if [ "$rc" -gt 1 ]; then
    echo "hil exited with $rc on $capture"
    status=1
  fi
done

echo "== worlds"
if ! "$hil" world check scenarios/worlds/*.yaml; then status=1; fi
mkdir -p build/worlds
"$hil" world render -o build/worlds/builtin-warehouse.svg || status=1
for world in scenarios/worlds/*.yaml; do
  "$hil" world render "$world" -o "build/worlds/$(basename "$world" .yaml).svg" || status=1
done

echo "== scenarios"
if ! "$hil" run scenarios/ --junit build/hil-junit.xml --report-dir build/hil-report; then
  status=1
fi

echo "== package"
cmake --build --preset default --target logi-client wr8-client arduino-client leka-client \
  hil_man_pages
if ! (cd build && cpack -G DEB); then status=1; fi
exit "$status"

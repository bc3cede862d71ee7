#!/usr/bin/env bash
# Installs every build and test dependency of hil from Debian 12 packages.
# Safe to run again: apt-get skips what is already installed.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  clang libclang-rt-14-dev   # every tree's compiler (clang 14), with its sanitizer and libFuzzer runtimes
  mold                       # the linker of every tree (cmake/hil_build_speed.cmake)
  libasio-dev                # standalone Asio (header-only)
  libgtest-dev libgmock-dev  # GoogleTest / GoogleMock
  librapidcheck-dev          # property-based tests
  libbox2d-dev               # Box2D 2.4
  libcli11-dev               # command-line parsing
  libbenchmark-dev           # Google Benchmark
  libyaml-cpp-dev            # fault profiles, scenarios, worlds and behaviours
  nlohmann-json3-dev         # NDJSON wire logs and timelines
  tshark                     # reads the pcap files hil writes (tested)
  libncurses-dev             # the logi-client terminal UI
  libcpp-httplib-dev         # hil mock --view: the live view's web server
  chromium chromium-driver   # the live view's browser test (~130 MB download, ~440 MB installed)
  python3-jsonschema python3-yaml  # checks scenario files against scenarios/schema.json (tested)
  gcc-avr avr-libc           # hil firmware build: the AVR compiler and C library for real sketches
  arduino-core-avr arduino-mk  # the Arduino Uno core and the Makefile that builds a sketch with it
  simavr                     # the emulator's command-line tool (run a sketch's ELF by hand)
  libsimavr-dev libelf-dev   # the emulated ATmega328P that hil::mocks links (mocks/avr/)
  libtelnet-dev              # the Telnet layer of the serial cars' RFC 2217 listener (link/)
  python3-serial             # pySerial's rfc2217:// client, unmodified, drives it in the tests
  libpugixml-dev             # hil report merge reads the shards' JUnit XML
  help2man                   # the Debian package's man pages, made from each program's --help
  python3-pytest python3-pip python3-venv python3-setuptools  # python/: the pytest plugin, installed with pip and tested
  python3-prometheus-client  # its text parser checks the /metrics pages of hil proxy and hil mock --view
)
# The Toxiproxy client test installs toxiproxy-node-client from the npm
# registry with npm; a machine without Node.js gets Debian's.
command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)

if [ "$(id -u)" -ne 0 ]; then
  sudo=sudo
else
  sudo=
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"

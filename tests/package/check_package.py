#!/usr/bin/env python3
"""The Debian package as a user gets it (ctest -L package).

Builds hil_<version>_<arch>.deb afresh from the build tree with cpack,
checks its control fields, that apt would install it (a dry run), and its
file list, unpacks it with dpkg -x into a
scratch root and runs the unpacked programs from there, away from the
source tree: --version of every program, a LOGI mock car a TCP client
reads a status frame from, and `hil run` on an installed scenario that
reads an installed fault profile.

  check_package.py --build-dir DIR --source-dir DIR --version X.Y.Z
                   --scratch DIR [--cpack PATH]
"""

import argparse
import gzip
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

PROGRAMS = ["hil", "logi-client", "wr8-client", "arduino-client", "leka-client"]
# Debian 12 packages dpkg-shlibdeps must find behind the programs' shared
# libraries (a Depends without them would install a hil that cannot start).
EXPECTED_DEPENDS = ["libc6", "libstdc++6", "libbox2d", "libyaml-cpp", "libncursesw6", "libelf1"]
EXPECTED_RECOMMENDS = ["gcc-avr", "avr-libc", "arduino-core-avr", "arduino-mk"]
# The scenario the unpacked hil runs: it names its fault profile as
# ../faults/fragmented-writes.yaml, so it passes only when the installed
# library keeps the source tree's layout.
SCENARIO = "logi/logi-buttons-fragmented.yaml"

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL: " + message, flush=True)
    return condition


def run(command, timeout=60, **kwargs):
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, **kwargs)


def built_commit(build_dir):
    """The commit the build tree's programs name (its generated header)."""
    header = (build_dir / "generated" / "hil_source_commit.h").read_text()
    found = re.search(r'#define HIL_SOURCE_COMMIT "([^"]*)"', header)
    return found.group(1) if found else None


def build_package(args, out_dir):
    """cpack in the build tree, into a folder of this run's own."""
    started = time.monotonic()
    result = run([args.cpack, "-G", "DEB", "-B", str(out_dir), "--config",
                  str(args.build_dir / "CPackConfig.cmake")], timeout=240)
    seconds = time.monotonic() - started
    if not check(result.returncode == 0, "cpack exited %d:\n%s%s" %
                 (result.returncode, result.stdout, result.stderr)):
        return None
    arch = run(["dpkg", "--print-architecture"]).stdout.strip() or "amd64"
    deb = out_dir / ("hil_%s_%s.deb" % (args.version, arch))
    if not check(deb.is_file(), "cpack wrote no %s; it wrote %s" %
                 (deb.name, sorted(p.name for p in out_dir.glob("*.deb")))):
        return None
    print("package: %s, %.0f KiB, built in %.1f s" % (deb.name, deb.stat().st_size / 1024, seconds))
    return deb


def control_field(info, name):
    found = re.search(r"^ %s: (.*)$" % re.escape(name), info, re.MULTILINE)
    return found.group(1) if found else ""


def check_control(deb, version):
    info = run(["dpkg-deb", "-I", str(deb)]).stdout
    check(control_field(info, "Package") == "hil", "Package is not hil:\n" + info)
    check(control_field(info, "Version") == version, "Version is not %s:\n%s" % (version, info))
    check(control_field(info, "Maintainer") != "", "no Maintainer:\n" + info)
    depends = control_field(info, "Depends")
    names = [re.split(r"[ (]", d.strip())[0] for d in depends.split(",") if d.strip()]
    for package in EXPECTED_DEPENDS:
        check(any(n.startswith(package) for n in names),
              "Depends names no %s package: %s" % (package, depends))
    for name in names:
        # What dpkg-shlibdeps writes comes from the dpkg database: a name
        # no installed package has would make apt refuse the package.
        check(run(["dpkg-query", "-W", name]).returncode == 0,
              "Depends names %s, which is no installed package" % name)
    recommends = control_field(info, "Recommends")
    for package in EXPECTED_RECOMMENDS:
        check(package in recommends, "Recommends lacks %s: %s" % (package, recommends))
    print("Depends: " + depends)


def check_apt_accepts(deb):
    """apt would install the package here: every Depends resolves (a dry run)."""
    if shutil.which("apt-get") is None:
        print("apt-get: not on this machine, no dry run")
        return
    result = run(["apt-get", "install", "--simulate", "--no-install-recommends", str(deb.resolve())],
                 timeout=120)
    planned = re.search(r"^Inst hil |^hil is already the newest version", result.stdout,
                        re.MULTILINE)
    check(result.returncode == 0 and planned is not None,
          "apt-get install --simulate %s:\n%s%s" % (deb.name, result.stdout, result.stderr))


def check_files(root, source_dir):
    for program in PROGRAMS:
        path = root / "usr" / "bin" / program
        check(path.is_file() and os.access(path, os.X_OK), "no program usr/bin/" + program)
        page = root / "usr" / "share" / "man" / "man1" / (program + ".1.gz")
        if check(page.is_file(), "no man page usr/share/man/man1/%s.1.gz" % program):
            text = gzip.decompress(page.read_bytes()).decode()
            check(re.search(r'^\.TH "?%s"? "?1"?' % re.escape(program.upper()), text, re.MULTILINE)
                  is not None, "%s.1 has no .TH line for section 1" % program)
            # help2man's pages are roff, where a dash is written \-.
            check(r"\-\-help" in text and r"\-\-version" in text,
                  "%s.1 lists no --help or --version: not made from the program's --help" %
                  program)
    # Every file of the scenario library, fault profiles, worlds,
    # behaviours and schema, at the same place under usr/share/hil.
    source = source_dir / "scenarios"
    installed = root / "usr" / "share" / "hil" / "scenarios"
    wanted = sorted(p.relative_to(source) for p in source.rglob("*") if p.is_file())
    missing = [str(p) for p in wanted if not (installed / p).is_file()]
    check(not missing, "the package lacks scenarios/%s" % ", scenarios/".join(missing[:10]))
    for folder in ["faults", "worlds", "behaviours", "logi", "wr8", "arduino", "leka"]:
        check(any((installed / folder).glob("*.yaml")), "no scenarios/%s/*.yaml" % folder)
    check((installed / "schema.json").is_file(), "no scenarios/schema.json")
    print("files: %d programs, %d scenario-library files" % (len(PROGRAMS), len(wanted)))


def check_versions(bin_dir, version, commit):
    for program in PROGRAMS:
        result = run([str(bin_dir / program), "--version"])
        line = result.stdout.strip()
        check(result.returncode == 0 and line == "%s %s (commit %s)" % (program, version, commit),
              "%s --version printed %r (exit %d), expected '%s %s (commit %s)'" %
              (program, line, result.returncode, program, version, commit))
    print("version: " + run([str(bin_dir / "hil"), "--version"]).stdout.strip())


def read_frame(port, timeout_s):
    """The first LOGI frame the car sends on its own (its status report)."""
    deadline = time.monotonic() + timeout_s
    with socket.create_connection(("127.0.0.1", port), timeout=timeout_s) as s:
        data = b""
        while time.monotonic() < deadline:
            s.settimeout(max(0.1, deadline - time.monotonic()))
            try:
                chunk = s.recv(4096)
            except socket.timeout:
                break
            if not chunk:
                break
            data += chunk
            found = re.search(rb"LOGI:[^#]*#", data)
            if found:
                return found.group(0).decode()
    return None


def check_mock(bin_dir, scratch):
    ports_file = scratch / "ports.txt"
    car = subprocess.Popen([str(bin_dir / "hil"), "mock", "logi", "--port", "0", "--ports-file",
                            str(ports_file), "-q", "--no-status"],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                           text=True, cwd=scratch)
    try:
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline and car.poll() is None:
            if ports_file.is_file() and ports_file.read_text().endswith("\n"):
                break
            time.sleep(0.05)
        if not check(ports_file.is_file(), "hil mock logi wrote no ports file"):
            return
        found = re.search(r":(\d+)\s*$", ports_file.read_text())
        if not check(found is not None, "no port in %r" % ports_file.read_text()):
            return
        frame = read_frame(int(found.group(1)), 10)
        if check(frame is not None and frame.startswith("LOGI:STAT:"),
                 "the mock car sent no status frame, got %r" % frame):
            decoded = run([str(bin_dir / "hil"), "decode", "logi", frame])
            check(decoded.returncode == 0, "hil decode logi %r: %s" % (frame, decoded.stdout))
            print("mock: " + frame)
    finally:
        car.send_signal(signal.SIGTERM)
        try:
            output, _ = car.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            car.kill()
            output, _ = car.communicate()
        check(car.returncode == 0, "hil mock logi ended with %d on SIGTERM:\n%s" %
              (car.returncode, output))


def check_run(bin_dir, root, scratch):
    scenario = root / "usr" / "share" / "hil" / "scenarios" / SCENARIO
    result = run([str(bin_dir / "hil"), "run", str(scenario)], timeout=120, cwd=scratch)
    check(result.returncode == 0 and "1 passed, 0 failed" in result.stdout,
          "hil run %s exited %d:\n%s%s" % (SCENARIO, result.returncode, result.stdout, result.stderr))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build-dir", type=Path, required=True)
    parser.add_argument("--source-dir", type=Path, required=True)
    parser.add_argument("--version", required=True)
    parser.add_argument("--scratch", type=Path, required=True)
    parser.add_argument("--cpack", default="cpack")
    args = parser.parse_args()

    started = time.monotonic()
    # Nothing from an earlier run: the package, the root and the ports file
    # are all made by this one.
    shutil.rmtree(args.scratch, ignore_errors=True)
    out_dir = args.scratch / "out"
    root = args.scratch / "root"
    out_dir.mkdir(parents=True)
    root.mkdir()

    deb = build_package(args, out_dir)
    if deb is None:
        return 1
    check_control(deb, args.version)
    check_apt_accepts(deb)
    unpacked = run(["dpkg", "-x", str(deb), str(root)])
    if not check(unpacked.returncode == 0, "dpkg -x: " + unpacked.stderr):
        return 1
    check_files(root, args.source_dir)
    bin_dir = root / "usr" / "bin"
    commit = built_commit(args.build_dir)
    check(commit not in (None, ""), "the build tree names no source commit")
    if (args.source_dir / ".git").exists():
        check(commit != "unknown", "the tree was built from a git checkout, yet names no commit")
    check_versions(bin_dir, args.version, commit)
    check_mock(bin_dir, args.scratch)
    check_run(bin_dir, root, args.scratch)

    print("package test: %.1f s, %d failure(s)" % (time.monotonic() - started, len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
# Runs one command as a user would (hil run ..., ci/client-gate.sh ...) and
# checks what the user would see: its exit status, lines its output must
# and must not contain, and files it must have written. Prints the whole
# output, so a failed CTest test shows what happened.
#
# check_run.py --exit N [--expect REGEX]... [--reject REGEX]... [--count N REGEX]...
#              [--file PATH]... [--file-has PATH REGEX]... [--remove PATH]...
#              -- COMMAND [ARG]...
#
# REGEX is a Python regular expression searched in the output (stdout and
# stderr together), with re.MULTILINE; --count wants exactly N matches.
# --file wants a non-empty file, --file-has a file whose text matches.
# --remove deletes PATH (a file or a folder) before the run, so a file
# check cannot pass on what an earlier run left.

import argparse
import re
import shutil
import os
import subprocess
import sys


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--exit", type=int, required=True, help="the exit status expected")
    parser.add_argument("--expect", action="append", default=[], help="a regex the output must match")
    parser.add_argument("--reject", action="append", default=[], help="a regex it must not match")
    parser.add_argument("--count", action="append", nargs=2, default=[], metavar=("N", "REGEX"),
                        help="the output must match REGEX exactly N times")
    parser.add_argument("--file", action="append", default=[], help="a file that must exist after")
    parser.add_argument("--file-has", action="append", nargs=2, default=[],
                        metavar=("PATH", "REGEX"), help="a file whose text must match")
    parser.add_argument("--remove", action="append", default=[], help="removed before the run")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no command given")

    for path in args.remove:
        if os.path.isdir(path):
            shutil.rmtree(path)
        elif os.path.exists(path):
            os.remove(path)

    print("$ " + " ".join(command), flush=True)
    run = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    output = run.stdout
    sys.stdout.write(output)
    print("-- exit status %d" % run.returncode)

    problems = []
    if run.returncode != args.exit:
        problems.append("exit status %d, expected %d" % (run.returncode, args.exit))
    for pattern in args.expect:
        if not re.search(pattern, output, re.MULTILINE):
            problems.append("the output has nothing matching: %s" % pattern)
    for pattern in args.reject:
        found = re.search(pattern, output, re.MULTILINE)
        if found:
            problems.append("the output has %r, matching: %s" % (found.group(0), pattern))
    for n, pattern in args.count:
        found = len(re.findall(pattern, output, re.MULTILINE))
        if found != int(n):
            problems.append("%d matches of %s, expected %s" % (found, pattern, n))
    for path in args.file:
        if not os.path.isfile(path) or os.path.getsize(path) == 0:
            problems.append("no file (or an empty one) at %s" % path)
    for path, pattern in args.file_has:
        if not os.path.isfile(path):
            problems.append("no file at %s" % path)
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            if not re.search(pattern, f.read(), re.MULTILINE):
                problems.append("%s has nothing matching: %s" % (path, pattern))

    for p in problems:
        print("CHECK FAILED: " + p)
    if not problems:
        print("CHECK PASSED")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())

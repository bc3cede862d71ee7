#!/usr/bin/env python3
"""The sharded gates of ci/examples/ run as CI would run them.

Reads ci/examples/github-actions-sharded-gate.yml and gitlab-sharded-gate.yml,
checks that their shard jobs run `hil run --shard K/N` for every K of N and
that a merge job runs `hil report merge`, then runs those very commands
here (the shards one after another, the hil built in this tree, the
reference client instead of the team's program, the short scenarios of
tests/harness/data/shard): the shards together must run every scenario
once, and the merge must pass; without one shard's results it must fail
naming the scenarios that shard ran.

usage: check_sharded_gate.py HIL SOURCE_DIR
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import yaml

HIL, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
SCENARIOS = os.path.join(SOURCE, "tests/harness/data/shard")
EXAMPLES = os.path.join(SOURCE, "ci/examples")
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
        print("FAIL: " + message)
    return ok


def local(command):
    """A CI command made to run here: this tree's hil in place of the one the
    package installs, no --client-exec."""
    command = re.sub(r"(^|\n)(\s*)hil ", lambda m: m.group(1) + m.group(2) + HIL + " ", command)
    command = re.sub(r'--client-exec\s+"[^"]*"\s*(\\\n)?\s*', "", command)
    return command


def run(command, cwd, env):
    full = dict(os.environ, **env)
    r = subprocess.run(["bash", "-euo", "pipefail", "-c", command], cwd=cwd, env=full,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return r.returncode, r.stdout


def testcase_files(path):
    return [tc.get("file") for tc in ET.parse(path).getroot().iter("testcase")]


def all_scenarios():
    found = []
    for root, _, files in os.walk(SCENARIOS):
        for f in files:
            if f.endswith(".yaml"):
                found.append(os.path.normpath(os.path.join(root, f)))
    return sorted(found)


def run_gate(name, shards, shard_command, merge_command, shard_env):
    """Runs each shard's command, then the merge; checks what they wrote."""
    work = tempfile.mkdtemp(prefix="hil-sharded-gate-")
    try:
        seen = []
        for k in range(1, shards + 1):
            code, out = run(local(shard_command), work, shard_env(k))
            check(code == 0, f"{name}: shard {k}/{shards} exited {code}:\n{out}")
            xml = os.path.join(work, "gate", f"junit-{k}.xml")
            if check(os.path.exists(xml), f"{name}: shard {k} wrote no {xml}"):
                seen += [os.path.normpath(f) for f in testcase_files(xml)]
        check(sorted(seen) == all_scenarios(),
              f"{name}: the shards ran {sorted(seen)}, not each of {all_scenarios()} once")
        env = {"SCENARIOS": SCENARIOS, "SHARDS": str(shards)}
        code, out = run(local(merge_command), work, env)
        check(code == 0, f"{name}: the merge exited {code}:\n{out}")
        merged = os.path.join(work, "gate", "junit.xml")
        if check(os.path.exists(merged), f"{name}: the merge wrote no {merged}"):
            files = sorted(os.path.normpath(f) for f in testcase_files(merged))
            check(files == all_scenarios(), f"{name}: the merged JUnit holds {files}")
        check(os.path.exists(os.path.join(work, "gate", "report", "index.html")),
              f"{name}: the merge wrote no report")
        if failures:
            return
        # Without shard 2's results, the merge fails naming what it ran.
        lost = [os.path.normpath(f) for f in testcase_files(os.path.join(work, "gate", "junit-2.xml"))]
        shutil.rmtree(os.path.join(work, "gate", "report-2"))
        shutil.rmtree(os.path.join(work, "gate", "report"))
        code, out = run(local(merge_command), work, env)
        check(code == 1, f"{name}: the merge without shard 2 exited {code}:\n{out}")
        for f in lost:
            check(f"missing: {f} is in no input" in out,
                  f"{name}: the merge without shard 2 does not name {f}:\n{out}")
    finally:
        shutil.rmtree(work, ignore_errors=True)


def github():
    path = os.path.join(EXAMPLES, "github-actions-sharded-gate.yml")
    doc = yaml.safe_load(open(path))
    jobs = doc["jobs"]
    shards = jobs["gate"]["strategy"]["matrix"]["shard"]
    n = int(doc["env"]["SHARDS"])
    check(shards == list(range(1, n + 1)), f"{path}: the matrix {shards} is not 1..SHARDS={n}")
    runs = [s.get("run", "") for s in jobs["gate"]["steps"]]
    shard_cmd = next((r for r in runs if " run " in r and "--shard" in r), None)
    if not check(shard_cmd is not None, f"{path}: no step runs hil run --shard"):
        return
    check("--shard ${{ matrix.shard }}/${{ env.SHARDS }}" in shard_cmd,
          f"{path}: the shard step does not run --shard K/N from the matrix:\n{shard_cmd}")
    merge_runs = [s.get("run", "") for s in jobs["merge"]["steps"]]
    merge_cmd = next((r for r in merge_runs if "report merge" in r), None)
    if not check(merge_cmd is not None, f"{path}: the merge job does not run hil report merge"):
        return
    check("gate" in jobs["merge"]["needs"], f"{path}: the merge job does not need the shards")
    for job in ("gate", "merge"):
        check("hil" in jobs[job]["needs"], f"{path}: the {job} job does not need the package job")
        check(any("./hil_*.deb" in s.get("run", "") for s in jobs[job]["steps"]),
              f"{path}: the {job} job does not install hil's package")
    check("--expect" in merge_cmd, f"{path}: the merge does not check every scenario ran")

    def env(k):
        return {"SCENARIOS": SCENARIOS, "SHARDS": str(n)}

    run_gate("github", n,
             shard_cmd.replace("${{ matrix.shard }}", "$SHARD_K").replace("${{ env.SHARDS }}",
                                                                         "$SHARDS"),
             merge_cmd, lambda k: dict(env(k), SHARD_K=str(k)))


def gitlab():
    path = os.path.join(EXAMPLES, "gitlab-sharded-gate.yml")
    doc = yaml.safe_load(open(path))
    n = int(doc["gate"]["parallel"])
    script = [s for s in doc["gate"]["script"] if isinstance(s, str)]
    shard_cmd = next((s for s in script if " run " in s and "--shard" in s), None)
    if not check(shard_cmd is not None, f"{path}: the gate job does not run hil run --shard"):
        return
    check('--shard "$CI_NODE_INDEX/$CI_NODE_TOTAL"' in shard_cmd,
          f"{path}: the gate job does not run --shard CI_NODE_INDEX/CI_NODE_TOTAL:\n{shard_cmd}")
    merge_cmd = next((s for s in doc["merge"]["script"] if isinstance(s, str)
                      and "report merge" in s), None)
    if not check(merge_cmd is not None, f"{path}: the merge job does not run hil report merge"):
        return
    check("gate" in doc["merge"]["needs"], f"{path}: the merge job does not need the shards")
    for job in ("gate", "merge"):
        check("hil" in doc[job]["needs"], f"{path}: the {job} job does not need the package job")
    check(any("cpack" in str(line) for line in doc["hil"]["script"]),
          f"{path}: the hil job does not build the package")
    check("--expect" in merge_cmd, f"{path}: the merge does not check every scenario ran")
    run_gate("gitlab", n, shard_cmd, merge_cmd,
             lambda k: {"SCENARIOS": SCENARIOS, "CI_NODE_INDEX": str(k),
                        "CI_NODE_TOTAL": str(n)})


github()
gitlab()
if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("both sharded gates split the scenarios and merge them as they should")

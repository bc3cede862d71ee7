#!/usr/bin/env python3
"""ci/soak-shard.sh K/N: its argument checks and its arithmetic.

For several N and session totals, the dry runs of shards 1..N must give
each property program shares that add up to the total (none more than one
apart), a seed of each shard's own, and split the other soak tests so that
each runs in exactly one shard. Bad arguments exit 2 naming what was wrong.

usage: check_soak_shard.py SOURCE_DIR BUILD_DIR
"""

import re
import subprocess
import sys

SOURCE, BUILD = sys.argv[1], sys.argv[2]
SCRIPT = f"{SOURCE}/ci/soak-shard.sh"
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
        print("FAIL: " + message)


def run(*args):
    r = subprocess.run(["bash", SCRIPT, *args, "--build-dir", BUILD], stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True)
    return r.returncode, r.stdout


_listed = {}


def soak_tests(exclude_properties):
    if exclude_properties in _listed:
        return _listed[exclude_properties]
    args = ["ctest", "--test-dir", BUILD, "-C", "soak", "-L", "soak", "-N"]
    if exclude_properties:
        args += ["-E", r"^soak\.property_"]
    else:
        args += ["-R", r"^soak\.property_"]
    out = subprocess.run(args, stdout=subprocess.PIPE, text=True, check=True).stdout
    _listed[exclude_properties] = sorted(re.findall(r"Test +#\d+: (\S+)", out))
    return _listed[exclude_properties]


def dry_run(k, n, total, seed):
    code, out = run(f"{k}/{n}", "--sessions", str(total), "--seed", str(seed), "--dry-run")
    check(code == 0, f"{k}/{n} --sessions {total}: exit {code}\n{out}")
    head = re.search(r"(\d+) of (\d+) sessions per property in each of (\d+) property programs, "
                     r"seed (\d+)", out)
    check(head is not None, f"{k}/{n}: no summary line\n{out}")
    share, seed_k = int(head.group(1)), int(head.group(4))
    params = re.findall(r"^(soak\.property_\S+): .*RC_PARAMS='seed=(\d+) max_success=(\d+)'", out,
                        re.M)
    if share > 0:
        check(sorted(p[0] for p in params) == soak_tests(False),
              f"{k}/{n}: not every property program runs: {params}")
        for name, s, m in params:
            check((int(s), int(m)) == (seed_k, share),
                  f"{k}/{n}: {name} runs seed={s} max_success={m}, not {seed_k} and {share}")
    else:
        check(not params and "no property sessions" in out, f"{k}/{n}: runs programs for 0\n{out}")
    others = re.findall(r"^  would run: (\S+)", out, re.M)
    check(f"-I {k},,{n}" in out, f"{k}/{n}: the other soak tests are not split by -I {k},,{n}")
    return share, seed_k, others


for n, total in [(1, 5000), (2, 5000), (3, 5000), (4, 10), (3, 2), (7, 100)]:
    shares, seeds, others = [], [], []
    for k in range(1, n + 1):
        share, seed, ran = dry_run(k, n, total, 11)
        shares.append(share)
        seeds.append(seed)
        others += ran
    check(sum(shares) == total, f"N={n}: the shares {shares} do not add up to {total}")
    check(max(shares) - min(shares) <= 1, f"N={n}: the shares {shares} are uneven")
    check(len(set(seeds)) == n, f"N={n}: shards share seeds {seeds}")
    check(sorted(others) == soak_tests(True),
          f"N={n}: the other soak tests do not each run once: {sorted(others)}")

# Another base seed gives other seeds, the same for every machine.
_, seed_a, _ = dry_run(1, 4, 100, 11)
_, seed_b, _ = dry_run(1, 4, 100, 12)
check(seed_a != seed_b, "the base seed does not change the shard's seed")
check(dry_run(3, 4, 100, 12)[1] == dry_run(3, 4, 100, 12)[1], "a shard's seed is not repeatable")

for args, message in [
    ([], "which shard?"),
    (["0/3"], "'0/3': K and N must be whole numbers of at least 1"),
    (["4/3"], "'4/3' names shard 4 of only 3"),
    (["3"], "'3' is not K/N"),
    (["a/b"], "'a/b' is not K/N"),
    (["1/2", "2/2"], "one K/N only"),
    (["1/2", "--sessions", "0"], "--sessions '0' is not a whole number"),
    (["1/2", "--sessions", "x"], "--sessions 'x' is not a whole number"),
    (["1/2", "--sessions"], "--sessions needs a value"),
    (["1/2", "--seed", "-4"], "--seed '-4' is not a whole number"),
    (["1/2", "--frobnicate"], "unknown option --frobnicate"),
]:
    r = subprocess.run(["bash", SCRIPT, *args], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True)
    check(r.returncode == 2, f"{args}: exit {r.returncode}, not 2\n{r.stdout}")
    check(message in r.stdout, f"{args}: does not say {message!r}\n{r.stdout}")

code, out = run("1/2", "--dry-run")
check(code == 0 and "2500 of 5000 sessions" in out, f"the default total is not 5000:\n{out}")

# One real shard, the property programs only (the gate's soak runs take
# most of an hour): 3 sessions over 3 shards is one session per property
# for shard 2, from seed 1*3 + 2-1 = 4, and rapidcheck says it took them.
code, out = run("2/3", "--sessions", "3", "--seed", "1", "--properties-only")
check(code == 0 and "soak shard 2/3: passed" in out, f"a real shard did not pass:\n{out}")
configs = [line for line in out.splitlines() if line.startswith("Using configuration:")]
check(len(configs) > 0, f"no property program said which configuration it ran:\n{out}")
check(all("max_success=1" in c and "seed=4" in c for c in configs),
      f"a property program did not take the shard's sessions and seed: {configs}")
check("would run" not in out and "left out (--properties-only)" in out,
      f"--properties-only ran other soak tests:\n{out}")

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("ci/soak-shard.sh splits the soak as it should")

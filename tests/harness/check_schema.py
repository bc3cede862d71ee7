#!/usr/bin/env python3
"""Checks scenarios/schema.json against the scenario files hil ships.

Every scenario under scenarios/ (a YAML map with `car` and `steps`; the
faults, behaviours and worlds folders hold other kinds of file) and every
scenario fixture of the loader's tests must pass the schema, and documents
with typical mistakes must fail it, so editors flag what the loader refuses.

Usage: check_schema.py SOURCE_DIR
"""

import json
import pathlib
import sys

import jsonschema
import yaml

SKIPPED_FOLDERS = {"faults", "behaviours", "worlds"}

# Each of these is wrong in one way an editor should underline.
WRONG = {
    "no car": "name: t\nsteps: [connect]\n",
    "no steps": "name: t\ncar: logi\n",
    "a misspelt top-level key": "name: t\ncar: logi\nstpes: [connect]\n",
    "an unknown car": "name: t\ncar: tesla\nsteps: [connect]\n",
    "a duration without a unit": "name: t\ncar: logi\ntimeout: 60\nsteps: [connect]\n",
    "a step doing two things": "name: t\ncar: logi\nsteps:\n  - {wait: 1s, car: fault}\n",
    "an unknown step key": "name: t\ncar: logi\nsteps:\n  - {sleep: 1s}\n",
    "two quantifiers": (
        "name: t\ncar: logi\nsteps: [connect]\n"
        "expect:\n  - {received: SP, count: 1, never: true}\n"
    ),
    "tolerance without times": (
        "name: t\ncar: logi\nsteps: [connect]\n"
        "expect:\n  - {received: SP, tolerance: 1s}\n"
    ),
    "an unknown client state": (
        "name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - {client: conected}\n"
    ),
    "an expectation with nothing to match": (
        "name: t\ncar: logi\nsteps: [connect]\nexpect:\n  - {within: 1s}\n"
    ),
    "a scheduled step without a time": (
        "name: t\ncar: logi\nsteps: [connect]\nschedule:\n  - car: fault\n"
    ),
    "between with after": (
        "name: t\ncar: logi\nsteps: [release]\n"
        "expect:\n  - {sim: at_rest, between: [1s, 2s], after: release}\n"
    ),
    "an unknown behaviour": "name: t\ncar: logi\nsteps:\n  - car: {rejct: MV}\n",
    "another car's profile": "name: t\ncar: arduino\nprofile: comspecs-v3\nsteps: [connect]\n",
    "a WR8 profile misspelt": "name: t\ncar: wr8\nprofile: svgui-2020\nsteps: [connect]\n",
    "a reply latency without a unit": "name: t\ncar: arduino\nreply_latency: 20\nsteps: [PING]\n",
    "an end state misspelt": "name: t\ncar: logi\nat_end: movin\nsteps: [connect]\n",
    "a replay without its car": "name: t\ncar: {replay: car.ndjson}\nsteps: [connect]\n",
    "unmatched without a replay": "name: t\ncar: {kind: logi, unmatched: silent}\nsteps: [connect]\n",
    "an unmatched policy misspelt": (
        "name: t\ncar: {kind: logi, replay: car.ndjson, unmatched: mocked}\nsteps: [connect]\n"
    ),
    "firmware on another car": (
        "name: t\ncar: {kind: logi, firmware: {elf: a.elf}}\nsteps: [connect]\n"
    ),
    "firmware with a replay": (
        "name: t\ncar: {kind: arduino, replay: c.ndjson, firmware: {elf: a.elf}}\nsteps: [PING]\n"
    ),
    "firmware as both a sketch and an image": (
        "name: t\ncar: {kind: arduino, firmware: {sketch: a/a.ino, elf: a.elf}}\nsteps: [PING]\n"
    ),
    "firmware without a sketch or an image": (
        "name: t\ncar: {kind: arduino, firmware: {pins: pins.yaml}}\nsteps: [PING]\n"
    ),
    "a firmware key misspelt": (
        "name: t\ncar: {kind: arduino, firmware: {skecth: a/a.ino}}\nsteps: [PING]\n"
    ),
    "firmware with a reply latency": (
        "name: t\ncar: {kind: arduino, firmware: {elf: a.elf}}\nreply_latency: 20ms\n"
        "steps: [PING]\n"
    ),
    "another car's profile with a replay": (
        "name: t\ncar: {kind: logi, replay: car.ndjson}\nprofile: readme\nsteps: [connect]\n"
    ),
}

# And these are right in ways that are easy to get wrong in a schema.
RIGHT = {
    "the Leka spec's own table": "name: t\ncar: leka\nprofile: comspecs-v3\nsteps: [connect]\n",
    "the real WR8 head program": "name: t\ncar: wr8\nprofile: svgui-head\nsteps: [connect]\n",
    "the LOGI guide, named": "name: t\ncar: logi\nprofile: guide\nsteps: [connect]\n",
    "a reply latency": "name: t\ncar: arduino\nreply_latency: 20ms\nsteps: [PING]\n",
    "variables in a duration and a count": (
        "name: t\ncar: logi\nvariables: {t: 2s, n: 3}\ntimeout: ${t}\nsteps: [connect]\n"
        "expect:\n  - {received: SP, at_least: '${n}'}\n"
    ),
    "faults off in YAML 1.1": "name: t\ncar: logi\nfaults: off\nsteps:\n  - faults: off\n",
    "a scenario that ends moving": "name: t\ncar: logi\nat_end: moving\nsteps: [connect]\n",
    "a replayed car": (
        "name: t\ncar: {kind: logi, replay: ../captures/car.ndjson, unmatched: silent}\n"
        "steps: [connect]\n"
    ),
    "a sketch on the emulated board": (
        "name: t\ncar: {kind: arduino, firmware: {sketch: ../firmware/robot/robot.ino}}\n"
        "steps: [PING]\n"
    ),
    "an image and its pin map": (
        "name: t\ncar: {kind: arduino, firmware: {elf: robot.elf, pins: pins.yaml}}\n"
        "steps: [PING]\n"
    ),
    "an exec client": (
        "name: t\ncar: wr8\nclient: {exec: 'c {host} {port}', startup_timeout: 5s}\n"
        "steps: [connect]\n"
    ),
}


def is_scenario(document):
    return isinstance(document, dict) and "car" in document and "steps" in document


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    root = pathlib.Path(sys.argv[1])
    schema = json.loads((root / "scenarios" / "schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    failures = []

    files = []
    # Other tests' fixtures may be wrong on purpose, so only the loader's own.
    for folder in (root / "scenarios", root / "bench" / "scenarios",
                   root / "tests" / "harness" / "data" / "scenario_yaml"):
        for path in sorted(folder.rglob("*.yaml")):
            if SKIPPED_FOLDERS & set(path.relative_to(folder).parts[:-1]):
                continue
            files.append(path)
    checked = 0
    for path in files:
        try:
            document = yaml.safe_load(path.read_text())
        except yaml.YAMLError as error:
            failures.append(f"{path}: not YAML: {error}")
            continue
        if not is_scenario(document):
            continue
        checked += 1
        for error in validator.iter_errors(document):
            where = "/".join(str(p) for p in error.absolute_path) or "(top)"
            failures.append(f"{path}: {where}: {error.message}")
    if checked < 4:
        failures.append(f"only {checked} scenario files found under {root}; expected the examples")

    for what, text in WRONG.items():
        if validator.is_valid(yaml.safe_load(text)):
            failures.append(f"the schema accepts {what}:\n{text}")
    for what, text in RIGHT.items():
        for error in validator.iter_errors(yaml.safe_load(text)):
            failures.append(f"the schema refuses {what}: {error.message}")

    for failure in failures:
        print(failure, file=sys.stderr)
    print(f"{checked} scenario files checked, {len(WRONG)} wrong and {len(RIGHT)} right documents")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

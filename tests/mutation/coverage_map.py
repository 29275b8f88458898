#!/usr/bin/env python3
"""Which lines of the plugin runtime each test of the mutation runner executes: the map
the runner reads to choose a mutant's tests by what they run, not by a hand-kept list.

    coverage_map.py --dissgen build/bin/dissgen [--tests NAME ...]   # run, write coverage.json
    coverage_map.py --check                                          # is the map stale? (ctest)

The runtime runs inside tshark, in a plugin that `dissgen install` compiles from the
generated code and the plugin_runtime sources.  Each test (a name of run_mutants.TESTS)
runs with DISSGEN_COVERAGE_DIR=DIR: dissgen (build_plugin) then compiles each plugin with
"--coverage -dumpdir DIR/<its build folder>/" (every plugin has the runtime's file names,
and one rule file may make several): its .gcno notes land there, and tshark writes its
.gcda counts there at exit; gcov turns them into the executed lines of each runtime file.
Tests that build no plugin (the unit tests) map to no runtime line.  The generator is not mapped yet: for its files the runner keeps the
mutant's own tests.

The map (coverage.json): for each test its seconds, {runtime file: [executed lines]} and
the sha256 of each source file when its lines were counted (a file changed since: the
runner takes that test for any line of it); the map's own sources, with their sha256;
"unmapped": the runner's tests not run for the map yet.
--check fails when the runner has a test or the runtime a source file that the map does
not know (added since the map was written: refresh it with the first command).
"""

import argparse
import glob
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import run_mutants  # noqa: E402

MAP = os.path.join(HERE, "coverage.json")
RUNTIME = "plugin_runtime"


def runtime_sources(source_dir):
    """Repository paths of the runtime's sources ("plugin_runtime/...")."""
    found = []
    for root, _, files in os.walk(os.path.join(source_dir, RUNTIME)):
        found += [os.path.relpath(os.path.join(root, f), source_dir) for f in files if f.endswith((".cpp", ".h"))]
    return sorted(found)


def sha256(path):
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def gcov_lines(notes_dir, by_basename):
    """{repository path: sorted executed lines} from the .gcda/.gcno pairs in notes_dir."""
    lines = {}
    for gcda in sorted(glob.glob(os.path.join(notes_dir, "*", "*.gcda"))):
        p = subprocess.run(["gcov", "--json-format", "--stdout", gcda], cwd=os.path.dirname(gcda),
                           capture_output=True)
        for chunk in p.stdout.splitlines():
            if not chunk.strip():
                continue
            for f in json.loads(chunk).get("files", []):
                path = by_basename.get(os.path.basename(f["file"]))
                if path:
                    lines.setdefault(path, set()).update(
                        l["line_number"] for l in f["lines"] if l["count"] > 0)
    return {path: sorted(v) for path, v in lines.items() if v}


def run_with_coverage(name, source_dir, dissgen, work):
    """(kind, seconds, {path: lines}, output) of test name run with coverage plugins."""
    notes = os.path.join(work, name)
    shutil.rmtree(notes, ignore_errors=True)
    os.makedirs(notes)
    build_dir = os.path.dirname(os.path.dirname(os.path.abspath(dissgen)))
    env = dict(os.environ, DISSGEN_COVERAGE_DIR=notes)
    cmd = run_mutants.TESTS[name](source_dir, build_dir)
    start = time.monotonic()
    p = subprocess.run(cmd, cwd=build_dir, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       errors="replace")
    secs = time.monotonic() - start
    kind, _ = run_mutants.classify(p.returncode, p.stdout)
    by_basename = {os.path.basename(f): f for f in runtime_sources(source_dir)}
    return kind, secs, gcov_lines(notes, by_basename), p.stdout


def source_hashes(source_dir):
    return {f: sha256(os.path.join(source_dir, f)) for f in runtime_sources(source_dir)}


def save(source_dir, tests, path):
    data = {
        "about": "tests/mutation/coverage_map.py: executed runtime lines per mutation-runner test",
        "sources": source_hashes(source_dir),
        "tests": dict(sorted(tests.items())),
        "unmapped": sorted(set(run_mutants.TESTS) - set(tests)),
    }
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(data, fh, indent=0, sort_keys=True)
        fh.write("\n")


def write_map(source_dir, dissgen, names, path):
    """Map tests names, keeping what the map at path says of the others; the map is
    written after each test (a long run stopped keeps what it measured)."""
    old = json.load(open(path)) if os.path.isfile(path) else {"tests": {}}
    tests = {n: t for n, t in old.get("tests", {}).items() if n in run_mutants.TESTS}
    work = tempfile.mkdtemp(prefix="dissgen-coverage-")
    os.chmod(work, 0o755)
    try:
        for name in names:
            kind, secs, lines, out = run_with_coverage(name, source_dir, dissgen, work)
            print("%-22s %-7s %5.0fs %d runtime files, %d lines" % (
                name, kind, secs, len(lines), sum(len(v) for v in lines.values())), flush=True)
            if kind in (run_mutants.FAIL, run_mutants.TIMEOUT):
                raise SystemExit("%s fails unmutated: fix it before mapping\n%s" % (name, run_mutants.tail(out)))
            # the sources these lines were counted in: a test mapped again alone must not make
            # the others' lines look current (the runner takes a moved file's every test)
            tests[name] = {"seconds": round(secs, 1), "lines": lines, "sources": source_hashes(source_dir)}
            save(source_dir, tests, path)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def stale(source_dir, data):
    """What the map does not know: runner tests and runtime sources added since it was written."""
    known_tests = set(data.get("tests", {})) | set(data.get("unmapped", []))
    problems = ["test %s" % t for t in sorted(set(run_mutants.TESTS) - known_tests)]
    problems += ["source %s" % f for f in runtime_sources(source_dir) if f not in data.get("sources", {})]
    return problems


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--source-dir", default=os.path.normpath(os.path.join(HERE, "..", "..")))
    ap.add_argument("--dissgen", help="the dissgen of a build of this tree (its runtime is compiled into plugins)")
    ap.add_argument("--tests", nargs="*", help="runner tests to (re)map (default: all)")
    ap.add_argument("--map", default=MAP)
    ap.add_argument("--check", action="store_true", help="fail when the map misses tests or sources")
    args = ap.parse_args(argv)
    if args.check:
        problems = stale(args.source_dir, json.load(open(args.map, encoding="utf-8")))
        if problems:
            print("%s is stale: it does not know %s; refresh it: python3 tests/mutation/coverage_map.py "
                  "--dissgen build/bin/dissgen --tests NAME..." % (args.map, ", ".join(problems)))
            return 1
        print("%s knows every runner test and runtime source" % args.map)
        return 0
    if not args.dissgen:
        ap.error("--dissgen is needed to run the tests")
    unknown = set(args.tests or []) - set(run_mutants.TESTS)
    if unknown:
        ap.error("unknown tests: %s" % " ".join(sorted(unknown)))
    write_map(args.source_dir, args.dissgen, args.tests or sorted(run_mutants.TESTS), args.map)
    return 0


if __name__ == "__main__":
    sys.exit(main())

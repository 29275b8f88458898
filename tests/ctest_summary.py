#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""After a ctest run: every skipped test with its reason, and the corpus check (Python 3 stdlib only).

ctest lists skipped tests (exit status 77) without saying why; each of our tests prints
"SKIPPED: <why>" first.  This reads the JUnit file ctest wrote (--output-junit) and prints
one line per skipped test with that reason, the `corpus` ones (label `corpus`: they need
../shared/corpus beside the source tree) marked as such.

    ctest_summary.py --junit build/ctest-junit.xml [--build-dir build] [--require-corpus]

--require-corpus (CI, when the corpus is present): exit 1 if a `corpus` test was skipped
or did not run at all; a corpus that is there must be used.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

# Other tests whose skip reason names the corpus count as corpus tests even unlabelled.
CORPUS_REASON = re.compile(r"shared/corpus|\bcorpus\b", re.I)


def skip_reason(output):
    """The test's "SKIPPED: ..." line (its last one), else its last non-empty line."""
    lines = [l.strip() for l in (output or "").splitlines() if l.strip()]
    skipped = [l for l in lines if l.startswith("SKIPPED")]
    if skipped:
        return skipped[-1]
    return lines[-1] if lines else "(no output)"


def read_junit(path):
    """{test name: (status, output)}: status is 'run', 'fail', 'skipped' or 'notrun'."""
    results = {}
    for case in ET.parse(path).getroot().iter("testcase"):
        out = case.findtext("system-out") or ""
        status = case.get("status", "run")
        if case.find("failure") is not None:
            status = "fail"
        elif case.find("skipped") is not None:
            # ctest writes <skipped message="SKIP_RETURN_CODE=77"/> for a skip by exit status.
            message = case.find("skipped").get("message", "")
            status = "skipped" if "SKIP" in message else "notrun"
        results[case.get("name")] = (status, out)
    return results


def labelled(build_dir, label):
    """Names of the tests carrying label, from ctest --show-only=json-v1."""
    p = subprocess.run(["ctest", "--show-only=json-v1"], cwd=build_dir, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError("ctest --show-only=json-v1 in %s failed: %s" % (build_dir, p.stderr.strip()))
    names = set()
    for test in json.loads(p.stdout).get("tests", []):
        for prop in test.get("properties", []):
            if prop.get("name") == "LABELS" and label in prop.get("value", []):
                names.add(test["name"])
    return names


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--junit", required=True, help="the file of ctest --output-junit")
    ap.add_argument("--build-dir", default=".", help="where ctest ran (for the test labels)")
    ap.add_argument("--require-corpus", action="store_true",
                    help="fail when a corpus test was skipped or did not run")
    args = ap.parse_args(argv)
    if not os.path.isfile(args.junit):
        print("ctest_summary: no %s (did ctest run?)" % args.junit)
        return 1
    results = read_junit(args.junit)
    corpus_tests = labelled(args.build_dir, "corpus")

    not_run = {name: r for name, r in results.items() if r[0] in ("skipped", "notrun")}
    corpus_skipped = []
    if not_run:
        print()
        print("=" * 78)
        print("%d of %d tests did not run:" % (len(not_run), len(results)))
        for name in sorted(not_run):
            status, out = not_run[name]
            reason = skip_reason(out) if status == "skipped" else "not run (%s)" % status
            is_corpus = name in corpus_tests or bool(CORPUS_REASON.search(reason))
            if is_corpus:
                corpus_skipped.append(name)
            print("  %-34s %s%s" % (name, "[corpus] " if is_corpus else "", reason))
        print("=" * 78)
    missing = sorted(corpus_tests - set(results))
    if args.require_corpus:
        if corpus_skipped or missing:
            print("FAILED: the corpus is present but these corpus tests did not use it: %s"
                  % ", ".join(sorted(corpus_skipped) + ["%s (not run)" % m for m in missing]))
            return 1
        print("corpus: all %d corpus tests ran (%s)" % (len(corpus_tests), ", ".join(sorted(corpus_tests))))
    return 0


if __name__ == "__main__":
    sys.exit(main())

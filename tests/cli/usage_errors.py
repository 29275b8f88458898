#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Every misuse of dissgen's command line: exit status 2 (as for a usage error anywhere), one
line on stderr that says what is wrong, nothing on stdout, and nothing written; and -h/--help
after a command: the help, exit 0 (Python 3 stdlib only).

    usage_errors.py --dissgen build/bin/dissgen

A rule file that exists is passed where one is needed, so that only the misuse can fail.
Prints "N passed, N failed".
"""

import argparse
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
RULES = os.path.normpath(os.path.join(HERE, "..", "rules", "paper_example.xml"))


def misuses(rules, out):
    """(arguments, the first line dissgen must write to stderr)."""
    return [
        (["frobnicate", rules], "dissgen: unknown command 'frobnicate'"),
        (["check", rules, "--frob"], "dissgen: unknown option '--frob'"),
        (["check"], "dissgen: check needs a rule file"),
        (["check", rules, rules], "dissgen: one rule file at a time ('%s' is extra)" % rules),
        (["generate", rules], "dissgen: generate needs -o DIR"),
        (["generate", rules, "-o"], "dissgen: -o needs a value"),
        (["check", rules, "--network"], "dissgen: --network needs a value"),
        (["install", rules, "--system", "--dir", out], "dissgen: use either --dir or --system"),
        (["check", rules, "--network", "a.xml", "--network", "b.xml"], "dissgen: one --network at a time"),
        (["check", rules, "--rules", rules], "dissgen: --rules is an option of report"),
        (["fields", rules, "--protocol", "ecat"], "dissgen: --protocol is an option of report"),
        (["esi"], "dissgen: esi takes ESI files or folders only"),
        (["esi", "x.xml", "--compact"], "dissgen: esi takes ESI files or folders only"),
        (["report", "c.pcap"], "dissgen: report takes captures (one, or a ring-buffer set in order) and -o FILE.html"),
        (["sources", rules, rules], "dissgen: sources takes at most one rule file"),
        (["sources", "-o", out], "dissgen: sources takes at most one rule file"),
    ]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", required=True)
    args = ap.parse_args(argv)
    dissgen = os.path.abspath(args.dissgen)
    passed = failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out")
        for arguments, first_line in misuses(RULES, out):
            p = subprocess.run([dissgen] + arguments, capture_output=True, text=True, cwd=tmp)
            got = p.stderr.splitlines()[0] if p.stderr else ""
            ok = p.returncode == 2 and got == first_line and not p.stdout and not os.listdir(tmp)
            if ok:
                passed += 1
                print("ok: dissgen %s: exit 2, %r" % (" ".join(arguments), first_line))
            else:
                failed += 1
                print("FAILED: dissgen %s: exit %d (want 2), stderr %r (want %r), stdout %r, files %s" % (
                    " ".join(arguments), p.returncode, got, first_line, p.stdout[:80], os.listdir(tmp)))
        # Help asked for after a command is no misuse: the help, exit 0, nothing written.
        for arguments in (["install", RULES, "--help"], ["report", "-h"], ["check", "--help"]):
            p = subprocess.run([dissgen] + arguments, capture_output=True, text=True, cwd=tmp)
            if p.returncode == 0 and p.stdout.startswith("usage: dissgen") and not p.stderr and not os.listdir(tmp):
                passed += 1
                print("ok: dissgen %s: exit 0, the help" % " ".join(arguments))
            else:
                failed += 1
                print("FAILED: dissgen %s: exit %d (want 0), stdout %r, stderr %r, files %s" % (
                    " ".join(arguments), p.returncode, p.stdout[:40], p.stderr[:80], os.listdir(tmp)))
        # A report whose folder is missing says so before it reads the capture (tshark is
        # never started: a wrong DISSGEN_TSHARK would say otherwise).
        env = dict(os.environ, DISSGEN_TSHARK=os.path.join(tmp, "no-such-tshark"))
        p = subprocess.run([dissgen, "report", "c.pcap", "-o", "missing/r.html"], capture_output=True, text=True,
                           cwd=tmp, env=env)
        want = "dissgen: report: cannot write missing/r.html: no folder missing"
        if p.returncode == 1 and p.stderr.splitlines() == [want] and not os.listdir(tmp):
            passed += 1
            print("ok: dissgen report -o missing/r.html: exit 1, %r" % want)
        else:
            failed += 1
            print("FAILED: dissgen report -o missing/r.html: exit %d (want 1), stderr %r (want %r)" % (
                p.returncode, p.stderr, want))
    print("%d passed, %d failed" % (passed, failed))
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())

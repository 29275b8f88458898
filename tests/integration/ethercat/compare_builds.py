#!/usr/bin/env python3
"""Whether two builds of dissgen decode the EtherCAT captures byte for byte alike: tshark -V, -2 -V,
-T fields of the pairing's and the analysis' fields (one pass and two), -z ecatr,tree,
-z ecatr,cycles and -z ecatr.cycles,tree, on every corpus capture and both samples, with each
tree's own rules/ethercat.xml.

A change meant to leave the output alone (e.g. the analysis reading the walk instead of the bytes)
is checked against the build before it:

    compare_builds.py --before /work/main --after . [--captures A.pcapng ...]

Each tree's build/bin/dissgen installs the plugin. Prints one line per capture and view, and the
first differing lines; exits 1 when anything differs.
"""

import argparse
import difflib
import glob
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkEnv  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))


def default_captures():
    corpus = os.path.join(os.path.dirname(SOURCE), "shared", "corpus", "ethercat")
    return sorted(glob.glob(os.path.join(corpus, "*.pcap*"))) + \
        sorted(glob.glob(os.path.join(SOURCE, "samples", "*.pcap*")))


def analysis_fields(tree):
    """The display-filter names the pairing and its analysis add (dissgen fields)."""
    out = subprocess.run([os.path.join(tree, "build", "bin", "dissgen"), "fields",
                          os.path.join(tree, "rules", "ethercat.xml")],
                         capture_output=True, text=True, check=True).stdout
    rows = [line.split("\t") for line in out.splitlines() if line]
    return [r[0] for r in rows if len(r) > 3 and r[3] in ("pairing", "ethercat-esc")
            and r[1] not in ("FT_NONE", "FT_PROTOCOL")]


def views(fields):
    """The tshark runs compared: name -> arguments after -r CAPTURE."""
    field_args = ["-T", "fields", "-E", "occurrence=a"]
    for f in fields:
        field_args += ["-e", f]
    return {
        "-V": ["-V"],
        "-2 -V": ["-2", "-V"],
        "fields": field_args,
        "-2 fields": ["-2"] + field_args,
        "-z ecatr,tree": ["-q", "-z", "ecatr,tree"],
        "-2 -z ecatr,tree": ["-2", "-q", "-z", "ecatr,tree"],
        "-z ecatr,cycles": ["-q", "-z", "ecatr,cycles"],
        "-2 -z ecatr.cycles,tree": ["-2", "-q", "-z", "ecatr.cycles,tree"],
    }


def outputs(tree, captures, fields):
    """{(capture, view): stdout} with the plugin of `tree`."""
    result = {}
    with TsharkEnv() as env:
        env.install_plugin(os.path.join(tree, "build", "bin", "dissgen"), os.path.join(tree, "rules", "ethercat.xml"))
        for cap in captures:
            path = env.readable(cap)
            for name, args in views(fields).items():
                p = env.tshark(["-r", path] + args, check=False)
                result[(cap, name)] = p.stdout + ("\n[exit %d]\n%s" % (p.returncode, p.stderr) if p.returncode else "")
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--before", required=True, help="source tree with the build to compare against")
    ap.add_argument("--after", default=SOURCE, help="source tree with the build under test")
    ap.add_argument("--captures", nargs="*", help="default: the corpus's EtherCAT captures and samples/")
    a = ap.parse_args()
    captures = [os.path.abspath(c) for c in (a.captures or default_captures())]
    fields = analysis_fields(a.before)
    before = outputs(a.before, captures, fields)
    after = outputs(a.after, captures, fields)
    differ = 0
    for key in before:
        same = before[key] == after[key]
        differ += not same
        print("%s %-40s %-18s %d bytes" % ("same" if same else "DIFF", os.path.basename(key[0]), key[1],
                                          len(after[key])))
        if not same:
            diff = difflib.unified_diff(before[key].splitlines(), after[key].splitlines(), "before", "after",
                                        lineterm="", n=1)
            for i, line in enumerate(diff):
                if i >= 20:
                    break
                print("    " + line)
    print("%d of %d outputs differ (%d captures, %d fields)" % (differ, len(before), len(captures), len(fields)))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())

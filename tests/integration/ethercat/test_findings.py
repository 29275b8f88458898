#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The findings on the real captures, frame by frame, against a reviewed list.

  test_findings.py --dissgen build/bin/dissgen --source-dir . [--corpus DIR] [--write]

For every capture of ../shared/corpus/ethercat and ../shared/corpus/enip, the expert infos
our plugins raise (tshark -2) are compared with tests/findings/PROTOCOL/CAPTURE.findings: one
line per finding, `FRAME EXPERT`, each group explained by a comment written when it was checked
by hand. A finding added or lost fails the test: a new false alarm, or a real fault no longer
seen. In one pass the same findings must appear, except that a lost request's
`no_response` sits on the frame that proves the loss and names it (`P.no_response_to`);
a line `FRAME EXPERT end` marks a loss only the capture's end shows (-2 only).

--write rewrites the lists from what the plugins say now (keeping no comments): review every
line before committing, and explain it.
"""

import collections
import os
import re
import sys
import unittest
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import Checks, TsharkEnv, TsharkTestCase, corpus_captures, run_unittests  # noqa: E402

PROTOCOLS = {"ethercat": ("rules/ethercat.xml", "ecatr"), "enip": ("rules/enip.xml", "enipr")}
ARGS = None


def registered(env, proto):
    """The protocol's expert info names, and whether it has the pairing's loss link."""
    fields = env.tshark(["-G", "fields"]).stdout
    names = {line.split("\t")[2] for line in fields.splitlines() if line.count("\t") >= 2}
    return sorted(n for n in names if n.startswith(proto + ".expert.")), proto + ".no_response_to" in names


def findings(env, path, proto, experts, has_link, two_pass):
    """Counter of (frame, expert), and {frame: [lost requests it names]}."""
    links = [proto + ".no_response_to"] if has_link else []
    fields = ["frame.number"] + links + experts
    found, named = collections.Counter(), {}
    for frame, r in env.field_rows(path, fields, two_pass, display_filter=proto).items():
        if links and r[links[0]]:
            named[frame] = [int(x) for x in r[links[0]]]
        for e in experts:
            if r[e]:
                found[(frame, e)] += len(r[e])
    return found, named


# Fields that are counts, lengths, working counters or times: never negative.
NEVER_NEGATIVE = re.compile(r"\.(wkc|len|length|count|time|slaves_passed|datagrams)$|count$")
# A negative number in an expert info's text ("got -4", "round trip -1.2 ms").
NEGATIVE_IN_TEXT = re.compile(r"(^|[\s(:=,])-\d")


def impossible_values(env, path, proto):
    """(frame, field or expert text) with a negative count, length, working counter or time,
    in every field the protocol shows (tshark -2 -T pdml)."""
    out = []
    args = ["-r", path, "-2", "-Y", proto, "-T", "pdml"]
    p = env.tshark(args, stdout=open(env.path("scan.pdml"), "w"))
    del p
    frame = None
    for _event, el in ET.iterparse(env.path("scan.pdml")):
        if el.tag == "field":
            name, show = el.get("name", ""), el.get("show", "")
            if name == "num":  # geninfo
                frame = show
            elif name.startswith(proto + ".") and NEVER_NEGATIVE.search(name) and show.startswith("-"):
                out.append((frame, "%s = %s" % (name, show)))
            elif name.startswith(proto + ".expert") or name == "_ws.expert.message":
                if NEGATIVE_IN_TEXT.search(show):
                    out.append((frame, show))
        elif el.tag == "packet":
            el.clear()
    os.unlink(env.path("scan.pdml"))
    return out


def read_list(path):
    """Counter of (frame, expert) and the set of frames marked `end`."""
    found, end = collections.Counter(), set()
    with open(path, encoding="utf-8") as fh:
        for n, line in enumerate(fh, 1):
            text = line.split("#", 1)[0].split()
            if not text:
                continue
            if len(text) not in (2, 3) or not text[0].isdigit() or (len(text) == 3 and text[2] != "end"):
                raise ValueError("%s:%d: expected 'FRAME EXPERT [end]'" % (path, n))
            found[(int(text[0]), text[1])] += 1
            if len(text) == 3:
                end.add(int(text[0]))
    return found, end


def write_list(path, capture, found, end):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("# %s: the findings expected (tshark -2), one per line: FRAME EXPERT\n" % capture)
        if not found:
            fh.write("# none: a healthy capture\n")
        for (frame, expert), count in sorted(found.items()):
            for _ in range(count):
                fh.write("%d %s%s\n" % (frame, expert, " end" if frame in end and expert.endswith(
                    ".no_response") else ""))


def diff_text(want, got):
    missing = sorted((want - got).elements())
    added = sorted((got - want).elements())
    return missing, added


def run_protocol(check, env, args, kind, rules, proto):
    corpus = os.path.join(args.corpus, kind)
    env.install_plugin(args.dissgen, os.path.join(args.source_dir, rules))
    experts, has_link = registered(env, proto)
    for name in corpus_captures(corpus):
        with open(os.path.join(corpus, name), "rb") as fh:
            path = env.add_file(kind + "-" + name, fh.read())
        listed = os.path.join(args.source_dir, "tests", "findings", kind, name + ".findings")
        two, named2 = findings(env, path, proto, experts, has_link, True)
        one, named1 = findings(env, path, proto, experts, has_link, False)
        lost = {f for (f, e) in two if e == proto + ".expert.no_response"}
        proved = {x for xs in named1.values() for x in xs}
        if args.write:
            write_list(listed, name, two, lost - proved)
            print("wrote %s (%d findings)" % (listed, sum(two.values())))
            continue
        if not os.path.isfile(listed):
            check(False, "%s: no reviewed list %s" % (name, listed))
            continue
        bad = impossible_values(env, path, proto)
        check(not bad, "%s: no negative count, length, working counter or time in any field or expert "
              "text (%s)" % (name, bad[:4]))
        want, end = read_list(listed)
        missing, added = diff_text(want, two)
        check(not missing and not added, "%s, -2: the %d findings reviewed, no more, no fewer (missing %s, added %s)" % (
            name, sum(want.values()), missing[:6], added[:6]))
        no_response = proto + ".expert.no_response"
        others1 = collections.Counter({k: v for k, v in one.items() if k[1] != no_response})
        others2 = collections.Counter({k: v for k, v in want.items() if k[1] != no_response})
        missing, added = diff_text(others2, others1)
        check(not missing and not added, "%s, one pass: the same findings but for losses (missing %s, added %s)" % (
            name, missing[:6], added[:6]))
        want_lost = {f for (f, e) in want if e == no_response}
        unlinked = sorted(f for (f, e) in one if e == no_response and f not in named1)
        check(proved == want_lost - end and not unlinked,
              "%s, one pass: each loss reported on the frame that proves it, naming it (%d; missing %s, "
              "wrong %s, unlinked %s)" % (name, len(proved), sorted(want_lost - end - proved)[:6],
                                          sorted(proved - (want_lost - end))[:6], unlinked[:6]))
        check(named2 == named1, "%s: -2 keeps the links of one pass on the proving frames" % name)


class TestFindings(TsharkTestCase, unittest.TestCase):
    def protocol(self, kind):
        rules, proto = PROTOCOLS[kind]
        if not ARGS.corpus:
            ARGS.corpus = os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus")
        corpus = os.path.join(ARGS.corpus, kind)
        if not corpus_captures(corpus):
            self.skipTest("no corpus at %s (no *.pcap/*.pcapng)" % corpus)
        with TsharkEnv() as env:
            if ARGS.write:
                run_protocol(Checks(), env, ARGS, kind, rules, proto)
                return
            with self.checks() as check:
                run_protocol(check, env, ARGS, kind, rules, proto)

    def test_ethercat_findings_as_reviewed(self):
        self.protocol("ethercat")

    def test_enip_findings_as_reviewed(self):
        self.protocol("enip")


def add_arguments(parser):
    parser.add_argument("--corpus", help="the corpus (default ../shared/corpus)")
    parser.add_argument("--write", action="store_true", help="rewrite the lists (then review them)")


if __name__ == "__main__":
    sys.exit(run_unittests(add_arguments)[1])

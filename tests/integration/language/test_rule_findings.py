#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Findings from the rules (<finding>) with real tshark: tests/rules/findings.xml.

Random replies on ethertype 0x88b7, the faults put in by the test: a value
above 1000 in some items, a status other than 0 in some replies, an odd count
of values with status 0 in others, the extended status's top bit (read by an
overlay) in failed ones. Each expert info must sit exactly on the
frames (and items) where its condition holds, with its text, severity and
group, and nowhere else: in one pass and with -2, filterable by its name,
counted by `tshark -z expert`. Needs no corpus.

    test_rule_findings.py --dissgen build/bin/dissgen --source-dir .
"""

import collections
import os
import random
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from pcapgen import raw_pcap_bytes  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

ARGS = None
ETHERTYPE = 0x88B7
STATUS_NAMES = {0: "Success", 8: "Service not supported"}
# _ws.expert.severity and .group as -T fields prints them (Wireshark's PI_ values)
SEVERITY = {"Chat": 0x00200000, "Note": 0x00400000, "Warning": 0x00600000, "Error": 0x00800000}
GROUP = {"Sequence": 0x02000000, "Response code": 0x03000000, "Protocol": 0x09000000}


def reply(rng):
    """(service, values, status, extended), the fault put in by chance."""
    service = rng.randrange(256)
    values = [rng.choice([0, 999, 1000, 1001, 65535, rng.randrange(1001), rng.randrange(65536)])
              for _ in range(rng.choice([0, 1, 2, 3, 5]))]
    status = rng.choice([0, 0, 0, 8, 1, 255])
    return service, values, status, rng.randrange(65536)


def body(service, values, status, extended):
    return struct.pack(">BB", service, len(values)) + b"".join(struct.pack(">H", v) for v in values) + \
        struct.pack(">BH", status, extended)


def expected(service, values, status, extended):
    """[(finding, severity, group, text)] in tree order."""
    out = [("value_high", "Warning", "Protocol", "Item %d: value %d is above 1000" % (i + 1, v))
           for i, v in enumerate(values) if v > 1000]
    if status != 0 and extended & 0x8000:  # on the overlay inside the reply, before the reply's own
        out.append(("retry", "Error", "Sequence", "failed, retry advised"))
    if status != 0:
        name = STATUS_NAMES.get(status, "Unknown (0x%02x)" % status)
        out.append(("error_status", "Note", "Response code",
                    "Service 0x%02x failed: %s, extended status 0x%04x" % (service, name, extended)))
    if len(values) % 2 == 1 and status == 0:
        out.append(("odd_count", "Chat", "Sequence", "%d values" % len(values)))
    return out


def ethernet_frame(data):
    f = b"\x02\0\0\0\0\x02\x02\0\0\0\0\x01" + struct.pack("!H", ETHERTYPE) + data
    return f + bytes(max(0, 60 - len(f)))


def replies(seed, count):
    rng = random.Random(seed)
    return [reply(rng) for _ in range(count)]


class TestRuleFindings(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "findings.xml"), "rfind")
        cls.replies = replies(4040, 400)
        frames = [ethernet_frame(body(*r)) for r in cls.replies]
        cls.path = cls.env.add_file("findings.pcap", raw_pcap_bytes(frames))
        # the same replies without a fault: values at most 1000, an even count, status 0
        clean = [ethernet_frame(body(s, [v % 1001 for v in vals] + [0] * (len(vals) % 2), 0, e))
                 for s, vals, _, e in cls.replies]
        cls.clean = cls.env.add_file("clean.pcap", raw_pcap_bytes(clean))

    def test_faults_found_exactly_where_they_are(self):
        fields = ["frame.number", "_ws.expert.message", "_ws.expert.severity", "_ws.expert.group"]
        faulty = sum(1 for r in self.replies if expected(*r))
        with self.checks() as check:
            check(0 < faulty < len(self.replies), "%d of %d replies have a fault" % (faulty, len(self.replies)))
            for two_pass in (False, True):
                mode = "-2" if two_pass else "one pass"
                rows = self.env.field_rows(self.path, fields, two_pass, aggregator="|")
                wrong = []
                for n, r in enumerate(self.replies, 1):
                    want = [(str(SEVERITY[sev]), str(GROUP[grp]), text) for _, sev, grp, text in expected(*r)]
                    got = list(zip(rows[n]["_ws.expert.message"], rows[n]["_ws.expert.severity"],
                                   rows[n]["_ws.expert.group"]))
                    got = [(sev, grp, text) for text, sev, grp in got]
                    if got != want:
                        wrong.append((n, got, want))
                check(not wrong, "%s: every frame's expert infos are exactly its faults (%d frames%s)" % (
                    mode, len(self.replies), "" if not wrong else "; wrong: %s" % wrong[:2]))

    def test_each_finding_filters_and_counts(self):
        counts = collections.Counter(f for r in self.replies for f, *_ in expected(*r))
        with self.checks() as check:
            for name in ("value_high", "error_status", "odd_count", "retry"):
                for two_pass in (False, True):
                    args = ["-r", self.path, "-Y", "rfind.finding." + name, "-T", "fields", "-e", "frame.number"]
                    frames = self.env.tshark(args + (["-2"] if two_pass else [])).stdout.split()
                    want = [str(n) for n, r in enumerate(self.replies, 1) if any(f == name for f, *_ in expected(*r))]
                    check(frames == want, "%s: -Y rfind.finding.%s keeps the %d frames with that fault" % (
                        "-2" if two_pass else "one pass", name, len(want)))
            out = self.env.tshark(["-r", self.path, "-q", "-z", "expert"]).stdout
            for name, severity in (("value_high", "Warns"), ("error_status", "Notes"), ("odd_count", "Chats"),
                                   ("retry", "Errors")):
                section = re.search(r"\n%s \((\d+)\)\n" % severity, out)
                check(section is not None and int(section.group(1)) == counts[name],
                      "-z expert counts %d %s (%s)" % (counts[name], severity, name))

    def test_clean_capture_raises_nothing(self):
        for two_pass in (False, True):
            rows = self.env.field_rows(self.clean, ["frame.number", "_ws.expert.message"], two_pass)
            raised = {n: r["_ws.expert.message"] for n, r in rows.items() if r["_ws.expert.message"]}
            self.assertEqual(raised, {}, "no finding on clean replies (%s)" % ("-2" if two_pass else "one pass"))

    def test_node_cut_short_raises_no_finding(self):
        """A reply cut off before its extended status is malformed: the reply was not
        decoded whole, so its odd_count finding (whose condition its earlier fields
        would make hold) is not raised; the whole frames around it still raise theirs."""
        whole = body(0x21, [5], 0, 0)
        cut = b"\x02\0\0\0\0\x02\x02\0\0\0\0\x01" + struct.pack("!H", ETHERTYPE) + whole[:-2]
        path = self.env.add_file("cut.pcap", raw_pcap_bytes([ethernet_frame(whole), cut, ethernet_frame(whole)]))
        for two_pass in (False, True):
            rows = self.env.field_rows(path, ["frame.number", "_ws.expert.message"], two_pass)
            messages = {n: r["_ws.expert.message"] for n, r in rows.items()}
            self.assertIn("1 values", messages[1])
            self.assertIn("1 values", messages[3])
            self.assertTrue(any(m.startswith("Truncated") for m in messages[2]), messages[2])
            self.assertNotIn("1 values", messages[2], "no finding on the reply cut short")

    def test_finding_sits_beside_its_item_on_its_bytes(self):
        n = next(i for i, r in enumerate(self.replies, 1) if any(v > 1000 for v in r[1]))
        out = self.env.tshark(["-r", self.path, "-V", "-Y", "frame.number == %d" % n]).stdout
        self.assertRegex(out, r"Value: (\d+)\n\s+Item \d+: value \1 is above 1000\n"
                              r"\s+\[Expert Info \(Warning/Protocol\): Item \d+: value \1 is above 1000\]")


# A <finding> in a <group> used twice: one expert info, raised by each use.
TWO_POINTS_RULES = """<root name="Two points" abbreviation="TWOPT" ethertype="0x88b6">
  <group name="Point">
    <node name="X" length="2byte" displaytype="numberdec"/>
    <node name="Y" length="2byte" displaytype="numberdec"/>
    <finding name="on_axis" severity="warning" group="protocol" condition="{X} == 0 || {Y} == 0"
             text="on an axis at {X},{Y}"/>
  </group>
  <node name="From"><use group="Point"/></node>
  <node name="To"><use group="Point"/></node>
</root>
"""


class TestFindingInAGroupUsedTwice(TsharkTestCase, unittest.TestCase):
    """One name, one expert info registered: it fires inside each use where its condition
    holds there, with that use's values, and nowhere else; one pass and -2."""

    POINTS = [((0, 5), (3, 4)), ((3, 4), (7, 0)), ((0, 0), (0, 9)), ((3, 4), (5, 6))]

    @classmethod
    def prepare(cls):
        cls.install_text("two_points.xml", TWO_POINTS_RULES, "twopt")
        frames = [b"\x02\0\0\0\0\x02\x02\0\0\0\0\x01\x88\xb6" + struct.pack(">4H", *a, *b) + bytes(38)
                  for a, b in cls.POINTS]
        cls.path = cls.env.add_file("two_points.pcap", raw_pcap_bytes(frames))

    def test_each_use_raises_it(self):
        with self.checks() as check:
            fields = self.env.tshark(["-G", "fields"]).stdout
            check(len(re.findall(r"\ttwopt\.finding\.on_axis\t", fields)) == 1, "registered once")
            for two_pass in (False, True):
                how = "-2" if two_pass else "one pass"
                text = self.env.tshark(["-r", self.path, "-V", "-O", "twopt"] + (["-2"] if two_pass else [])).stdout
                frames = re.split(r"^Frame \d+:", text, flags=re.M)[1:]
                for tree, points in zip(frames, self.POINTS):
                    got, use = [], None
                    for line in tree.splitlines():
                        if re.match(r"^    (From|To)$", line):
                            use = line.strip()
                        elif re.match(r"^\s+\[Expert Info \(Warning/Protocol\): ", line):
                            got.append((use, line.split("): ", 1)[1].rstrip("]")))
                    want = [(use, "on an axis at %d,%d" % p) for use, p in zip(("From", "To"), points) if 0 in p]
                    check(got == want, "%s %s: %s, expected %s" % (how, points, got, want))
                rows = self.env.field_rows(self.path, ["frame.number"], two_pass, display_filter="twopt.finding.on_axis")
                check(sorted(rows) == [1, 2, 3], "%s: the filter finds frames %s" % (how, sorted(rows)))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

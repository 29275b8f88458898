#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Overlays (overlay="XPATH") with real tshark: tests/rules/overlays.xml.

Random messages on ethertype 0x88b7: a status word and, over it, its bit
flags; an option byte and, when it is 1, a 2-byte extension (a container)
with an overlay of its two bytes; a body of raw bytes with two overlays, a
record (type, name, 16-bit items to its end) and a head of `Head length`
bytes; a trailer. Every value is compared with the bytes, in one pass and
with -2; the trailer and the fields after each overlay sit where they would
without it; malformed messages (a head longer than the body, an odd byte
left for an item, a frame cut inside the body) give their expert info and
the tree decoded before it; the record's own finding (a type from 128) is
raised on every record decoded whole and never on one cut short. Needs no
corpus.

    test_overlays.py --dissgen build/bin/dissgen --source-dir .
"""

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

ETHERTYPE = 0x88B7
HEADER = b"\x02\0\0\0\0\x02\x02\0\0\0\0\x01" + struct.pack("!H", ETHERTYPE)
FIELDS = ["frame.number", "ovl.status", "ovl.flags.ready", "ovl.flags.error", "ovl.flags.code", "ovl.flags.state",
          "ovl.options", "ovl.extension.word", "ovl.ext.low", "ovl.ext.high", "ovl.length", "ovl.head_length",
          "ovl.body", "ovl.record.type", "ovl.record.name", "ovl.record.item", "ovl.head.head_bytes",
          "ovl.trailer"]
KINDS = ["ok"] * 7 + ["head_past", "odd", "cut"]


def message(rng):
    kind = rng.choice(KINDS)
    status = rng.randrange(65536)
    options = rng.choice([0, 1, 2])
    ext = rng.randrange(65536)
    name = "".join(rng.choice("abcxyz") for _ in range(rng.randrange(6)))
    items = [rng.randrange(65536) for _ in range(rng.randrange(4))]
    body = bytes([rng.randrange(256), len(name)]) + name.encode() + b"".join(struct.pack("<H", i) for i in items)
    if kind == "odd":
        body += b"\xee"
    head = len(body) + rng.randrange(1, 4) if kind == "head_past" else rng.randrange(len(body) + 1)
    trailer = rng.randrange(65536)
    pre = struct.pack("<HB", status, options) + (struct.pack("<H", ext) if options == 1 else b"")
    pre += bytes([len(body), head])
    data = pre + body + struct.pack("<H", trailer)
    cut = None
    if kind == "cut":
        cut = rng.randrange(len(body))  # body bytes left in the frame
        data = pre + body[:cut]
    m = dict(kind=kind, status=status, options=options, ext=ext, name=name, items=items, body=body, head=head,
             trailer=trailer, cut=cut, pre=len(pre))
    return m, data


def hexbytes(b):
    return b.hex(" ")


def expected(m):
    """What each field shows, as tshark -T fields prints it ("" when absent)."""
    s, kind, body = m["status"], m["kind"], m["body"]
    want = {
        "ovl.status": "0x%04x" % s, "ovl.flags.ready": str(s & 1), "ovl.flags.error": str((s >> 1) & 1),
        "ovl.flags.code": str((s >> 2) & 0x3F), "ovl.flags.state": str(s >> 8), "ovl.options": "0x%02x" % m["options"],
        "ovl.extension.word": "0x%04x" % m["ext"] if m["options"] == 1 else "",
        "ovl.ext.low": str(m["ext"] & 0xFF) if m["options"] == 1 else "",
        "ovl.ext.high": str(m["ext"] >> 8) if m["options"] == 1 else "",
        "ovl.length": str(len(body)), "ovl.head_length": str(m["head"]),
        "ovl.body": hexbytes(body), "ovl.record.type": str(body[0]), "ovl.record.name": m["name"],
        "ovl.record.item": ",".join("0x%04x" % i for i in m["items"]),
        "ovl.head.head_bytes": hexbytes(body[:m["head"]]), "ovl.trailer": "0x%04x" % m["trailer"],
    }
    if kind == "head_past":      # the head shows the body's bytes, then the message stops
        want["ovl.head.head_bytes"] = hexbytes(body)
        want["ovl.trailer"] = ""
    elif kind == "odd":          # the record's last item is short: the message stops there
        want["ovl.head.head_bytes"] = want["ovl.trailer"] = ""
    elif kind == "cut":          # the body is cut short: the bytes there, no overlay, nothing after
        want["ovl.body"] = hexbytes(body[:m["cut"]])
        for f in ("ovl.record.type", "ovl.record.name", "ovl.record.item", "ovl.head.head_bytes", "ovl.trailer"):
            want[f] = ""
    return want


EXPERTS = {"head_past": "ovl.expert.past_end", "odd": "ovl.expert.truncated", "cut": "ovl.expert.past_end"}


class TestOverlays(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "overlays.xml"), "ovl")
        rng = random.Random(4242)
        cls.messages = [message(rng) for _ in range(400)]
        # a frame cut inside the body stays short; the others are padded to Ethernet's 60 bytes
        frames = [HEADER + data + bytes(0 if m["kind"] == "cut" else max(0, 60 - len(HEADER + data)))
                  for m, data in cls.messages]
        cls.path = cls.env.add_file("overlays.pcap", raw_pcap_bytes(frames))

    def test_every_value_as_read_from_the_bytes(self):
        kinds = {k: sum(1 for m, _ in self.messages if m["kind"] == k) for k in set(KINDS)}
        self.assertTrue(all(kinds.values()), kinds)
        with self.checks() as check:
            for two_pass in (False, True):
                mode = "-2" if two_pass else "one pass"
                rows = self.env.field_rows(self.path, FIELDS, two_pass, aggregator=",")
                wrong = {}
                for n, (m, _) in enumerate(self.messages, 1):
                    for f, w in expected(m).items():
                        g = ",".join(rows[n][f])
                        if g != w:
                            wrong.setdefault(f, []).append((n, m["kind"], g, w))
                for f in FIELDS[1:]:
                    check(f not in wrong, "%s: %s as read from the bytes in all %d messages %s%s" % (
                        mode, f, len(self.messages), kinds, "" if f not in wrong else " (wrong: %s)" % wrong[f][:3]))

    def test_overlays_start_at_their_target_and_the_walk_does_not_move(self):
        pdml = self.env.tshark(["-r", self.path, "-T", "pdml", "-c", "60"]).stdout
        packets = pdml.split("<packet>")[1:]
        pos = lambda text, name: [int(p) for p in re.findall(r'<field name="%s"[^>]* pos="(\d+)"' % re.escape(name),
                                                             text)]
        with self.checks() as check:
            checked = 0
            for (m, _), text in zip(self.messages, packets):
                if m["kind"] != "ok":
                    continue
                checked += 1
                body_at = 14 + m["pre"]
                want = {"ovl.status": [14], "ovl.flags": [14], "ovl.flags.state": [15],
                        "ovl.length": [body_at - 2], "ovl.body": [body_at], "ovl.record": [body_at],
                        "ovl.record.type": [body_at], "ovl.head": [body_at],
                        "ovl.trailer": [body_at + len(m["body"])]}
                if m["options"] == 1:
                    want.update({"ovl.extension": [17], "ovl.ext": [17], "ovl.ext.high": [18]})
                for name, at in want.items():
                    got = pos(text, name)
                    check(got == at, "frame %d: %s at %s (got %s)" % (checked, name, at, got))
            check(checked > 20, "%d well-formed frames checked" % checked)

    def test_malformed_messages_give_expert_infos_and_the_tree_so_far(self):
        with self.checks() as check:
            for expert in sorted(set(EXPERTS.values())):
                got = self.env.tshark(["-r", self.path, "-Y", expert, "-T", "fields", "-e", "frame.number"]
                                      ).stdout.split()
                kinds = sorted(k for k, e in EXPERTS.items() if e == expert)
                want = [str(n) for n, (m, _) in enumerate(self.messages, 1) if m["kind"] in kinds]
                check(got == want, "%s: exactly the %d %s messages (got %d)" % (expert, len(want), "/".join(kinds),
                                                                                len(got)))
            malformed = "_ws.expert.group == 0x07000000"  # PI_MALFORMED: not the record's own finding
            clean = self.env.tshark(["-r", self.path, "-Y", malformed, "-T", "fields", "-e", "frame.number"]
                                    ).stdout.split()
            bad = [str(n) for n, (m, _) in enumerate(self.messages, 1) if m["kind"] != "ok"]
            check(clean == bad, "no malformed expert info on the %d well-formed messages" % (
                len(self.messages) - len(bad)))

    def test_record_finding_only_on_records_decoded_whole(self):
        """The record overlay stops at an odd byte left for an item ("odd"): its
        finding is not raised there, though its type was read; a head past the
        body stops the message after the record, which was decoded whole."""
        vendor = lambda m: m["kind"] != "cut" and m["body"][0] >= 128
        want = [str(n) for n, (m, _) in enumerate(self.messages, 1) if vendor(m) and m["kind"] != "odd"]
        odd = sum(1 for m, _ in self.messages if vendor(m) and m["kind"] == "odd")
        with self.checks() as check:
            check(odd > 0 and want, "%d odd records of a vendor type, %d whole ones" % (odd, len(want)))
            for two_pass in ([], ["-2"]):
                got = self.env.tshark(["-r", self.path, "-Y", "ovl.finding.vendor_record", "-T", "fields",
                                       "-e", "frame.number"] + two_pass).stdout.split()
                check(got == want, "%s: the finding on exactly the %d whole records of a vendor type (got %d)" % (
                    "-2" if two_pass else "one pass", len(want), len(got)))

    def test_record_summary_in_the_info_column(self):
        rows = self.env.field_rows(self.path, ["frame.number", "_ws.col.Info"], aggregator="\x01")
        with self.checks() as check:
            wrong = [(n, rows[n]["_ws.col.Info"]) for n, (m, _) in enumerate(self.messages, 1)
                     if m["kind"] == "ok" and rows[n]["_ws.col.Info"] != ["%d %s" % (m["body"][0], m["name"])]]
            check(not wrong, "the record's summary '{Type} {Name}' is the Info column (wrong: %s)" % wrong[:3])


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

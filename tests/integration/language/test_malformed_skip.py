#!/usr/bin/env python3
"""malformed="skip" with real tshark: tests/rules/skip.xml.

Messages of Count records, each a Length and a Body of that length (an Id, an
Items count, that many 2-byte items), then a 2-byte trailer. A Body whose items
need more bytes than its Length gives is malformed: with malformed="skip" the
expert info marks the spot, the rest of that Body is skipped and the next records
and the trailer are decoded from where the Length says; the same rules without
the attribute (protocol skps, built here) stop at the spot, as the contract says
for every other container. A Body longer than the packet is not skipped (its end
is not in the packet). Values are checked against the bytes written here, in one
pass and with -2.

    test_malformed_skip.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkEnv, run_unittests  # noqa: E402
from test_enip import pcap  # noqa: E402

ARGS = None
ENV = None
RULES = os.path.join("tests", "rules", "skip.xml")
SKIP, STOP = 0x88B6, 0x88B7


def frame(ethertype, payload):
    f = b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01" + struct.pack("!H", ethertype) + payload
    return f + bytes(max(0, 60 - len(f)))


def record(ident, items, length=None):
    body = bytes([ident, len(items)]) + b"".join(struct.pack("!H", i) for i in items)
    return bytes([len(body) if length is None else length]) + body


GOOD = bytes([2]) + record(0x11, [0xAAAA]) + record(0x22, [0xBBBB, 0xCCCC]) + b"\xfe\xed"
# Record 1 says one item, but its Length leaves one byte for it: truncated inside Body.
BAD_INSIDE = bytes([2]) + record(0x11, [0xAAAA], length=3)[:4] + record(0x22, [0xBBBB, 0xCCCC]) + b"\xfe\xed"
# Record 2's Length runs past the end of the packet.
BAD_LENGTH = bytes([2]) + record(0x11, [0xAAAA]) + bytes([200, 0x22, 1]) + b"\xbb"

FIELDS = ["body.id", "body.items", "body.item", "trailer"]


def decode(cap, proto, extra=()):
    names = ["%s.record.%s" % (proto, f) if f != "trailer" else "%s.trailer" % proto for f in FIELDS]
    args = ["-r", cap, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=|", "-e", "_ws.col.Info",
            "-e", "_ws.expert.message"] + [a for n in names for a in ("-e", n)] + list(extra)
    rows = []
    for line in ENV.tshark(args).stdout.splitlines():
        cols = line.split("\t")
        rows.append(dict(zip(["info", "experts"] + FIELDS, cols)))
    return rows


class MalformedSkip(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        global ENV
        ENV = TsharkEnv()
        rules = open(os.path.join(ARGS.source_dir, RULES)).read()
        ENV.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, RULES))
        # The control: the same rules without malformed="skip", another protocol and ethertype.
        stop = rules.replace(' malformed="skip"', "").replace('"SKPT"', '"SKPS"').replace('"Skip test"', '"Stop test"').replace("0x88b6", "0x88b7")
        assert stop != rules and 'malformed=' not in re.sub(r"<!--.*?-->", "", stop, flags=re.S)
        ENV.install_plugin(ARGS.dissgen, ENV.add_file("skip_stop.xml", stop.encode()))
        messages = [GOOD, BAD_INSIDE, BAD_LENGTH]
        cls.cap = ENV.add_file("skip.pcap", pcap([frame(SKIP, m) for m in messages] +
                                                 [frame(STOP, m) for m in messages]))

    @classmethod
    def tearDownClass(cls):
        ENV.cleanup()

    def rows(self):
        one, two = decode(self.cap, "skpt"), decode(self.cap, "skpt", ["-2"])
        self.assertEqual(one, two, "one pass and -2 differ")
        one_s, two_s = decode(self.cap, "skps"), decode(self.cap, "skps", ["-2"])
        self.assertEqual(one_s, two_s, "one pass and -2 differ (control)")
        return one[:3], one_s[3:]

    def test_a_clean_message_decodes_whole_and_quietly(self):
        skip, stop = self.rows()
        for r in (skip[0], stop[0]):
            self.assertEqual((r["body.id"], r["body.items"], r["body.item"], r["trailer"]),
                             ("0x11|0x22", "1|2", "0xaaaa|0xbbbb|0xcccc", "0xfeed"))
            self.assertEqual(r["experts"], "")

    def test_skip_goes_on_after_the_malformed_container(self):
        skip, _ = self.rows()
        r = skip[1]
        self.assertEqual(r["experts"], "Truncated: 'Item' needs 2 bytes, only 1 left")
        self.assertEqual(r["body.id"], "0x11|0x22")     # the next record is decoded
        self.assertEqual(r["body.item"], "0xbbbb|0xcccc")
        self.assertEqual(r["trailer"], "0xfeed")
        self.assertIn("0x22", r["info"])

    def test_without_skip_decoding_stops_at_the_spot(self):
        _, stop = self.rows()
        r = stop[1]
        self.assertEqual(r["experts"], "Truncated: 'Item' needs 2 bytes, only 1 left")
        self.assertEqual((r["body.id"], r["body.item"], r["trailer"]), ("0x11", "", ""))

    def test_a_length_past_the_packet_is_not_skipped(self):
        skip, stop = self.rows()
        for r in (skip[2], stop[2]):
            self.assertIn("'Body' has length 200, past the end of its data", r["experts"])
            self.assertEqual(r["trailer"], "")


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

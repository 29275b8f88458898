#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Values learned for ranges of keys (<key span="...">) with real tshark:
tests/rules/learned_ranges.xml on ethertype 0x88c4.

A Window message gives a device the addresses start .. start + size - 1 of a segment; each
byte of a later Data message of that segment looks its address up and shows the device whose
window holds it (Owner) and its offset in that window, or raises win.finding.unmapped. The
expected values come from a model of the frames in order (the truth of the bytes): each device
has one window per segment (the key's id), which its next Window message moves, or removes with
size 0; where windows overlap the one taught latest wins; a Window cut short teaches nothing;
each segment has its own windows. A Pieces message is laid out piece by piece, each from its address to the end of the
window that holds it or of its bytes (a byte no window holds alone): each piece's address,
owner and length are checked against the model too. The same values in one pass, with -2, and with -2 and a display filter that keeps
every third frame. Needs no corpus.

    test_learned_ranges.py --dissgen build/bin/dissgen --source-dir .
"""

import os
import random
import struct
import sys
import unittest
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from pcapgen import raw_pcap_bytes  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

ETHERTYPE = 0x88C4
SENDER = b"\x02\0\0\0\0\x01"


def frame(payload):
    return b"\x02\0\0\0\0\xff" + SENDER + struct.pack("!H", ETHERTYPE) + payload


def window(segment, device, start, size, cut=False):
    data = struct.pack("!BBBHB", 1, segment, device, start, size)
    return data[:5] if cut else data


def data(segment, address, values):
    return struct.pack("!BBHB", 2, segment, address, len(values)) + bytes(values)


def pieces(segment, address, values):
    return struct.pack("!BBHB", 3, segment, address, len(values)) + bytes(values)


def holder(windows, segment, at):
    """The window (segment, start, end, device) taught latest that holds `at`, or None."""
    return next((w for w in reversed(windows) if w[0] == segment and w[1] <= at < w[2]), None)


def laid_out(windows, segment, address, count):
    """[(address, owner, length) of each piece] of a Pieces message."""
    out = []
    while count > 0:
        w = holder(windows, segment, address)
        length = min(w[2] - address, count) if w else 1
        out.append((address, w[3] if w else None, length))
        address, count = address + length, count - length
    return out


def overtaken(windows, w):
    """Whether a window taught after w overlaps it (teaching w again makes it the latest)."""
    later = windows[windows.index(w) + 1:]
    return any(o[0] == w[0] and o[1] < w[2] and w[1] < o[2] for o in later)


def expected(messages):
    """{frame: [(address, owner, offset, unmapped findings) of each byte]} of the Data
    frames (owner, offset None and one finding where no window holds the byte), and {frame:
    [(address, owner, length) of each piece]} of the Pieces frames, by a model of the rules:
    the windows taught by earlier frames, the latest taught first."""
    windows, out = [], []  # windows: [(segment, start, end, device)], latest last
    out = {}
    for number, (kind, fields) in enumerate(messages, 1):
        if kind == "window":
            segment, device, start, size, cut = fields
            if cut:
                continue
            taught = (segment, start, start + size, device)
            if taught in windows and not overtaken(windows, taught):
                continue  # said again: no change
            windows = [w for w in windows if (w[0], w[3]) != (segment, device)]
            if size:
                windows.append(taught)
            continue
        segment, address, values = fields
        if kind == "pieces":
            out[number] = laid_out(windows, segment, address, len(values))
            continue
        row = []
        for i in range(len(values)):
            at = address + i
            w = holder(windows, segment, at)
            row.append((at, w[3], at - w[1], 0) if w else (at, None, None, 1))
        out[number] = row
    return out


def scripted():
    """Each rule of the construct once, in order."""
    return [
        ("data", (0, 0x100, [1])),                # 1: nothing learned: unmapped
        ("window", (0, 7, 0x100, 4, False)),      # 2: device 7: 0x100..0x103
        ("window", (0, 8, 0x104, 2, False)),      # 3: device 8: 0x104..0x105
        ("data", (0, 0xFF, [0, 1, 2, 3, 4, 5, 6, 7])),  # 4: 0xff unmapped, 7 x4, 8 x2, 0x106 unmapped
        ("window", (0, 9, 0x102, 3, False)),      # 5: device 9 overlaps both: 0x102..0x104
        ("data", (0, 0x100, [0] * 6)),            # 6: 7 7 9 9 9 8
        ("window", (0, 5, 0x200, 0, False)),      # 7: size 0: device 5 had no window, nothing
        ("window", (0, 6, 0x200, 4, True)),       # 8: cut short: teaches nothing
        ("data", (0, 0x200, [1, 2])),             # 9: unmapped
        ("data", (1, 0x100, [1])),                # 10: segment 1 has no windows
        ("window", (0, 7, 0x100, 4, False)),      # 11: device 7 again, latest now: 7 7 7 7 8 8
        ("data", (0, 0x100, [0] * 6)),            # 12
        ("window", (0, 3, 0xFFFF, 1, False)),     # 13: the last address
        ("data", (0, 0xFFFF, [1])),               # 14: device 3
        ("pieces", (0, 0xFE, [0] * 10)),          # 15: 0xfe, 0xff alone; 7 x4, 8 x2; 0x106, 0x107 alone
        ("pieces", (0, 0x101, [0] * 2)),          # 16: one piece, cut by the bytes' end
        ("window", (0, 9, 0x102, 3, False)),      # 17: device 9 again, latest now
        ("pieces", (0, 0x100, [0] * 7)),          # 18: 7 holds 0x100: to its end, x4; 9 x1, 8 x1, 0x106
        ("window", (0, 8, 0x120, 2, False)),      # 19: device 8 moves: 0x105 is no one's
        ("data", (0, 0x103, [0] * 4)),            # 20: 7, 9, unmapped, unmapped
        ("window", (0, 9, 0x102, 0, False)),      # 21: device 9's window removed: 7 holds 0x102.. again
        ("data", (0, 0x102, [0] * 3)),            # 22: 7, 7, unmapped
        ("data", (0, 0x120, [0] * 2)),            # 23: 8, 8 at its new place
        ("window", (0, 7, 0x100, 4, True)),       # 24: cut short: device 7 keeps its window
        ("data", (0, 0x100, [0])),                # 25: 7
    ]


def random_messages(rng, count):
    out = []
    for _ in range(count):
        segment = rng.randrange(2)
        if rng.random() < 0.25:
            out.append(("window", (segment, rng.randrange(1, 12), 0x100 + rng.randrange(64), rng.randrange(0, 12),
                                   rng.random() < 0.05)))
        else:
            out.append((rng.choice(["data", "pieces"]),
                        (segment, 0xF8 + rng.randrange(80), [rng.randrange(256)] * rng.randrange(1, 10))))
    return out


def capture(messages):
    return raw_pcap_bytes([frame(payload(kind, f)) for kind, f in messages])


def payload(kind, fields):
    return {"window": window, "data": data, "pieces": pieces}[kind](*fields)


def descendants(field, name):
    return [f for f in field.iter("field") if f.get("name") == name]


def shown(field, name):
    """The number a field inside `field` shows, or None when it is not there."""
    found = descendants(field, name)
    return int(found[0].get("show"), 0) if found else None


class TestLearnedRanges(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "learned_ranges.xml"), "win")

    def decoded(self, path, two_pass, display_filter=None):
        """What expected() gives, from PDML: a finding's expert item sits at its byte's position."""
        args = ["-r", path, "-T", "pdml"] + (["-2"] if two_pass else [])
        args += ["-Y", display_filter] if display_filter else []
        root = ET.fromstring(self.env.tshark(args).stdout)
        out = {}
        for packet in root.iter("packet"):
            number = int(descendants(packet, "frame.number")[0].get("show"))
            laid = descendants(packet, "win.pieces.bytes.piece")
            if laid:
                out[number] = [(shown(p, "win.pieces.bytes.piece.byte_address"), shown(p, "win.pieces.bytes.piece.owner"),
                                shown(p, "win.pieces.bytes.piece.piece_length")) for p in laid]
                continue
            data_fields = descendants(packet, "win.data")
            if not data_fields:
                continue
            unmapped = [e.get("pos") for e in descendants(packet, "_ws.expert")
                        if descendants(e, "win.finding.unmapped")]
            out[number] = [(shown(byte, "win.data.byte.byte_address"), shown(byte, "win.data.byte.owner"),
                            shown(byte, "win.data.byte.offset"), unmapped.count(byte.get("pos")))
                           for byte in descendants(data_fields[0], "win.data.byte")]
        return out

    def check_capture(self, name, messages):
        path = self.env.add_file(name, capture(messages))
        want = expected(messages)
        with self.checks() as check:
            self.check_every_pass(check, lambda two_pass, shown: self.decoded(path, two_pass, shown), want,
                                  "each byte finds the window that holds it, win.finding.unmapped on those none holds")

    def test_each_rule_once(self):
        self.check_capture("scripted.pcap", scripted())

    def test_random_frames_against_a_model(self):
        rng = random.Random(20261201)
        self.check_capture("random.pcap", random_messages(rng, 400))


EDGE_RULES = """<root name="Range edges" abbreviation="EDGE" ethertype="0x88c4">
  <node name="Kind" length="1byte" displaytype="numberdec"/>
  <node name="Windows" if="../node[@name='Kind']" in="1">
    <node name="Count" length="1byte" displaytype="numberdec"/>
    <node name="Window" count="../node[@name='Count']">
      <node name="Device" length="1byte" displaytype="numberdec"/>
      <node name="Start" length="8byte" displaytype="numberhex"/>
      <node name="Size" length="1byte" displaytype="numberdec"/>
      <learn name="Owner" value="{Device}">
        <key value="{Start}" span="{Size}" lookup="{Address}"/>
      </learn>
    </node>
  </node>
  <node name="Read" if="../node[@name='Kind']" in="2">
    <node name="Address" length="8byte" displaytype="numberhex"/>
    <node name="Owner" value="learned{Owner}" displaytype="numberdec"/>
  </node>
</root>
"""


def windows(*taught):
    return struct.pack("!BB", 1, len(taught)) + b"".join(struct.pack("!BQB", *w) for w in taught)


def read(address):
    return struct.pack("!BQ", 2, address)


# (message, the owner a read shows or None)
EDGES = [
    (windows((8, 0xFE, 4)), None),
    (windows((7, 0x100, 4), (8, 0xFE, 4)), None),  # 8 taught again after 7 in one message: the later
    (read(0x101), 8),
    (read(0x103), 7),
    (windows((7, 0x100, 4)), None),                # 7 again: it holds the overlap now
    (read(0x101), 7),
    (read(0xFF), 8),
    (windows((5, 0x7FFFFFFFFFFFFFFE, 4)), None),   # across 2^63: keys of an unsigned 8-byte field
    (read(0x7FFFFFFFFFFFFFFF), 5),
    (read(0x8000000000000001), 5),
    (read(0x8000000000000002), None),
    (windows((6, 0xFFFFFFFFFFFFFFFE, 4)), None),   # past 2^64: modulo, to 0 and 1
    (read(0xFFFFFFFFFFFFFFFF), 6),
    (read(0x1), 6),
    (read(0x2), None),
    (read(0x100), 7),
    (windows((9, 0x0, 0x40)), None),               # a wide window: reads below it still find theirs
    (read(0x101), 7),
    (read(0x3F), 9),
    (read(0x1), 9),
    (windows((7, 0x200, 4), (8, 0x1FE, 4), (7, 0x200, 4)), None),  # 7 twice in one message: the later
    (read(0x201), 7),
    (read(0x1FF), 8),
]


class TestRangeEdges(TsharkTestCase, unittest.TestCase):
    """Windows taught together in one message (the later one in it holds the overlap), keys
    past 2^63 and windows that wrap past 2^64, as the manual says; one pass and -2."""

    @classmethod
    def prepare(cls):
        cls.install_text("edges.xml", EDGE_RULES, "edge")

    def test_edges(self):
        path = self.env.add_file("edges.pcap", raw_pcap_bytes([frame(m) for m, _ in EDGES]))
        want = {n: owner for n, (m, owner) in enumerate(EDGES, 1) if m[0] == 2}
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number", "edge.read.owner"], two_pass)
                got = {n: int(r["edge.read.owner"][0]) if r["edge.read.owner"] else None
                       for n, r in rows.items() if n in want}
                check(got == want, "%s: each read finds its window (frame: (got, want)) %s" % (
                    "-2" if two_pass else "one pass", {n: (got.get(n), w) for n, w in want.items() if got.get(n) != w}))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

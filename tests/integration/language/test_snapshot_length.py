#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Frames cut by the capture's snapshot length, with real tshark: tests/rules/capture_cut.xml.

A message of 10 records (a Length, then a Body of that many bytes of 2-byte Words), a Status
chosen by a look-ahead at the Trailer (else Other) and a 4-byte Trailer, captured whole on the
wire but kept only up to each byte in turn (pcap caplen below its length): the frame is not
malformed, so as Wireshark shows it, it gets one "[Packet size limited during capture]" item
(_ws.short) and no expert info, every Word the capture kept is decoded, and neither Status nor
Other (which one holds lies in the bytes not kept). The control: the same bytes really that short on the wire (caplen =
length) are malformed (an expert info, no _ws.short); and a Length that runs past even the
frame's length on the wire stays an error in a cut frame. A leaf the capture cut inside (an
address, a text, bytes) shows none of its bytes (its value is not known; a part would match
filters), while one really that short on the wire shows the bytes it has. So does a `rest` leaf
in a container whose length field says more than the capture kept: the bytes it has to take are
the container's on the wire, not the captured ones. One pass and -2.

    test_snapshot_length.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

RECORDS = 10
HEADER = 14  # Ethernet


def message(lie=None):
    """Count, then RECORDS records of two words (record 1's Length `lie` when given), a trailer."""
    p = bytes([RECORDS])
    for i in range(RECORDS):
        p += bytes([lie if lie is not None and i == 1 else 4]) + struct.pack(">HH", 0x1000 + i, 0x2000 + i)
    return b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01\x88\xb5" + p + b"\x00\x07\xde\xad\xbe\xef"


def words_kept(caplen):
    """The Words wholly inside the first caplen bytes, as tshark shows them."""
    out = []
    for i in range(RECORDS):
        for k, value in enumerate((0x1000 + i, 0x2000 + i)):
            if HEADER + 1 + 5 * i + 1 + 2 * k + 2 <= caplen:
                out.append("0x%04x" % value)
    return out


def pcap(records):
    """A microsecond pcap of (caplen, frame): each frame kept up to caplen."""
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for n, (caplen, frame) in enumerate(records):
        out.append(struct.pack("<IIII", 1, n, caplen, len(frame)) + frame[:caplen])
    return b"".join(out)


class SnapshotLength(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "capture_cut.xml"), "cutt")
        whole = message()
        cls.cuts = list(range(HEADER + 1, len(whole)))            # cut by the capture at every byte
        cls.short = [HEADER + 6, HEADER + 19, len(whole) - 3]     # really that short on the wire
        records = [(c, whole) for c in cls.cuts] + [(c, whole[:c]) for c in cls.short]
        records.append((HEADER + 16, message(lie=200)))           # Length 200: past the frame itself
        records.append((len(whole), whole))                        # whole: the look-ahead sees the trailer
        cls.capture = cls.env.add_file("cut.pcap", pcap(records))

    def test_cut_frames_are_not_malformed(self):
        fields = ["frame.number", "frame.cap_len", "_ws.short", "_ws.expert.message", "cutt.record.body.word",
                  "cutt.status", "cutt.other"]
        with self.checks() as check:
            for how, rows in self.env.field_rows_each_pass(self.capture, fields, aggregator="|"):
                check(len(rows) == len(self.cuts) + len(self.short) + 2, "%s: %d frames" % (how, len(rows)))
                for n, caplen in enumerate(self.cuts, 1):
                    r = rows[n]
                    check(len(r["_ws.short"]) == 1 and not r["_ws.expert.message"],
                          "%s frame %d (kept %d bytes): one _ws.short %s, no expert %s" % (
                              how, n, caplen, r["_ws.short"], r["_ws.expert.message"]))
                    check(r["cutt.record.body.word"] == words_kept(caplen),
                          "%s frame %d: words %s, kept %s" % (how, n, r["cutt.record.body.word"], words_kept(caplen)))
                    check(not r["cutt.status"] and not r["cutt.other"],
                          "%s frame %d: no alternative taken without the trailer: %s %s" % (
                              how, n, r["cutt.status"], r["cutt.other"]))
                for k, caplen in enumerate(self.short):
                    r = rows[len(self.cuts) + 1 + k]
                    check(r["_ws.expert.message"] and not r["_ws.short"],
                          "%s: %d bytes on the wire are malformed: %s, short %s" % (
                              how, caplen, r["_ws.expert.message"], r["_ws.short"]))
                whole = rows[len(rows)]
                check(whole["cutt.status"] == ["0x0007"] and not whole["cutt.other"] and not whole["_ws.short"] and
                      not whole["_ws.expert.message"], "%s: the whole frame takes Status: %s" % (how, whole))
                short_other = rows[len(self.cuts) + len(self.short)]
                check(short_other["cutt.other"] == ["0x0007"], "%s: that short on the wire, the look-ahead "
                      "fails and Other is taken: %s" % (how, short_other["cutt.other"]))
                lie = rows[len(rows) - 1]["_ws.expert.message"]
                check(any("'Body' has length 200, past the end" in m for m in lie),
                      "%s: a Length past the frame on the wire is an error in a cut frame: %s" % (how, lie))

    def test_the_cut_is_said_after_what_was_kept(self):
        """In the tree, "[Packet size limited during capture]" comes after every field the
        capture kept, also inside a Body whose Length runs past the kept bytes."""
        with self.checks() as check:
            for two_pass in (False, True):
                text = self.env.tshark(["-r", self.capture, "-V", "-O", "cutt"] + (["-2"] if two_pass else [])).stdout
                frames = re.split(r"^Frame (\d+):", text, flags=re.M)[1:]
                for number, tree in zip(frames[::2], frames[1::2]):
                    if int(number) > len(self.cuts):
                        continue
                    lines = [line.strip() for line in tree.splitlines()]
                    said = [i for i, line in enumerate(lines) if line.startswith("[Packet size limited")]
                    kept = [i for i, line in enumerate(lines) if re.match(r"(Count|Length|Word): ", line)]
                    check(len(said) == 1 and all(i < said[0] for i in kept),
                          "%s frame %s: the cut said at line %s, after the fields at %s" % (
                              "-2" if two_pass else "one pass", number, said, kept))


LEAVES_RULES = """<root name="Cut leaves" abbreviation="CUTL" ethertype="0x88b5">
  <node name="Kind" length="1byte" displaytype="numberdec"/>
  <node name="Station" length="6byte" displaytype="address"/>
  <node name="Name" length="8byte" displaytype="string"/>
  <node name="Payload" length="4byte" displaytype="origin"/>
</root>
"""


class SnapshotInsideALeaf(TsharkTestCase, unittest.TestCase):
    """Cut by the capture inside a leaf: no part of the leaf is shown, the leaves before it are."""
    LEAVES = [("cutl.station", 1, 6), ("cutl.name", 7, 8), ("cutl.payload", 15, 4)]  # field, offset, length

    @classmethod
    def prepare(cls):
        cls.install_text("cut_leaves.xml", LEAVES_RULES, "cutl")
        cls.whole = (b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01\x88\xb5" + b"\x01" + b"\xc0\xa8\x01\x02\x01\x01" +
                     b"ABCDEFGH" + b"\xde\xad\xbe\xef")
        cls.cuts = list(range(HEADER + 2, len(cls.whole)))
        records = [(c, cls.whole) for c in cls.cuts] + [(HEADER + 3, cls.whole[:HEADER + 3])]
        cls.capture = cls.env.add_file("cut_leaves.pcap", pcap(records))

    def test_no_part_of_a_cut_leaf(self):
        fields = ["frame.number", "_ws.short", "_ws.expert.message"] + [f for f, _, _ in self.LEAVES]
        with self.checks() as check:
            for how, rows in self.env.field_rows_each_pass(self.capture, fields, aggregator="|"):
                for n, caplen in enumerate(self.cuts, 1):
                    r = rows[n]
                    kept = sorted(f for f, at, length in self.LEAVES if HEADER + at + length <= caplen)
                    shown = sorted(f for f, _, _ in self.LEAVES if r[f])
                    check(shown == kept and len(r["_ws.short"]) == 1 and not r["_ws.expert.message"],
                          "%s frame %d (kept %d bytes): leaves %s, want %s; short %s, expert %s" % (
                              how, n, caplen, shown, kept, r["_ws.short"], r["_ws.expert.message"]))
                short = rows[len(self.cuts) + 1]
                check(short["cutl.station"] == ["c0:a8"] and short["_ws.expert.message"] and not short["_ws.short"],
                      "%s: really short on the wire, the bytes there and an expert: %s" % (how, short))


CONTAINER_RULES = """<root name="Cut in container" abbreviation="CUTC" ethertype="0x88b5">
  <node name="Length" length="1byte" displaytype="numberdec"/>
  <node name="Block" length="../node[@name='Length']">
    <node name="Kind" length="1byte" displaytype="numberdec"/>
    <node name="Name" length="4byte">
      <node name="Text" length="rest" displaytype="string"/>
    </node>
    <node name="Inner" length="rest" displaytype="string"/>
  </node>
  <node name="Tail" length="rest" displaytype="origin"/>
</root>
"""


class SnapshotInsideAContainer(TsharkTestCase, unittest.TestCase):
    """A `rest` leaf runs to its container's end on the wire: cut by the capture, it is not shown
    (as a leaf whose length field says more); really short on the wire, it shows what is there.
    A container inside the cut one that the capture kept whole (Name, even when it ends right
    where the capture does) ends where its own length says: its `rest` leaf is shown."""
    NAME_END = HEADER + 6  # Length, Kind, then the 4 bytes of Name

    @classmethod
    def prepare(cls):
        cls.install_text("cut_container.xml", CONTAINER_RULES, "cutc")
        cls.whole = (b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01\x88\xb5" + b"\x0b" + b"\x07" + b"wxyz" + b"abcdef" +
                     b"\x01\x02")
        cls.cuts = list(range(HEADER + 3, HEADER + 12))  # inside Name, then inside Inner
        short = cls.whole[:HEADER + 8]
        records = [(c, cls.whole) for c in cls.cuts] + [(len(cls.whole), cls.whole), (len(short), short)]
        cls.capture = cls.env.add_file("cut_container.pcap", pcap(records))

    def test_rest_in_a_cut_container(self):
        fields = ["frame.number", "_ws.short", "_ws.expert.message", "cutc.block.kind", "cutc.block.name.text",
                  "cutc.block.inner", "cutc.tail"]
        with self.checks() as check:
            for how, rows in self.env.field_rows_each_pass(self.capture, fields, aggregator="|"):
                for n, caplen in enumerate(self.cuts, 1):
                    r = rows[n]
                    text = ["wxyz"] if caplen >= self.NAME_END else []
                    check(r["cutc.block.kind"] == ["7"] and r["cutc.block.name.text"] == text and
                          not r["cutc.block.inner"] and not r["cutc.tail"] and
                          len(r["_ws.short"]) == 1 and not r["_ws.expert.message"],
                          "%s frame %d (kept %d bytes): Text %s, Inner cut by the capture not shown: %s" % (
                              how, n, caplen, text, r))
                whole = rows[len(self.cuts) + 1]
                check(whole["cutc.block.name.text"] == ["wxyz"] and whole["cutc.block.inner"] == ["abcdef"] and
                      whole["cutc.tail"] == ["01 02"] and not whole["_ws.expert.message"],
                      "%s: the whole frame: %s" % (how, whole))
                short = rows[len(self.cuts) + 2]
                check(short["cutc.block.inner"] == ["ab"] and short["_ws.expert.message"] and not short["_ws.short"],
                      "%s: really short on the wire, the bytes there and an expert: %s" % (how, short))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

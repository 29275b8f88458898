#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Messages at the edges of what a rule file says, with real tshark, in one pass and -2:

- an Ethernet frame that ends after its type: no bytes for the protocol, which still
  takes the frame (its Protocol column, no Data) with one expert info saying what is
  missing;
- a length or count from an `int` leaf that is negative (a 1-byte -1 is -1, not 255):
  P.expert.bad_length on it, and nothing after it read as items;
- a zero-length `string`: an item with the empty text, which `== ""` finds;
- a stream message whose length (pdulength) is shorter than the bytes up to its length
  field: its header shown, one expert info at the length, and no messages made up
  from the bytes after it;
- a response whose request is not in the capture: its note
  (P.expert.no_request_context) is in `-z expert` also without a tree;
- a frame shorter than nested lengths say: one expert info, the outermost length's.

    test_message_edges.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import struct
import sys
import unittest

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402
from test_enip import TcpFlow, pcap, udp  # noqa: E402

PORT = 47611
RULES = """<root name="Edges" abbreviation="EDGE" ethertype="0x88b5" byteorder="little"
      pdulength="node[@name='Size']">
  <hook table="udp.port" value="%d"/>
  <hook table="tcp.port" value="%d"/>
  <pairing>
    <key field="node[@name='Transaction']"/>
  </pairing>
  <node name="Kind" length="2byte" displaytype="numberhex"/>
  <node name="Size" length="2byte" displaytype="numberdec"/>
  <node name="Transaction" length="1byte" displaytype="numberdec"/>
  <node name="Reference" length="1byte" displaytype="numberdec" direction="request"/>
  <node name="First" value="request{Reference}" displaytype="numberdec" direction="response"/>
  <node name="Length" length="1byte" displaytype="int"/>
  <node name="Text" length="../node[@name='Length']" displaytype="string"/>
  <node name="Count" length="1byte" displaytype="int"/>
  <node name="Item" count="../node[@name='Count']" length="1byte" displaytype="numberhex"/>
  <node name="Trailer" length="1byte" displaytype="numberhex"/>
</root>
""" % (PORT, PORT + 1)


def message(txn, text=b"hi", count=2, reference=9, request=True, length=None, count_byte=None):
    body = bytes([txn]) + (bytes([reference]) if request else b"")
    body += bytes([len(text) if length is None else length]) + text
    body += bytes([count if count_byte is None else count_byte]) + bytes(range(0xA0, 0xA0 + count)) + b"\x99"
    return struct.pack("<HH", 1, 4 + len(body)) + body


def to_server(payload):
    return udp(40000, PORT, payload)


def from_server(payload):
    return udp(PORT, 40000, payload, src=(10, 1, 1, 164), dst=(10, 1, 1, 167))


# frame number -> what it is
FRAMES = [
    ("empty", b"\x02\0\0\0\0\x02\x02\0\0\0\0\x01\x88\xb5"),          # 14 bytes: no payload at all
    ("request", to_server(message(5))),
    ("response", from_server(message(5, request=False))),
    ("orphan", from_server(message(7, request=False))),              # its request was not captured
    ("negative length", to_server(message(8, text=b"", length=0xFF, count=0))),
    ("negative count", to_server(message(9, text=b"ab", count=0, count_byte=0xFF))),
    ("empty text", to_server(message(10, text=b"", count=1))),
]
TCP = TcpFlow(40001, PORT + 1)
FRAMES += [
    ("stream", TCP.segment(message(11))),
    # Size 3: shorter than Kind and Size themselves; what follows is not a message
    ("short length", TCP.segment(struct.pack("<HH", 1, 3) + message(12))),
]
NUMBER = {what: i for i, (what, _frame) in enumerate(FRAMES, 1)}


class TestMessageEdges(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install_text("edges.xml", RULES, "edge")
        cls.capture = cls.env.add_file("edges.pcap", pcap([f for _what, f in FRAMES]))

    def rows(self, two_pass):
        fields = ["frame.number", "_ws.col.Protocol", "_ws.malformed", "_ws.expert.message", "edge.kind",
                  "edge.first", "edge.text", "edge.item", "edge.trailer", "edge.expert.bad_length",
                  "edge.expert.no_request_context", "data"]
        return self.env.field_rows(self.capture, fields, two_pass=two_pass, aggregator="|")

    def test_each_edge_in_one_pass_and_two(self):
        with self.checks() as check:
            for two_pass in (False, True):
                how = "-2" if two_pass else "one pass"
                rows = self.rows(two_pass)
                row = lambda what: rows[NUMBER[what]]  # noqa: E731
                bad = [what for what, _f in FRAMES if row(what)["edge.expert.bad_length"]]
                check(bad == ["negative length", "negative count", "short length"], "%s: bad_length on %s" % (how, bad))
                malformed = [what for what, _f in FRAMES if row(what)["_ws.malformed"]]
                # bad_length is a malformed expert too (Wireshark adds _ws.malformed to each)
                check(malformed == ["empty", "negative length", "negative count", "short length"],
                      "%s: malformed: %s" % (how, malformed))
                check(row("empty")["_ws.col.Protocol"] == ["EDGE"] and not row("empty")["data"] and
                      row("empty")["_ws.expert.message"] == ["Truncated: 'Kind' needs 2 bytes, only 0 left"],
                      "%s: the empty frame is ours: %s" % (how, row("empty")))
                check(row("response")["edge.first"] == ["9"], "%s: request{Reference}: %s" % (how, row("response")))
                check(row("request")["edge.text"] == ["hi"] and row("request")["edge.item"] == ["0xa0", "0xa1"],
                      "%s: a plain request: %s" % (how, row("request")))
                for what in ("negative length", "negative count"):
                    check(not row(what)["edge.item"], "%s: %s reads no items: %s" % (how, what, row(what)["edge.item"]))
                messages = " ".join(row("negative length")["_ws.expert.message"] +
                                    row("negative count")["_ws.expert.message"])
                check(messages.count("is negative (-1)") == 2, "%s: both say -1: %s" % (how, messages))
                check(row("empty text")["edge.item"] == ["0xa0"], "%s: after an empty text: %s" % (how, row("empty text")))
                check(row("stream")["edge.kind"] == ["0x0001"], "%s: a stream message: %s" % (how, row("stream")))
                short = row("short length")
                check(short["edge.kind"] == ["0x0001"] and not short["edge.trailer"] and not short["edge.item"],
                      "%s: a short length: its header shown, nothing made up after it: %s" % (how, short))
                check(short["_ws.expert.message"] == [
                    "The message length 'Size' gives (3) is shorter than the 4 bytes up to its end; "
                    "the 13 bytes after them are not decoded"] and short["edge.expert.bad_length"],
                      "%s: a short length is one fault, told at the length: %s" % (how, short["_ws.expert.message"]))
                check(row("orphan")["edge.expert.no_request_context"] and
                      not any(row(w)["edge.expert.no_request_context"] for w, _f in FRAMES if w != "orphan"),
                      "%s: the request-context note on the orphan response only" % how)
            for extra in ([], ["-2"]):  # -T fields shows an empty text as nothing: a filter tells
                filtered = self.env.tshark(["-r", self.capture, "-Y", 'edge.text == ""', "-T", "fields",
                                            "-e", "frame.number"] + extra).stdout.split()
                check(filtered == [str(NUMBER["empty text"])], 'edge.text == "" finds the empty text: %s' % filtered)

    def test_notes_without_a_tree(self):
        """-z expert with no -V and no filter: tshark builds no tree, and the note of a
        response whose request is not known is listed all the same."""
        with self.checks() as check:
            for extra in ([], ["-2"]):
                out = self.env.tshark(["-r", self.capture, "-q", "-z", "expert"] + extra).stdout
                check("The request of this response is not known" in out, "%s -z expert lists the note:\n%s" %
                      (" ".join(extra) or "one pass", out))


class TestShortStreamHeader(TsharkTestCase, unittest.TestCase):
    """A stream message whose length says less than its 8-byte header: the header's fields,
    the one expert info at the length, and no item for the body's container (empty, it
    would show as if decoded)."""

    @classmethod
    def prepare(cls):
        cls.install_text("short_header.xml", """<root name="Short header" abbreviation="SHDR" byteorder="little"
      pdulength="node[@name='Size']">
  <hook table="tcp.port" value="48401"/>
  <node name="Type" length="3byte" displaytype="numberhex"/>
  <node name="Chunk" length="1byte" displaytype="numberhex"/>
  <node name="Size" length="4byte" displaytype="numberdec"/>
  <node name="Hello" summary="version {Version}">
    <node name="Version" length="4byte" displaytype="numberdec"/>
  </node>
</root>
""", "shdr")

    def test_header_then_nothing(self):
        flow = TcpFlow(40002, 48401)
        path = self.env.add_file("short_header.pcap", pcap([flow.segment(b"HELF" + struct.pack("<I", 4) + bytes(8))]))
        for extra in ([], ["-2"]):
            tree = self.env.tshark(["-r", path, "-V", "-O", "shdr"] + extra).stdout
            lines = [line.strip() for line in tree.splitlines()[tree.splitlines().index("Short header") + 1:]]
            self.assertEqual([x for x in lines if x and not x.startswith("[")], [
                "Type: 0x4c4548", "Chunk: 0x46", "Size: 4",
                "The message length 'Size' gives (4) is shorter than the 8 bytes up to its end; "
                "the 8 bytes after them are not decoded"], extra)


class TestHugeLengths(TsharkTestCase, unittest.TestCase):
    """A 4-byte length field of 2^31 or more points past the end: the message quotes the
    length the field holds (it was capped at 2147483648)."""

    @classmethod
    def prepare(cls):
        cls.install_text("huge_lengths.xml", """<root name="Huge lengths" abbreviation="HUGE" ethertype="0x88b5">
  <node name="Len" length="4byte" displaytype="numberdec"/>
  <node name="Body" length="../node[@name='Len']" displaytype="origin"/>
</root>
""", "huge")

    def test_past_the_end_quotes_the_field(self):
        lengths = [0x7FFFFFFF, 0x80000000, 0xFFFFFFFF, 0x100]
        frames = [b"\x02" + bytes(5) + b"\x02" + bytes(4) + b"\x01\x88\xb5" + struct.pack(">I", n) + bytes(60)
                  for n in lengths]
        path = self.env.add_file("huge_lengths.pcap", pcap(frames))
        rows = self.env.field_rows(path, ["frame.number", "_ws.expert.message"], aggregator="|")
        got = [rows[n + 1]["_ws.expert.message"] for n in range(len(lengths))]
        want = [["'Body' has length %d, past the end of its data (60 bytes left)" % n] for n in lengths]
        self.assertEqual(got, want)


NESTED_RULES = """<root name="Nested lengths" abbreviation="NEST" ethertype="0x88b5">
  <node name="Outer len" length="1byte" displaytype="numberdec"/>
  <node name="Outer" length="../node[@name='Outer len']">
    <node name="Inner len" length="1byte" displaytype="numberdec"/>
    <node name="Inner" length="../node[@name='Inner len']">
      <node name="Count" length="1byte" displaytype="numberdec"/>
      <node name="Value" length="2byte" displaytype="numberhex" count="../node[@name='Count']"/>
    </node>
    <node name="Tail len" length="1byte" displaytype="numberdec"/>
    <node name="Tail" length="../node[@name='Tail len']" displaytype="origin"/>
  </node>
</root>
"""


# A record whose length runs past the end, in a container skipped as malformed: decoding goes
# on after that container, and a fault there is its own, however far the record's length said.
SKIPPED_RULES = """<root name="Skipped record" abbreviation="SKIPREC" ethertype="0x88b6">
  <node name="Records" length="4byte" malformed="skip">
    <node name="Length" length="1byte" displaytype="numberdec"/>
    <node name="Record" length="../node[@name='Length']">
      <node name="Data" length="2byte" displaytype="numberhex"/>
    </node>
  </node>
  <node name="Trailer" length="4byte" displaytype="numberhex"/>
</root>
"""


# A box the data holds whole, inside a length past the end: a field its own end cuts short is
# a fault of its own.
BOXED_RULES = """<root name="Boxed" abbreviation="BOXED" ethertype="0x88b7">
  <node name="Outer len" length="1byte" displaytype="numberdec"/>
  <node name="Outer" length="../node[@name='Outer len']">
    <node name="Box" length="3byte">
      <node name="Item len" length="1byte" displaytype="numberdec"/>
      <node name="Item" length="../node[@name='Item len']" displaytype="origin"/>
    </node>
    <node name="Rest" length="4byte" displaytype="numberhex"/>
  </node>
</root>
"""


# A counted list the data ends in, then a field: the count is the one fault.
COUNTED_RULES = """<root name="Counted" abbreviation="COUNTED" ethertype="0x88b8">
  <node name="Count" length="1byte" displaytype="numberdec"/>
  <node name="Items" count="../node[@name='Count']">
    <node name="Item" length="1byte" displaytype="numberdec"/>
  </node>
  <node name="Trailer" length="4byte" displaytype="numberhex"/>
</root>
"""

# Tags that open a constructed value until a closing tag (BACnet's), nested: an unclosed one
# at each level runs out of data once.
NESTED_TAGS_RULES = """<root name="Nested tags" abbreviation="NTAGS" ethertype="0x88b9">
  <group name="Item" depth="4">
    <node name="Tag" length="1byte" displaytype="numberhex"/>
    <node name="Opening" value="{Tag} == 0x3e" displaytype="nondisplay"/>
    <node name="Closing" value="{Tag} == 0x3f" displaytype="nondisplay"/>
    <node name="Constructed" if="../node[@name='Opening']" in="1">
      <node name="Member" repeat="node[@name='More']">
        <use group="Item"/>
        <node name="More" value="!{Closing}" displaytype="nondisplay"/>
      </node>
    </node>
  </group>
  <node name="Items" repeat="rest"><use group="Item"/></node>
</root>
"""


class TestOneCauseOneExpert(TsharkTestCase, unittest.TestCase):
    """A frame shorter than its outer length says: that length past the end is the one
    expert info. The lengths and counts inside that end within it are not faults of their
    own (the data they miss is the data the outer length misses); one that reaches past
    the outer length's end is, and so is one cut short by the end of a box the data holds
    whole, or one after a skipped container. What the data holds is decoded."""

    @classmethod
    def prepare(cls):
        cls.install_text("nested_lengths.xml", NESTED_RULES, "nest")
        cls.install_text("skipped_record.xml", SKIPPED_RULES, "skiprec")
        cls.install_text("boxed.xml", BOXED_RULES, "boxed")
        cls.install_text("counted.xml", COUNTED_RULES, "counted")
        cls.install_text("nested_tags.xml", NESTED_TAGS_RULES, "ntags")

    def test_a_list_the_data_ends_in_is_the_one_fault(self):
        self.assert_experts(0x88b8, "counted", bytes([3, 1]), [
            "'Items' should occur 3 times, but the data ends after 1"])
        self.assert_experts(0x88b9, "nested_tags", bytes([0x3e] * 4 + [0x21]), [
            "'Member': the repeat flag 'More' says another follows, but no data is left"])

    def assert_experts(self, ethertype, name, message, want):
        """One frame of `message` bytes on `ethertype`: its expert infos are `want`, one pass and -2."""
        eth = b"\x02" + bytes(5) + b"\x02" + bytes(4) + b"\x01" + struct.pack(">H", ethertype)
        path = self.env.add_file(name + ".pcap", pcap([eth + message]))
        for how, rows in self.env.field_rows_each_pass(path, ["frame.number", "_ws.expert.message"],
                                                      aggregator="|"):
            self.assertEqual(rows[1]["_ws.expert.message"], want, how)

    def test_a_box_cut_by_its_own_end_is_its_own_fault(self):
        self.assert_experts(0x88b7, "boxed", bytes([20, 5, 1, 2, 9]), [
            "'Outer' has length 20, past the end of its data (4 bytes left)",
            "'Item' has length 5, past the end of its data (2 bytes left)"])

    def test_a_fault_after_a_skipped_record_is_its_own(self):
        self.assert_experts(0x88b6, "skipped_record", bytes([200, 1, 2, 3, 0xAA, 0xBB]), [
            "'Record' has length 200, past the end of its data (3 bytes left)",
            "Truncated: 'Trailer' needs 4 bytes, only 2 left"])

    def test_inner_lengths_within_the_outer_one_are_not_told_again(self):
        eth = b"\x02" + bytes(5) + b"\x02" + bytes(4) + b"\x01\x88\xb5"
        frames = [
            bytes([10, 7, 3, 1, 2, 3, 4]),           # Outer 10, Inner 7 with 3 values: cut before the 3rd
            bytes([10, 7, 3, 1, 2, 3, 4, 5, 6, 1]),  # cut in the Tail
            bytes([10, 7, 3, 1, 2, 3, 4, 5, 6, 30]),  # Tail len 30 reaches past Outer's 10: its own fault
            bytes([10, 3, 1, 1, 2, 5, 1, 2, 3, 4, 5]),  # whole: nothing to report
        ]
        path = self.env.add_file("nested_lengths.pcap", pcap([eth + f for f in frames]))
        want = [
            (["'Outer' has length 10, past the end of its data (6 bytes left)"], "0x0102|0x0304"),
            (["'Outer' has length 10, past the end of its data (9 bytes left)"], "0x0102|0x0304|0x0506"),
            (["'Outer' has length 10, past the end of its data (9 bytes left)",
              "'Tail' has length 30, past the end of its data (0 bytes left)"], "0x0102|0x0304|0x0506"),
            ([], "0x0102"),
        ]
        for how, rows in self.env.field_rows_each_pass(path, ["frame.number", "_ws.expert.message",
                                                             "nest.outer.inner.value"], aggregator="|"):
            got = [(rows[n]["_ws.expert.message"], "|".join(rows[n]["nest.outer.inner.value"]))
                   for n in range(1, len(frames) + 1)]
            self.assertEqual(got, want, how)


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

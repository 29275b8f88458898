#!/usr/bin/env python3
"""Values of every width drive the decoding: tests/rules/widths.xml.

Tree text comes from Wireshark's own masks and getters, so the runtime's own
reading of a value is seen only where it drives something: a length, a count,
an `if`, a repeat, a summary. Here a numeric field of every width 1..8 bytes,
in both byte orders, plain and inside a bit group, drives each of these, in
one container per width and byte order (filter wdth.wNb / wdth.wNl):

    Value          W bytes, numberhex        shown in the container's summary (Info column),
                                             if of Zero (in="0"; the first file's Value is the
                                             first value the runtime keeps: slot 0)
    Length         W bytes                   length of Data
    Count          W bytes                   count of Item
    Selector       W bytes, numberhex        if of Low half (in="0-2^(8W-1)-1") and of
                                             Pattern (in = the bytes 01 02 .. W), summary
    Pattern tail   if on Pattern, which is absent when its own if fails: no item then
    Group length / Group value / Group flag  a W-byte bit group (4 + 8W-5 + 1 bits): length
                                             of Group data, summary, if of Flagged
    Chunk          repeat on a 1-bit flag in a W-byte bit group whose other 8W-1 bits
                   give the length of Chunk data
    Box length     W bytes                   length of the container Box (2 bytes of fields)
    Record         repeat on a W-byte flag

Values are random with many edges (0, all ones, one bit, the range bounds of
the `in` lists, bytes that differ in each position). For each message the test
knows what it wrote and checks every field's -T fields values (so every length,
count, branch and repeat), the Info column (the summaries, formatted by the
runtime from its own reading of the values), and the expert infos, by message
and by filter name, for frames with a Box longer than its fields (zeros after them
are padding, wdth.padding, with no expert info), a repeat flag set with nothing
after it, a Box past the end of the data and a bit group cut short.

    test_widths.py --dissgen build/bin/dissgen --source-dir .  [--write-rules]

tests/rules/widths.xml is written by this script (--write-rules) and a test
checks that the file in the tree is what it writes.
"""
import os
import random
import struct
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
sys.dont_write_bytecode = True
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402
from test_everything import pcap, punct, tfield_uint  # noqa: E402

ARGS = None
PROTO = "wdth"
ETHERTYPE = 0x88B6      # IEEE local experimental ethertype 2: Wireshark 4.0 decodes nothing there
RULES = os.path.join("tests", "rules", "widths.xml")
COMBOS = [(w, order) for w in range(1, 9) for order in ("big", "little")]


def seg(w, order):
    return "w%d%s" % (w, order[0])


def low_half_top(w):
    return (1 << (8 * w - 1)) - 1


def pattern(w):
    """The value whose bytes are 01 02 .. w in big-endian order: every byte differs."""
    return int.from_bytes(bytes(range(1, w + 1)), "big")


# --------------------------------------------------------------------------- the rule file

def render_rules():
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           "<!--",
           "  Written by tests/integration/language/test_widths.py (option write-rules): edit that script, not this file.",
           "  Numeric fields of every width 1..8 bytes, in both byte orders, plain and in bit",
           "  groups, drive lengths, counts, if conditions, repeats and summaries.",
           "-->",
           '<root name="Widths Protocol" abbreviation="WDTH" ethertype="0x%04x">' % ETHERTYPE]
    for w, order in COMBOS:
        s = seg(w, order)
        out += [
            '  <node name="W%d %s" filter="%s" byteorder="%s"' % (w, order, s, order),
            '        summary="%s: {Value} {Selector} {Group value} {Group flag}">' % s,
            '    <node name="Value" length="%dbyte" displaytype="numberhex"/>' % w,
            '    <node name="Zero" length="1byte" displaytype="numberhex" if="../node[@name=\'Value\']" in="0"/>',
            '    <node name="Length" length="%dbyte" displaytype="numberdec"/>' % w,
            '    <node name="Data" length="../node[@name=\'Length\']" displaytype="origin"/>',
            '    <node name="Count" length="%dbyte" displaytype="numberdec"/>' % w,
            '    <node name="Item" length="1byte" displaytype="numberhex" count="../node[@name=\'Count\']"/>',
            '    <node name="Selector" length="%dbyte" displaytype="numberhex"/>' % w,
            '    <node name="Low half" length="1byte" displaytype="numberhex"',
            '          if="../node[@name=\'Selector\']" in="0-0x%x"/>' % low_half_top(w),
            '    <node name="Pattern" length="2byte" displaytype="numberhex"',
            '          if="../node[@name=\'Selector\']" in="0x%x"/>' % pattern(w),
            '    <node name="Pattern tail" length="1byte" displaytype="numberhex"',
            '          if="../node[@name=\'Pattern\']" in="0-0xffff"/>',
            '    <node name="Group length" length="4bit" displaytype="numberdec"/>',
            '    <node name="Group value" length="%dbit" displaytype="numberhex"/>' % (8 * w - 5),
            '    <node name="Group flag" length="1bit" displaytype="bool"/>',
            '    <node name="Group data" length="../node[@name=\'Group length\']" displaytype="origin"/>',
            '    <node name="Flagged" length="1byte" displaytype="numberhex" if="../node[@name=\'Group flag\']" in="1"/>',
            '    <node name="Chunk" repeat="node[@name=\'Chunk more\']">',
            '      <node name="Chunk more" length="1bit" displaytype="bool"/>',
            '      <node name="Chunk size" length="%dbit" displaytype="numberdec"/>' % (8 * w - 1),
            '      <node name="Chunk data" length="../node[@name=\'Chunk size\']" displaytype="origin"/>',
            '    </node>',
            '    <node name="Box length" length="%dbyte" displaytype="numberdec"/>' % w,
            '    <node name="Box" length="../node[@name=\'Box length\']">',
            '      <node name="Box a" length="1byte" displaytype="numberhex"/>',
            '      <node name="Box b" length="1byte" displaytype="numberdec"/>',
            '    </node>',
            '    <node name="Record" repeat="node[@name=\'Record more\']">',
            '      <node name="Record more" length="%dbyte" displaytype="numberdec"/>' % w,
            '      <node name="Record value" length="1byte" displaytype="numberhex"/>',
            '    </node>',
            '  </node>']
    out.append("</root>")
    return "\n".join(out) + "\n"


# --------------------------------------------------------------------------- messages

class Gen:
    def __init__(self, seed):
        self.rng = random.Random(seed)

    def val(self, bits, edges=()):
        """A value of `bits` bits: often an edge (0, all ones, one bit, bytes that all differ)."""
        r = self.rng.random()
        top = (1 << bits) - 1
        choices = [0, top, 1 << self.rng.randrange(bits), top >> 1, (top >> 1) + 1] + list(edges)
        if r < 0.4:
            return self.rng.choice(choices) & top
        if r < 0.55 and bits >= 8:
            return int.from_bytes(bytes(self.rng.randrange(1, 256) for _ in range(bits // 8)), "big") & top
        return self.rng.getrandbits(bits)

    def small(self, limit):
        return self.rng.randrange(0, limit + 1)

    def bytes(self, n):
        return bytes(self.rng.getrandbits(8) for _ in range(n))


def show_hex(value, bits):
    return "0x%0*x" % ((bits + 3) // 4, value)


class Message:
    """The bytes written, what each field must show (-T fields), the Info column and the
    expert infos (filter name, message) in order."""

    def __init__(self, note):
        self.note = note
        self.data = bytearray()
        self.fields = {}
        self.info = []
        self.experts = []

    def field(self, name, text):
        self.fields.setdefault("%s.%s" % (PROTO, name), []).append(text)

    def number(self, name, value, w, order, display):
        self.data += value.to_bytes(w, order)
        self.field(name, tfield_uint(value, display, w))

    def group(self, w, order, members):
        """members: (field name, bits, value, display); the first takes the low bits with
        little, the high bits with big."""
        word, used = 0, 0
        for _, bits, value, _ in members:
            assert 0 <= value < (1 << bits)
            shift = used if order == "little" else 8 * w - used - bits
            word |= value << shift
            used += bits
        assert used == 8 * w
        self.data += word.to_bytes(w, order)
        for name, _, value, display in members:
            self.field(name, tfield_uint(value, display, w))

    def blob(self, name, data):
        self.data += data
        if data:                                  # an empty byte field adds no item
            self.field(name, punct(data, " ", 1 << 30))


def build_message(g, note="valid", box_extra=None, box_zeros=(), last_record_more=False, end_after_box=False,
                  cut_group=None):
    """All 16 containers. box_extra {(w, order): n}: that Box length says n bytes more than
    its fields (and the bytes are there: zeros but for one random byte, all zeros for the
    combinations in box_zeros); last_record_more: the last container's last Record
    has its flag set (and nothing follows); end_after_box: the last container's Box length
    says 1-3 bytes more, and the message ends after its fields; cut_group: the message
    ends after that many bytes of the last container's bit group."""
    rng = g.rng
    box_extra = box_extra or {}
    m = Message(note)
    for k, (w, order) in enumerate(COMBOS):
        last = k == len(COMBOS) - 1
        s = seg(w, order)
        bits = 8 * w
        m.field(s, "1")
        value = g.val(bits, (pattern(w),))
        m.number(s + ".value", value, w, order, "hex")
        if value == 0:
            m.number(s + ".zero", g.val(8), 1, order, "hex")
        n = g.small(4)
        m.number(s + ".length", n, w, order, "dec")
        m.blob(s + ".data", g.bytes(n))
        n = g.small(3)
        m.number(s + ".count", n, w, order, "dec")
        for _ in range(n):
            m.number(s + ".item", g.val(8), 1, order, "hex")
        sel = g.val(bits, (pattern(w), low_half_top(w), low_half_top(w) + 1, pattern(w) + 1, pattern(w) - 1))
        m.number(s + ".selector", sel, w, order, "hex")
        if sel <= low_half_top(w):
            m.number(s + ".low_half", g.val(8), 1, order, "hex")
        if sel == pattern(w):
            m.number(s + ".pattern", g.val(16), 2, order, "hex")
            m.number(s + ".pattern_tail", g.val(8), 1, order, "hex")
        summary = "%s: %s %s" % (s, show_hex(value, bits), show_hex(sel, bits))
        if last and cut_group is not None:
            m.data += g.bytes(cut_group)
            m.info.append(summary + " - -")
            m.experts.append(("truncated", "Truncated: 'Group length' needs %d bytes, only %d left" % (w, cut_group)))
            return m
        glen = rng.choice([0, 1, 2, 3, 5, 15, g.small(15)])
        gval, gflag = g.val(bits - 5), g.val(1)
        m.group(w, order, [(s + ".group_length", 4, glen, "dec"), (s + ".group_value", bits - 5, gval, "hex"),
                           (s + ".group_flag", 1, gflag, "bool")])
        m.blob(s + ".group_data", g.bytes(glen))
        if gflag:
            m.number(s + ".flagged", g.val(8), 1, order, "hex")
        summary += " %s %s" % (show_hex(gval, bits - 5), "True" if gflag else "False")
        m.info.append(summary)
        nchunk = rng.randint(1, 3)
        for i in range(nchunk):
            size = rng.choice([0, 1, 3])
            m.field(s + ".chunk", "1")
            m.group(w, order, [(s + ".chunk.chunk_more", 1, int(i < nchunk - 1), "bool"),
                               (s + ".chunk.chunk_size", bits - 1, size, "dec")])
            m.blob(s + ".chunk.chunk_data", g.bytes(size))
        extra = box_extra.get((w, order), 0)
        if last and end_after_box:
            extra = rng.randint(1, 3)
        m.number(s + ".box_length", 2 + extra, w, order, "dec")
        m.field(s + ".box", "1")
        m.number(s + ".box.box_a", g.val(8), 1, order, "hex")
        m.number(s + ".box.box_b", g.val(8), 1, order, "dec")
        if last and end_after_box:
            m.experts.append(("past_end", "'Box' has length %d, past the end of its data (2 bytes left)" % (2 + extra)))
            return m
        if extra:
            # zeros are padding (no expert info); one other byte anywhere among them is reported
            gap = bytearray(extra)
            if (w, order) not in box_zeros:
                gap[rng.randrange(extra)] = rng.randrange(1, 256)
            m.data += gap
            if any(gap):
                m.experts.append(("unused", "'Box' is %d bytes, but its fields end after 2: %d bytes are not decoded"
                                  % (2 + extra, extra)))
            else:
                m.field("padding", bytes(gap).hex())
        nrec = rng.randint(1, 3)
        for i in range(nrec):
            more = i < nrec - 1 or (last and last_record_more)
            flag = (g.val(bits) or 1) if more else 0
            m.field(s + ".record", "1")
            m.number(s + ".record.record_more", flag, w, order, "dec")
            m.number(s + ".record.record_value", g.val(8), 1, order, "hex")
        if last and last_record_more:
            m.experts.append(("more_no_data", "'Record': the repeat flag 'Record more' says another follows, "
                              "but no data is left"))
    return m


def cases(g, n):
    out = [build_message(g) for _ in range(n)]
    for k, combo in enumerate(COMBOS):
        out.append(build_message(g, "Box of %s longer than its fields" % seg(*combo), box_extra={combo: 1 + k % 3}))
        out.append(build_message(g, "Box of %s padded with zeros" % seg(*combo), box_extra={combo: 1 + k % 3},
                                 box_zeros=(combo,)))
    for _ in range(3):
        out.append(build_message(g, "last Record has its flag set", last_record_more=True))
        out.append(build_message(g, "last Box past the end", end_after_box=True))
    for cut in range(8):
        out.append(build_message(g, "cut %d bytes into the last bit group" % cut, cut_group=cut))
    return out


def frame(payload):
    return b"\x02\xee\xee\xee\xee\xee\x02\x00\x00\x00\x00\x01" + struct.pack("!H", ETHERTYPE) + bytes(payload)


# --------------------------------------------------------------------------- the tests

EXPERT_NAMES = ("truncated", "past_end", "more_no_data", "count_short", "bad_length", "unused")


class Widths(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        rules = os.path.join(ARGS.source_dir, RULES)
        cls.env.install_plugin(ARGS.dissgen, rules)
        g = Gen(ARGS.seed)
        cls.cases = cases(g, ARGS.messages)
        cls.capture = cap = cls.env.add_file("widths.pcap", pcap([(frame(c.data), len(frame(c.data))) for c in cls.cases]))
        listing = subprocess_lines([ARGS.dissgen, "fields", rules])
        # the rule file's fields (the fourth column says "rules"), not the runtime's expert infos,
        # and the field the runtime registers for every protocol
        rows = [line.split("\t") for line in listing[1:]]
        cls.fields = [r[0] for r in rows if r[3] == "rules" or (r[3] == "runtime" and r[1] != "FT_NONE")]
        experts = ["%s.expert.%s" % (PROTO, e) for e in EXPERT_NAMES]
        extra = ["_ws.col.Info", "_ws.expert.message"] + experts
        args = ["-r", cap, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=|"]
        for f in cls.fields + extra:
            args += ["-e", f]
        p = cls.env.tshark(args, check=False)
        cls.stderr = p.stderr
        cls.rows = [dict(zip(cls.fields + extra, line.split("\t"))) for line in p.stdout.splitlines()]

    def where(self, i):
        return "packet %d (%s)" % (i + 1, self.cases[i].note)

    def test_rule_file_is_what_this_script_writes(self):
        with open(os.path.join(ARGS.source_dir, RULES), encoding="utf-8") as fh:
            self.assertEqual(fh.read(), render_rules(), "run test_widths.py --write-rules")

    def test_tshark_is_clean(self):
        self.assertEqual(self.stderr.strip(), "")
        self.assertEqual(len(self.rows), len(self.cases))

    def test_fields(self):
        bad = []
        for i, c in enumerate(self.cases):
            for f in self.fields:
                want, got = "|".join(c.fields.get(f, [])), self.rows[i].get(f, "")
                if want != got:
                    bad.append("%s: %s = %r, expected %r" % (self.where(i), f, got, want))
            unknown = set(c.fields) - set(self.fields)
            if unknown:
                bad.append("%s: fields the rules do not have: %s" % (self.where(i), sorted(unknown)))
        self.assertEqual(bad[:20], [], "%d mismatches" % len(bad))

    def test_info_column(self):
        bad = []
        for i, c in enumerate(self.cases):
            want, got = ", ".join(c.info), self.rows[i]["_ws.col.Info"]
            if want != got:
                bad.append("%s:\n  expected %r\n  got      %r" % (self.where(i), want, got))
        self.assertEqual(bad[:10], [], "%d packets differ" % len(bad))

    def test_info_column_by_the_table_walk(self):
        """The runtime's own summary builder (DISSGEN_TABLE_WALK=1: no compiled summaries)
        gives the same Info column: hex digits for a field of any bit width."""
        p = self.env.tshark(["-r", self.capture, "-T", "fields", "-e", "_ws.col.Info"],
                            extra_env={"DISSGEN_TABLE_WALK": "1"})
        got = p.stdout.splitlines()
        self.assertEqual(len(got), len(self.cases))
        bad = ["%s:\n  expected %r\n  got      %r" % (self.where(i), ", ".join(c.info), got[i])
               for i, c in enumerate(self.cases) if ", ".join(c.info) != got[i]]
        self.assertEqual(bad[:10], [], "%d packets differ" % len(bad))

    def test_expert_infos_by_message_and_filter_name(self):
        bad = []
        for i, c in enumerate(self.cases):
            want = "|".join(text for _, text in c.experts)
            got = self.rows[i]["_ws.expert.message"]
            if want != got:
                bad.append("%s: expert messages %r, expected %r" % (self.where(i), got, want))
            for name in EXPERT_NAMES:
                f = "%s.expert.%s" % (PROTO, name)
                n_want = sum(1 for k, _ in c.experts if k == name)
                got_f = self.rows[i][f]
                n_got = len(got_f.split("|")) if got_f else 0
                if n_want != n_got:
                    bad.append("%s: %d x %s, expected %d" % (self.where(i), n_got, f, n_want))
        self.assertEqual(bad[:10], [], "%d mismatches" % len(bad))

    def test_every_branch_is_taken(self):
        """Each container's optional fields are both present and absent, each repeat runs
        once and more than once, somewhere among the valid messages."""
        valid = [c for c in self.cases if c.note == "valid"]
        for w, order in COMBOS:
            s = "%s.%s." % (PROTO, seg(w, order))
            for name in ("zero", "low_half", "pattern", "flagged", "item", "data", "group_data"):
                counts = {len(c.fields.get(s + name, [])) for c in valid}
                self.assertIn(0, counts, s + name)
                self.assertTrue(max(counts) > 0, s + name)
            for name in ("chunk", "record"):
                counts = {len(c.fields.get(s + name, [])) for c in valid}
                self.assertTrue(1 in counts and max(counts) > 1, (s + name, counts))


def subprocess_lines(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return p.stdout.splitlines()


def main():
    if "--write-rules" in sys.argv:
        here = os.path.dirname(os.path.abspath(__file__))
        with open(os.path.join(here, "..", "..", "rules", "widths.xml"), "w", encoding="utf-8") as fh:
            fh.write(render_rules())
        return 0

    def arguments(parser):
        parser.add_argument("--seed", type=int, default=15)
        parser.add_argument("--messages", type=int, default=150, help="valid messages")
    return run_unittests(arguments)[1]


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Conditional and repeated bit fields decode as the bytes say (tests/rules/bit_fields.xml).

docs/manual.md, "Bit fields": a member of a bit group with an `if` keeps its bits in the
group and shows only when its condition holds (Ready); members that are never decoded
together (a chain of `otherwise` alternatives: Port, Slot, Raw; or `if`s on one field
with lists that share no value: Low, Low other) are meanings of the same bits. A bit
field of 1, 2 or 4 bits with `count` is a packed list: `count` values packed into whole
bytes, least significant bits first in a little-endian node (Coil, Offset), most
significant first otherwise (State, Flag).

This test writes random messages of three kinds (counts from 0 to past two bytes, values
random, the bits after a list's last value random too), each also cut short at random
bytes, and checks every value of every field in -T fields against its own reading of the
bytes, the Info column (a summary naming the last Coil), and the expert infos: a list the
data ends inside says `'Coil' should occur N times, but the data ends after K` and the
walk goes on, that being the one fault told (later fields missing the same bytes say
nothing more); otherwise a one-byte field or bit group with no byte left is truncated
(named by the group's first member, shown or not) and ends it. One pass and -2 alike.

    test_bit_fields.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import random
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
sys.dont_write_bytecode = True
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402
from test_everything import pcap  # noqa: E402

ARGS = None
PROTO = "bitf"
RULES = os.path.join("tests", "rules", "bit_fields.xml")
ETHERTYPE = 0x88B6
P = PROTO + ".message."
FIELDS = ["kind", "head", "port", "slot", "raw", "ready", "spare", "low", "low_other", "high", "coils", "coil", "pairs", "state", "nibbles", "offset_count", "offset", "flag", "tail"]


class Message:
    def __init__(self, note):
        self.note = note
        self.data = bytearray()
        self.fields = {}
        self.experts = []
        self.info = None


def packed(rng, count, bits):
    """Random values and the bytes that hold them, the spare bits random too."""
    per_byte = 8 // bits
    values = [rng.randrange(1 << bits) for _ in range(count)]
    data = bytearray(rng.randrange(256) for _ in range(-(-count // per_byte)))
    return values, data


def value_at(data, i, bits, little):
    per_byte = 8 // bits
    pos = (i % per_byte) * bits
    shift = pos if little else 8 - pos - bits
    return (data[i // per_byte] >> shift) & ((1 << bits) - 1)


def layout(rng):
    """The message's parts in order: (name, kind, ...) and its bytes."""
    kind = rng.choice([0, 1, 1, 2])
    coils = rng.choice([0, 1, 7, 8, 9, 15, 16, 17, rng.randrange(0, 40)])
    pairs = rng.choice([0, 1, 3, 4, 5, rng.randrange(0, 12)])
    nibbles = rng.choice([0, 1, 2, rng.randrange(0, 9)])
    b1, b2, b3 = rng.randrange(256), rng.randrange(256), rng.randrange(256)
    low_name = {0: "raw", 1: "port", 2: "slot"}[kind]
    group1 = [("head", b1 >> 4), (low_name, b1 & 15)]
    group2 = ([("ready", b2 >> 7)] if kind in (1, 2) else []) + [("spare", b2 & 0x7F)]
    group3 = [("low" if kind == 1 else "low_other", b3 & 15), ("high", b3 >> 4)]
    parts = [("kind", "byte", kind), ("group", "Head", b1, group1), ("group", "Ready", b2, group2),
             ("group", "Low", b3, group3), ("coils", "byte", coils),
             ("coil", "list", coils, 1, True, packed(rng, coils, 1)[1]),
             ("pairs", "byte", pairs), ("state", "list", pairs, 2, False, packed(rng, pairs, 2)[1]),
             ("nibbles", "byte", nibbles), ("offset_count", "computed", nibbles + kind),
             ("offset", "list", nibbles + kind, 4, True, packed(rng, nibbles + kind, 4)[1])]
    if kind == 1:
        parts.append(("flag", "list", coils, 1, False, packed(rng, coils, 1)[1]))
    parts.append(("tail", "byte", rng.randrange(256)))
    return parts


def shown(name, value, bits):
    if name in ("coil", "ready"):
        return "1" if value else "0"
    if name in ("state", "flag", "tail", "slot", "raw", "spare", "low_other"):
        return "0x%02x" % value
    if name == "offset":
        return "%d" % (value - (1 << bits) if value >= 1 << (bits - 1) else value)
    return "%d" % value


def build(parts, cut=None):
    """The message's bytes cut to `cut` bytes, and what the plugin must show for them."""
    whole = bytearray()
    for p in parts:
        whole += bytes([p[2]]) if p[0] == "group" or p[1] == "byte" else p[5] if p[1] == "list" else b""
    m = Message("whole" if cut is None else "cut to %d bytes" % cut)
    m.data = whole if cut is None else whole[:cut]
    at, left = 0, len(m.data)
    names = {"kind": "Kind", "coils": "Coils", "coil": "Coil", "pairs": "Pairs", "state": "State",
             "nibbles": "Nibbles", "offset": "Offset", "flag": "Flag", "tail": "Tail"}
    last_coil = None
    told = False   # a list the data ended in is the one fault: later shortfalls are not told again
    for p in parts:
        name, what = p[0], p[1]
        if name == "group":
            if left < 1:
                if not told:
                    m.experts.append("Truncated: '%s' needs 1 bytes, only 0 left" % what)
                break
            for member, value in p[3]:
                m.fields[member] = [shown(member, value, 4)]
            at, left = at + 1, left - 1
        elif what == "computed":
            m.fields[name] = ["%d" % p[2]]
        elif what == "byte":
            if left < 1:
                if not told:
                    m.experts.append("Truncated: '%s' needs 1 bytes, only 0 left" % names[name])
                break
            m.fields[name] = [shown(name, m.data[at], 8)]
            at, left = at + 1, left - 1
        else:
            count, bits, little, data = p[2], p[3], p[4], p[5]
            have = min(len(data), left)
            n = min(count, have * (8 // bits))
            values = [value_at(m.data[at:at + have], i, bits, little) for i in range(n)]
            if values:
                m.fields[name] = [shown(name, v, bits) for v in values]
            if name == "coil" and values:
                last_coil = values[-1]
            if n < count and not told:
                m.experts.append("'%s' should occur %d times, but the data ends after %d" % (names[name], count, n))
            told = told or n < count
            at, left = at + have, left - have
    kind, coils = m.fields.get("kind"), m.fields.get("coils")
    m.info = "%s: %s coils, last %s" % (kind[0] if kind else "-", coils[0] if coils else "-",
                                         "-" if last_coil is None else ("True" if last_coil else "False"))
    return m


def messages(seed, count):
    rng = random.Random(seed)
    out = []
    for _ in range(count):
        parts = layout(rng)
        whole = build(parts)
        out.append(whole)
        # (cut to 0 bytes, a frame carries no message: Wireshark does not call the plugin)
        for cut in sorted(rng.sample(range(1, len(whole.data)), min(4, len(whole.data) - 1))):
            out.append(build(parts, cut))
    return out


def frame(payload):
    return b"\x02\xee\xee\xee\xee\xee\x02\x00\x00\x00\x00\x01" + struct.pack("!H", ETHERTYPE) + bytes(payload)


class BitFields(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(RULES, PROTO)
        cls.messages = messages(ARGS.seed, ARGS.messages)
        cap = cls.env.add_file("packed.pcap", pcap([(frame(m.data), len(frame(m.data))) for m in cls.messages]))
        fields = ["frame.number"] + [P + f for f in FIELDS] + ["_ws.col.Info", "_ws.expert.message"]
        cls.runs = {passes: cls.env.field_rows(cap, fields, two_pass=passes == 2, aggregator="|",
                                               with_stderr=True) for passes in (1, 2)}

    def test_tshark_is_clean(self):
        for passes, (rows, stderr) in self.runs.items():
            self.assertEqual(stderr.strip(), "", "%d pass(es)" % passes)
            self.assertEqual(len(rows), len(self.messages))

    def test_values_info_and_experts(self):
        with self.checks() as check:
            for passes, (rows, _) in self.runs.items():
                bad = []
                for i, m in enumerate(self.messages):
                    row = rows[i + 1]
                    where = "frame %d (%s, %d pass(es))" % (i + 1, m.note, passes)
                    for f in FIELDS:
                        if row[P + f] != m.fields.get(f, []):
                            bad.append("%s: %s = %s, expected %s" % (where, f, row[P + f], m.fields.get(f, [])))
                    if row["_ws.col.Info"] != [m.info]:
                        bad.append("%s: Info %s, expected %r" % (where, row["_ws.col.Info"], m.info))
                    if row["_ws.expert.message"] != m.experts:
                        bad.append("%s: experts %s, expected %s" % (where, row["_ws.expert.message"], m.experts))
                check(not bad, "%d messages, %d pass(es): every value, Info and expert info as the bytes say%s"
                      % (len(self.messages), passes, "".join("\n  " + b for b in bad[:10])))

    def test_every_shape_is_there(self):
        """Each alternative of the bits, the flag there and not, empty lists, lists ending
        inside a byte and on its boundary, and each list cut short."""
        whole = [m for m in self.messages if m.note == "whole"]
        for f in ("port", "slot", "raw", "ready", "low", "low_other"):
            self.assertTrue(any(f in m.fields for m in whole) and any(f not in m.fields for m in whole), f)
        for f, per_byte in (("coil", 8), ("state", 4), ("offset", 2), ("flag", 8)):
            sizes = {len(m.fields.get(f, [])) for m in whole}
            self.assertIn(0, sizes, f)
            self.assertTrue(any(s % per_byte for s in sizes) and any(s and s % per_byte == 0 for s in sizes),
                            (f, sorted(sizes)))
            self.assertTrue(any("'%s' should occur" % f.capitalize() in e for m in self.messages
                                for e in m.experts), f)



class WordsOfBitFields(TsharkTestCase, unittest.TestCase):
    """A container of 2 to 8 bytes made of bit fields (an overlay too) is one bit group: each
    field's mask is on the whole word, as Wireshark registers a flag word's bits, and its value
    is still what the bytes say (docs/manual.md, "Bit fields")."""

    RULES = """<root name="Bit words" abbreviation="BITW" ethertype="0x%04x">
  <node name="Control" filter="control" length="4byte" byteorder="little">
    <node name="Flag" filter="flag" length="1bit" displaytype="numberdec"/>
    <node name="Tx" filter="tx" length="15bit" displaytype="numberdec"/>
    <node name="Spare" filter="spare" length="1bit" displaytype="numberdec"/>
    <node name="Rx" filter="rx" length="15bit" displaytype="numberdec"/>
  </node>
  <node name="Again" filter="again" length="4byte" byteorder="little" overlay="../node[@name='Control']">
    <node name="A" filter="a" length="2bit" displaytype="numberhex"/>
    <node name="B" filter="b" length="6bit" displaytype="numberhex"/>
    <node name="C" filter="c" length="8bit" displaytype="numberhex"/>
    <node name="D" filter="d" length="16bit" displaytype="numberhex"/>
  </node>
  <node name="Flags" filter="flags" length="2byte">
%s  </node>
</root>
""" % (ETHERTYPE + 1, "".join('    <node name="F%d" filter="f%d" length="1bit" displaytype="bool"/>\n' % (i, i)
                               for i in range(16)))
    # field: (type, mask) as tshark -G fields lists them
    MASKS = {"control.flag": ("FT_UINT32", 0x1), "control.tx": ("FT_UINT32", 0xfffe),
             "control.spare": ("FT_UINT32", 0x10000), "control.rx": ("FT_UINT32", 0xfffe0000),
             "again.a": ("FT_UINT32", 0x3), "again.b": ("FT_UINT32", 0xfc), "again.c": ("FT_UINT32", 0xff00),
             "again.d": ("FT_UINT32", 0xffff0000)}
    MASKS.update({"flags.f%d" % i: ("FT_BOOLEAN", 0x8000 >> i) for i in range(16)})

    @classmethod
    def prepare(cls):
        cls.install_text("bit_words.xml", cls.RULES, "bitw")

    def test_masks_are_on_the_word(self):
        out = self.env.tshark(["-G", "fields"]).stdout
        listed = {}
        for line in out.splitlines():
            cols = line.split("\t")
            if len(cols) >= 7 and cols[0] == "F" and cols[2].startswith("bitw."):
                listed[cols[2][len("bitw."):]] = (cols[3], int(cols[6], 16))
        with self.checks() as check:
            for name, want in self.MASKS.items():
                check(listed.get(name) == want, "bitw.%s: %s, expected %s" % (name, listed.get(name), want))

    def test_values_are_what_the_bytes_say(self):
        rng = random.Random(11)
        words = [(rng.getrandbits(32), rng.getrandbits(16)) for _ in range(40)] + [(0xffffffff, 0xffff), (0, 0)]
        path = self.env.add_file("bit_words.pcap", pcap([
            (f, len(f)) for f in (b"\x02\xee\xee\xee\xee\xee\x02\x00\x00\x00\x00\x01" +
                                  struct.pack("!H", ETHERTYPE + 1) + struct.pack("<I", c) + struct.pack(">H", fl)
                                  for c, fl in words)]))
        names = list(self.MASKS)
        with self.checks() as check:
            for label, rows in self.env.field_rows_each_pass(path, ["frame.number"] + ["bitw." + n for n in names]):
                bad = []
                for i, (c, fl) in enumerate(words, 1):
                    for n in names:
                        kind, mask = self.MASKS[n]
                        raw = (fl if n.startswith("flags.") else c) & mask
                        value = raw // (mask & -mask)
                        if kind == "FT_BOOLEAN":
                            want = ["1" if value else "0"]
                        elif n.startswith("again."):
                            want = ["0x%08x" % value]
                        else:
                            want = [str(value)]
                        if rows[i]["bitw." + n] != want:
                            bad.append("frame %d %s: %s, expected %s" % (i, n, rows[i]["bitw." + n], want))
                check(not bad, "%s: %d words, every field as the bytes say%s" % (
                    label, len(words), "".join("\n  " + b for b in bad[:8])))


def main():
    def arguments(parser):
        parser.add_argument("--seed", type=int, default=7)
        parser.add_argument("--messages", type=int, default=120, help="whole messages (each also cut short)")
    return run_unittests(arguments)[1]


if __name__ == "__main__":
    sys.exit(main())

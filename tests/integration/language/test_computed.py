#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Computed values (value="...") with real tshark: tests/rules/computed.xml.

Random messages on ethertype 0x88b6 (start, count, a signed raw value, count
16-bit registers each followed by a flag byte when odd, a tail byte when
count is odd). Every computed field is
computed again here from the bytes, with C's rules (integer division
truncates, 64-bit wrapping), and compared with what tshark shows, in one pass
and with -2: reals, booleans, hex, enums, signed values, the instance index,
a hex value as wide as its mask, c ? a : b (its unchosen value undefined), an undefined value
(division by zero: no item), a computed length, a summary; a negative computed length is reported negative.
Needs no corpus.

    test_computed.py --dissgen build/bin/dissgen --source-dir .
"""

import os
import random
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

ARGS = None
ETHERTYPE = 0x88B6
FIELDS = ["frame.number", "calc.temperature", "calc.alarm", "calc.mixed", "calc.high_byte", "calc.kind", "calc.parity", "calc.ratio",
          "calc.negated", "calc.magnitude", "calc.safe_ratio", "calc.secret", "calc.registers.register", "calc.registers.flags.flag_index", "calc.tail_bytes", "calc.tail",
          "_ws.col.Info"]


def c_div(a, b):
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b > 0) else -q


def message(rng):
    start = rng.choice([0, 1, 40000, 65535, rng.randrange(65536)])
    count = rng.choice([0, 1, 2, 3, rng.randrange(8)])
    raw = rng.choice([-32768, -1, 0, 900, 901, 32767, rng.randrange(-32768, 32768)])
    values = [rng.randrange(65536) for _ in range(count)]
    # each register: its value, then one flag byte when the value is odd
    body = struct.pack(">HBh", start, count, raw) + b"".join(
        struct.pack(">H", v) + bytes([0x0F]) * (v & 1) for v in values)
    body += bytes([0xA5]) * (count & 1)
    return (start, count, raw, values), body


def fmt_g(x):
    """A double as Wireshark shows it: %.15g."""
    return "%.15g" % x


def expected(start, count, raw, values):
    """What each field shows, as tshark -T fields prints it (None: no item)."""
    registers = ", ".join("r%d=0x%04x" % (start + i + 1, v) for i, v in enumerate(values))
    return {
        "calc.temperature": raw * 0.1 - 40,
        "calc.alarm": "1" if raw > 900 or count == 0 else "0",
        "calc.mixed": "0x%016x" % ((((start << 4) | count) & 0xFFFF) ^ 0x5A),
        "calc.high_byte": "0x%02x" % (start >> 8),  # masked to 8 bits: an 8-bit field
        "calc.kind": str(count % 3),
        "calc.parity": "0x%02x" % (count & 1),  # masked to 8 bits: an 8-bit field
        "calc.ratio": None if count == 2 else str(c_div(start, count - 2)),
        "calc.negated": str(-start + -1 + (0 if count else 1)),
        "calc.magnitude": str(abs(raw)),
        "calc.safe_ratio": "-1" if count == 2 else str(c_div(start, count - 2)),
        "calc.secret": str(start >> 2),
        "calc.registers.register": ",".join(str(start + i + 1) for i in range(count)),
        "calc.registers.flags.flag_index": ",".join("0" for v in values if v & 1),
        "calc.tail_bytes": str(count & 1),
        "calc.tail": "a5" if count & 1 else "",
        # the climate's summary, then a repeated node's summaries ("Name ×N: ..." from two on)
        "info": "%s °C, alarm %s" % (fmt_g(raw * 0.1 - 40), "True" if raw > 900 or count == 0 else "False")
                + ("" if count == 0 else ", " + registers if count == 1 else ", Registers ×%d: %s" % (count, registers)),
    }


def ethernet_frame(body):
    f = b"\x02\0\0\0\0\x02\x02\0\0\0\0\x01" + struct.pack("!H", ETHERTYPE) + body
    return f + bytes(max(0, 60 - len(f)))


def messages(seed, count):
    """[(fields, message bytes)]: random messages (test_quiet decodes them too)."""
    rng = random.Random(seed)
    return [message(rng) for _ in range(count)]


class TestComputed(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "computed.xml"), "calc")
        cls.messages = messages(1234, 300)
        frames = [ethernet_frame(body) for _, body in cls.messages]
        out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
        for i, f in enumerate(frames):
            out.append(struct.pack("<IIII", 1_700_000_000 + i, 0, len(f), len(f)) + f)
        cls.path = cls.env.add_file("computed.pcap", b"".join(out))

    def test_every_value_as_computed_from_the_bytes(self):
        with self.checks() as check:
            for two_pass in (False, True):
                mode = "-2" if two_pass else "one pass"
                rows = self.env.field_rows(self.path, FIELDS, two_pass, aggregator=",")
                wrong = {}
                for n, (fields, _) in enumerate(self.messages, 1):
                    want = expected(*fields)
                    got = {f: ",".join(v) for f, v in rows[n].items()}
                    for f, w in want.items():
                        g = got["_ws.col.Info"] if f == "info" else got[f]
                        if f == "calc.temperature":
                            ok = g != "" and abs(float(g) - w) < 1e-9
                        else:
                            ok = g == ("" if w is None else w)
                        if not ok:
                            wrong.setdefault(f, []).append((n, g, w))
                for f in list(expected(0, 0, 0, []).keys()):
                    check(f not in wrong, "%s: %s as computed from the bytes in all %d messages%s" % (
                        mode, f, len(self.messages), "" if f not in wrong else " (wrong: %s)" % wrong[f][:3]))

    def test_items_are_generated_and_nondisplay_is_hidden(self):
        out = self.env.tshark(["-r", self.path, "-V", "-c", "3"]).stdout
        with self.checks() as check:
            check("[Temperature: " in out, "a computed value is a generated item: [Temperature: ...]")
            check(re.search(r"\[Temperature: -?[0-9.]+ °C\]", out) is not None, "a float's unit label follows its value")
            check(re.search(r"Count: [0-9]+ registers\n", out) is not None, "an integer's unit label follows its value")
            check("[Register: " in out, "computed values inside a repeat are generated items too")
            check("Secret" not in out, "a nondisplay computed value is not printed")
            filtered = self.env.tshark(["-r", self.path, "-Y", "calc.secret >= 0 && calc.ratio == 0",
                                        "-T", "fields", "-e", "frame.number"]).stdout.split()
            want = [str(n) for n, (f, _) in enumerate(self.messages, 1)
                    if f[1] != 2 and c_div(f[0], f[1] - 2) == 0]
            check(filtered == want, "computed fields filter like any field (%d frames)" % len(want))

    def test_covers_shows_a_value_on_the_bytes_it_names(self):
        """Register (covers="../node[@name='Value']") sits on its register's two bytes;
        a value without covers takes none."""
        pdml = self.env.tshark(["-r", self.path, "-T", "pdml", "-c", "30"]).stdout
        places = re.findall(r'<field name="(calc\.registers\.(?:value|register)|calc\.ratio)"[^>]*? size="(\d+)" pos="(\d+)"',
                            pdml)
        pairs = [(places[i], places[i + 1]) for i in range(len(places) - 1)
                 if places[i][0] == "calc.registers.value" and places[i + 1][0] == "calc.registers.register"]
        with self.checks() as check:
            check(len(pairs) >= 20, "%d registers in the first 30 frames" % len(pairs))
            check(all(v[1:] == r[1:] == ("2", v[2]) for v, r in pairs),
                  "every [Register] has its Value's position and 2 bytes")
            check(all(size == "0" for name, size, _ in places if name == "calc.ratio"),
                  "a value without covers is zero-length")


NEGATIVE_LENGTH_RULES = """<root name="Negative length" abbreviation="NEGL" ethertype="0x88b7">
  <node name="Count" length="1byte" displaytype="numberdec"/>
  <node name="Body length" value="{Count} - 8" displaytype="numberdec"/>
  <node name="Body" length="../node[@name='Body length']" displaytype="origin"/>
</root>
"""


class TestNegativeComputedLength(TsharkTestCase, unittest.TestCase):
    """A length from a computed value below 0 is reported as negative where it is, not taken
    for 2^31 bytes (the computed value is signed, as a length written as ../X - 8 is)."""
    @classmethod
    def prepare(cls):
        cls.install_text("negative_length.xml", NEGATIVE_LENGTH_RULES, "negl")

    def test_reported_negative(self):
        macs = b"\x02\x00\x00\x00\x00\x02\x02\x00\x00\x00\x00\x01"
        frames = [macs + struct.pack(">H", 0x88B7) + bytes([count]) + b"\x01\x02\x03" + b"\x00" * 42
                  for count in (5, 10)]
        out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
        for i, f in enumerate(frames):
            out.append(struct.pack("<IIII", 1_700_000_000 + i, 0, len(f), len(f)) + f)
        path = self.env.add_file("negative.pcap", b"".join(out))
        rows = self.env.field_rows(path, ["frame.number", "negl.body_length", "negl.body", "_ws.expert.message"],
                                   aggregator="|")
        with self.checks() as check:
            check(rows[1]["negl.body_length"] == ["-3"] and not rows[1]["negl.body"] and
                  rows[1]["_ws.expert.message"] == ["The length of 'Body' is negative (-3)"],
                  "count 5: body length -3, no body, the length reported negative (%s)" % rows[1])
            ours = [m for m in rows[2]["_ws.expert.message"] if "'Body'" in m]
            check(rows[2]["negl.body_length"] == ["2"] and rows[2]["negl.body"] == ["01 02"] and not ours,
                  "count 10: a body of 2 bytes, nothing reported on it (%s)" % rows[2])


HEX_WIDTH_RULES = """<root name="Hex widths" abbreviation="HEXW" ethertype="0x88b8" byteorder="big">
  <node name="Message" summary="{Kind} {Sized} {Code}">
    <node name="Size" length="1byte" displaytype="numberdec"/>
    <node name="Sized" length="../node[@name='Size']" displaytype="numberhex"/>
    <node name="Kind" length="../node[@name='Size']" displaytype="enum">
      <enum value="85" name="present-value"/>
    </node>
    <node name="Code" value="{Sized} + 0x200" displaytype="enum">
      <enum value="0x255" name="answer"/>
    </node>
  </node>
</root>
"""


class TestVariableWidthHex(TsharkTestCase, unittest.TestCase):
    """Numbers of 64-bit fields whose values vary in width (a length from a field, a computed
    value) show in hex with the digits the value needs, in whole bytes, in the tree and the
    Info column; -T fields shows Wireshark's 64-bit field as it is."""
    @classmethod
    def prepare(cls):
        cls.install_text("hex_widths.xml", HEX_WIDTH_RULES, "hexw")

    def test_digits_the_value_needs(self):
        macs = b"\x02\x00\x00\x00\x00\x02\x02\x00\x00\x00\x00\x01"
        bodies = [b"\x01\x55\x55", b"\x02\x01\x02\x02\x00"]
        frames = [macs + struct.pack(">H", 0x88B8) + b + bytes(46 - len(b)) for b in bodies]
        out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
        for i, f in enumerate(frames):
            out.append(struct.pack("<IIII", 1_700_000_000 + i, 0, len(f), len(f)) + f)
        path = self.env.add_file("hex_widths.pcap", b"".join(out))
        want = {1: ["Sized: 0x55", "Kind: present-value (0x55)", "Code: answer (0x0255)"],
                2: ["Sized: 0x0102", "Kind: Unknown (0x0200)", "Code: Unknown (0x0302)"]}
        info = {1: "present-value 0x55 answer", 2: "Unknown (0x0200) 0x0102 Unknown (0x0302)"}
        with self.checks() as check:
            for number in (1, 2):
                for extra in ([], ["-2"]):
                    text = self.env.tshark(["-r", path, "-V", "-Y", "frame.number == %d" % number] + extra).stdout
                    lines = [line.strip().strip("[]") for line in text.splitlines()]  # a computed item is [generated]
                    check(all(w in lines for w in want[number]), "frame %d %s: %s in %s" %
                          (number, extra, want[number], [x for x in lines if x.startswith(("Sized", "Kind", "Code"))]))
            rows = self.env.field_rows(path, ["frame.number", "_ws.col.Info", "hexw.message.sized"])
            for number in (1, 2):
                check(rows[number]["_ws.col.Info"] == [info[number]], "frame %d Info: %s" % (number, rows[number]))
            check(rows[1]["hexw.message.sized"] == ["0x0000000000000055"], "-T fields: %s" % rows[1])


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

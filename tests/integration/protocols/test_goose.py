#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""A protocol dissgen was not built for, from rules alone: tests/rules/goose.xml (IEC 61850
GOOSE, ASN.1 BER) against Wireshark's goose dissector, value by value, on generated frames.

BER lengths come in three forms (one byte below 0x80, 0x81 nn, 0x82 nnnn): the rule file
chooses with c ? a : b. Each frame's goosePdu holds the eleven elements of IEC 61850-8-1
with random values, strings long enough for every length form, integers of 1-5 bytes
(positive and negative), and an allData of two elements. Checked, in one pass and -2:
every integer (timeAllowedtoLive, stNum, sqNum, confRev, numDatSetEntries) and string
(gocbRef, datSet, goID) equals what goose shows; the allData elements equal the bytes
written. Frames cut inside an element leave the elements before it decoded. Needs no corpus.

    test_goose.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import random
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import pcapgen  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

ARGS = None
INTEGER_FIELDS = ["goose.timeAllowedtoLive", "goose.stNum", "goose.sqNum", "goose.confRev",
                  "goose.numDatSetEntries"]
TEXT_FIELDS = ["goose.gocbRef", "goose.datSet", "goose.goID"]


def tlv(tag, value):
    """A BER element, its length in the shortest form."""
    n = len(value)
    if n < 0x80:
        length = bytes([n])
    elif n < 0x100:
        length = bytes([0x81, n])
    else:
        length = b"\x82" + struct.pack(">H", n)
    return bytes([tag]) + length + value


def ber_integer(v):
    """Two's complement in the fewest bytes."""
    size = 1
    while not -(1 << (8 * size - 1)) <= v < (1 << (8 * size - 1)):
        size += 1
    return v.to_bytes(size, "big", signed=True)


def goose_message(rng, i):
    """(what goose shows: integers, texts, allData integers; the frame)."""
    gocb = ("IED%d/LLN0$GO$gcb%d" % (rng.randrange(100), i % 7)) + "X" * rng.choice([0, 0, 120, 300])
    integers = [rng.choice([2000, 100, 127, 128, 65535]), rng.randrange(0, 1 << 31),
                rng.choice([0, 1, 255, 256, rng.randrange(1 << 31)]), rng.randrange(1, 300), 2]
    texts = [gocb, "IED/LLN0$DS%d" % rng.randrange(10), "goid%d" % i]
    data = [rng.choice([-5, 0, 127, -129, rng.randrange(-(1 << 39), 1 << 39)]) for _ in range(2)]
    body = b"".join([
        tlv(0x80, texts[0].encode()), tlv(0x81, ber_integer(integers[0])), tlv(0x82, texts[1].encode()),
        tlv(0x83, texts[2].encode()), tlv(0x84, struct.pack(">II", 1_700_000_000 + i, 0)),
        tlv(0x85, ber_integer(integers[1])), tlv(0x86, ber_integer(integers[2])), tlv(0x87, b"\x00"),
        tlv(0x88, ber_integer(integers[3])), tlv(0x89, bytes([rng.randrange(2)])),
        tlv(0x8A, ber_integer(integers[4])),
        tlv(0xAB, b"".join(tlv(0x85, ber_integer(v)) for v in data))])
    pdu = tlv(0x61, body)
    payload = struct.pack(">HHHH", rng.randrange(0x4000), len(pdu) + 8, 0, 0) + pdu
    frame = b"\x01\x0c\xcd\x01\x00\x01" + b"\x02\0\0\0\0\x01" + b"\x88\xb8" + payload
    return (integers, texts, data), frame + bytes(max(0, 60 - len(frame)))


def goose_frames(seed=5, count=200):
    rng = random.Random(seed)
    return [goose_message(rng, i)[1] for i in range(count)]


def field_rows(env, path, fields, args=()):
    """{frame number: {field: [values]}}; occurrences joined by '|' (no string here has one)."""
    return env.field_rows(path, ["frame.number"] + fields, aggregator="|", extra_args=args)


class TestGoose(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "goose.xml"), "gooser")
        rng = random.Random(5)
        cls.messages = [goose_message(rng, i) for i in range(200)]
        cls.path = cls.env.add_file("goose.pcap", pcapgen.raw_pcap_bytes([f for _, f in cls.messages]))

    def test_values_equal_wiresharks_goose(self):
        theirs = field_rows(self.env, self.path, INTEGER_FIELDS + TEXT_FIELDS, ["--disable-protocol", "gooser"])
        with self.checks() as check:
            for two_pass in (False, True):
                mode = "-2" if two_pass else "one pass"
                ours = field_rows(self.env, self.path, ["gooser.pdu.elem.int", "gooser.pdu.elem.text",
                                                        "gooser.pdu.elem.lenbyte", "gooser.pdu.elem.alldata.elem.int"],
                                  ["-2"] if two_pass else [])
                agree = total = 0
                wrong = []
                forms = set()
                for n, ((integers, texts, data), _) in enumerate(self.messages, 1):
                    got_ints = ours[n]["gooser.pdu.elem.int"]
                    got_texts = ours[n]["gooser.pdu.elem.text"]
                    forms.update(int(b, 16) for b in ours[n]["gooser.pdu.elem.lenbyte"])
                    want = [theirs[n][f][0] for f in INTEGER_FIELDS] + [theirs[n][f][0] for f in TEXT_FIELDS]
                    got = got_ints[:5] + got_texts
                    for g, w in zip(got, want):
                        total += 1
                        agree += g == w
                        if g != w:
                            wrong.append((n, g[:40], w[:40]))
                    # allData's integers (goose shows them without a field of their own): the bytes
                    all_data = ours[n]["gooser.pdu.elem.alldata.elem.int"]
                    if got_ints[5:] or all_data != [str(v) for v in data]:
                        wrong.append((n, "allData", all_data, data))
                check(total == len(self.messages) * 8 and agree == total and not wrong,
                      "%s: %d of %d values equal goose's%s" % (mode, agree, total, "" if not wrong else
                                                              " (first wrong: %s)" % (wrong[:3],)))
                check({0x81, 0x82} <= forms and any(f < 0x80 for f in forms),
                      "%s: the three length forms occur (%s)" % (mode, sorted(hex(f) for f in forms if f >= 0x80)))

    def test_a_frame_cut_inside_an_element_keeps_the_elements_before_it(self):
        # a message whose timeAllowedtoLive takes 2 bytes or more, cut after its first byte
        for (integers, texts, _), frame in self.messages:
            elements = ber_elements(frame)
            tag, start, end = elements[1]
            if end - start >= 2:
                break
        self.assertEqual(tag, 0x81)
        path = self.env.add_file("goose_cut.pcap", pcapgen.raw_pcap_bytes([frame[:start + 1]]))
        rows = field_rows(self.env, path, ["gooser.pdu.elem.text", "gooser.pdu.elem.tag", "gooser.pdu.elem.int",
                                           "_ws.expert"])
        with self.checks() as check:
            check(rows[1]["gooser.pdu.elem.text"] == [texts[0]], "gocbRef decoded before the cut")
            check(rows[1]["gooser.pdu.elem.tag"] == ["0x80", "0x81"], "the cut element's tag is shown, nothing after it")
            check(rows[1]["gooser.pdu.elem.int"] == [], "the cut integer is not shown as a value")
            check(rows[1]["_ws.expert"] != [], "the cut raises an expert info")


def ber_elements(frame):
    """[(tag, value start, value end)] of the goosePdu's elements, as offsets in the frame."""
    def length_at(at):
        first = frame[at]
        if first < 0x80:
            return first, at + 1
        size = first & 0x7F
        return int.from_bytes(frame[at + 1:at + 1 + size], "big"), at + 1 + size

    pdu_length, at = length_at(14 + 8 + 1)
    end, out = at + pdu_length, []
    while at < end:
        length, start = length_at(at + 1)
        out.append((frame[at], start, start + length))
        at = start + length
    return out


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

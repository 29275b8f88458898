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
written. Frames cut inside an element leave the elements before it decoded. allData's Data
values nest (arrays and structures of Data, a <group> used inside itself, depth="4"): every
value of the first four levels equals goose's, at its level and in its order; deeper levels
are one raw leaf per container, exactly their bytes. Needs no corpus.

    test_goose.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import random
import struct
import sys
import unittest
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import pcapgen  # noqa: E402
from tshark_env import TsharkTestCase, read_tshark_output, run_unittests  # noqa: E402

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


def goose_frame(pdu):
    payload = struct.pack(">HHHH", 0x3001, len(pdu) + 8, 0, 0) + pdu
    frame = b"\x01\x0c\xcd\x01\x00\x01" + b"\x02\0\0\0\0\x01" + b"\x88\xb8" + payload
    return frame + bytes(max(0, 60 - len(frame)))


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


RULE_DEPTH = 4  # tests/rules/goose.xml: <group name="Data" depth="4">
GOOSE_LEAVES = {"goose.integer": "int", "goose.unsigned": "uint", "goose.boolean": "bool",
                "goose.visible_string": "vstring"}


class NestedData:
    """A random allData: Data values (integer, unsigned, boolean, visible-string) in arrays and
    structures up to 6 levels; what each level-1..4 value is, and the containers at level 4
    that hold values (the rules show their contents as one raw leaf)."""

    def __init__(self, rng, elements=3):
        self.leaves = []   # (level, kind, shown value) in frame order
        self.deep = []     # content lengths of level-4 containers with members
        self.encoded = b"".join(self.data(rng, 1) for _ in range(elements))

    def data(self, rng, level):
        kind = rng.choice(["int", "uint", "bool", "vstring", "structure", "array"] if level < 6 else ["int", "bool"])
        if kind in ("structure", "array"):
            members = b"".join(self.data(rng, level + 1) for _ in range(rng.randrange(1, 4)))
            if level == RULE_DEPTH:
                self.deep.append(len(members))
            return tlv(0xA2 if kind == "structure" else 0xA1, members)
        value = {"int": lambda: rng.randrange(-(1 << 31), 1 << 31), "uint": lambda: rng.randrange(1 << 31),
                 "bool": lambda: rng.randrange(2), "vstring": lambda: "v%d" % rng.randrange(10 ** 6)}[kind]()
        if level <= RULE_DEPTH:
            self.leaves.append((level, kind, str(value)))
        tag, content = {"int": (0x85, lambda: ber_integer(value)), "uint": (0x86, lambda: ber_integer(value)),
                        "bool": (0x83, lambda: bytes([value])), "vstring": (0x8A, lambda: value.encode())}[kind]
        return tlv(tag, content())


def nested_goose_frame(data):
    body = b"".join([tlv(0x80, b"IED/LLN0$GO$gcb"), tlv(0x81, ber_integer(2000)), tlv(0x82, b"IED/LLN0$DS"),
                     tlv(0x83, b"id"), tlv(0x84, struct.pack(">II", 1_700_000_000, 0)), tlv(0x85, b"\x01"),
                     tlv(0x86, b"\x01"), tlv(0x87, b"\x00"), tlv(0x88, b"\x01"), tlv(0x89, b"\x00"),
                     tlv(0x8A, b"\x03"), tlv(0xAB, data.encoded)])
    return goose_frame(tlv(0x61, body))


def pdml_packets(env, path, args):
    """The PDML <packet> elements tshark writes for path."""
    out = env.path("nested.pdml")
    with open(out, "w") as fh:
        env.tshark(["-r", path, "-T", "pdml"] + list(args), stdout=fh)
    return ET.fromstring(read_tshark_output(out, xml=True)).findall("packet")


def goose_leaves(packet):
    """goose's Data values of one packet: (level, kind, value), level 1 in allData."""
    found = []

    def walk(el, level):
        for child in el:  # <proto> and <field>
            name = child.get("name")
            if name in GOOSE_LEAVES:
                found.append((level, GOOSE_LEAVES[name], child.get("show")))
            walk(child, level + (name in ("goose.structure", "goose.array")))
    walk(packet, 1)
    return found


def rule_leaves(packet):
    """Our Data values of one packet, (level, kind, value), and the sizes of the raw deeper leaves."""
    found, deeper = [], []
    for field in packet.iter("field"):
        name = field.get("name") or ""
        if not name.startswith("gooser.pdu.elem.alldata."):
            continue
        level = 1 + name.count(".structure.") + name.count(".array.")
        kind = name.rsplit(".", 1)[1]
        if kind in GOOSE_LEAVES.values():
            found.append((level, kind, field.get("show")))
        elif kind == "deeper":
            deeper.append(int(field.get("size")))
    return found, deeper


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

    def test_nested_data_values_equal_wiresharks_goose(self):
        rng = random.Random(11)
        datas = [NestedData(rng) for _ in range(150)]
        path = self.env.add_file("goose_nested.pcap", pcapgen.raw_pcap_bytes([nested_goose_frame(d) for d in datas]))
        theirs = [[v for v in goose_leaves(p) if v[0] <= RULE_DEPTH]
                  for p in pdml_packets(self.env, path, ["--disable-protocol", "gooser"])]
        with self.checks() as check:
            check(sum(len(d.deep) for d in datas) >= 10 and max(lv for d in datas for lv, _, _ in d.leaves) == 4,
                  "the capture nests values four levels deep and deeper")
            for n, (d, t) in enumerate(zip(datas, theirs), 1):
                if t != d.leaves:
                    check(False, "frame %d: goose shows %s, the bytes hold %s" % (n, t[:4], d.leaves[:4]))
                    break
            for args in ([], ["-2"]):
                ours = [rule_leaves(p) for p in pdml_packets(self.env, path, args)]
                values = sum(len(d.leaves) for d in datas)
                agree = sum(o == d.leaves for (o, _), d in zip(ours, datas))
                check(len(ours) == len(datas) and agree == len(datas),
                      "%s: %d of %d frames' %d Data values (level, kind, value) equal goose's%s" % (
                          " ".join(args) or "one pass", agree, len(datas), values,
                          next(("; frame %d: %s vs %s" % (n, o[:4], d.leaves[:4])
                                for n, ((o, _), d) in enumerate(zip(ours, datas), 1) if o != d.leaves), "")))
                deep = [deeper for _, deeper in ours]
                check(deep == [d.deep for d in datas],
                      "%s: one raw leaf per level-4 container with members, its contents' bytes" % (
                          " ".join(args) or "one pass"))

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

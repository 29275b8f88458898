#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Process data laid out by a mapping learned from earlier frames, with real tshark:
tests/rules/learned_layout.xml on ethertype 0x88c2 (and tests/rules/entry_list.xml: a counted
list whose entries take no bytes, as a layout over bytes decoded before it is).

Map messages write one subindex of a node's mapping (subindex 0: the number of
entries; k: the k-th entry's object, size in bytes and sign), as POWERLINK's and
EtherCAT's masters write PDO mappings. A Data message of a node is a list of entries
laid out by what the node's mapping was when it was sent: each entry's object, its
value as a number of its learned size (1-8 bytes, signed or not), looked up by the
entry's own instance number; a node whose mapping was never seen is a warning
(mpd.finding.not_mapped) and its bytes stay raw. Expected values come from a model of
the frames in order (the truth of the bytes); the same in one pass, with -2, and with
-2 and a display filter keeping every third frame. An entry of a size outside 1-8 is a
malformed packet there. Needs no corpus.

    test_learned_layout.py --dissgen build/bin/dissgen --source-dir .
"""

import os
import random
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from pcapgen import raw_pcap_bytes  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

ETHERTYPE = 0x88C2
FIELDS = ["frame.number", "mpd.kind", "mpd.data.entry_count", "mpd.data.entry.object", "mpd.data.entry.value",
          "mpd.data.entry.signed_value", "mpd.data.unmapped", "mpd.finding.not_mapped", "mpd.expert.bad_length"]


def frame(payload):
    f = b"\x02\0\0\0\0\xff\x02\0\0\0\0\x01" + struct.pack("!H", ETHERTYPE) + payload
    return f + bytes(max(0, 60 - len(f)))


def map_count(node, count):
    return struct.pack("<BBBB", 1, node, 0, count)


def map_entry(node, sub, obj, obj_sub, size, signed):
    return struct.pack("<BBBHBBB", 1, node, sub, obj, obj_sub, size, signed)


def encode(value, size, signed):
    return (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little")


class Model:
    """The mappings as the Map messages so far set them, and what a Data message shows."""

    def __init__(self):
        self.count, self.entries = {}, {}

    def teach(self, message):
        _, node, sub, *rest = message
        if sub == 0:
            self.count[node] = rest[0]
        else:
            self.entries[(node, sub)] = tuple(rest)

    def layout(self, node):
        """[(object, size, signed)] of the node's entries, or None when its mapping was not seen."""
        if node not in self.count:
            return None
        return [self.entries.get((node, k + 1)) for k in range(self.count[node])]


def data_message(rng, node, layout):
    """(payload, want): random values for the layout; want as -T fields shows them."""
    payload = struct.pack("<BB", 2, node)
    if layout is None:
        raw = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 6)))
        return payload + raw, {"count": "", "objects": [], "values": [], "signed": [], "unmapped": None,
                               "not_mapped": True, "bad_length": False}
    want = {"count": str(len(layout)), "objects": [], "values": [], "signed": [], "unmapped": "",
            "not_mapped": False, "bad_length": False}
    for entry in layout:
        obj, obj_sub, size, signed = entry
        want["objects"].append("0x%016x" % (obj << 8 | obj_sub))
        if not 1 <= size <= 8:
            want["bad_length"] = True
            break
        value = rng.randrange(1 << (8 * size))
        payload += encode(value, size, signed)
        if signed:
            want["signed"].append(str(value - (1 << (8 * size)) if value >> (8 * size - 1) else value))
        else:
            want["values"].append("0x%016x" % value)
    return payload, want


def messages(rng, count, nodes=(1, 2, 3)):
    """[(payload, want or None)]: Map messages write random mappings, some in several steps
    (entries, then the count), Data messages follow what is mapped at their time."""
    model, out = Model(), []
    for _ in range(count):
        node = rng.choice(nodes)
        if rng.random() < 0.25:
            if rng.random() < 0.3:
                message = (1, node, 0, rng.randrange(0, 5))
            else:
                size = rng.choice([1, 2, 3, 4, 5, 6, 7, 8, 2, 4])
                message = (1, node, rng.randrange(1, 5), rng.randrange(0x1000, 0x10000), rng.randrange(256), size,
                           rng.randrange(2))
            out.append((map_count(node, message[3]) if message[2] == 0 else map_entry(*message[1:]), None))
            model.teach(message)
            continue
        layout = model.layout(node)
        if layout is not None and any(e is None for e in layout):
            continue  # an entry never written: the message cannot be laid out (tested on its own)
        out.append(data_message(rng, node, layout))
    return out


class TestLearnedLayout(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "learned_layout.xml"), "mpd")

    def decoded(self, path, two_pass, display_filter=None):
        rows = self.env.field_rows(path, FIELDS, two_pass, display_filter=display_filter, aggregator=",")
        out = {}
        for n, r in rows.items():
            if r["mpd.kind"] != ["0x02"]:
                continue
            out[n] = {"count": ",".join(r["mpd.data.entry_count"]), "objects": r["mpd.data.entry.object"],
                      "values": r["mpd.data.entry.value"], "signed": r["mpd.data.entry.signed_value"],
                      "unmapped": ",".join(r["mpd.data.unmapped"]), "not_mapped": bool(r["mpd.finding.not_mapped"]),
                      "bad_length": bool(r["mpd.expert.bad_length"])}
        return out

    def check_capture(self, name, items):
        path = self.env.add_file(name, raw_pcap_bytes([frame(p) for p, _ in items]))
        want = {n: w for n, (_, w) in enumerate(items, 1) if w is not None}
        for n, w in want.items():
            if w["not_mapped"]:  # raw to the end of the frame, Ethernet's padding included
                w["unmapped"] = frame(items[n - 1][0])[16:].hex(" ")
        with self.checks() as check:
            self.check_every_pass(check, lambda two_pass, shown: self.decoded(path, two_pass, shown), want,
                                  "each Data frame laid out by the mapping of its time")
        return want

    def test_each_rule_once(self):
        rng = random.Random(7)
        items = [data_message(rng, 1, None),                               # 1: nothing mapped: raw, warning
                 (map_entry(1, 1, 0x6000, 1, 2, 0), None),                 # 2: entry 1: 16 bits unsigned
                 (map_entry(1, 2, 0x6001, 0, 1, 1), None),                 # 3: entry 2: 8 bits signed
                 data_message(rng, 1, None),                               # 4: no count yet: still not mapped
                 (map_count(1, 2), None)]                                  # 5: two entries
        items.append((struct.pack("<BBHb", 2, 1, 0xBEEF, -3),
                      {"count": "2", "objects": ["0x0000000000600001", "0x0000000000600100"],
                       "values": ["0x000000000000beef"], "signed": ["-3"], "unmapped": "", "not_mapped": False,
                       "bad_length": False}))                              # 6: laid out
        items += [(map_entry(1, 1, 0x7000, 2, 8, 1), None),                # 7: entry 1 now 64 bits signed
                  (struct.pack("<BBqb", 2, 1, -2, 5),
                   {"count": "2", "objects": ["0x0000000000700002", "0x0000000000600100"], "values": [],
                    "signed": ["-2", "5"], "unmapped": "", "not_mapped": False, "bad_length": False}),  # 8
                  data_message(rng, 2, None),                              # 9: node 2: its own mapping, none
                  (map_entry(1, 2, 0x6001, 0, 9, 0), None),                # 10: entry 2 of 9 bytes
                  (struct.pack("<BBq", 2, 1, 7) + bytes(9),
                   {"count": "2", "objects": ["0x0000000000700002", "0x0000000000600100"], "values": [],
                    "signed": ["7"], "unmapped": "", "not_mapped": False, "bad_length": True})]  # 11: malformed
        self.check_capture("layout_rules.pcap", items)

    def test_random_mappings_against_a_model(self):
        items = messages(random.Random(2024), 600)
        want = self.check_capture("layout_random.pcap", items)
        laid_out = sum(1 for w in want.values() if w["count"] not in ("", "0"))
        self.assertGreater(laid_out, 100, "enough Data frames laid out by a learned mapping")
        self.assertGreater(sum(1 for w in want.values() if w["not_mapped"]), 5)


class TestEntryList(TsharkTestCase, unittest.TestCase):
    """tests/rules/entry_list.xml: a counted list whose entries take no bytes (computed values
    and an overlay) repeats exactly `Count` times where the message's bytes end, without a
    count_short; a count above 65535 is bad_length there, and the frames after it decode."""

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "entry_list.xml"), "elist")

    def test_counts(self):
        rng = random.Random(3)
        counts = [3, 0, 20, 70000, 1, 65535]
        tables = [bytes(rng.randrange(256) for _ in range(8)) for _ in counts]
        frames = [b"\x02\0\0\0\0\xff\x02\0\0\0\0\x01" + struct.pack("!H", 0x88C3) + struct.pack("<I", c) + t
                  for c, t in zip(counts, tables)]  # 26 bytes: the message ends with its table
        path = self.env.add_file("entry_list.pcap", raw_pcap_bytes(frames))
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number", "elist.entry.number", "elist.entry.byte",
                                                  "elist.expert.bad_length", "elist.expert.count_short"], two_pass)
                for n, (count, table) in enumerate(zip(counts, tables), 1):
                    row = rows[n]
                    shown = min(count, 65535) if count <= 65535 else 0
                    want_bytes = ["0x%02x" % table[i % 8] for i in range(shown)]
                    check(row["elist.entry.number"] == [str(i + 1) for i in range(shown)] and
                          row["elist.entry.byte"] == want_bytes,
                          "frame %d (%s): %d entries, each its byte of the table" % (
                              n, "-2" if two_pass else "one pass", shown))
                    check(bool(row["elist.expert.bad_length"]) == (count > 65535) and
                          not row["elist.expert.count_short"],
                          "frame %d: bad_length only for a count above 65535, never count_short" % n)


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

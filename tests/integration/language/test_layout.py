#!/usr/bin/env python3
"""Alternatives, multi-field conditions, look-ahead and register maps
with real tshark: tests/rules/layout.xml.

Records of a made-up UDP protocol (kind, mode, address, length, data, counter,
more) are written at random; a small model of the rules says what each one must
show, and the PDML of tshark is compared with it item by item: filter name,
position, size, the bytes under the item and the value shown (numbers read
from the bytes written), and the label of every block instance ("Channel 2",
"Word 5"). The data of a record is
  - a register window (kind 1-2, mode 0, address below 0x1000; <when> on two
    fields) whose children sit at absolute addresses, some overlapping, a
    block of 4 channels at a stride of 8, shown only when wholly inside,
  - else a word window (kind 4, base = address * 2, otherwise + if),
  - else a page window (kind 6, base = address - 16, a child with its own if),
  - else a window whose base is the Echo byte (kind 7),
  - else, for kind 9, a field whose length comes from the Echo byte,
  - else, for kind 8, the data as one item when the record has its Echo byte
    (a <when field> on a field only some records have: without it, raw bytes),
  - else a mailbox when the counter AFTER the data is 1 (peek counted from the
    start of the data container, whose length is known),
  - else raw bytes (otherwise);
and an Echo byte precedes the data when that counter is 2 (peek from the node
itself, past the data). Malformed variants (windows past the end of the
capture, counters cut off so a peek cannot read them or ending exactly at the
end of the capture so it can, a mailbox too short for
its header, a base below zero, a base or a length from a field the record lacks) must give
our expert infos where the fault is and the tree so far.

    test_layout.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import random
import struct
import sys
import unittest
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from pcapgen import udp_ethernet_frame  # noqa: E402
from test_everything import pcap  # noqa: E402
from tshark_env import TsharkEnv, run_unittests  # noqa: E402

ARGS = None
PORT = 47475
RULES = os.path.join("tests", "rules", "layout.xml")
UDP_HEAD = 14 + 20 + 8
EXPERTS = ("lyt.expert.truncated", "lyt.expert.past_end", "lyt.expert.more_no_data",
           "lyt.expert.count_short", "lyt.expert.bad_length", "lyt.expert.unused")

# Register window children in document order: (filter, address, size, stride, instances, label)
REGISTERS = [
    ("lyt.rec.reg.status", 0x0010, 2, 0, 1, "Status"),
    ("lyt.rec.reg.ctl", 0x0012, 1, 0, 1, "Control"),
    ("lyt.rec.reg.id", 0x0000, 4, 0, 1, "Identity"),
    ("lyt.rec.reg.status_low", 0x0010, 1, 0, 1, "Status low"),
    ("lyt.rec.reg.ch", 0x0100, 8, 8, 4, "Channel {i}"),
    ("lyt.rec.reg.scratch", 0x0F80, 16, 0, 1, "Scratch"),
]
WORDS = ("lyt.rec.words.word", 0x0020, 2, 2, 8, "Word")
PAGES = [
    ("lyt.rec.pages.header", 0x0000, 2, 0, 1, "Page header"),
    ("lyt.rec.pages.word", 0x0010, 4, 4, 4, "Page {i} word"),
    ("lyt.rec.pages.wflag", 0x0002, 1, 0, 1, "Write flag"),      # only in mode 1
]
ECHOED = [("lyt.rec.echoed.reg", 0x00E5, 1, 0, 1, "Echo register")]


def udp_frame(payload):
    return udp_ethernet_frame(payload, PORT)


class Item:
    """One expected tree item: filter name, offset in the UDP payload, size, shown value."""

    def __init__(self, name, pos, size, show=None, label=None):
        self.name, self.pos, self.size, self.show, self.label = name, pos, size, show, label

    def key(self):
        return (self.name, self.pos, self.size) + ((self.show,) if self.show is not None else ())

    def __repr__(self):
        return "Item%r" % (self.key() + ((self.label,) if self.label else ()),)


class Record:
    def __init__(self, kind, mode, address, data, counter, more, length=None):
        self.kind, self.mode, self.address, self.data = kind, mode, address, data
        self.counter, self.more = counter, more
        self.length = len(data) if length is None else length

    def echo(self):
        """The Echo byte, written only when the counter after the data is 2."""
        return b"\xe5" if self.counter == 2 else b""

    def size(self):
        return 6 + len(self.echo()) + self.length + 3

    def encode(self):
        return (struct.pack("<BBHH", self.kind, self.mode, self.address, self.length) + self.echo() + self.data +
                struct.pack("<HB", self.counter, self.more))


def le(data):
    return int.from_bytes(data, "little")


def window_items(prefix_items, base, start, avail, places):
    """Children wholly inside [base, base + avail), in document order."""
    out = []
    for name, at, size, stride, instances, label in places:
        for i in range(instances):
            a = at + stride * i
            if a < base or a + size > base + avail:
                continue
            pos = start + a - base
            if "{i}" in label:
                text = label.replace("{i}", str(i))
            elif stride:
                text = "%s %d" % (label, i)
            else:
                text = None
            out.append((name, pos, size, i, text))
    return out


class Expected:
    """What the rules show for a packet: items in tree order and expert infos."""

    def __init__(self, records, cut=None):
        self.items, self.experts = [], []
        payload = b"".join(r.encode() for r in records)
        self.payload = payload if cut is None else payload[:cut]
        end = len(self.payload)
        off = 0
        for r in records:
            if not self.record(r, off, end):
                break
            off += r.size()

    def add(self, name, pos, size, show=None, label=None):
        self.items.append(Item(name, pos, size, show, label))

    def expert(self, name, pos, size):
        """An expert info at the fault: over the bytes left of what was cut short, none for a bad base."""
        self.experts.append((name, pos, size))

    def num(self, name, pos, size):
        self.add(name, pos, size, le(self.payload[pos:pos + size]))

    def record(self, r, o, end):
        """Adds one record's items; False when decoding stops inside it."""
        self.add("lyt.rec", o, None)
        for name, p, s in (("kind", 0, 1), ("mode", 1, 1), ("address", 2, 2), ("length", 4, 2)):
            if o + p + s > end:
                self.expert("lyt.expert.truncated", o + p, end - (o + p))
                return False
            self.num("lyt.rec." + name, o + p, s)
        d = o + 6
        # Echo: present when the counter, 1 + Length bytes on, is 2 (and there)
        at = d + 1 + r.length
        echo = at + 2 <= end and le(self.payload[at:at + 2]) == 2
        if echo:
            self.num("lyt.rec.echo", d, 1)
            d += 1
        # Data: its children end where Length says; the mailbox peeks at the counter after it
        counter_there = d + r.length + 2 <= end
        counter = le(self.payload[d + r.length:d + r.length + 2]) if counter_there else None
        avail = min(r.length, end - d)
        past = r.length > end - d
        if past:
            self.expert("lyt.expert.past_end", d, end - d)
        if r.kind in (1, 2) and r.address <= 0x0FFF and r.mode == 0:
            self.add("lyt.rec.reg", d, avail)
            for name, pos, size, i, text in window_items(self, r.address, d, avail, REGISTERS):
                self.register(name, pos, size, text)
        elif r.kind == 4:
            self.add("lyt.rec.words", d, avail)
            for name, pos, size, i, text in window_items(self, r.address * 2, d, avail, [WORDS]):
                self.add(name, pos, size, le(self.payload[pos:pos + size]), text)
        elif r.kind == 6:
            self.add("lyt.rec.pages", d, avail if r.address >= 16 else 0)   # stops at the window's start
            if r.address < 16:
                self.expert("lyt.expert.bad_length", d, 0)     # base out of range
                return False
            for name, pos, size, i, text in window_items(self, r.address - 16, d, avail, PAGES):
                if name != "lyt.rec.pages.wflag" or r.mode == 1:
                    self.add(name, pos, size, le(self.payload[pos:pos + size]), text)
        elif r.kind == 7:
            self.add("lyt.rec.echoed", d, avail if echo else 0)
            if not echo:
                self.expert("lyt.expert.bad_length", d, 0)     # base field not in this packet
                return False
            for name, pos, size, i, text in window_items(self, 0xE5, d, avail, ECHOED):
                self.add(name, pos, size, le(self.payload[pos:pos + size]), text)
        elif r.kind == 9:
            if not echo:
                self.expert("lyt.expert.bad_length", d, 0)     # length field not in this packet
                return False
            assert r.length == 0xE5 - 224, "a kind 9 record carries as many data bytes as Echo - 224 says"
            self.add("lyt.rec.echosized", d, r.length)
        elif r.kind == 8 and echo:
            if avail > 0:
                self.add("lyt.rec.echodata", d, avail)
        elif r.kind in (1, 2, 3) and counter == 1:
            self.add("lyt.rec.mbx", d, avail if avail >= 3 else None)
            inner = d + avail
            if inner - d < 2:
                self.expert("lyt.expert.truncated", d, inner - d)
                return False
            self.num("lyt.rec.mbx.len", d, 2)
            if inner - d < 3:
                self.expert("lyt.expert.truncated", d + 2, inner - d - 2)
                return False
            self.num("lyt.rec.mbx.type", d + 2, 1)
            if inner - d > 3:
                self.add("lyt.rec.mbx.data", d + 3, inner - d - 3)
        else:
            if avail > 0:
                self.add("lyt.rec.raw", d, avail)
        if past:
            return False
        c = d + r.length
        for name, p, s in (("counter", 0, 2), ("more", 2, 1)):
            if c + p + s > end:
                self.expert("lyt.expert.truncated", c + p, end - (c + p))
                return False
            self.num("lyt.rec." + name, c + p, s)
        return r.more != 0

    def register(self, name, pos, size, text):
        if name == "lyt.rec.reg.ctl":
            b = self.payload[pos]
            self.add(name, pos, 1, None, text)
            self.add("lyt.rec.reg.ctl.run", pos, 1, b & 1)
            self.add("lyt.rec.reg.ctl.level", pos, 1, (b >> 1) & 7)
        elif name == "lyt.rec.reg.ch":
            self.add(name, pos, size, None, text)
            self.num("lyt.rec.reg.ch.start", pos, 4)
            self.num("lyt.rec.reg.ch.size", pos + 4, 2)
            self.num("lyt.rec.reg.ch.flags", pos + 6, 2)
        elif name == "lyt.rec.reg.scratch":
            self.add(name, pos, size)
        else:
            self.add(name, pos, size, le(self.payload[pos:pos + size]), text)


def random_record(rng, more):
    kind = rng.choice([1, 1, 2, 3, 4, 5, 6, 7, 8])
    mode = rng.choice([0, 0, 0, 1])
    address = rng.choice([0, 0x0010, 0x0011, 0x0012, 0x00FC, 0x0100, 0x0104, 0x0110, 0x0118, 0x0F78,
                          0x0F80, 0x0FF0, 0x1000, 0x8000, rng.randrange(0x1000), rng.randrange(0x10000)])
    n = rng.choice([0, 1, 2, 3, 4, 8, 16, 20, 0x20, 0x40, rng.randrange(0x120)])
    data = bytes(rng.randrange(256) for _ in range(n))
    counter = rng.choice([0, 1, 1, 2])
    if n < 3 and counter == 1:
        counter = 2     # a mailbox needs its 3-byte header (malformed_packets has the short one)
    if kind == 6 and address < 16:
        address += 16   # below 16 the base is out of range (malformed_packets)
    if kind == 7:
        counter = 2     # the Echoed window's base is the Echo byte, there only then
    return Record(kind, mode, address, data, counter, more)


def valid_packets(rng, count):
    out = []
    for _ in range(count):
        n = rng.choice([1, 1, 2, 3])
        out.append(([random_record(rng, int(i + 1 < n)) for i in range(n)], None))
    # A read of 0x0000..0x0FFF shows every register it covers.
    # A length from the Echo byte (0xE5 - 224 = 5 bytes), which only some records have.
    out.append(([Record(9, 0, 0x0010, bytes(range(5)), 2, 0)], None))
    whole = Record(1, 0, 0x0000, bytes(rng.randrange(256) for _ in range(0x1000)), 0, 0)
    out.append(([whole], None))
    # Every branch once: registers, words, mailbox (peek 1), raw (peek 2, kind 5), pages, echoed,
    # echo data (kind 8 with its Echo byte) and raw bytes for kind 8 without it.
    for kind, counter in ((2, 0), (4, 1), (3, 1), (3, 2), (5, 1), (6, 0), (7, 2), (8, 2), (8, 0)):
        out.append(([Record(kind, 0, 0x0010, bytes(range(24)), counter, 0)], None))
    return out


def malformed_packets():
    data = bytes(range(0x40))
    return [
        # register window whose length runs past the capture: the registers there are shown
        ([Record(1, 0, 0x000C, data, 0, 0)], 6 + 0x14),
        # word window past the capture
        ([Record(4, 0, 0x0008, data, 0, 0)], 6 + 9),
        # the counter a mailbox peeks at is cut off: not a mailbox, raw bytes, then truncated
        ([Record(3, 0, 0x2000, data[:8], 1, 0)], 6 + 8 + 1),
        # the counter Echo peeks at is cut off: no Echo, its byte is taken as data
        ([Record(5, 0, 0x2000, data[:8], 2, 0)], 6 + 1 + 8 + 1),
        # ... and ends exactly at the end of the capture: Echo is there (More is cut off)
        ([Record(5, 0, 0x2000, data[:8], 2, 0)], 6 + 1 + 8 + 2),
        # the counter a mailbox peeks at ends exactly at the end of the capture: a mailbox
        ([Record(3, 0, 0x2000, data[:8], 1, 0)], 6 + 8 + 2),
        # a window base below zero (address - 16)
        ([Record(6, 1, 0x0008, data[:8], 0, 0)], None),
        # a window base from a field this record does not have
        ([Record(7, 0, 0x0000, data[:8], 0, 0)], None),
        # a length from a field this record does not have
        ([Record(9, 0, 0x0000, data[:5], 0, 0)], None),
        # a mailbox too short for its header
        ([Record(2, 0, 0x2000, data[:1], 1, 0)], None),
        # a length past the end of the packet: the peek finds no counter, raw bytes and past_end
        ([Record(3, 0, 0x2000, data[:8], 1, 0, length=0x30)], None),
        # the record header itself is cut
        ([Record(1, 0, 0x0010, data[:4], 0, 0)], 3),
    ]


def pdml_items(proto):
    """(name, pos, size, show, label) of every visible field under our protocol, in tree order."""
    out = []

    def visit(el):
        for f in el.findall("field"):
            if f.get("name") in ("_ws.expert", ""):   # expert infos sit in a text item
                visit(f)
            if f.get("hide") == "yes" or not f.get("name", "").startswith("lyt"):
                continue
            out.append(f)
            visit(f)
    visit(proto)
    return out


class Layout(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.env = TsharkEnv()
        try:
            cls.env.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, RULES))
            rng = random.Random(ARGS.seed)
            cls.cases = valid_packets(rng, ARGS.packets)
            cls.valid_count = len(cls.cases)
            cls.cases += malformed_packets()
            packets = []
            for records, cut in cls.cases:
                payload = b"".join(r.encode() for r in records)
                # a cut message is that short on the wire (its UDP datagram ends there): a
                # capture's cut of a whole one is no fault of the message (test_snapshot_length)
                frame = udp_frame(payload if cut is None else payload[:cut])
                packets.append((frame, len(frame)))
            cls.expected = [Expected(records, cut) for records, cut in cls.cases]
            cap = cls.env.add_file("layout.pcap", pcap(packets))
            p = cls.env.tshark(["-r", cap, "-T", "pdml"], check=False)
            cls.stderr = p.stderr
            cls.packets = ET.fromstring(p.stdout).findall("packet")
            two = cls.env.tshark(["-r", cap, "-2", "-T", "pdml"], check=False)
            cls.two_pass = two.stdout
            cls.one_pass = p.stdout
        except BaseException:
            cls.env.cleanup()
            raise

    @classmethod
    def tearDownClass(cls):
        cls.env.cleanup()

    def proto(self, i):
        for p in self.packets[i].findall("proto"):
            if p.get("name") == "lyt":
                return p
        self.fail("packet %d: no lyt protocol" % (i + 1))

    def test_tshark_is_clean(self):
        self.assertEqual(self.stderr.strip(), "")
        self.assertEqual(len(self.packets), len(self.cases))
        self.assertEqual(self.one_pass[self.one_pass.index("<packet>"):],
                         self.two_pass[self.two_pass.index("<packet>"):])
        for i in range(len(self.cases)):
            # our malformed expert infos add a hidden _ws.malformed; an exception a visible one
            for p in self.packets[i].iter("proto"):
                if p.get("name") == "_ws.malformed":
                    self.assertEqual(p.get("hide"), "yes", "packet %d: a Wireshark exception escaped" % (i + 1))

    def test_items_match_the_bytes(self):
        for i, exp in enumerate(self.expected):
            with self.subTest(packet=i + 1):
                got = []
                for f in pdml_items(self.proto(i)):
                    name = f.get("name")
                    if name.startswith("lyt.expert"):
                        continue
                    pos, size = int(f.get("pos")) - UDP_HEAD, int(f.get("size"))
                    value = f.get("unmaskedvalue", f.get("value"))   # bit fields: value is masked
                    self.assertEqual(value or "", exp.payload[pos:pos + size].hex() if value else "",
                                     "%s at %d: the item's bytes are not the bytes written" % (name, pos))
                    show = f.get("show")
                    shown = None
                    if show is not None and show.startswith("0x"):
                        shown = int(show, 16)
                    elif show is not None and show.isdigit():
                        shown = int(show)
                    got.append((name, pos, size, shown, f.get("showname")))
                want = exp.items
                self.assertEqual([g[0] for g in got], [w.name for w in want])
                for g, w in zip(got, want):
                    self.assertEqual(g[1], w.pos, w)
                    if w.size is not None:
                        self.assertEqual(g[2], w.size, w)
                    if w.show is not None:
                        self.assertEqual(g[3], w.show, (w, g))
                    if w.label is not None:
                        self.assertTrue(g[4].startswith(w.label + ":") or g[4] == w.label, (w, g[4]))

    def test_experts_where_the_fault_is(self):
        for i, exp in enumerate(self.expected):
            with self.subTest(packet=i + 1):
                got = [(f.get("name"), int(item.get("pos")) - UDP_HEAD, int(item.get("size")))
                       for item in self.proto(i).iter("field") if item.find("field[@name='_ws.expert']") is not None
                       for f in item.iter("field") if f.get("name") in EXPERTS]
                self.assertEqual(got, exp.experts, "(name, position, size) of each expert info")
        for i in range(self.valid_count):
            self.assertEqual(self.expected[i].experts, [], "valid packet %d has a fault in the model" % (i + 1))

    def test_whole_register_space_shows_every_register(self):
        exp = self.expected[self.valid_count - 10]
        names = [it.name for it in exp.items]
        for name in ("lyt.rec.reg.status", "lyt.rec.reg.ctl", "lyt.rec.reg.id", "lyt.rec.reg.status_low",
                     "lyt.rec.reg.scratch"):
            self.assertEqual(names.count(name), 1, name)
        self.assertEqual(names.count("lyt.rec.reg.ch"), 4)
        labels = [f.get("showname") for f in pdml_items(self.proto(self.valid_count - 10))
                  if f.get("name") == "lyt.rec.reg.ch"]
        self.assertEqual([s.split(":")[0] for s in labels], ["Channel 0", "Channel 1", "Channel 2", "Channel 3"])

    def test_every_branch_is_taken(self):
        seen = set()
        for exp in self.expected[:self.valid_count]:
            seen.update(it.name for it in exp.items)
        for name in ("lyt.rec.reg", "lyt.rec.words", "lyt.rec.mbx", "lyt.rec.raw", "lyt.rec.reg.ch",
                     "lyt.rec.words.word", "lyt.rec.echo", "lyt.rec.pages.word", "lyt.rec.pages.wflag",
                     "lyt.rec.echoed.reg", "lyt.rec.echodata", "lyt.rec.echosized"):
            self.assertIn(name, seen)


if __name__ == "__main__":
    def more_args(p):
        p.add_argument("--seed", type=int, default=10)
        p.add_argument("--packets", type=int, default=300)
    sys.exit(run_unittests(more_args)[1])

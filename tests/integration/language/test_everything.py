#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Every construct of the rule language at once: tests/rules/everything.xml.

A protocol-specific encoder (Python 3 stdlib only) builds randomised but valid
messages for the made-up "Everything" protocol, and for each one what the
generated plugin must show: every field's -T fields value in tree order, the
-V tree line by line (bit masks in both byte orders, hex widths, enum names
and "Unknown (0x..)", True/False, addresses, bytes, hidden fields left out,
summaries on nested containers) and the Info column; a small model of the
decoding rules of docs/manual.md (class Expected) walks what the encoder wrote over
the bytes actually captured. The messages travel on
the ethertype and on the UDP hook. Malformed messages (truncated, lengths past
the end, negative lengths, short counts, repeat flags with nothing after
them, containers not filled) must give our expert infos and what was decoded
so far, and never a Wireshark exception; a message whole on the wire that the
capture kept only in part (pcap caplen below its length) is not malformed:
Wireshark's "[Packet size limited during capture]" item where its data runs out.

    test_everything.py --dissgen build/bin/dissgen --source-dir .  [--keep-pcap DIR]
"""
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import unittest
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkEnv, TsharkTestCase, run_unittests  # noqa: E402

ARGS = None
PROTO = "evry"
PROTO_NAME = "Everything Protocol"
ETHERTYPE = 0x88B5
UDP_PORT = 47474
RULES = os.path.join("tests", "rules", "everything.xml")
ELLIPSIS = "\u2026"
KNOWN_END = -1  # Decoder.cut_end of a box the capture kept whole (DG_END_KNOWN)
TIMES = "\u00d7"

# --------------------------------------------------------------------------- enums (as in the rules)

KIND = {1: "Data", 2: "Control", 3: "Data (compressed)", 0x1F: "Escape 转义"}
BE_NIBBLE = {0: "Zero", 0xF: "Fifteen"}
STATION = {1: "First", 0x0100000000: "Bit 32", 0xFFFFFFFFFF: "All stations"}
LNK_NIBBLE = {1: "One", 0xE: "Fourteen"}
WIDE_KIND = {0: "None", 0x41: "Sixty-five", 127: "Max"}
NODE_ID = {0xFFFFFFFFFFFFFFFF: "Broadcast", 0x0123456789ABCDEF: "Master", 1: "One"}
STATE = {0: "Init", 8: "Operational"}
OPTION_KIND = {0: "End", 7: "Timestamp"}
COMMAND = {1: "Start", 2: "Stop"}
SECTION_TYPE = {0: "Config", 1: "Measurement", 2: "Log"}
ITEM_TYPE = {0: "Integer", 4: "Hardware address", 0x0B: "Blob", 0xFF: "Reserved"}

CONTROL_KINDS = {2, 4, 5, 6}                                      # in="2,4-6"
DATA_KINDS = {0, 1, 3} | set(range(7, 0x1F))                      # in="0-1,0x03,7-0x1e"
NUMBER_ITEMS = {0, 1, 2, 3, 0x0A}                                 # in="0-3,0x0a"
MAC_ITEMS = set(range(4, 10))                                     # in="4-9"
BLOB_ITEMS = set(range(0x0B, 0x100))                              # in="0x0b-0xff"


# --------------------------------------------------------------------------- how Wireshark shows values

def hex_digits(bits):
    return (bits + 3) // 4


def show_hex(value, bits):
    """numberhex in the tree (and in summaries): as many digits as the field's bits need."""
    return "0x%0*x" % (hex_digits(bits), value)


def enum_name(value, names, bits):
    """An enum's shown value in a summary: its name, or Unknown (0x..) as the tree shows it."""
    return names[value] if value in names else "Unknown (%s)" % show_hex(value, bits)


def enum_label(value, names, bits):
    """An enum in the tree: NAME (0x..)."""
    return "%s (%s)" % (names.get(value, "Unknown"), show_hex(value, bits))


def show_bool(value):
    return "True" if value else "False"


def punct(data, sep, limit=24):
    """Bytes as Wireshark labels them: at most 24 bytes, then the separator and an ellipsis."""
    text = sep.join("%02x" % b for b in data[:limit])
    return text + (sep + ELLIPSIS if len(data) > limit else "")


def bit_pattern(value, mask, width):
    """Wireshark's bit picture of a masked field: '..01 1...' over the whole container."""
    out = []
    for i in range(width):
        bit = 1 << (width - 1 - i)
        out.append(("1" if value & bit else "0") if mask & bit else ".")
        if (i + 1) % 4 == 0 and i + 1 < width:
            out.append(" ")
    return "".join(out)


def tfield_uint(value, display, ft_bytes):
    """-T fields text of an unsigned integer field (FT_UINT<8*ft_bytes>): hex is as wide
    as the field type (FT_UINT40..64 use 16 digits), decimal plain, bool 1/0. Enums are
    BASE_HEX, but Wireshark 4.0 prints 5-8 byte ones (BASE_HEX|BASE_VAL64_STRING) in decimal."""
    if display == "enum" and ft_bytes > 4:
        return "%d" % value
    if display in ("hex", "enum"):
        width = {1: 2, 2: 4, 3: 6, 4: 8}.get(ft_bytes, 16)
        return "0x%0*x" % (width, value)
    if display == "bool":
        return "1" if value else "0"
    return "%d" % value


# --------------------------------------------------------------------------- what the encoder wrote

# filter name -> (Wireshark type, bit mask), as the encoder writes the fields
REGISTERED = {}


def register(field, ftype, mask=0):
    if field:
        assert REGISTERED.setdefault(field, (ftype, mask)) == (ftype, mask), field


class Node:
    """One node instance as the encoder wrote it.

    kind: "box" (container), "num" (whole-byte number), "bit" (member of a bit
    group), "blob" (bytes), "run" (the instances of a count/repeat node, in
    `children`; not a tree item itself)."""

    def __init__(self, kind, name, field, start):
        self.kind, self.name, self.field, self.start, self.end = kind, name, field, start, start
        self.children = []
        self.lenkind = "fixed"  # box: sum/fixed/field; blob: fixed/field/rest
        self.length = None      # declared length (box, blob); may disagree with the bytes
        self.pieces = None      # box summary: [literal text or a leaf Node]
        self.label = None       # num/bit: the -V line (None: hidden)
        self.fval = None        # num/bit: the -T fields text
        self.sval = None        # num/bit: the value as a summary shows it
        self.display = None     # blob: address/origin/hidden
        self.group = None       # bit: (bytes, first member?, last member?)
        self.mode = None        # run: count/repeat
        self.wanted = None      # run (count): the count field's value
        self.flag_name = None   # run (repeat): the flag's name
        self.summarised = False  # run: its instances have a summary
        self.flag = None        # instance of a repeat run: the flag's value


def tree_value(display, value, bits, names):
    if display == "hex":
        return show_hex(value, bits)
    if display == "dec":
        return "%d" % value
    if display == "bool":
        return show_bool(value)
    return enum_label(value, names, bits)


def summary_value(display, value, bits, names):
    if display == "enum":
        return enum_name(value, names, bits)
    if display == "hidden":
        return "%d" % value
    return tree_value(display, value, bits, names)


class Message:
    """The bytes of one message, and the tree of nodes that wrote them."""

    def __init__(self):
        self.data = bytearray()
        self.top = Node("box", PROTO_NAME, PROTO, 0)
        self.stack = [self.top]
        self.runs = {}          # name -> the last run of that name

    def _add(self, node):
        self.stack[-1].children.append(node)
        return node

    def open(self, name, field, lenkind="sum", length=None):
        """A container: field None for filter="" (a plain subtree, not a field)."""
        n = self._add(Node("box", name, field, len(self.data)))
        n.lenkind, n.length = lenkind, length
        register(field, "FT_NONE")
        self.stack.append(n)
        return n

    def close(self, n, pieces=None):
        assert self.stack.pop() is n
        n.end = len(self.data)
        n.pieces = pieces
        if n.lenkind != "sum" and n.length is None:
            n.length = n.end - n.start
        return n

    def run(self, name, mode, wanted=None, summarised=False, flag_name=None):
        n = self._add(Node("run", name, None, len(self.data)))
        self.runs[name] = n
        n.mode, n.wanted, n.summarised, n.flag_name = mode, wanted, summarised, flag_name
        self.stack.append(n)
        return n

    def end_run(self, n):
        assert self.stack.pop() is n
        if n.mode == "count" and n.wanted is None:
            n.wanted = len(n.children)
        n.end = len(self.data)

    def number(self, name, field, nbytes, value, display, order="big", names=None):
        """A whole-byte numeric leaf (numberhex, numberdec, bool, enum, nondisplay)."""
        n = self._add(Node("num", name, field, len(self.data)))
        register(field, "FT_BOOLEAN" if display == "bool" else "FT_UINT%d" % (8 * nbytes))
        self.data += value.to_bytes(nbytes, order)
        n.end = len(self.data)
        bits = nbytes * 8
        n.fval = tfield_uint(value, display, nbytes)
        n.sval = summary_value(display, value, bits, names)
        if display != "hidden":
            n.label = "%s: %s" % (name, tree_value(display, value, bits, names))
        return n

    def group(self, order, members):
        """A bit group: members are (name, field, bits, value, display, names). With
        big-endian the first member takes the most significant bits, with little the least."""
        total = sum(m[2] for m in members)
        assert total % 8 == 0 and 8 <= total <= 64
        nbytes = total // 8
        word, used, placed = 0, 0, []
        for name, field, bits, value, display, names in members:
            assert 0 <= value < (1 << bits), (name, value)
            shift = used if order == "little" else total - used - bits
            word |= value << shift
            used += bits
            placed.append((name, field, bits, value, display, names, shift))
        start = len(self.data)
        self.data += word.to_bytes(nbytes, order)
        nodes = []
        for k, (name, field, bits, value, display, names, shift) in enumerate(placed):
            n = self._add(Node("bit", name, field, start))
            register(field, "FT_BOOLEAN" if display == "bool" else "FT_UINT%d" % total, ((1 << bits) - 1) << shift)
            n.end = len(self.data)
            n.group = (nbytes, k == 0, k == len(placed) - 1)
            n.fval = tfield_uint(value, display, nbytes)
            n.sval = summary_value(display, value, bits, names)
            if display != "hidden":
                n.label = "%s = %s: %s" % (bit_pattern(word, ((1 << bits) - 1) << shift, total), name,
                                           tree_value(display, value, bits, names))
            nodes.append(n)
        return nodes

    def blob(self, name, field, data, display, lenkind="fixed", length=None):
        """A byte leaf shown as address (aa:bb), origin (aa bb) or not at all (nondisplay).
        `length` is the length the rules compute, when it is not len(data) (malformed)."""
        n = self._add(Node("blob", name, field, len(self.data)))
        register(field, "FT_BYTES")
        self.data += data
        n.end = len(self.data)
        n.display, n.lenkind = display, lenkind
        n.length = len(data) if length is None else length
        return n


# --------------------------------------------------------------------------- what the plugin must show

class Item:
    """One expected tree item: its -V label (None when hidden), its filter name and
    -T fields text (None for a plain subtree), its children."""

    def __init__(self, label, field=None, fval=None):
        self.label = label
        self.field = field
        self.fval = fval
        self.children = []

    def walk(self):
        yield self
        for c in self.children:
            yield from c.walk()


EXPERTS = {  # expert field -> (severity, group) as -V shows them
    "truncated": ("Error", "Malformed"), "past_end": ("Error", "Malformed"),
    "more_no_data": ("Warning", "Malformed"), "count_short": ("Error", "Malformed"),
    "bad_length": ("Error", "Malformed"), "unused": ("Warning", "Protocol"),
}
# Registered by every protocol, raised by constructs everything.xml does not use
# (offsets= tables: tests/unit/test_offsets.cpp, test_enip.py).
OTHER_EXPERTS = ("bad_offset",)


class Expected:
    """Walks the written nodes the way docs/manual.md says a packet is decoded, over the
    bytes actually captured (`cut`), and collects what tshark must show: the tree,
    the expert messages and the Info column."""

    def __init__(self, msg, cut=None, on_wire=None):
        self.buf = bytes(msg.data if cut is None else msg.data[:cut])
        self.on_wire = on_wire  # the message's length on the wire, when the capture kept less
        self.cut_shown = False
        self.stopped = False
        # where the innermost box ends on the wire when the capture cut it short; KNOWN_END in
        # one the capture kept whole; 0 at the top level (a rest blob runs to it)
        self.cut_end = 0
        # where a box whose length was reported past the end of its data says it ends (0: none),
        # and where its data ran out: data missing there, needed no further, is that fault
        self.told_end, self.told_short_at = 0, 0
        self.experts = []       # (field, message) in order
        self.info = []
        self.svals = {}         # id(leaf node) -> value as a summary shows it
        self.root = Item(PROTO_NAME)
        self.end = self.node_list(msg.top.children, self.root, 0, len(self.buf), False)

    # -- results -------------------------------------------------------------
    def fields(self):
        """{filter name: [-T fields texts in tree order]}"""
        out = {}
        for item in self.root.walk():
            if item.field and item.fval is not None:
                out.setdefault(item.field, []).append(item.fval)
        return out

    def verbose(self):
        """The -V lines of the protocol's tree (4 spaces a level; hidden items left out)."""
        lines = []

        def visit(item, depth):
            if item.label is None:
                return
            lines.append("    " * depth + item.label)
            for c in item.children:
                visit(c, depth + 1)

        visit(self.root, 0)
        return lines

    def info_text(self):
        return ", ".join(self.info) if self.info else PROTO_NAME

    # -- decoding --------------------------------------------------------------
    def cut_by_capture(self, data_end, needed):
        """Data that ran out at data_end where a node needed it up to `needed` only because the
        capture kept less of the frame than was on the wire (a snapshot length)."""
        return (data_end is not None and self.on_wire is not None and data_end >= len(self.buf) and
                len(self.buf) < self.on_wire and needed <= self.on_wire)

    def expert(self, parent, kind, text, stop=True, data_end=None, needed=None):
        """An expert info of ours; data_end, needed: where the data ran out and how far the
        node needed it, for a shortfall: in a frame the capture kept only in part (a snapshot
        length), one that the frame on the wire covers is Wireshark's "[Packet size limited
        during capture]" item (once), no expert info (docs/manual.md, "Malformed packets")."""
        if self.cut_by_capture(data_end, needed):
            if not self.cut_shown:
                parent.children.append(Item("[Packet size limited during capture: %s truncated]" % PROTO.upper(),
                                            "_ws.short"))
                self.cut_shown = True
            self.stopped = True
            return
        if data_end is not None and data_end >= self.told_short_at and needed <= self.told_end:  # told
            self.stopped = True
            return
        severity, group = EXPERTS[kind]
        item = Item(text, "%s.expert.%s" % (PROTO, kind))
        info = Item("[Expert Info (%s/%s): %s]" % (severity, group, text))
        info.children = [Item("[%s]" % text), Item("[Severity level: %s]" % severity),
                         Item("[Group: %s]" % group)]
        item.children.append(info)
        parent.children.append(item)
        self.experts.append((kind, text))
        if stop:
            self.stopped = True

    def node_list(self, nodes, parent, offset, end, in_summary):
        for n in nodes:
            if self.stopped:
                break
            if n.kind == "run":
                offset = self.run(n, parent, offset, end, in_summary)
            else:
                offset = self.instance(n, parent, offset, end, in_summary, None)
        return offset

    def instance(self, n, parent, offset, end, in_summary, sink):
        # Decoding goes on at the end of the data after a short count or a repeat flag
        # with nothing after it; everywhere else it is where the encoder wrote the node.
        assert offset == n.start or offset >= end, (n.name, offset, n.start)
        if n.kind == "box":
            return self.box(n, parent, offset, end, in_summary, sink)
        if n.kind == "bit":
            nbytes, first, last = n.group
            if first and nbytes > end - offset:
                self.expert(parent, "truncated", "Truncated: '%s' needs %d bytes, only %d left"
                            % (n.name, nbytes, end - offset), data_end=end, needed=offset + nbytes)
                return offset
            parent.children.append(Item(n.label, n.field, n.fval))
            self.svals[id(n)] = n.sval
            return offset + nbytes if last else offset
        if n.kind == "num":
            length = n.end - n.start
            if length > end - offset:
                self.expert(parent, "truncated", "Truncated: '%s' needs %d bytes, only %d left"
                            % (n.name, length, end - offset), data_end=end, needed=offset + length)
                return offset
            parent.children.append(Item(n.label, n.field, n.fval))
            self.svals[id(n)] = n.sval
            return offset + length
        # blob
        if n.lenkind == "field" and n.length < 0:
            self.expert(parent, "bad_length", "The length of '%s' is negative (%d)" % (n.name, n.length))
            return offset
        rest_end = self.cut_end if end == len(self.buf) and self.cut_end > end else end
        length = rest_end - offset if n.lenkind == "rest" else n.length
        left = end - offset
        if length > left:
            # the bytes there, in a message really that short; none of a leaf the capture cut
            if left > 0 and not self.cut_by_capture(end, offset + length):
                parent.children.append(self.blob_item(n, self.buf[offset:end]))
            if n.lenkind == "field":
                self.expert(parent, "past_end", "'%s' has length %d, past the end of its data (%d bytes left)"
                            % (n.name, length, left), data_end=end, needed=offset + length)
            else:
                self.expert(parent, "truncated", "Truncated: '%s' needs %d bytes, only %d left"
                            % (n.name, length, left), data_end=end, needed=offset + length)
            return offset
        data = self.buf[offset:offset + length]
        if data:
            parent.children.append(self.blob_item(n, data))
        self.svals[id(n)] = punct(data, ":" if n.display == "address" else " ")
        return offset + length

    @staticmethod
    def blob_item(n, data):
        if n.display == "hidden":
            return Item(None, n.field, data.hex())
        sep = ":" if n.display == "address" else " "
        return Item("%s: %s" % (n.name, punct(data, sep)), n.field, punct(data, sep, 1 << 30))

    def box(self, n, parent, offset, end, in_summary, sink):
        start, length = offset, -1
        if n.lenkind != "sum":
            length = n.length
            if length < 0:
                self.expert(parent, "bad_length", "The length of '%s' is negative (%d)" % (n.name, length))
                return offset
        past_end = length > end - start
        inner_end = start + length if length >= 0 and not past_end else end
        item = Item(n.name, n.field, "1" if n.field else None)
        parent.children.append(item)
        cut = past_end and self.cut_by_capture(end, start + length)  # said after what the kept bytes hold
        if past_end and n.lenkind == "field" and not cut:  # the length field is the fault
            self.expert(item, "past_end",
                        "'%s' has length %d, past the end of its data (%d bytes left)" % (n.name, length, end - start),
                        data_end=end, needed=start + length)
        outer_told = self.told_end, self.told_short_at
        if past_end and n.lenkind == "field" and start + length > self.told_end:
            self.told_end, self.told_short_at = start + length, end
        was_stopped, self.stopped = self.stopped, False
        outer_cut_end = self.cut_end
        if length >= 0:
            self.cut_end = start + length if cut else KNOWN_END
        offset = self.node_list(n.children, item, offset, inner_end, in_summary or bool(n.pieces))
        self.cut_end = outer_cut_end
        if self.told_end != float("inf") or self.told_short_at < end:  # a list told short at the shared end stays
            self.told_end, self.told_short_at = outer_told
        if past_end and (cut or n.lenkind != "field") and not self.stopped:  # no child ran out: the box is short
            self.expert(item, "truncated", "Truncated: '%s' needs %d bytes, only %d left" % (n.name, length, end - start),
                        data_end=end, needed=start + length)
        self.stopped = self.stopped or was_stopped
        if not self.stopped and length >= 0 and offset < inner_end:
            gap = self.buf[offset:inner_end]
            if any(gap):
                self.expert(item, "unused", "'%s' is %d bytes, but its fields end after %d: %d bytes are not decoded"
                            % (n.name, length, offset - start, inner_end - offset), stop=False)
            else:   # zeros up to the length: padding, no expert info
                label = gap[:36].hex() + (ELLIPSIS if len(gap) > 36 else "")   # bytes without separators
                item.children.append(Item("Padding: " + label, PROTO + ".padding", gap.hex()))
        if not self.stopped and length >= 0:
            offset = inner_end
        if n.pieces:
            text = "".join(p if isinstance(p, str) else self.svals.get(id(p), "-") for p in n.pieces)
            item.label += ": " + text
            if not in_summary:
                (self.info if sink is None else sink).append(text)
        return offset

    def list_told_short(self, end):
        """A list told short where its data ends: later fields that need bytes past that end
        miss the same ones (told, not again); empty ones still decode."""
        if not self.told_end or end < self.told_short_at:
            self.told_short_at = end
        self.told_end = float("inf")
        self.stopped = False

    def run(self, r, parent, offset, end, in_summary):
        sink = [] if r.summarised and not in_summary else None
        done = 0
        while r.mode == "repeat" or done < r.wanted:
            if r.mode == "count" and offset >= end:
                self.expert(parent, "count_short", "'%s' should occur %d times, but the data ends after %d"
                            % (r.name, r.wanted, done), data_end=end, needed=end + 1)
                self.list_told_short(end)
                break
            inst = r.children[done]
            before = offset
            offset = self.instance(inst, parent, offset, end, in_summary, sink)
            done += 1
            if self.stopped or offset == before:
                break
            if r.mode == "repeat":
                if not inst.flag:
                    break
                if offset >= end:
                    self.expert(parent, "more_no_data", "'%s': the repeat flag '%s' says another follows, "
                                "but no data is left" % (r.name, r.flag_name), data_end=end, needed=end + 1)
                    self.list_told_short(end)
                    break
        if sink and len(sink) > 1:
            self.info.append("%s %s%d: %s" % (r.name, TIMES, len(sink), ", ".join(sink)))
        elif sink:
            self.info.append(sink[0])
        return offset


# --------------------------------------------------------------------------- random valid messages

class Gen:
    def __init__(self, seed):
        self.rng = random.Random(seed)

    def val(self, bits):
        """Random value of `bits` bits, often an edge value."""
        r = self.rng.random()
        if r < 0.1:
            return 0
        if r < 0.2:
            return (1 << bits) - 1
        if r < 0.3:
            return 1 << self.rng.randrange(bits)
        return self.rng.getrandbits(bits)

    def pick(self, names, bits):
        """An enum value: a named one or any other."""
        if self.rng.random() < 0.6:
            return self.rng.choice(sorted(names))
        return self.val(bits)

    def bytes(self, n):
        return bytes(self.rng.getrandbits(8) for _ in range(n))


def build_message(g, kind=None, nsec=None, nrec=None, bad=None, env_padding=0):
    """One random message for tests/rules/everything.xml: valid unless `bad` (a dict)
    sets a field to a wrong value: total, tail_size, words, nsec_field, blob_length
    (the values written), env_size / env_extra (a short / a long Envelope, its extra
    bytes not all zero), last_record_more, last_item_more (a repeat flag set on the last
    instance). env_padding: the Envelope holds that many zero bytes after its fields."""
    rng = g.rng
    bad = bad or {}
    m = Message()
    # ---- Header: big-endian 3+5 and 13+3 bit groups; the lengths and counts used later
    version, seq, prio = g.val(3), g.val(13), g.val(3)
    if kind is None:
        kind = rng.choice([0, 1, 2, 3, 4, 5, 6, 7, 0x10, 0x1E, 0x1F, g.val(5)])
    words = rng.randrange(0, 6)
    nsec = rng.choice([0, 1, 1, 2, 3]) if nsec is None else nsec
    opt_body = g.bytes(rng.choice([0, 1, 3, 23, 24, 25, 40]))
    total = bad.get("total", 24 + 1 + len(opt_body))
    pad = rng.randrange(0, 5)
    tail_rest = g.bytes(rng.randrange(0, 7))
    tail_size = bad.get("tail_size", 24 + 3 + len(tail_rest))
    h = m.open("Header", "evry.header")
    hv, hk = m.group("big", [("Version", "evry.header.version", 3, version, "dec", None),
                             ("Kind", "evry.header.kind", 5, kind, "enum", KIND)])
    hs, hp = m.group("big", [("Sequence", "evry.header.sequence", 13, seq, "dec", None),
                             ("Priority", "evry.header.priority", 3, prio, "hex", None)])
    m.number("Words", "evry.header.words", 1, bad.get("words", words), "dec")
    m.number("Section count", "evry.header.nsec", 1, bad.get("nsec_field", nsec), "dec")
    m.number("Total length", "evry.header.total_length", 2, total, "dec")
    m.number("Pad length", "evry.header.pad_length", 1, pad, "dec")
    m.number("Tail size", "evry.header.tail_size", 1, tail_size, "dec")
    m.hidden_tag = g.val(16)
    m.number("Hidden tag", "evry.header.hidden_tag", 2, m.hidden_tag, "hidden")
    m.close(h, ["v", hv, " ", hk, " #", hs, " p", hp])

    # ---- Bits BE (10 bytes): 3-byte (7+13+4), 5-byte (13+7+20), 2-byte (4+8+4) groups
    b = m.open("Bits BE", "evry.be", "fixed", 10)
    m.group("big", [("Odd seven", "evry.be.odd_seven", 7, g.val(7), "hex", None),
                    ("Thirteen", "evry.be.thirteen", 13, g.val(13), "dec", None),
                    ("Nibble", "evry.be.nibble", 4, g.pick(BE_NIBBLE, 4), "enum", BE_NIBBLE)])
    m.group("big", [("Wide A", "evry.be.wide_a", 13, g.val(13), "dec", None),
                    ("Wide flag", "evry.be.wide_flag", 7, g.val(7), "bool", None),
                    ("Wide C", "evry.be.wide_c", 20, g.val(20), "hex", None)])
    m.group("big", [("Nib A", "evry.be.nib_a", 4, g.val(4), "dec", None),
                    ("Mid byte", "evry.be.mid_byte", 8, g.val(8), "hex", None),
                    ("Nib B", "evry.be.nib_b", 4, g.val(4), "dec", None)])
    m.close(b)

    # ---- Clock: 8-byte big-endian group (1+9+54), summarised
    c = m.open("Clock", "evry.clock")
    cv, ce, ct = m.group("big", [("Valid", "evry.clock.valid", 1, g.val(1), "bool", None),
                                 ("Epoch", "evry.clock.epoch", 9, g.val(9), "dec", None),
                                 ("Ticks", "evry.clock.ticks", 54, g.val(54), "hex", None)])
    m.close(c, [ce, ":", ct, " ", cv])

    # ---- Station: a 40-bit enum
    m.number("Station", "evry.station", 5, g.pick(STATION, 40), "enum", "big", STATION)

    # ---- Link: little-endian, with a big-endian island holding a little-endian one
    lk = m.open("Link", "evry.lnk")
    m.group("little", [("Link length", "evry.lnk.len", 11, g.val(11), "dec", None),
                       ("Reserved", "evry.lnk.reserved", 3, g.val(3), "hidden", None),
                       ("Circulating", "evry.lnk.circulating", 1, g.val(1), "bool", None),
                       ("More", "evry.lnk.more", 1, g.val(1), "bool", None)])
    m.group("little", [("Odd seven", "evry.lnk.odd_seven", 7, g.val(7), "hex", None),
                       ("Thirteen", "evry.lnk.thirteen", 13, g.val(13), "dec", None),
                       ("Nibble", "evry.lnk.nibble", 4, g.pick(LNK_NIBBLE, 4), "enum", LNK_NIBBLE)])
    m.group("little", [("Wide A", "evry.lnk.wide_a", 13, g.val(13), "dec", None),
                       ("Wide kind", "evry.lnk.wide_kind", 7, g.pick(WIDE_KIND, 7), "enum", WIDE_KIND),
                       ("Wide C", "evry.lnk.wide_c", 20, g.val(20), "hex", None)])
    m.group("little", [("Tri", "evry.lnk.tri", 3, g.val(3), "dec", None),
                       ("Sept", "evry.lnk.sept", 7, g.val(7), "bool", None),
                       ("Treize", "evry.lnk.treize", 13, g.val(13), "hex", None),
                       ("Big rest", "evry.lnk.big_rest", 41, g.val(41), "hex", None)])
    m.number("Port", "evry.lnk.port", 2, g.val(16), "hex", "little")
    m.number("Counter", "evry.lnk.counter", 4, g.val(32), "dec", "little")
    m.blob("MAC", "evry.lnk.mac", g.bytes(6), "address")
    m.number("Serial", "evry.lnk.serial", 6, g.val(48), "hex", "little")
    m.number("Big seven", "evry.lnk.big_seven", 7, g.val(56), "dec", "little")
    m.number("Node ID", "evry.lnk.node_id", 8, g.pick(NODE_ID, 64), "enum", "little", NODE_ID)
    m.number("Flag word", "evry.lnk.flag_word", 2, g.val(16), "bool", "little")
    st = m.open("Status", "evry.lnk.status")
    ss, sr, sc = m.group("big", [("State", "evry.lnk.status.state", 4, g.pick(STATE, 4), "enum", STATE),
                                 ("Ready", "evry.lnk.status.ready", 1, g.val(1), "bool", None),
                                 ("Code", "evry.lnk.status.code", 11, g.val(11), "hex", None)])
    m.number("Uptime", "evry.lnk.status.uptime", 3, g.val(24), "dec", "big")
    inner = m.open("Inner", "evry.lnk.status.inner")
    m.number("Le24", "evry.lnk.status.inner.le24", 3, g.val(24), "hex", "little")
    m.close(inner)
    m.close(st, [ss, " ", sc, " ", sr])
    m.number("After island", "evry.lnk.after_island", 2, g.val(16), "hex", "little")
    m.close(lk)

    # ---- Word data (Words * 2); Options (Total length - 24) with rest inside
    m.blob("Word data", "evry.word_data", g.bytes(words * 2), "origin", "field", bad.get("words", words) * 2)
    o = m.open("Options", "evry.options", "field", total - 24)
    ok = m.number("Option kind", "evry.options.option_kind", 1, g.pick(OPTION_KIND, 8), "enum", names=OPTION_KIND)
    ob = m.blob("Option body", "evry.options.option_body", opt_body, "origin", "rest")
    m.close(o, [ok, ": ", ob])

    # ---- if/in alternatives on Kind
    if kind in CONTROL_KINDS:
        cb = m.open("Control block", "evry.ctl")
        m.number("Command", "evry.ctl.command", 1, g.pick(COMMAND, 8), "enum", names=COMMAND)
        m.number("Argument", "evry.ctl.argument", 2, g.val(16), "dec")
        m.close(cb)
    if kind in DATA_KINDS:
        db = m.open("Data block", None)
        rd = m.open("Reading", None)
        rt = m.number("Temperature", "evry.temperature", 2, g.val(16), "dec")
        rh = m.number("Humidity", "evry.humidity", 1, g.val(8), "dec")
        ra = m.number("Alarm", "evry.alarm", 1, g.val(8), "bool")
        m.close(rd, [rt, " C ", rh, "% ", ra])
        m.blob("Raw", "evry.raw", g.bytes(4), "origin")
        m.close(db)

    # ---- Section: count, with a count and an arithmetic count (Pair count * 2) inside
    r = m.run("Section", "count", bad.get("nsec_field", nsec), summarised=True)
    for _ in range(nsec):
        sec = m.open("Section", "evry.section")
        nent, npair = rng.randrange(0, 4), rng.randrange(0, 3)
        stype = m.number("Section type", "evry.section.type", 1, g.pick(SECTION_TYPE, 8), "enum",
                         names=SECTION_TYPE)
        sn = m.number("Entry count", "evry.section.nent", 1, nent, "dec")
        m.number("Pair count", "evry.section.pair_count", 1, npair, "dec")
        er = m.run("Entry", "count", summarised=True)
        for _ in range(nent):
            e = m.open("Entry", "evry.section.entry")
            key = m.number("Key", "evry.section.entry.key", 1, g.val(8), "hex")
            value = m.number("Value", "evry.section.entry.value", 2, g.val(16), "dec")
            m.close(e, [key, "=", value])
        m.end_run(er)
        hr = m.run("Half", "count")
        for _ in range(npair * 2):
            m.number("Half", "evry.section.half", 1, g.val(8), "hex")
        m.end_run(hr)
        m.close(sec, [stype, " n=", sn])
    m.end_run(r)

    # ---- Record: repeat, with a repeat inside and if/in alternatives in that
    nrec = rng.randint(1, 4) if nrec is None else nrec
    r = m.run("Record", "repeat", summarised=True, flag_name="More records")
    for i in range(nrec):
        rec = m.open("Record", "evry.record")
        fl = m.open("Record flags", "evry.record.record_flags", "fixed", 1)
        rec.flag = int(i < nrec - 1 or "last_record_more" in bad)
        _, rkind = m.group("big", [("More records", "evry.record.record_flags.more", 1, rec.flag, "bool", None),
                                   ("Record kind", "evry.record.record_flags.kind", 7, g.val(7), "dec", None)])
        m.close(fl)
        rid = m.number("Record id", "evry.record.id", 2, g.val(16), "hex")
        ir = m.run("Item", "repeat", summarised=True, flag_name="Item more")
        nitem = rng.randint(1, 3)
        for k in range(nitem):
            it = m.open("Item", "evry.record.item")
            it.flag = rng.randint(1, 255) if k < nitem - 1 or ("last_item_more" in bad and i == nrec - 1) else 0
            itype = rng.choice([g.pick(ITEM_TYPE, 8), rng.choice(sorted(NUMBER_ITEMS)),
                                rng.choice(sorted(MAC_ITEMS)), g.val(8)])
            t = m.number("Item type", "evry.record.item.type", 1, itype, "enum", names=ITEM_TYPE)
            m.number("Item more", "evry.record.item.more", 1, it.flag, "hidden")
            number = mac = blob = None
            if itype in NUMBER_ITEMS:
                iv = m.open("Item value", None)
                number = m.number("Number", "evry.record.item.number", 4, g.val(32), "hex")
                m.close(iv)
            if itype in MAC_ITEMS:
                mac = m.blob("Item MAC", "evry.record.item.mac", g.bytes(6), "address")
            if itype in BLOB_ITEMS:
                ib = m.open("Item blob", "evry.record.item.item_blob")
                data = g.bytes(rng.choice([0, 1, 7, 20, 21, 30]) + 4)
                blen = bad.pop("blob_length", len(data) - 4)
                m.number("Blob length", "evry.record.item.item_blob.blob_length", 1, blen, "dec")
                blob = m.blob("Blob", "evry.record.item.item_blob.blob", data, "origin", "field", blen + 4)
                m.close(ib)
            m.close(it, [t, ": ", number or "-", " ", mac or "-", " ", blob or "-"])
        m.end_run(ir)
        m.blob("Record pad", "evry.record.pad", g.bytes(pad + 4), "hidden", "field")
        m.close(rec, [rid, " ", rkind])
    m.end_run(r)

    # ---- Name byte: a leaf repeated until it is zero
    r = m.run("Name byte", "repeat", flag_name="Name byte")
    for v in [rng.randint(1, 255) for _ in range(rng.randrange(0, 4))] + [0]:
        m.number("Name byte", "evry.namebyte", 1, v, "hex").flag = v
    m.end_run(r)

    # ---- Tail (Tail size - 24) and Trailer block (8 bytes), both with rest inside
    t = m.open("Tail", "evry.tail", "field", tail_size - 24)
    m.number("Tail id", "evry.tail.tail_id", 1, g.val(8), "dec")
    m.number("校验和", "evry.tail.f96", 2, g.val(16), "hex")
    m.blob("Tail rest", "evry.tail.tail_rest", tail_rest, "origin", "rest")
    m.close(t)
    tb = m.open("Trailer block", "evry.trailer_block", "fixed", 8)
    m.number("Magic", "evry.trailer_block.magic", 2, g.val(16), "hex")
    m.blob("Trailer tail", "evry.trailer_block.trailer_tail", g.bytes(6), "origin", "rest")
    m.close(tb)
    m.blob("2nd address", "evry.f2nd_address", g.bytes(3), "address")
    # ---- Envelope: length from a field, fixed fields inside (bytes beyond them are skipped)
    extra = bad.get("env_extra", env_padding)
    size = bad.get("env_size", 3 + extra)
    m.number("Envelope size", "evry.envelope_size", 1, size, "dec")
    e = m.open("Envelope", "evry.envelope", "field", size)
    ea = m.number("Env a", "evry.envelope.env_a", 2, g.val(16), "hex")
    eb = m.number("Env b", "evry.envelope.env_b", 1, g.val(8), "dec")
    m.data += bytes(b or 0x5a for b in g.bytes(extra)) if "env_extra" in bad else bytes(extra)
    m.close(e, [ea, "/", eb])
    m.blob("Wide words", "evry.wide_words", g.bytes(words * 2), "origin", "field")
    m.blob("Pad copy", "evry.pad_copy", g.bytes(pad + 4), "origin", "field")
    m.blob("Tail copy", "evry.tail_copy", g.bytes(len(tail_rest) + 3), "origin", "field", tail_size - 24)
    # ---- rest at top level: to the end of the packet
    m.blob("Trailer", "evry.trailer", g.bytes(rng.choice([0, 0, 1, 5, 30])), "origin", "rest")
    return m


# --------------------------------------------------------------------------- capture

def eth_frame(payload, udp=False, src=b"\x02\x00\x00\x00\x00\x01"):
    dst = b"\x02\xee\xee\xee\xee\xee"
    if not udp:
        return dst + src + struct.pack("!H", ETHERTYPE) + payload
    u = struct.pack("!HHHH", UDP_PORT, UDP_PORT, 8 + len(payload), 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0,
                     bytes([10, 0, 0, 1]), bytes([10, 0, 0, 2]))
    s = sum(struct.unpack("!10H", ip))
    while s >> 16:
        s = (s & 0xFFFF) + (s >> 16)
    ip = ip[:10] + struct.pack("!H", ~s & 0xFFFF) + ip[12:]
    return dst + src + struct.pack("!H", 0x0800) + ip + u


def pcap(packets):
    """packets: [(captured bytes, original length)]; linktype Ethernet."""
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i, (data, orig) in enumerate(packets):
        out.append(struct.pack("<IIII", 1700000000 + i, 0, len(data), orig))
        out.append(bytes(data))
    return b"".join(out)


# --------------------------------------------------------------------------- the messages of the test

class Case:
    """One packet: a message, where its capture ends (None: whole), how it travels."""

    def __init__(self, msg, cut=None, udp=False, short=False, note="valid"):
        self.msg, self.cut, self.udp, self.short, self.note = msg, cut, udp, short, note
        # cut by the capture (not short): the whole message was on the wire
        self.expected = Expected(msg, cut, None if cut is None or short else len(msg.data))

    def packet(self):
        frame = eth_frame(bytes(self.msg.data), self.udp)
        if self.cut is None:
            return frame, len(frame)
        head = len(frame) - len(self.msg.data)
        data = frame[:head + self.cut]
        return data, len(data) if self.short else len(frame)


def valid_cases(g, n):
    """n valid messages: every Kind branch, 0-3 sections, 1-4 records; a third on UDP."""
    kinds = [0, 1, 2, 3, 4, 5, 6, 7, 0x10, 0x1E, 0x1F]
    cases = []
    for i in range(n):
        kind = kinds[i % len(kinds)] if i < 3 * len(kinds) else None
        cases.append(Case(build_message(g, kind=kind, nsec=i % 4 if i < 8 else None,
                                        nrec=1 + i % 4 if i < 8 else None,
                                        env_padding=(0, 0, 0, 1, 0, 2, 0, 40)[i % 8]), udp=i % 3 == 2))
    return cases


def malformed_cases(g):
    """Truncations (everywhere in two messages, at random places in many) and wrong fields."""
    rng = g.rng
    cases = []
    for k in range(2):
        m = build_message(g, kind=(1, 2)[k], nsec=2, nrec=2)
        for cut in range(1, len(m.data)):   # (Ethernet calls nobody for an empty payload)
            cases.append(Case(m, cut, udp=k == 1, note="cut at %d of %d" % (cut, len(m.data))))
    for k in range(120):
        m = build_message(g)
        cut = rng.randrange(1, len(m.data))
        cases.append(Case(m, cut, udp=k % 4 == 3, short=k % 4 == 1, note="cut at %d" % cut))

    def bad(note, cut_after=None, **kw):
        m = build_message(g, nsec=kw.pop("nsec", None), nrec=kw.pop("nrec", None), bad=kw)
        cut = m.runs[cut_after].end if cut_after else None
        # cut after a run: that short on the wire (a capture's cut would be no fault of the message)
        cases.append(Case(m, cut, udp=cut is None and len(cases) % 2 == 1, short=cut is not None, note=note))

    for total in (0, 1, 23):
        bad("Total length %d: Options length negative" % total, total=total)
    for size in (0, 25, 26):
        bad("Tail size %d" % size, tail_size=size)
    bad("Words points past the end", words=250)
    bad("Blob length points past the end", nrec=1, blob_length=255)
    bad("Section count says more than the data holds", cut_after="Section", nsec=2, nsec_field=5)
    bad("Section count with no data at all", cut_after="Section", nsec=0, nsec_field=1)
    bad("More records set on the last record", cut_after="Record", last_record_more=True)
    bad("Item more set on the last item", cut_after="Item", last_item_more=True)
    bad("Envelope longer than its fields", env_extra=3)
    bad("Envelope shorter than its fields", env_size=2)
    return cases


# --------------------------------------------------------------------------- tshark output

def verbose_blocks(text):
    """Our protocol's lines of each packet of a tshark -V output."""
    blocks, inside = [], False
    for line in text.splitlines():
        if line.startswith("Frame ") and not line.startswith(" "):
            blocks.append([])
            inside = False
        elif line == PROTO_NAME:
            inside = True
        elif inside and (not line or not line.startswith(" ")):
            inside = False
        if inside:
            blocks[-1].append(line)
    return blocks


def rules_path():
    return os.path.join(ARGS.source_dir, RULES)


def dissgen(*args):
    return subprocess.run([ARGS.dissgen] + list(args), capture_output=True, text=True)


def naming_rule(xml_path, proto):
    """The display-filter names docs/manual.md gives the nodes of a rule file, computed here."""
    root = ET.parse(xml_path).getroot()
    names, position = [], [0]

    def segment(node):
        if "filter" in node.attrib:
            return node.attrib["filter"]
        seg = re.sub(r"[^a-z0-9]+", "_", node.attrib["name"].lower()).strip("_")
        if seg and seg[0].isdigit():
            seg = "f" + seg
        return seg or "f%d" % position[0]

    def visit(node, prefix):
        for child in node.findall("node"):
            position[0] += 1
            seg = segment(child)
            own = prefix + "." + seg if seg else ""
            if own:
                names.append(own)
            visit(child, own or prefix)

    visit(root, proto)
    return names


# --------------------------------------------------------------------------- the tests

class Everything(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.env.install_plugin(ARGS.dissgen, rules_path())
        listing = dissgen("fields", rules_path())
        assert listing.returncode == 0, listing.stderr
        # the rule file's own fields (the fourth column says "rules")
        cls.listing = [line.split("\t") for line in listing.stdout.splitlines() if line.split("\t")[3] == "rules"]
        cls.fields = [f[0] for f in cls.listing[1:]]
        # and the field the runtime registers for every protocol (not a rule file's)
        cls.shown = cls.fields + [PROTO + ".padding"]
        g = Gen(ARGS.seed)
        cls.valid = valid_cases(g, ARGS.messages)
        cls.malformed = malformed_cases(g)
        cls.cases = cls.valid + cls.malformed
        cap = cls.env.add_file("everything.pcap", pcap([c.packet() for c in cls.cases]))
        if ARGS.keep_pcap:
            shutil.copy(cap, ARGS.keep_pcap)
        extra = ["_ws.col.Protocol", "_ws.col.Info", "_ws.expert.message"]
        args = ["-r", cap, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=|"]
        for f in cls.shown + extra:
            args += ["-e", f]
        p = cls.env.tshark(args, check=False)
        cls.fields_stderr = p.stderr
        cls.columns = cls.shown + extra
        cls.rows = [dict(zip(cls.columns, line.split("\t"))) for line in p.stdout.splitlines()]
        v = cls.env.tshark(["-r", cap, "-V"], check=False)
        cls.verbose_text, cls.verbose_stderr = v.stdout, v.stderr
        cls.verbose = verbose_blocks(v.stdout)
        cls.capture = cap

    def where(self, i):
        c = self.cases[i]
        return "packet %d (%s, %s)" % (i + 1, c.note, "UDP" if c.udp else "Ethernet")

    def test_tshark_is_clean(self):
        self.assertEqual(self.fields_stderr.strip(), "")
        self.assertEqual(self.verbose_stderr.strip(), "")
        self.assertEqual(len(self.rows), len(self.cases))
        self.assertEqual(len(self.verbose), len(self.cases))
        self.assertNotIn("Malformed Packet", self.verbose_text, "a Wireshark exception escaped the rules")
        self.assertNotIn("Dissector bug", self.verbose_text)
        for i, row in enumerate(self.rows):
            self.assertEqual(row["_ws.col.Protocol"], "EVRY", self.where(i))

    def check_fields(self, first, last):
        bad = []
        for i in range(first, last):
            want = self.cases[i].expected.fields()
            for f in self.shown:
                got = self.rows[i].get(f, "")
                exp = "|".join(want.get(f, []))
                if got != exp:
                    bad.append("%s: %s = %r, expected %r" % (self.where(i), f, got, exp))
            unknown = set(want) - set(self.shown)
            if unknown:
                bad.append("%s: the test expects fields the rules do not have: %s" % (self.where(i), unknown))
        self.assertEqual(bad[:20], [], "%d mismatches" % len(bad))

    def check_verbose(self, first, last):
        bad = []
        for i in range(first, last):
            want, got = self.cases[i].expected.verbose(), self.verbose[i]
            if want != got:
                k = next((k for k, (a, b) in enumerate(zip(want, got)) if a != b), min(len(want), len(got)))
                bad.append("%s, line %d:\n  expected %r\n  got      %r" % (
                    self.where(i), k, want[k] if k < len(want) else "(end)", got[k] if k < len(got) else "(end)"))
        self.assertEqual(bad[:10], [], "%d packets differ" % len(bad))

    def check_info(self, first, last):
        bad = []
        for i in range(first, last):
            want, got = self.cases[i].expected.info_text(), self.rows[i]["_ws.col.Info"]
            if want != got:
                bad.append("%s:\n  expected %r\n  got      %r" % (self.where(i), want, got))
        self.assertEqual(bad[:10], [], "%d packets differ" % len(bad))

    # -- valid messages ------------------------------------------------------
    def test_valid_fields(self):
        self.check_fields(0, len(self.valid))

    def test_valid_tree(self):
        self.check_verbose(0, len(self.valid))

    def test_valid_info_column(self):
        self.check_info(0, len(self.valid))

    def test_valid_messages_have_no_expert_info(self):
        for i in range(len(self.valid)):
            self.assertEqual(self.rows[i]["_ws.expert.message"], "", self.where(i))

    def test_every_field_and_branch_is_exercised(self):
        seen = set()
        for c in self.valid:
            seen |= set(c.expected.fields())
        leaves = {f for f, t, *_ in self.listing[1:] if t != "FT_NONE"}
        self.assertEqual(sorted(leaves - seen), [], "fields no valid message shows")
        info = " ".join(c.expected.info_text() for c in self.valid)
        for text in ("Section %s" % TIMES, "Record %s" % TIMES, "Unknown (0x", ELLIPSIS, ": ,"):
            self.assertIn(text, info)
        for text in ("Item: Integer: 0x", "Item: Hardware address: - ", "Item: Blob: - - ", " - -\n"):
            self.assertIn(text, self.verbose_text)
        kinds = {c.msg.top.children[0].children[1].fval for c in self.valid}
        self.assertTrue(kinds >= {"0x%02x" % k for k in (0, 1, 2, 3, 4, 0x1E, 0x1F)}, kinds)

    # -- malformed messages ----------------------------------------------------
    def test_malformed_fields(self):
        self.check_fields(len(self.valid), len(self.cases))

    def test_malformed_tree(self):
        self.check_verbose(len(self.valid), len(self.cases))

    def test_malformed_info_column(self):
        self.check_info(len(self.valid), len(self.cases))

    def test_malformed_expert_infos(self):
        bad, kinds = [], set()
        for i in range(len(self.valid), len(self.cases)):
            want = [text for _, text in self.cases[i].expected.experts]
            kinds |= {k for k, _ in self.cases[i].expected.experts}
            got = self.rows[i]["_ws.expert.message"]
            if got != "|".join(want):
                bad.append("%s:\n  expected %r\n  got      %r" % (self.where(i), want, got))
            c = self.cases[i]
            if not want and c.cut is not None and c.short and c.cut < c.msg.top.children[-1].start:
                bad.append("%s: a message cut before its trailer without an expert info?" % self.where(i))
            if c.cut is not None and not c.short and not c.expected.cut_shown and c.cut < c.msg.top.children[-1].start:
                bad.append("%s: cut by the capture before its trailer, and not shown so?" % self.where(i))
        self.assertEqual(bad[:10], [], "%d packets differ" % len(bad))
        self.assertEqual(kinds, set(EXPERTS), "every expert info is exercised")

    # -- names, hooks, help texts, hidden fields ---------------------------------
    def test_filter_names_follow_the_naming_rule(self):
        self.assertEqual(self.fields, naming_rule(rules_path(), PROTO))
        self.assertIn("evry.tail.f96", self.fields)       # 校验和: 96th node
        self.assertIn("evry.f2nd_address", self.fields)   # leading digit
        p = dissgen("check", rules_path())
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("warning: name '校验和' gives no filter name; using 'f96'", p.stderr)
        self.assertEqual(len(p.stderr.strip().splitlines()), 1, p.stderr)

    def test_registered_fields_types_masks_and_descriptions(self):
        """tshark -G fields: F, name, filter, type, protocol, base, bit mask, description."""
        p = self.env.tshark(["-G", "fields"])
        registered = {}
        for line in p.stdout.splitlines():
            parts = line.split("\t")
            if parts[0] == "F" and (parts[2] == PROTO or parts[2].startswith(PROTO + ".")):
                registered[parts[2]] = parts
        self.assertEqual(sorted(registered), sorted(self.shown + ["%s.expert.%s" % (PROTO, k) for k in list(EXPERTS) + list(OTHER_EXPERTS)]))
        bad = []
        for name in self.fields:
            ftype, mask = REGISTERED[name]
            got = registered[name]
            if (got[3], got[6]) != (ftype, "0x%x" % mask):
                bad.append("%s: %s %s, the encoder wrote %s 0x%x" % (name, got[3], got[6], ftype, mask))
        self.assertEqual(bad, [])
        nodes = [n for n in ET.parse(rules_path()).getroot().iter("node") if n.attrib.get("filter") != ""]
        described = 0
        for name, node in zip(self.fields, nodes):
            self.assertEqual(registered[name][1], node.attrib["name"])
            self.assertEqual(registered[name][7], node.attrib.get("description", ""), name)
            described += "description" in node.attrib
        self.assertGreaterEqual(described, 8)

    def test_statistics_tree_counts_what_the_fields_show(self):
        """-z evry,tree: messages; each enum field's values as -T fields shows them (the total and
        how often each value occurs); each repeated node's instances per message add up."""
        out = self.env.tshark(["-r", self.capture, "-q", "-z", PROTO + ",tree"]).stdout
        rows, current = {}, None
        for line in out.splitlines():
            m = re.match(r"^(\S.*?)\s{2,}(\d+)\s", line)
            child = re.match(r"^ (\S.*?)\s{2,}(\d+)\s", line)
            if m and not line.startswith(" "):
                current = rows.setdefault(m.group(1), [int(m.group(2)), []])
            elif child and current is not None:
                current[1].append(int(child.group(2)))
        self.assertEqual(rows.get("Messages", [None])[0], len(self.cases), out[:2000])
        checked = 0
        for label, (total, children) in rows.items():
            f = re.search(r"\((%s\.[\w.]+)\)$" % PROTO, label)
            if not f:
                continue
            self.assertEqual(sum(children), total, "%s: the values add up to the total" % label)
            if " per message " in label:
                continue
            values = [v for r in self.rows for v in (r[f.group(1)].split("|") if r[f.group(1)] else [])]
            counts = sorted((values.count(v) for v in set(values)), reverse=True)
            self.assertEqual((total, sorted(children, reverse=True)), (len(values), counts),
                             "%s: as often as -T fields shows it, each value as often" % label)
            checked += 1
        self.assertGreaterEqual(checked, 10, "enum fields in the tree: %d" % checked)

    def test_statistics_tree_of_a_rule_file_ending_in_a_counted_node(self):
        """The tree's rows are kept per node: the last node of the file counted too (an enum
        after a repeated node), each value and each number of instances as often as sent; a
        repeat inside a repeat counts its instances in the whole message (each Item's Subs
        added up). A '/' in a node's name shows as U+2215 (the tree would show only what
        follows it)."""
        rules = ('<root name="Counted last" abbreviation="CLAST" filter="clast" byteorder="big">\n'
                 '  <hook table="udp.port" value="%d"/>\n'
                 '  <node name="Count" length="1byte" displaytype="numberdec"/>\n'
                 '  <node name="Item" count="../node[@name=\'Count\']">\n'
                 '    <node name="Value" length="1byte" displaytype="numberhex"/>\n'
                 '    <node name="Subs" length="1byte" displaytype="numberdec"/>\n'
                 '    <node name="Sub" count="../node[@name=\'Subs\']" length="1byte" displaytype="numberhex"/>\n'
                 '  </node>\n'
                 '  <node name="Kind/mode" length="1byte" displaytype="enum">'
                 '<enum value="1" name="One"/><enum value="2" name="Two"/></node>\n'
                 '</root>\n' % UDP_PORT)
        rng = random.Random(7)
        sent = [(rng.randrange(1, 4), rng.choice([1, 1, 2])) for _ in range(40)]
        subs = [[rng.randrange(0, 3) for _ in range(n)] for n, _k in sent]  # per message, per Item

        def body(n, kind, item_subs):
            return bytes([n]) + b"".join(bytes([0xAA, k] + [0x55] * k) for k in item_subs) + bytes([kind])
        with TsharkEnv() as env:
            path = os.path.join(env.home, "counted_last.xml")
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(rules)
            env.install_plugin(ARGS.dissgen, path)
            frames = [(f, len(f)) for f in (eth_frame(body(n, kind, item_subs), udp=True)
                                            for (n, kind), item_subs in zip(sent, subs))]
            cap = env.add_file("counted_last.pcap", pcap(frames))
            out = env.tshark(["-r", cap, "-q", "-z", "clast,tree"]).stdout
        rows = {m.group(1).strip(): int(m.group(2)) for m in re.finditer(r"^(\S.*?|\s\S.*?)\s{2,}(\d+)\s", out, re.M)}
        want = {"Messages": len(sent), "Kind\u2215mode (clast.kind_mode)": len(sent),
                "One": sum(k == 1 for _n, k in sent), "Two": sum(k == 2 for _n, k in sent),
                "Item per message (clast.item)": len(sent), "Sub per message (clast.item.sub)": len(sent)}
        self.assertEqual({k: rows.get(k) for k in want}, want, out)
        # each per-message row's values, in the order the tree lists them
        children, current = {}, None
        for line in out.splitlines():
            top = re.match(r"^(\S.*?)\s{2,}\d+\s", line)
            child = re.match(r"^ (\S.*?)\s{2,}(\d+)\s", line)
            if top:
                current = children.setdefault(top.group(1), {})
            elif child and current is not None and child.group(1).isdigit():
                current[int(child.group(1))] = int(child.group(2))
        totals = [sum(item_subs) for item_subs in subs]
        self.assertEqual(children.get("Item per message (clast.item)"),
                         {c: sum(n == c for n, _k in sent) for c in {n for n, _k in sent}}, out)
        self.assertEqual(children.get("Sub per message (clast.item.sub)"),
                         {t: totals.count(t) for t in set(totals)}, out)

    def test_hooks(self):
        p = self.env.tshark(["-G", "decodes"])
        ours = {tuple(line.split("\t")[:2]) for line in p.stdout.splitlines() if line.endswith("\t" + PROTO)}
        self.assertEqual(ours, {("ethertype", "%d" % ETHERTYPE), ("udp.port", "%d" % UDP_PORT)})
        udp = [i for i, c in enumerate(self.valid) if c.udp]
        self.assertGreater(len(udp), 10)

    def test_hidden_fields_are_filterable_but_not_shown(self):
        tag = self.valid[5].msg.hidden_tag
        p = self.env.tshark(["-r", self.capture, "-Y", "evry.header.hidden_tag == %d" % tag,
                             "-T", "fields", "-e", "frame.number"])
        want = [str(i + 1) for i, c in enumerate(self.valid) if c.msg.hidden_tag == tag]
        got = [n for n in p.stdout.split() if int(n) <= len(self.valid)]
        self.assertEqual(got, want)
        p = self.env.tshark(["-r", self.capture, "-Y", "evry.record.pad && evry.lnk.reserved <= 7",
                             "-T", "fields", "-e", "frame.number"])
        frames = {int(n) for n in p.stdout.split()}
        self.assertLessEqual(set(range(1, len(self.valid) + 1)), frames)
        hidden = ("Hidden tag:", "Reserved:", "Item more:", "Record pad:")
        shown = [line for block in self.verbose[:len(self.valid)] for line in block
                 if line.strip().split(" = ")[-1].startswith(hidden)]
        self.assertEqual(shown, [])


def main():
    def arguments(parser):
        parser.add_argument("--seed", type=int, default=2024)
        parser.add_argument("--messages", type=int, default=300, help="valid messages")
        parser.add_argument("--keep-pcap", help="copy the capture here")
    return run_unittests(arguments)[1]


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Constructs of the rule language at their edges, with real tshark, each decoded field checked
against the bytes this script wrote.

handoff   tests/rules/handoff.xml: a leaf with dissector="eth_withoutfcs" followed by a
          checksum in its container, a box of known length ending with such a leaf and a
          trailer after the box, two such leaves back to back. The other dissector gets the
          leaf's own bytes only: the inner frames' payloads (data.data) are exactly those
          written, from none (a bare Ethernet header) to 100 bytes, and the fields after the
          leaf have their values.
peek      <when peek> at a bit-group member with a non-zero shift (rule files written here,
          one little-endian, one big-endian): for every member width 1..62, in a group of the
          fewest bytes that leaves it a neighbour on each side (1 to 8 bytes, shifts varied),
          the node is decoded exactly when the member's bits (as written here, and as the
          member's own field shows them) hold the listed value: the value, each neighbour all
          ones or all zeros, and the value with its lowest or highest bit flipped.
offsets   tests/rules/offsets_from.xml: offsets= counted from the container around the node
          (from=".."), from the one around that (from="../..") and one more up ("../../.."),
          each container starting at another byte: the entries are where the table says (their
          tags and bodies), with the first right after the table or after a gap, entries of a
          single byte, the last one ending with the message; no expert info. A first offset
          one byte inside the table, or a second one before the first, gives
          offs.expert.bad_offset and no entry, and its message names the entry and the reason.
          Offsets counted from a field (from="../node[@name='Base']"), after a byte of its
          container: from its first byte; when an if= left that field out, no entry and
          offs.expert.bad_length, which says so.

    test_edges.py --dissgen build/bin/dissgen --source-dir . [TestEdges.test_handoff_...|-k peek|-k offsets]
"""
import os
import random
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import pcapgen  # noqa: E402
from tshark_env import TsharkEnv, TsharkTestCase, run_unittests  # noqa: E402

ARGS = None


def pcap(payloads, port):
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i, p in enumerate(payloads):
        data = pcapgen.udp_ethernet_frame(bytes(p), port)
        out.append(struct.pack("<IIII", 1704067200 + i, 0, len(data), len(data)) + data)
    return b"".join(out)


def fields(check, env, path, names):
    """[{field: [values]}] per packet."""
    rows, err = env.field_rows(path, ["frame.number"] + names, aggregator="|", with_stderr=True)
    check(not err.strip(), "%s: tshark wrote nothing to stderr%s" % (
        os.path.basename(path), ": " + err.strip()[:300] if err.strip() else ""))
    return list(rows.values())


# ----------------------------------------------------------------------------- hand-off

def inner_frame(payload):
    """An Ethernet frame of an ethertype Wireshark has no dissector for: its payload is data."""
    return b"\x02\x11\x11\x11\x11\x11\x02\x22\x22\x22\x22\x22\x88\xb5" + payload


def handoff_checks(check, dissgen, source_dir):
    print("\n== hand-off: the other dissector gets the leaf's bytes only")
    rng = random.Random(1)
    cases = []   # (payload, [inner payloads expected], {field: value})
    for n in (0, 1, 2, 45, 46, 100):
        body = bytes(rng.getrandbits(8) for _ in range(n))
        inner = inner_frame(body)
        checksum = rng.getrandbits(16) | 1
        cases.append((struct.pack("!BH", 1, len(inner)) + inner + struct.pack("!H", checksum), [body],
                      {"hndf.framed.checksum": checksum}, "a %d-byte frame, then a checksum" % len(inner)))
        trailer = rng.getrandbits(16) | 1
        cases.append((struct.pack("!BH", 2, len(inner)) + inner + struct.pack("!H", trailer), [body],
                      {"hndf.trailer": trailer}, "a box ending with a %d-byte frame, then a trailer" % len(inner)))
        second = bytes(rng.getrandbits(8) for _ in range(3 + n // 2))
        cases.append((struct.pack("!BH", 3, len(inner)) + inner + inner_frame(second), [body, second], {},
                      "a %d-byte frame, then another" % len(inner)))
    names = ["data.data", "data.len", "hndf.framed.checksum", "hndf.trailer", "eth.type", "_ws.expert",
             "_ws.malformed"]
    with TsharkEnv() as env:
        env.install_plugin(dissgen, os.path.join(source_dir, "tests", "rules", "handoff.xml"))
        env.assert_plugin_loaded("hndf")
        path = env.add_file("handoff.pcap", pcap([c[0] for c in cases], 47490))
        rows = fields(check, env, path, names)
        check(len(rows) == len(cases), "one line per packet (%d)" % len(rows))
        for (payload, bodies, after, what), r in zip(cases, rows):
            want_data = [b.hex() for b in bodies if b]
            got = {"data": r["data.data"], "len": r["data.len"],
                   "after": {k: int(r[k][0], 16) if r[k] else None for k in after},
                   "inner frames": len(r["eth.type"]) - 1, "experts": r["_ws.expert"] + r["_ws.malformed"]}
            want = {"data": want_data, "len": [str(len(b)) for b in bodies if b], "after": after,
                    "inner frames": len(bodies), "experts": []}
            check(got == want, "%s: the inner frames' data is what was written, the fields after them too%s" % (
                what, "" if got == want else "\n       got  %s\n       want %s" % (got, want)))


# ----------------------------------------------------------------------------- message tail

def ethertype_frame(payload):
    return b"\x02\x11\x11\x11\x11\x11\x02\x22\x22\x22\x22\x22\x88\xb5" + payload


def message_tail_checks(check, dissgen, source_dir):
    print("\n== the bytes after a message's last field")
    message = b"\x07\x12\x34\xab\xcd"
    junk = b"\xde\xad\xbe\xef"
    # (frame, what, tail.padding length, tail.expert.unused, eth.padding, eth.trailer)
    cases = [
        (ethertype_frame(message + bytes(41)), "Ethernet type, zeros to 60 bytes", None, False, None, None),
        (ethertype_frame(message + junk + bytes(37)), "Ethernet type, bytes that are not zero", None, False, None,
         (junk + bytes(37)).hex()),
        (ethertype_frame(message), "Ethernet type, nothing after", None, False, None, None),
        (pcapgen.udp_ethernet_frame(message + bytes(5), 47493), "UDP, zeros", 5, False, None, None),
        (pcapgen.udp_ethernet_frame(message + junk, 47493), "UDP, bytes that are not zero", None, True, None,
         None),
        (pcapgen.udp_ethernet_frame(message, 47493), "UDP, nothing after", None, False, None, None),
    ]
    names = ["tail.word", "tail.padding", "tail.expert.unused", "eth.padding", "eth.trailer", "_ws.expert.message"]
    with TsharkEnv() as env:
        env.install_plugin(dissgen, os.path.join(source_dir, "tests", "rules", "message_tail.xml"))
        env.assert_plugin_loaded("tail")
        path = env.add_file("tail.pcap", pcapgen.raw_pcap_bytes([c[0] for c in cases]))
        for extra in ([], ["-2"]):
            rows, err = env.field_rows(path, ["frame.number"] + names, two_pass=bool(extra), aggregator="|",
                                       with_stderr=True)
            check(not err.strip(), "tshark %s wrote nothing to stderr: %s" % (extra, err.strip()[:300]))
            for (frame, what, padding, unused, eth_padding, eth_trailer), r in zip(cases, rows.values()):
                got = {"word": r["tail.word"], "padding bytes": len(r["tail.padding"][0]) // 2 if r["tail.padding"]
                       else None, "unused": bool(r["tail.expert.unused"]), "eth.trailer": r["eth.trailer"][0]
                       if r["eth.trailer"] else None, "eth.padding": r["eth.padding"][0] if r["eth.padding"]
                       else None}
                want = {"word": ["0x1234"], "padding bytes": padding, "unused": unused, "eth.trailer": eth_trailer,
                        "eth.padding": eth_padding}
                check(got == want, "%s %s: %s%s" % (what, extra, "the message, then what the bytes after it are",
                                                    "" if got == want else "\n       got  %s\n       want %s" %
                                                    (got, want)))
                if unused:
                    check(r["_ws.expert.message"] == ["4 bytes after the message's last field are not decoded"],
                          "%s: the warning says how many bytes (%s)" % (what, r["_ws.expert.message"]))


def no_padding_checks(check, dissgen, source_dir):
    """padding="none" (tests/rules/no_padding.xml): zeros a length leaves over raise
    nopad.expert.unused exactly where they are, and nothing on clean messages; the same
    rules without the attribute show them as nopad.padding and raise nothing."""
    print("\n== padding=\"none\": zeros a length leaves over are not padding")
    word = b"\x12\x34"
    udp = lambda payload: pcapgen.udp_ethernet_frame(payload, 47494)
    eth = lambda payload: b"\x02\x11\x11\x11\x11\x11\x02\x22\x22\x22\x22\x22\x88\xb6" + payload + bytes(43)
    # (frame, what, the warning without padding="none" shown as padding, the warning's text or None)
    cases = [
        (udp(b"\x02" + word), "UDP, clean", None),
        (eth(b"\x02" + word), "Ethernet type, clean (Ethernet's padding after it)", None),
        (udp(b"\x04" + word + bytes(2)), "UDP, two zeros inside Body's length",
         "'Body' is 4 bytes, but its fields end after 2: 2 bytes are not decoded"),
        (eth(b"\x05" + word + bytes(3)), "Ethernet type, three zeros inside Body's length",
         "'Body' is 5 bytes, but its fields end after 2: 3 bytes are not decoded"),
        (udp(b"\x02" + word + bytes(3)), "UDP, three zeros after the message",
         "3 bytes after the message's last field are not decoded"),
    ]
    rules = os.path.join(source_dir, "tests", "rules", "no_padding.xml")
    with open(rules, encoding="utf-8") as f:
        text = f.read()
    for none in (True, False):
        with TsharkEnv() as env:
            variant = env.add_file("no_padding.xml", (text if none else text.replace(' padding="none"', "")).encode())
            env.install_plugin(dissgen, variant)
            env.assert_plugin_loaded("nopad")
            path = env.add_file("nopad.pcap", pcapgen.raw_pcap_bytes([c[0] for c in cases]))
            for extra in ([], ["-2"]):
                rows = env.field_rows(path, ["frame.number", "nopad.body.word", "nopad.expert.unused",
                                             "nopad.padding", "_ws.expert.message"], two_pass=bool(extra),
                                      aggregator="|")
                for (_, what, warning), r in zip(cases, rows.values()):
                    want = {"word": ["0x1234"], "warning": [warning] if warning and none else [],
                            "padding": bool(warning) and not none}
                    got = {"word": r["nopad.body.word"], "warning": r["_ws.expert.message"],
                           "padding": bool(r["nopad.padding"])}
                    check(got == want, "%s %s %s: %s%s" % (
                        'padding="none"' if none else "default", what, extra,
                        "unused exactly there" if none else "zeros are padding, no expert",
                        "" if got == want else "\n       got  %s\n       want %s" % (got, want)))


# ----------------------------------------------------------------------------- peek

MAX_WIDTH = 62


def peek_layout(w):
    """(group bytes, bits before the member, bits after it): both neighbours at least 1 bit."""
    g = (w + 2 + 7) // 8
    lo = 1 + (w * 5) % (8 * g - w - 1)
    return g, lo, 8 * g - w - lo


def peek_value(w):
    return (0xA5C3_5A3C_96E1_7B2D >> (64 - w)) | 1


def peek_rules(order):
    abbr = "PKB" + order[0].upper()
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           '<root name="Peek at bits %s" abbreviation="%s" byteorder="%s">' % (order, abbr, order),
           '  <hook table="udp.port" value="%d"/>' % (47491 if order == "little" else 47492),
           '  <node name="Width" length="1byte" displaytype="numberdec"/>']
    for w in range(1, MAX_WIDTH + 1):
        g, lo, hi = peek_layout(w)
        first, last = ("Low", "High") if order == "little" else ("High", "Low")
        a, b = (lo, hi) if order == "little" else (hi, lo)
        out += ['  <node name="W%d" if="../node[@name=\'Width\']" in="%d">' % (w, w),
                '    <node name="Probe" length="1byte" displaytype="numberdec">',
                '      <when peek="../node[@name=\'Target\']" in="%d"/>' % peek_value(w),
                '    </node>',
                '    <node name="Miss" length="1byte" displaytype="numberdec" otherwise="true"/>',
                '    <node name="%s" length="%dbit" displaytype="numberhex"/>' % (first, a),
                '    <node name="Target" length="%dbit" displaytype="numberhex"/>' % w,
                '    <node name="%s" length="%dbit" displaytype="numberhex"/>' % (last, b),
                '  </node>']
    out.append('</root>')
    return "\n".join(out) + "\n"


def peek_message(order, w, target, low, high):
    """Width, the probed byte, then the group: with little the first member (Low) takes the
    least significant bits, with big the first member (High) the most significant."""
    g, lo, hi = peek_layout(w)
    value = low | (target << lo) | (high << (lo + w))
    return bytes([w, 0x5A]) + value.to_bytes(g, "little" if order == "little" else "big")


def peek_checks(check, dissgen, source_dir):
    print("\n== peek at a bit-group member with a shift, widths 1..%d" % MAX_WIDTH)
    rng = random.Random(2)
    with TsharkEnv() as env:
        for order in ("little", "big"):
            abbr = "pkb" + order[0]
            rules = env.add_file("peek_%s.xml" % order, peek_rules(order).encode())
            env.install_plugin(dissgen, rules)
            cases = []
            for w in range(1, MAX_WIDTH + 1):
                g, lo, hi = peek_layout(w)
                v, mask = peek_value(w), (1 << w) - 1
                ones_lo, ones_hi = (1 << lo) - 1, (1 << hi) - 1
                for target, low, high in ((v, ones_lo, ones_hi), (v, 0, 0), (v, rng.getrandbits(lo), 0),
                                          (v, 0, rng.getrandbits(hi)), (v ^ 1, ones_lo, ones_hi),
                                          (v ^ (1 << (w - 1)), 0, 0), (rng.getrandbits(w) & mask, ones_lo, 0)):
                    cases.append((w, target, low, high))
            path = env.add_file("peek_%s.pcap" % order, pcap([peek_message(order, *c) for c in cases],
                                                            47491 if order == "little" else 47492))
            names = []
            for w in range(1, MAX_WIDTH + 1):
                names += ["%s.w%d.probe" % (abbr, w), "%s.w%d.miss" % (abbr, w), "%s.w%d.target" % (abbr, w)]
            rows = fields(check, env, path, names + ["_ws.expert"])
            wrong = {}
            for (w, target, low, high), r in zip(cases, rows):
                shown = [int(x, 16) for x in r["%s.w%d.target" % (abbr, w)]]
                hit = target == peek_value(w)
                got = (bool(r["%s.w%d.probe" % (abbr, w)]), bool(r["%s.w%d.miss" % (abbr, w)]), shown,
                       r["_ws.expert"])
                if got != (hit, not hit, [target], []):
                    wrong.setdefault(w, []).append("target %#x low %#x high %#x: probe/miss/target/experts %s" % (
                        target, low, high, got))
            check(len(rows) == len(cases), "%s: one line per packet (%d)" % (order, len(rows)))
            for w in range(1, MAX_WIDTH + 1):
                if w in wrong or w in (1, 8, 31, 32, 33, MAX_WIDTH):
                    g, lo, hi = peek_layout(w)
                    check(w not in wrong, "%s-endian, %d-bit member at shift %d of a %d-byte group: the peek "
                          "reads its bits%s" % (order, w, lo if order == "little" else hi, g,
                                                "".join("\n       " + x for x in wrong.get(w, [])[:3])))
            check(not wrong, "%s-endian: the peek reads the member's bits at every width 1..%d%s" % (
                order, MAX_WIDTH, ": wrong at widths %s" % sorted(wrong) if wrong else ""))


# ----------------------------------------------------------------------------- offsets

KINDS = {  # kind: (filter prefix, bytes from the base to the table's count, offset size)
    1: ("offs.near", 0, 1),
    2: ("offs.two.inner", 2, 1),
    3: ("offs.three.middle.inner", 4, 2),
    4: ("offs.field", 2, 1),    # from the field Base (2 bytes), after one byte of its container
}
LEAD = {4: b"\x5a"}   # bytes of the container before the base


def offsets_message(kind, entries, gap, first_shift=0, second_before_first=False):
    """Kind, Pad, the heads of the containers, the table, a gap, the entries (tag, body).
    Returns (payload, [(tag, body)] expected)."""
    _prefix, heads, size = KINDS[kind]
    n = len(entries)
    table_end = heads + 1 + size * n      # bytes from the base (the from= container's first byte)
    offsets, at = [], table_end + gap
    for tag, body in entries:
        offsets.append(at)
        at += 1 + len(body)
    offsets[0] -= first_shift
    if second_before_first:
        offsets[1] = offsets[0] - 1
    head = LEAD.get(kind, b"") + bytes(range(0xA0, 0xA0 + heads))
    fmt = "<B" + ("B" if size == 1 else "H") * n
    return (bytes([kind, 0xEE]) + head + struct.pack(fmt, n, *offsets) + bytes(gap)
            + b"".join(bytes([tag]) + body for tag, body in entries)), entries


def offsets_checks(check, dissgen, source_dir):
    print("\n== offsets= counted from the containers around the node")
    rng = random.Random(3)
    cases = []   # (kind, payload, entries, bad, what)
    for kind in KINDS:
        for n, gap, sizes in ((1, 0, [0]), (1, 3, [5]), (2, 0, [0, 0]), (3, 0, [2, 0, 7]), (4, 2, [1, 1, 1, 1]),
                              (5, 1, None), (9, 0, None)):
            sizes = sizes or [rng.randint(0, 6) for _ in range(n)]
            entries = [(0x10 * (k + 1) + kind, bytes(rng.getrandbits(8) for _ in range(s)))
                       for k, s in enumerate(sizes)]
            payload, want = offsets_message(kind, entries, gap)
            cases.append((kind, payload, want, None, "kind %d, %d entries (%s bytes), gap %d" % (
                kind, n, sizes, gap)))
        payload, _ = offsets_message(kind, [(0x77, b"\x01"), (0x78, b"")], 0, first_shift=1)
        cases.append((kind, payload, [], "'Entry' 1 of 2: offset %d (byte %d) is before the bytes left",
                      "kind %d, the first offset one byte inside the table" % kind))
        payload, _ = offsets_message(kind, [(0x77, b"\x01\x02"), (0x78, b"")], 1, second_before_first=True)
        cases.append((kind, payload, [], "'Entry' 2 of 2: offset %d (byte %d) is smaller than the one before it",
                      "kind %d, the second offset before the first" % kind))
    # kind 5: the same container without its Base, which the offsets count from
    payload, _ = offsets_message(4, [(0x77, b"\x01"), (0x78, b"")], 0)
    cases.append((4, bytes([5]) + payload[1:3] + payload[5:], [],
                  "The offsets of 'Entry' count from a field that is not in this packet",
                  "kind 5, the field the offsets count from left out"))
    names = ["_ws.expert", "_ws.expert.message", "offs.expert.bad_offset", "offs.expert.bad_length"]
    for prefix, _h, _s in KINDS.values():
        names += [prefix + ".entry.tag", prefix + ".entry.body"]
    with TsharkEnv() as env:
        env.install_plugin(dissgen, os.path.join(source_dir, "tests", "rules", "offsets_from.xml"))
        env.assert_plugin_loaded("offs")
        path = env.add_file("offsets.pcap", pcap([c[1] for c in cases], 47493))
        rows = fields(check, env, path, names)
        check(len(rows) == len(cases), "one line per packet (%d)" % len(rows))
        for (kind, _payload, entries, bad, what), r in zip(cases, rows):
            prefix = KINDS[kind][0]
            got = ([int(t, 16) for t in r[prefix + ".entry.tag"]],
                   [b.replace(" ", "").replace(":", "") for b in r[prefix + ".entry.body"]],
                   bool(r["offs.expert.bad_offset"] or r["offs.expert.bad_length"]), len(r["_ws.expert"]))
            want = ([t for t, _b in entries], [b.hex() for _t, b in entries if b], bool(bad), 1 if bad else 0)
            check(got == want, "%s: entries where the table says, %s%s" % (
                what, ("offs.expert.bad_length" if "not in this packet" in bad else "offs.expert.bad_offset") if bad
                else "no expert info",
                "" if got == want else "\n       got  %s\n       want %s" % (got, want)))
            if bad:
                # which entry is wrong, and how: the number and the reason
                pattern = re.escape(bad).replace("%d", r"\d+")
                message = " ".join(r["_ws.expert.message"])
                check(re.match(pattern, message) is not None, "%s: the message says %r (%s)" % (
                    what, bad.split(": ", 1)[0] + ": ... " + bad.rsplit(" is ", 1)[1] if ": " in bad else bad,
                    message))


class TestEdges(TsharkTestCase, unittest.TestCase):
    def test_handoff_gives_the_other_dissector_the_leaf_only(self):
        with self.checks() as check:
            handoff_checks(check, ARGS.dissgen, ARGS.source_dir)

    def test_peek_at_shifted_bit_group_members(self):
        with self.checks() as check:
            peek_checks(check, ARGS.dissgen, ARGS.source_dir)

    def test_bytes_after_the_message(self):
        with self.checks() as check:
            message_tail_checks(check, ARGS.dissgen, ARGS.source_dir)

    def test_protocol_without_padding(self):
        with self.checks() as check:
            no_padding_checks(check, ARGS.dissgen, ARGS.source_dir)

    def test_offsets_from_enclosing_containers(self):
        with self.checks() as check:
            offsets_checks(check, ARGS.dissgen, ARGS.source_dir)


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

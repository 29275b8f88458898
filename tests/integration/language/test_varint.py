#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Base-128 numbers (displaytype="varint": 1 to 10 bytes, lowest 7 bits first, bit 7 set
while another byte follows) with real tshark, in one pass and -2, against the bytes:

- a varint's value and its bytes (the item covers them), as a length and as a count;
- one whose last byte is missing: one P.expert.truncated at it, nothing after it; one whose
  10 bytes all say another follows, or whose 10th byte holds more than the 64th bit: one
  P.expert.bad_length at it;
- a TCP protocol framed by a varint (pdulength, MQTT's remaining length, counted from the
  end of the length field), with and without valid=: messages split anywhere across
  segments (inside the varint too) and several in one segment decode as the messages
  written, and each frame's Info column names each of its messages once;
- a varint pairing key: a response finds its request's fields (request{...}).

    test_varint.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import random
import sys
import unittest

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402
from test_enip import TcpFlow, pcap, udp  # noqa: E402

UDP_PORT, TCP_PORT = 47621, 47622
RULES = """<root name="Varints" abbreviation="VAR" filter="var">
  <hook table="udp.port" value="%d"/>
  <node name="Size" displaytype="varint"/>
  <node name="Data" length="../node[@name='Size']" displaytype="origin"/>
  <node name="Count" displaytype="varint"/>
  <node name="Item" count="../node[@name='Count']" displaytype="varint"/>
  <node name="Last" length="1byte" displaytype="numberhex"/>
</root>
""" % UDP_PORT

# MQTT's fixed header: a type byte, then the remaining length (a varint) counting what follows it;
# the same with a valid= test on the type (framed by the test, then the length).
STREAM_RULES = """<root name="%s" abbreviation="%s" filter="%s" pdulength="node[@name='Remaining']">
  <hook table="tcp.port" value="%d"/>
  <node name="Type" length="1byte" displaytype="numberhex"%s/>
  <node name="Remaining" displaytype="varint"/>
  <node name="Payload" length="rest" displaytype="origin"/>
</root>
"""
STREAMS = {"vst": ("Varint stream", TCP_PORT, ""), "vsv": ("Varint stream tested", TCP_PORT + 1, ' valid="0x30-0x3f"')}

PAIRED_PORT = 47625
PAIRED_RULES = """<root name="Varint keys" abbreviation="VKEY" filter="vkey">
  <hook table="udp.port" value="%d"/>
  <pairing>
    <key field="node[@name='Transaction']"/>
  </pairing>
  <node name="Transaction" displaytype="varint"/>
  <node name="Quantity" length="1byte" displaytype="numberdec" direction="request"/>
  <node name="Asked" value="request{Quantity}" direction="response"/>
</root>
""" % PAIRED_PORT


def varint(value):
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def message(size, items):
    return varint(size) + bytes(i & 0xFF for i in range(size)) + varint(len(items)) + b"".join(varint(i) for i in items) + b"\xee"


def random_item(rng):
    bits = rng.choice([1, 7, 8, 14, 15, 21, 28, 35, 42, 49, 56, 63, 64])
    return rng.getrandbits(bits)


class TestVarint(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install_text("varints.xml", RULES, "var")
        for name, (title, port, valid) in STREAMS.items():
            cls.install_text(name + ".xml", STREAM_RULES % (title, name.upper(), name, port, valid), name)
        cls.install_text("varint_keys.xml", PAIRED_RULES, "vkey")

    def rows(self, path, fields, two_pass):
        return self.env.field_rows(path, ["frame.number"] + fields, two_pass, aggregator="|")

    def test_values_lengths_and_counts_against_the_bytes(self):
        rng = random.Random(20261203)
        messages = [(0, []), (127, [0, 127, 128]), (128, [2 ** 64 - 1, 2 ** 63, 16383, 16384])]
        messages += [(rng.randrange(300), [random_item(rng) for _ in range(rng.randrange(6))]) for _ in range(40)]
        path = self.env.add_file("varints.pcap", pcap([udp(UDP_PORT, UDP_PORT, message(s, i)) for s, i in messages]))
        want = {n: {"size": str(s), "data_len": str(s), "count": str(len(items)),
                    "items": "|".join(str(i) for i in items), "last": "0xee"}
                for n, (s, items) in enumerate(messages, 1)}
        # each item covers its own bytes: the Count's position plus the bytes before it
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.rows(path, ["var.size", "var.data", "var.count", "var.item", "var.last",
                                        "_ws.expert"], two_pass)
                got = {n: {"size": "|".join(r["var.size"]),
                           "data_len": str(len(bytes.fromhex("".join(r["var.data"]).replace(" ", "")))),
                           "count": "|".join(r["var.count"]), "items": "|".join(r["var.item"]),
                           "last": "|".join(r["var.last"])} for n, r in rows.items()}
                wrong = [n for n in want if got.get(n) != want[n]]
                check(not wrong, "%s: every varint's value as written (%d messages)%s" % (
                    "-2" if two_pass else "one pass", len(want),
                    "; first wrong %s: got %s want %s" % (wrong[0], got.get(wrong[0]), want[wrong[0]]) if wrong else ""))
                experts = [n for n, r in rows.items() if r["_ws.expert"]]
                check(not experts, "no expert info on sound messages (got on %s)" % experts[:5])

    def test_item_covers_its_bytes(self):
        path = self.env.add_file("cover.pcap", pcap([udp(UDP_PORT, UDP_PORT, message(2, [300, 5]))]))
        p = self.env.tshark(["-r", path, "-T", "pdml"])
        # Size at 0 (1 byte), Data 2, Count at 3, items at 4 (2 bytes: 300) and 6 (1 byte)
        for name, label, pos, size in (("var.size", "Size: 2", 0, 1), ("var.count", "Count: 2", 3, 1),
                                       ("var.item", "Item: 300", 4, 2), ("var.item", "Item: 5", 6, 1)):
            self.assertIn('<field name="%s" showname="%s" size="%d" pos="%d"' % (name, label, size, 42 + pos),
                          p.stdout)

    def test_faults_told_once_where_they_are(self):
        too_long = b"\x02ab\x01" + b"\xff" * 10 + b"\x01\xee"
        cut = b"\x02ab\x02\x05\x81"
        too_big = b"\x02ab\x01" + b"\xff" * 9 + b"\x02\xee"  # a 10th byte above 1: 65 bits
        path = self.env.add_file("faults.pcap", pcap([udp(UDP_PORT, UDP_PORT, too_long),
                                                      udp(UDP_PORT, UDP_PORT, cut),
                                                      udp(UDP_PORT, UDP_PORT, too_big)]))
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.rows(path, ["var.item", "var.last", "var.expert.bad_length", "var.expert.truncated",
                                        "_ws.expert.message"], two_pass)
                r1, r2, r3 = rows[1], rows[2], rows[3]
                check(r1["var.expert.bad_length"] and not r1["var.item"] and not r1["var.last"] and
                      len(r1["_ws.expert.message"]) == 1 and "more than 64 bits" in r1["_ws.expert.message"][0],
                      "10 bytes with bit 7: one bad_length, nothing after it: %s" % r1)
                check(r3["var.expert.bad_length"] and not r3["var.item"] and not r3["var.last"] and
                      len(r3["_ws.expert.message"]) == 1 and "more than 64 bits" in r3["_ws.expert.message"][0],
                      "a 10th byte of 2: one bad_length, nothing after it: %s" % r3)
                check(r2["var.expert.truncated"] and r2["var.item"] == ["5"] and not r2["var.last"] and
                      len(r2["_ws.expert.message"]) == 1 and "has no last byte" in r2["_ws.expert.message"][0],
                      "a last byte missing: one truncated at it, the item before it decoded: %s" % r2)

    def test_stream_framed_by_a_varint(self):
        for name, (title, port, _valid) in STREAMS.items():
            with self.subTest(protocol=name):
                self.check_stream(name, title, port)

    def check_stream(self, name, title, port):
        rng = random.Random(7)
        sizes = [0, 1, 127, 128, 200, 16383, 16384, 70000, 5, 300] + [rng.randrange(400) for _ in range(30)]
        stream, inside_varints = b"", set()
        for n, size in enumerate(sizes):
            if len(varint(size)) > 1:  # a cut after the varint's first byte, and before its last
                inside_varints |= {len(stream) + 2, len(stream) + len(varint(size))}
            stream += bytes([0x30 | (n & 0xF)]) + varint(size) + bytes((n + i) & 0xFF for i in range(size))
        # cut anywhere: inside headers, inside varints, several messages in one segment
        flow, frames, at = TcpFlow(50000, port), [], 0
        cuts = sorted(set(rng.randrange(1, len(stream)) for _ in range(60)) | {2, 3, 4} | inside_varints)
        for cut in cuts + [len(stream)]:
            if cut > at:
                frames.append(flow.segment(stream[at:cut]))
                at = cut
        path = self.env.add_file(name + "_stream.pcap", pcap(frames))
        want = ["%d:%d" % (0x30 | (n & 0xF), size) for n, size in enumerate(sizes)]
        with self.checks() as check:
            for two_pass in (False, True):
                f = dict((k, name + "." + k) for k in ("type", "remaining", "payload"))
                rows = self.rows(path, [f["type"], f["remaining"], f["payload"], "_ws.expert", "_ws.col.Info"],
                                 two_pass)
                got, payload_ok, experts, info_wrong = [], True, [], []
                for n in sorted(rows):
                    r = rows[n]
                    if r["_ws.expert"]:
                        experts.append(n)
                    types = r[f["type"]]
                    info = "|".join(r["_ws.col.Info"])  # the aggregator split it
                    if types and info.split(" | ") != [title] * len(types):
                        info_wrong.append((n, info))
                    payloads = r[f["payload"]] + [""] * (len(types) - len(r[f["payload"]]))
                    for t, size, data in zip(types, r[f["remaining"]], payloads):
                        got.append("%d:%s" % (int(t, 16), size))
                        index = len(got) - 1
                        expect = bytes((index + i) & 0xFF for i in range(int(size)))
                        payload_ok &= bytes.fromhex(data.replace(" ", "")) == expect
                check(got == want, "%s: each message once, in order, with its length (%d of %d)" % (
                    "-2" if two_pass else "one pass", sum(a == b for a, b in zip(got, want)), len(want)))
                check(payload_ok, "each payload holds the bytes written")
                check(not experts, "no expert info (got on frames %s)" % experts[:5])
                check(not info_wrong, "each frame's Info names each of its messages once (wrong: %s)" % info_wrong[:3])

    def test_pairing_key(self):
        client, server = (10, 1, 1, 167), (10, 1, 1, 164)

        def request(payload):
            return udp(40000, PAIRED_PORT, payload, client, server)

        def response(payload):
            return udp(PAIRED_PORT, 40000, payload, server, client)
        frames = [request(varint(300) + b"\x07"), response(varint(300)),
                  request(varint(5) + b"\x09"), response(varint(5))]
        path = self.env.add_file("keys.pcap", pcap(frames))
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.rows(path, ["vkey.transaction", "vkey.asked"], two_pass)
                got = {n: (r["vkey.transaction"], r["vkey.asked"]) for n, r in rows.items()}
                check(got[2] == (["300"], ["7"]) and got[4] == (["5"], ["9"]),
                      "%s: each response reads its own request's quantity: %s" % (
                          "-2" if two_pass else "one pass", got))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

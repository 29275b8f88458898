#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""valid="LIST" fields and <heuristic>: a protocol claims only its own messages (real tshark).

A Modbus/TCP-like rule file (protocol identifier valid="0", Length valid="2-254",
pdulength on a tcp.port hook; <heuristic table="udp"/> and a disabled one on tcp):

- TCP: a connection whose middle segment has an invalid header declaring a length of
  2000 bytes, and a segment with a valid message followed by an invalid header. Every
  valid message decodes (the transaction ids the bytes hold, in order), in one pass and
  with -2; the same rules without `valid` lose every message after the bad header,
  which is the failure this guards against;
- UDP on a port nobody registered: the heuristic finds the valid messages and claims no
  random payload that fails the test (the test counts, from the bytes, which random
  payloads pass it); `--disable-heuristic mbl_udp` finds none; `tshark -G
  heuristic-decodes` lists the protocol enabled on udp and disabled on tcp;
- TCP on a port nobody registered: nothing until `--enable-heuristic mbl_tcp`, then
  every message;
- a heuristic list this Wireshark does not have: a warning, and tshark goes on;
- a message refused on a hooked value another dissector had (KNX/IP's UDP port 3671,
  Modbus/TCP's TCP port 502) goes to that dissector, on UDP and on a TCP stream with
  pdulength, as if the protocol were not there; accepted ones stay ours;
- a message a heuristic found has its conversation's direction: over TCP the SYN says
  which port is the server's, otherwise the first message's receiver is; its request and
  response layouts decode as through a port hook, in one pass and with -2 (on ports where
  the lower one is the client's, so that no guess by port numbers could pass).

    test_validity.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import random
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import pcapgen  # noqa: E402
from tshark_env import TsharkEnv, TsharkTestCase, run_unittests  # noqa: E402

ARGS = None
PORT = 5020            # the tcp.port hook
UDP_PORT = 40123       # registered by nobody
TCP_PORT = 40999       # registered by nobody

RULES = """<root name="Modbus-like" abbreviation="MBL" filter="mbl"
      pdulength="node[@name='Length']" pdulengthadd="6">
  <hook table="tcp.port" value="%d"/>
  <heuristic table="udp"/>
  <heuristic table="tcp" enabled="false"/>
  <node name="Transaction" length="2byte" displaytype="numberdec"/>
  <node name="Protocol" length="2byte" displaytype="numberdec" VALID0/>
  <node name="Length" length="2byte" displaytype="numberdec" VALID1/>
  <node name="Unit" length="1byte" displaytype="numberdec"/>
  <node name="Function" length="1byte" displaytype="numberhex"/>
  <node name="Data" length="rest" displaytype="origin"/>
</root>
""" % PORT


def rules(valid=True):
    text = RULES.replace("VALID0", 'valid="0"' if valid else "").replace("VALID1", 'valid="2-254"' if valid else "")
    return text if valid else text.replace('  <heuristic table="udp"/>\n  <heuristic table="tcp" enabled="false"/>\n', "")


def message(tid, function, data):
    body = bytes([1, function]) + data
    return struct.pack("!HHH", tid, 0, len(body)) + body


def bad_header(tid, protocol=0x1234, length=2000):
    return struct.pack("!HHH", tid, protocol, length)


def is_valid(payload):
    """The rule file's test, from the bytes."""
    if len(payload) < 6:
        return False
    _, protocol, length = struct.unpack("!HHH", payload[:6])
    return protocol == 0 and 2 <= length <= 254


class Flow:
    def __init__(self, dport, sport=41000):
        self.sport, self.dport, self.seq, self.frames = sport, dport, 1000, []

    def send(self, payload):
        self.frames.append(pcapgen.tcp_ethernet_frame(payload, self.sport, self.dport, self.seq))
        self.seq += len(payload)


def bad_header_connection(dport):
    """Segments of one connection and the transaction ids of its valid messages, in order."""
    flow, tids = Flow(dport), []

    def send(*parts):
        flow.send(b"".join(m for m, _ in parts))
        tids.extend(t for _, t in parts if t is not None)

    send((message(1, 3, b"\x00\x01\x00\x02"), 1))
    send((message(2, 3, b"\x00\x01\x00\x02"), 2), (message(3, 6, b"\x00\x05\x12\x34"), 3))
    send((bad_header(4) + b"\xff" * 10, None))                      # claims 2000 bytes
    for tid in range(5, 10):
        send((message(tid, 4, b"\x00\x00\x00\x01"), tid))
    send((message(10, 6, b"\x00\x01\x00\x07"), 10), (bad_header(11, protocol=7) + b"\xee" * 5, None))
    send((message(12, 16, b"\x00\x01\x00\x01\x02\x00\x0a"), 12))
    send((message(13, 3, b"\x00\x01\x00\x02"), 13))
    return flow.frames, tids


DIRECTED = """<root name="Directed" abbreviation="DIRH" filter="dirh"
      pdulength="node[@name='Length']" pdulengthadd="6">
  <heuristic table="udp"/>
  <heuristic table="tcp"/>
  <node name="Transaction" length="2byte" displaytype="numberdec"/>
  <node name="Protocol" length="2byte" displaytype="numberdec" valid="0"/>
  <node name="Length" length="2byte" displaytype="numberdec" valid="2-254"/>
  <node name="Unit" length="1byte" displaytype="numberdec"/>
  <node name="Function" length="1byte" displaytype="numberhex"/>
  <node name="Read request" filter="request" direction="request">
    <node name="Start" length="2byte" displaytype="numberdec"/>
    <node name="Quantity" length="2byte" displaytype="numberdec"/>
  </node>
  <node name="Read response" filter="response" direction="response">
    <node name="Byte count" filter="byte_count" length="1byte" displaytype="numberdec"/>
    <node name="Values" length="rest" displaytype="origin"/>
  </node>
</root>
"""
SERVER_PORT, CLIENT_PORT = 41999, 1500   # the client's port is the lower one


def tcp_segment(payload, sport, dport, seq, ack, flags, src, dst):
    """One TCP segment (flags: 0x02 SYN, 0x12 SYN+ACK, 0x10 ACK, 0x18 PSH+ACK) in IPv4 in Ethernet."""
    t = struct.pack("!HHIIBBHHH", sport, dport, seq, ack, 5 << 4, flags, 65535, 0, 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(t), 0, 0x4000, 64, 6, 0, bytes(src), bytes(dst))
    ip = ip[:10] + struct.pack("!H", pcapgen.ip_checksum(ip)) + ip[12:]
    return b"\x02\0\0\0\0\x02\x02\0\0\0\0\x01\x08\x00" + ip + t


def read_request(tid, start, quantity):
    return message(tid, 3, struct.pack("!HH", start, quantity))


def read_response(tid, values):
    return message(tid, 3, bytes([2 * len(values)]) + b"".join(struct.pack("!H", v) for v in values))


def directed_tcp(handshake):
    """A client asking a server on SERVER_PORT three times, with or without the handshake:
    the frames and, per frame with a message, 'request' or 'response'."""
    client, server = (10, 0, 0, 1), (10, 0, 0, 2)
    cseq, sseq, frames, kinds = 100, 700, [], []
    if handshake:
        frames += [tcp_segment(b"", CLIENT_PORT, SERVER_PORT, cseq, 0, 0x02, client, server),
                   tcp_segment(b"", SERVER_PORT, CLIENT_PORT, sseq, cseq + 1, 0x12, server, client),
                   tcp_segment(b"", CLIENT_PORT, SERVER_PORT, cseq + 1, sseq + 1, 0x10, client, server)]
        kinds += [None, None, None]
    cseq, sseq = cseq + 1, sseq + 1
    for tid in range(1, 4):
        q, r = read_request(tid, 100 * tid, tid), read_response(tid, list(range(tid)))
        frames.append(tcp_segment(q, CLIENT_PORT, SERVER_PORT, cseq, sseq, 0x18, client, server))
        cseq += len(q)
        frames.append(tcp_segment(r, SERVER_PORT, CLIENT_PORT, sseq, cseq, 0x18, server, client))
        sseq += len(r)
        kinds += ["request", "response"]
    return frames, kinds


class HeuristicDirection(TsharkTestCase, unittest.TestCase):
    """Messages found by a heuristic decode their request and response layouts."""

    @classmethod
    def prepare(cls):
        cls.env.install_plugin(ARGS.dissgen, cls.env.add_file("dirh.xml", DIRECTED.encode()))
        cls.env.assert_plugin_loaded("dirh")

    def kinds(self, frames, name):
        path = self.env.add_file(name, pcapgen.raw_pcap_bytes(frames))
        fields = ["frame.number", "dirh.transaction", "dirh.request.start", "dirh.response.byte_count"]
        out = []
        for two_pass in (False, True):
            rows = self.env.field_rows(path, fields, two_pass=two_pass)
            out.append([None if not rows.get(n, {}).get("dirh.transaction") else
                        "request" if rows[n]["dirh.request.start"] and not rows[n]["dirh.response.byte_count"] else
                        "response" if rows[n]["dirh.response.byte_count"] and not rows[n]["dirh.request.start"] else
                        "both or neither" for n in range(1, len(frames) + 1)])
        return out

    def test_tcp_the_syn_names_the_server(self):
        frames, kinds = directed_tcp(handshake=True)
        self.assertEqual(self.kinds(frames, "dirh_syn.pcap"), [kinds, kinds])

    def test_tcp_without_handshake_the_first_receiver_is_the_server(self):
        frames, kinds = directed_tcp(handshake=False)
        self.assertEqual(self.kinds(frames, "dirh_nosyn.pcap"), [kinds, kinds])

    def test_udp_the_first_receiver_is_the_server(self):
        client, server = b"\x0a\0\0\x01", b"\x0a\0\0\x02"
        frames, kinds = [], []
        for tid in range(1, 4):
            frames.append(udp_frame(read_request(tid, 7, 2), CLIENT_PORT, SERVER_PORT, client, server))
            frames.append(udp_frame(read_response(tid, [5, 6]), SERVER_PORT, CLIENT_PORT, server, client))
            kinds += ["request", "response"]
        self.assertEqual(self.kinds(frames, "dirh_udp.pcap"), [kinds, kinds])


def udp_frame(payload, sport, dport, src, dst):
    u = struct.pack("!HHHH", sport, dport, 8 + len(payload), 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0, src, dst)
    ip = ip[:10] + struct.pack("!H", pcapgen.ip_checksum(ip)) + ip[12:]
    return b"\x02\0\0\0\0\x02\x02\0\0\0\0\x01\x08\x00" + ip + u


class Validity(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.env.install_plugin(ARGS.dissgen, cls.env.add_file("mbl.xml", rules().encode()))
        cls.env.assert_plugin_loaded("mbl")
        frames, cls.tids = bad_header_connection(PORT)
        cls.tcp = cls.env.add_file("tcp.pcap", pcapgen.raw_pcap_bytes(frames))

        rng = random.Random(20240611)
        cls.udp_sent = []   # (payload, valid?)
        for i in range(400):
            if i % 20 == 0:
                payload = message(1000 + i, 3, b"\x00\x01\x00\x02")
            elif i % 20 == 10:
                # near misses: one of the two checks fails
                payload = struct.pack("!HHH", i, 0, 255 if i % 40 == 10 else 1) + b"\x01\x03" if i % 40 == 10 \
                    else struct.pack("!HHH", i, 1, 6) + b"\x01\x03\x00\x01\x00\x02"
            else:
                payload = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 40)))
            cls.udp_sent.append((payload, is_valid(payload)))
        cls.udp = cls.env.add_file("udp.pcap", pcapgen.raw_pcap_bytes(
            [pcapgen.udp_ethernet_frame(p, UDP_PORT) for p, _ in cls.udp_sent]))

        flow = Flow(TCP_PORT)
        for tid in range(20, 25):
            flow.send(message(tid, 3, b"\x00\x01\x00\x02"))
        cls.tcp_unregistered = cls.env.add_file("tcp_unregistered.pcap", pcapgen.raw_pcap_bytes(flow.frames))

    def transactions(self, path, two_pass=False, extra=()):
        args = ["-r", path, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=,", "-e", "mbl.transaction"]
        out = self.env.tshark(args + (["-2"] if two_pass else []) + list(extra)).stdout
        return [int(v) for line in out.splitlines() for v in line.split(",") if v]

    def claimed_frames(self, path, extra=()):
        out = self.env.tshark(["-r", path, "-Y", "mbl", "-T", "fields", "-e", "frame.number"] + list(extra)).stdout
        return [int(v) for v in out.split()]

    def test_every_valid_message_after_a_bad_header_decodes(self):
        self.assertEqual(len(self.tids), 11)
        for two_pass in (False, True):
            self.assertEqual(self.transactions(self.tcp, two_pass), self.tids, "-2" if two_pass else "one pass")

    def test_the_bad_header_is_no_message_of_the_protocol(self):
        out = self.env.tshark(["-r", self.tcp, "-T", "fields", "-e", "frame.number", "-e", "_ws.col.Protocol",
                               "-e", "data.len", "-e", "frame.protocols"]).stdout.splitlines()
        rows = {int(r.split("\t")[0]): r.split("\t")[1:] for r in out}
        # refused (the dissector returned 0): the TCP payload is data, no layer of ours
        self.assertEqual(rows[3], ["TCP", "16", "eth:ethertype:ip:tcp:data"])
        self.assertEqual(rows[9], ["MBL", "11", "eth:ethertype:ip:tcp:mbl:data"])  # message 10, then 11 bytes of data

    def test_heuristic_finds_the_protocol_on_an_unregistered_udp_port(self):
        expected = [i + 1 for i, (_, valid) in enumerate(self.udp_sent) if valid]
        self.assertGreaterEqual(len(expected), 20)
        for two_pass in (False, True):
            self.assertEqual(self.claimed_frames(self.udp, ["-2"] if two_pass else []), expected)

    def test_no_false_positives_on_payloads_failing_the_test(self):
        claimed = set(self.claimed_frames(self.udp))
        failing = [i + 1 for i, (_, valid) in enumerate(self.udp_sent) if not valid]
        self.assertGreater(len(failing), 350)
        self.assertEqual(claimed.intersection(failing), set())

    def test_disable_heuristic_turns_it_off(self):
        self.assertEqual(self.claimed_frames(self.udp, ["--disable-heuristic", "mbl_udp"]), [])

    def test_heuristics_listed_like_wiresharks_own(self):
        rows = {tuple(l.split("\t")) for l in self.env.tshark(["-G", "heuristic-decodes"]).stdout.splitlines()}
        # list, protocol, enabled by default
        self.assertIn(("udp", "mbl", "T"), rows)
        self.assertIn(("tcp", "mbl", "F"), rows)

    def test_a_disabled_heuristic_is_enabled_on_request(self):
        self.assertEqual(self.transactions(self.tcp_unregistered), [])
        self.assertEqual(self.transactions(self.tcp_unregistered, extra=["--enable-heuristic", "mbl_tcp"]),
                         list(range(20, 25)))


GATE = """<root name="Gate" abbreviation="GATE" filter="gate"
      pdulength="node[@name='Length']" pdulengthadd="2">
  <hook table="udp.port" value="3671"/>
  <hook table="tcp.port" value="502"/>
  <hook table="udp.port" value="3671"/>
  <hook table="udp.port" value="47001"/>
  <hook table="udp.port" value="47001"/>
  <node name="Magic" length="1byte" displaytype="numberhex" valid="0x42"/>
  <node name="Length" length="1byte" displaytype="numberdec"/>
  <node name="Body" length="rest" displaytype="origin"/>
</root>
"""
KNX_SEARCH = bytes.fromhex("06100201000e" "08010a0000010e57")  # header, then the discovery endpoint
MODBUS_READ = bytes.fromhex("000100000006" "0103" "00000001")


class DisplacedDissector(TsharkTestCase, unittest.TestCase):
    """A message the valid fields refuse on a hooked value goes to the dissector the hook
    displaced there (Wireshark's kip on UDP 3671, mbtcp on TCP 502), one pass and -2; a value
    hooked twice (a warning) never hands a refused message back to the protocol itself."""

    @classmethod
    def prepare(cls):
        cls.install_text("gate.xml", GATE, "gate")
        udp = lambda p: pcapgen.udp_ethernet_frame(p, 3671)
        ours = b"\x42\x03abc"
        frames = [udp(ours), udp(KNX_SEARCH), udp(b"\x07")]
        # a port nobody else has, hooked twice: a refused message is UDP's data, not ours again
        frames.append(pcapgen.udp_ethernet_frame(b"\x07\x07", 47001))
        seq = 1000
        for payload in (MODBUS_READ, ours, MODBUS_READ):
            frames.append(pcapgen.tcp_ethernet_frame(payload, 41000, 502, seq))
            seq += len(payload)
        cls.capture = cls.env.add_file("displaced.pcap", pcapgen.raw_pcap_bytes(frames))
        # the last protocol of each frame, as Wireshark's own dissectors decode them
        cls.want = ["gate", "kip", "kip", "data", "mbtcp", "gate", "mbtcp"]

    def last_layers(self, extra):
        out = self.env.tshark(["-r", self.capture, "-T", "fields", "-e", "frame.protocols"] + extra).stdout
        # Modbus/TCP's payload is its "modbus" layer
        return [line.split(":")[-1].replace("modbus", "mbtcp") for line in out.splitlines()]

    def test_refused_messages_go_to_the_displaced_dissector(self):
        with self.checks() as check:
            for extra in ([], ["-2"]):
                got = self.last_layers(extra)
                check(got == self.want, "%s: %s, expected %s" % (extra or "one pass", got, self.want))
            gone = self.last_layers(["--disable-protocol", "gate"])
            check(gone[:5] == ["kip", "kip", "kip", "data", "mbtcp"],
                  "gate disabled: the displaced dissectors take everything: %s" % gone)


TESTED_FIRST = """<root name="Tested first" abbreviation="TFIRST" byteorder="little" pdulength="node[@name='Size']">
  <hook table="tcp.port" value="48400"/>
  <node name="Type" length="3byte" byteorder="big" displaytype="numberhex" valid="0x48454c,0x4d5347"/>
  <node name="Chunk" length="1byte" displaytype="numberhex"/>
  <node name="Size" length="4byte" displaytype="numberdec"/>
  <node name="Body" length="rest" displaytype="origin"/>
</root>
"""


class TestedBeforeTheLength(TsharkTestCase, unittest.TestCase):
    """The valid field (3 bytes) ends before the length field (8): a short tail that fails
    the test is data at once, and does not wait for the next segment to complete a
    header (which made the next message part of a made-up length); a valid start of a
    message cut before its length waits for the rest, one pass and -2."""

    @classmethod
    def prepare(cls):
        cls.install_text("tfirst.xml", TESTED_FIRST, "tfirst")
        flow = Flow(48400)
        hello = lambda: b"HELF" + struct.pack("<I", 12) + b"\x01\x02\x03\x04"  # noqa: E731
        msg = b"MSGF" + struct.pack("<I", 14) + b"\x05\x06\x07\x08\x09\x0a"
        flow.send(hello() + b"\x00\x00abc")   # a valid message, then 5 bytes that fail the test
        flow.send(msg)                        # a message of its own
        flow.send(msg[:5])                    # a valid type, the length still to come
        flow.send(msg[5:])
        cls.capture = cls.env.add_file("tested_first.pcap", pcapgen.raw_pcap_bytes(flow.frames))

    def test_a_failing_tail_does_not_swallow_the_next_message(self):
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(self.capture, ["frame.number", "tfirst.type", "tfirst.size", "data.len"],
                                           two_pass=two_pass)
                got = {n: (r["tfirst.type"], r["tfirst.size"], r["data.len"]) for n, r in rows.items()}
                want = {1: (["0x48454c"], ["12"], ["5"]), 2: (["0x4d5347"], ["14"], []), 3: ([], [], []),
                        4: (["0x4d5347"], ["14"], [])}
                check(got == want, "%s: %s, expected %s" % ("-2" if two_pass else "one pass", got, want))


class WithoutValidity(TsharkTestCase, unittest.TestCase):
    """The same rules without `valid`: the bad header holds back the rest of the connection."""

    @classmethod
    def prepare(cls):
        cls.env.install_plugin(ARGS.dissgen, cls.env.add_file("mbl.xml", rules(valid=False).encode()))
        frames, cls.tids = bad_header_connection(PORT)
        cls.tcp = cls.env.add_file("tcp.pcap", pcapgen.raw_pcap_bytes(frames))

    def test_messages_after_the_bad_header_are_lost(self):
        out = self.env.tshark(["-r", self.tcp, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=,",
                               "-e", "mbl.transaction"]).stdout
        decoded = [int(v) for line in out.splitlines() for v in line.split(",") if v]
        self.assertEqual(decoded, [1, 2, 3])


class MissingList(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        xml = ('<root name="Lost heuristic" abbreviation="LOSTH" filter="losth">\n'
               '  <heuristic table="nosuchlist"/>\n'
               '  <heuristic table="udp"/>\n'
               '  <node name="Magic" length="2byte" displaytype="numberhex" valid="0xcafe"/>\n'
               '</root>\n')
        cls.env.install_plugin(ARGS.dissgen, cls.env.add_file("losth.xml", xml.encode()))

    def test_a_list_wireshark_lacks_is_reported_and_skipped(self):
        p = self.env.tshark(["-G", "heuristic-decodes"])
        self.assertIn('no heuristic list "nosuchlist"', p.stderr)
        self.assertIn("udp\tlosth\tT", p.stdout.splitlines())
        udp = self.env.add_file("magic.pcap", pcapgen.raw_pcap_bytes(
            [pcapgen.udp_ethernet_frame(b"\xca\xfe\x00\x01", UDP_PORT),
             pcapgen.udp_ethernet_frame(b"\xca\xfd\x00\x01", UDP_PORT)]))
        out = self.env.tshark(["-r", udp, "-Y", "losth", "-T", "fields", "-e", "frame.number"]).stdout
        self.assertEqual(out.split(), ["1"])


if __name__ == "__main__":
    ARGS, code = run_unittests()
    sys.exit(code)

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Cycles declared in the rules (<cycles>) with real tshark: EtherNet/IP's class-1 I/O
as rules/enip.xml declares it (per connection ID and sender, window 1, the 32-bit
sequence number of the Sequenced Address item).

Every message's enipr.cycle, .period, .jitter, .lost and .duplicate, the expert infos
(exactly on the frames with a gap or a repeat, nowhere else) and `-z enipr,cycles` are
checked against a model of the manual's rules ("Cycles of any protocol") computed here
from the bytes and timestamps of the capture, to the nanosecond, in one pass and with -2,
and so is the statistics tree of the Statistics menu (`-2 -z enipr.cycles,tree`):

- a generated capture (nanosecond timestamps): several connections at different RPIs with
  known injected jitter, drops of one and of three packets, a packet sent twice, a
  sequence number wrapping past 2^32-1, a connection that starts mid-capture, one whose
  count restarts, and two adapters using the same connection ID;
- ../shared/corpus/enip/enip_cip_example.pcap (24 I/O connections, 398 packets), when
  the corpus is there.

    test_rule_cycles.py --dissgen build/bin/dissgen --source-dir .
"""

import os
import re
import random
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from pcapgen import ip_checksum  # noqa: E402
from cyclemodel import figures, mark_fields, mark_of, model, parse_report, pcap_ns, read_pcap  # noqa: E402
from cyclemodel import tree_unit, tree_value  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

ARGS = None
IO_PORT = 2222
FIELDS = ["frame.number"] + mark_fields("enipr")


# --- captures: writing and reading ----------------------------------------------------

def io_payload(connection, sequence, data=b"\x01\x00\x2a\x00"):
    items = [(0x8002, struct.pack("<II", connection, sequence)), (0x00B1, data)]
    return struct.pack("<H", len(items)) + b"".join(struct.pack("<HH", t, len(d)) + d for t, d in items)


def udp_frame(payload, src_ip, dst_ip=(10, 0, 0, 100), sport=IO_PORT, dport=IO_PORT):
    u = struct.pack("!HHHH", sport, dport, 8 + len(payload), 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0, bytes(src_ip), bytes(dst_ip))
    ip = ip[:10] + struct.pack("!H", ip_checksum(ip)) + ip[12:]
    return b"\x02\0\0\0\0\x64\x02\0\0\0\0" + bytes([src_ip[3]]) + b"\x08\x00" + ip + u


def io_messages(packets):
    """The class-1 I/O messages of Ethernet/IPv4/UDP frames, from their bytes:
    (frame, time ns, (connection ID, sender address, sender port), sequence number)."""
    out = []
    for number, (ts, f) in enumerate(packets, 1):
        if len(f) < 42 or f[12:14] != b"\x08\x00" or f[23] != 17:
            continue
        ihl = (f[14] & 0x0F) * 4
        udp = 14 + ihl
        sport, dport = struct.unpack("!HH", f[udp:udp + 4])
        if IO_PORT not in (sport, dport):
            continue
        cpf = udp + 8
        count = struct.unpack("<H", f[cpf:cpf + 2])[0]
        pos, connection, sequence = cpf + 2, None, None
        for _ in range(count):
            kind, length = struct.unpack("<HH", f[pos:pos + 4])
            if kind == 0x8002 and length >= 8:
                connection, sequence = struct.unpack("<II", f[pos + 4:pos + 12])
            pos += 4 + length
        if connection is not None:
            out.append((number, ts, (connection, bytes(f[26:30]), sport), sequence))
    return out


def generated_capture(seed=2222):
    """(packets, description): the connections below, each packet at its RPI plus a
    jitter drawn from the seed, merged in time order."""
    rng = random.Random(seed)
    ms = 10**6
    plan = [
        # connection, sender, RPI, start, packets, jitter (ns, either way), first count, faults
        (0x00110001, (10, 0, 0, 1), 10 * ms, 0, 70, 300_000, 2**32 - 25,
         {"drop": {20, 35, 36, 37}, "repeat": {45}}),
        (0x00220002, (10, 0, 0, 2), 4 * ms, 100 * ms, 120, 100_000, 1000, {"restart": {60}, "drop": {90}}),
        # the same connection ID from another adapter: another stream
        (0x00110001, (10, 0, 0, 3), 25 * ms, 3 * ms, 28, 2_000, 7, {}),
        (0x00330003, (10, 0, 0, 4), 1 * ms, 50 * ms, 300, 20_000, 0, {"repeat": {100, 101}}),
    ]
    packets = []
    for connection, sender, rpi, start, count, jitter, first_count, faults in plan:
        seq = first_count
        for i in range(count):
            if i in faults.get("restart", ()):
                seq = 0
            t = start + i * rpi + rng.randint(-jitter, jitter) + 1_000_000_000  # odd nanoseconds
            if i not in faults.get("drop", ()):
                frame = udp_frame(io_payload(connection, seq & 0xFFFFFFFF), sender)
                packets.append((t, frame))
                if i in faults.get("repeat", ()):
                    packets.append((t + 40_000 + rng.randint(0, 999), frame))
            seq += 1
    packets.sort(key=lambda p: p[0])
    return packets


class TestRuleCycles(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("rules", "enip.xml"), "enipr")
        cls.generated = cls.env.add_file("io_cycles.pcap", pcap_ns(generated_capture()))

    def run_fields(self, path, two_pass):
        return self.env.field_rows(path, FIELDS, two_pass=two_pass)

    def assert_marks(self, path, messages, check):
        marks, cycles = model(messages, window=1, bits=32)
        for two_pass in (False, True):
            rows = self.run_fields(path, two_pass)
            how = "-2" if two_pass else "one pass"
            for frame, row in sorted(rows.items()):
                want = marks.get(frame, {})
                got = mark_of(row, "enipr")
                if not check(got == want, "%s frame %d: %s, expected %s" % (how, frame, got, want)):
                    continue
                # the expert infos sit exactly where the marks say
                check(bool(row["enipr.expert.cycle_lost"]) == ("lost" in want),
                      "%s frame %d: cycle_lost expert %s" % (how, frame, row["enipr.expert.cycle_lost"]))
                check(bool(row["enipr.expert.cycle_duplicate"]) == ("duplicate" in want),
                      "%s frame %d: cycle_duplicate expert %s" % (how, frame, row["enipr.expert.cycle_duplicate"]))
        return marks, cycles

    def assert_report(self, path, cycles, check):
        for two_pass in (False, True):
            out = self.env.tshark(["-r", path, "-q", "-z", "enipr,cycles"] + (["-2"] if two_pass else [])).stdout
            got = parse_report(out)
            check(len(got) == len(cycles), "-z enipr,cycles lists %d cycles, expected %d" % (len(got), len(cycles)))
            for c, g in zip(cycles, got):
                connection, address, port = c["stream"]["key"]
                name = "Connection ID 0x%08x, sender %s:%d" % (connection, ".".join(map(str, address)), port)
                check(g["name"] == name, "cycle %d is %r, expected %r" % (c["number"], g["name"], name))
                want = figures(c)
                check(g["figures"] == want, "cycle %d figures %s, expected %s" % (c["number"], g["figures"], want))
        self.assert_statistics_tree(path, cycles, check)

    def assert_statistics_tree(self, path, cycles, check):
        """The statistics tree (Statistics menu; tshark -2 -z enipr.cycles,tree) holds the model's
        figures, row by row (the jitter's standard deviation rounded to the ns)."""
        out = self.env.tshark(["-2", "-r", path, "-q", "-z", "enipr.cycles,tree"]).stdout
        have = {}
        for line in out.splitlines():
            m = re.match(r"^\s*Cycle (\d+) (\S.*?)\s{2,}(\d+)\s", line)
            if m:
                have[(int(m.group(1)), m.group(2))] = int(m.group(3))
        want = {}
        for c in cycles:
            f, n = figures(c), c["number"]
            unit, scale = tree_unit(max([f["nominal"]] + list(f["period"] or ())))
            want[(n, "messages")] = f["messages"]
            want[(n, "nominal period (%s)" % unit)] = tree_value(f["nominal"], scale)
            for name, value in zip(("min", "median", "p99", "max"), f["period"] or ()):
                want[(n, "period %s (%s)" % (name, unit))] = tree_value(value, scale)
            want[(n, "jitter std dev (%s)" % unit)] = tree_value(int(float(f["jitter sd"]) + 0.5), scale)
            want[(n, "messages lost")] = f["lost"]
            want[(n, "duplicates")] = f["duplicates"]
        differ = sorted(k for k in set(have) | set(want) if k not in have or k not in want or
                        abs(have[k] - want[k]) > (1 if k[1].startswith("jitter") else 0))  # sd: rounding
        check(not differ, "-2 -z enipr.cycles,tree: %d rows as the model computes%s" % (
            len(want), "" if not differ else " (differ: %s)" % [(k, have.get(k), want.get(k)) for k in differ[:5]]))

    def test_generated_capture_to_the_nanosecond(self):
        messages = io_messages(read_pcap(self.generated))
        with self.checks() as check:
            marks, cycles = self.assert_marks(self.generated, messages, check)
            # the capture holds what the test means to check
            check(sum(1 for m in marks.values() if m.get("lost") == 1) == 2, "two single drops")
            check(sum(1 for m in marks.values() if m.get("lost") == 3) == 1, "one drop of three")
            check(sum(1 for m in marks.values() if "duplicate" in m) == 3, "three repeats")
            check(len(cycles) == 4, "four streams (the same ID from two senders is two)")
            self.assert_report(self.generated, cycles, check)

    def test_expert_infos_only_at_faults(self):
        """A clean capture (no drop, no repeat, a wrap) raises no cycle expert info."""
        ms = 10**6
        packets = [(10**9 + i * 2 * ms + (i * 7919) % 50_000, udp_frame(io_payload(0x44, (2**32 - 3 + i) & 0xFFFFFFFF),
                                                                        (10, 0, 0, 9)))
                   for i in range(40)]
        path = self.env.add_file("io_clean.pcap", pcap_ns(packets))
        with self.checks() as check:
            for two_pass in ([], ["-2"]):
                out = self.env.tshark(["-r", path, "-q", "-z", "expert"] + two_pass).stdout
                check("cycle" not in out.lower() and "lost" not in out.lower(),
                      "expert infos on a clean capture %s:\n%s" % (two_pass, out))
            marks, _cycles = self.assert_marks(path, io_messages(read_pcap(path)), check)
            check(all("lost" not in m and "duplicate" not in m for m in marks.values()), "model: clean")

    def test_corpus_capture(self):
        path = os.path.abspath(os.path.join(ARGS.source_dir, "..", "shared", "corpus", "enip", "enip_cip_example.pcap"))
        if not os.path.exists(path):
            self.skipTest("no ../shared/corpus/enip/enip_cip_example.pcap")
        messages = io_messages(read_pcap(path))
        staged = self.env.readable(path)
        with self.checks() as check:
            check(len(messages) == 398, "%d I/O packets in the capture" % len(messages))
            _marks, cycles = self.assert_marks(staged, messages, check)
            check(len(cycles) == 24, "%d cycles, expected one per connection (24)" % len(cycles))
            self.assert_report(staged, cycles, check)


def follows_the_model(env, check, capture, protocol, marks, cycles, names=None, duplicates=True):
    """In one pass and -2: each frame's marks and cycle expert infos are the model's, and
    -z P,cycles lists the model's cycles with its figures (and `names`, when given;
    duplicates=False: no sequence count, the report counts none)."""
    for two_pass in (False, True):
        how = "-2" if two_pass else "one pass"
        rows = env.field_rows(capture, ["frame.number"] + mark_fields(protocol), two_pass=two_pass)
        for frame, row in sorted(rows.items()):
            got, want = mark_of(row, protocol), marks.get(frame, {})
            check(got == want, "%s frame %d: %s, expected %s" % (how, frame, got, want))
            for expert, key in (("cycle_lost", "lost"), ("cycle_duplicate", "duplicate")):
                shown = row["%s.expert.%s" % (protocol, expert)]
                check(bool(shown) == (key in want), "%s frame %d: %s expert %s" % (how, frame, expert, shown))
        got = parse_report(env.tshark(["-r", capture, "-q", "-z", protocol + ",cycles"] +
                                      (["-2"] if two_pass else [])).stdout)
        if names is not None:
            check([g["name"] for g in got] == names,
                  "%s -z %s,cycles names %s, expected %s" % (how, protocol, [g["name"] for g in got], names))
        want = [figures(c) for c in cycles]
        for f in want if not duplicates else ():
            del f["duplicates"]
        check([g["figures"] for g in got] == want,
              "%s -z %s,cycles: %s, expected %s" % (how, protocol, [g["figures"] for g in got], want))


# --- a count wrapping at the sample rate ----------------------------------------------

SAMPLE_RATE = 4000  # tests/rules/cycles_wrap.xml: wrap="4000"


def sample_frame(stream, count, size=2):
    """A frame of tests/rules/cycles_wrap.xml: stream, the count in `size` bytes, a sample."""
    return (bytes([0x01, 0x0C, 0xCD, 0x04, 0, 1, 0x02, 0, 0, 0, 0, 1]) + struct.pack(">HHB", 0x88B5, stream, size) +
            count.to_bytes(size, "big") + struct.pack(">i", -count))


def sample_capture(seed=4000):
    """Stream 0x4000 at 250 us from count 3980 through the wrap 3999 -> 0: the sample at the
    wrap (3999) dropped, later three in a row, one sent twice, one count out of range (4095:
    no count); stream 0x4001 at 208.333 us from mid-capture, its count in 4 bytes."""
    rng = random.Random(seed)
    packets = []
    for k in range(80):
        count = (3980 + k) % SAMPLE_RATE
        t = 10**9 + k * 250_000 + rng.randint(-3000, 3000)
        if count == 3999 or k in (50, 51, 52):
            continue
        packets.append((t, sample_frame(0x4000, 4095 if k == 60 else count)))
        if k == 40:
            packets.append((t + 10_123, sample_frame(0x4000, count)))
    for k in range(60):
        t = 10**9 + 7_000_000 + k * 208_333 + rng.randint(-2000, 2000)
        packets.append((t, sample_frame(0x4001, (3990 + k) % SAMPLE_RATE, size=4)))
    packets.sort(key=lambda p: p[0])
    return packets


class CountWrappingAtTheSampleRate(TsharkTestCase, unittest.TestCase):
    """wrap="4000": the count's step from 3999 to 0 is the next sample, a sample dropped at
    the wrap is one lost, a count of 4000 or more is no count (timed, nothing lost); a count
    whose length comes from a field is counted (it once had no width and was never)."""

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "cycles_wrap.xml"), "samples")
        cls.packets = sample_capture()
        cls.capture = cls.env.add_file("samples.pcap", pcap_ns(cls.packets))

    def test_marks_and_report_follow_the_model(self):
        messages = []
        for frame, (t, data) in enumerate(self.packets, 1):
            size = data[16]
            messages.append((frame, t, struct.unpack(">H", data[14:16])[0],
                             int.from_bytes(data[17:17 + size], "big")))
        marks, cycles = model(messages, window=8, bits=64, wrap=SAMPLE_RATE)
        with self.checks() as check:
            check(sorted(m["lost"] for m in marks.values() if "lost" in m) == [1, 3],
                  "the model: one lost at the wrap, three in a row")
            check(sum(1 for m in marks.values() if "duplicate" in m) == 1, "the model: one duplicate")
            check(len(cycles) == 2, "the model: two cycles")
            follows_the_model(self.env, check, self.capture, "samples", marks, cycles)


# --- streams named by text and addresses ----------------------------------------------

SOURCE = bytes([7, 0, 168, 192])  # 192.168.0.7, little-endian


def named_frame(name, station, count):
    """A frame of tests/rules/named_streams.xml."""
    return (b"\x01\x0c\xcd\x04\x00\x02" + station + b"\x88\xb6" + bytes([len(name)]) + name + station + SOURCE +
            struct.pack(">Hh", count & 0xFFFF, -1))


NAMED_STREAMS = [
    # name, station, period, start, messages, first count, dropped, repeated
    (b"PUMP-1", b"\x02\x00\x00\x00\x00\x01", 1_000_000, 0, 40, 65530, {12}, {20}),
    (b"PUMP-2", b"\x02\x00\x00\x00\x00\x01", 2_000_000, 300_000, 30, 0, set(), set()),
    (b"PUMP-1", b"\x02\x00\x00\x00\x00\x02", 1_000_000, 500_000, 40, 9, {30, 31}, set()),  # another station
    (b"PUMP-10", b"\x02\x00\x00\x00\x00\x01", 4_000_000, 100_000, 15, 100, set(), set()),  # a longer name
    (b"", b"\x02\x00\x00\x00\x00\x03", 3_000_000, 0, 20, 5, set(), set()),  # no name at all
    (b"TANK\x07", b"\x02\x00\x00\x00\x00\x01", 2_500_000, 0, 20, 0, set(), set()),  # a control character
    (b"IED1LD0/LLN0$GO$gcb1", b"\x02\x00\x00\x00\x00\x04", 5_000_000, 0, 10, 0, set(), set()),  # GOOSE's '/'
]


def named_capture(seed=61850):
    rng = random.Random(seed)
    packets = []
    for name, station, period, start, count, first, dropped, repeated in NAMED_STREAMS:
        for k in range(count):
            if k in dropped:
                continue
            t = 10**9 + start + k * period + rng.randint(-5000, 5000)
            frame = named_frame(name, station, first + k)
            packets.append((t, frame))
            if k in repeated:
                packets.append((t + 7_777, frame))
    packets.sort(key=lambda p: p[0])
    return packets


def wireshark_text(name):
    """A name as Wireshark's format_text() shows it: printable ASCII as is, a control
    character by its C escape."""
    escapes = {7: "\\a", 8: "\\b", 9: "\\t", 10: "\\n", 11: "\\v", 12: "\\f", 13: "\\r"}
    return "".join(chr(b) if 32 <= b < 127 else escapes.get(b, "\\%03o" % b) for b in name)


class StreamsNamedByText(TsharkTestCase, unittest.TestCase):
    """Signature fields of text and addresses are compared byte for byte ("PUMP-1" is not
    "PUMP-10", nor "PUMP-1" from another station) and named in -z as their items show
    them (a little-endian IPv4 address too); marks, losses and duplicates follow the model
    in one pass and -2."""

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "named_streams.xml"), "named")
        cls.packets = named_capture()
        cls.capture = cls.env.add_file("named.pcap", pcap_ns(cls.packets))

    def test_streams_by_their_bytes(self):
        messages = []
        for frame, (t, data) in enumerate(self.packets, 1):
            size = data[14]
            name, station = data[15:15 + size], data[15 + size:21 + size]
            messages.append((frame, t, (name, station), struct.unpack(">H", data[25 + size:27 + size])[0]))
        marks, cycles = model(messages, window=8, bits=16)
        with self.checks() as check:
            check(len(cycles) == len(NAMED_STREAMS), "the model: a cycle per stream, %d" % len(cycles))
            names = ['Name "%s", Station %s, Source 192.168.0.7' % (wireshark_text(c["stream"]["key"][0]),
                                                                     ":".join("%02x" % b for b in c["stream"]["key"][1]))
                     for c in cycles]
            follows_the_model(self.env, check, self.capture, "named", marks, cycles, names)
            # the statistics tree names each cycle as -z does; a top-level name would show only what
            # follows its last '/', so each is shown as U+2215
            tree = self.env.tshark(["-2", "-r", self.capture, "-q", "-z", "named.cycles,tree"]).stdout
            shown = [m.group(1) for m in re.finditer(r"^Cycle \d+: (.*?)\s{2,}\d+\s", tree, re.M)]
            check(shown == [n.replace("/", "\u2215") for n in names],
                  "-2 -z named.cycles,tree names the cycles as -z named,cycles: %s" % shown)

# --- a 3-bit count, sometimes not sent --------------------------------------------------

SMALL_COUNT_RULES = """<root name="Small count" abbreviation="SMALLC" ethertype="0x88b5">
  <cycles>
    <signature field="node[@name='Stream']"/>
    <sequence field="node[@name='Count']" bits="3"/>
  </cycles>
  <node name="Stream" length="1byte" displaytype="numberdec"/>
  <node name="Has count" length="1byte" displaytype="numberdec"/>
  <node name="Count" length="1byte" displaytype="numberdec" if="../node[@name='Has count']" in="1"/>
</root>
"""


def small_count_capture():
    """Stream 1 every ms (±3 us): its count (3 bits) advancing by one, then by 4 (half the
    range: three lost), by 5 (past half: the count went back), and across messages sent
    without their count (SERCOS III's 'cycle count valid' clear), after which the next
    count is the stream's first again; stream 2 from mid-capture, one message dropped."""
    counts = [0, 1, 2, 3, 7, 0, 1, None, 3, 4, 5, 6, None, None, 1, 2, 3, 0, 1, 2, 3, 4, 5]
    packets = []
    for i, count in enumerate(counts):
        t = 1_000_000_000 + i * 1_000_000 + (i * 7919) % 6001 - 3000
        body = bytes([1, 0]) if count is None else bytes([1, 1, count])
        packets.append((t, b"\x01\x0c\xcd\x04\0\x01\x02\0\0\0\0\x01\x88\xb5" + body + bytes(46 - len(body))))
    for i in range(12):
        if i != 7:
            t = 1_000_400_000 + (10 + i) * 1_000_000
            packets.append((t, b"\x01\x0c\xcd\x04\0\x01\x02\0\0\0\0\x01\x88\xb5" + bytes([2, 1, i % 8]) + bytes(43)))
    packets.sort(key=lambda p: p[0])
    return packets


class TestSmallCount(TsharkTestCase, unittest.TestCase):
    """A loss of half the count's range is a loss; a message without its count makes the
    next count the stream's first (nothing counted lost across it, no false alarm)."""

    @classmethod
    def prepare(cls):
        cls.install_text("small_count.xml", SMALL_COUNT_RULES, "smallc")
        cls.packets = small_count_capture()
        cls.capture = cls.env.add_file("small_count.pcap", pcap_ns(cls.packets))

    def test_losses_by_a_small_count(self):
        messages = [(frame, t, data[14], data[16] if data[15] else None)
                    for frame, (t, data) in enumerate(self.packets, 1)]
        marks, cycles = model(messages, window=8, bits=3)
        lost = {frame: m["lost"] for frame, m in marks.items() if "lost" in m}
        with self.checks() as check:
            # the model itself: 3 lost before count 7 (3 -> 7), 1 in stream 2; nothing after
            # the messages without a count, nor at 6 -> 1 across them
            check(sorted(lost.values()) == [1, 3], "the model counts 3 and 1 lost: %s" % lost)
            follows_the_model(self.env, check, self.capture, "smallc", marks, cycles)


# --- one stream per side of each connection ---------------------------------------------

CONNECTION_RULES = """<root name="Telecontrol {kind}" abbreviation="{abbreviation}" byteorder="little">
  <hook table="udp.port" value="{port}"/>
  <cycles window="4" sender="{sender}">
    <signature field="node[@name='Kind']"/>
    <sequence field="node[@name='Send number']" bits="15"/>
  </cycles>
  <node name="Kind" length="1byte" displaytype="numberdec"/>
  <node name="Send number" length="2byte" displaytype="numberdec"/>
</root>
"""
SERVER = (10, 0, 0, 100)
CLIENTS = (((10, 0, 0, 1), 50001), ((10, 0, 0, 2), 50002))


def connection_capture(server_port):
    """A server sending to two clients, each connection counting its own send numbers from
    0 every 10 ms (+-50 us), the second client's from 30 ms on and without its number 6
    (one lost); each client answering with kind 2, counted from 0 too (and without its 6)."""
    rng = random.Random(104)
    packets = []
    for c, (address, port) in enumerate(CLIENTS):
        for i in range(16 - 3 * c):
            if c == 1 and i == 6:
                continue
            t = 10**9 + (i + 3 * c) * 10_000_000 + c * 1_000_000 + rng.randint(-50_000, 50_000)
            packets.append((t, udp_frame(struct.pack("<BH", 1, i), SERVER, address, server_port, port)))
            packets.append((t + 200_000, udp_frame(struct.pack("<BH", 2, i), address, SERVER, port, server_port)))
    packets.sort(key=lambda p: p[0])
    return packets


def connection_messages(packets, by_connection):
    """(frame, time ns, stream key, send number) of each message, the key the sender's
    address and port, and with by_connection the receiver's too."""
    out = []
    for frame, (t, f) in enumerate(packets, 1):
        sport, dport = struct.unpack("!HH", f[34:38])
        key = (f[42], bytes(f[26:30]), sport) + ((bytes(f[30:34]), dport) if by_connection else ())
        out.append((frame, t, key, struct.unpack("<H", f[43:45])[0]))
    return out


class TestStreamsPerConnection(TsharkTestCase, unittest.TestCase):
    """sender="connection": a server's messages to each client are a stream of their own,
    so two connections counting from 0 are two clean cycles (one loss, where it is); with
    sender="yes" the same server's two counts are one stream, its count jumping back and
    forth (losses that are not there)."""

    @classmethod
    def prepare(cls):
        cls.packets, cls.captures = {}, {}
        for sender, abbreviation, port in (("connection", "CONN", 2404), ("yes", "CSND", 2405)):
            cls.install_text(abbreviation.lower() + ".xml", CONNECTION_RULES.format(
                kind=sender, abbreviation=abbreviation, sender=sender, port=port), abbreviation.lower())
            cls.packets[sender] = connection_capture(port)
            cls.captures[sender] = cls.env.add_file("two_connections_%d.pcap" % port, pcap_ns(cls.packets[sender]))

    def test_each_side_of_each_connection_is_a_stream(self):
        marks, cycles = model(connection_messages(self.packets["connection"], True), window=4, bits=15)
        with self.checks() as check:
            lost = {f: m["lost"] for f, m in marks.items() if "lost" in m}
            check(list(lost.values()) == [1, 1] and len(cycles) == 4 and
                  not any("duplicate" in m for m in marks.values()),
                  "the model: four cycles, one lost each way, no repeats: %s, %d cycles" % (lost, len(cycles)))
            names = ["Kind %d, sender %s:%d, receiver %s:%d" % (c["stream"]["key"][0],
                                                                 ".".join(map(str, c["stream"]["key"][1])),
                                                                 c["stream"]["key"][2],
                                                                 ".".join(map(str, c["stream"]["key"][3])),
                                                                 c["stream"]["key"][4]) for c in cycles]
            follows_the_model(self.env, check, self.captures["connection"], "conn", marks, cycles, names=names)

    def test_by_sender_alone_the_server_repeats_itself(self):
        marks, cycles = model(connection_messages(self.packets["yes"], False), window=4, bits=15)
        with self.checks() as check:
            lost = [m["lost"] for m in marks.values() if "lost" in m]
            check(len(lost) > 1, "the model sees the server's two counts as losses: %s" % lost)
            follows_the_model(self.env, check, self.captures["yes"], "csnd", marks, cycles)


# --- periods of seconds and minutes -----------------------------------------------------

LONG_PERIOD_RULES = """<root name="Heartbeats" abbreviation="BEAT" ethertype="0x88b5">
  <cycles lost="period">
    <signature field="node[@name='Stream']"/>
  </cycles>
  <node name="Stream" length="1byte" displaytype="numberdec"/>
</root>
"""


def long_period_capture():
    """Stream 1 every 4.3 s (just above 2^32 ns, +-5 ms), one message dropped (a gap of
    8.6 s: one lost); stream 2 a heartbeat every 60 s (+-1 s), one dropped; stream 3 every
    5 ms, then silent for 10 s (longer than 4.29 s, more than 16 periods: a pause)."""
    rng = random.Random(4300)
    packets = []
    head = b"\x01\x0c\xcd\x04\0\x01\x02\0\0\0\0\x01\x88\xb5"
    for stream, period, jitter, count, drop in ((1, 4_300_000_000, 5_000_000, 14, {11}),
                                                (2, 60 * 10**9, 10**9, 12, {10})):
        for i in range(count):
            if i not in drop:
                packets.append((10**9 + i * period + rng.randint(-jitter, jitter), head + bytes([stream]) + bytes(45)))
    for i in range(20):
        t = 10**9 + i * 5_000_000 + (10 * 10**9 if i >= 12 else 0) + rng.randint(-20_000, 20_000)
        packets.append((t, head + bytes([3]) + bytes(45)))
    packets.sort(key=lambda p: p[0])
    return packets


class TestLongPeriods(TsharkTestCase, unittest.TestCase):
    """A period longer than 2^32 ns (4.29 s) is a period: a stream every 4.3 s or every
    minute becomes a cycle, its figures are in nanoseconds to the end, a whole missing
    period is one lost message, and a 10 s silence in a 5 ms cycle is a pause."""

    @classmethod
    def prepare(cls):
        cls.install_text("heartbeats.xml", LONG_PERIOD_RULES, "beat")
        cls.packets = long_period_capture()
        cls.capture = cls.env.add_file("heartbeats.pcap", pcap_ns(cls.packets))

    def test_periods_of_seconds_and_minutes(self):
        messages = [(frame, t, data[14], None) for frame, (t, data) in enumerate(self.packets, 1)]
        marks, cycles = model(messages, window=8, bits=0, lost_by_period=True)
        with self.checks() as check:
            # the model itself: three cycles, one lost in each of streams 1 and 2, and their
            # longest period in ns beyond 32 bits
            lost = sorted(m["lost"] for m in marks.values() if "lost" in m)
            check(len(cycles) == 3 and lost == [1, 1], "the model: 3 cycles, 1 lost twice (%d, %s)" % (
                len(cycles), lost))
            longest = {figures(c)["period"][3] for c in cycles}
            check(any(p > 2**32 for p in longest), "the model: periods beyond 2^32 ns (%s)" % longest)
            follows_the_model(self.env, check, self.capture, "beat", marks, cycles, duplicates=False)
            self.assert_tree_units(cycles, check)

    def assert_tree_units(self, cycles, check):
        """The statistics tree's rows hold a gint: a cycle's times are in ns while its longest
        fits (2^31 - 1), else in the first of us, ms, s that holds it, rounded; the rows say which."""
        out = self.env.tshark(["-2", "-r", self.capture, "-q", "-z", "beat.cycles,tree"]).stdout
        have = {(int(m.group(1)), m.group(2)): int(m.group(3))
                for m in re.finditer(r"^\s*Cycle (\d+) (\S.*?)\s{2,}(\d+)\s", out, re.M)}
        want = {}
        for c in cycles:
            f, n = figures(c), c["number"]
            unit, scale = tree_unit(max(f["nominal"], f["period"][3]))
            want[(n, "messages")] = f["messages"]
            want[(n, "messages lost")] = f["lost"]
            want[(n, "nominal period (%s)" % unit)] = tree_value(f["nominal"], scale)
            for name, value in zip(("min", "median", "p99", "max"), f["period"]):
                want[(n, "period %s (%s)" % (name, unit))] = tree_value(value, scale)
            want[(n, "jitter std dev (%s)" % unit)] = tree_value(int(float(f["jitter sd"]) + 0.5), scale)
        units = sorted({k[1].split("(")[1] for k in want if "(" in k[1]})
        check(units == ["ns)", "us)"], "the model: rows in ns and in us (%s)" % units)
        check(have == want, "-2 -z beat.cycles,tree: %s, expected %s" % (
            sorted(set(have.items()) ^ set(want.items())), len(want)))


# --- the most messages lost in one gap --------------------------------------------------

MOST_LOST_RULES = """<root name="Restarting {kind}" abbreviation="{abbreviation}" ethertype="{ethertype:#06x}">
  <cycles {losses} maxlost="{most}">
    <signature field="node[@name='Stream']"/>
    {sequence}
  </cycles>
  <node name="Stream" length="1byte" displaytype="numberdec"/>
  <node name="Count" length="2byte" displaytype="numberdec"/>
</root>
"""

MOST_LOST = 10


def restarting_capture(ethertype):
    """Stream 1 every ms (+-3 us), its 16-bit count jumping by 11 (10 lost: maxlost, still
    counted), by 12 (11 lost: more, a restart), to 20000 (a device reset); stream 2 every
    2 ms, silent for 11 periods (10 lost) and then for 12 (11 lost: a pause by the period)."""
    rng = random.Random(1011)
    head = b"\x01\x0c\xcd\x04\0\x01\x02\0\0\0\0\x01" + struct.pack(">H", ethertype)
    counts = list(range(12)) + list(range(22, 34)) + list(range(45, 57)) + list(range(20000, 20012))
    packets = []
    for i, count in enumerate(counts):
        t = 10**9 + i * 1_000_000 + rng.randint(-3_000, 3_000)
        packets.append((t, head + bytes([1]) + struct.pack(">H", count) + bytes(43)))
    slot = 0
    for i in range(36):
        slot += 1 + (10 if i == 12 else 11 if i == 24 else 0)
        t = 10**9 + 500_000 + slot * 2_000_000 + rng.randint(-3_000, 3_000)
        packets.append((t, head + bytes([2]) + struct.pack(">H", i) + bytes(43)))
    packets.sort(key=lambda p: p[0])
    return packets


class TestMostLostInAGap(TsharkTestCase, unittest.TestCase):
    """maxlost="10": a gap of up to 10 messages lost is counted, a longer one is a restart
    of the count (a device reset) or a pause of the stream, with nothing counted lost and no
    expert info: by the sequence count and by the period (lost="period")."""

    # each kind its own ethertype: one protocol per table entry
    KINDS = {"restart": ("RESTART", 0x88b5, "", '<sequence field="node[@name=\'Count\']"/>'),
             "pause": ("PAUSE", 0x88b6, 'lost="period"', "")}

    @classmethod
    def prepare(cls):
        cls.packets, cls.captures = {}, {}
        for kind, (abbreviation, ethertype, losses, sequence) in cls.KINDS.items():
            cls.install_text(abbreviation.lower() + ".xml", MOST_LOST_RULES.format(
                kind=kind, abbreviation=abbreviation, ethertype=ethertype, losses=losses, most=MOST_LOST,
                sequence=sequence), abbreviation.lower())
            cls.packets[kind] = restarting_capture(ethertype)
            cls.captures[kind] = cls.env.add_file(kind + ".pcap", pcap_ns(cls.packets[kind]))

    def test_by_the_sequence_count(self):
        messages = [(frame, t, data[14], struct.unpack(">H", data[15:17])[0])
                    for frame, (t, data) in enumerate(self.packets["restart"], 1)]
        marks, cycles = model(messages, window=8, bits=16, max_lost=MOST_LOST)
        with self.checks() as check:
            # the model itself: 10 lost once in stream 1; stream 2's count has no gap
            lost = sorted(m["lost"] for m in marks.values() if "lost" in m)
            check(lost == [MOST_LOST], "the model: 10 lost once (%s)" % lost)
            unbounded = sorted(m["lost"] for m in model(messages, window=8, bits=16)[0].values() if "lost" in m)
            check(unbounded == [10, 11, 19943], "the model without maxlost: %s" % unbounded)
            follows_the_model(self.env, check, self.captures["restart"], "restart", marks, cycles)

    def test_by_the_period(self):
        messages = [(frame, t, data[14], None) for frame, (t, data) in enumerate(self.packets["pause"], 1)]
        marks, cycles = model(messages, window=8, bits=0, lost_by_period=True, max_lost=MOST_LOST)
        with self.checks() as check:
            # the model itself: stream 2's 11-period gap is 10 lost, its 12-period one a pause;
            # stream 1 loses nothing by its period
            lost = sorted(m["lost"] for m in marks.values() if "lost" in m)
            check(lost == [MOST_LOST], "the model: 10 lost once (%s)" % lost)
            unbounded = sorted(m["lost"] for m in model(messages, window=8, bits=0, lost_by_period=True)[0].values()
                               if "lost" in m)
            check(unbounded == [10, 11], "the model without maxlost: %s" % unbounded)
            follows_the_model(self.env, check, self.captures["pause"], "pause", marks, cycles, duplicates=False)


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

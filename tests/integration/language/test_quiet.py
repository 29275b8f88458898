#!/usr/bin/env python3
"""Quiet nodes: a walk nobody sees steps over quiet nodes, and nothing shown changes.

With no tree and no tap listener (tshark's summary lines), the EtherCAT and
EtherNet/IP plugins step over the nodes that feed nothing (generator/quiet.cpp)
and the pairing does its first-pass work only. A tap listener (here `-z
io,stat,0`, which shows nothing per packet) turns that off, so the packet lines
of the two runs must be the same, byte for byte: on generated EtherCAT frames
of every command with malformed variants (truncated frames, lengths that lie)
and bytes after the datagrams inside the header's Length (zeros: padding, no
expert info; or not), on the shipped samples, and on the corpus captures when ../shared/corpus is
there; in one pass and with -2. The generated frames are also shown with an
Expert column: a quiet walk raises its expert infos without their text (the
pairing's too), so the same frames must show a severity there. (Which one, when
a frame has several, is Wireshark's business: without a tree the last one
raised, with a tree the highest.)

The same comparison runs on every rule file of tests/rules/ and rules/ (each plugin alone,
as the only plugin tshark loads), on captures that exercise it: the messages the rule
file's own test builds (or, for tests/rules/quiet_bits.xml, bit groups with whole-byte
members that feed nothing, with random values), each also cut short at up to 24 places.
A rule file without a capture here fails the test.

    test_quiet.py --dissgen build/bin/dissgen --source-dir .
"""
import glob
import os
import random
import struct
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import eplgen  # noqa: E402
import pcapgen  # noqa: E402
import pngen  # noqa: E402
from tshark_env import TsharkEnv, run_unittests  # noqa: E402

ARGS = None


def corpus_captures(kind):
    folder = os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus", kind)
    if not os.path.isdir(folder):
        return []
    return [os.path.join(folder, f) for f in sorted(os.listdir(folder)) if f.endswith((".pcap", ".pcapng"))]


def padded_frames():
    """A 13-byte datagram inside a header Length of 14 or 28 bytes: the rest zeros (padding,
    no expert info), or with a non-zero byte (the unused expert info, a warning), or that
    short on the wire inside the zeros (not known to be zero: the datagrams are past the
    end, an error), or cut there by the capture only (not malformed: no expert info).
    -> [(frame, severity in the Expert column in one pass)], a second apart
    from the rest of the capture and from one another (nothing pairs with them)."""
    frames = []

    def frame(padding, severity, **kw):
        d = pcapgen.Datagram(cmd=4, idx=0xA0 + len(frames), adp=0x1001, ado=0x0130, data=b"\x01", wkc=1)
        frames.append((pcapgen.Frame([d], padding=bytes(padding), ts=1704070000.0 + len(frames), **kw), severity))

    for declared in (14, 28):
        size = declared - 13
        frame(bytes(size), "")
        for k in sorted({0, size - 1}):
            padding = bytearray(size)
            padding[k] = 0x80
            frame(padding, "Warning")
        frame(bytes(size), "Error", truncate_to=2 + 13 + size // 2, truncate_mode="short", pad=False)
        frame(bytes(size), "", truncate_to=2 + 13 + size // 2, truncate_mode="snap", pad=False)
    return frames


class QuietWalk(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.env = TsharkEnv()
        for rules in ("ethercat.xml", "enip.xml"):
            cls.env.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "rules", rules))
        frames = pcapgen.random_frames(14, 3000, max_datagrams=12, m_on_last=40, truncated=80, other_types=20,
                                       odd_lengths=40)
        frames += [f for f, _ in padded_frames()]
        cls.generated = cls.env.add_file("quiet.pcap", pcapgen.pcap_bytes(frames))

    @classmethod
    def tearDownClass(cls):
        cls.env.cleanup()

    def packet_lines(self, capture, extra):
        """The summary lines without and with a tap listener; both runs must agree."""
        cap = self.env.readable(capture)
        quiet = self.env.tshark(["-r", cap] + extra).stdout.splitlines()
        tapped = self.env.tshark(["-r", cap, "-z", "io,stat,0"] + extra).stdout.splitlines()
        self.assertGreater(len(quiet), 0, capture)
        self.assertGreater(len(tapped), len(quiet), "the io,stat table follows the packet lines")
        following = tapped[len(quiet):len(quiet) + 2]
        self.assertTrue(following[0] == "" and set(following[1]) == {"="}, following)  # the io,stat table
        return quiet, tapped[:len(quiet)]

    def check(self, capture):
        for extra in ([], ["-2"]):
            quiet, tapped = self.packet_lines(capture, extra)
            for number, (a, b) in enumerate(zip(quiet, tapped), 1):
                self.assertEqual(a, b, "%s%s: packet line %d differs when nobody sees the tree"
                                 % (os.path.basename(capture), " -2" if extra else "", number))

    def test_generated_frames_with_malformed_ones(self):
        self.check(self.generated)
        lines = self.env.tshark(["-r", self.env.readable(self.generated)]).stdout
        self.assertIn("ECATR", lines)

    def test_expert_column(self):
        columns = ["-o", 'gui.column.format:"No.","%m","Expert","%a","Info","%i"']
        for extra in ([], ["-2"]):
            quiet, tapped = self.packet_lines(self.generated, columns + extra)
            with_experts = [{line.split()[0] for line in lines if line.split()[1] in ("Error", "Warning", "Note", "Chat")}
                            for lines in (quiet, tapped)]
            self.assertGreater(len(with_experts[1]), 100, "the malformed frames raise expert infos")
            self.assertEqual(with_experts[0], with_experts[1], "frames with a severity in the Expert column%s"
                             % (" (-2)" if extra else ""))
        # The padded frames at the end (one pass: with -2 each also has no response). A frame
        # that proves earlier requests lost (ecatr.no_response_to: the first one a second
        # after the rest) carries that warning too.
        severities = [s for _, s in padded_frames()]
        links = self.env.tshark(["-r", self.env.readable(self.generated), "-T", "fields",
                                 "-e", "ecatr.no_response_to"]).stdout.splitlines()[-len(severities):]
        severities = [s or ("Warning" if link else "") for s, link in zip(severities, links)]
        for lines in self.packet_lines(self.generated, columns):
            shown = [line.split()[1] if line.split()[1] in ("Error", "Warning", "Note", "Chat") else ""
                     for line in lines[-len(severities):]]
            self.assertEqual(shown, severities, "Expert column of the padded frames")

    def test_generated_enip_messages(self):
        cap = self.env.add_file("enip.pcap", pcap(with_cuts(enip_frames(), cut_frames=len(enip_frames()))))
        self.check(cap)
        self.assertIn("ENIPR", self.env.tshark(["-r", cap]).stdout)

    def test_samples(self):
        samples = os.path.join(os.path.abspath(ARGS.source_dir), "samples")
        for name in sorted(os.listdir(samples)):
            if name.endswith((".pcap", ".pcapng")):
                with self.subTest(capture=name):
                    self.check(os.path.join(samples, name))

    def test_corpus(self):
        captures = corpus_captures("ethercat") + corpus_captures("enip")
        if not captures:
            self.skipTest("no ../shared/corpus: generated frames and samples only")
        for path in captures:
            with self.subTest(capture=os.path.basename(path)):
                self.check(path)


# --------------------------------------------------------------------------- every rule file

def eth_frame(ethertype, payload):
    f = b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01" + struct.pack("!H", ethertype) + bytes(payload)
    return f + bytes(max(0, 60 - len(f)))


def udp_frame(port, payload):
    return pcapgen.udp_ethernet_frame(bytes(payload), port)


def widths_frames():
    import test_widths as m
    return [m.frame(c.data) for c in m.cases(m.Gen(15), 40)]


def bit_fields_frames():
    import test_bit_fields as m
    return [m.frame(x.data) for x in m.messages(7, 30)]


def everything_frames():
    import test_everything as m
    g = m.Gen(2024)
    return [c.packet() for c in m.valid_cases(g, 60) + m.malformed_cases(g)]


def capture_cut_frames():
    import test_snapshot_length as m
    whole = m.message()
    return ([(whole[:c], len(whole)) for c in range(m.HEADER + 1, len(whole))] +
            [(whole[:c], c) for c in range(m.HEADER + 1, len(whole), 7)])


def cycles_wrap_frames():
    import test_rule_cycles as m
    return [(frame, len(frame)) for _t, frame in m.sample_capture()]


def named_streams_frames():
    """Its streams, then one message cut in its name, in its address and after it."""
    import test_rule_cycles as m
    whole = m.named_frame(b"PUMP-1", b"\x02\x00\x00\x00\x00\x01", 7)
    return [(frame, len(frame)) for _t, frame in m.named_capture()] + [(whole[:c], len(whole)) for c in (18, 24, 27, 31)]


def polled_cycles_frames():
    import test_polled_cycles as m
    return [(frame, len(frame)) for _t, frame in m.polled_capture()]


def layout_frames():
    import test_layout as m
    out = []
    for records, cut in m.valid_packets(random.Random(10), 60) + m.malformed_packets():
        frame = m.udp_frame(b"".join(r.encode() for r in records))
        out.append((frame if cut is None else frame[:m.UDP_HEAD + cut], len(frame)))
    return out


def typed_values_frames():
    import test_typed_values as m
    a, b = bytes(range(48)), bytes(range(100, 148))
    return [m.to_port(m.values_message()), m.to_port(bytes([3]) + m.inner_frame((10, 1, 2, 3))),
            m.to_port(bytes([4]) + b"\x01\x02\x03"),
            m.to_port(m.fragment(7, 0, False, a[:16])), m.to_port(m.fragment(7, 32, True, a[32:])),
            m.to_port(m.fragment(8, 0, False, b[:16])), m.to_port(m.fragment(7, 16, False, a[16:32])),
            m.to_port(m.piece(1, 0, True, b"abc")), m.to_port(m.piece(1, 1, False, b"def")),
            m.to_port(bytes([8, 1, 0x11, 0x22])), m.to_port(bytes([8, 2, 0x33])), m.to_port(bytes([8, 3, 0x44])),
            m.to_port(bytes([7, 1, 2, 3, 4, 5, 6])), m.from_port(bytes([2, 1, 2, 3, 4, 5, 6, 7]))]


def skip_frames():
    import test_malformed_skip as m
    return [m.frame(m.SKIP, payload) for payload in (m.GOOD, m.BAD_INSIDE, m.BAD_LENGTH)]


def ethercat_frames():
    frames = pcapgen.random_frames(21, 150, max_datagrams=6, m_on_last=4, truncated=6, other_types=2,
                                   odd_lengths=4) + pcapgen.demo_frames()
    return [pcapgen.encode_frame(f) for f in frames]


def enip_frames():
    import test_enip as m
    msgs = [m.REGISTER, m.GET_ATTR, m.GET_ATTR_ERROR, m.LIST_IDENTITY_REQ, m.LIST_IDENTITY_REPLY,
            m.LIST_SERVICES_REPLY, m.FORWARD_OPEN_REPLY,
            m.unconnected(m.cip_request(0x0E, bytes.fromhex("20012401"))),
            m.unconnected(m.unconnected_send(m.cip_request(0x0E, bytes.fromhex("20012401300700")))),
            m.unconnected(m.multiple_service([m.cip_request(0x0E, bytes.fromhex("20012401")),
                                              m.cip_request(0x01, bytes.fromhex("20022401"))]))]
    return [m.udp(50000, 44818, x) for x in msgs] + [m.udp(2222, 2222, m.IO_FRAME)]


def handoff_frames():
    import test_edges as m
    rng = random.Random(4)
    out = []
    for n in (0, 1, 46):
        inner = m.inner_frame(bytes(rng.getrandbits(8) for _ in range(n)))
        for kind in (1, 2, 3):
            tail = m.inner_frame(b"\x01\x02") if kind == 3 else b"\xbe\xef"
            out.append(udp_frame(47490, struct.pack("!BH", kind, len(inner)) + inner + tail))
    return out


def offsets_frames():
    import test_edges as m
    out = []
    for kind in m.KINDS:
        for entries, gap, shift in (([(1, b"ab"), (2, b""), (3, b"xyz")], 1, 0), ([(9, b"q")], 0, 0),
                                    ([(1, b"a"), (2, b"b")], 0, 1)):
            out.append(udp_frame(47493, m.offsets_message(kind, entries, gap, shift)[0]))
    return out


def transactions_frames():
    """tests/rules/transactions.xml: requests to the port and responses from it, paired,
    orphaned and lost (test_transactions.py's messages)."""
    import test_transactions as m
    return [m.frame(direction, transaction, unit, n)
            for n, (_ms, direction, transaction, unit) in enumerate(m.MESSAGES, 1)]


def computed_frames():
    """tests/rules/computed.xml: test_computed.py's random messages."""
    import test_computed as m
    return [m.ethernet_frame(body) for _, body in m.messages(77, 40)]


def read_transaction_frames(seed, order_seed):
    """Read transactions in flight together, then responses without their requests
    (test_request_context.py's messages)."""
    import test_request_context as m
    txns = m.transactions(seed, 30)
    paired = [m.frame(d, m.modbus(d, txns[k])) for d, k in m.schedule(txns, order_seed)]
    return paired + [m.frame("response", m.modbus("response", t)) for t in txns[:10]]


def request_context_frames():
    """tests/rules/request_context.xml: read transactions (read_transaction_frames)."""
    return read_transaction_frames(47502, 1)


def request_by_position_frames():
    """tests/rules/request_by_position.xml: batches answered by position, out of order, then
    responses without their requests (test_request_context.py's messages)."""
    import test_request_context as m
    return m.batch_frames(47506, 20)[3]


def request_context_decoded_keys_frames():
    """tests/rules/request_context_decoded_keys.xml: the same, each message behind a client name
    of its own length, so that the keys are not at fixed offsets."""
    import test_request_context as m
    txns = m.transactions(47503, 30)
    paired = [m.frame(d, m.payload(d, txns[k], m.client_name(k))) for d, k in m.schedule(txns, 2)]
    return paired + [m.frame("response", m.payload("response", t, m.client_name(k)))
                     for k, t in enumerate(txns[:10])]


def quiet_bits_frames():
    """tests/rules/quiet_bits.xml with random values: whole-byte members in the middle of groups."""
    rng = random.Random(5)
    out = []
    for _ in range(40):
        n = rng.randint(0, 4)
        header = (rng.getrandbits(4) << 12 | rng.getrandbits(8) << 4 | rng.getrandbits(4)).to_bytes(2, "big")
        body = header + struct.pack("!H", rng.choice([0, 7, 255, 256, 0xFFFF, rng.getrandbits(16)])) + bytes([n])
        for _ in range(n):
            body += rng.getrandbits(32).to_bytes(4, "little") + bytes([rng.getrandbits(8)]) + \
                struct.pack("<H", rng.getrandbits(16))
        body += rng.getrandbits(32).to_bytes(4, "big") + bytes([rng.getrandbits(8)])
        out.append(udp_frame(47494, body))
    return out


def rule_findings_frames():
    """tests/rules/findings.xml: test_rule_findings.py's replies, faulty and clean."""
    import test_rule_findings as m
    return [m.ethernet_frame(m.body(*r)) for r in m.replies(41, 40)]


def dates_guids_frames():
    """tests/rules/dates_guids_shared.xml: test_dates_guids_shared_names.py's messages of
    every kind (dates and GUIDs, each alternative sharing a filter name, computed times)."""
    import test_dates_guids_shared_names as m
    payloads = [m.times_message(), m.short_message(5, 1704067200, 500), m.long_message(7, 10**18 + 3),
                m.other_message(4, 9), m.other_message(9, 1)] + [m.clock_message(d) for d in m.CLOCK_DELTAS]
    return [m.frame(p) for p in payloads * 4]


def learned_layout_frames():
    """tests/rules/learned_layout.xml: test_learned_layout.py's mappings and process data."""
    import test_learned_layout as m
    return [m.frame(payload) for payload, _ in m.messages(random.Random(11), 120)]


def goose_frames():
    """tests/rules/goose.xml: test_goose.py's GOOSE messages (every BER length form)."""
    import test_goose as m
    return m.goose_frames(seed=13, count=60)


def entry_list_frames():
    """tests/rules/entry_list.xml: counted lists of entries that take no bytes, one too long."""
    header = b"\x02\0\0\0\0\xff\x02\0\0\0\0\x01" + struct.pack("!H", 0x88C3)
    return [header + struct.pack("<I", c) + bytes(range(8)) for c in (0, 1, 5, 20, 70000, 3)]


def learned_frames():
    """tests/rules/learned.xml: test_learned.py's configurations and data of two senders."""
    import test_learned as m
    messages = m.scripted() + m.random_messages(random.Random(10), 80)
    return [m.frame(sender, m.configure(*f) if kind == "configure" else m.data(*f)) for sender, kind, f in messages]


def learned_ranges_frames():
    """tests/rules/learned_ranges.xml: test_learned_ranges.py's windows and data, some unmapped."""
    import test_learned_ranges as m
    messages = m.scripted() + m.random_messages(random.Random(12), 80)
    return [m.frame(m.payload(kind, f)) for kind, f in messages]


def overlays_frames():
    """tests/rules/overlays.xml: test_overlays.py's messages, well-formed and malformed."""
    import test_overlays as m
    rng = random.Random(6)
    return [m.HEADER + data for _m, data in (m.message(rng) for _ in range(60))]


def message_tail_frames():
    """tests/rules/message_tail.xml: messages with bytes after them, zero or not, on the
    Ethernet type and on UDP."""
    import test_edges as m
    rng = random.Random(7)
    out = []
    for n in (0, 1, 4, 41):
        for zero in (True, False):
            rest = bytes(n) if zero else bytes(rng.getrandbits(8) | 1 for _ in range(n))
            message = bytes(rng.getrandbits(8) for _ in range(5))
            out.append(m.ethertype_frame(message + rest))
            out.append(udp_frame(47493, message + rest))
    return out


def builtin_ethertypes_frames():
    """tests/rules/builtin_ethertypes.xml: frames on POWERLINK's and SERCOS III's ethertypes."""
    ethernet = b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01"
    rng = random.Random(8)
    return [ethernet + ethertype + bytes(rng.getrandbits(8) for _ in range(n))
            for ethertype in (b"\x88\xab", b"\x88\xcd") for n in (0, 1, 46)]


def request_path_frames():
    """tests/rules/request_path.xml: both read functions, each response reading its own layout."""
    return read_transaction_frames(47507, 2)


def request_defined_frames():
    """tests/rules/request_defined.xml: coil responses with and without their requests."""
    return read_transaction_frames(47508, 3)


def no_padding_frames():
    """tests/rules/no_padding.xml: bodies longer than their word, zeros or not, on both carriers."""
    import test_edges as m
    rng = random.Random(9)
    out = []
    for extra in (0, 1, 3):
        for zero in (True, False):
            rest = bytes(extra) if zero else bytes(rng.getrandbits(8) | 1 for _ in range(extra))
            body = bytes([2 + extra]) + b"\x12\x34" + rest
            out += [udp_frame(47494, body), udp_frame(47494, body + rest),
                    m.ethertype_frame(body)[:12] + b"\x88\xb6" + body]
    return out


# Rule file (relative to the source folder) -> the captures that exercise it.
CAPTURES = {
    "tests/rules/widths.xml": widths_frames,
    "tests/rules/everything.xml": everything_frames,
    "tests/rules/layout.xml": layout_frames,
    "tests/rules/typed_values.xml": typed_values_frames,
    "tests/rules/skip.xml": skip_frames,
    "tests/rules/paper_example.xml": ethercat_frames,
    "tests/rules/handoff.xml": handoff_frames,
    "tests/rules/offsets_from.xml": offsets_frames,
    "tests/rules/quiet_bits.xml": quiet_bits_frames,
    "tests/rules/transactions.xml": transactions_frames,
    "tests/rules/overlays.xml": overlays_frames,
    "tests/rules/computed.xml": computed_frames,
    "tests/rules/request_context.xml": request_context_frames,
    "tests/rules/request_context_decoded_keys.xml": request_context_decoded_keys_frames,
    "tests/rules/request_by_position.xml": request_by_position_frames,
    "tests/rules/message_tail.xml": message_tail_frames,
    "tests/rules/builtin_ethertypes.xml": builtin_ethertypes_frames,
    "tests/rules/request_path.xml": request_path_frames,
    "tests/rules/request_defined.xml": request_defined_frames,
    "tests/rules/no_padding.xml": no_padding_frames,
    "tests/rules/findings.xml": rule_findings_frames,
    "tests/rules/dates_guids_shared.xml": dates_guids_frames,
    "tests/rules/bit_fields.xml": bit_fields_frames,
    "tests/rules/learned.xml": learned_frames,
    "tests/rules/learned_layout.xml": learned_layout_frames,
    "tests/rules/learned_ranges.xml": learned_ranges_frames,
    "tests/rules/entry_list.xml": entry_list_frames,
    "tests/rules/goose.xml": goose_frames,
    "tests/rules/capture_cut.xml": capture_cut_frames,
    "tests/rules/cycles_wrap.xml": cycles_wrap_frames,
    "tests/rules/polled_cycles.xml": polled_cycles_frames,
    "tests/rules/named_streams.xml": named_streams_frames,
    # QuietWalk: with Wireshark's own plugins, the samples and the corpus
    "rules/ethercat.xml": None,
    "rules/enip.xml": None,
    # No PROFINET sample or corpus capture yet: pngen's frames of every kind.
    "rules/profinet.xml": lambda: pngen.all_frames(random.Random(7), rounds=4, cyclic=60, alarms=20),
    # Nor of POWERLINK: eplgen's frames of every message type and ASnd service.
    "rules/powerlink.xml": lambda: eplgen.all_frames(random.Random(7), rounds=6),
}


def with_cuts(frames, places=24, cut_frames=12):
    """Each frame as it is, and the first cut_frames of them (and every tenth after) also cut
    short (the original length kept) at up to `places` places inside the message (after the
    Ethernet header, or the IPv4 and UDP headers)."""
    out = []
    for k, f in enumerate(frames):
        data, orig = f if isinstance(f, tuple) else (f, len(f))
        out.append((data, orig))
        if k < cut_frames or k % 10 == 0:
            head = 14
            if data[12:14] == b"\x08\x00" and len(data) > 14:
                head += (data[14] & 0x0F) * 4 + 8
            step = max(1, (len(data) - head) // places)
            out += [(data[:cut], orig) for cut in range(head + 1, len(data), step)]
    return out


def pcap(packets):
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i, (data, orig) in enumerate(packets):
        out.append(struct.pack("<IIII", 1704067200 + i // 1000, (i % 1000) * 1000, len(data), orig) + data)
    return b"".join(out)


class EveryRuleFile(unittest.TestCase):
    def test_every_rule_file_has_captures(self):
        src = os.path.abspath(ARGS.source_dir)
        files = {os.path.relpath(p, src) for p in glob.glob(os.path.join(src, "tests", "rules", "*.xml")) +
                 glob.glob(os.path.join(src, "rules", "*.xml"))}
        self.assertEqual(sorted(files - set(CAPTURES)), [], "rule files without captures in CAPTURES")

    def test_summary_lines_alike_with_and_without_a_tap_listener(self):
        for rules, frames in sorted(CAPTURES.items()):
            if frames is None:
                continue
            with self.subTest(rules=rules), TsharkEnv() as env:
                # This plugin alone: a rule file whose names Wireshark's own plugins take
                # (the paper's ECAT) decodes too.
                folder = os.path.join(env.home, "alone")
                epan = os.path.join(folder, env.abi, "epan")
                os.makedirs(epan)
                subprocess.run([ARGS.dissgen, "install", os.path.join(ARGS.source_dir, rules), "--dir", epan],
                               check=True, capture_output=True)
                subprocess.run(["chmod", "-R", "a+rX", env.home], check=True)
                base = env.env
                env.env = lambda: dict(base(), WIRESHARK_PLUGIN_DIR=folder)
                packets = with_cuts(frames())
                cap = env.add_file("rules.pcap", pcap(packets))
                walk = QuietWalk()
                walk.env = env
                walk.check(cap)
                proto = subprocess.run([ARGS.dissgen, "fields", os.path.join(ARGS.source_dir, rules)],
                                       capture_output=True, text=True, check=True).stdout.split("\t")[0]
                layers = env.tshark(["-r", cap, "-T", "fields", "-e", "frame.protocols"]).stdout.splitlines()
                ours = sum(1 for line in layers if proto in line.split(":"))
                self.assertGreater(ours, len(packets) // 2, "%s: the plugin decodes the captures" % rules)


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

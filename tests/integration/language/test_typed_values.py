#!/usr/bin/env python3
"""Typed values, hand-off and reassembly with real tshark: tests/rules/typed_values.xml.

UDP messages to and from port 47480 carry, by their first byte: typed values
(string, stringz, ipv4, int, float, time, a range enum), a request/response
exchange told apart by direction (with repeat="rest"), an Ethernet frame handed
to Wireshark's eth_withoutfcs, bytes for a dissector this Wireshark does not
have, and fragments reassembled across frames (by byte offset into an Ethernet
frame, out of order and with one message missing a fragment; by number into
raw bytes). Every value is checked against the bytes this script wrote, in one
pass and with -2; malformed messages give our expert infos and the tree so far.

    test_typed_values.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import struct
import sys
import unittest
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import SANITIZE, TsharkEnv, run_unittests  # noqa: E402
from test_enip import pcap, udp  # noqa: E402

ARGS = None
ENV = None
PORT = 47480
CLIENT_PORT = 50000
RULES = os.path.join("tests", "rules", "typed_values.xml")
MISSING_WARNING = "hands its bytes to the dissector \"no_such_dissector\""


def to_port(payload):
    return udp(CLIENT_PORT, PORT, payload)


def from_port(payload):
    return udp(PORT, CLIENT_PORT, payload, src=(10, 1, 1, 164), dst=(10, 1, 1, 167))


# --------------------------------------------------------------------------- messages

VALUES = dict(name="Motor", label="Größe", comment="hello", fixed=b"ab\0xyz",
              address=(192, 168, 1, 20), address_le=(10, 0, 0, 1),
              small=-5, medium=-1234, odd=-100000, large=-1234567890123, low=-3, high=5,
              real=1.5, lreal=-2.25, dc_ns=1234567890123, delay_us=2500, cycle_ms=10, uptime_s=3600,
              status=0x0015)


def values_message(v=VALUES):
    label = v["label"].encode("utf-8")
    return (bytes([1]) + v["name"].encode("ascii").ljust(8, b"\0") + bytes([len(label)]) + label
            + v["comment"].encode() + b"\0" + v["fixed"]
            + bytes(v["address"]) + bytes(reversed(v["address_le"]))
            + struct.pack("<b", v["small"]) + struct.pack("<h", v["medium"])
            + (v["odd"] & 0xFFFFFF).to_bytes(3, "big") + struct.pack("<q", v["large"])
            + bytes([(v["low"] & 0xF) | (v["high"] & 0xF) << 4])
            + struct.pack("<f", v["real"]) + struct.pack(">d", v["lreal"])
            + struct.pack("<Q", v["dc_ns"]) + struct.pack("<I", v["delay_us"])
            + struct.pack("<H", v["cycle_ms"]) + struct.pack("<I", v["uptime_s"])
            + struct.pack("<H", v["status"]))


def seconds(count, per_second):
    """FT_RELATIVE_TIME as -T fields prints it: seconds with nine decimals."""
    ns = count * (10 ** 9 // per_second)
    return "%d.%09d" % (ns // 10 ** 9, ns % 10 ** 9)


def inner_frame(sender_ip):
    """An Ethernet frame carrying an ARP request (42 bytes, no padding, no FCS)."""
    arp = struct.pack("!HHBBH6s4s6s4s", 1, 0x0800, 6, 4, 1, b"\x02\x10\0\0\0\x05", bytes(sender_ip),
                      bytes(6), bytes((10, 9, 9, 9)))
    return b"\xff" * 6 + b"\x02\x10\0\0\0\x05" + struct.pack("!H", 0x0806) + arp


def fragment(msg_id, offset_bytes, last, data):
    assert offset_bytes % 4 == 0
    return bytes([5]) + struct.pack("<HHB", msg_id, offset_bytes // 4, 1 if last else 0) + data


def piece(piece_id, number, more, data):
    return bytes([6, piece_id, number, 1 if more else 0]) + data


# --------------------------------------------------------------------------- running tshark

def run_fields(capture, names, extra=(), allow_stderr=(MISSING_WARNING,)):
    args = ["-r", capture, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=|"] + list(extra)
    for n in names:
        args += ["-e", n]
    p = ENV.tshark(args)
    stderr = [l for l in p.stderr.splitlines() if l.strip() and not any(a in l for a in allow_stderr)]
    if stderr:
        raise AssertionError("tshark wrote to stderr:\n" + "\n".join(stderr))
    return [dict(zip(names, line.split("\t"))) for line in p.stdout.splitlines()]


def both_passes(capture, names, extra=()):
    """The rows of -2, and the same rows in one pass, but for "Reassembled in" on the
    fragments before the one that completes a message: a single pass prints them before
    it has read that frame (as with Wireshark's own reassembling dissectors)."""
    one = run_fields(capture, names, extra)
    two = run_fields(capture, names, ["-2"] + list(extra))
    for a, b in zip(one, two):
        if "dspt.reassembled_in" in a and a["dspt.reassembled_in"] == "":
            a["dspt.reassembled_in"] = b["dspt.reassembled_in"]
    assert one == two, "one pass and -2 differ:\n%s\n%s" % (one, two)
    return two


def assert_no_exception(capture):
    """Our expert infos, not a Wireshark exception, report the defects."""
    out = ENV.tshark(["-r", capture, "-V", "-2"]).stdout
    assert "[Malformed Packet: DSPT]" not in out, out


def capture(name, frames):
    return ENV.add_file(name, pcap(frames))


class TypedValues(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        global ENV
        ENV = TsharkEnv()
        ENV.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, RULES))

    @classmethod
    def tearDownClass(cls):
        ENV.cleanup()

    def test_plugin_loads_and_warns_once_about_the_missing_dissector(self):
        p = ENV.tshark(["-G", "protocols"])
        self.assertIn("dspt", {l.split("\t")[2] for l in p.stdout.splitlines() if l.count("\t") >= 2})
        self.assertEqual(p.stderr.count(MISSING_WARNING), 1, p.stderr)
        others = [l for l in p.stderr.splitlines() if l.strip() and MISSING_WARNING not in l]
        self.assertEqual(others, [])

    def test_typed_values_match_the_bytes(self):
        v = VALUES
        cap = capture("values.pcap", [to_port(values_message())])
        names = ["dspt.values.name", "dspt.values.label", "dspt.values.comment", "dspt.values.fixed_text",
                 "dspt.values.address", "dspt.values.address_le", "dspt.values.small", "dspt.values.medium",
                 "dspt.values.odd", "dspt.values.large", "dspt.values.low_nibble", "dspt.values.high_nibble",
                 "dspt.values.real", "dspt.values.lreal", "dspt.values.dc_time", "dspt.values.delay",
                 "dspt.values.cycle", "dspt.values.uptime", "dspt.values.status", "_ws.col.Info",
                 "_ws.expert"]
        row = both_passes(cap, names)[0]
        expected = {
            "dspt.values.name": v["name"], "dspt.values.label": v["label"], "dspt.values.comment": v["comment"],
            "dspt.values.fixed_text": v["fixed"].split(b"\0")[0].decode(),
            "dspt.values.address": "%d.%d.%d.%d" % v["address"],
            "dspt.values.address_le": "%d.%d.%d.%d" % v["address_le"],
            "dspt.values.small": str(v["small"]), "dspt.values.medium": str(v["medium"]),
            "dspt.values.odd": str(v["odd"]), "dspt.values.large": str(v["large"]),
            "dspt.values.low_nibble": str(v["low"]), "dspt.values.high_nibble": str(v["high"]),
            "dspt.values.real": "1.5", "dspt.values.lreal": "-2.25",
            "dspt.values.dc_time": seconds(v["dc_ns"], 10 ** 9),
            "dspt.values.delay": seconds(v["delay_us"], 10 ** 6),
            "dspt.values.cycle": seconds(v["cycle_ms"], 10 ** 3),
            "dspt.values.uptime": seconds(v["uptime_s"], 1),
            "dspt.values.status": "0x%04x" % v["status"],
            # The Info column is the runtime's own reading of each type (sign, byte
            # order, unit), not Wireshark's: the summary shows one of each kind.
            "_ws.col.Info": "%s State error %d %s seconds %d %d.%d.%d.%d %s %s seconds" % (
                v["name"], v["small"], seconds(v["dc_ns"], 10 ** 9), v["odd"], *v["address_le"], "1.5",
                seconds(v["delay_us"], 10 ** 6)),
            "_ws.expert": "",
        }
        self.assertEqual(row, expected)

    def test_tree_shows_range_names_signs_and_times(self):
        cap = capture("values_v.pcap", [to_port(values_message())])
        out = ENV.tshark(["-r", cap, "-V", "-O", "dspt"]).stdout
        for line in ["Status: State error (0x0015)", "Small: -5", ".... 1101 = Low nibble: -3",
                     "0101 .... = High nibble: 5", "DC time: 1234.567890123 seconds", "Delay: 0.002500000 seconds",
                     "Address: 192.168.1.20", "Address LE: 10.0.0.1", "Real: 1.5", "LReal: -2.25",
                     "Label: Größe", "Fixed text: ab", "Comment: hello"]:
            self.assertIn(line, out)
        for status, name in [(0, "OK"), (0x11, "State error"), (0x1F, "State error"), (32, "Configuration error"),
                             (47, "Configuration error"), (0x100, "Watchdog"), (0x30, "Unknown")]:
            v = dict(VALUES, status=status)
            cap = capture("status.pcap", [to_port(values_message(v))])
            out = ENV.tshark(["-r", cap, "-V", "-O", "dspt"]).stdout
            self.assertIn("Status: %s (0x%04x)" % (name, status), out)

    def test_direction_picks_the_layout_and_repeat_rest_fills_the_container(self):
        request = bytes([2]) + struct.pack("<HH", 0x0010, 3)
        registers = [0x1111, 0x2222, 0x3333]
        response = bytes([2, 6]) + b"".join(struct.pack("<H", r) for r in registers) + b"\xaa"
        cap = capture("exchange.pcap", [to_port(request), from_port(response)])
        names = ["dspt.request.start", "dspt.request.quantity", "dspt.response.byte_count",
                 "dspt.response.registers.register", "dspt.response.trailer", "_ws.expert"]
        rows = both_passes(cap, names)
        self.assertEqual(rows[0], {"dspt.request.start": "0x0010", "dspt.request.quantity": "3",
                                   "dspt.response.byte_count": "", "dspt.response.registers.register": "",
                                   "dspt.response.trailer": "", "_ws.expert": ""})
        self.assertEqual(rows[1], {"dspt.request.start": "", "dspt.request.quantity": "",
                                   "dspt.response.byte_count": "6",
                                   "dspt.response.registers.register": "|".join("0x%04x" % r for r in registers),
                                   "dspt.response.trailer": "0xaa", "_ws.expert": ""})
        # Both ports the hooked one: the destination decides, a request.
        cap = capture("same_port.pcap", [udp(PORT, PORT, request)])
        self.assertEqual(run_fields(cap, names)[0]["dspt.request.quantity"], "3")

    def test_repeat_rest_with_an_odd_byte_left_reports_truncated(self):
        response = bytes([2, 5]) + struct.pack("<HH", 1, 2) + b"\x07" + b"\xaa"
        cap = capture("odd.pcap", [from_port(response)])
        rows = run_fields(cap, ["dspt.response.registers.register", "dspt.expert.truncated"])
        self.assertEqual(rows[0]["dspt.response.registers.register"], "0x0001|0x0002")
        self.assertNotEqual(rows[0]["dspt.expert.truncated"], "")
        assert_no_exception(cap)

    def test_a_chain_after_a_taken_one_still_takes_its_otherwise(self):
        cap = capture("chains.pcap", [to_port(bytes([8, 1, 0x11, 0x22])), to_port(bytes([8, 2, 0x33])),
                                      to_port(bytes([8, 3, 0x44]))])
        names = ["dspt.chained.first", "dspt.chained.second", "dspt.chained.second_other", "_ws.expert"]
        rows = both_passes(cap, names)
        self.assertEqual([[r[n] for n in names] for r in rows],
                         [["0x11", "", "0x22", ""], ["", "0x33", "", ""], ["", "", "0x44", ""]])

    def test_hand_off_to_eth_withoutfcs(self):
        cap = capture("handoff.pcap", [to_port(bytes([3]) + inner_frame((10, 1, 2, 3)))])
        rows = both_passes(cap, ["eth.type", "arp.src.proto_ipv4", "dspt.frame", "_ws.col.Protocol"])
        self.assertEqual(rows[0]["eth.type"], "0x0800|0x0806")
        self.assertEqual(rows[0]["arp.src.proto_ipv4"], "10.1.2.3")
        self.assertNotEqual(rows[0]["dspt.frame"], "")  # still filterable
        self.assertEqual(rows[0]["_ws.col.Protocol"], "DSPT")
        # ... but hidden: the other dissector shows the bytes, our tree does not repeat them raw
        # (-V shortens a long bytes label to "Frame […]: ...", so the PDML's hide says it).
        tree = ENV.tshark(["-r", cap, "-V", "-O", "dspt"]).stdout
        self.assertIn("Kind: Frame", tree)
        self.assertNotRegex(tree, r"(?m)^\s+Frame( \[\S+\])?: [0-9a-f]{8}")
        pdml = ET.fromstring(ENV.tshark(["-r", cap, "-T", "pdml"]).stdout)
        ours = [f for f in pdml.iter("field") if f.get("name") == "dspt.frame"]
        self.assertEqual([f.get("hide") for f in ours], ["yes"])

    def test_hand_off_of_a_truncated_frame_stays_inside_the_other_dissector(self):
        cap = capture("handoff_short.pcap", [to_port(bytes([3]) + inner_frame((10, 1, 2, 3))[:20])])
        p = ENV.tshark(["-r", cap, "-V"], check=False)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("Display Test", p.stdout)
        self.assertIn("Malformed Packet", p.stdout)

    def test_unknown_dissector_shows_raw_bytes(self):
        cap = capture("opaque.pcap", [to_port(bytes([4]) + b"\x01\x02\x03")])
        p = ENV.tshark(["-r", cap, "-T", "fields", "-e", "dspt.opaque", "-e", "_ws.expert"], check=False)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stdout.strip().split("\t")[0].replace(":", "").replace(" ", ""), "010203")
        self.assertEqual(p.stderr.count(MISSING_WARNING), 1, p.stderr)

    def test_fragments_reassembled_out_of_order_and_missing(self):
        a, b = inner_frame((10, 0, 0, 7)), inner_frame((10, 0, 0, 9))
        frames = [
            to_port(fragment(7, 0, False, a[:16])),     # 1
            to_port(fragment(7, 32, True, a[32:])),     # 2: last, before the middle one
            to_port(fragment(8, 0, False, b[:16])),     # 3: message 8 never gets its middle
            to_port(fragment(7, 16, False, a[16:32])),  # 4: completes message 7
            to_port(fragment(8, 32, True, b[32:])),     # 5
            to_port(fragment(9, 0, False, b[:24])),     # 6
            to_port(fragment(9, 24, True, b[24:])),     # 7: completes message 9
        ]
        cap = capture("fragments.pcap", frames)
        names = ["frame.number", "dspt.chunk.message_id", "dspt.reassembled_in", "dspt.fragment",
                 "dspt.reassembled.length", "arp.src.proto_ipv4", "_ws.expert"]
        rows = both_passes(cap, names)
        by_frame = {r["frame.number"]: r for r in rows}
        for f in ("1", "2"):
            self.assertEqual(by_frame[f]["dspt.reassembled_in"], "4")
        self.assertEqual(by_frame["4"]["dspt.fragment"], "1|4|2")
        self.assertEqual(by_frame["4"]["dspt.reassembled.length"], str(len(a)))
        self.assertEqual(by_frame["4"]["arp.src.proto_ipv4"], "10.0.0.7")
        for f in ("3", "5"):
            self.assertEqual(by_frame[f]["dspt.reassembled_in"], "")
            self.assertEqual(by_frame[f]["arp.src.proto_ipv4"], "")
        self.assertEqual(by_frame["6"]["dspt.reassembled_in"], "7")
        self.assertEqual(by_frame["7"]["arp.src.proto_ipv4"], "10.0.0.9")
        for r in rows:
            self.assertEqual(r["_ws.expert"], "", r)
        # Filtering on the reassembled contents finds the completing frames.
        rows = run_fields(cap, ["frame.number"], ["-Y", "arp", "-2"])
        self.assertEqual([r["frame.number"] for r in rows], ["4", "7"])

    def test_numbered_pieces_reassembled_raw(self):
        frames = [to_port(piece(3, 1, True, b"def")), to_port(piece(3, 0, True, b"abc")),
                  to_port(piece(3, 2, False, b"gh"))]
        cap = capture("pieces.pcap", frames)
        rows = both_passes(cap, ["dspt.piece.piece_data", "dspt.reassembled_in", "dspt.fragment.count"])
        self.assertEqual(rows[0]["dspt.reassembled_in"], "3")
        self.assertEqual(rows[1]["dspt.reassembled_in"], "3")
        self.assertEqual(rows[2]["dspt.fragment.count"], "3")
        data = rows[2]["dspt.piece.piece_data"].split("|")
        self.assertEqual([d.replace(":", "").replace(" ", "") for d in data], ["6768", b"abcdefgh".hex()])

    def test_reassembly_faults_give_an_expert_info_where_they_are(self):
        def tagged(tag, number, data, with_id=True):
            return bytes([7, tag]) + (struct.pack("<H", 5) if with_id else b"") + struct.pack("<I", number) + data
        frames = [to_port(tagged(1, 0, b"whole")),                  # 1: clean, one fragment, complete
                  to_port(tagged(0, 0, b"no id", with_id=False)),   # 2: the id field is not in this message
                  to_port(tagged(1, 70000, b"far"))]                # 3: fragment number out of range
        cap = capture("tagged.pcap", frames)
        rows = both_passes(cap, ["dspt.tagged.tagged_data", "dspt.fragment.count", "dspt.expert.bad_length",
                                 "_ws.expert"])
        self.assertEqual(rows[0]["dspt.fragment.count"], "1")
        self.assertEqual(rows[0]["_ws.expert"], "")
        for r in rows[1:]:
            self.assertNotEqual(r["dspt.expert.bad_length"], "", r)
            self.assertEqual(r["dspt.fragment.count"], "", r)
        # The fragment's bytes are still shown.
        self.assertEqual(rows[1]["dspt.tagged.tagged_data"].replace(" ", ""), b"no id".hex())
        self.assertEqual(rows[2]["dspt.tagged.tagged_data"].replace(" ", ""), b"far".hex())
        assert_no_exception(cap)

    def test_stringz_without_nul_and_string_past_the_end(self):
        no_nul = bytes([1]) + b"Motor\0\0\0" + bytes([2]) + b"ok" + b"unterminated"
        past_end = bytes([1]) + b"Motor\0\0\0" + bytes([40]) + b"short"
        cap = capture("bad_strings.pcap", [to_port(no_nul), to_port(past_end)])
        rows = run_fields(cap, ["dspt.values.name", "dspt.values.label", "dspt.values.comment",
                                "dspt.expert.truncated", "dspt.expert.past_end", "_ws.expert.message"])
        self.assertEqual(rows[0]["dspt.values.label"], "ok")
        self.assertEqual(rows[0]["dspt.values.comment"], "unterminated")
        self.assertNotEqual(rows[0]["dspt.expert.truncated"], "")
        # The stringz's own message, not the generic one of a fixed length.
        self.assertIn("'Comment' has no NUL before the end of its data (12 bytes left)",
                      rows[0]["_ws.expert.message"])
        self.assertEqual(rows[1]["dspt.values.name"], "Motor")
        self.assertEqual(rows[1]["dspt.values.label"], "short")
        self.assertNotEqual(rows[1]["dspt.expert.past_end"], "")
        assert_no_exception(cap)
        # On the clean messages, none of our expert infos fires.
        cap = capture("clean.pcap", [to_port(values_message())])
        self.assertEqual(run_fields(cap, ["_ws.expert"])[0]["_ws.expert"], "")

    def test_truncated_address_and_float_give_expert_infos(self):
        """An IPv4 address or a float cut short: our expert info, no Wireshark exception
        (FT_IPv4 and FT_FLOAT items cannot show fewer bytes than their size)."""
        m = values_message()
        address = m.index(bytes(VALUES["address"]))
        real = m.index(struct.pack("<f", VALUES["real"]))
        cap = capture("cut_fixed_size.pcap", [to_port(m[:address + 2]), to_port(m[:real + 3])])
        rows = run_fields(cap, ["dspt.values.fixed_text", "dspt.values.address", "dspt.values.small",
                                "dspt.values.real", "_ws.expert.message"])
        self.assertEqual(rows[0]["dspt.values.fixed_text"], "ab")
        self.assertEqual(rows[0]["dspt.values.address"], "")
        self.assertIn("Truncated: 'Address' needs 4 bytes, only 2 left", rows[0]["_ws.expert.message"])
        self.assertEqual(rows[1]["dspt.values.small"], str(VALUES["small"]))
        self.assertEqual(rows[1]["dspt.values.real"], "")
        self.assertIn("Truncated: 'Real' needs 4 bytes, only 3 left", rows[1]["_ws.expert.message"])
        assert_no_exception(cap)

    def test_every_truncation_of_every_message_decodes_without_exception(self):
        messages = [values_message(), bytes([2]) + struct.pack("<HH", 1, 2),
                    bytes([3]) + inner_frame((1, 2, 3, 4)), fragment(11, 0, False, bytes(16)),
                    piece(4, 0, True, b"xyz")]
        frames = []
        for m in messages:
            step = 1 if not SANITIZE else 3
            frames += [to_port(m[:n]) for n in range(1, len(m) + 1, step)]
        cap = capture("truncations.pcap", frames)
        p = ENV.tshark(["-r", cap, "-V", "-2"], check=False)
        self.assertEqual(p.returncode, 0, p.stderr[-2000:])
        self.assertNotIn("Dissector bug", p.stdout)
        self.assertNotIn("[Malformed Packet: DSPT]", p.stdout)


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Malformed EtherCAT frames through the plugin generated from rules/ethercat.xml.

tshark must exit 0 with nothing on stderr, the rules protocol must never
raise a Wireshark exception ("[Malformed Packet: ECATR]"), every defect must
carry one of our expert infos where it happens, and what is there must still
be decoded.
"""
import io
import os
import random
import struct
import sys
import unittest
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import pcapgen  # noqa: E402
from pcapgen import Datagram, Frame  # noqa: E402
from tshark_env import TsharkEnv, read_tshark_output, run_unittests  # noqa: E402

ARGS = None
ETH_HEADER = b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01" + b"\x88\xa4"
PI_MALFORMED = 0x07000000  # epan/proto.h: the expert group of a malformed spot
OUR_EXPERTS = ("ecatr.expert.truncated", "ecatr.expert.past_end", "ecatr.expert.more_no_data",
               "ecatr.expert.count_short", "ecatr.expert.bad_length", "ecatr.expert.unused")


def pcap(packets):
    """packets: [(captured bytes, original length)]"""
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i, (data, orig) in enumerate(packets):
        out.append(struct.pack("<IIII", 1700000000 + i, 0, len(data), orig))
        out.append(data)
    return b"".join(out)


def frame_bytes(frame):
    data, _ = pcapgen.encode_frame(frame)
    return data


class Malformed(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.env = TsharkEnv()
        cls.env.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "rules", "ethercat.xml"))

    @classmethod
    def tearDownClass(cls):
        cls.env.cleanup()

    def decode(self, packets, fields):
        cap = self.env.add_file("m.pcap", pcap(packets))
        args = ["-r", cap, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=|"]
        for f in fields:
            args += ["-e", f]
        p = self.env.tshark(args, check=False)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stderr.strip(), "", "tshark complained")
        verbose = self.env.tshark(["-r", cap, "-V"], check=False)
        self.assertEqual(verbose.returncode, 0)
        self.assertNotIn("[Malformed Packet: ECATR]", verbose.stdout, "a Wireshark exception escaped the rules")
        self.assertNotIn("Dissector bug", verbose.stdout + verbose.stderr)
        rows = [line.split("\t") for line in p.stdout.splitlines()]
        self.assertEqual(len(rows), len(packets))
        return rows

    def test_truncated_at_every_byte_offset(self):
        rng = random.Random(11)
        frames = []
        for _ in range(25):
            n = rng.randint(1, 4)
            frames.append(Frame([Datagram(cmd=rng.randint(0, 14), idx=rng.randint(0, 255),
                                          data=bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 20))),
                                          wkc=rng.randint(0, 5)) for _ in range(n)], pad=False))
        packets, expected_cmds = [], []
        for f in frames:
            whole = frame_bytes(f)
            starts, at = [], 16  # command byte offsets of each datagram
            for d in f.datagrams:
                starts.append(at)
                at += 12 + len(d.data)
            for cut in range(15, len(whole)):
                for orig in (len(whole), cut):   # snap-length truncation and a short frame
                    packets.append((whole[:cut], orig))
                    expected_cmds.append(["0x%02x" % d.cmd for d, s in zip(f.datagrams, starts) if s < cut])
        rows = self.decode(packets, ["ecatr.datagram.cmd", "_ws.expert.message", "_ws.col.Protocol", "_ws.short",
                                     "_ws.expert.group"])
        for (data, orig), row, cmds in zip(packets, rows, expected_cmds):
            self.assertEqual(row[2], "ECATR")
            got = row[0].split("|") if row[0] else []
            self.assertEqual(got, cmds, "datagrams inside the cut must still be decoded (%d bytes)" % len(data))
            if len(data) > 14 and orig == len(data):  # that short on the wire: malformed
                self.assertTrue(any(w in row[1] for w in ("Truncated", "past the end")) and not row[3],
                                "no expert info for a frame of %d bytes: %r" % (len(data), row[1]))
                # one cause, one expert info: the header's Length past the end, not again for
                # each datagram, field or count inside it that the cut leaves short
                malformed = [g for g in row[4].split("|") if int(g) == PI_MALFORMED]
                self.assertEqual(len(malformed), 1, "a frame of %d bytes: expert infos %r" % (len(data), row[1]))
            elif len(data) > 14:  # whole on the wire, the capture kept less: not malformed
                malformed = ("Truncated", "past the end", "no data is left", "should occur")
                self.assertTrue(row[3] and not any(w in row[1] for w in malformed),
                                "a frame cut by the capture at %d of %d bytes: "
                                "expert %r, _ws.short %r" % (len(data), orig, row[1], row[3]))

    def test_length_fields_past_the_end(self):
        f = Frame([Datagram(cmd=4, data=b"\x01\x02", wkc=1)], header_length=2000 & 0x7FF, pad=False)
        g = Frame([Datagram(cmd=12, data=b"\x01\x02", wkc=1, len_field=900)], pad=False)
        rows = self.decode([(frame_bytes(f), len(frame_bytes(f))), (frame_bytes(g), len(frame_bytes(g)))],
                           ["ecatr.datagram.cmd", "_ws.expert.message"])
        self.assertIn("'Datagrams' has length 2000, past the end of its data", rows[0][1])
        self.assertEqual(rows[0][0], "0x04")
        self.assertIn("past the end of its data", rows[1][1])
        self.assertEqual(rows[1][0], "0x0c")

    def test_more_flag_on_last_datagram_with_padding(self):
        f = Frame([Datagram(cmd=7, data=b"\x00", wkc=3)], m_on_last=True)  # padded to 60 bytes
        rows = self.decode([(frame_bytes(f), len(frame_bytes(f)))],
                           ["ecatr.datagram.cmd", "ecatr.datagram.more", "_ws.expert.message"])
        self.assertEqual(rows[0][0], "0x07", "no datagram may be invented from the padding")
        self.assertEqual(rows[0][1], "1")
        self.assertIn("the repeat flag 'More' says another follows, but no data is left", rows[0][2])

    def test_header_length_longer_than_the_datagrams(self):
        """A header Length of 34 over a 14-byte datagram: the 20 bytes after it are the
        Ethernet padding. Zeros there are padding; anything else is reported."""
        f = Frame([Datagram(cmd=1, data=b"\xaa\xbb", wkc=1)], header_length=14 + 20)
        zeros = frame_bytes(f)
        self.assertEqual(zeros[30:], bytes(30), "Ethernet pads the frame with zeros")
        other = zeros[:40] + b"\x5a" + zeros[41:]
        rows = self.decode([(zeros, len(zeros)), (other, len(other))],
                           ["ecatr.datagram.cmd", "ecatr.padding", "_ws.expert.message"])
        self.assertEqual(rows[0], ["0x01", "00" * 20, ""])
        self.assertEqual(rows[1][0:2], ["0x01", ""])
        self.assertEqual(rows[1][2], "'Datagrams' is 34 bytes, but its fields end after 14: 20 bytes are not decoded")

    def padded_frames(self):
        """One short datagram (12 to 14 bytes) inside a header Length of 14 (as TwinCAT sends
        it) or 28 (as ethercrab does): first the rest in zeros, then with one non-zero byte at
        each place of it in turn, then zeros with non-zero bytes after the Length (the
        Ethernet padding, outside the datagrams). -> [(frame bytes, padding offset in the
        frame, padding length, place of the non-zero byte or None)]"""
        out = []
        for declared in (14, 28):
            for data_len in (0, 1, 2):
                size = 12 + data_len
                pad = declared - size
                d = Datagram(cmd=4, idx=len(out) & 0xFF, adp=0x1001, ado=0x0130, data=bytes(range(1, data_len + 1)),
                             wkc=1)
                at = 14 + 2 + size
                out.append((frame_bytes(Frame([d], padding=bytes(pad))), at, pad, None))
                for k in range(pad):
                    padding = bytearray(pad)
                    padding[k] = 1 + (k * 37) % 255
                    d = Datagram(cmd=4, idx=len(out) & 0xFF, adp=0x1001, ado=0x0130,
                                 data=bytes(range(1, data_len + 1)), wkc=1)
                    out.append((frame_bytes(Frame([d], padding=bytes(padding))), at, pad, k))
                d = Datagram(cmd=4, idx=len(out) & 0xFF, adp=0x1001, ado=0x0130, data=bytes(range(1, data_len + 1)),
                             wkc=1)
                f = frame_bytes(Frame([d], padding=bytes(pad), pad=False))
                out.append((f + b"\xff" * max(60 - len(f), 1), at, pad, None))
        return out

    def padding_and_experts(self, cap, two_pass):
        """{frame: ([(padding pos, size, value)], [(our expert, pos, message)])} from the PDML."""
        pdml = self.env.path("padding.pdml")
        with open(pdml, "w") as fh:
            self.env.tshark(["-r", cap, "-T", "pdml"] + (["-2"] if two_pass else []), stdout=fh)
        out = {}
        for _, packet in ET.iterparse(io.BytesIO(read_tshark_output(pdml, xml=True).encode("utf-8"))):
            if packet.tag != "packet":
                continue
            num = int(packet.find("proto[@name='geninfo']/field[@name='num']").get("show"))
            padding, experts = [], []
            for item in packet.iter("field"):
                if item.get("name") == "ecatr.padding":
                    padding.append((int(item.get("pos")), int(item.get("size")), item.get("value")))
                if item.get("name") == "_ws.expert":
                    for child in item.findall("field"):
                        if child.get("name") in OUR_EXPERTS:
                            experts.append((child.get("name"), int(item.get("pos")), child.get("showname")))
            out[num] = (padding, experts)
            packet.clear()
        return out

    def test_zero_padding_is_shown_as_padding_and_other_bytes_are_reported(self):
        frames = self.padded_frames()
        rows = self.decode([(f, len(f)) for f, _, _, _ in frames], ["ecatr.datagram.cmd"])
        self.assertEqual([r[0] for r in rows], ["0x04"] * len(frames))
        cap = self.env.add_file("padded.pcap", pcap([(f, len(f)) for f, _, _, _ in frames]))
        nonzero = 0
        for two_pass in (False, True):
            shown = self.padding_and_experts(cap, two_pass)
            for number, (f, at, pad, k) in enumerate(frames, 1):
                padding, experts = shown[number]
                where = "frame %d (%d bytes of padding, non-zero byte at %s%s)" % (
                    number, pad, k, ", -2" if two_pass else "")
                if k is None:
                    self.assertEqual(experts, [], where)
                    self.assertEqual(padding, [(at, pad, "00" * pad)] if pad else [], where)
                else:
                    nonzero += 1
                    self.assertEqual(padding, [], where)
                    self.assertEqual(experts, [("ecatr.expert.unused", at,
                                                "'Datagrams' is %d bytes, but its fields end after %d: "
                                                "%d bytes are not decoded" % (at - 16 + pad, at - 16, pad))], where)
        self.assertEqual(nonzero, 2 * (2 + 1 + 16 + 15 + 14))

    def test_padding_cut_short_by_the_capture(self):
        """Zeros the capture did not keep are not known to be zeros: no padding item. The frame
        had them on the wire (the capture kept less: a snapshot length), so it is not malformed:
        Wireshark's "[Packet size limited during capture]" (_ws.short), no expert info; the same
        bytes that short on the wire: the header Length runs past the end."""
        packets, cuts = [], []
        for declared in (14, 28):
            size = 13
            for cut in range(0, declared - size):
                f = Frame([Datagram(cmd=4, idx=len(packets), data=b"\x01", wkc=1)], padding=bytes(declared - size),
                          truncate_to=2 + size + cut, pad=False)
                data, orig = pcapgen.encode_frame(f)
                packets += [(data, orig), (data, len(data))]
                cuts.append((declared, size + cut))
        rows = self.decode(packets, ["ecatr.datagram.cmd", "ecatr.padding", "_ws.expert.message", "_ws.short"])
        for k, (declared, left) in enumerate(cuts):
            cut_by_capture, short = rows[2 * k], rows[2 * k + 1]
            self.assertEqual(cut_by_capture[:3], ["0x04", "", ""])
            self.assertTrue(cut_by_capture[3].startswith("[Packet size limited during capture"), cut_by_capture)
            self.assertEqual(short, ["0x04", "", "'Datagrams' has length %d, past the end of its data (%d bytes left)"
                                     % (declared, left), ""])

    def test_over_a_hundred_empty_datagrams(self):
        f = Frame([Datagram(cmd=0, idx=i & 0xFF) for i in range(124)])
        rows = self.decode([(frame_bytes(f), len(frame_bytes(f)))],
                           ["ecatr.datagram.cmd", "ecatr.datagram.idx", "_ws.expert.message"])
        self.assertEqual(len(rows[0][0].split("|")), 124)
        self.assertEqual(rows[0][2], "")

    def test_random_bytes_on_the_ethertype(self):
        rng = random.Random(3)
        packets = []
        for _ in range(3000):
            body = bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 200)))
            packets.append((ETH_HEADER + body, 14 + len(body)))
        rows = self.decode(packets, ["_ws.col.Protocol", "_ws.malformed"])
        for (data, _), row in zip(packets, rows):
            self.assertEqual(row[0], "ECATR")
            if len(data) == 14:  # no payload at all: ours, and malformed (our expert info)
                self.assertTrue(row[1], "an empty EtherCAT frame is malformed")


def main():
    return run_unittests()[1]


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Zero padding after the datagrams of real EtherCAT captures is not an error.

Masters send a header Length longer than the datagrams and fill the rest with
zeros (TwinCAT keeps it at 14 bytes at least, ethercrab at 28). Zero bytes between
the end of a known-length container's fields and the end of its length are
padding: the plugin shows them as `ecatr.padding` and raises no
`ecatr.expert.unused` (that warning is for bytes that are not all zero;
test_malformed.py checks both on generated frames).

On every capture of ../shared/corpus/ethercat, and on a copy of it whose
EtherCAT frames (on Ethernet, frame type 1) have their header Length raised by
1 to 28 bytes (1 + the first datagram's index modulo 28, so that a returned
frame gets what its request got) with as many zero bytes inserted after the
old Length, in one pass and with -2:

- no frame has an ecatr.expert.unused;
- in the copy, every rewritten frame shows ecatr.padding over exactly the zero
  bytes after its last datagram (the ones the capture had plus the inserted
  ones), and every other frame shows what it shows in the original;
- every frame has the same expert infos (all of them, the pairing's included)
  in the copy as in the original: the padding changes nothing else.

Without the corpus the script prints "SKIPPED: ..." and exits 77.

    test_corpus_padding.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
sys.dont_write_bytecode = True
from pcaprewrite import Capture, ecat_datagrams, get_u16, set_u16  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

ARGS = None
COLUMNS = ["frame.number", "ecatr.padding", "ecatr.expert.unused", "_ws.expert.message"]


def corpus_dir():
    return os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus", "ethercat")


def captures():
    folder = corpus_dir()
    if not os.path.isdir(folder):
        return []
    return sorted(f for f in os.listdir(folder) if f.endswith((".pcap", ".pcapng")))


def ethertype_offset(pkt):
    """Where the EtherCAT header starts in a frame of ethertype 0x88A4 (after any 802.1Q
    tags), or None (other ethertypes, EtherCAT over UDP)."""
    d, off = pkt.data, 12
    while len(d) >= off + 2 and struct.unpack("!H", d[off:off + 2])[0] in (0x8100, 0x88A8):
        off += 4
    if len(d) >= off + 4 and struct.unpack("!H", d[off:off + 2])[0] == 0x88A4:
        return off + 2
    return None


def padded_copy(path):
    """(the copy's bytes, {frame number: padding bytes it must show}) for the rewritten frames."""
    cap = Capture.read(path)
    padding = {}
    for number, pkt in enumerate(cap.packets, 1):
        base = ethertype_offset(pkt)
        datagrams = ecat_datagrams(pkt)
        d = pkt.data
        if base is None or not datagrams:
            continue        # not EtherCAT on Ethernet (UDP would need its lengths changed too)
        header = get_u16(pkt, base)
        end = base + 2 + (header & 0x7FF)
        last = datagrams[-1]["wkc_offset"] + 2
        extra = 1 + datagrams[0]["idx"] % 28
        if datagrams[-1]["more"] or end > len(d) or (header & 0x7FF) + extra > 0x7FF:
            continue        # a chain the Length cuts, or no room left: as captured
        set_u16(pkt, base, header + extra)
        d[end:end] = bytes(extra)
        padding[number] = end + extra - last
    return cap.to_bytes(), padding


class CorpusPadding(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        if captures():
            cls.env.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "rules", "ethercat.xml"))

    def rows(self, capture, two_pass):
        args = ["-r", capture, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=|"]
        for c in COLUMNS:
            args += ["-e", c]
        out = self.env.tshark(args + (["-2"] if two_pass else [])).stdout
        return {int(r[0]): dict(zip(COLUMNS[1:], r[1:])) for r in (line.split("\t") for line in out.splitlines())}

    def test_no_unused_bytes_on_real_captures_and_padded_copies(self):
        names = captures()
        if not names:
            self.skipTest("no EtherCAT corpus at %s" % corpus_dir())
        total = {"frames": 0, "rewritten": 0, "padded in original": 0}
        for name in names:
            path = os.path.join(corpus_dir(), name)
            blob, padding = padded_copy(path)
            copy = self.env.add_file("padded-" + name, blob)
            original = self.env.readable(path)
            for two_pass in (False, True):
                mode = " (-2)" if two_pass else ""
                was, now = self.rows(original, two_pass), self.rows(copy, two_pass)
                self.assertEqual(sorted(was), sorted(now), name)
                for number in sorted(was):
                    where = "%s frame %d%s" % (name, number, mode)
                    self.assertEqual(was[number]["ecatr.expert.unused"], "", where)
                    self.assertEqual(now[number]["ecatr.expert.unused"], "", where + " (padded copy)")
                    want = "00" * padding[number] if number in padding else was[number]["ecatr.padding"]
                    self.assertEqual(now[number]["ecatr.padding"], want, where + " (padded copy)")
                    self.assertEqual(now[number]["_ws.expert.message"], was[number]["_ws.expert.message"],
                                     where + ": the same expert infos in the padded copy")
            in_original = sum(1 for r in was.values() if r["ecatr.padding"])
            print("%s: %d frames, %d rewritten, %d with padding as captured" % (name, len(was), len(padding),
                                                                               in_original), file=sys.stderr)
            total["frames"] += len(was)
            total["rewritten"] += len(padding)
            total["padded in original"] += in_original
        print("all captures: %s" % total, file=sys.stderr)
        self.assertGreater(total["rewritten"], total["frames"] * 0.5, total)


if __name__ == "__main__":
    ARGS, status = run_unittests()
    if status == 0 and not captures():
        print("SKIPPED: no EtherCAT corpus at %s" % corpus_dir())
        status = 77
    sys.exit(status)

#!/usr/bin/env python3
"""Issue 14: a walk nobody sees steps over quiet nodes, and nothing shown changes.

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

    test_quiet.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pcapgen  # noqa: E402
from tshark_env import TsharkEnv, run_unittests  # noqa: E402

ARGS = None


def corpus_captures(kind):
    folder = os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus", kind)
    if not os.path.isdir(folder):
        return []
    return [os.path.join(folder, f) for f in sorted(os.listdir(folder)) if f.endswith((".pcap", ".pcapng"))]


def padded_frames():
    """A 13-byte datagram inside a header Length of 14 or 28 bytes: the rest zeros (padding,
    no expert info), or with a non-zero byte (the unused expert info, a warning), or cut
    short by the capture inside the zeros (not known to be zero: the datagrams are past the
    end, an error). -> [(frame, severity in the Expert column in one pass)], a second apart
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
        frame(bytes(size), "Error", truncate_to=2 + 13 + size // 2, pad=False)
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


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

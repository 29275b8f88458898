#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Values learned from earlier frames (<learn>, learned{Name}) with real tshark:
tests/rules/learned.xml on ethertype 0x88c1.

A Configure message teaches the scale of a (channel, slot); a Data message reads the scale
of its channel and its own slot (the key's lookup) and shows Scale used, Value = Raw x scale
and Scale known; each sender's status per channel is learned, and a Data message whose
status differs from that sender's previous one raises lrn.finding.status_changed. The
expected values come from a model of the frames in order (the truth of the bytes): a scale
of 0 is not learned (the learn's if), a Configure cut short teaches nothing, a message never
reads what it teaches itself. The same values in one pass, with -2, and with -2 and a display
filter that keeps every third frame (later passes read what the first pass learned, at each
frame's place, in any order). Needs no corpus.

    test_learned.py --dissgen build/bin/dissgen --source-dir .
"""

import os
import random
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from pcapgen import raw_pcap_bytes  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

ETHERTYPE = 0x88C1
SENDERS = [b"\x02\0\0\0\0\x01", b"\x02\0\0\0\0\x02"]
FIELDS = ["frame.number", "lrn.data.scale_used", "lrn.data.value", "lrn.data.scale_known",
          "lrn.finding.status_changed"]


def frame(sender, payload):
    return b"\x02\0\0\0\0\xff" + sender + struct.pack("!H", ETHERTYPE) + payload


def configure(channel, slot, scale, cut=False):
    data = struct.pack("!BBBH", 1, channel, slot, scale)
    return data[:4] if cut else data


def data(channel, slot, status, raw):
    return struct.pack("!BBBBH", 2, channel, slot, status, raw)


def expected(messages):
    """{frame: (scale used, value, scale known, status changed)} of the Data frames, by a
    model of the protocol's rules: what each frame sees is what earlier frames taught."""
    scales, statuses, out = {}, {}, {}
    for number, (sender, kind, fields) in enumerate(messages, 1):
        if kind == "configure":
            channel, slot, scale, cut = fields
            if not cut and scale != 0:
                scales[(channel, slot)] = scale
            continue
        channel, slot, status, raw = fields
        scale = scales.get((channel, slot))
        before = statuses.get((sender, channel))
        out[number] = (scale, None if scale is None else raw * scale, scale is not None,
                       before is not None and before != status)
        statuses[(sender, channel)] = status
    return out


def scripted():
    """Each rule of the construct once, in order."""
    a, b = SENDERS
    return [
        (a, "data", (1, 2, 0, 5)),          # 1: nothing learned yet: no scale, no status before
        (a, "configure", (1, 2, 10, False)),  # 2: channel 1 slot 2 scale 10
        (a, "data", (1, 2, 0, 5)),          # 3: 50
        (a, "data", (1, 2, 1, 6)),          # 4: 60, status changed 0 -> 1
        (a, "configure", (1, 2, 0, False)),   # 5: scale 0: not learned (if)
        (a, "data", (1, 2, 1, 7)),          # 6: still 10: 70; status unchanged
        (a, "configure", (1, 2, 20, True)),   # 7: cut short: teaches nothing
        (a, "data", (1, 3, 1, 7)),          # 8: slot 3 was never configured
        (b, "data", (1, 2, 4, 1)),          # 9: another sender: its own status history
        (a, "configure", (1, 2, 30, False)),  # 10
        (a, "data", (1, 2, 1, 2)),          # 11: 60
        (b, "data", (1, 2, 5, 1)),          # 12: sender b's status changed 4 -> 5
        (a, "data", (2, 2, 1, 2)),          # 13: channel 2: another key
    ]


def random_messages(rng, count):
    out = []
    for _ in range(count):
        sender = rng.choice(SENDERS)
        channel, slot = rng.randrange(3), rng.randrange(3)
        if rng.random() < 0.2:
            out.append((sender, "configure", (channel, slot, rng.choice([0, rng.randrange(1, 100)]),
                                              rng.random() < 0.1)))
        else:
            out.append((sender, "data", (channel, slot, rng.randrange(3), rng.randrange(1000))))
    return out


def capture(messages):
    frames = []
    for sender, kind, fields in messages:
        frames.append(frame(sender, configure(*fields) if kind == "configure" else data(*fields)))
    return raw_pcap_bytes(frames)


class TestLearned(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "learned.xml"), "lrn")

    def decoded(self, path, two_pass, display_filter=None):
        rows = self.env.field_rows(path, FIELDS, two_pass, display_filter=display_filter)
        out = {}
        for n, r in rows.items():
            if not r["lrn.data.scale_known"]:
                continue  # not a Data message
            scale = int(r["lrn.data.scale_used"][0]) if r["lrn.data.scale_used"] else None
            value = int(r["lrn.data.value"][0]) if r["lrn.data.value"] else None
            known = r["lrn.data.scale_known"][0] in ("1", "True")
            out[n] = (scale, value, known, bool(r["lrn.finding.status_changed"]))
        return out

    def check_capture(self, name, messages):
        path = self.env.add_file(name, capture(messages))
        want = expected(messages)
        with self.checks() as check:
            self.check_every_pass(check, lambda two_pass, shown: self.decoded(path, two_pass, shown), want,
                                  "each Data frame reads what earlier frames taught")

    def test_each_rule_once(self):
        self.check_capture("scripted.pcap", scripted())

    def test_random_frames_against_a_model(self):
        rng = random.Random(20261129)
        self.check_capture("random.pcap", random_messages(rng, 400))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

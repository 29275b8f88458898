#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Values learned from earlier frames (<learn>, learned{Name}) with real tshark:
tests/rules/learned.xml on ethertype 0x88c1.

A Configure message teaches the scale of a (channel, slot); a Data message reads the scale
of its channel and its own slot (the key's lookup) and shows Scale used, Value = Raw x scale
and Scale known; each sender's status per channel is learned, and a Data message whose
status differs from that sender's previous one raises lrn.finding.status_changed.
TestLearnedPerConversation: a value learned with conversation="yes" is the TCP conversation's,
taught by either end and read by both (an MQTT-like version from the client's hello, read on
the server's replies), one per conversation however their frames interleave. The
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
from pcapgen import raw_pcap_bytes, tcp_ethernet_frame  # noqa: E402
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


SERVER = (b"\x0a\x00\x00\x64", 1883)
CLIENTS = [(b"\x0a\x00\x00\x01", 50001), (b"\x0a\x00\x00\x01", 50002), (b"\x0a\x00\x00\x02", 50001)]
CONVERSATION_RULES = """<root name="Versioned" abbreviation="VER" filter="ver">
  <hook table="tcp.port" value="1883"/>
  <node name="Kind" length="1byte" displaytype="numberdec"/>
  <node name="Hello" if="../node[@name='Kind']" in="1">
    <node name="Version" length="1byte" displaytype="numberdec"/>
    <learn name="Version" value="{Version}" conversation="yes"/>
  </node>
  <node name="Data" if="../node[@name='Kind']" in="2">
    <node name="Version used" value="learned{Version}"/>
    <node name="Version known" value="defined(learned{Version})"/>
  </node>
</root>
"""


def conversation_messages(rng, count):
    """(client, from the client?, version or None for a Data message), interleaved."""
    return [(rng.randrange(len(CLIENTS)), rng.random() < 0.5,
             rng.choice([3, 4, 5]) if rng.random() < 0.25 else None) for _ in range(count)]


def conversation_capture(messages):
    seqs, frames = {}, []
    for client, from_client, version in messages:
        (cip, cport), (sip, sport) = CLIENTS[client], SERVER
        ends = ((cip, cport), (sip, sport)) if from_client else ((sip, sport), (cip, cport))
        payload = bytes([1, version]) if version is not None else bytes([2])
        seq = seqs.get(ends, 1000)
        seqs[ends] = seq + len(payload)
        frames.append(tcp_ethernet_frame(payload, ends[0][1], ends[1][1], seq, ends[0][0], ends[1][0]))
    return raw_pcap_bytes(frames)


def conversation_expected(messages):
    """{frame: version used or None} of the Data frames: the latest hello of their
    conversation before them, whichever end sent it."""
    learned, out = {}, {}
    for number, (client, _from_client, version) in enumerate(messages, 1):
        if version is not None:
            learned[client] = version
        else:
            out[number] = learned.get(client)
    return out


class TestLearnedPerConversation(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install_text("conversation.xml", CONVERSATION_RULES, "ver")

    def decoded(self, path, two_pass, display_filter=None):
        rows = self.env.field_rows(path, ["frame.number", "ver.data.version_used", "ver.data.version_known"],
                                   two_pass, display_filter=display_filter)
        return {n: int(r["ver.data.version_used"][0]) if r["ver.data.version_used"] else None
                for n, r in rows.items() if r["ver.data.version_known"]}

    def check_capture(self, name, messages):
        path = self.env.add_file(name, conversation_capture(messages))
        with self.checks() as check:
            self.check_every_pass(check, lambda two_pass, shown: self.decoded(path, two_pass, shown),
                                  conversation_expected(messages),
                                  "each Data frame reads its own conversation's latest hello, from either end")

    def test_each_end_reads_what_the_other_taught(self):
        self.check_capture("conversations.pcap", [
            (0, True, None),   # 1: nothing learned yet
            (0, True, 5),      # 2: the client says 5
            (0, False, None),  # 3: the server's reply reads 5
            (1, False, None),  # 4: another conversation: nothing
            (1, True, 4),      # 5
            (0, False, None),  # 6: still 5
            (1, False, None),  # 7: 4
            (2, False, 3),     # 8: the server says 3 to the third client
            (2, True, None),   # 9: the client reads it
            (0, True, None),   # 10: 5
        ])

    def test_random_interleaving_against_a_model(self):
        self.check_capture("interleaved.pcap", conversation_messages(random.Random(20261203), 300))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""<cycles requests="yes"> with real tshark (tests/rules/polled_cycles.xml: a master
polling units over UDP, paired by transaction number, timed per unit and function).

Only requests are in streams; a period is regular only when the stream's previous request
was answered before this one was sent and this one is not a poll (sent less than that
round trip after the answer). Each request's poll.cycle, .period and .jitter, and
`-z poll,cycles` with its round trips, requests answered and unanswered, are checked
against the manual's rules computed here from the capture's bytes and timestamps, to the
nanosecond, in one pass and with -2, and the statistics tree row by row. The capture
holds: three streams at different periods, one starting mid-capture; round trips that
vary; a request never answered (a later one is: one unanswered); a response that comes
after the next request (that request's period is not regular); a stream's first request
answered only once the stream has become a cycle (its round trip is not the cycle's); a poll right after an
answer (not regular; the request after it is); the last request still in flight at the
end (not counted).

    test_polled_cycles.py --dissgen build/bin/dissgen --source-dir .
"""

import os
import random
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from pcapgen import ip_checksum  # noqa: E402
from cyclemodel import mark_fields, mark_of, model, parse_report, pcap_ns, quantiles, clamp  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402
from test_report_cycles import run_report, stage_report, table  # noqa: E402

PORT = 47481
MASTER, SLAVE = (10, 0, 0, 1), (10, 0, 0, 100)
MS, US = 10**6, 10**3


def frame(request, transaction, unit, function, data=0):
    """A message on the master's connection to `unit` (client port 40000 + unit)."""
    payload = struct.pack(">HBBI", transaction, unit, function, data)
    sport, dport = (40000 + unit, PORT) if request else (PORT, 40000 + unit)
    src, dst = (MASTER, SLAVE) if request else (SLAVE, MASTER)
    u = struct.pack("!HHHH", sport, dport, 8 + len(payload), 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0, bytes(src), bytes(dst))
    ip = ip[:10] + struct.pack("!H", ip_checksum(ip)) + ip[12:]
    return b"\x02\0\0\0\0\x64\x02\0\0\0\0\x01\x08\x00" + ip + u


def polled_capture(seed=47481):
    """[(time ns, frame)] of the polls described above, in time order."""
    rng = random.Random(seed)
    plan = [
        # unit, function, period, start, requests, round trip range, faults
        (1, 3, 10 * MS, 0, 60, (200 * US, 900 * US), {"unanswered": {30, 59}}),
        (2, 4, 25 * MS, 2 * MS, 24, (1 * MS, 3 * MS), {"poll": {12}}),
        (1, 16, 4 * MS, 150 * MS, 80, (100 * US, 400 * US), {"late": {50}, "very late": {0}}),
    ]
    events, transaction = [], 0
    for unit, function, period, start, count, (lo, hi), faults in plan:
        for i in range(count):
            t = 10**9 + start + i * period + rng.randint(-period // 50, period // 50)
            rtt = rng.randint(lo, hi)
            if i in faults.get("late", ()):
                rtt = period + period // 4  # after the next request
            if i in faults.get("very late", ()):
                rtt = 11 * period + period // 4  # after the stream became a cycle
            events.append((t, True, unit, function, rtt, i not in faults.get("unanswered", ())))
            if i in faults.get("poll", ()):  # asked again right after the answer
                events.append((t + rtt + 50 * US, True, unit, function, rng.randint(lo, hi), True))
    events.sort()
    packets = []
    for t, _request, unit, function, rtt, answered in events:
        transaction += 1
        packets.append((t, frame(True, transaction, unit, function)))
        if answered:
            packets.append((t + rtt, frame(False, transaction, unit, function, rtt)))
    packets.sort(key=lambda p: p[0])
    return packets


def requests_of(packets):
    """From the bytes: [(frame, time, (unit, function), transaction)] of the requests, and
    {transaction: (response frame, response time)}."""
    requests, responses = [], {}
    for number, (t, f) in enumerate(packets, 1):
        transaction, unit, function = struct.unpack(">HBB", f[42:46])
        if struct.unpack("!H", f[36:38])[0] == PORT:
            requests.append((number, t, (unit, function), transaction))
        else:
            responses[transaction] = (number, t)
    return requests, responses


def expected(packets):
    """The manual's rules: marks per request frame, and per cycle what -z poll,cycles adds
    (round trips, answered, unanswered)."""
    requests, responses = requests_of(packets)
    irregular, previous = set(), {}
    for frame_no, t, key, transaction in requests:
        if key in previous:
            before = previous[key]
            answer = responses.get(before[1])
            # answered before this request, and not asked again within that round trip
            if not answer or answer[0] > frame_no or t - answer[1] < answer[1] - before[0]:
                irregular.add(frame_no)
        previous[key] = (t, transaction)
    marks, cycles = model([(f, t, key, None) for f, t, key, _ in requests], window=8, bits=1, irregular=irregular)
    for c in cycles:
        marked = [r for r in requests if r[2] == c["stream"]["key"] and r[0] >= c["first"]]
        rtts, latest = [], 0
        for ordinal, (_f, t, _key, transaction) in enumerate(marked, 1):
            if transaction in responses:
                rtts.append(clamp(responses[transaction][1] - t))
                latest = ordinal
        c["round trip"], c["answered"], c["unanswered"] = quantiles(rtts), len(rtts), latest - len(rtts)
    return marks, cycles, irregular


class TestPolledCycles(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "polled_cycles.xml"), "poll")
        cls.packets = polled_capture()
        cls.capture = cls.env.add_file("polled.pcap", pcap_ns(cls.packets))
        cls.marks, cls.cycles, cls.irregular = expected(cls.packets)

    def test_the_capture_holds_the_faults(self):
        with self.checks() as check:
            check(len(self.cycles) == 3, "three cycles: %d" % len(self.cycles))
            check(sorted(c["unanswered"] for c in self.cycles) == [0, 0, 1], "one request unanswered, one in flight")
            # after the unanswered request, after each late answer, and the poll
            check(len(self.irregular) == 4, "irregular periods: %s" % sorted(self.irregular))

    def test_marks_follow_the_model(self):
        requests = {f for f, _t, _k, _x in requests_of(self.packets)[0]}
        with self.checks() as check:
            for two_pass in (False, True):
                how = "-2" if two_pass else "one pass"
                rows = self.env.field_rows(self.capture, ["frame.number"] + mark_fields("poll"), two_pass=two_pass)
                for frame_no, row in sorted(rows.items()):
                    got, want = mark_of(row, "poll"), self.marks.get(frame_no, {})
                    check(got == want, "%s frame %d (%s): %s, expected %s" % (
                        how, frame_no, "request" if frame_no in requests else "response", got, want))

    def test_report_and_statistics_tree(self):
        want = []
        for c in self.cycles:
            v = sorted(c["marked"])
            n = len(c["jitters"])
            mean = sum(map(float, c["jitters"])) / n if n else 0.0
            var = sum(float(j) * float(j) for j in c["jitters"]) / n - mean * mean if n else 0.0
            want.append({"first frame": c["first"], "messages": c["frames"],
                         "nominal": sorted(c["periods"])[(len(c["periods"]) - 1) // 2],
                         "period": quantiles(v), "jitter sd": "%.1f" % (var ** 0.5 if var > 0 else 0.0),
                         "round trip": c["round trip"], "answered": c["answered"], "unanswered": c["unanswered"]})
        with self.checks() as check:
            for two_pass in ([], ["-2"]):
                out = self.env.tshark(["-r", self.capture, "-q", "-z", "poll,cycles"] + two_pass).stdout
                got = parse_report(out)
                check([g["figures"] for g in got] == want, "%s -z poll,cycles:\n%s\nexpected %s" % (
                    two_pass, [g["figures"] for g in got], want))
                check([g["name"] for g in got] == ["Unit %d, Function %d" % c["stream"]["key"] for c in self.cycles],
                      "cycle names %s" % [g["name"] for g in got])
            out = self.env.tshark(["-2", "-r", self.capture, "-q", "-z", "poll.cycles,tree"]).stdout
            have = {}
            for line in out.splitlines():
                m = re.match(r"^\s*Cycle (\d+) (\S.*?)\s{2,}(\d+)\s", line)
                if m:
                    have[(int(m.group(1)), m.group(2))] = int(m.group(3))
            for number, w in enumerate(want, 1):
                for name, value in zip(("min", "median", "p99", "max"), w["round trip"] or ()):
                    check(have.get((number, "round trip %s (ns)" % name)) == value,
                          "tree: cycle %d round trip %s %s, expected %s" % (
                              number, name, have.get((number, "round trip %s (ns)" % name)), value))
                check(have.get((number, "requests answered")) == w["answered"], "tree: cycle %d answered" % number)
                check(have.get((number, "requests unanswered")) == w["unanswered"],
                      "tree: cycle %d unanswered" % number)

    def test_report_shows_the_round_trips(self):
        dissgen, out = stage_report(self.env, self.args.dissgen)
        p, page, _took = run_report(self.env, dissgen, out, self.capture, "polled")
        with self.checks() as check:
            check(p.returncode == 0, "dissgen report: %d %s" % (p.returncode, p.stderr.strip()))
            rows = table(page, "cycles")
            check(len(rows) == len(self.cycles), "%d rows, %d cycles" % (len(rows), len(self.cycles)))
            for row, c in zip(rows, self.cycles):
                trip = [str(v) for v in c["round trip"]] if c["round trip"] else ["none"] * 4
                check(row[-6:] == trip + [str(c["answered"]), str(c["unanswered"])],
                      "cycle %d: round trips and answers %s, expected %s" % (
                          c["number"], row[-6:], trip + [str(c["answered"]), str(c["unanswered"])]))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

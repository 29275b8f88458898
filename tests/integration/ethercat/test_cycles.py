#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""EtherCAT cycles: ecatr.cycle, ecatr.cycle.period and ecatr.cycle.jitter on the frames sent,
and tshark -z ecatr,cycles, against a computation of this script's own.

  test_cycles.py --dissgen build/bin/dissgen --source-dir . [--corpus DIR]

The reference below applies the manual's definition ("Cycles" in the EtherCAT analysis) to the
frames' bytes and timestamps as the capture file holds them (which frame answers which comes
from tshark's ecatr.request_in); every period, jitter and round trip is compared to the
nanosecond, every frame's cycle number exactly, in one pass and with -2 (which must agree).
The -z ecatr,cycles figures are compared with the same computation.

Generated captures: two tasks (1 ms LRW + FRMW 0x0910, 10 ms LRW to another logical address)
with known injected jitter; the same with gaps (frames not captured) and lost returns; a
mailbox exchange and a back-to-back status poll that must not become cycles; returns that come
after 16 other frames were sent; a capture that starts mid-flight (a return first). The rule
file's <cycles> decides what is timed: without its <never> and with window="2" the mailbox is
cyclic from its third frame; without <cycles>, nothing is. Then every capture of the corpus (../shared/corpus/ethercat,
or --corpus DIR; skipped when absent).
"""

import os
import random
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, corpus_captures, relative_time_ns, run_unittests  # noqa: E402
from cyclemodel import tree_unit, tree_value  # noqa: E402
import pcaprewrite as pr  # noqa: E402
from test_losses import ecat_frame, generated as write_pcap, returned  # noqa: E402

ARGS = None
MASTER = bytes.fromhex("00a0de000001")
T0 = 1_700_000_000 * 10**9
WINDOW = 8

FIELDS = ["frame.number", "ecatr.request_in", "ecatr.response_in", "ecatr.no_request", "ecatr.expert.duplicate",
          "ecatr.time", "ecatr.cycle", "ecatr.cycle.period", "ecatr.cycle.jitter", "ecatr.dc.systime",
          "ecatr.dc.drift"]


# ----------------------------------------------------------------------------- generated captures

def jitter_ns(n, amplitude):
    """A known, irregular offset: a fixed pseudo-random sequence in [-amplitude, amplitude]."""
    return random.Random(n).randint(-amplitude, amplitude)


DC_PPM = 50


def dc_time(t):
    """The reference clock's system time at capture time t: 10^12 ns at T0, DC_PPM fast."""
    return 10**12 + (t - T0) * (10**6 + DC_PPM) // 10**6


def two_tasks(cycles=300, drop_frames=(), drop_returns=(), wkc_short=()):
    """Task A every 1 ms (LRW 0x00010000 + FRMW 0x0910), task B every 10 ms (LRW 0x00020000),
    each with its own index and +-20 us of jitter; returns after 40-60 us. drop_frames: task A
    cycles not captured at all; drop_returns: task A cycles whose return is missing;
    wkc_short: task A cycles returned with a working counter 1 short."""
    events = []
    for n in range(cycles):
        t = T0 + n * 1_000_000 + jitter_ns(n, 20_000)
        dgs = [(12, 0x10, 0x0000, 0x0001, bytes([n & 0xFF, 0, 0, 0]), 0),
               (14, 0x10, 0x1001, 0x0910, b"\0" * 8, 0)]
        if n not in drop_frames:
            events.append((t, ecat_frame(MASTER, dgs)))
            if n not in drop_returns:
                t_back = t + 40_000 + jitter_ns(n + 7, 10_000)
                # the reference clock's time: 50 ppm fast against the capture's clock
                back = [dgs[0], dgs[1][:4] + (struct.pack("<Q", dc_time(t_back - 20_000)),) + dgs[1][5:]]
                events.append((t_back, returned(MASTER, back, 2 if n in wkc_short else 3)))
        if n % 10 == 3:
            tb = T0 + n * 1_000_000 + 500_000 + jitter_ns(n + 3, 50_000)
            dgb = [(12, 0x20, 0x0000, 0x0002, b"\0" * 6, 0)]
            events.append((tb, ecat_frame(MASTER, dgb)))
            events.append((tb + 35_000, returned(MASTER, dgb, 3)))
    events.sort(key=lambda e: e[0])
    return [pr.Packet(d, t) for t, d in events]


def mailbox_and_polls(rounds=200):
    """Every millisecond: a mailbox write (FPWR 0x1000), a poll of SM1's status (FPRD 0x080D)
    and a mailbox read (FPRD 0x1100); after them an AL status poll (FPRD 0x0130) sent 12
    times, each 10 us after the previous one's return (back to back): none of them is a cycle."""
    packets, t = [], T0
    for n in range(rounds):
        base = T0 + n * 1_000_000
        for k, (cmd, ado, size) in enumerate([(5, 0x1000, 128), (4, 0x080D, 1), (4, 0x1100, 128)]):
            dgs = [(cmd, 0x30 + k, 0x1001, ado, b"\0" * size, 0)]
            packets.append(pr.Packet(ecat_frame(MASTER, dgs), base + k * 100_000))
            packets.append(pr.Packet(returned(MASTER, dgs, 1), base + k * 100_000 + 30_000))
        for k in range(12):
            t = base + 400_000 + k * 40_000
            dgs = [(4, 0x40, 0x1001, 0x0130, b"\0\0", 0)]
            packets.append(pr.Packet(ecat_frame(MASTER, dgs), t))
            packets.append(pr.Packet(returned(MASTER, dgs, 1), t + 30_000))
    packets.sort(key=lambda p: p.ts)
    return packets


def late_returns(cycles=40):
    """Task A (LRW 0x00010000) every 1 ms, each frame back only after 16 other frames were sent
    (reads of an AL status that no slave answers), so that 17 frames sent lie between a frame
    and its return: the return still finds its frame's signature, and task A is a cycle."""
    packets = []
    for n in range(cycles):
        t = T0 + n * 1_000_000
        dgs = [(12, 0x10, 0x0000, 0x0001, bytes([n & 0xFF, 0, 0, 0]), 0)]
        packets.append(pr.Packet(ecat_frame(MASTER, dgs), t))
        for k in range(16):
            poll = [(4, 0x50 + k, 0x1001 + k, 0x0130, b"\0\0", 0)]
            packets.append(pr.Packet(ecat_frame(MASTER, poll), t + 10_000 + k * 10_000))
        packets.append(pr.Packet(returned(MASTER, dgs, 1), t + 300_000))
    return packets


def mid_flight(cycles=100):
    """Task A of two_tasks, the capture starting with the return of a frame it does not hold."""
    packets = two_tasks(cycles)
    first_return = next(i for i, p in enumerate(packets) if p.data[6] & 0x02)
    return packets[first_return:]


# ----------------------------------------------------------------------------- the reference

def ns_of(cap, pkt):
    if cap.kind == "pcap":
        return pkt.ts
    units = cap.units.get(pkt.ifid, 10**6)
    return pkt.ts * 10**9 // units


def overlaps(ado, length, lo, hi):
    return ado <= hi and ado + length > lo


def eligible(sig):
    """Neither a mailbox transfer nor what only a start-up does (the manual's list)."""
    if not sig:
        return False
    for cmd, _adp, ado, length in sig:
        if cmd == 0 or 10 <= cmd <= 12:
            continue
        if (ado + length > 0x1000 or overlaps(ado, length, 0x0805, 0x0805) or overlaps(ado, length, 0x080D, 0x080D)
                or overlaps(ado, length, 0x0500, 0x050F) or overlaps(ado, length, 0x0900, 0x090F)):
            return False
    return True


def lower_median(values):
    s = sorted(values)
    return s[(len(s) - 1) // 2]


def p99(values):
    s = sorted(values)
    return s[-(-99 * len(s) // 100) - 1]


def is_request(r):
    return not (r["ecatr.request_in"] or r["ecatr.no_request"] or r["ecatr.expert.duplicate"])


class Reference:
    """The cycles of a capture by the manual's rules: per sent frame (cycle, period, jitter),
    per cycle its whole-capture figures."""

    def __init__(self, cap, rows):
        self.marks = {}
        self.cycles = []
        sigs = {}
        sig_of_frame = {}
        times = {}
        for num, pkt in enumerate(cap.packets, 1):
            if num not in rows:
                continue
            r = rows[num]
            t = ns_of(cap, pkt)
            times[num] = t
            dgs = pr.ecat_datagrams(pkt)
            if is_request(r):
                sig = tuple((d["cmd"], d["adp"], d["ado"], d["length"]) for d in dgs)
                sig_of_frame[num] = (sig, dgs)
                self.sent(sigs, sig, num, t)
            elif r["ecatr.request_in"]:
                req = int(r["ecatr.request_in"][0])
                sig, sent_dgs = sig_of_frame[req]
                if len(sent_dgs) != len(dgs):
                    continue   # the frame changed length: the analysis compares nothing
                self.returned(sigs, sig, req, times[req], t, sent_dgs, dgs)

    def sent(self, sigs, sig, num, t):
        s = sigs.setdefault(sig, {"eligible": eligible(sig), "last": None, "answered": None, "ret": None,
                                  "rtt": None, "recent": [], "cycle": None})
        if not s["eligible"]:
            return
        previous, previous_t = s["last"] or (None, None)
        s["last"] = (num, t)
        if previous is None:
            return
        period = t - previous_t
        c = s["cycle"]
        if c is None:
            answered = s["answered"] == previous
            poll = answered and t - s["ret"] < s["rtt"]
            if period <= 0 or not answered or poll:
                s["recent"] = []
                return
            s["recent"] = (s["recent"] + [period])[-WINDOW:]
            if len(s["recent"]) < WINDOW:
                return
            m = lower_median(s["recent"])
            if m == 0 or m > 2**32 - 1 or 2 * min(s["recent"]) < m or 2 * max(s["recent"]) > 3 * m:
                return
            c = {"number": len(self.cycles) + 1, "sig": sig, "periods": list(s["recent"][:-1]), "first": num,
                 "frames": [], "rtts": [], "answered": set(), "wkc_high": [0] * len(sig), "wkc_errors": 0}
            s["cycle"] = c
            self.cycles.append(c)
        period = max(0, period)   # timestamps that went backwards: 0
        c["periods"].append(period)
        nominal = lower_median(c["periods"])
        self.marks[num] = (c["number"], period, period - nominal)
        c["frames"].append(num)

    def returned(self, sigs, sig, req, t_req, t, sent_dgs, back_dgs):
        s = sigs.get(sig)
        if not s or not s["eligible"]:
            return
        rtt = t - t_req
        if s["answered"] is None or req >= s["answered"]:
            s["answered"], s["ret"], s["rtt"] = req, t, rtt
        c = s["cycle"]
        if c is None or req < c["first"]:
            return
        c["rtts"].append(max(0, rtt))
        c["answered"].add(req)
        error = False
        for i, (a, b) in enumerate(zip(sent_dgs, back_dgs)):
            if b["wkc"] <= a["wkc"] or b["wkc"] < c["wkc_high"][i]:
                error = True
            c["wkc_high"][i] = max(c["wkc_high"][i], b["wkc"])
        c["wkc_errors"] += error

    def figures(self, c):
        """What -z ecatr,cycles prints for cycle c."""
        periods = [self.marks[f][1] for f in c["frames"]]
        jitters = [self.marks[f][2] for f in c["frames"]]
        mean = sum(jitters) / len(jitters)
        sd = max(0.0, sum(j * j for j in jitters) / len(jitters) - mean * mean) ** 0.5
        last_answered = max(c["answered"]) if c["answered"] else 0
        lost = sum(1 for f in c["frames"] if f not in c["answered"] and f < last_answered)
        return {"frames": len(c["frames"]), "nominal": lower_median(c["periods"]),
                "period": (min(periods), lower_median(periods), p99(periods), max(periods)),
                "sd": sd, "round trip": (min(c["rtts"]), lower_median(c["rtts"]), p99(c["rtts"]), max(c["rtts"]))
                if c["rtts"] else None, "returned": len(c["answered"]), "lost": lost,
                "wkc": c["wkc_errors"]}


def dc_reference(cap, rows):
    """{returned frame: (system time, drift in ns/s or None)}: the first FRMW/ARMW of 4 or 8
    bytes at 0x0910 that a slave processed, its data as returned; the drift against the
    capture's first such time of the same width, the 32-bit ones unwrapped to the value
    nearest the capture time elapsed."""
    out, first = {}, {}
    for num, r in sorted(rows.items()):
        if not r["ecatr.request_in"]:
            continue
        pkt = cap.packets[num - 1]
        sent = pr.ecat_datagrams(cap.packets[int(r["ecatr.request_in"][0]) - 1])
        back = pr.ecat_datagrams(pkt)
        for s, b in zip(sent, back):
            if (s["cmd"] in (13, 14) and s["ado"] == 0x0910 and s["length"] in (4, 8) and b["cmd"] == s["cmd"]
                    and b["ado"] == s["ado"] and b["length"] == s["length"] and b["wkc"] > s["wkc"]):
                size = b["length"]
                raw = int.from_bytes(bytes(pkt.data[b["data_offset"]:b["data_offset"] + size]), "little")
                t = ns_of(cap, pkt)
                if size not in first:
                    first[size] = (raw, t)
                    out[num] = (raw, None)
                    break
                raw0, t0 = first[size]
                elapsed = t - t0
                if size == 8:
                    dc = raw - raw0
                else:
                    low = (raw - raw0) % 2**32
                    dc = low + ((elapsed - low + 2**31) >> 32 << 32)
                out[num] = (raw, (dc - elapsed) * 1e9 / elapsed if elapsed > 0 else None)
                break
    return out


def parse_tree(text):
    """tshark -2 -z ecatr.cycles,tree: {(cycle, row name): count}."""
    out = {}
    for line in text.splitlines():
        m = re.match(r"^\s*Cycle (\d+) (\S.*?)\s{2,}(\d+)\s", line)
        if m:
            out[(int(m.group(1)), m.group(2))] = int(m.group(3))
    return out


def tree_rows(number, stats):
    """What the statistics tree shows for a cycle of -z ecatr,cycles."""
    largest = max([stats["nominal period"]] + [max(stats.get(w) or (0,)) for w in ("period", "round trip")])
    unit, scale = tree_unit(largest)
    rows = {(number, "frames"): stats["frames"],
            (number, "nominal period (%s)" % unit): tree_value(stats["nominal period"], scale),
            (number, "jitter std dev (%s)" % unit): tree_value(int(stats["jitter std dev"] + 0.5), scale),
            (number, "frames returned"): stats["frames returned"], (number, "frames lost"): stats["frames lost"],
            (number, "working counter errors"): stats["working counter errors"]}
    for what in ("period", "round trip"):
        for name, value in zip(("min", "median", "p99", "max"), stats.get(what) or ()):
            rows[(number, "%s %s (%s)" % (what, name, unit))] = tree_value(value, scale)
    return rows


def parse_cycles(text):
    """-z ecatr,cycles: {cycle number: figures}."""
    out, cur = {}, None
    for line in text.splitlines():
        m = re.match(r"Cycle (\d+): (.*)", line)
        if m:
            cur = out.setdefault(int(m.group(1)), {"signature": m.group(2)})
            continue
        m = re.match(r"  (.*?)(?: \(ns\))?: (.*)", line)
        if cur is None or not m:
            continue
        key, value = m.group(1), m.group(2)
        if key.endswith("min/median/p99/max"):
            cur[key.split(" min/")[0]] = tuple(int(v) for v in value.split())
        elif value == "none":
            cur[key] = None
        else:
            cur[key] = float(value) if "." in value else int(value)
    return out


# ----------------------------------------------------------------------------- the checks

class TestCycles(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("rules", "ethercat.xml"), "ecatr")
        cls.corpus_dir = ARGS.corpus or os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus",
                                                     "ethercat")

    def decode(self, path):
        """(rows of -2, rows of one pass, -z ecatr,cycles output), rows of EtherCAT frames only."""
        two = self.env.field_rows(path, FIELDS, two_pass=True, display_filter="ecatr")
        one = self.env.field_rows(path, FIELDS, display_filter="ecatr")
        z = self.env.tshark(["-r", path, "-q", "-z", "ecatr,cycles"]).stdout
        tree = self.env.tshark(["-2", "-r", path, "-q", "-z", "ecatr.cycles,tree"]).stdout
        return two, one, z, tree

    def check_capture(self, check, name, path, expect_cycles=None):
        """Every sent frame's cycle fields against the reference, one pass against two, -z
        against both. Returns the reference."""
        two, one, z, tree = self.decode(path)
        cap = pr.Capture.read(path)
        ref = Reference(cap, two)
        got = {}
        for num, r in two.items():
            if r["ecatr.cycle"]:
                got[num] = (int(r["ecatr.cycle"][0]), relative_time_ns(r["ecatr.cycle.period"][0]),
                            relative_time_ns(r["ecatr.cycle.jitter"][0]))
        wrong = [n for n in set(got) | set(ref.marks) if got.get(n) != ref.marks.get(n)]
        check(not wrong, "%s: %d frames marked, each cycle, period and jitter as computed to the ns%s" % (
            name, len(got), "" if not wrong else " (first wrong: frame %d: got %s, computed %s)" % (
                min(wrong), got.get(min(wrong)), ref.marks.get(min(wrong)))))
        check(all(is_request(two[n]) for n in got), "%s: only frames sent carry the cycle fields" % name)
        cyc = ("ecatr.cycle", "ecatr.cycle.period", "ecatr.cycle.jitter")
        differ = [n for n in two if any(two[n][f] != one.get(n, {}).get(f) for f in cyc)]
        check(not differ, "%s: one pass shows the same cycle fields as -2%s" % (
            name, "" if not differ else " (first differing frame %d)" % min(differ)))
        rtt_wrong = [n for n, r in two.items() if r["ecatr.request_in"] and r["ecatr.time"] and
                     relative_time_ns(r["ecatr.time"][0]) != ns_of(cap, cap.packets[n - 1]) -
                     ns_of(cap, cap.packets[int(r["ecatr.request_in"][0]) - 1])]
        check(not rtt_wrong, "%s: every round trip (ecatr.time) is the timestamps' difference to the ns" % name)
        stats = parse_cycles(z)
        check(sorted(stats) == [c["number"] for c in ref.cycles],
              "%s: -z ecatr,cycles lists cycles %s (computed %s)" % (name, sorted(stats),
                                                                     [c["number"] for c in ref.cycles]))
        want_tree = {}
        for number, figures in stats.items():
            want_tree.update(tree_rows(number, figures))
        have_tree = parse_tree(tree)
        differ = [k for k in set(have_tree) | set(want_tree) if k not in have_tree or k not in want_tree or
                  abs(have_tree[k] - want_tree[k]) > (1 if k[1].startswith("jitter") else 0)]  # sd: rounding
        check(not differ, "%s: the statistics tree (-2 -z ecatr.cycles,tree) shows the same figures as "
              "-z ecatr,cycles (%d rows)%s" % (name, len(want_tree), "" if not differ else " (differ: %s)" % differ))
        for c in ref.cycles:
            want, have = ref.figures(c), stats.get(c["number"], {})
            label = "%s cycle %d" % (name, c["number"])
            check(have.get("frames") == want["frames"], "%s: frames %s = %s" % (label, have.get("frames"),
                                                                             want["frames"]))
            check(have.get("nominal period") == want["nominal"], "%s: nominal period %s = %s" % (
                label, have.get("nominal period"), want["nominal"]))
            check(have.get("period") == want["period"], "%s: period min/median/p99/max %s = %s" % (
                label, have.get("period"), want["period"]))
            check(abs(have.get("jitter std dev", -1) - want["sd"]) <= 0.05 + 1e-9 * want["sd"],
                  "%s: jitter std dev %s = %.1f" % (label, have.get("jitter std dev"), want["sd"]))
            check(have.get("round trip") == want["round trip"], "%s: round trip min/median/p99/max %s = %s" % (
                label, have.get("round trip"), want["round trip"]))
            check(have.get("frames returned") == want["returned"], "%s: frames returned %s = %s" % (
                label, have.get("frames returned"), want["returned"]))
            check(have.get("frames lost") == want["lost"], "%s: frames lost %s = %s" % (
                label, have.get("frames lost"), want["lost"]))
            check(have.get("working counter errors") == want["wkc"], "%s: working counter errors %s = %s" % (
                label, have.get("working counter errors"), want["wkc"]))
            print("   %s: %s; %d frames, nominal %d ns, period %s ns, jitter sd %.1f ns, round trip %s ns, "
                  "lost %d, wkc errors %d" % (label, have.get("signature"), want["frames"], want["nominal"],
                                              "/".join(map(str, want["period"])), want["sd"],
                                              "/".join(map(str, want["round trip"] or ())), want["lost"],
                                              want["wkc"]))
        dc = dc_reference(cap, two)
        got_dc = {n: (int(r["ecatr.dc.systime"][0]), float(r["ecatr.dc.drift"][0]) if r["ecatr.dc.drift"] else None)
                  for n, r in two.items() if r["ecatr.dc.systime"]}
        bad = [n for n in set(dc) | set(got_dc) if n not in dc or n not in got_dc or dc[n][0] != got_dc[n][0] or
               (dc[n][1] is None) != (got_dc[n][1] is None) or
               (dc[n][1] is not None and abs(dc[n][1] - got_dc[n][1]) > 1e-6 * max(1.0, abs(dc[n][1])))]
        check(not bad, "%s: %d returned frames carry the DC system time as returned and its drift as computed%s" % (
            name, len(got_dc), "" if not bad else " (first wrong: frame %d: got %s, computed %s)" % (
                min(bad), got_dc.get(min(bad)), dc.get(min(bad)))))
        dc_one = {n: (r["ecatr.dc.systime"], r["ecatr.dc.drift"]) for n, r in one.items() if r["ecatr.dc.systime"]}
        check(dc_one == {n: (two[n]["ecatr.dc.systime"], two[n]["ecatr.dc.drift"]) for n in got_dc},
              "%s: one pass shows the same DC fields as -2" % name)
        if expect_cycles is not None:
            check(len(ref.cycles) == expect_cycles, "%s: %d cycles found, %d expected" % (
                name, len(ref.cycles), expect_cycles))
        return ref, two, cap

    def generated(self, name, packets):
        path = self.env.path(name + ".pcap")
        write_pcap(path, packets)
        os.chmod(path, 0o644)
        return path

    def test_two_tasks_with_known_jitter(self):
        path = self.generated("two-tasks", two_tasks())
        with self.checks() as check:
            ref, two, cap = self.check_capture(check, "two tasks", path, expect_cycles=2)
            a, b = ref.cycles
            check(a["sig"][0][3] == 4 and b["sig"][0][3] == 6,
                  "cycle 1 is the 1 ms task (first to appear), cycle 2 the 10 ms one")
            check(len(a["frames"]) == 300 - WINDOW and len(b["frames"]) == 30 - WINDOW,
                  "every frame from each task's 9th on is marked (%d, %d)" % (len(a["frames"]), len(b["frames"])))
            # the injected offsets, independently of the capture: period n = 1 ms + j(n) - j(n-1)
            want = [1_000_000 + jitter_ns(n, 20_000) - jitter_ns(n - 1, 20_000) for n in range(WINDOW, 300)]
            have = [ref.marks[f][1] for f in a["frames"]]
            check(have == want, "task A's periods are 1 ms plus the injected jitter's differences")
            drifts = [float(r["ecatr.dc.drift"][0]) for n, r in two.items()
                      if r["ecatr.dc.drift"] and ns_of(cap, cap.packets[n - 1]) - T0 > 10**8]
            check(drifts and all(abs(d - DC_PPM * 1000) < 20 for d in drifts),
                  "the DC drift is the injected %d ppm (%d ns/s) after 0.1 s (%s .. %s)" % (
                      DC_PPM, DC_PPM * 1000, min(drifts or [0]), max(drifts or [0])))
            check(lower_median(a["periods"]) == lower_median(
                [1_000_000 + jitter_ns(n, 20_000) - jitter_ns(n - 1, 20_000) for n in range(1, 300)]),
                "task A's nominal period is the median of its periods")

    def test_gaps_and_lost_returns(self):
        drop = {100, 200, 201, 202}
        path = self.generated("gaps", two_tasks(drop_frames=drop, drop_returns={50, 150, 299}, wkc_short={120}))
        with self.checks() as check:
            ref, two, cap = self.check_capture(check, "gaps", path, expect_cycles=2)
            a = ref.cycles[0]
            marks = [ref.marks[f] for f in a["frames"]]
            big = sorted(round(p / 1_000_000) for _c, p, _j in marks if p > 1_500_000)
            check(big == [2, 4], "the gaps show as periods of 2 ms and 4 ms (%s)" % big)
            f = ref.figures(a)
            check(f["lost"] == 2 and f["wkc"] == 1, "2 returns lost (the last one, in flight at the end, is "
                  "not), 1 working counter short (%d, %d)" % (f["lost"], f["wkc"]))

    def test_mailbox_and_polls_are_not_cycles(self):
        path = self.generated("mailbox", mailbox_and_polls())
        with self.checks() as check:
            ref, two, cap = self.check_capture(check, "mailbox", path, expect_cycles=0)
            check(not any(r["ecatr.cycle"] for r in two.values()), "no frame carries ecatr.cycle")

    def test_returns_after_many_frames_sent(self):
        path = self.generated("late-returns", late_returns())
        with self.checks() as check:
            ref, two, cap = self.check_capture(check, "late returns", path, expect_cycles=1)
            check(len(ref.cycles[0]["frames"]) == 40 - WINDOW,
                  "task A is a cycle from its 9th frame, its returns 17 frames sent later (%d marked)" % len(
                      ref.cycles[0]["frames"]))

    def test_capture_starting_mid_flight(self):
        path = self.generated("mid-flight", mid_flight())
        with self.checks() as check:
            ref, two, cap = self.check_capture(check, "mid-flight", path, expect_cycles=2)
            first = min(n for n, r in two.items() if r["ecatr.cycle"])
            sent_before = sum(1 for n, r in two.items() if n < first and is_request(r) and
                              pr.ecat_datagrams(cap.packets[n - 1])[0]["adp"] == 0x0000 and
                              pr.ecat_datagrams(cap.packets[n - 1])[0]["ado"] == 0x0001)
            check(sent_before == WINDOW, "the first marked frame is task A's 9th sent (%d before)" % sent_before)

    def test_corpus(self):
        files = corpus_captures(self.corpus_dir)
        if not files:
            self.skipTest("no corpus at %s" % self.corpus_dir)
        with self.checks() as check:
            for f in files:
                path = self.env.readable(os.path.join(self.corpus_dir, f))
                self.check_capture(check, f, path)


def shipped_rules():
    with open(os.path.join(ARGS.source_dir, "rules", "ethercat.xml"), encoding="utf-8") as f:
        return f.read()


def shipped_rules_changed(old, new):
    """rules/ethercat.xml with `old` (once in it) replaced by `new`."""
    text = shipped_rules()
    if text.count(old) != 1:
        raise AssertionError("rules/ethercat.xml no longer holds %r once" % old)
    return text.replace(old, new)


NEVER = "<never field=\"node[@name='Datagrams']/node[@name='Datagram']/node[@name='Not cyclic']\"/>"


class TestCyclesAsDeclared(TsharkTestCase, unittest.TestCase):
    """What the analysis times is what the rule file's <cycles> says: without its <never>
    the mailbox traffic is cyclic, its window decides the first marked frame."""
    @classmethod
    def prepare(cls):
        rules = shipped_rules_changed(NEVER, "").replace("<cycles>", "<cycles window=\"2\">", 1)
        cls.install_text("ethercat-window-2.xml", rules, "ecatr")

    def test_mailbox_traffic_cyclic_from_its_third_frame(self):
        path = self.env.path("mailbox.pcap")
        write_pcap(path, mailbox_and_polls(rounds=20))
        os.chmod(path, 0o644)
        rows = self.env.field_rows(path, FIELDS, two_pass=True, display_filter="ecatr")
        cap = pr.Capture.read(path)
        with self.checks() as check:
            by_ado = {}
            for n, r in sorted(rows.items()):
                if is_request(r):
                    ado = pr.ecat_datagrams(cap.packets[n - 1])[0]["ado"]
                    by_ado.setdefault(ado, []).append(r["ecatr.cycle"][0] if r["ecatr.cycle"] else None)
            for ado in (0x1000, 0x080D, 0x1100):
                marks = by_ado.get(ado, [])
                check(marks[:2] == [None, None] and len(marks) == 20 and None not in marks[2:] and
                      len(set(marks[2:])) == 1,
                      "FPxx 0x%04x every ms: one cycle from its 3rd frame on (window 2, no <never>): %s" % (
                          ado, marks[:4]))
            polls = by_ado.get(0x0130, [])
            check(len(polls) == 240 and not any(polls),
                  "the AL status polls, sent again as soon as back, are in no cycle (%d)" % len(polls))
            z = parse_cycles(self.env.tshark(["-r", path, "-q", "-z", "ecatr,cycles"]).stdout)
            check(sorted(z) == [1, 2, 3], "-z ecatr,cycles lists 3 cycles (%s)" % sorted(z))


class TestCyclesUndeclared(TsharkTestCase, unittest.TestCase):
    """The analysis with no <cycles> in the rule file times nothing."""
    @classmethod
    def prepare(cls):
        text = shipped_rules()
        start, end = text.index("  <cycles>"), text.index("</cycles>") + len("</cycles>")
        cls.install_text("ethercat-no-cycles.xml", text[:start] + text[end:], "ecatr")

    def test_no_cycle_without_the_declaration(self):
        path = self.env.path("two-tasks.pcap")
        write_pcap(path, two_tasks(cycles=50))
        os.chmod(path, 0o644)
        rows = self.env.field_rows(path, FIELDS, two_pass=True, display_filter="ecatr")
        with self.checks() as check:
            check(len(rows) > 100 and not any(r["ecatr.cycle"] for r in rows.values()),
                  "no frame of %d carries ecatr.cycle" % len(rows))
            z = self.env.tshark(["-r", path, "-q", "-z", "ecatr,cycles"]).stdout
            check("No cycles" in z, "-z ecatr,cycles says: No cycles")


def add_arguments(parser):
    parser.add_argument("--corpus", help="the EtherCAT captures (default ../shared/corpus/ethercat)")


if __name__ == "__main__":
    sys.exit(run_unittests(add_arguments)[1])

#!/usr/bin/env python3
"""EtherCAT figures against each other and against the bytes: the statistics tree and the
round trip, on every capture of ../shared/corpus/ethercat and on a generated capture with
faults, with real tshark.

1. Statistics (`tshark -q -z ecatr,tree`, one pass and -2): every row of "Requests and
   responses" equals a count of the fields and expert infos tshark -2 -T fields shows:
     Requests            the other frames with a datagram index (a pairing key): answered,
                         lost, or still in flight when the capture ends
     Responses           frames with ecatr.request_in
     No response         ecatr.expert.no_response
     Duplicates          ecatr.expert.duplicate
     Responses to requests not captured
                         ecatr.no_request
     Round trip (ms)     count, average, minimum and maximum of ecatr.time
     Working counter per command (returned)
                         the returned datagrams compared (one ecatr.esc.wkc_added each), per
                         command (ecatr.datagram.cmd) and per working counter
                         (ecatr.datagram.wkc) under it
     Working counter went down
                         ecatr.expert.wkc_down, each occurrence (and the negative
                         ecatr.esc.wkc_added)
     Unexpected working counter
                         ecatr.expert.wkc, each occurrence
2. Round trip: on every returned frame, one pass and -2, ecatr.time is the frame's timestamp
   minus that of the frame ecatr.request_in names, to the nanosecond, the timestamps read from
   the capture file here (pcaprewrite.py). The generated capture has nanosecond timestamps
   and round trips that are not whole microseconds.

The generated capture (pairs of every command, with 1..3 datagrams): returns lost, captured
twice, without a captured request, out of order, working counters that came back lower and
unchanged. Without the corpus the generated capture is checked and the corpus test is
reported skipped.

    test_ecat_figures.py --dissgen build/bin/dissgen --source-dir . [--corpus DIR]
"""
import os
import struct
import sys
import unittest
from decimal import Decimal

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import pcapgen as pg  # noqa: E402
import pcaprewrite as pr  # noqa: E402
from tshark_env import TsharkTestCase, corpus_captures, run_unittests  # noqa: E402

FIELDS = ["frame.number", "ecatr.response_in", "ecatr.no_request", "ecatr.request_in", "ecatr.time", "ecatr.expert.no_response",
          "ecatr.expert.duplicate", "ecatr.expert.wkc_down", "ecatr.expert.wkc", "ecatr.datagram.idx",
          "ecatr.datagram.cmd", "ecatr.datagram.wkc", "ecatr.esc.wkc_added"]
MASTER = b"\x00\x1b\x21\x3c\x55\x10"
RETURNED = bytes([MASTER[0] | 0x02]) + MASTER[1:]
ARGS = None


# ----------------------------------------------------------------------------- tshark's view

def decode(env, path, two_pass):
    """{frame number: {field: [values]}}."""
    return env.field_rows(path, FIELDS, two_pass)


def stats_tree(env, path, two_pass):
    """{path of labels: [count, average, min, max]} of the rows under "Requests and responses"."""
    out = env.tshark(["-r", path, "-q", "-z", "ecatr,tree"] + (["-2"] if two_pass else [])).stdout.splitlines()
    header = next(line for line in out if line.startswith("Topic / Item"))
    width = header.index("Count")
    rows, inside, stack = {}, False, []
    for line in out:
        label = line[:width].rstrip()
        if line.startswith("Requests and responses"):
            inside = True
            continue
        if not inside:
            continue
        if not line.startswith(" ") or not label.strip():
            break
        depth = len(label) - len(label.lstrip(" "))
        stack[depth - 1:] = [label.strip()]
        rows[tuple(stack)] = line[width:].split()
    return rows


# ----------------------------------------------------------------------------- the figures

def figures(rows):
    """What the statistics must say, from the fields: {path: count}, and the round trips (ms)."""
    f = {}

    def add(path, n=1):
        f[path] = f.get(path, 0) + n

    for path in [("Requests",), ("Responses",), ("No response",), ("Duplicates",),
                 ("Responses to requests not captured",), ("Working counter per command (returned)",),
                 ("Working counter went down",), ("Unexpected working counter",)]:
        f[path] = 0
    times = []
    for r in rows.values():
        response = bool(r["ecatr.request_in"])
        duplicate = bool(r["ecatr.expert.duplicate"])
        orphan = bool(r["ecatr.no_request"])
        request = bool(r["ecatr.datagram.idx"]) and not (response or duplicate or orphan)
        add(("Requests",), request)
        add(("Responses",), response)
        add(("No response",), bool(r["ecatr.expert.no_response"]))
        add(("Duplicates",), duplicate)
        add(("Responses to requests not captured",), orphan)
        add(("Working counter went down",), len(r["ecatr.expert.wkc_down"]))
        add(("Unexpected working counter",), len(r["ecatr.expert.wkc"]))
        if response:
            times += [float(t) * 1000 for t in r["ecatr.time"]]
            compared = len(r["ecatr.esc.wkc_added"])
            top = "Working counter per command (returned)"
            add((top,), compared)
            for cmd, wkc in list(zip(r["ecatr.datagram.cmd"], r["ecatr.datagram.wkc"]))[:compared]:
                name = pg.CMD_NAMES.get(int(cmd, 0), "0x%02x" % int(cmd, 0))
                add((top, name))
                add((top, name, "working counter %d" % int(wkc)))
    return f, times


def down_by_value(rows):
    return sum(1 for r in rows.values() for v in r["ecatr.esc.wkc_added"] if int(v) < 0)


def stats_checks(check, env, path, name, rows):
    want, times = figures(rows)
    check(want[("Working counter went down",)] == down_by_value(rows),
          "%s: one ecatr.expert.wkc_down per negative ecatr.esc.wkc_added (%d)" % (name, down_by_value(rows)))
    for two_pass in (False, True):
        tag = " (-2)" if two_pass else ""
        got = stats_tree(env, path, two_pass)
        rtt = got.get(("Round trip (ms)",), ["0"])
        counted = {p: int(v[0]) for p, v in got.items()
                   if p[0] not in ("Round trip (ms)", "Slaves (returned datagrams)")}
        wrong = {p: (counted.get(p, 0), n) for p, n in want.items() if counted.get(p, 0) != n}
        extra = {p: n for p, n in counted.items() if p not in want and n}
        check(not wrong and not extra, "%s%s: every row of Requests and responses is its count of fields "
              "(%d rows)%s%s" % (name, tag, len(want), "; stats vs fields: %s" % wrong if wrong else "",
                                "; rows with no such fields: %s" % extra if extra else ""))
        ok = int(rtt[0]) == len(times)
        if times:
            avg, low, high = (float(x) for x in rtt[1:4])
            ok = ok and abs(low - min(times)) < 0.001 and abs(high - max(times)) < 0.001 and \
                abs(avg - sum(times) / len(times)) <= 0.0051  # the average is shown with 2 decimals
        check(ok, "%s%s: Round trip (ms) %s is the count, average, min, max of ecatr.time (%d)" % (
            name, tag, rtt[:4], len(times)))


def nanoseconds(cap, pkt):
    if cap.kind == "pcap":
        return pkt.ts
    units = cap.units.get(pkt.ifid, 10**6)
    return pkt.ts * 10**9 // units


def time_checks(check, env, path, name, rows_two_pass):
    cap = pr.Capture.read(path)
    ts = [nanoseconds(cap, p) for p in cap.packets]
    for two_pass in (False, True):
        rows = rows_two_pass if two_pass else decode(env, path, False)
        bad, paired = [], 0
        for n, r in rows.items():
            if not r["ecatr.request_in"]:
                check(not r["ecatr.time"], "%s: ecatr.time only on returned frames (frame %d)" % (name, n)) \
                    if r["ecatr.time"] else None
                continue
            paired += 1
            req = int(r["ecatr.request_in"][0])
            got = int(Decimal(r["ecatr.time"][0]) * 10**9) if r["ecatr.time"] else None
            if got != ts[n - 1] - ts[req - 1]:
                bad.append((n, req, got, ts[n - 1] - ts[req - 1]))
        check(not bad, "%s%s: ecatr.time is the return's timestamp minus the request's, to the ns, on all %d "
              "returned frames%s" % (name, " (-2)" if two_pass else "", paired,
                                     " (frame, request, ns shown, ns in the file): %s" % bad[:4] if bad else ""))


# ----------------------------------------------------------------------------- generated frames

def generated():
    """[(Frame, ns)]: pairs of every command, and the faults the docstring names."""
    out = []
    t = [1704067200 * 10**9]
    idx = [0]

    def dg(cmd, wkc=0, data=b"\x01\x02\x03\x04"):
        idx[0] = (idx[0] + 1) & 0xFF
        return pg.Datagram(cmd=cmd, idx=idx[0], adp=0x1001 if cmd in (4, 5, 6, 14) else 0, ado=0x0130,
                           lad=0x10000 if cmd in pg.LOGICAL_CMDS else 0, data=data, wkc=wkc)

    def back(ds, wkcs=None):
        b = []
        for k, d in enumerate(ds):
            r = pg.Datagram(**vars(d))
            r.wkc = d.wkc + 1 if wkcs is None else wkcs[k]
            if d.cmd in (1, 2, 3, 7, 8, 9, 13):
                r.adp = (d.adp + 2) & 0xFFFF
            b.append(r)
        return b

    def send(ds, src=MASTER, gap=1000):
        t[0] += gap
        out.append((pg.Frame(ds, src_mac=src), t[0]))

    for k, cmd in enumerate(sorted(pg.CMD_NAMES)):
        ds = [dg(cmd)] + [dg((cmd + j) % 15) for j in range(1, 1 + k % 3)]
        send(ds, gap=1000000 + 7919 * k)
        send(back(ds), RETURNED, gap=100000 + 1237 * k + (k * k) % 997)
    # working counters that came back unchanged (nobody there), and one that went down
    for k in range(4):
        ds = [dg(7), dg(4)]
        send(ds, gap=999983)
        send(back(ds, [0, 0]), RETURNED, gap=51234 + k)
    ds = [dg(12, wkc=3), dg(4, wkc=1)]
    send(ds, gap=1000001)
    send(back(ds, [2, 2]), RETURNED, gap=77777)
    # a return lost, then a return captured twice
    send([dg(4)], gap=1000003)
    ds = [dg(5)]
    send(ds, gap=1000003)
    send(back(ds), RETURNED, gap=60001)
    out.append((out[-1][0], out[-1][1] + 3))
    # a return whose request was not captured, once the lost one is given up (timeout 0.1 s)
    send(back([dg(4)]), RETURNED, gap=200000007)
    # returns out of order: A B B' A'
    a, b = [dg(4)], [dg(1)]
    send(a, gap=1000009)
    send(b, gap=20011)
    send(back(b), RETURNED, gap=90013)
    send(back(a), RETURNED, gap=10007)
    return out


def pcap_ns(frames):
    """Classic pcap with nanosecond timestamps."""
    blob = [struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 1)]
    for f, ns in frames:
        data, orig = pg.encode_frame(f)
        blob.append(struct.pack("<IIII", ns // 10**9, ns % 10**9, len(data), orig) + data)
    return b"".join(blob)


def capture_checks(check, env, path, name, expect_faults=False):
    rows = decode(env, path, True)
    if expect_faults:
        want, _ = figures(rows)
        present = [p for p in [("No response",), ("Duplicates",), ("Responses to requests not captured",),
                               ("Working counter went down",)] if want[p]]
        check(len(present) == 4, "%s: the faults show (%s)" % (name, present))
    stats_checks(check, env, path, name, rows)
    time_checks(check, env, path, name, rows)


class TestEcatFigures(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("rules", "ethercat.xml"), "ecatr")

    def test_generated_faults_counted_and_timed(self):
        with self.checks() as check:
            capture_checks(check, self.env, self.env.add_file("figures.pcap", pcap_ns(generated())), "generated",
                           expect_faults=True)

    def test_corpus_captures_counted_and_timed(self):
        corpus = ARGS.corpus or os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus", "ethercat")
        files = corpus_captures(corpus)
        if not files:
            self.skipTest("no corpus at %s (no *.pcap/*.pcapng)" % corpus)
        with self.checks() as check:
            for f in files:
                print("== %s" % f)
                capture_checks(check, self.env, self.env.readable(os.path.join(corpus, f)), f)


def add_arguments(parser):
    parser.add_argument("--corpus", help="the EtherCAT captures (default ../shared/corpus/ethercat)")


if __name__ == "__main__":
    sys.exit(run_unittests(add_arguments)[1])

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""`dissgen report`: the timing report shows the plugin's numbers, and a browser draws it.

  test_report.py --dissgen build/bin/dissgen --source-dir . [--corpus DIR] [--screenshots DIR]

For a generated capture (two tasks, 1 ms and 10 ms, with known jitter, a lost return and a
mailbox exchange) and for every capture of the corpus, `dissgen report` is run as the tshark
user with the plugin installed per user, and:

- its cycle table equals the figures computed here from the same capture's fields
  (ecatr.cycle, ecatr.cycle.period, ecatr.cycle.jitter, ecatr.time, ecatr.request_in,
  ecatr.no_response_to, ecatr.expert.wkc): frames, period min/median/p99/max (nearest rank),
  jitter standard deviation, round trip min/median/p99/max, lost, working-counter errors;
- the same table equals `tshark -z ecatr,cycles` where the plugin has that statistic;
- AL status read by station address from slaves of unknown position shows by station;
  identical out and back timestamps are said, not drawn; a ring-buffer file set reports as
  one capture;
- the page embeds everything it needs (no http:, no src= outside the page) and Debian's
  chromium, headless, draws a canvas in every chart; its screenshot is written to
  --screenshots (default: the system's temporary folder) and must not be blank.
Bad input: a capture that is not there, or tshark without the plugin, gives one clear
message and exit status 1.
"""

import html.parser
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import unittest
import zlib

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import NOBODY, TsharkTestCase, corpus_captures, relative_time_ns, run_unittests  # noqa: E402
import pcaprewrite as pr  # noqa: E402
from test_losses import MASTER, ecat_frame, generated, returned  # noqa: E402

ARGS = None
FIELDS = ["frame.number", "frame.time_epoch", "ecatr.cycle", "ecatr.cycle.period", "ecatr.cycle.jitter",
          "ecatr.time", "ecatr.request_in", "ecatr.datagram.wkc", "ecatr.esc.wkc_added"]


# ----------------------------------------------------------------------------- a capture with known timing

def two_task_capture():
    """A 1 ms task (LRW + FRMW of the reference clock) with a jitter of -3..+3 us in a fixed
    pattern, a 10 ms task (LRW of another image), one lost return, and a mailbox exchange."""
    packets, t0 = [], 1_700_000_000 * 10**9
    jitter = [0, 3_000, -2_000, 1_000, -3_000, 2_000]
    for n in range(600):
        t = t0 + n * 1_000_000 + jitter[n % len(jitter)]
        dgs = [(12, 0x10, 0x0000, 0x0001, bytes([n & 0xFF, 0, 0, 0]), 0), (14, 0x10, 0x1001, 0x0910, b"\0" * 8, 0)]
        packets.append(pr.Packet(ecat_frame(MASTER, dgs), t))
        if n != 300:
            packets.append(pr.Packet(returned(MASTER, dgs, 3), t + 40_000 + (n % 7) * 1_000))
        if n % 10 == 5:
            slow = [(12, 0x20, 0x0000, 0x0002, b"\0" * 16, 0)]
            packets.append(pr.Packet(ecat_frame(MASTER, slow), t + 200_000))
            packets.append(pr.Packet(returned(MASTER, slow, 2), t + 260_000))
        if n in (100, 101):
            mbx = [(5, 0x30 + n - 100, 0x1002, 0x1000, b"\x0a\x00" + b"\0" * 126, 0)]
            packets.append(pr.Packet(ecat_frame(MASTER, mbx), t + 500_000))
            packets.append(pr.Packet(returned(MASTER, mbx, 1), t + 560_000))
    packets.sort(key=lambda p: p.ts)
    return packets


def run_mode_capture():
    """A capture started after the scan (TwinCAT in run mode): LRW every millisecond, and every
    10 ms the AL status (0x0130) of stations 0x1001 and 0x1002 read by FPRD, one datagram each.
    No position was ever learned.  0x1001 stays in OP; 0x1002 is in SAFEOP, then OP from t = 0.1 s."""
    packets, t0 = [], 1_700_000_000 * 10**9
    for n in range(200):
        t = t0 + n * 1_000_000
        dgs = [(12, 0x10, 0x0000, 0x0001, bytes([n & 0xFF, 0, 0, 0]), 0)]
        packets.append(pr.Packet(ecat_frame(MASTER, dgs), t))
        packets.append(pr.Packet(returned(MASTER, dgs, 3), t + 40_000))
        if n % 10 == 5:
            reads = [(4, 0x40 + n % 64, 0x1001, 0x0130, b"\0\0", 0), (4, 0x40 + n % 64, 0x1002, 0x0130, b"\0\0", 0)]
            states = [b"\x08\x00", b"\x04\x00" if n < 100 else b"\x08\x00"]
            back = [(c, i, a, o, state, w + 1) for (c, i, a, o, _d, w), state in zip(reads, states)]
            packets.append(pr.Packet(ecat_frame(MASTER, reads), t + 300_000))
            packets.append(pr.Packet(ecat_frame(bytes([MASTER[0] | 0x02]) + MASTER[1:], back), t + 360_000))
    return packets


def same_stamp_capture():
    """The two-task capture as some capture drivers stamp it: every return at its request's time."""
    packets, last_out = [], 0
    for p in two_task_capture():
        if p.data[6] & 0x02:
            p = pr.Packet(p.data, last_out)
        else:
            last_out = p.ts
        packets.append(p)
    return packets


def task_periods(packets, lad):
    """The periods between the frames the master sent to logical address `lad` (ns)."""
    times = [p.ts for p in packets if p.data[6:12] == MASTER and p.data[16] == 12 and
             struct.unpack_from("<I", p.data, 18)[0] == lad]
    return [b - a for a, b in zip(times, times[1:])]


def lower_median(values):
    return sorted(values)[(len(values) - 1) // 2]


# ----------------------------------------------------------------------------- what the report says

class TableReader(html.parser.HTMLParser):
    """The rows of <table id="cycles">, each a list of cell texts."""

    def __init__(self, table_id):
        super().__init__()
        self.table_id, self.inside, self.rows, self.cell = table_id, False, [], None

    def handle_starttag(self, tag, attrs):
        if tag == "table" and dict(attrs).get("id") == self.table_id:
            self.inside = True
        elif self.inside and tag == "tr":
            self.rows.append([])
        elif self.inside and tag == "td":
            self.cell = ""

    def handle_endtag(self, tag):
        if tag == "table":
            self.inside = False
        elif tag == "td" and self.cell is not None:
            self.rows[-1].append(self.cell.strip())
            self.cell = None

    def handle_data(self, data):
        if self.cell is not None:
            self.cell += data


def report_table(page):
    reader = TableReader("cycles")
    reader.feed(page)
    return {int(r[0]): r for r in reader.rows if r}


def quantiles(values):
    """min, lower median, nearest-rank p99, max."""
    v = sorted(values)
    return [v[0], v[(len(v) - 1) // 2], v[(99 * len(v) + 99) // 100 - 1], v[-1]] if v else [0, 0, 0, 0]


def us(v):
    return "%.3f" % (v / 1000)


def cycle_figures(rows):
    """{cycle: figures} computed from the fields, by the rules of docs/manual.md ("Cycles"):
    frames, nominal (the last frame's period minus its jitter), period and round-trip
    quantiles, jitter standard deviation (population, ns), returned, lost (unanswered before
    the latest answered), working-counter errors (a datagram not raised, or below the highest
    that datagram returned before)."""
    cycles, cycle_of = {}, {}
    for frame, r in sorted(rows.items()):
        if r["ecatr.cycle"]:
            c = cycles.setdefault(int(r["ecatr.cycle"][0]), {"sent": [], "period": [], "jitter": [], "rtt": [],
                                                              "answered": [], "wkc": 0, "high": None})
            c["sent"].append(frame)
            cycle_of[frame] = c
            c["period"] += [relative_time_ns(v) for v in r["ecatr.cycle.period"]]
            c["jitter"] += [relative_time_ns(v) for v in r["ecatr.cycle.jitter"]]
            if r["ecatr.cycle.jitter"]:
                period, jitter = (relative_time_ns(r[f][0]) for f in ("ecatr.cycle.period", "ecatr.cycle.jitter"))
                c["nominal"] = period - jitter
        if r["ecatr.time"] and r["ecatr.request_in"] and int(r["ecatr.request_in"][0]) in cycle_of:
            c = cycle_of[int(r["ecatr.request_in"][0])]
            c["rtt"].append(min(max(relative_time_ns(r["ecatr.time"][0]), 0), 2**32 - 1))
            c["answered"].append(int(r["ecatr.request_in"][0]))
            back, added = r["ecatr.datagram.wkc"], r["ecatr.esc.wkc_added"]
            if c["high"] is None:
                c["high"] = [-1] * len(back)
            error = False
            for i in range(min(len(back), len(added), len(c["high"]))):
                if int(added[i]) <= 0 or int(back[i], 0) < c["high"][i]:
                    error = True
                c["high"][i] = max(c["high"][i], int(back[i], 0))
            c["wkc"] += error
    out = {}
    for number, c in cycles.items():
        latest = max(c["answered"], default=0)
        j = c["jitter"]
        mean = sum(j) / len(j) if j else 0
        out[number] = {"frames": len(c["sent"]), "nominal": c.get("nominal", 0), "period": quantiles(c["period"]),
                       "jitter_sd": math.sqrt(sum((x - mean) ** 2 for x in j) / len(j)) if j else 0.0,
                       "rtt": quantiles(c["rtt"]), "returned": len(c["rtt"]), "wkc": c["wkc"],
                       "lost": sum(1 for f in c["sent"] if f < latest and f not in set(c["answered"]))}
    return out


def as_table_row(number, f):
    """The cells of the report's cycle table for figures f (signature not compared)."""
    return [str(number), None, str(f["frames"]), us(f["nominal"])] + [us(v) for v in f["period"]] + \
        [None] + [us(v) for v in f["rtt"]] + [str(f["returned"]), str(f["lost"]), str(f["wkc"])]


def stats_cycles(text):
    """{cycle: figures} from `tshark -z ecatr,cycles`."""
    out, current = {}, None
    for line in text.splitlines():
        m = re.match(r"Cycle (\d+): (.*)$", line)
        if m:
            current = out.setdefault(int(m.group(1)), {"signature": m.group(2)})
            continue
        if current is None:
            continue
        m = re.match(r"\s+(period|round trip) min/median/p99/max \(ns\): (\d+) (\d+) (\d+) (\d+)", line)
        if m:
            current["period" if m.group(1) == "period" else "rtt"] = [int(x) for x in m.groups()[1:]]
        elif re.match(r"\s+(period|round trip): none", line):
            current["period" if "period" in line else "rtt"] = [0, 0, 0, 0]
        for key, label in (("frames", "frames"), ("nominal", "nominal period \\(ns\\)"),
                           ("returned", "frames returned"), ("lost", "frames lost"),
                           ("wkc", "working counter errors"), ("jitter_sd", "jitter std dev \\(ns\\)")):
            m = re.match(r"\s+%s: ([\d.]+)$" % label, line)
            if m:
                current[key] = float(m.group(1)) if key == "jitter_sd" else int(m.group(1))
    return out


def png_pixels(path):
    """(width, height, set of distinct RGB colours) of an 8-bit RGB/RGBA PNG (stdlib only)."""
    with open(path, "rb") as fh:
        blob = fh.read()
    assert blob[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width = 8, b"", 0
    while pos < len(blob):
        length, kind = struct.unpack(">I4s", blob[pos:pos + 8])
        data = blob[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", data[:10])
            assert depth == 8 and colour in (2, 6), "PNG not 8-bit RGB(A)"
            bpp = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += data
        pos += 12 + length
    raw, stride, colours, prev = zlib.decompress(idat), width * bpp, set(), bytearray(width * bpp)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if kind == 1:
                line[i] = (line[i] + a) & 0xFF
            elif kind == 2:
                line[i] = (line[i] + b) & 0xFF
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 0xFF
            elif kind == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 0xFF
        if y % 8 == 0:
            colours.update(bytes(line[i:i + 3]) for i in range(0, stride, bpp * 8))
        prev = line
    return width, height, colours


def screenshot_path(folder, name):
    """name in folder (--screenshots), default the system's temporary folder."""
    folder = folder or tempfile.gettempdir()
    os.makedirs(folder, exist_ok=True)
    return os.path.join(folder, name)


def browser_checks(check, chromium, html_path, page, shot, least_charts):
    """Debian's chromium, headless, draws a canvas in every chart of the page at html_path
    (whose text is `page`), and its screenshot, written to shot, is not blank."""
    charts = re.findall(r'<div class="chart[^"]*" id="([^"]+)"', page)
    profile = tempfile.mkdtemp(prefix="dissgen-chromium-")
    base = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
            "--user-data-dir=" + profile, "--window-size=1400,2400", "--virtual-time-budget=5000"]
    url = "file://" + html_path
    try:
        dom = subprocess.run(base + ["--dump-dom", url], capture_output=True, text=True, timeout=180).stdout
        subprocess.run(base + ["--screenshot=" + shot, url], capture_output=True, timeout=180)
    finally:
        shutil.rmtree(profile, ignore_errors=True)
    check(len(charts) >= least_charts, "the page has charts (%d)" % len(charts))
    for chart in charts:
        m = re.search(r'id="%s"(.*?)(?=<div class="chart|<h2|<table|</body)' % re.escape(chart), dom, re.S)
        check(m is not None and "<canvas" in m.group(1), "chromium drew chart %s" % chart)
    check(os.path.exists(shot), "screenshot written: %s" % shot)
    if os.path.exists(shot):
        width, height, colours = png_pixels(shot)
        check(width == 1400 and len(colours) > 20,
              "the screenshot (%dx%d) shows a drawing (%d colours)" % (width, height, len(colours)))


# ----------------------------------------------------------------------------- the tests

class TestReport(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install("rules/ethercat.xml", "ecatr")
        # dissgen runs tshark itself: it must run as the tshark user, from a place that user can read.
        cls.dissgen = cls.env.path("dissgen")
        shutil.copyfile(ARGS.dissgen, cls.dissgen)
        os.chmod(cls.dissgen, 0o755)
        cls.out = cls.env.path("reports")    # the tshark user writes the reports here
        os.makedirs(cls.out)
        if cls.env.as_nobody:
            os.chown(cls.out, NOBODY, NOBODY)
        cls.capture = cls.env.path("two-tasks.pcap")
        generated(cls.capture, two_task_capture())
        os.chmod(cls.capture, 0o644)

    def report(self, capture, name, check=True, extra=(), environment=None):
        out = os.path.join(self.out, name + ".html")
        cmd = [self.dissgen, "report", capture, "-o", out] + list(extra)
        if self.env.as_nobody:
            cmd = ["setpriv", "--reuid=%d" % NOBODY, "--regid=%d" % NOBODY, "--clear-groups"] + cmd
        started = time.monotonic()
        p = subprocess.run(cmd, env=dict(self.env.env(), **(environment or {})), cwd=self.env.home,
                           capture_output=True, text=True, timeout=1800)
        took = time.monotonic() - started
        if check and p.returncode != 0:
            self.fail("dissgen report %s: exit %d\n%s%s" % (name, p.returncode, p.stdout, p.stderr))
        page = ""
        if p.returncode == 0:
            with open(out, encoding="utf-8") as fh:
                page = fh.read()
        return p, page, took

    def table_checks(self, check, capture, name):
        """The report's cycle table against the fields' figures and -z ecatr,cycles."""
        p, page, took = self.report(capture, name)
        table = report_table(page)
        figures = cycle_figures(self.env.field_rows(capture, FIELDS, aggregator="\x1f"))
        stats = stats_cycles(self.env.tshark(["-r", capture, "-q", "-z", "ecatr,cycles"]).stdout)
        check(sorted(table) == sorted(figures) == sorted(stats), "%s: cycles in the report %s, the fields %s, "
              "-z ecatr,cycles %s" % (name, sorted(table), sorted(figures), sorted(stats)))
        for number, f in figures.items():
            got, want = table.get(number), as_table_row(number, f)
            if got is None:
                continue
            same = len(got) == len(want) and all(w is None or g == w for g, w in zip(got, want))
            check(same, "%s cycle %d: report %s == fields %s" % (name, number, got, want))
            check(abs(float(got[8]) * 1000 - f["jitter_sd"]) < 1, "%s cycle %d: jitter std dev %s us, fields %.1f ns"
                  % (name, number, got[8], f["jitter_sd"]))
            z = stats.get(number, {})
            keys = ("frames", "nominal", "period", "rtt", "returned", "lost", "wkc")
            check(all(z.get(k) == f[k] for k in keys) and abs(z.get("jitter_sd", -9) - f["jitter_sd"]) < 0.1 and
                  got[1] == z.get("signature"), "%s cycle %d: -z ecatr,cycles %s == fields %s" % (
                      name, number, {k: z.get(k) for k in keys + ("jitter_sd", "signature")},
                      dict({k: f[k] for k in keys + ("jitter_sd",)}, signature=got[1])))
        print("   %s: report in %.1f s, %d cycles" % (name, took, len(table)))
        return table, page

    def test_generated_two_tasks(self):
        with self.checks() as check:
            table, page = self.table_checks(check, self.capture, "two-tasks")
            check(len(table) == 2, "two tasks, two cycles (got %d)" % len(table))
            if len(table) == 2:
                fast, slow = table[1], table[2]
                check(fast[1] == "LRW 0x00010000 (4 bytes), FRMW 0x1001:0x0910 (8 bytes)",
                      "cycle 1 signature: %s" % fast[1])
                want = [us(lower_median(task_periods(two_task_capture(), lad))) for lad in (0x10000, 0x20000)]
                check([fast[3], slow[3]] == want, "nominal periods: the lower median of each task's periods "
                      "from the timestamps written, %s (got %s, %s)" % (want, fast[3], slow[3]))
                check(fast[14] == "1", "the lost return is counted in cycle 1 (got %s)" % fast[14])
                check(fast[4] == "995.000" and fast[7] == "1005.000",
                      "period min/max from the injected jitter of -3..+3 us (got %s/%s)" % (fast[4], fast[7]))
            check(not re.search(r"<(script|link|img|iframe)\b[^>]*\b(src|href)=", page, re.I),
                  "the page loads nothing from outside (no src= or href= on a script, link, image or frame)")

    def test_al_status_by_station_address(self):
        """Slaves whose position was never learned still show, by the station address their AL
        status was read from (FPRD of 0x0130)."""
        capture = self.env.path("run-mode.pcap")
        generated(capture, run_mode_capture())
        os.chmod(capture, 0o644)
        _p, page, _took = self.report(capture, "run-mode")
        reader = TableReader("slaves")
        reader.feed(page)
        rows = {r[0]: r for r in reader.rows if r}
        with self.checks() as check:
            check(sorted(rows) == ["station 0x1001", "station 0x1002"],
                  "the two stations read by FPRD are the Slaves section's rows: %s" % sorted(rows))
            if len(rows) == 2:
                check(rows["station 0x1001"][2] == "OP (0.005 s)", "0x1001 in OP: %s" % rows["station 0x1001"][2])
                check(rows["station 0x1002"][2] == "SAFEOP (0.005 s) → OP (0.105 s)",
                      "0x1002 from SAFEOP to OP: %s" % rows["station 0x1002"][2])

    def test_identical_out_and_back_timestamps(self):
        """A capture whose returns carry their requests' timestamps says so instead of drawing
        the round trip as a flat line at 0."""
        capture = self.env.path("same-stamp.pcap")
        generated(capture, same_stamp_capture())
        os.chmod(capture, 0o644)
        _p, page, _took = self.report(capture, "same-stamp")
        _p, clean, _took = self.report(self.capture, "stamped")
        with self.checks() as check:
            check('id="round-trip"' not in page, "no round-trip chart when every round trip is 0")
            check('id="round-trip-same-stamp"' in page and "same timestamp" in page,
                  "the page says the out and back timestamps are identical")
            check('id="round-trip"' in clean and 'id="round-trip-same-stamp"' not in clean,
                  "a capture with real round trips still draws them, without the note")

    def test_ring_buffer_files_are_one_capture(self):
        """Files of a `dumpcap -b` set, given in order, report as the one capture they split."""
        packets = two_task_capture()
        parts = []
        for k, (a, b) in enumerate(((0, 700), (700, 1400), (1400, len(packets)))):
            parts.append(self.env.path("ring_%05d.pcap" % (k + 1)))
            generated(parts[-1], packets[a:b])
            os.chmod(parts[-1], 0o644)
        p, page, _took = self.report(parts[0], "ring", extra=parts[1:])
        _p, whole, _took = self.report(self.capture, "whole")
        with self.checks() as check:
            check(report_table(page) == report_table(whole) and len(report_table(page)) == 2,
                  "the three files' cycle table is the whole capture's")
            frames = re.search(r'<p class="note">(\d+) frames', page)
            check(frames is not None and int(frames.group(1)) == len(packets),
                  "all %d frames of the three files counted (%s)" % (len(packets), frames and frames.group(1)))
            check("ring_00001.pcap" in page and "ring_00003.pcap" in page, "the page names the files")

    def test_browser_draws_every_chart(self):
        chromium = shutil.which("chromium") or shutil.which("chromium-browser")
        if not chromium:
            self.skipTest("chromium is not installed (Debian package chromium)")
        _p, page, _took = self.report(self.capture, "browser")
        with self.checks() as check:
            browser_checks(check, chromium, os.path.join(self.out, "browser.html"), page,
                           screenshot_path(ARGS.screenshots, "dissgen-report.png"), 4)

    def test_bad_input_is_one_clear_message(self):
        p, _page, _took = self.report(self.env.path("absent.pcap"), "absent", check=False)
        with self.checks() as check:
            check(p.returncode == 1 and "absent.pcap" in p.stderr and "Traceback" not in p.stderr,
                  "a missing capture: exit 1 and its name (%d: %s)" % (p.returncode, p.stderr.strip()))
            bare = dict(self.env.env(), HOME=tempfile.mkdtemp(prefix="dissgen-noplugin-"))
            # writable by the tshark user: what is missing is the plugin, not a place for the report
            os.chmod(bare["HOME"], 0o777)
            cmd = [self.dissgen, "report", self.capture, "-o", os.path.join(bare["HOME"], "r.html")]
            if self.env.as_nobody:
                cmd = ["setpriv", "--reuid=%d" % NOBODY, "--regid=%d" % NOBODY, "--clear-groups"] + cmd
            q = subprocess.run(cmd, env=bare, capture_output=True, text=True, timeout=300)
            shutil.rmtree(bare["HOME"], ignore_errors=True)
            check(q.returncode == 1 and "dissgen install" in q.stderr,
                  "tshark without the plugin: exit 1, says how to install it (%d: %s)" % (q.returncode, q.stderr.strip()))

    def test_with_a_catalogue_and_a_design(self):
        """--esi and --network: a plugin built for the run names the slaves and checks the bus."""
        source = os.path.abspath(ARGS.source_dir)
        corpus = os.path.join(source, "..", "shared", "corpus")
        capture = os.path.join(corpus, "ethercat", "soem-sdinfo-ek1100-el1004.pcapng")
        if not os.path.exists(capture):
            self.skipTest("no corpus at %s" % corpus)
        if not self.env.as_nobody and os.geteuid() == 0:
            self.skipTest("needs a user other than root")
        # What dissgen reads as the tshark user: copies it can read.
        runtime = self.env.path("runtime")
        if not os.path.isdir(runtime):
            shutil.copytree(os.path.join(source, "plugin_runtime"), runtime)
            subprocess.run(["chmod", "-R", "a+rX", runtime], check=True)
        esi = [self.env.readable(os.path.join(corpus, "esi", f)) for f in ("Beckhoff_EK11xx.xml", "Beckhoff_EL1xxx.xml")]
        rules = self.env.readable(os.path.join(source, "rules", "ethercat.xml"))
        design = self.env.readable(os.path.join(source, "tests", "network", "soem_design.xml"))
        args = ["--rules", rules, "--network", design] + [a for f in esi for a in ("--esi", f)]
        _p, page, took = self.report(self.env.readable(capture), "design", extra=args,
                                     environment={"DISSGEN_RUNTIME_DIR": runtime})
        with self.checks() as check:
            check("<td>EK1100</td>" in page and "<td>EL1004</td>" in page,
                  "the slaves named from the ESI files (%.1f s, the plugin's build included)" % took)
            m = re.search(r'<ul id="network">(.*?)</ul>', page, re.S)
            # The design has a third slave (an AKD drive) that the capture's bus lacks.
            check(m is not None and "<li>design: 3 slaves, bus: 2</li>" in m.group(1),
                  "the network check's finding, whole: %s" % (m.group(1).strip() if m else "none"))

    def test_corpus_reports_match_the_fields(self):
        corpus = ARGS.corpus or os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus", "ethercat")
        files = corpus_captures(corpus)
        if not files:
            self.skipTest("no corpus at %s (no *.pcap/*.pcapng)" % corpus)
        with self.checks() as check:
            for f in files:
                self.table_checks(check, self.env.readable(os.path.join(corpus, f)), f)


if __name__ == "__main__":
    def options(parser):
        parser.add_argument("--corpus", help="the EtherCAT captures (default ../shared/corpus/ethercat)")
        parser.add_argument("--screenshots", help="where the browser's screenshot goes")
    ARGS, status = run_unittests(options)
    sys.exit(status)

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""`dissgen report` of a protocol other than EtherCAT, whose rules declare <cycles> and
<pairing>: EtherNet/IP's class-1 I/O as rules/enip.xml declares it.

    test_report_cycles.py --dissgen build/bin/dissgen --source-dir . [--screenshots DIR]

With only the enipr plugin installed (as the tshark user), `dissgen report` writes the
cycles report, and:

- its Cycles table has one row per cycle of `tshark -z enipr,cycles`, every figure exactly
  as that statistic prints it (stream, first frame, messages, nominal period, period
  min/median/p99/max, jitter std dev, messages lost, duplicates), and one period chart and
  one jitter histogram per cycle;
- its headline and losses table count the messages lost and repeated as the fields show
  them (enipr.cycle.lost, enipr.cycle.duplicate), on a generated capture with drops and
  repeats (test_rule_cycles.generated_capture) and on
  ../shared/corpus/enip/enip_cip_example.pcap (24 I/O connections: 24 rows), when there;
- Debian's chromium, headless, draws a canvas in every chart; the screenshot (written to
  --screenshots, default the system's temporary folder) is not blank;
- with a second plugin with <pairing> installed, the report asks for --protocol, and
  --protocol picks either one (the pairing-only one: its round trips and unanswered
  requests as the fields show them, no cycle section); an unknown one is one clear message.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import NOBODY, TsharkTestCase, run_unittests  # noqa: E402
from test_report import TableReader, browser_checks, screenshot_path  # noqa: E402
from test_rule_cycles import generated_capture, parse_report, pcap_ns  # noqa: E402
from test_request_context import frame, payload, schedule, transactions  # noqa: E402
import pcapgen  # noqa: E402

ARGS = None
CORPUS_CAPTURE = os.path.join("..", "shared", "corpus", "enip", "enip_cip_example.pcap")


def expected_row(number, cycle):
    """The report's row for one cycle of -z enipr,cycles (parse_report), cell by cell."""
    f = cycle["figures"]
    period = [str(v) for v in f["period"]] if f.get("period") else ["none"] * 4
    counted = "lost" in f
    return ([str(number), cycle["name"], str(f["first frame"]), str(f["messages"]), str(f["nominal"])] + period +
            [f["jitter sd"], str(f["lost"]) if counted else "", str(f["duplicates"]) if counted else ""])


def request_context_frames():
    """Modbus-style requests and responses of tests/rules/request_context.xml (pairing, no
    cycles), every 17th transaction's response left out."""
    txns = transactions(47502, 120)
    return [frame(d, payload(d, txns[k], None)) for d, k in schedule(txns, 1) if not (d == "response" and k % 17 == 3)]


def table(page, table_id):
    reader = TableReader(table_id)
    reader.feed(page)
    return [r for r in reader.rows if r]


def stage_report(env, dissgen):
    """(dissgen, reports folder) where the tshark user can run and write: dissgen runs
    tshark itself, so it must run as that user, from a place that user can read."""
    staged = env.path("dissgen")
    shutil.copyfile(dissgen, staged)
    os.chmod(staged, 0o755)
    out = env.path("reports")
    os.makedirs(out)
    if env.as_nobody:
        os.chown(out, NOBODY, NOBODY)
    return staged, out


def run_report(env, dissgen, out_dir, capture, name, extra=(), home=None):
    """(completed process, page or "", seconds) of `dissgen report` as the tshark user."""
    out = os.path.join(out_dir, name + ".html")
    cmd = [dissgen, "report", capture, "-o", out] + list(extra)
    if env.as_nobody:
        cmd = ["setpriv", "--reuid=%d" % NOBODY, "--regid=%d" % NOBODY, "--clear-groups"] + cmd
    environment = dict(env.env(), **({"HOME": home} if home else {}))
    started = time.monotonic()
    p = subprocess.run(cmd, env=environment, cwd=env.home, capture_output=True, text=True, timeout=1800)
    took = time.monotonic() - started
    page = ""
    if p.returncode == 0:
        with open(out, encoding="utf-8") as fh:
            page = fh.read()
    return p, page, took


class TestReportCycles(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("rules", "enip.xml"), "enipr")
        cls.dissgen, cls.out = stage_report(cls.env, ARGS.dissgen)
        cls.generated = cls.env.add_file("io_cycles.pcap", pcap_ns(generated_capture()))

    def report(self, capture, name, extra=(), home=None):
        return run_report(self.env, self.dissgen, self.out, capture, name, extra, home)

    def corpus_capture(self):
        path = os.path.abspath(os.path.join(ARGS.source_dir, CORPUS_CAPTURE))
        if not os.path.exists(path):
            self.skipTest("no %s" % CORPUS_CAPTURE)
        return self.env.readable(path)

    def checks_against_tshark(self, check, capture, name):
        """The page's table, charts, headline and losses against -z enipr,cycles and the fields."""
        p, page, took = self.report(capture, name)
        check(p.returncode == 0, "%s: dissgen report exit %d %s" % (name, p.returncode, p.stderr.strip()))
        stats = parse_report(self.env.tshark(["-r", capture, "-q", "-z", "enipr,cycles"]).stdout)
        rows = table(page, "cycles")
        check(len(rows) == len(stats) and len(stats) > 0,
              "%s: %d rows in the report, %d cycles in -z enipr,cycles" % (name, len(rows), len(stats)))
        for number, (got, cycle) in enumerate(zip(rows, stats), 1):
            want = expected_row(number, cycle)
            check(got == want, "%s cycle %d: report %s == -z enipr,cycles %s" % (name, number, got, want))
        charts = re.findall(r'<div class="chart[^"]*" id="([^"]+)"', page)
        for number in range(1, len(stats) + 1):
            check(charts.count("period-%d" % number) == 1 and charts.count("jitter-%d" % number) == 1,
                  "%s cycle %d: one period chart and one jitter histogram" % (name, number))
        fields = self.env.field_rows(capture, ["frame.number", "enipr.cycle.lost", "enipr.cycle.duplicate",
                                               "enipr.time"])
        lost = sum(int(v) for r in fields.values() for v in r["enipr.cycle.lost"])
        repeats = sum(1 for r in fields.values() if r["enipr.cycle.duplicate"])
        trips = sum(len(r["enipr.time"]) for r in fields.values())
        headline = re.search(r'<p class="note" id="headline">(\d+) frames, [0-9.]+ s; (\d+) cycles?, (\d+) messages? '
                             r'lost, (\d+) duplicates?; (\d+) round trips?', page)
        got = tuple(int(g) for g in headline.groups()) if headline else None
        check(got == (len(fields), len(stats), lost, repeats, trips),
              "%s: headline %s, the fields: %d frames, %d cycles, %d lost, %d duplicates, %d round trips"
              % (name, got, len(fields), len(stats), lost, repeats, trips))
        marked = {int(r[0]) for r in table(page, "losses")}
        want = {f for f, r in fields.items() if r["enipr.cycle.lost"] or r["enipr.cycle.duplicate"]}
        check(marked == want, "%s: the losses table's frames %s are those the fields mark %s"
              % (name, sorted(marked), sorted(want)))
        check(not re.search(r"<(script|link|img|iframe)\b[^>]*\b(src|href)=", page, re.I),
              "%s: the page loads nothing from outside" % name)
        print("   %s: report in %.2f s, %d bytes, %d cycles" % (name, took, len(page.encode()), len(rows)))
        return stats, page

    def test_generated_capture_with_drops_and_repeats(self):
        with self.checks() as check:
            stats, page = self.checks_against_tshark(check, self.generated, "generated")
            check(len(stats) == 4, "four streams, four cycles (got %d)" % len(stats))
            check(len(table(page, "losses")) == 6, "three gaps and three repeats in the losses table")
            check('id="loss-events"' in page and 'id="round-trip"' not in page,
                  "a losses chart; no round-trip chart without a request")

    def test_corpus_capture_one_row_per_connection(self):
        capture = self.corpus_capture()
        with self.checks() as check:
            stats, page = self.checks_against_tshark(check, capture, "corpus")
            check(len(stats) == 24, "24 I/O connections, 24 cycles (got %d)" % len(stats))
            check('id="round-trip"' in page, "the explicit messages' round trips are drawn")

    def test_browser_draws_every_chart(self):
        chromium = shutil.which("chromium") or shutil.which("chromium-browser")
        if not chromium:
            self.skipTest("chromium is not installed (Debian package chromium)")
        path = os.path.abspath(os.path.join(ARGS.source_dir, CORPUS_CAPTURE))
        capture = self.env.readable(path) if os.path.exists(path) else self.generated
        _p, page, _took = self.report(capture, "browser")
        with self.checks() as check:
            browser_checks(check, chromium, os.path.join(self.out, "browser.html"), page,
                           screenshot_path(ARGS.screenshots, "dissgen-report-cycles.png"), 9)

    def test_several_protocols_need_protocol_option(self):
        """A second plugin with <pairing> beside enipr, in a HOME of its own."""
        home = tempfile.mkdtemp(prefix="two-plugins-", dir=self.env.home)
        os.chmod(home, 0o755)
        plugins = os.path.join(home, os.path.relpath(self.env.plugin_dir, self.env.home))
        os.makedirs(plugins)
        for f in os.listdir(self.env.plugin_dir):
            shutil.copy(os.path.join(self.env.plugin_dir, f), plugins)
        subprocess.run([ARGS.dissgen, "install", os.path.join(ARGS.source_dir, "tests", "rules",
                                                              "request_context.xml"), "--dir", plugins],
                       check=True, capture_output=True)
        subprocess.run(["chmod", "-R", "a+rX", home], check=True)
        pairs = self.env.add_file("pairs.pcap", pcapgen.raw_pcap_bytes(request_context_frames()))
        try:
            rqc, pairing_page, _took = self.report(pairs, "pairing", extra=["--protocol", "rqc"], home=home)
            rqc_fields = subprocess.run(self.env.command(["-r", pairs, "-T", "fields", "-e", "rqc.time", "-e",
                                                          "rqc.no_response_to", "-e", "frame.number",
                                                          "-e", "frame.time_relative"]),
                                        env=dict(self.env.env(), HOME=home), capture_output=True, text=True).stdout
            both, _page, _took = self.report(self.generated, "both", home=home)
            chosen, page, _took = self.report(self.generated, "chosen", extra=["--protocol", "enipr"], home=home)
            unknown, _page, _took = self.report(self.generated, "unknown", extra=["--protocol", "nosuch"], home=home)
        finally:
            shutil.rmtree(home, ignore_errors=True)
        with self.checks() as check:
            check(both.returncode == 1 and "--protocol" in both.stderr and "enipr" in both.stderr,
                  "two candidates: exit 1, names them and --protocol (%d: %s)" % (both.returncode, both.stderr.strip()))
            check(chosen.returncode == 0 and len(table(page, "cycles")) == 4,
                  "--protocol enipr: its report, 4 cycles (%d: %s)" % (chosen.returncode, chosen.stderr.strip()))
            trips = sum(1 for line in rqc_fields.splitlines() if line.split("\t")[0])
            unanswered = sum(len(line.split("\t")[1].split(",")) for line in rqc_fields.splitlines()
                             if line.split("\t")[1:] and line.split("\t")[1])
            headline = re.search(r'id="headline">\d+ frames, [0-9.]+ s; (\d+) round trips?, (\d+) requests? without',
                                 pairing_page)
            check(rqc.returncode == 0 and headline is not None and
                  (int(headline.group(1)), int(headline.group(2))) == (trips, unanswered) and unanswered > 0,
                  "--protocol rqc (pairing, no cycles): headline %s, the fields %d round trips, %d unanswered"
                  % (headline and headline.groups(), trips, unanswered))
            # each unanswered request is marked when it was sent, not when a later message proved it
            sent = {int(c[2]): float(c[3]) for c in (line.split("\t") for line in rqc_fields.splitlines())}
            want = sorted(round(sent[int(f)], 6) for line in rqc_fields.splitlines()
                          for f in (line.split("\t")[1].split(",") if line.split("\t")[1] else []))
            data = json.loads(re.search(r'id="report-data">(.*?)</script>', pairing_page, re.S).group(1))
            got = sorted(round(e[0], 6) for e in data["no_response"])
            check(got == want, "the unanswered requests marked at their own times %s, sent at %s" % (got[:5], want[:5]))
            check('id="round-trip"' in pairing_page and 'id="cycles"' not in pairing_page and
                  'id="loss-events"' not in pairing_page, "pairing only: a round-trip chart, no cycles, no losses")
            check(unknown.returncode == 1 and "nosuch" in unknown.stderr,
                  "an unknown --protocol: exit 1, named (%d: %s)" % (unknown.returncode, unknown.stderr.strip()))


if __name__ == "__main__":
    def options(parser):
        parser.add_argument("--screenshots", help="where the browser's screenshot goes")
    ARGS, status = run_unittests(options)
    sys.exit(status)

#!/usr/bin/env python3
"""Absolute dates and times, GUIDs and filter names shared by alternatives, with real
tshark: tests/rules/dates_guids_shared.xml.

UDP messages to port 47490 carry, by their first byte: every datetime encoding (seconds
and nanoseconds in both byte orders, 64-bit counts of ns, us and ms, 32-bit seconds) and
a GUID in both byte orders (1); or one of three alternative layouts (2, 3, 4-9) whose
Option (and When) fields share one filter name. Every value is checked against the
bytes this script wrote, as tshark prints it and through display filters, in one pass
and with -2; cut messages give our expert info, never an exception.

    test_dates_guids_shared_names.py --dissgen build/bin/dissgen --source-dir .
"""
import datetime
import os
import struct
import sys
import unittest
import uuid

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import SANITIZE, TsharkTestCase, run_unittests  # noqa: E402
from test_enip import pcap, udp  # noqa: E402

RULES = os.path.join("tests", "rules", "dates_guids_shared.xml")
PORT = 47490
EPOCH = datetime.datetime(1970, 1, 1, tzinfo=datetime.timezone.utc)

# seconds since 1970 and nanoseconds: 2024-01-01 00:00:00.5, and odd digits to the last place
NET_TIME = (1704067200, 500000000)
NET_TIME_BIG = (1718454896, 123456789)
STAMP_NS = 1700000000 * 10 ** 9 + 987654321      # nanoseconds: none may be lost
STAMP_US = 1600000000 * 10 ** 6 + 654321
STAMP_MS = 1500000000 * 10 ** 3 + 321
BOOT_S = 1234567890
OBJECT = bytes(range(0x10, 0x20))
OBJECT_BIG = bytes.fromhex("00112233445566778899aabbccddeeff")


def shown(secs, nsecs):
    """An FT_ABSOLUTE_TIME in UTC as tshark prints it: 'Jan  1, 2024 00:00:00.500000000 UTC'."""
    t = EPOCH + datetime.timedelta(seconds=secs)
    return "%s %2d, %d %s.%09d UTC" % (t.strftime("%b"), t.day, t.year, t.strftime("%H:%M:%S"), nsecs)


def times_message():
    return (bytes([1]) + struct.pack("<II", *NET_TIME) + struct.pack(">II", *NET_TIME_BIG)
            + struct.pack("<Q", STAMP_NS) + struct.pack("<Q", STAMP_US) + struct.pack("<Q", STAMP_MS)
            + struct.pack("<I", BOOT_S) + OBJECT + OBJECT_BIG)


# IEC 61850 UtcTime: seconds and a 24-bit fraction of a second (0x800001: just past .5)
CLOCK = (1718454896, 0x800001)
CLOCK_DELTAS = (1234567, 250)    # microseconds: 0.734567 s after, 0.499750 s before


def clock_message(delta):
    return bytes([10]) + struct.pack(">I", CLOCK[0]) + CLOCK[1].to_bytes(3, "big") + struct.pack("<I", delta)


def offset_shown(us):
    """An FT_RELATIVE_TIME of `us` microseconds as tshark prints it: '-0.499750000'."""
    return "%s%d.%09d" % ("-" if us < 0 else "", abs(us) // 10 ** 6, abs(us) % 10 ** 6 * 1000)


def short_message(option, secs, nsecs):
    return bytes([2, option]) + struct.pack("<II", secs, nsecs)


def long_message(option, ns):
    return bytes([3, 1, option]) + struct.pack(">Q", ns)


def other_message(kind, option):
    return bytes([kind, option])


def frame(payload):
    return udp(50000, PORT, payload)


class DatesGuidsSharedNames(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(RULES, "dtgd")

    def capture(self, name, payloads):
        return self.env.add_file(name, pcap([frame(p) for p in payloads]))

    def rows(self, path, fields, display_filter=None):
        """The rows of -2, after checking one pass gives the same."""
        one = self.env.field_rows(path, ["frame.number"] + fields, display_filter=display_filter, aggregator="|")
        two = self.env.field_rows(path, ["frame.number"] + fields, two_pass=True, display_filter=display_filter,
                                  aggregator="|")
        self.assertEqual(one, two, "one pass and -2 differ")
        return two

    def test_dates_and_guids_match_the_bytes(self):
        cap = self.capture("times.pcap", [times_message()])
        fields = ["dtgd.times.net_time", "dtgd.times.net_time_big", "dtgd.times.stamp", "dtgd.times.stamp_us",
                  "dtgd.times.stamp_ms", "dtgd.times.boot", "dtgd.times.object", "dtgd.times.object_big"]
        row = self.rows(cap, fields)[1]
        self.assertEqual(row["dtgd.times.net_time"], [shown(*NET_TIME)])
        self.assertEqual(row["dtgd.times.net_time_big"], [shown(*NET_TIME_BIG)])
        self.assertEqual(row["dtgd.times.stamp"], [shown(STAMP_NS // 10 ** 9, STAMP_NS % 10 ** 9)])
        self.assertEqual(row["dtgd.times.stamp_us"], [shown(STAMP_US // 10 ** 6, STAMP_US % 10 ** 6 * 1000)])
        self.assertEqual(row["dtgd.times.stamp_ms"], [shown(STAMP_MS // 1000, STAMP_MS % 1000 * 10 ** 6)])
        self.assertEqual(row["dtgd.times.boot"], [shown(BOOT_S, 0)])
        # little: Microsoft's mixed-endian form, as Python's bytes_le; big: wire order
        self.assertEqual(row["dtgd.times.object"], [str(uuid.UUID(bytes_le=OBJECT))])
        self.assertEqual(row["dtgd.times.object_big"], [str(uuid.UUID(bytes=OBJECT_BIG))])
        self.assertEqual(row["dtgd.times.object_big"], ["00112233-4455-6677-8899-aabbccddeeff"])

    def test_computed_times_from_the_bytes(self):
        """Computed datetime and time values: counts of their unit from other fields, to the
        nanosecond, as the tree, -T fields, filters and the summary show them."""
        cap = self.capture("clock.pcap", [clock_message(d) for d in CLOCK_DELTAS])
        utc_ns = CLOCK[1] * 10 ** 9 // 2 ** 24
        utc = shown(CLOCK[0], utc_ns)
        rows = self.rows(cap, ["dtgd.clock.utc", "dtgd.clock.midnight", "dtgd.clock.offset", "dtgd.clock.before"])
        for frame, delta in enumerate(CLOCK_DELTAS, 1):
            self.assertEqual(rows[frame]["dtgd.clock.utc"], [utc])
            self.assertEqual(rows[frame]["dtgd.clock.midnight"], [shown(CLOCK[0] - CLOCK[0] % 86400, 0)])
            self.assertEqual(rows[frame]["dtgd.clock.offset"], [offset_shown(delta - 500000)])
            # before 1970: the whole seconds before it, the nanoseconds after them
            before_secs, before_us = divmod(-delta, 10 ** 6)
            self.assertEqual(rows[frame]["dtgd.clock.before"], [shown(before_secs, before_us * 1000)])
        cases = {'dtgd.clock.utc == "%s.%09dZ"' % (datetime.datetime.fromtimestamp(CLOCK[0], datetime.timezone.utc)
                                                  .strftime("%Y-%m-%d %H:%M:%S"), utc_ns): [1, 2],
                 "dtgd.clock.offset < 0": [2], "dtgd.clock.offset > 0.7": [1]}
        for flt, frames in cases.items():
            with self.subTest(filter=flt):
                self.assertEqual(sorted(self.rows(cap, ["dtgd.kind"], display_filter=flt)), frames)
        info = self.env.tshark(["-r", cap, "-T", "fields", "-e", "_ws.col.Info"]).stdout.splitlines()
        self.assertEqual(info, ["%s %s seconds" % (utc, offset_shown(d - 500000)) for d in CLOCK_DELTAS])

    def test_filters_compare_dates_and_guids(self):
        later = (NET_TIME[0] + 86400, 0)
        cap = self.capture("filters.pcap", [times_message(), times_message()[:1] + struct.pack("<II", *later)
                                            + times_message()[9:]])
        cases = {
            'dtgd.times.net_time == "2024-01-01 00:00:00.5Z"': [1],
            'dtgd.times.net_time == "2024-01-01 00:00:00Z"': [],
            'dtgd.times.net_time > "2024-01-01 12:00:00Z"': [2],
            'dtgd.times.stamp == "2023-11-14 22:13:20.987654321Z"': [1, 2],
            'dtgd.times.stamp == "2023-11-14 22:13:20.987654320Z"': [],
            "dtgd.times.object_big == 00112233-4455-6677-8899-aabbccddeeff": [1, 2],
            "dtgd.times.object == %s" % uuid.UUID(bytes_le=OBJECT): [1, 2],
            "dtgd.times.object == %s" % uuid.UUID(bytes=OBJECT): [],
        }
        for flt, frames in cases.items():
            with self.subTest(filter=flt):
                self.assertEqual(sorted(self.rows(cap, ["dtgd.kind"], display_filter=flt)), frames)

    def test_summary_and_tree_show_the_values(self):
        cap = self.capture("tree.pcap", [times_message()])
        out = self.env.tshark(["-r", cap, "-V", "-O", "dtgd"]).stdout
        date, guid = shown(*NET_TIME), str(uuid.UUID(bytes_le=OBJECT))
        self.assertIn("Net time: %s" % date, out)
        self.assertIn("Object: %s" % guid, out)
        self.assertIn("Times: %s %s" % (date, guid), out)   # the summary shows what the items show

    def test_alternatives_share_one_field(self):
        payloads = [short_message(0x11, *NET_TIME), long_message(0x22, STAMP_NS), other_message(4, 0x33),
                    other_message(9, 0x44), bytes([1])]
        cap = self.capture("shared.pcap", payloads)
        rows = self.rows(cap, ["dtgd.option", "dtgd.when", "dtgd.length"])
        self.assertEqual([rows[i]["dtgd.option"] for i in range(1, 6)], [["0x11"], ["0x22"], ["0x33"], ["0x44"], []])
        self.assertEqual(rows[1]["dtgd.when"], [shown(*NET_TIME)])
        self.assertEqual(rows[2]["dtgd.when"], [shown(STAMP_NS // 10 ** 9, STAMP_NS % 10 ** 9)])
        self.assertEqual(rows[2]["dtgd.length"], ["1"])
        self.assertEqual(sorted(self.rows(cap, ["dtgd.kind"], display_filter="dtgd.option")), [1, 2, 3, 4])
        self.assertEqual(sorted(self.rows(cap, ["dtgd.kind"], display_filter="dtgd.option == 0x22")), [2])
        self.assertEqual(sorted(self.rows(cap, ["dtgd.kind"], display_filter="dtgd.when")), [1, 2])
        # Wireshark knows one field of each name
        names = [l.split("\t")[2] for l in self.env.tshark(["-G", "fields"]).stdout.splitlines()
                 if l.startswith("F\t") and l.count("\t") >= 2]
        self.assertEqual(names.count("dtgd.option"), 1)
        self.assertEqual(names.count("dtgd.when"), 1)

    def test_cut_dates_and_guids_give_our_expert_info(self):
        m = times_message()
        obj = m.index(OBJECT)
        cap = self.capture("cut.pcap", [m[:5], m[:obj + 10], short_message(0x11, *NET_TIME)[:7]])
        rows = self.rows(cap, ["dtgd.times.net_time", "dtgd.times.boot", "dtgd.times.object", "dtgd.when",
                               "_ws.expert.message"])
        self.assertEqual(rows[1]["dtgd.times.net_time"], [])
        self.assertIn("Truncated: 'Net time' needs 8 bytes, only 4 left", rows[1]["_ws.expert.message"])
        self.assertEqual(rows[2]["dtgd.times.boot"], [shown(BOOT_S, 0)])
        self.assertEqual(rows[2]["dtgd.times.object"], [])
        self.assertIn("Truncated: 'Object' needs 16 bytes, only 10 left", rows[2]["_ws.expert.message"])
        self.assertIn("Truncated: 'When' needs 8 bytes, only 5 left", rows[3]["_ws.expert.message"])
        out = self.env.tshark(["-r", cap, "-V", "-2"]).stdout
        self.assertNotIn("Malformed Packet", out)
        # and the clean messages raise none
        clean = self.capture("clean.pcap", [times_message(), short_message(1, 2, 3), long_message(4, 5)])
        rows = self.rows(clean, ["_ws.expert"])
        self.assertEqual([r["_ws.expert"] for r in rows.values()], [[], [], []])

    def test_every_cut_decodes_without_exception(self):
        step = 1 if not SANITIZE else 3
        messages = [times_message(), short_message(1, 2, 3), long_message(4, 5)]
        cap = self.capture("cuts.pcap", [m[:n] for m in messages for n in range(1, len(m) + 1, step)])
        p = self.env.tshark(["-r", cap, "-V", "-2"], check=False)
        self.assertEqual(p.returncode, 0, p.stderr[-2000:])
        self.assertNotIn("Dissector bug", p.stdout)
        self.assertNotIn("Malformed Packet", p.stdout)


LATIN1_RULES = """<root name="Latin text" abbreviation="LATT" byteorder="big">
  <hook table="udp.port" value="47490"/>
  <cycles window="1">
    <signature field="node[@name='Label']"/>
  </cycles>
  <node name="Station" summary="{Name}">
    <node name="Name" length="8byte" displaytype="string" encoding="latin-1"/>
  </node>
  <node name="Label" displaytype="stringz" encoding="iso-8859-1"/>
  <node name="Raw" length="8byte" displaytype="string"/>
</root>
"""


class Latin1Text(TsharkTestCase, unittest.TestCase):
    """encoding="latin-1" (or "iso-8859-1"): each byte is its character, as a KNX device
    name or an older PLC's label holds it; the same bytes in UTF-8 are not text."""
    NAME, LABEL = "Müller ß", "Größe"

    @classmethod
    def prepare(cls):
        cls.install_text("latin1.xml", LATIN1_RULES, "latt")
        payload = cls.NAME.encode("latin-1") + cls.LABEL.encode("latin-1") + b"\0" + cls.NAME.encode("latin-1")
        cls.capture = cls.env.add_file("latin1.pcap", pcap([udp(50000, 47490, payload)] * 3))

    def test_latin1_text_from_the_bytes(self):
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(self.capture, ["frame.number", "latt.station.name", "latt.label", "latt.raw",
                                                          "_ws.col.Info"], two_pass=two_pass)
                r = rows[1]
                check(r["latt.station.name"] == [self.NAME] and r["latt.label"] == [self.LABEL],
                      "latin-1 text as its bytes say: %s %s" % (r["latt.station.name"], r["latt.label"]))
                check(r["latt.raw"] != [self.NAME], "the same bytes as UTF-8 are not that text: %s" % r["latt.raw"])
                check(self.NAME in r["_ws.col.Info"][0], "the summary shows the name: %s" % r["_ws.col.Info"])
            filtered = self.env.tshark(["-r", self.capture, "-Y", 'latt.station.name == "%s"' % self.NAME]).stdout
            check(filtered.strip() != "", "a filter compares the text")
            report = self.env.tshark(["-r", self.capture, "-q", "-z", "latt,cycles"]).stdout
            check('Cycle 1: Label "%s"' % self.LABEL in report, "-z latt,cycles names the stream by its text: %s"
                  % report)



FILETIME_RULES = """<root name="Filetime" abbreviation="FTIME" byteorder="little">
  <hook table="udp.port" value="%d"/>
  <node name="Stamp" summary="at {When}">
    <node name="When" length="8byte" displaytype="datetime" unit="filetime"/>
  </node>
</root>
""" % (PORT + 1)
FILETIME_EPOCH = datetime.datetime(1601, 1, 1)


def filetime_shown(count):
    """A count of 100 ns since 1601 as tshark prints an FT_ABSOLUTE_TIME in UTC."""
    t = FILETIME_EPOCH + datetime.timedelta(seconds=count // 10 ** 7)
    return "%s %2d, %d %s.%09d UTC" % (t.strftime("%b"), t.day, t.year, t.strftime("%H:%M:%S"), count % 10 ** 7 * 100)


class Filetime(TsharkTestCase, unittest.TestCase):
    """unit="filetime": 100 ns since 1601 (Windows FILETIME, OPC UA's DateTime), to the last
    100 ns, in the tree, -T fields and the summary, one pass and -2; OPC UA's null DateTime (0)
    is 1601."""

    @classmethod
    def prepare(cls):
        cls.install_text("filetime.xml", FILETIME_RULES, "ftime")

    def test_every_count_to_the_last_digit(self):
        counts = [0, 133485408001234567, 116444736000000000]   # 1601; 2024-01-01 00:00:00.1234567; 1970
        path = self.env.add_file("filetime.pcap", pcap([udp(50000, PORT + 1, struct.pack("<Q", c)) for c in counts]))
        for how, rows in self.env.field_rows_each_pass(path, ["frame.number", "ftime.stamp.when", "_ws.col.Info"],
                                                      aggregator="|"):
            for n, count in enumerate(counts, 1):
                want = filetime_shown(count)
                self.assertEqual(rows[n]["ftime.stamp.when"], [want], how)
                self.assertEqual(rows[n]["_ws.col.Info"], ["at " + want], how)


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

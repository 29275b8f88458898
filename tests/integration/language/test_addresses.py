#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Addresses of one size, with real tshark: `ipv6` (FT_IPv6), `mac` (FT_ETHER) and `eui64`
(FT_EUI64, in either byte order); and object identifiers, `oid` (FT_OID). Each value equals the bytes (tshark's fields), filters
compare them as Wireshark's own fields do, the summary shows what the items show, the tree
names the vendor of a MAC address and an EUI-64, and a message cut inside an address shows
the fields before it and our expert info, never an exception; one pass and -2 alike.

    test_addresses.py --dissgen build/bin/dissgen --source-dir .
"""
import ipaddress
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402
from test_enip import pcap, udp  # noqa: E402

ARGS = None
PORT = 47495
RULES = """<root name="Addresses" abbreviation="ADDR" byteorder="big">
  <hook table="udp.port" value="%d"/>
  <node name="Kind" length="1byte" displaytype="numberdec"/>
  <node name="Station" summary="{Interface} {Mac}">
    <node name="Interface" length="16byte" displaytype="ipv6"/>
    <node name="Mac" length="6byte" displaytype="mac"/>
    <node name="Clock" length="8byte" displaytype="eui64"/>
    <node name="Clock little" length="8byte" displaytype="eui64" byteorder="little"/>
  </node>
</root>
""" % PORT

INTERFACE = ipaddress.IPv6Address("2001:db8::4:0:1")
MAC = bytes.fromhex("0001050a0b0c")       # 00:01:05 is Beckhoff's
CLOCK = bytes.fromhex("00010203fffe0405")


def message(interface=INTERFACE, mac=MAC, clock=CLOCK):
    return bytes([1]) + interface.packed + mac + clock + clock[::-1]


def colons(b):
    return ":".join("%02x" % x for x in b)


class Addresses(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install_text("addresses.xml", RULES, "addr")

    def test_values_match_the_bytes_in_each_pass(self):
        other = ipaddress.IPv6Address("fe80::1")
        cap = self.env.add_file("addresses.pcap", pcap([udp(50000, PORT, message()),
                                                         udp(50000, PORT, message(interface=other))]))
        fields = ["frame.number", "addr.station.interface", "addr.station.mac", "addr.station.clock",
                  "addr.station.clock_little"]
        with self.checks() as check:
            for how, rows in self.env.field_rows_each_pass(cap, fields):
                want = {1: [str(INTERFACE), colons(MAC), colons(CLOCK), colons(CLOCK)],
                        2: [str(other), colons(MAC), colons(CLOCK), colons(CLOCK)]}
                got = {n: [r[f][0] if r[f] else "" for f in fields[1:]] for n, r in rows.items()}
                check(got == want, "%s: the addresses as their bytes say (%s)" % (how, got))

    def test_filters_compare_addresses(self):
        other = ipaddress.IPv6Address("fe80::1")
        cap = self.env.add_file("filters.pcap", pcap([udp(50000, PORT, message()),
                                                       udp(50000, PORT, message(interface=other))]))
        cases = [("addr.station.interface == %s" % INTERFACE, [1]),
                 ("addr.station.interface == fe80::1", [2]),
                 ("addr.station.interface == 2001:db8::/32", [1]),
                 ("addr.station.mac == %s" % colons(MAC), [1, 2]),
                 ("addr.station.mac == 00:01:05:00:00:00", []),
                 ("addr.station.clock == %s" % colons(CLOCK), [1, 2])]
        with self.checks() as check:
            for display_filter, frames in cases:
                rows = self.env.field_rows(cap, ["frame.number"], display_filter=display_filter)
                check(sorted(rows) == frames, "%s: frames %s (%s)" % (display_filter, frames, sorted(rows)))

    def test_summary_and_tree_show_the_values(self):
        cap = self.env.add_file("tree.pcap", pcap([udp(50000, PORT, message())]))
        out = self.env.tshark(["-r", self.env.readable(cap), "-V", "-O", "addr"]).stdout
        with self.checks() as check:
            check("Station: %s %s" % (INTERFACE, colons(MAC)) in out, "the summary shows the IPv6 and MAC addresses")
            check("Interface: %s" % INTERFACE in out, "the tree shows the IPv6 address")
            check("Mac: Beckhoff_0a:0b:0c (%s)" % colons(MAC) in out, "the tree names the MAC address's vendor")
            check("Clock little: 3Com_03:ff:fe:04:05 (%s)" % colons(CLOCK) in out,
                  "a little-endian EUI-64 read in its byte order, its vendor named")

    def test_a_cut_address_gives_our_expert_info(self):
        # messages the sender cut short (the datagrams are whole): inside each address
        cuts = [1 + 7, 1 + 16 + 3, 1 + 16 + 6 + 5]
        cap = self.env.add_file("cut.pcap", pcap([udp(50000, PORT, message()[:at]) for at in cuts]))
        fields = ["frame.number", "addr.kind", "addr.station.interface", "addr.station.mac", "addr.station.clock",
                  "_ws.expert.message"]
        want = {1: ([], [], [], "Truncated: 'Interface' needs 16 bytes, only 7 left"),
                2: ([str(INTERFACE)], [], [], "Truncated: 'Mac' needs 6 bytes, only 3 left"),
                3: ([str(INTERFACE)], [colons(MAC)], [], "Truncated: 'Clock' needs 8 bytes, only 5 left")}
        with self.checks() as check:
            for how, rows in self.env.field_rows_each_pass(cap, fields, aggregator="|"):
                for n, (interface, mac, clock, note) in want.items():
                    r = rows[n]
                    check(r["addr.kind"] == ["1"] and r["addr.station.interface"] == interface and
                          r["addr.station.mac"] == mac and r["addr.station.clock"] == clock,
                          "%s, frame %d: the addresses before the cut shown, the cut one not (%s)" % (how, n, r))
                    check(r["_ws.expert.message"] == [note],
                          "%s, frame %d: %s (%s)" % (how, n, note, r["_ws.expert.message"]))

    def test_every_cut_decodes_without_exception(self):
        m = message()
        cap = self.env.add_file("cuts.pcap", pcap([udp(50000, PORT, m[:n]) for n in range(1, len(m))]))
        for two_pass in ([], ["-2"]):
            p = self.env.tshark(["-r", cap, "-V"] + two_pass, check=False)
            self.assertEqual(p.returncode, 0, p.stderr[-2000:])
            self.assertNotIn("Dissector bug", p.stdout)
            self.assertNotIn("Malformed Packet", p.stdout)

# --- object identifiers -------------------------------------------------------------

OID_PORT = 47496
OID_RULES = """<root name="Object ids" abbreviation="OIDT">
  <hook table="udp.port" value="%d"/>
  <node name="Entry" summary="{Object} / {Fixed}">
    <node name="Length" length="1byte" displaytype="numberdec"/>
    <node name="Object" length="../node[@name='Length']" displaytype="oid"/>
    <node name="Fixed" length="3byte" displaytype="oid"/>
  </node>
</root>
""" % OID_PORT


def dotted(ber):
    """An OID's BER content octets (no tag, no length) as dotted decimal: the truth from the bytes."""
    arcs, value = [], 0
    for b in ber:
        value = value << 7 | b & 0x7F
        if not b & 0x80:
            arcs.append(value)
            value = 0
    first = arcs[0]
    head = [min(first // 40, 2), first - 40 * min(first // 40, 2)]
    return ".".join(str(a) for a in head + arcs[1:])


class ObjectIdentifiers(TsharkTestCase, unittest.TestCase):
    """`oid` (FT_OID): BER content octets shown dotted, as LLDP's management address OID or
    SNMP's: values equal the bytes decoded here, filters compare OIDs, the Info column shows
    what the items show, an empty one adds no item, and one cut short shows none of its
    bytes (they would be another OID) with our expert info; one pass and -2 alike."""

    OIDS = ["2b06010401bf08030204", "2b060102010101", "550403", "8837", ""]  # net-snmp, sysDescr, cn, 2.999
    FIXED = "2a8648"

    @classmethod
    def prepare(cls):
        cls.install_text("oids.xml", OID_RULES, "oidt")
        entries = [bytes([len(o) // 2]) + bytes.fromhex(o + cls.FIXED) for o in cls.OIDS]
        cut = bytes([10]) + bytes.fromhex(cls.OIDS[0])[:5]
        cls.capture = cls.env.add_file("oids.pcap", pcap([udp(50000, OID_PORT, e) for e in entries + [cut]]))

    def test_values_filters_and_info(self):
        fields = ["frame.number", "oidt.entry.object", "oidt.entry.fixed", "_ws.col.Info", "_ws.expert.message"]
        with self.checks() as check:
            for how, rows in self.env.field_rows_each_pass(self.capture, fields, aggregator="|"):
                for n, o in enumerate(self.OIDS, 1):
                    want = [dotted(bytes.fromhex(o))] if o else []
                    got = rows[n]["oidt.entry.object"], rows[n]["oidt.entry.fixed"], rows[n]["_ws.col.Info"]
                    check(got == (want, ["1.2.840"], ["%s / 1.2.840" % (want[0] if want else "")]),
                          "%s frame %d: %s, expected %s" % (how, n, got, want))
                cut = rows[len(self.OIDS) + 1]
                check(not cut["oidt.entry.object"] and cut["_ws.expert.message"] ==
                      ["'Object' has length 10, past the end of its data (5 bytes left)"],
                      "%s: a cut OID shows none of it, and our expert info: %s" % (how, cut))
            found = self.env.field_rows(self.capture, ["frame.number"],
                                        display_filter="oidt.entry.object == 1.3.6.1.2.1.1.1")
            check(sorted(found) == [2], "the filter finds sysDescr's frame: %s" % sorted(found))


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

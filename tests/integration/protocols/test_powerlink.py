#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Ethernet POWERLINK from rules alone: rules/powerlink.xml (eplr) against Wireshark's epl,
value by value, on generated captures (eplgen.py): SoC, PReq, PRes, SoA and ASnd with every
flag at random, AInv and AMNI, ASnd's IdentResponse, StatusResponse, NMTRequest, NMTCommand and SDO.

- the plugin loads beside Wireshark's epl and takes ethertype 0x88AB; with eplr disabled,
  epl decodes the frames again;
- for each Wireshark field of COUNTERPARTS, per frame, its values are matched with our
  counterpart fields' values (as multisets); the agreement is the share of Wireshark's
  values matched, printed with every value that did not match; goal: 99.5 %, in one pass
  and with -2;
- fields of Wireshark's without a counterpart are listed (WITHOUT_COUNTERPART says why);
- PReq/PRes payloads laid out by the PDO mappings SDO writes configured (learned from earlier
  frames), against epl's and against the bytes, with the note where a mapping was not seen;
- <cycles>: the SoC stream and each node's PRes stream are timed to the nanosecond from
  the generator's timestamps (a regular cycle with known jitter and a dropped PRes), in
  the manner of test_rule_cycles.py (cyclemodel.py), and -z eplr,cycles agrees.
"""
import os
import random
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import cyclemodel  # noqa: E402
import differential  # noqa: E402
import eplgen  # noqa: E402
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402

FEATURES = ["isochronous", "sdo_udp", "sdo_asnd", "sdo_pdo", "nmt_info", "ext_nmt_commands", "dynamic_pdo_mapping",
            "nmt_udp", "configuration_manager", "multiplexed_access", "node_id_by_sw", "mn_basic_ethernet",
            "routing_type1", "routing_type2", "sdo_rw_all", "sdo_rw_multiple", "multiple_asnd", "ring_redundancy",
            "pres_chaining", "multiple_preq_pres", "dynamic_node_allocation", "modular_device"]
# The <enum> names of rules/powerlink.xml's MessageType, a <cycles> signature field.
MESSAGE_TYPES = {0x01: "Start of Cycle (SoC)", 0x03: "PollRequest (PReq)", 0x04: "PollResponse (PRes)",
                 0x05: "Start of Asynchronous (SoA)", 0x06: "Asynchronous Send (ASnd)",
                 0x07: "Active Managing Node Indication (AMNI)", 0x0D: "Asynchronous Invite (AInv)"}
# epl names the feature bits by their number in hex up to 0x14, then "bit21" for bit 21.
FEATURE_BITS = ["%X" % n for n in range(21)] + ["21"]

# Wireshark's fields -> ours (each side a list: their values are pooled per frame).
COUNTERPARTS = [
    (["epl.mtyp"], ["eplr.mtyp"]),
    (["epl.dest"], ["eplr.dest"]),
    (["epl.src"], ["eplr.src"]),
    (["epl.node"], ["eplr.dest", "eplr.src"]),
    (["epl.soc.flags"], ["eplr.soc.flags"]),
    (["epl.soc.mc"], ["eplr.soc.mc"]),
    (["epl.soc.ps"], ["eplr.soc.ps"]),
    (["epl.soc.an"], ["eplr.soc.an"]),
    (["epl.soc.nettime"], ["eplr.soc.nettime"]),
    (["epl.soc.relativetime"], ["eplr.soc.relativetime"]),
    (["epl.preq.flags"], ["eplr.preq.flags"]),
    (["epl.preq.ms"], ["eplr.preq.ms"]),
    (["epl.preq.ea"], ["eplr.preq.ea"]),
    (["epl.preq.rd"], ["eplr.preq.rd"]),
    (["epl.preq.sls"], ["eplr.preq.sls"]),
    (["epl.preq.fls"], ["eplr.preq.fls"]),
    (["epl.preq.pdov"], ["eplr.preq.pdov"]),
    (["epl.preq.size"], ["eplr.preq.size"]),
    (["epl.pres.stat"], ["eplr.pres.stat"]),
    (["epl.pres.flags"], ["eplr.pres.flags"]),
    (["epl.pres.ms"], ["eplr.pres.ms"]),
    (["epl.pres.en"], ["eplr.pres.en"]),
    (["epl.pres.rd"], ["eplr.pres.rd"]),
    (["epl.pres.pr"], ["eplr.pres.pr"]),
    (["epl.pres.rs"], ["eplr.pres.rs"]),
    (["epl.pres.sls"], ["eplr.pres.sls"]),
    (["epl.pres.fls"], ["eplr.pres.fls"]),
    (["epl.pres.pdov"], ["eplr.pres.pdov"]),
    (["epl.pres.size"], ["eplr.pres.size"]),
    (["epl.soa.stat"], ["eplr.soa.stat", "eplr.ainv.stat"]),
    (["epl.soa.ea"], ["eplr.soa.ea", "eplr.ainv.ea"]),
    (["epl.soa.er"], ["eplr.soa.er", "eplr.ainv.er"]),
    (["epl.soa.an.global"], ["eplr.soa.an_global"]),
    (["epl.soa.an.local"], ["eplr.soa.an_local"]),
    (["epl.soa.svid"], ["eplr.soa.svid"]),
    (["epl.soa.svtg"], ["eplr.soa.svtg"]),
    (["epl.soa.eplv"], ["eplr.soa.eplv"]),
    (["epl.soa.rrFlags"], ["eplr.soa.rr_flags"]),
    (["epl.soa.rrFlags.mnred"], ["eplr.soa.rr.mn_redundancy"]),
    (["epl.soa.rrFlags.cblred"], ["eplr.soa.rr.cable_redundancy"]),
    (["epl.soa.rrFlags.ringred"], ["eplr.soa.rr.ring_redundancy"]),
    (["epl.soa.rrFlags.ringstat"], ["eplr.soa.rr.ring_status"]),
    (["epl.asnd.svid"], ["eplr.asnd.svid", "eplr.ainv.svid"]),
    (["epl.asnd.ires.en", "epl.asnd.sres.en"], ["eplr.asnd.en"]),
    (["epl.asnd.ires.ec", "epl.asnd.sres.ec"], ["eplr.asnd.ec"]),
    (["epl.asnd.ires.pr", "epl.asnd.sres.pr"], ["eplr.asnd.pr"]),
    (["epl.asnd.ires.rs", "epl.asnd.sres.rs"], ["eplr.asnd.rs"]),
    (["epl.asnd.ires.sls", "epl.asnd.sres.sls"], ["eplr.asnd.sls"]),
    (["epl.asnd.ires.fls", "epl.asnd.sres.fls"], ["eplr.asnd.fls"]),
    (["epl.asnd.ires.state", "epl.asnd.sres.stat"], ["eplr.asnd.stat"]),
    (["epl.asnd.ires.eplver"], ["eplr.asnd.ires.eplver"]),
    (["epl.asnd.ires.features"], ["eplr.asnd.ires.features"]),
] + [(["epl.asnd.ires.features.bit" + b], ["eplr.asnd.ires.feature." + f]) for b, f in zip(FEATURE_BITS, FEATURES)] + [
    (["epl.asnd.ires.%s" % ws], ["eplr.asnd.ires.%s" % ours]) for ws, ours in [
        ("mtu", "mtu"), ("pollinsize", "pollinsize"), ("polloutsizes", "polloutsize"), ("resptime", "resptime"),
        ("devicetype", "devicetype"), ("devicetype.add", "devicetype_add"), ("vendorid", "vendorid"),
        ("productcode", "productcode"), ("revisionno", "revisionno"), ("serialno", "serialno"),
        ("vendorext1", "vendorext1"), ("confdate", "confdate"), ("conftime", "conftime"),
        ("appswdate", "appswdate"), ("appswtime", "appswtime"), ("ip", "ip"), ("subnet", "subnet"),
        ("gateway", "gateway"), ("hostname", "hostname"), ("vendorext2", "vendorext2")]
] + [
    (["epl.asnd.res.seb.bit0"], ["eplr.asnd.sres.seb.generic"]),
    (["epl.asnd.res.seb.bit1"], ["eplr.asnd.sres.seb.current"]),
    (["epl.asnd.res.seb.bit2"], ["eplr.asnd.sres.seb.voltage"]),
    (["epl.asnd.res.seb.bit3"], ["eplr.asnd.sres.seb.temperature"]),
    (["epl.asnd.res.seb.bit4"], ["eplr.asnd.sres.seb.communication"]),
    (["epl.asnd.res.seb.bit5"], ["eplr.asnd.sres.seb.device_profile"]),
    (["epl.asnd.res.seb.bit7"], ["eplr.asnd.sres.seb.manufacturer"]),
    (["epl.asnd.res.seb.devicespecific_err"], ["eplr.asnd.sres.seb.device_specific"]),
    (["epl.asnd.sres.el.entry.type"], ["eplr.asnd.sres.entry.type"]),
    (["epl.asnd.sres.el.entry.type.profile"], ["eplr.asnd.sres.entry.profile"]),
    (["epl.asnd.sres.el.entry.type.mode"], ["eplr.asnd.sres.entry.mode"]),
    (["epl.asnd.sres.el.entry.type.bit14"], ["eplr.asnd.sres.entry.bit14"]),
    (["epl.asnd.sres.el.entry.type.bit15"], ["eplr.asnd.sres.entry.bit15"]),
    (["epl.asnd.sres.el.entry.code"], ["eplr.asnd.sres.entry.code"]),
    (["epl.asnd.sres.el.entry.time"], ["eplr.asnd.sres.entry.time"]),
    (["epl.asnd.sres.el.entry.add"], ["eplr.asnd.sres.entry.add"]),
    (["epl.asnd.nmtrequest.rcid"], ["eplr.asnd.nmtrequest.rcid"]),
    (["epl.asnd.nmtrequest.rct"], ["eplr.asnd.nmtrequest.rct"]),
    (["epl.asnd.nmtrequest.rcd"], ["eplr.asnd.nmtrequest.rcd"]),
    (["epl.asnd.nmtcommand.cid"], ["eplr.asnd.nmtcommand.cid"]),
    (["epl.asnd.nmtcommand.cdat"], ["eplr.asnd.nmtcommand.cdat"]),
    (["epl.asnd.sdo.seq.receive.sequence.number"], ["eplr.asnd.sdo.seq.receive_sequence_number"]),
    (["epl.asnd.sdo.seq.receive.con"], ["eplr.asnd.sdo.seq.receive_con"]),
    (["epl.asnd.sdo.seq.send.sequence.number"], ["eplr.asnd.sdo.seq.send_sequence_number"]),
    (["epl.asnd.sdo.seq.send.con"], ["eplr.asnd.sdo.seq.send_con"]),
    (["epl.asnd.sdo.cmd.transaction.id"], ["eplr.asnd.sdo.cmd.transaction_id"]),
    (["epl.asnd.sdo.cmd.response"], ["eplr.asnd.sdo.cmd.response"]),
    (["epl.asnd.sdo.cmd.abort"], ["eplr.asnd.sdo.cmd.abort"]),
    (["epl.asnd.sdo.cmd.segmentation"], ["eplr.asnd.sdo.cmd.segmentation"]),
    (["epl.asnd.sdo.cmd.command.id"], ["eplr.asnd.sdo.cmd.command_id"]),
    (["epl.asnd.sdo.cmd.segment.size"], ["eplr.asnd.sdo.cmd.segment_size"]),
    (["epl.asnd.sdo.cmd.data.size"], ["eplr.asnd.sdo.cmd.data_size"]),
    (["epl.asnd.sdo.cmd.data.index"], ["eplr.asnd.sdo.cmd.index"]),
    (["epl.asnd.sdo.cmd.data.subindex"], ["eplr.asnd.sdo.cmd.subindex"]),
    (["epl.asnd.sdo.cmd.data.mapping.index"], ["eplr.asnd.sdo.cmd.mapping.index"]),
    (["epl.asnd.sdo.cmd.data.mapping.subindex"], ["eplr.asnd.sdo.cmd.mapping.subindex"]),
    (["epl.asnd.sdo.cmd.data.mapping.offset"], ["eplr.asnd.sdo.cmd.mapping.offset"]),
    (["epl.asnd.sdo.cmd.data.mapping.length"], ["eplr.asnd.sdo.cmd.mapping.length"]),
]

# PDOs laid out by the mappings SDO writes taught (PdoMappingsAgainstWireshark's captures).
PDO_COUNTERPARTS = [
    (["epl.pdo.index"], ["eplr.preq.pdo.index", "eplr.pres.pdo.index"]),
    (["epl.pdo.subindex"], ["eplr.preq.pdo.subindex", "eplr.pres.pdo.subindex"]),
    # (and, on an SDO write, the value written: here a mapping's number of entries)
    (["epl.od.data.uint"], ["eplr.preq.pdo.data", "eplr.pres.pdo.data", "eplr.asnd.sdo.cmd.mapping_entries"]),
]

# Not compared: after an AInv's service ID of 1 to 6 (an ASnd service), epl reads the rest of
# the AInv as that service's payload (an IdentResponse, ...); eplr keeps it raw, as DS 302-A's
# AInv carries no service payload. eplgen's AInv invite the other services.

# Wireshark's fields (of those epl shows on these captures) that have no counterpart, and why.
WITHOUT_COUNTERPART = {
    "epl.soc": "a hidden flag epl sets per message type: eplr.mtyp says the type",
    "epl.preq": "a hidden flag per message type (eplr.mtyp)",
    "epl.pres": "a hidden flag per message type (eplr.mtyp)",
    "epl.soa": "a hidden flag per message type (eplr.mtyp)",
    "epl.asnd": "a hidden flag per message type (eplr.mtyp)",
    "epl.ainv": "a hidden flag per message type (eplr.mtyp)",
    "epl.amni": "a hidden flag per message type (eplr.mtyp)",
    "epl.payload.capture_size": "epl's count of the PDO bytes captured: eplr.preq.payload/eplr.pres.payload "
                                "are those bytes (their length)",
    "epl.asnd.sdo.seq": "a container (eplr.asnd.sdo.seq is one too; containers carry no value)",
    "epl.asnd.sdo.cmd": "a container (eplr.asnd.sdo.cmd)",
    "epl.asnd.sdo.cmd.abort.code": "epl registers it as FT_UINT8 and shows the low byte of the 4-byte code; "
                                   "eplr.asnd.sdo.cmd.abort_code is the whole 32-bit code",
    "epl.asnd.sdo.cmd.sub.abort": "epl's reading of the abort bit in a sub-transfer of a multiple-parameter "
                                  "command, whose data eplr keeps raw",
    "epl.asnd.sdo.cmd.data.padding": "epl shows the padding byte after a by-index request's subindex on some "
                                     "commands only; eplr.asnd.sdo.cmd.padding is always there",
    "epl.asnd.sdo.cmd.data.mapping": "a container (eplr.asnd.sdo.cmd.mapping is one too)",
    "epl.asnd.sdo.od.multiparam.abort": "a sub-transfer's abort in a multiple-parameter command's data, "
                                        "which eplr keeps raw",
    "epl.asnd.sdo.cmd.fragments": "epl reassembles segmented SDO transfers across frames; eplr does not",
    "epl.asnd.sdo.cmd.reassembled.in": "as epl.asnd.sdo.cmd.fragments",
    "epl.asnd.sdo.cmd.reassembled.data": "as epl.asnd.sdo.cmd.fragments",
    "epl.asnd.sdo.cmd.reassembled.length": "as epl.asnd.sdo.cmd.fragments",
    "epl.asnd.sdo.cmd.reassembled": "as epl.asnd.sdo.cmd.fragments",
    "epl.asnd.sdo.cmd.fragment": "as epl.asnd.sdo.cmd.fragments",
    "epl.asnd.sdo.cmd.fragment.count": "as epl.asnd.sdo.cmd.fragments",
    "epl.asnd.sdo.duplication": "epl's cross-frame check of repeated sequence numbers; eplr has none",
    "epl.error.value.send.sequence": "epl's cross-frame check of the sequence numbers' progress",
    "epl.error.value.receive.sequence": "as epl.error.value.send.sequence",
    "epl.asnd.nmtcommand.resetnode_reason": "the per-command layouts of NMTCommandData stay raw "
                                            "(eplr.asnd.nmtcommand.cdat)",
    "epl.asnd.nmtcommand.nmtnethostnameset.hn": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.nmtflusharpentry.nid": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.nmtpublishtime.dt": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.flags": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.ltv": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.hpm": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.nnn": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.mac": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.cnn": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.currmac": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.hubenmsk": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.currnn": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.newnn": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.asnd.nmtcommand.dna.leasetime": "as epl.asnd.nmtcommand.resetnode_reason",
    "epl.od.data.uint": "on these captures, epl's guess of a PDO value without a mapping (a payload of "
                        "up to 8 bytes as a number): eplr keeps a payload whose mapping was not seen raw; laid "
                        "out PDOs are compared by PdoMappingsAgainstWireshark",
    "epl.od.data.bytestring": "as epl.od.data.uint",
    "epl.pdo": "the PDO entry's label (its index:subindex): eplr.preq.pdo.index and .subindex",
    "epl.pdo.index": "compared by PdoMappingsAgainstWireshark, on captures that map every PDO",
    "epl.pdo.subindex": "as epl.pdo.index",
    "epl.error.payload.length.differs": "an expert info of epl's on PDO sizes",
}


# Fields of bytes: epl prints them as 0102..., eplr as 01 02 ...
BYTE_FIELDS = {"epl.asnd.ires.vendorext2", "epl.asnd.res.seb.devicespecific_err", "epl.asnd.nmtrequest.rcd",
               "epl.asnd.nmtcommand.cdat", "eplr.asnd.ires.vendorext2", "eplr.asnd.sres.seb.device_specific",
               "eplr.asnd.nmtrequest.rcd", "eplr.asnd.nmtcommand.cdat"}


def normalized(field, value):
    """A value as tshark -T fields prints it, comparable across the two dissectors: bytes
    without separators, booleans and numbers as ints, anything else as text."""
    if field in BYTE_FIELDS:
        return value.replace(":", "").replace(" ", "").lower()
    return differential.number_or_text(value)


class PowerlinkAgainstWireshark(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install("rules/powerlink.xml", "eplr")
        cls.frames = eplgen.all_frames(random.Random(41), rounds=150)
        cls.capture = cls.env.add_file("powerlink.pcap", eplgen.pcap(cls.frames))

    def rows(self, fields, extra=()):
        return differential.field_table(self.env, self.capture, fields, extra)

    def test_ours_decodes_wireshark_stays_selectable(self):
        with self.checks() as check:
            protos = self.rows(["frame.protocols"])
            check(len(protos) == len(self.frames), "%d frames read" % len(protos))
            check(all("eplr" in p[0][0].split(":") and "epl" not in p[0][0].split(":") for p in protos.values()),
                  "eplr decodes every frame, epl none")
            # (epl hands some ASnd frames' last bytes to data and is then left out of
            # frame.protocols, though it decoded them: its message type says it did.)
            theirs = self.rows(["epl.mtyp"], ["--disable-protocol", "eplr"])
            check(all(p[0] for p in theirs.values()), "with eplr disabled, epl decodes every frame")

    def test_values_agree_with_wireshark(self):
        with self.checks() as check:
            for two_pass in (False, True):
                total, matched, misses = differential.agreement(self.env, self.capture, COUNTERPARTS, "eplr",
                                                                normalized, ["-2"] if two_pass else [])
                share = 100.0 * matched / max(total, 1)
                print("agreement%s: %d of %d Wireshark values (%.3f %%)"
                      % (" (-2)" if two_pass else "", matched, total, share))
                for (field, frame, value), n in sorted(misses.items()):
                    print("  not matched: %s = %r in frame %d (x%d)" % (field, value, frame, n))
                check(total > 20000, "the captures give epl many values (%d)" % total)
                check(share >= 99.5, "agreement %.2f %% >= 99.5 %%" % share)

    def test_no_expert_info_on_generated_captures(self):
        """None but the note on each node's first PReq/PRes whose mapping was not seen
        (PdoMappingsAgainstWireshark checks where those are)."""
        unseen = "eplr.finding.preq_mapping_unseen || eplr.finding.pres_mapping_unseen"
        with self.checks() as check:
            for two_pass in ([], ["-2"]):
                clean = self.env.tshark(["-r", self.capture, "-Y", "_ws.expert && !(%s)" % unseen, "-T", "fields",
                                         "-e", "frame.number"] + two_pass).stdout.split()
                check(clean == [], "no expert info %s: %s" % (two_pass, clean[:5]))

    def test_size_past_the_frame_is_reported_where_it_is(self):
        """A PRes whose Size points past the frame gets eplr.expert.past_end on that frame
        only, in one pass and with -2 (the generated captures have none: above)."""
        rng = random.Random(3)
        frames = [eplgen.ethernet(eplgen.PRES, 5, eplgen.pres(rng, 5)) for _ in range(10)]
        lying = 7
        frame = bytearray(frames[lying - 1])
        frame[14 + 8:14 + 10] = struct.pack("<H", 2000)
        frames[lying - 1] = bytes(frame)
        cap = self.env.add_file("past_end.pcap", eplgen.pcap(frames))
        with self.checks() as check:
            for two_pass in ([], ["-2"]):
                rows = self.env.tshark(["-r", cap, "-Y", "eplr.expert.past_end", "-T", "fields",
                                        "-e", "frame.number"] + two_pass).stdout.split()
                check(rows == [str(lying)], "past_end %s on frame %d only: %s" % (two_pass, lying, rows))

    def test_wireshark_fields_without_counterpart_are_listed(self):
        """Every field epl shows on these captures has a counterpart or a reason in
        WITHOUT_COUNTERPART."""
        mapped = {f for ws, _ in COUNTERPARTS for f in ws}
        shown = differential.fields_shown(self.env, self.capture, ["epl."], "eplr")
        unexplained = sorted(shown - mapped - set(WITHOUT_COUNTERPART))
        print("\nepl fields without a counterpart: " + ", ".join(sorted(shown - mapped)))
        self.assertEqual(unexplained, [])


class PdoMappingsAgainstWireshark(TsharkTestCase, unittest.TestCase):
    """PReq and PRes payloads laid out by the mappings that SDO writes configured (0x1600 and
    0x1A00 per node, learned from earlier frames): value by value against epl, which learns
    them too (its use_sdo_mappings preference, on by default), on byte-aligned entries; against
    the bytes (a model of the frames) on byte-aligned and on bit-granular entries, in one pass,
    with -2 and with -2 and a filter; the note on each node's first PReq/PRes whose mapping was
    not seen sits exactly there."""

    @classmethod
    def prepare(cls):
        cls.install("rules/powerlink.xml", "eplr")
        cls.frames, cls.truth = eplgen.mapped_traffic(random.Random(5))
        cls.capture = cls.env.add_file("mapped.pcap", eplgen.pcap(cls.frames))
        cls.bit_frames, cls.bit_truth = eplgen.mapped_traffic(random.Random(6), bit_granular=True)
        cls.bit_capture = cls.env.add_file("mapped_bits.pcap", eplgen.pcap(cls.bit_frames))

    def test_values_agree_with_wireshark(self):
        with self.checks() as check:
            for two_pass in (False, True):
                total, matched, misses = differential.agreement(self.env, self.capture,
                                                                COUNTERPARTS + PDO_COUNTERPARTS, "eplr", normalized,
                                                                ["-2"] if two_pass else [])
                for (field, frame, value), n in sorted(misses.items()):
                    print("  not matched: %s = %r in frame %d (x%d)" % (field, value, frame, n))
                pdo_total, pdo_matched, _ = differential.agreement(self.env, self.capture, PDO_COUNTERPARTS, "eplr",
                                                                   normalized, ["-2"] if two_pass else [])
                mode = " (-2)" if two_pass else ""
                print("agreement%s: %d of %d values, %d of %d PDO values" % (mode, matched, total, pdo_matched,
                                                                            pdo_total))
                check(pdo_total > 1500, "epl lays out many PDO values%s (%d)" % (mode, pdo_total))
                check(matched == total, "every value of epl's matched%s: %d of %d" % (mode, matched, total))

    def decoded(self, capture, two_pass, display_filter=None):
        """{frame: [(index, subindex, value)] or None} of each PReq/PRes as eplr laid it out."""
        fields = ["frame.number", "eplr.mtyp", "eplr.preq.mapped", "eplr.pres.mapped", "eplr.preq.pdo.index",
                  "eplr.pres.pdo.index", "eplr.preq.pdo.subindex", "eplr.pres.pdo.subindex", "eplr.preq.pdo.data",
                  "eplr.pres.pdo.data"]
        rows = self.env.field_rows(capture, fields, two_pass, display_filter=display_filter, aggregator=",")
        out = {}
        for frame, row in rows.items():
            kind = "preq" if row["eplr.mtyp"] == ["0x03"] else "pres" if row["eplr.mtyp"] == ["0x04"] else None
            if not kind:
                continue
            if row["eplr.%s.mapped" % kind] not in (["1"], ["True"]):
                out[frame] = None
                continue
            values = [row["eplr.%s.pdo.%s" % (kind, f)] for f in ("index", "subindex", "data")]
            out[frame] = [tuple(int(v, 0) for v in entry) for entry in zip(*values)]
        return out

    def test_pdo_values_are_the_bytes(self):
        with self.checks() as check:
            for capture, truth, what in ((self.capture, self.truth, "byte-aligned"),
                                         (self.bit_capture, self.bit_truth, "bit-granular")):
                want = {frame: t["entries"] for frame, t in truth.items()}
                laid_out = sum(len(e) for e in want.values() if e)
                self.check_every_pass(check, lambda two_pass, shown: self.decoded(capture, two_pass, shown), want,
                                      "%s: %d entries of PReq/PRes as their bytes say" % (what, laid_out))

    def test_mapping_unseen_note_exactly_where(self):
        want = sorted(f for f, t in self.truth.items() if t["note"])
        unseen = "eplr.finding.preq_mapping_unseen || eplr.finding.pres_mapping_unseen"
        with self.checks() as check:
            check(len(want) == 4, "two unmapped nodes: a first PReq and a first PRes each (%s)" % want)
            for two_pass in ([], ["-2"]):
                got = [int(f) for f in self.env.tshark(["-r", self.capture, "-Y", unseen, "-T", "fields",
                                                        "-e", "frame.number"] + two_pass).stdout.split()]
                check(got == want, "the note %s on frames %s (got %s)" % (two_pass, want, got))
                # (the mapping written anew halfway takes a round's time: the PRes streams' timing
                # counts a message lost there, eplr.expert.cycle_lost)
                other = self.env.tshark(["-r", self.capture, "-Y", "_ws.expert && !(%s) && !eplr.expert.cycle_lost"
                                         % unseen, "-T", "fields", "-e", "frame.number"] + two_pass).stdout.split()
                check(other == [], "no other expert info %s: %s" % (two_pass, other[:5]))


class CyclesOfTheIsochronousPhase(TsharkTestCase, unittest.TestCase):
    """<cycles> in rules/powerlink.xml: the SoC stream and each node's PRes stream are
    cycles, timed to the ns as the manual says (cyclemodel) and as the generator made them
    (its SoC times, with their jitter); the dropped PRes is a gap in its node's stream: a
    period of two cycles, one message lost (lost="period"), no jitter."""

    @classmethod
    def prepare(cls):
        cls.install("rules/powerlink.xml", "eplr")
        cls.nodes = (1, 2, 3)
        cls.dropped = (2, 17)
        cls.period = 400_000
        cls.packets, cls.truth = eplgen.cycle(random.Random(88), cycles=40, period_ns=cls.period,
                                              nodes=cls.nodes, dropped=cls.dropped)
        cls.capture = cls.env.add_file("cycle.pcap", cyclemodel.pcap_ns(cls.packets))

    def timed(self):
        """(frame, time ns, (message type, source), None) of every SoC and PRes."""
        return [(n, t, (f[14] & 0x7F, f[16]), None) for n, (t, f) in enumerate(self.packets, 1)
                if f[14] & 0x7F in (eplgen.SOC, eplgen.PRES)]

    def marks(self, two_pass):
        rows = self.env.field_rows(self.capture, ["frame.number"] + cyclemodel.mark_fields("eplr"),
                                   two_pass=two_pass)
        return {frame: got for frame, got in ((f, cyclemodel.mark_of(row, "eplr")) for f, row in rows.items())
                if got}

    def lost_experts(self, two_pass):
        """{frame: the cycle_lost expert's count} (its text says how many)."""
        rows = self.env.field_rows(self.capture, ["frame.number", "eplr.expert.cycle_lost", "_ws.expert.message"],
                                   two_pass=two_pass)
        return {f: row["_ws.expert.message"] for f, row in rows.items() if row["eplr.expert.cycle_lost"]}

    def test_marks_follow_the_manuals_model(self):
        marks, cycles = cyclemodel.model(self.timed(), window=8, bits=0, lost_by_period=True)
        with self.checks() as check:
            check(len(cycles) == 1 + len(self.nodes), "%d cycles: the SoC's and one per node" % len(cycles))
            for two_pass in (False, True):
                got = self.marks(two_pass)
                for frame in sorted(set(got) | set(marks)):
                    check(got.get(frame) == marks.get(frame), "frame %d %s: %s, expected %s" % (
                        frame, "-2" if two_pass else "one pass", got.get(frame), marks.get(frame)))

    def test_soc_periods_are_the_generators(self):
        """Every timed SoC's period is the time between the generator's SoCs, to the ns."""
        soc_times = self.truth["soc"]
        soc_frames = [n for n, (t, f) in enumerate(self.packets, 1) if f[14] & 0x7F == eplgen.SOC]
        with self.checks() as check:
            for two_pass in (False, True):
                got = self.marks(two_pass)
                timed = [k for k, frame in enumerate(soc_frames) if frame in got]
                check(len(timed) == len(soc_frames) - 8, "%d SoCs timed (all after the window of 8)" % len(timed))
                for k in timed:
                    want = soc_times[k] - soc_times[k - 1]
                    check(got[soc_frames[k]]["period"] == want,
                          "SoC %d period %d ns, generated %d" % (k, got[soc_frames[k]]["period"], want))

    def test_dropped_pres_is_a_gap_in_its_nodes_stream(self):
        node, lost_cycle = self.dropped
        pres = [(n, t) for n, (t, f) in enumerate(self.packets, 1)
                if f[14] & 0x7F == eplgen.PRES and f[16] == node]
        after = next(k for k, (n, t) in enumerate(pres) if t > self.truth["soc"][lost_cycle])
        frame, t = pres[after]
        with self.checks() as check:
            for two_pass in (False, True):
                got = self.marks(two_pass).get(frame, {})
                check(got.get("period") == t - pres[after - 1][1],
                      "the PRes after the gap: period %s, generated %d" % (got.get("period"), t - pres[after - 1][1]))
                check(abs(got.get("period", 0) - 2 * self.period) < self.period // 10, "about two cycles")
                # lost="period": two whole cycles are one PRes lost, and the gap has no jitter
                check(got.get("lost") == 1 and "jitter" not in got, "one lost, no jitter: %s" % got)
                experts = self.lost_experts(two_pass)
                check(list(experts) == [frame], "the lost expert only on frame %d: %s" % (frame, experts))

    def test_gaps_of_whole_cycles_and_a_pause(self):
        """lost="period" beyond one PRes: node 1 misses two cycles in a row (2 lost), node 3 is
        silent for 18 cycles (a gap of 19 periods, past 16: a pause, nothing lost, no jitter);
        every mark as the model says, and the lost expert only where the model has a loss."""
        missing = {(1, 20), (1, 21)} | {(3, c) for c in range(30, 48)}
        packets, _truth = eplgen.cycle(random.Random(89), cycles=60, period_ns=self.period, nodes=self.nodes,
                                       dropped=(0, 0), missing=missing)
        path = self.env.add_file("gaps.pcap", cyclemodel.pcap_ns(packets))
        timed = [(n, t, (f[14] & 0x7F, f[16]), None) for n, (t, f) in enumerate(packets, 1)
                 if f[14] & 0x7F in (eplgen.SOC, eplgen.PRES)]
        marks, _cycles = cyclemodel.model(timed, window=8, bits=0, lost_by_period=True)
        pres = {node: [n for n, (t, f) in enumerate(packets, 1) if f[14] & 0x7F == eplgen.PRES and f[16] == node]
                for node in (1, 3)}
        after_two = next(n for n in pres[1] if marks.get(n, {}).get("lost"))
        time_of = {n: t for n, (t, _f) in enumerate(packets, 1)}
        after_pause = next(n for before, n in zip(pres[3], pres[3][1:]) if time_of[n] - time_of[before] > 16 * self.period)
        with self.checks() as check:
            check(marks[after_two].get("lost") == 2, "the model: 2 lost after node 1's gap: %s" % marks[after_two])
            check("lost" not in marks[after_pause] and "jitter" not in marks[after_pause],
                  "the model: the pause loses nothing and has no jitter: %s" % marks[after_pause])
            want_experts = sorted(f for f, m in marks.items() if m.get("lost"))
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number"] + cyclemodel.mark_fields("eplr"), two_pass=two_pass)
                got = {f: m for f, m in ((f, cyclemodel.mark_of(row, "eplr")) for f, row in rows.items()) if m}
                for frame in sorted(set(got) | set(marks)):
                    check(got.get(frame) == marks.get(frame), "frame %d %s: %s, expected %s" % (
                        frame, "-2" if two_pass else "one pass", got.get(frame), marks.get(frame)))
                experts = sorted(f for f, row in rows.items() if row["eplr.expert.cycle_lost"])
                check(experts == want_experts, "lost experts on %s, expected %s" % (experts, want_experts))

    def test_cycles_report(self):
        _marks, cycles = cyclemodel.model(self.timed(), window=8, bits=0, lost_by_period=True)
        with self.checks() as check:
            for two_pass in (False, True):
                out = self.env.tshark(["-r", self.capture, "-q", "-z", "eplr,cycles"] + (["-2"] if two_pass else []))
                got = cyclemodel.parse_report(out.stdout)
                check(len(got) == len(cycles), "-z eplr,cycles lists %d cycles" % len(got))
                for c, g in zip(cycles, got):
                    mtyp, source = c["stream"]["key"]
                    # an enum signature field by its name, as the tree shows it
                    name = "MessageType %s (0x%02x), Source %d" % (MESSAGE_TYPES[mtyp], mtyp, source)
                    check(g["name"] == name, "cycle %d is %r, expected %r" % (c["number"], g["name"], name))
                    want = cyclemodel.figures(c)
                    del want["duplicates"]  # no sequence count: not printed
                    check(g["figures"] == want, "cycle %s: %s, expected %s" % (g["name"], g["figures"], want))


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

#!/usr/bin/env python3
"""The Info column of rules/ethercat.xml on real captures, against the bytes.

rules/ethercat.xml summarises each datagram with nested summaries and optional
parts ({X} naming a summarised container, {?...}); this script rebuilds the text
each datagram should get from the capture's bytes alone (ETG.1000 command names,
addresses, the AL control/status registers a datagram covers, the mailbox type and
the CoE service, SDO command specifier and object) and compares it with tshark's
Info column, in one pass and with -2. Frames with something the script does not
model (other mailbox contents, inconsistent mailbox lengths) are counted and
left out; each capture must still give AL status reads or SDO transfers.

    test_info_column.py --dissgen build/bin/dissgen --source-dir .

The general constructs are checked on tests/rules_ok/summary_parts.xml with
frames this script writes: each Info text is built from the values written.

The corpus part needs <source-dir>/../shared/corpus/ethercat; without it that
part is skipped and the script exits 77 when everything else passed.
"""
import os
import struct
import sys
import unittest

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from pcaprewrite import Capture, ecat_datagrams  # noqa: E402
from tshark_env import TsharkEnv, TsharkTestCase, run_unittests  # noqa: E402
from test_enip import ethernet, pcap  # noqa: E402
from pcapgen import raw_pcap_bytes, tcp_ethernet_frame  # noqa: E402

ARGS = None
ENV = None

COMMANDS = ["NOP", "APRD", "APWR", "APRW", "FPRD", "FPWR", "FPRW", "BRD", "BWR", "BRW",
            "LRD", "LWR", "LRW", "ARMW", "FRMW"]
STATES = {1: "INIT", 2: "PREOP", 3: "BOOTSTRAP", 4: "SAFEOP", 8: "OP"}             # ETG.1000.6 AL states
MAILBOX_TYPES = {0: "Error", 1: "AoE", 2: "EoE", 3: "CoE", 4: "FoE", 5: "SoE", 15: "VoE"}
COE_SERVICES = {1: "Emergency", 2: "SDO request", 3: "SDO response", 4: "TxPDO", 5: "RxPDO",
                6: "TxPDO remote request", 7: "RxPDO remote request", 8: "SDO information"}
# SDO command specifiers (CiA 301): client to server, server to client
REQUEST_CS = {0: "Download segment", 1: "Initiate download", 2: "Initiate upload", 3: "Upload segment",
              4: "Abort transfer"}
RESPONSE_CS = {0: "Upload segment", 1: "Download segment", 2: "Initiate upload", 3: "Initiate download",
               4: "Abort transfer"}
REQUEST_WITH_OBJECT = (1, 2, 4)
RESPONSE_WITH_OBJECT = (2, 3, 4)
SDO_INFO = {1: "Get OD list request", 2: "Get OD list response", 3: "Get object description request",
            4: "Get object description response", 5: "Get entry description request",
            6: "Get entry description response", 7: "SDO information error request"}


class NotModelled(Exception):
    pass


def enum(names, value, digits):
    return names.get(value, "Unknown (0x%0*x)" % (digits, value))


def register_state(data, ado, length, register):
    """The AL state in a 2-byte register when the datagram covers it wholly, else None."""
    if ado <= register and register + 2 <= ado + length:
        return enum(STATES, data[register - ado] & 0x0F, 1)
    return None


def coe_text(body):
    """CoE summary: service, then what the service's own summary says."""
    if len(body) < 2:
        raise NotModelled("CoE header truncated")
    service = struct.unpack("<H", body[:2])[0] >> 12
    text = enum(COE_SERVICES, service, 1)
    if service in (2, 3):
        if len(body) < 3:
            raise NotModelled("SDO without command")
        cs = body[2] >> 5
        names, with_object = (REQUEST_CS, REQUEST_WITH_OBJECT) if service == 2 else (RESPONSE_CS, RESPONSE_WITH_OBJECT)
        if cs not in names:
            raise NotModelled("reserved command specifier")
        text += " " + names[cs]
        if cs in with_object:
            if len(body) < 6:
                raise NotModelled("SDO object truncated")
            text += " 0x%04x:0x%02x" % (struct.unpack("<H", body[3:5])[0], body[5])
    elif service == 8:
        if len(body) < 6:                            # the 4-byte header is read as one bit group
            raise NotModelled("SDO information header truncated")
        text += " " + enum(SDO_INFO, body[2] & 0x7F, 2)
    elif service == 1 and len(body) >= 4:
        text += " error 0x%04x" % struct.unpack("<H", body[2:4])[0]
    return text


def datagram_text(raw, dg):
    cmd, ado, length = dg["cmd"], dg["ado"], dg["length"]
    if cmd >= len(COMMANDS):
        raise NotModelled("reserved command")
    if cmd in (10, 11, 12):
        address = "0x%08x" % (dg["adp"] | ado << 16)
    else:
        address = "0x%04x:0x%04x" % (dg["adp"], ado)
    text = "%s %s len %d" % (COMMANDS[cmd], address, length)
    data = raw[dg["data_offset"]:dg["data_offset"] + length]
    if cmd in (1, 4, 7) and length >= 1 and dg["wkc"] == 0:
        return text                                  # not read: nothing the slaves wrote
    if cmd in (1, 2, 3, 4, 5, 6, 7, 8, 9, 13, 14) and ado <= 0x0FFF and length >= 1:
        for label, register in (("AL control", 0x0120), ("AL status", 0x0130)):
            state = register_state(data, ado, length, register)
            if state:
                text += " %s %s" % (label, state)
        return text
    if 1 <= cmd <= 6 and ado >= 0x1000 and length >= 6:
        mbx_length = struct.unpack("<H", data[:2])[0]
        if mbx_length > length - 6:
            raise NotModelled("mailbox length past the datagram")
        mbx_type = data[5] & 0x0F
        text += " " + enum(MAILBOX_TYPES, mbx_type, 1)
        if mbx_type == 3:
            text += " " + coe_text(data[6:6 + mbx_length])
        elif mbx_type != 0:
            raise NotModelled("mailbox type %d" % mbx_type)
        else:
            raise NotModelled("mailbox error")
    return text


def expected_info(raw, datagrams):
    texts = [datagram_text(raw, dg) for dg in datagrams]
    if len(texts) == 1:
        return texts[0]
    return "Datagram \u00d7%d: %s" % (len(texts), ", ".join(texts))


def corpus_dir():
    return os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus", "ethercat")


class InfoColumn(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        global ENV
        ENV = TsharkEnv()
        ENV.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "rules", "ethercat.xml"))

    @classmethod
    def tearDownClass(cls):
        ENV.cleanup()

    def info_lines(self, capture, extra=()):
        out = ENV.tshark(["-r", capture, "-T", "fields", "-e", "frame.number", "-e", "_ws.col.Info"]
                         + list(extra)).stdout
        return dict(line.split("\t", 1) for line in out.splitlines())

    def check_capture(self, name):
        path = os.path.join(corpus_dir(), name)
        if not os.path.isfile(path):
            self.skipTest("no corpus capture %s" % path)
        capture = ENV.readable(path)
        one, two = self.info_lines(capture), self.info_lines(capture, ["-2"])
        counts = {"frames": 0, "checked": 0, "not modelled": 0, "AL control": 0, "AL status": 0, "SDO upload": 0,
                  "SDO information": 0}
        for number, pkt in enumerate(Capture.read(path).packets, 1):
            datagrams = ecat_datagrams(pkt)
            if not datagrams:
                continue
            counts["frames"] += 1
            try:
                wanted = expected_info(pkt.data, datagrams)
            except NotModelled:
                counts["not modelled"] += 1
                continue
            self.assertEqual(one[str(number)], wanted, "frame %d" % number)
            self.assertEqual(two[str(number)], wanted, "frame %d, with -2" % number)
            counts["checked"] += 1
            counts["AL control"] += wanted.count(" AL control ")
            counts["AL status"] += wanted.count(" AL status ")
            counts["SDO upload"] += wanted.count(" CoE SDO request Initiate upload 0x")
            counts["SDO information"] += wanted.count(" CoE SDO information ")
        print("%s: %s" % (name, counts), file=sys.stderr)
        self.assertGreater(counts["checked"], counts["frames"] * 0.9, counts)
        return counts

    def test_al_states(self):
        counts = self.check_capture("soem-sdinfo-ek1100-el1004.pcapng")
        self.assertGreater(counts["AL status"], 0, counts)
        self.assertGreater(counts["AL control"], 0, counts)

    def test_sdo_uploads(self):
        counts = self.check_capture("replay-sdo-error.pcapng")
        self.assertGreater(counts["SDO upload"], 0, counts)

    def test_every_capture(self):
        names = sorted(f for f in os.listdir(corpus_dir()) if f.endswith((".pcap", ".pcapng"))) \
            if os.path.isdir(corpus_dir()) else []
        if not names:
            self.skipTest("no EtherCAT corpus at %s" % corpus_dir())
        total = {}
        for name in names:
            for key, value in self.check_capture(name).items():
                total[key] = total.get(key, 0) + value
        print("all captures: %s" % total, file=sys.stderr)
        self.assertGreater(total["AL status"], 0, total)
        self.assertGreater(total["SDO upload"], 0, total)


class SummaryParts(unittest.TestCase):
    """tests/rules_ok/summary_parts.xml: `{Operation} {Target}{? value {Value}}{? status
    {Status}{? (code {Code})}} {?more}`, Target summarised as `{Block}.{Register}`; the
    compiled summaries and the table walk's (DISSGEN_TABLE_WALK=1) give the same texts."""

    @classmethod
    def setUpClass(cls):
        cls.env = TsharkEnv()
        cls.env.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "tests", "rules_ok", "summary_parts.xml"))

    @classmethod
    def tearDownClass(cls):
        cls.env.cleanup()

    def test_parts_follow_what_each_message_holds(self):
        # (bytes of the message, Info text from the same values)
        messages = []
        for more, block, register, value in ((0, 0x0010, 2, 0x1234), (9, 0xBEEF, 255, 0)):
            messages.append((struct.pack("!BBHBH", more, 2, block, register, value),
                             "write 0x%04x.%d value 0x%04x %d" % (block, register, value, more)))
        for more, block, register, code in ((1, 0x0010, 2, 7), (3, 0x0A00, 0, 200)):
            messages.append((struct.pack("!BBHBBB", more, 1, block, register, 1, code),
                             "read 0x%04x.%d status busy (code %d) %d" % (block, register, code, more)))
        messages.append((struct.pack("!BBHBB", 5, 1, 0x0020, 4, 0), "read 0x0020.4 status ok 5"))
        # ethernet() pads to 60 bytes with zeros: frames end after the message so
        # that a missing reply is really missing.
        frames = [ethernet(m, ethertype=0x88B6) for m, _ in messages]
        frames.append(ethernet(b"", ethertype=0x88B6)[:14] + struct.pack("!BBHB", 6, 1, 0x0030, 1))
        expected = [text for _, text in messages] + ["read 0x0030.1 6"]
        cap = self.env.add_file("parts.pcap", pcap(frames))
        # the compiled summaries and the runtime's own builder (DISSGEN_TABLE_WALK=1)
        for walk in ({}, {"DISSGEN_TABLE_WALK": "1"}):
            for extra in ([], ["-2"]):
                out = self.env.tshark(["-r", cap, "-T", "fields", "-e", "_ws.col.Info"] + extra,
                                      extra_env=walk).stdout
                self.assertEqual(out.splitlines(), expected, "%s %s" % (walk, extra))
        # the tree: each summarised container's item carries its own text
        tree = self.env.tshark(["-r", cap, "-V", "-O", "sump"]).stdout
        self.assertIn("Target: 0x0010.2", tree)
        self.assertIn("Message: write 0x0010.2 value 0x1234 0", tree)


class ContainerLabels(unittest.TestCase):
    """tests/rules_ok/container_labels.xml: each container's label, "Name" or
    "Name: summary", on unnamed (filter="") and named containers, cut where
    Wireshark cuts a label (239 bytes and the NUL); booleans whole and in a bit
    group. Everything against the bytes written, in tshark's PDML."""

    LABEL = 239  # ITEM_LABEL_LENGTH less the NUL

    @classmethod
    def setUpClass(cls):
        cls.env = TsharkEnv()
        cls.env.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "tests", "rules_ok", "container_labels.xml"))

    @classmethod
    def tearDownClass(cls):
        cls.env.cleanup()

    def expected(self, flag, bits, text, words):
        cut = lambda label: label[:self.LABEL]  # noqa: E731
        return [("", "Pair: %d/%d" % (len(text), len(words))), ("", "Plain"),
                ("clab.flag", "1" if flag else "0"), ("clab.bits.low", str(bits >> 7)),
                ("clab.bits.high", str(bits & 0x7F)),
                ("clab.named", cut("Named: " + text)), ("", cut("Unnamed: " + words))]

    def test_labels_whole_and_cut_where_wireshark_cuts(self):
        import xml.etree.ElementTree as ET
        cases = [(1, 0x83, "hello", "abc"),
                 (0, 0x02, "y" * 232, "z" * 230),  # 239 bytes: whole
                 (2, 0x01, "x" * 233, "w" * 231),  # 240: cut
                 (0, 0xFE, "".join(chr(0x41 + i % 26) for i in range(250)), "v" * 236)]
        frames = [ethernet(struct.pack("!BBBB", len(t), len(w), f, b) + t.encode() + w.encode(), ethertype=0x88B7)
                  for f, b, t, w in cases]
        cap = self.env.add_file("labels.pcap", pcap(frames))
        for extra in ([], ["-2"]):
            root = ET.fromstring(self.env.tshark(["-r", cap, "-T", "pdml"] + extra).stdout)
            packets = root.findall("packet")
            self.assertEqual(len(packets), len(cases))
            for packet, case in zip(packets, cases):
                proto = packet.find("proto[@name='clab']")
                seen = []
                for field in proto.iter("field"):
                    name = field.get("name")
                    if name in ("", "clab.named"):
                        seen.append((name, field.get("show") if name == "" else field.get("showname")))
                    elif name in ("clab.flag", "clab.bits.low", "clab.bits.high"):
                        seen.append((name, field.get("show")))
                self.assertEqual(seen, self.expected(*case))



EMPTY_SUMMARY_RULES = """<root name="Empty summary" abbreviation="EMPS" ethertype="0x88b8">
  <node name="Head" summary="kind {Kind}">
    <node name="Kind" length="1byte" displaytype="numberdec"/>
  </node>
  <node name="Body" summary="{?extra {Extra}}">
    <node name="Extra" length="1byte" displaytype="numberdec" if="../../node[@name='Head']/node[@name='Kind']" in="1"/>
  </node>
</root>
"""


class EmptySummaries(TsharkTestCase, unittest.TestCase):
    """A summary all of whose parts are absent says nothing: no ", " in the Info column and
    a bare "Body" item, not "Body: " (compiled summaries and the table walk alike)."""

    @classmethod
    def prepare(cls):
        cls.install_text("empty_summary.xml", EMPTY_SUMMARY_RULES, "emps")

    def test_nothing_where_nothing_is_summarised(self):
        cap = self.env.add_file("empty.pcap", pcap([ethernet(bytes([1, 7]), ethertype=0x88B8),
                                                    ethernet(bytes([2, 7]), ethertype=0x88B8)]))
        for walk in ({}, {"DISSGEN_TABLE_WALK": "1"}):
            for extra in ([], ["-2"]):
                info = self.env.tshark(["-r", cap, "-T", "fields", "-e", "_ws.col.Info"] + extra,
                                       extra_env=walk).stdout.splitlines()
                self.assertEqual(info, ["kind 1, extra 7", "kind 2"], "%s %s" % (walk, extra))
                tree = self.env.tshark(["-r", cap, "-V", "-O", "emps"] + extra, extra_env=walk).stdout
                bodies = [line.strip() for line in tree.splitlines() if line.strip().startswith("Body")]
                self.assertEqual(bodies, ["Body: extra 7", "Body"], "%s %s" % (walk, extra))


ACROSS_REPEATS_RULES = """<root name="Summary across repeats" abbreviation="SUMX" ethertype="0x88b9">
  <node name="Message" summary="last a={A}">
    <node name="Count" length="1byte" displaytype="numberdec"/>
    <node name="Record" count="../node[@name='Count']" summary="a={A} b={B}{? c={C}}">
      <node name="Length" length="1byte" displaytype="numberdec"/>
      <node name="Members" length="../node[@name='Length']">
        <node name="Member" repeat="rest" summary="{Tag} a={A}">
          <node name="Tag" length="1byte" displaytype="numberdec"/>
          <node name="A" length="1byte" displaytype="numberdec" if="../node[@name='Tag']" in="1"/>
          <node name="C" length="1byte" displaytype="numberdec" if="../node[@name='Tag']" in="3" otherwise="true"/>
          <node name="B" length="1byte" displaytype="numberdec" otherwise="true"/>
        </node>
      </node>
    </node>
  </node>
</root>
"""

ACROSS_STRIDE_RULES = """<root name="Summary across a stride" abbreviation="SUMS" ethertype="0x88ba">
  <node name="Address" length="1byte" displaytype="numberhex"/>
  <node name="Memory" length="rest" base="../node[@name='Address']" summary="value {Value}">
    <node name="Slot {i}" filter="slot" at="0x0000" stride="2" instances="3" length="2byte">
      <node name="Flag" length="1byte" displaytype="numberdec"/>
      <node name="Value" length="1byte" displaytype="numberhex" if="../node[@name='Flag']" in="1"/>
      <node name="Pad" length="1byte" displaytype="numberhex" otherwise="true"/>
    </node>
  </node>
</root>
"""

ACROSS_CONTAINER_RULES = """<root name="Container across repeats" abbreviation="SUMC" ethertype="0x88bb">
  <node name="Length" length="1byte" displaytype="numberdec"/>
  <node name="Msg" length="../node[@name='Length']" summary="{Obj}{? / {Prop}}">
    <node name="Item" repeat="rest">
      <node name="Kind" length="1byte" displaytype="numberdec"/>
      <node name="Obj" length="2byte" if="../node[@name='Kind']" in="0" summary="{Hi}.{Lo}">
        <node name="Hi" length="1byte" displaytype="numberdec"/>
        <node name="Lo" length="1byte" displaytype="numberdec"/>
      </node>
      <node name="Prop" length="1byte" displaytype="numberdec" otherwise="true"/>
    </node>
  </node>
</root>
"""


class SummaryAcrossRepeats(TsharkTestCase, unittest.TestCase):
    """A summary names leaves inside a list of tagged members (one member each, as TLVs):
    it shows the last value its own instance decoded, though the last member held another
    field; a later instance of the summarised container does not show an earlier one's, a
    member's own summary shows only that member's, and a summary around them all the last
    of the message; a window's children at a stride alike (compiled summaries and the table
    walk, one pass and -2)."""

    @classmethod
    def prepare(cls):
        cls.install_text("across_repeats.xml", ACROSS_REPEATS_RULES, "sumx")
        cls.install_text("across_stride.xml", ACROSS_STRIDE_RULES, "sums")
        cls.install_text("across_container.xml", ACROSS_CONTAINER_RULES, "sumc")

    def test_last_text_of_a_summarised_container(self):
        """A summary names a container with a summary of its own inside the members: the
        text of the last one decoded, whichever member came after it."""
        bodies = [bytes([0, 1, 2, 1, 0x55]), bytes([1, 0x55, 0, 1, 2]), bytes([1, 0x55]), bytes([0, 1, 2, 0, 3, 4])]
        cap = self.env.add_file("across_container.pcap",
                                pcap([ethernet(bytes([len(b)]) + b, ethertype=0x88BB) for b in bodies]))
        for walk in ({}, {"DISSGEN_TABLE_WALK": "1"}):
            for extra in ([], ["-2"]):
                info = self.env.tshark(["-r", cap, "-T", "fields", "-e", "_ws.col.Info"] + extra,
                                       extra_env=walk).stdout.splitlines()
                self.assertEqual(info, ["1.2 / 85", "1.2 / 85", "- / 85", "3.4"], "%s %s" % (walk, extra))

    def test_last_value_of_the_instance(self):
        first = bytes([1, 7, 3, 8, 2, 9, 2, 4])  # A=7, C=8, B=9, B=4
        second = bytes([2, 5])                   # B=5 only
        frames = [ethernet(bytes([2, len(first)]) + first + bytes([len(second)]) + second, ethertype=0x88B9),
                  ethernet(bytes([1, 2, 1, 6]), ethertype=0x88B9),
                  ethernet(bytes([0, 1, 0x55, 0, 0, 0, 0]), ethertype=0x88BA)]
        cap = self.env.add_file("across.pcap", pcap(frames))
        for walk in ({}, {"DISSGEN_TABLE_WALK": "1"}):
            for extra in ([], ["-2"]):
                info = self.env.tshark(["-r", cap, "-T", "fields", "-e", "_ws.col.Info"] + extra,
                                       extra_env=walk).stdout.splitlines()
                self.assertEqual(info, ["last a=7", "last a=6", "value 0x55"], "%s %s" % (walk, extra))
                tree = self.env.tshark(["-r", cap, "-V", "-O", "sumx"] + extra, extra_env=walk).stdout
                labels = [line.strip() for line in tree.splitlines()
                          if line.strip().startswith(("Member:", "Record:", "Message:"))]
                self.assertEqual(labels, ["Message: last a=7", "Record: a=7 b=4 c=8", "Member: 1 a=7", "Member: 3 a=-",
                                          "Member: 2 a=-", "Member: 2 a=-", "Record: a=- b=5", "Member: 2 a=-",
                                          "Message: last a=6", "Record: a=6 b=-", "Member: 1 a=6"],
                                 "%s %s" % (walk, extra))


# A protocol that Wireshark's COTP hands each data unit of a TPKT message to (its heuristic
# list): COTP writes its own Info text once per TPKT message, between ours.
CARRIED_RULES = """<root name="Carried by COTP" abbreviation="CBC" filter="cbc">
  <heuristic table="cotp"/>
  <node name="Protocol Id" length="1byte" displaytype="numberhex" valid="0x32"/>
  <node name="Body" summary="kind {Kind}">
    <node name="Kind" length="1byte" displaytype="numberdec"/>
  </node>
</root>
"""


def tpkt_data_unit(payload):
    """A TPKT message (RFC 1006) holding a COTP data unit (last of its message) with payload."""
    cotp = b"\x02\xf0\x80" + payload
    return struct.pack("!BBH", 3, 0, 4 + len(cotp)) + cotp


class InfoOfMessagesCarriedApart(TsharkTestCase, unittest.TestCase):
    """Each message of ours in a TCP segment comes in its own call from COTP, which writes
    its text over the column before each: the Info column still joins ours, in order."""

    @classmethod
    def prepare(cls):
        cls.install_text("carried.xml", CARRIED_RULES, "cbc")

    def test_each_message_joined_in_order(self):
        segments = [[1], [1, 3], [4, 5, 6]]
        frames, seq = [], 1
        for kinds in segments:
            payload = b"".join(tpkt_data_unit(bytes([0x32, k])) for k in kinds)
            frames.append(tcp_ethernet_frame(payload, 40000, 102, seq))
            seq += len(payload)
        path = self.env.add_file("carried.pcap", raw_pcap_bytes(frames))
        want = {n: [" | ".join("kind %d" % k for k in kinds)] for n, kinds in enumerate(segments, 1)}
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number", "_ws.col.Info"], two_pass)
                got = {n: r["_ws.col.Info"] for n, r in rows.items()}
                check(got == want, "%s: Info joins every message's text: %s" % (
                    "-2" if two_pass else "one pass", got))


if __name__ == "__main__":
    ARGS, status = run_unittests()
    if status == 0 and not os.path.isdir(corpus_dir()):
        print("SKIPPED: no EtherCAT corpus at %s" % corpus_dir())
        status = 77
    sys.exit(status)

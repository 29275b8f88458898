#!/usr/bin/env python3
"""What the segment did, for every EtherCAT command: rules/ethercat.xml's ethercat-esc analysis
on generated frame pairs (a frame from the master's MAC, its return from the same MAC with the
locally administered bit set), with real tshark, one pass and -2.

For each of the 15 commands (NOP, the reads APRD FPRD BRD LRD, the writes APWR FPWR BWR LWR,
the read/writes APRW FPRW BRW LRW, ARMW, FRMW), one pair per case below, each pair with
indexes of its own. What each returned frame must show is worked out here from the ESC rules
of the manual (an independent statement of them, not the plugin's code): the command, index,
length and address (ADO; the ADP of configured-address commands and NOP; the logical address)
never change; auto-increment and broadcast commands advance their ADP by the slaves passed;
writes keep their data; the working counter only grows.

  clean           what a working segment returns: WKC +1, ADP +2 where it advances, new data
                  where the command reads
  data altered    the data came back with one byte other: ecatr.expert.write_changed on the
                  writes only, ecatr.esc.data_changed on all
  wkc down        sent with 5, back with 3: ecatr.expert.wkc_down, ecatr.esc.wkc_added -2
  wkc unchanged   0 and 0: neither
  ado changed     (logical: the logical address) ecatr.expert.changed on every command
  adp moved       by 3: slaves passed for the advancing commands, ecatr.expert.changed on the
                  others
  forwarding      (advancing commands) three datagrams, the last advanced by one more:
                  ecatr.expert.forwarding on it alone

Every returned frame carries ecatr.request_in of its request and ecatr.esc.* per datagram
(ecatr.esc.wkc_added, ecatr.esc.slaves_passed on advancing commands only,
ecatr.esc.data_changed), and exactly the expert infos above (counted per datagram); every sent
frame ecatr.response_in (-2) and no expert info.

Computed values, checked against the bytes written: the mailbox total length (the header's Length
+ 6) of mailboxes in datagrams, one or two in a frame, and of the mailbox gateway.

    test_esc_commands.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import pcapgen as pg  # noqa: E402
from tshark_env import TsharkTestCase, relative_time_ns, run_unittests  # noqa: E402

NAMES = pg.CMD_NAMES
WRITES = {2, 5, 8, 11}                  # APWR FPWR BWR LWR
DATA_READ = {1, 3, 4, 6, 7, 9, 10, 12, 13, 14}  # every command whose data a slave fills in
ADVANCING = {1, 2, 3, 7, 8, 9, 13}      # auto-increment and broadcast
LOGICAL = {10, 11, 12}
EXPERTS = ["changed", "frame_length", "write_changed", "wkc_down", "forwarding", "duplicate", "out_of_order",
           "no_response"]
ESC = ["ecatr.esc.wkc_added", "ecatr.esc.slaves_passed", "ecatr.esc.data_changed"]
FIELDS = ["frame.number", "ecatr.request_in", "ecatr.response_in"] + ESC + ["ecatr.expert." + e for e in EXPERTS]
MASTER = b"\x00\x1b\x21\x3c\x55\x10"
RETURNED = bytes([MASTER[0] | 0x02]) + MASTER[1:]
ARGS = None


def datagram(cmd, idx, adp=0xfffe, ado=0x1000, lad=0x00012340, data=b"\x11\x22\x33\x44", wkc=0):
    return pg.Datagram(cmd=cmd, idx=idx, adp=adp, ado=ado, lad=lad if cmd in LOGICAL else 0, data=data, wkc=wkc)


def returned(d, wkc=None, advance=2, data=None, ado=None, adp=None):
    """What a segment returns for datagram d; the keywords change what the rules fix."""
    back = pg.Datagram(**vars(d))
    back.wkc = d.wkc + 1 if wkc is None else wkc
    if d.cmd in ADVANCING:
        back.adp = (d.adp + advance) & 0xFFFF
    if data is not None:
        back.data = data
    elif d.cmd in DATA_READ:
        back.data = bytes(b ^ 0xA5 for b in d.data)
    if ado is not None:
        if d.cmd in LOGICAL:
            back.lad = d.lad ^ (ado << 16)
        else:
            back.ado = ado
    if adp is not None:
        if d.cmd in LOGICAL:
            back.lad = (d.lad & 0xFFFF0000) | adp
        else:
            back.adp = adp
    return back


class Case:
    """One frame pair and what its return must show, datagram by datagram."""
    def __init__(self, what, cmd, sent, back, expect):
        self.what, self.cmd, self.sent, self.back = what, cmd, sent, back
        self.expect = expect    # {field: [value per occurrence]}


def expected(sent, back, experts):
    """The ecatr.esc.* values from the two frames' datagrams (what the rules say), and the
    expert infos the case raises: {name: count}."""
    e = {"ecatr.esc.wkc_added": [str(b.wkc - s.wkc) for s, b in zip(sent, back)],
         "ecatr.esc.slaves_passed": [str((b.adp - s.adp) & 0xFFFF) for s, b in zip(sent, back)
                                     if s.cmd in ADVANCING],
         "ecatr.esc.data_changed": ["1" if s.data != b.data else "0" for s, b in zip(sent, back)]}
    for name in EXPERTS:
        e["ecatr.expert." + name] = ["1"] * experts.get(name, 0)
    return e


def cases():
    out = []
    idx = [0]

    def add(what, cmd, sent, back, experts):
        out.append(Case(what, cmd, sent, back, expected(sent, back, experts)))

    def nxt():
        idx[0] += 1
        return idx[0]

    for cmd in sorted(NAMES):
        d = datagram(cmd, nxt())
        add("clean", cmd, [d], [returned(d)], {})
        d = datagram(cmd, nxt())
        add("data altered", cmd, [d], [returned(d, data=bytes([d.data[0] ^ 0x5A]) + d.data[1:])],
            {"write_changed": 1} if cmd in WRITES else {})
        d = datagram(cmd, nxt(), wkc=5)
        add("wkc down", cmd, [d], [returned(d, wkc=3)], {"wkc_down": 1})
        d = datagram(cmd, nxt(), wkc=0)
        add("wkc unchanged", cmd, [d], [returned(d, wkc=0)], {})
        d = datagram(cmd, nxt())
        add("ado changed", cmd, [d], [returned(d, ado=0x1100)], {"changed": 1})
        d = datagram(cmd, nxt(), adp=0x1001)
        add("adp moved", cmd, [d], [returned(d, adp=0x1004)], {} if cmd in ADVANCING else {"changed": 1})
        if cmd in ADVANCING:
            ds = [datagram(cmd, nxt(), adp=(-k) & 0xFFFF, ado=0x0130) for k in range(3)]
            add("forwarding", cmd, ds, [returned(ds[0]), returned(ds[1]), returned(ds[2], advance=3)],
                {"forwarding": 1})
    return out


def frames_of(cs):
    frames, t = [], 1704067200.0
    for c in cs:
        frames.append(pg.Frame(c.sent, src_mac=MASTER, ts=t))
        frames.append(pg.Frame(c.back, src_mac=RETURNED, ts=t + 0.000150))
        t += 0.001
    return frames


def decode(env, path, two_pass):
    """{frame number: {field: [values]}}."""
    return env.field_rows(path, FIELDS, two_pass)


# --------------------------------------------------------------- computed values

COMPUTED = ["ecatr.datagram.mbx.totallength", "ecatr.datagram.mbx.length", "ecatr.gateway.totallength",
            "ecatr.datagram.recvdelay1"]


def mailbox(length, mtype=0x6, data_len=None):
    """A mailbox: the 6-byte header (Length, address, channel/priority, type/counter), then
    data_len bytes (default: Length)."""
    n = length if data_len is None else data_len
    return struct.pack("<HHBB", length, 0x1234, 0, mtype | 0x10) + bytes((i * 7) & 0xFF for i in range(n))


def computed_frames():
    """[(frame, {field: [values]})]: each frame with what the computed fields must show,
    worked out here from the bytes written."""
    out = []
    # Mailboxes written to 0x1000: the header's Length + 6, whatever the datagram's Length.
    for length, size in ((10, 16), (0, 6), (10, 128), (200, 206), (0x0400, 0x0406)):
        d = pg.Datagram(cmd=5, idx=7, adp=0x1001, ado=0x1000, data=mailbox(length, data_len=size - 6), wkc=1)
        out.append((pg.Frame([d]), {"ecatr.datagram.mbx.length": [str(length)],
                                    "ecatr.datagram.mbx.totallength": [str(length + 6)]}))
    # Two mailboxes in one frame, each with its own header.
    ds = [pg.Datagram(cmd=5, idx=8 + k, adp=0x1001 + k, ado=0x1000, data=mailbox(n, data_len=n), wkc=1)
          for k, n in enumerate((4, 30))]
    out.append((pg.Frame(ds), {"ecatr.datagram.mbx.length": ["4", "30"],
                               "ecatr.datagram.mbx.totallength": ["10", "36"]}))
    # The mailbox gateway (frame type 5): one mailbox right after the frame header.
    for length in (0, 12, 300):
        out.append((pg.Frame([], header_type=5, padding=mailbox(length)),
                    {"ecatr.gateway.totallength": [str(length + 6)]}))
    # DC receive times read back (0x0900 on): port 1's minus port 0's, modulo 2^32 (the local
    # clock wraps); a read that does not cover port 1's time, a write and an unanswered read
    # (working counter 0: not the slave's bytes) have none.
    for cmd, ado, times, wkc, want in (
            (4, 0x0900, (1000, 1600), 1, ["600"]), (7, 0x0900, (0xFFFFFF00, 0x100, 5, 6), 3, ["512"]),
            (1, 0x0900, (0x10, 0x10), 1, ["0"]), (4, 0x08FC, (7, 1000, 1310), 1, ["310"]),
            (4, 0x0900, (1000,), 1, []), (5, 0x0900, (1000, 1600), 1, []), (4, 0x0900, (1000, 1600), 0, [])):
        d = pg.Datagram(cmd=cmd, idx=9, adp=0x1001, ado=ado, data=struct.pack("<%dI" % len(times), *times), wkc=wkc)
        out.append((pg.Frame([d]), {"ecatr.datagram.recvdelay1": want}))
    # Two reads in one frame, each with its own difference.
    ds = [pg.Datagram(cmd=4, idx=10 + k, adp=0x1001 + k, ado=0x0900, data=struct.pack("<II", 50, 50 + d), wkc=1)
          for k, d in enumerate((200, 90))]
    out.append((pg.Frame(ds), {"ecatr.datagram.recvdelay1": ["200", "90"]}))
    return out


# ------------------------------------------------- mailboxes in datagrams and the gateway

def coe_sdo_download(index, subindex, value):
    """A CoE mailbox: an expedited initiate download request of 4 bytes."""
    coe = struct.pack("<HBHBI", 0x2000, 0x23, index, subindex, value)  # service 2: SDO request
    return struct.pack("<HHBB", len(coe), 0x1001, 0, 0x03 | 0x10) + coe


def eoe_fragments(inner, frame_number, size=32):
    """EoE mailboxes carrying the Ethernet frame `inner` in fragments of `size` bytes."""
    out = []
    for k in range(0, len(inner), size):
        piece, last = inner[k:k + size], k + size >= len(inner)
        offset = (len(inner) + 31) // 32 if k == 0 else k // 32
        eoe = struct.pack("<HH", 0x0 | (int(last) << 8), (k // size) | (offset << 6) | (frame_number << 12)) + piece
        out.append(struct.pack("<HHBB", len(eoe), 0x1001, 0, 0x02 | 0x10) + eoe)
    return out


class TestEscCommands(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        cls.install(os.path.join("rules", "ethercat.xml"), "ecatr")

    def test_unprocessed_return_of_an_unmarked_source_is_paired(self):
        """A simulator that does not mark returned frames: an auto-increment read of a position
        no slave has comes back from the master's own MAC with its working counter 0 and only its
        address advanced (by the slaves passed); each is its request come back, paired with it
        (one pass and -2), whatever follows the address in the frame."""
        frames, t = [], 1704067200.0
        for k, passed in enumerate((3, 1, 7)):
            d = datagram(1, 10 + k, adp=(-20) & 0xFFFF, ado=0x0130, data=bytes(2 + 2 * k), wkc=0)
            frames += [pg.Frame([d], src_mac=MASTER, ts=t),
                       pg.Frame([returned(d, wkc=0, advance=passed, data=d.data)], src_mac=MASTER, ts=t + 0.000150)]
            t += 0.001
        path = self.env.add_file("unprocessed.pcap", pg.pcap_bytes(frames))
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number", "ecatr.request_in"], two_pass)
                got = {n: int(r["ecatr.request_in"][0]) for n, r in rows.items() if r["ecatr.request_in"]}
                check(got == {2: 1, 4: 3, 6: 5}, "%s: each return answers its request: %s" % (
                    "-2" if two_pass else "one pass", got))

    def test_segment_items_lie_over_their_bytes(self):
        """On a returned APRD (Ethernet header 14 bytes, EtherCAT header 2, the datagram's
        header 10, 4 bytes of data, the working counter 2): ecatr.esc.slaves_passed over the
        ADP's 2 bytes, ecatr.esc.wkc_added over the working counter, ecatr.esc.data_changed
        over the data, in tshark's PDML."""
        import xml.etree.ElementTree as ET
        d = datagram(1, 40, adp=0, ado=0x0130)
        frames = [pg.Frame([d], src_mac=MASTER), pg.Frame([returned(d, advance=3)], src_mac=RETURNED)]
        path = self.env.add_file("items.pcap", pg.pcap_bytes(frames))
        packet = ET.fromstring(self.env.tshark(["-r", path, "-T", "pdml"]).stdout).findall("packet")[1]
        got = {f.get("name"): (int(f.get("pos")), int(f.get("size"))) for f in packet.iter("field")
               if f.get("name") in ("ecatr.esc.slaves_passed", "ecatr.esc.wkc_added", "ecatr.esc.data_changed")}
        self.assertEqual(got, {"ecatr.esc.slaves_passed": (18, 2), "ecatr.esc.wkc_added": (30, 2),
                               "ecatr.esc.data_changed": (26, 4)})

    def test_changed_says_what_came_back_changed(self):
        """ecatr.expert.changed names exactly what came back other than sent: the command, the
        index (a return whose index changed, while its frame alone waits), the address, each
        alone, in one pass and with -2."""
        fprd = lambda idx: datagram(4, idx, adp=0x1001, ado=0x0130)  # noqa: E731
        pairs = [(fprd(1), returned(fprd(1)), None)]   # a clean pair first: the capture has shown one
        d = fprd(2)
        back = returned(d)
        back.cmd = 1
        pairs.append((d, back, "Datagram 1 (FPRD), command FPRD came back as APRD"))
        d = fprd(3)
        back = returned(d)
        back.idx = 0x33
        pairs.append((d, back, "Datagram 1 (FPRD), index 0x03 came back as 0x33"))
        d = fprd(4)
        pairs.append((d, returned(d, ado=0x0140), "Datagram 1 (FPRD), address 0x01301001 came back as 0x01401001"))
        frames, t = [], 1704067200.0
        for sent, back, _ in pairs:
            frames += [pg.Frame([sent], src_mac=MASTER, ts=t), pg.Frame([back], src_mac=RETURNED, ts=t + 0.000150)]
            t += 0.001
        path = self.env.add_file("changed.pcap", pg.pcap_bytes(frames))
        want = {2 * k + 2: [text] for k, (_, _, text) in enumerate(pairs) if text}
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number", "ecatr.expert.changed", "_ws.expert.message"],
                                           two_pass, aggregator="|")
                got = {n: [m for m in r["_ws.expert.message"] if m.startswith("Datagram 1 (")]
                       for n, r in rows.items() if r["ecatr.expert.changed"]}
                check(got == want, "%s: %s" % ("-2" if two_pass else "one pass", got))

    def test_every_command_returned_as_the_rules_say(self):
        env = self.env
        with self.checks() as check:
            cs = cases()
            covered = {(c.what, c.cmd) for c in cs}
            check(all(("clean", cmd) in covered for cmd in NAMES), "every command has its cases (%d pairs)" % len(cs))
            path = env.add_file("esc-commands.pcap", pg.pcap_bytes(frames_of(cs)))
            for two_pass in (False, True):
                tag = " (-2)" if two_pass else ""
                rows = decode(env, path, two_pass)
                bad_requests, bad_returns = [], []
                for k, c in enumerate(cs):
                    sent_no, back_no = 2 * k + 1, 2 * k + 2
                    r = rows[sent_no]
                    want_sent = {f: [] for f in FIELDS[1:]}
                    if two_pass:
                        want_sent["ecatr.response_in"] = [str(back_no)]
                    if r != want_sent:
                        bad_requests.append((sent_no, c.what, NAMES[c.cmd], {f: v for f, v in r.items() if v}))
                    want = dict(c.expect, **{"ecatr.request_in": [str(sent_no)], "ecatr.response_in": []})
                    got = rows[back_no]
                    diff = {f: (got[f], want[f]) for f in want if got[f] != want[f]}
                    if diff:
                        bad_returns.append("%s %s (frame %d): %s" % (NAMES[c.cmd], c.what, back_no, diff))
                check(not bad_requests, "sent frames%s: paired, no expert info%s" % (
                    tag, ": %s" % bad_requests[:4] if bad_requests else ""))
                for cmd in sorted(NAMES):
                    mine = [b for b in bad_returns if b.startswith(NAMES[cmd] + " ")]
                    check(not mine, "%s%s: returned frames show what the rules say (%s)%s" % (
                        NAMES[cmd], tag, ", ".join(c.what for c in cs if c.cmd == cmd),
                        "".join("\n       " + b for b in mine[:4])))

    def test_comparison_printed_only_where_unusual(self):
        """-V prints a return's comparison (ecatr.esc) only when one of its datagrams raises an
        expert info, every one with the preference "Show slave and ESC details on every
        datagram"; the fields are filterable on every return either way."""
        env = self.env
        with self.checks() as check:
            cs = cases()
            path = env.add_file("esc-printed.pcap", pg.pcap_bytes(frames_of(cs)))
            unusual = {2 * k + 2 for k, c in enumerate(cs)
                       if any(v for f, v in c.expect.items() if f.startswith("ecatr.expert."))}
            for prefs, tag in (([], "default"), (["-o", "ecatr.show_details:TRUE"], "show_details")):
                text = env.tshark(["-r", path, "-V"] + prefs).stdout
                frames = {int(m.group(1)): m.group(0) for m in re.finditer(r"(?ms)^Frame (\d+):.*?(?=^Frame |\Z)", text)}
                printed = {n for n, t in frames.items() if "Out and back (ESC forwarding)" in t}
                returns = {2 * k + 2 for k in range(len(cs))}
                want = returns if prefs else unusual
                check(printed == want, "%s: the comparison is printed on %d returns (%s), want %d: %s" % (
                    tag, len(printed), "every one" if prefs else "the unusual ones", len(want),
                    sorted(printed ^ want)[:8]))
            # Filterable all the same: a filter finds the comparison on every return.
            rows = env.field_rows(path, ["frame.number"], display_filter="ecatr.esc.wkc_added")
            check(set(rows) == {2 * k + 2 for k in range(len(cs))},
                  "-Y ecatr.esc.wkc_added keeps every return (%d of %d)" % (len(rows), len(cs)))

    def test_gateway_mailboxes_decode_as_datagram_mailboxes(self):
        """One description of a mailbox (the rules' group "Mailbox") serves datagrams and the
        mailbox gateway: the same CoE request shows the same object and Info text either way,
        and an EoE frame in two fragments is reassembled and handed to eth either way."""
        env = self.env
        inner = bytes.fromhex("0102030405060a0b0c0d0e0f88b5") + bytes(range(46))
        via_datagram = [pg.Datagram(cmd=5, idx=1, adp=0x1001, ado=0x1000, data=m, wkc=1)
                        for m in [coe_sdo_download(0x1C12, 1, 0x1600)] + eoe_fragments(inner, 3)]
        frames = [pg.Frame([d]) for d in via_datagram]
        frames += [pg.Frame([], header_type=5, padding=m)
                   for m in [coe_sdo_download(0x1C12, 1, 0x1600)] + eoe_fragments(inner, 4)]
        t = 1704067200.0
        for f in frames:
            f.src_mac, f.ts = MASTER, t
            t += 0.001
        path = env.add_file("gateway-mailboxes.pcap", pg.pcap_bytes(frames))
        with self.checks() as check:
            for args in ([], ["-2"]):
                mode = " ".join(args) or "one pass"
                rows = env.field_rows(path, ["frame.number", "ecatr.datagram.mbx.coe.sdoreq.index",
                                             "ecatr.gateway.coe.sdoreq.index", "ecatr.reassembled_in", "eth.type",
                                             "_ws.col.Info"], two_pass=bool(args))
                check(rows[1]["ecatr.datagram.mbx.coe.sdoreq.index"] == ["0x1c12"] and
                      rows[4]["ecatr.gateway.coe.sdoreq.index"] == ["0x1c12"],
                      "%s: the CoE request's object in a datagram and through the gateway" % mode)
                info = [rows[n]["_ws.col.Info"][0] for n in (1, 4)]
                check("Initiate download" in info[0] and info[0].split("Initiate download", 1)[1] ==
                      info[1].split("Initiate download", 1)[1],
                      "%s: the same CoE summary in the Info column (%s)" % (mode, info))
                check(rows[3]["eth.type"] == ["0x88a4", "0x88b5"] and rows[6]["eth.type"] == ["0x88a4", "0x88b5"],
                      "%s: each EoE frame reassembled and handed to eth in its last fragment (%s, %s)" % (
                          mode, rows[3]["eth.type"], rows[6]["eth.type"]))
                if args:
                    check(rows[2]["ecatr.reassembled_in"] == ["3"] and rows[5]["ecatr.reassembled_in"] == ["6"],
                          "-2: each first fragment links to the frame it was reassembled in")

    def test_computed_values_match_the_bytes(self):
        """Mailbox total lengths (ecatr.datagram.mbx.totallength, ecatr.gateway.totallength),
        frame by frame."""
        env = self.env
        with self.checks() as check:
            fs = computed_frames()
            frames, t = [], 1704067200.0
            for f, _ in fs:
                f.src_mac, f.ts = MASTER, t
                frames.append(f)
                t += 0.001
            path = env.add_file("computed-values.pcap", pg.pcap_bytes(frames))
            rows, err = env.field_rows(path, ["frame.number"] + COMPUTED, with_stderr=True)
            check(not err.strip(), "tshark wrote nothing to stderr%s" % (": " + err.strip()[:300] if err.strip() else ""))
            bad = []
            for k, (_, want) in enumerate(fs):
                got = rows.get(k + 1, {})
                diff = {n: (got.get(n), want.get(n, [])) for n in COMPUTED if got.get(n) != want.get(n, [])}
                if diff:
                    bad.append("frame %d: %s" % (k + 1, diff))
            check(not bad, "%d frames: the computed values are those of the bytes%s" % (
                len(fs), "".join("\n       " + b for b in bad[:6])))
            shown = env.tshark(["-r", path, "-V", "-Y", "frame.number == 1"]).stdout
            check("[Total length: 16 bytes]" in shown, "the tree shows the value with its unit (16 bytes)")
            shown = env.tshark(["-r", path, "-V", "-Y", "ecatr.datagram.recvdelay1 == 600"]).stdout
            check("[Loop delay port 0 to port 1: 600 ns]" in shown, "the tree shows the loop delay in ns")

    def test_loop_delay_on_real_captures(self):
        """ecatr.datagram.recvdelay1 on the corpus's reads of the DC receive times: port 1's
        time minus port 0's (as ecatr.datagram.reg.recv0/recv1 show them), modulo 2^32 ns."""
        folder = os.path.join(os.path.abspath(self.args.source_dir), "..", "shared", "corpus", "ethercat")
        names = [f for f in ("replay-dc.pcapng", "replay-ek1100-el2828-el2889.pcapng") if os.path.exists(
            os.path.join(folder, f))]
        if not names:
            self.skipTest("no EtherCAT corpus at %s" % folder)
        with self.checks() as check:
            for name in names:
                path = self.env.readable(os.path.join(folder, name))
                rows = self.env.field_rows(path, ["frame.number", "ecatr.datagram.reg.recv0", "ecatr.datagram.reg.recv1",
                                                  "ecatr.datagram.recvdelay1"], aggregator="|",
                                           display_filter="ecatr.datagram.recvdelay1")
                bad, n = [], 0
                for frame, r in rows.items():
                    want = [str((relative_time_ns(b) - relative_time_ns(a)) % 2**32)
                            for a, b in zip(r["ecatr.datagram.reg.recv0"], r["ecatr.datagram.reg.recv1"])]
                    n += len(want)
                    if r["ecatr.datagram.recvdelay1"] != want:
                        bad.append((frame, r))
                check(n > 0 and not bad, "%s: %d loop delays, each port 1's receive time minus port 0's%s"
                      % (name, n, ": %s" % bad[:3] if bad else ""))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

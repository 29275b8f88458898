#!/usr/bin/env python3
"""The bus as the capture shows it, and the network check, with real tshark.

1. Identities: on every real capture of ../shared/corpus/ethercat, the slaves the plugin
   reports per position (ecatr.slave.position/station/vendor/product/revision) are the ones
   the corpus README lists (read there from the SII EEPROM by other means). With
   --esi Beckhoff_EK11xx.xml --esi Beckhoff_EL1xxx.xml the SOEM capture names both slaves
   (ecatr.slave.name EK1100, EL1004); with `-2` every datagram addressed to a slave carries
   its identity, also those before the scan.
2. The network check on soem-sdinfo-ek1100-el1004 (EK1100 + EL1004) with four designs:
   matching (one ecatr.expert.network.ok, no error), a slave dropped and one added
   (ecatr.expert.network.count on the first broadcast read that shows the count, nothing
   else), two models swapped (ecatr.expert.network.model on the two frames where the
   identities are read, nothing else). The frames are those a reading of the bytes here
   (not the plugin) finds; one pass and `-2` give the same experts.
3. Expected working counters (ecatr.wkc.expected, from the FMMU configuration the master
   wrote): no ecatr.expert.wkc on any real capture; on copies of the ethercrab captures with
   the returned working counter of some logical datagrams lowered, ecatr.expert.wkc on
   exactly those frames (one pass and -2).
4. The per-slave statistics (-z ecatr,tree): the same in one pass and -2, and the datagram
   counts those of the returned frames' slave items.
5. The ENI of ../shared/corpus/eni: its cyclic commands' Cnt is the expected working counter
   of a matching LRD (generated frames: the right count, then one short).
6. Process data by name (generated frames, tests/esi_ok/small_io.xml with
   tests/network/small_design.xml): after the stations and FMMUs are set, an LRW shows the
   EL2004's outputs (ecatr.pdo.el2004.*) in the frame as sent and the EL1004's inputs
   (ecatr.pdo.el1004.*) in the returned one, with the values written into the bytes here; sent
   again with its working counter already counted, returned short by 1, 2 or 3: ecatr.expert.wkc
   naming the one slave whose part the shortfall is, none when it is two slaves' parts. Every
   exchange comes back as the ring returns it (auto-increment addresses counted up) and raises no
   expert info; -z ecatr,tree counts position 1's mailbox datagrams (inside SyncManagers 0 and 1,
   not 2 though it is written in mailbox mode) and AL state changes as the bytes do; EEPROM words
   read past the identity, the address's low byte alone rewritten in between, leave it.
7. Process data as the master configures it over CoE (generated frames, an EL1252 of
   ../shared/corpus/esi/Beckhoff_EL1xxx.xml identified from its SII): 0x1C13 and a mapping
   written one subindex at a time (with a write the slave did not take and a segmented
   download, neither followed), by complete access (completed in the frame of the LRD), and
   read back by an upload; odd traffic (short mailboxes, an empty mapping, counts past the
   data, entries past the slave's share). Every LRD before the configuration is complete shows
   the ESI defaults; the one after it the entries at the bits the test computes from the
   assignment and mappings, with their fields, or ecatr.pdo.entry/value where the model has no
   field for them (0x1D09:10, only in a PDO not assigned by default) or its ESI file does not
   know them (0x7777:01); one pass and -2 alike. The same with a design
   (tests/network/small_design.xml: its EL1004 assigned 0x1A10, which small_io.xml does not
   assign by default), without the corpus too. The EL1252 test is skipped without the ESI file.
Each part is one test (TestBusModel.test_...; one alone: give its name after the options).
Without the corpus, parts 1 to 5 are reported skipped and parts 6 and 7 run all the same.
"""
import os
import random
import re
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import pcapgen as pg  # noqa: E402
import pcaprewrite as pr  # noqa: E402
from tshark_env import TsharkEnv, TsharkTestCase, corpus_captures, run_unittests  # noqa: E402

ARGS = None
SLAVE = ["ecatr.slave.position", "ecatr.slave.station", "ecatr.slave.vendor", "ecatr.slave.product",
         "ecatr.slave.revision", "ecatr.slave.name"]
EXPERTS = ["ecatr.expert.network.count", "ecatr.expert.network.model", "ecatr.expert.network.ok"]

# From ../shared/corpus/README.md: (vendor, product, revision) by position; None: not stated there.
BECKHOFF = 2
EK1100 = (BECKHOFF, 0x044c2c52, 0x00120000)
EL1004 = (BECKHOFF, 0x03ec3052, 0x00130000)
EXPECTED = {
    "soem-sdinfo-ek1100-el1004.pcapng": [EK1100, EL1004],
    "twincat-scan-boxes.pcapng": [EK1100, EL1004],
    "replay-ek1100-el2828-el2889.pcapng": [EK1100, (BECKHOFF, 0x0b0c3052, None), (BECKHOFF, 0x0b493052, None)],
    "replay-dc.pcapng": [EK1100, (BECKHOFF, 0x0b0c3052, None), (BECKHOFF, 0x0b493052, None)],
    "replay-issue-255.pcapng": [EK1100, (BECKHOFF, 0x0b0c3052, None), (BECKHOFF, 0x0b493052, None)],
    "replay-ek1914-segmented-upload.pcapng": [(BECKHOFF, 0x077a2c52, None), (BECKHOFF, 0x0bbc3052, None)],
    "replay-sdo-error.pcapng": [(BECKHOFF, 0x077a2c52, None)],
    "twincat-akd-nc-mode.pcapng": [(0x6a, 0x00414b44, None)],
    "soem-sdinfo-no-slaves.pcapng": [],
}


def decode(env, path, fields, two_pass, display_filter=None):
    """[(frame, {field: [values]})] from tshark -T fields (all occurrences)."""
    rows = env.field_rows(path, ["frame.number"] + fields, two_pass, display_filter, aggregator=";")
    return [(n, {f: [v for v in vs if v] for f, vs in r.items()}) for n, r in rows.items()]


def slaves_seen(rows):
    """{position: {(station, vendor, product, revision, name)}} over every datagram."""
    seen = {}
    for _n, r in rows:
        k = len(r["ecatr.slave.position"])
        for i in range(k):
            def col(f):
                v = r[f]
                return v[i] if len(v) == k else ("?" if v else "")
            seen.setdefault(int(col("ecatr.slave.position")), set()).add(
                tuple(col(f) for f in SLAVE[1:]))
    return seen


# ----------------------------------------------------------------------------- the bytes' view

def returned_pairs(cap):
    """[(frame number, sent datagrams, returned datagrams)] of returned frames, paired with the
    latest sent frame of the same datagram commands and lengths (returned frames come from the
    master's address with the locally administered bit set)."""
    out, waiting = [], {}
    for i, p in enumerate(cap.packets):
        dgs = pr.ecat_datagrams(p)
        if not dgs:
            continue
        key = tuple((d["cmd"], d["idx"], d["length"]) for d in dgs)
        if p.data[6] & 0x02:
            if key in waiting:
                out.append((i + 1, waiting.pop(key), (p, dgs)))
        else:
            waiting[key] = (p, dgs)
    return out


def u16(p, off):
    return struct.unpack("<H", bytes(p.data[off:off + 2]))[0]


def oracle(cap):
    """(frame of the first BRD with a working counter, {position: frame where vendor and
    product had both been read from the SII EEPROM})."""
    first_brd, station_pos, address, words, identity_frame = None, {}, {}, {}, {}
    for n, (sp, sent), (bp, back) in returned_pairs(cap):
        for s, b in zip(sent, back):
            if b["wkc"] <= s["wkc"]:
                continue
            if s["cmd"] == 7 and first_brd is None:
                first_brd = n
            if s["cmd"] in (1, 2):  # APRD APWR
                pos = (0x10000 - s["adp"]) & 0xFFFF
            elif s["cmd"] in (4, 5):  # FPRD FPWR
                pos = station_pos.get(s["adp"])
            else:
                continue
            if s["cmd"] == 2 and s["ado"] == 0x0010:
                station_pos[u16(sp, s["data_offset"])] = pos
            if s["cmd"] in (2, 5) and s["ado"] <= 0x0504 <= s["ado"] + s["length"] - 2:
                address[pos] = u16(sp, s["data_offset"] + 0x0504 - s["ado"])
            if s["cmd"] in (1, 4) and s["ado"] == 0x0508 and pos in address:
                for w in range(b["length"] // 2):
                    words.setdefault(pos, set()).add(address[pos] + w)
                if pos not in identity_frame and {8, 9, 10, 11} <= words.get(pos, set()):
                    identity_frame[pos] = n
    return first_brd, identity_frame


# ----------------------------------------------------------------------------- checks

def identity_checks(check, env, corpus, files):
    print("\n== identities per capture (tshark -2)")
    for name in files:
        rows = decode(env, os.path.join(corpus, name), SLAVE, True, "ecatr.slave")
        seen = slaves_seen(rows)
        want = EXPECTED.get(name)
        print("%s: %d datagram frames with slaves; %s" % (name, len(rows), {
            p: sorted(v) for p, v in sorted(seen.items())}))
        if want is None:
            continue
        check(sorted(seen) == list(range(len(want))), "%s: positions %s" % (name, list(range(len(want)))))
        for pos, (vendor, product, revision) in enumerate(want):
            ids = {(v, pr_, r) for _st, v, pr_, r, _name in seen.get(pos, set())}
            got = ids == {("0x%08x" % vendor, "0x%08x" % product,
                           "0x%08x" % revision if revision is not None else next(iter(ids))[2])} if ids else False
            check(got, "%s: position %d is vendor 0x%x product 0x%08x%s on every datagram (-2): %s" % (
                name, pos, vendor, product, "" if revision is None else " revision 0x%08x" % revision, sorted(ids)))
            stations = {st for st, *_rest in seen.get(pos, set())}
            check(len(stations) == 1 and "" not in stations, "%s: position %d has one station %s" % (
                name, pos, sorted(stations)))


def names_checks(check, env, corpus):
    print("\n== names from the ESI files (soem-sdinfo-ek1100-el1004)")
    path = os.path.join(corpus, "soem-sdinfo-ek1100-el1004.pcapng")
    rows = decode(env, path, SLAVE, True, "ecatr.slave")
    seen = slaves_seen(rows)
    names = {p: {t[-1] for t in v} for p, v in seen.items()}
    check(names == {0: {"EK1100"}, 1: {"EL1004"}}, "-2: every datagram to position 0 names EK1100, to 1 EL1004: %s"
          % names)
    one = decode(env, path, SLAVE, False, "ecatr.slave")
    _brd, ident = oracle(pr.Capture.read(path))
    for pos, want in ((0, "EK1100"), (1, "EL1004")):
        named = [n for n, r in one if pos_name(r, pos) == want]
        unnamed = [n for n, r in one if pos_name(r, pos) == ""]
        check(named and min(named) == ident[pos] and (not unnamed or max(unnamed) < ident[pos]),
              "one pass: position %d named %s from frame %s on (identity read there), not before" % (
                  pos, want, ident.get(pos)))


def pos_name(r, pos):
    ps, ns = r["ecatr.slave.position"], r["ecatr.slave.name"]
    if str(pos) not in ps:
        return None
    return ns[0] if ns and len(set(ps)) == 1 else ("" if not ns else None)


def design(env, name, slaves):
    body = "".join('  <slave vendor="0x%x" product="0x%08x"/>\n' % s[:2] for s in slaves)
    return env.add_file(name, ("<network>\n%s</network>\n" % body).encode())


def network_checks(check, dissgen, rules, corpus):
    print("\n== the network check (soem-sdinfo-ek1100-el1004)")
    path = os.path.join(corpus, "soem-sdinfo-ek1100-el1004.pcapng")
    first_brd, ident = oracle(pr.Capture.read(path))
    print("bytes: first BRD answered in frame %s; identities read in frames %s" % (first_brd, ident))
    cases = [
        ("match", [EK1100, EL1004], {"ok": {max(ident.values())}}),
        ("drop", [EK1100], {"count": {first_brd}}),
        ("add", [EK1100, EL1004, EL1004], {"count": {first_brd}}),
        ("swap", [EL1004, EK1100], {"model": {ident[0], ident[1]}}),
    ]
    for case, slaves, want in cases:
        with TsharkEnv() as env:
            env.install_plugin(dissgen, rules, ["--network", design(env, case + ".xml", slaves)])
            with open(path, "rb") as fh:
                local = env.add_file("soem.pcapng", fh.read())
            results = []
            for two_pass in (False, True):
                rows = decode(env, local, EXPERTS, two_pass)
                got = {e.rsplit(".", 1)[1]: {n for n, r in rows if r[e]} for e in EXPERTS}
                got = {k: v for k, v in got.items() if v}
                results.append(got)
                check(got == want, "%s design%s: experts %s, expected %s" % (
                    case, " (-2)" if two_pass else "", got, want))
            texts = env.tshark(["-r", local, "-2", "-z", "expert,note", "-q"]).stdout
            for line in texts.splitlines():
                if "design" in line or "Position" in line:
                    print("   " + line.strip())


def wkc_checks(check, env, corpus, files):
    print("\n== expected working counters")
    for name in files:
        path = os.path.join(corpus, name)
        rows = decode(env, path, ["ecatr.wkc.expected", "ecatr.expert.wkc"], True)
        with_expected = [n for n, r in rows if r["ecatr.wkc.expected"]]
        flagged = [n for n, r in rows if r["ecatr.expert.wkc"]]
        print("%s: %d frames with an expected working counter, %d flagged" % (name, len(with_expected),
                                                                             len(flagged)))
        check(not flagged, "%s: no ecatr.expert.wkc on the real capture" % name)
    for name in ("replay-ek1100-el2828-el2889.pcapng", "replay-dc.pcapng", "replay-issue-255.pcapng"):
        if name not in files:
            continue
        cap = pr.Capture.read(os.path.join(corpus, name))
        returned = [i for i, p in enumerate(cap.packets)
                    if p.data[6] & 0x02 and any(d["cmd"] in (10, 11, 12) and d["wkc"] for d in pr.ecat_datagrams(p))]
        lowered = set()
        for k, i in enumerate(returned):
            if k % 37 != 5:
                continue
            p = cap.packets[i]
            d = next(d for d in pr.ecat_datagrams(p) if d["cmd"] in (10, 11, 12) and d["wkc"])
            pr.set_u16(p, d["wkc_offset"], d["wkc"] - 1)
            lowered.add(i + 1)
        faulty = env.add_file("wkc-" + name, b"")
        cap.write(faulty)
        os.chmod(faulty, 0o644)
        for two_pass in (False, True):
            rows = decode(env, faulty, ["ecatr.expert.wkc"], two_pass)
            flagged = {n for n, r in rows if r["ecatr.expert.wkc"]}
            check(flagged == lowered, "%s with %d returned working counters lowered%s: ecatr.expert.wkc on exactly "
                  "those frames (missing %s, extra %s)" % (name, len(lowered), " (-2)" if two_pass else "",
                                                           sorted(lowered - flagged)[:5], sorted(flagged - lowered)[:5]))
        texts = env.tshark(["-r", faulty, "-q", "-z", "expert,warn"]).stdout
        print("\n".join("   " + l.strip() for l in texts.splitlines() if "expected working counter" in l))


def slave_stats(env, path, two_pass):
    """{position: {item: count}} of the "Slaves" part of -z ecatr,tree."""
    args = ["-r", path, "-q", "-z", "ecatr,tree"] + (["-2"] if two_pass else [])
    out, pos = {}, None
    for line in env.tshark(args).stdout.splitlines():
        # (columns are as wide as the longest label: split at the gap after it)
        label, _, rest = line.strip().partition("  ")
        cols = rest.split()
        if line.startswith("  Position "):
            pos = int(label.split()[1])
            out[pos] = {}
        elif line.startswith("   ") and pos is not None and cols:
            out[pos][label] = int(cols[0])
        elif not line.startswith("   "):
            pos = None
    return out


def stats_checks(check, env, corpus):
    print("\n== statistics per slave (-z ecatr,tree)")
    for name in ("soem-sdinfo-ek1100-el1004.pcapng", "replay-mailbox-el6910.pcapng", "twincat-scan-boxes.pcapng"):
        path = os.path.join(corpus, name)
        one, two = slave_stats(env, path, False), slave_stats(env, path, True)
        print("%s: %s" % (name, one))
        check(one == two and one, "%s: the same per-slave statistics in one pass and -2" % name)
        rows = decode(env, path, ["ecatr.slave.position"], False, "ecatr.request_in")
        counts = {}
        for _n, r in rows:
            for p in r["ecatr.slave.position"]:
                counts[int(p)] = counts.get(int(p), 0) + 1
        check({p: v.get("Datagrams") for p, v in one.items()} == counts,
              "%s: per-slave datagram counts are those of the returned frames' ecatr.slave.position (%s)"
              % (name, counts))
        mailbox = {p: v.get("Mailbox datagrams", 0) for p, v in one.items()}
        check(all(mailbox[p] <= v.get("Datagrams", 0) for p, v in one.items()),
              "%s: mailbox datagrams per slave, each at most its datagrams (%s)" % (name, mailbox))
        if name == "replay-mailbox-el6910.pcapng":
            check(sum(mailbox.values()) > 0, "%s: a capture of mailbox exchanges counts mailbox datagrams" % name)


def eni_checks(check, dissgen, rules, shared):
    print("\n== the ENI's expected working counters")
    eni = os.path.join(shared, "eni", "twincat_5_slaves_eni.xml")
    # Its cyclic frame reads 14 bytes at logical 0x01000000 with <Cnt>1</Cnt>.
    master, back = b"\x00\x00\x00\x00\x00\x01", b"\x02\x00\x00\x00\x00\x01"
    frames = []
    for i, wkc in enumerate((1, 0)):
        for src, w in ((master, 0), (back, wkc)):
            frames.append(pg.Frame([pg.Datagram(10, idx=i, lad=0x01000000, data=bytes(14), wkc=w)], src_mac=src))
    with TsharkEnv() as env:
        env.install_plugin(dissgen, rules, ["--network", eni])
        path = env.add_file("eni.pcap", pg.pcap_bytes(frames))
        for two_pass in (False, True):
            rows = decode(env, path, ["ecatr.wkc.expected", "ecatr.expert.wkc"], two_pass)
            got = [(n, r["ecatr.wkc.expected"], bool(r["ecatr.expert.wkc"])) for n, r in rows]
            check(got == [(1, ["1"], False), (2, ["1"], False), (3, ["1"], False), (4, ["1"], True)],
                  "ENI Cnt 1 expected on every frame, ecatr.expert.wkc on frame 4 only%s: %s" % (
                      " (-2)" if two_pass else "", got))


def fmmu(logical, length, kind, start_bit=0, physical=0x1000):
    """One FMMU's 16 configuration bytes (kind 1 read, 2 write), active."""
    return struct.pack("<IHBBHBBBxxx", logical, length, start_bit, 7, physical, 0, kind, 1)


def sii_reads(station, vendor, product, revision):
    """The master reading a slave's identity from its SII EEPROM: the word address written to
    0x0504 with the read command in 0x0502, then 8 bytes of 0x0508 (words 8-11: vendor and
    product; words 12-15: revision and serial)."""
    steps = []
    for word, data in ((0x0008, struct.pack("<II", vendor, product)), (0x000C, struct.pack("<II", revision, 0))):
        steps.append((pg.Datagram(5, adp=station, ado=0x0502, data=struct.pack("<HI", 0x0100, word)), None, 1))
        steps.append((pg.Datagram(4, adp=station, ado=0x0508, data=bytes(8)), data, 1))
    return steps


def pdo_checks(check, dissgen, source_dir, design=True):
    """Process data by name: with a design, of its slaves; without one, of the slaves the
    capture identifies from their SII, with their model's default process data (ESI)."""
    print("\n== process data by name (generated frames, %s)" % ("a design" if design else "the ESI file alone"))
    master, back = b"\x00\x00\x00\x00\x00\x01", b"\x02\x00\x00\x00\x00\x01"
    mode, setpoint = 0x35, -1234
    outputs = bytes([1 | mode << 1]) + struct.pack("<h", setpoint)
    # EL1004 reads: with a design, FMMU 0 at bit 0; without, FMMU 0 maps the mailbox status bit
    # (SyncManager 1 status, 0x080D: register space, not process data) and FMMU 1 the inputs
    # from logical bit 1 on.
    el1004 = fmmu(0x10000, 1, 1) if design else fmmu(0x80000, 1, 1, 0, 0x080D) + fmmu(0x10000, 1, 1, 1)
    inputs = 0b101 if design else 0b101 << 1
    steps = [  # (sent datagram, returned data or None: as sent, returned wkc)
        (pg.Datagram(2, adp=0xFFFF, ado=0x0010, data=struct.pack("<H", 0x1002)), None, 1),  # position 1
        (pg.Datagram(2, adp=0xFFFE, ado=0x0010, data=struct.pack("<H", 0x1003)), None, 1),  # position 2
        (pg.Datagram(5, adp=0x1002, ado=0x0600, data=el1004), None, 1),
        (pg.Datagram(5, adp=0x1003, ado=0x0600, data=fmmu(0x10001, 3, 2)), None, 1),  # EL2004 writes
    ]
    # Position 1's SyncManagers written at once: 0 and 1 mailboxes, 2 in mailbox mode too (only 0
    # and 1 are the mailboxes the model follows), 3 buffered; then its AL status read three times,
    # an upload request written to its mailbox and 4 bytes of its SyncManager 2 buffer read (too
    # few to be decoded as a mailbox).
    sms = [(0x1000, 128, 0x26), (0x1080, 128, 0x22), (0x1100, 8, 0x26), (0x1180, 8, 0x20)]
    states = (2, 2, 4)   # PREOP, PREOP, SAFEOP
    steps += [(pg.Datagram(5, adp=0x1002, ado=0x0800, data=b"".join(
        struct.pack("<HHBBBB", start, length, control, 0, 1, 0) for start, length, control in sms)), None, 1)]
    steps += [(pg.Datagram(4, adp=0x1002, ado=0x0130, data=bytes(2)), struct.pack("<H", al), 1) for al in states]
    steps += [(pg.Datagram(5, adp=0x1002, ado=0x1000, data=coe_mailbox(2, struct.pack("<BHBI", 0x40, 0x1018, 1, 0))),
               None, 1),
              (pg.Datagram(4, adp=0x1002, ado=0x1100, data=bytes(4)), None, 1)]
    mailbox = sum(1 for d, _data, _wkc in steps if d.adp == 0x1002 and d.cmd in (4, 5) and
                  any(start <= d.ado < start + length for start, length, _c in sms[:2]))
    al_changes = sum(1 for a, b in zip(states, states[1:]) if a != b)
    if not design:
        steps += sii_reads(0x1002, 2, 0x03EC3052, 0x00130000) + sii_reads(0x1003, 2, 0x07D43052, 0x00100000)
        # Then words 0x0108.. of position 2's EEPROM (past the identity), read twice: in between the
        # address's low byte alone is written again (1 byte, 0x08): its high byte stays, and what
        # is read there is not the identity.
        other = struct.pack("<II", 0x0BADC0DE, 0x12345678)
        steps += [(pg.Datagram(5, adp=0x1003, ado=0x0502, data=struct.pack("<HI", 0x0100, 0x0108)), None, 1),
                  (pg.Datagram(4, adp=0x1003, ado=0x0508, data=bytes(8)), other, 1),
                  (pg.Datagram(5, adp=0x1003, ado=0x0504, data=b"\x08"), None, 1),
                  (pg.Datagram(4, adp=0x1003, ado=0x0508, data=bytes(8)), other, 1)]
        # position 3: a product the ESI file does not have (its datagrams name no model)
        steps += [(pg.Datagram(2, adp=0xFFFD, ado=0x0010, data=struct.pack("<H", 0x1004)), None, 1)]
        steps += sii_reads(0x1004, 2, 0x0BADC0DE, 0x00100000)
    steps.append((pg.Datagram(12, lad=0x10000, data=bytes(1) + outputs), bytes([inputs]) + outputs, 3))
    ring = 4   # slaves: small_design.xml's, or positions 0 to 3
    frames = []
    for i, (d, data, wkc) in enumerate(steps):
        d.idx = i
        frames.append(pg.Frame([d], src_mac=master))
        # As the ring returns it: each of the slaves counts the address of an auto-increment
        # (position) command up.
        adp = (d.adp + ring) & 0xFFFF if d.cmd in (1, 2, 3) else d.adp
        r = pg.Datagram(d.cmd, idx=i, adp=adp, ado=d.ado, lad=d.lad, data=data if data else d.data, wkc=wkc)
        frames.append(pg.Frame([r], src_mac=back))
    fields = ["ecatr.pdo.el1004.channel_1.input", "ecatr.pdo.el1004.channel_2.input",
              "ecatr.pdo.el1004.channel_3.input", "ecatr.pdo.el2004.channel_1.output",
              "ecatr.pdo.el2004.channel_1.mode", "ecatr.pdo.el2004.channel_1.setpoint",
              "ecatr.wkc.expected", "ecatr.expert.wkc", "_ws.expert.message"]
    yes = {"1", "True"}
    no = {"0", "False"}
    lrw = len(frames) - 1   # the LRW as sent, then returned
    if design:
        # The same LRW sent with its working counter already at 4 (a frame the master passes
        # on): the slaves add 3 (met), then 2, 1 and 0 (one, two and three short). What counts is
        # what they added; a shortfall one slave's part accounts for names it (position 1, the
        # EL1004, reads: 1; position 2, the EL2004, writes: 2; neither identified from its SII
        # here), one of both slaves' parts names none.
        for k, back_wkc in enumerate((7, 6, 5, 4)):
            i = len(steps) + k
            frames.append(pg.Frame([pg.Datagram(12, idx=i, lad=0x10000, data=bytes(1) + outputs, wkc=4)],
                                   src_mac=master))
            frames.append(pg.Frame([pg.Datagram(12, idx=i, lad=0x10000, data=bytes([inputs]) + outputs,
                                                wkc=back_wkc)], src_mac=back))
    if not design:
        fields = fields[:6] + fields[-1:]
    with TsharkEnv() as env:
        env.install_plugin(dissgen, os.path.join(source_dir, "rules", "ethercat.xml"),
                           ["--esi", os.path.join(source_dir, "tests", "esi_ok", "small_io.xml")] +
                           (["--network", os.path.join(source_dir, "tests", "network", "small_design.xml")]
                            if design else []))
        path = env.add_file("pdo.pcap", pg.pcap_bytes(frames))
        for two_pass in (False, True):
            rows = dict(decode(env, path, fields, two_pass))
            tag = " (-2)" if two_pass else ""
            sent, ret = rows[lrw], rows[lrw + 1]
            check(sent["ecatr.pdo.el2004.channel_1.output"][0] in yes and
                  sent["ecatr.pdo.el2004.channel_1.mode"] == [str(mode)] and
                  sent["ecatr.pdo.el2004.channel_1.setpoint"] == [str(setpoint)],
                  "LRW as sent: EL2004 outputs by name (1, %d, %d)%s: %s" % (mode, setpoint, tag, sent))
            check(not any(sent[f] for f in fields[:3]), "LRW as sent: no EL1004 inputs" + tag)
            check([ret[f][0] if ret[f] else "" for f in fields[:3]] in (["1", "0", "1"], ["True", "False", "True"]),
                  "LRW returned: EL1004 inputs by name (1, 0, 1)%s: %s" % (tag, ret))
            check(not any(ret[f] for f in fields[3:6]), "LRW returned: no EL2004 outputs" + tag)
            noisy = {n: r["_ws.expert.message"] for n, r in rows.items() if n <= lrw + 1 and r["_ws.expert.message"]}
            check(not noisy, "the exchanges up to the LRW, as the ring returns them, raise no expert info%s: %s"
                  % (tag, noisy))
            stats = slave_stats(env, path, two_pass).get(1, {})
            check((stats.get("Mailbox datagrams", 0), stats.get("AL state changes", 0)) == (mailbox, al_changes),
                  "position 1: %d mailbox datagrams (inside SyncManagers 0 and 1), %d AL state change%s: %s"
                  % (mailbox, al_changes, tag, stats))
            if design:
                check(sent["ecatr.wkc.expected"] == ["3"] and ret["ecatr.wkc.expected"] == ["3"] and
                      not ret["ecatr.expert.wkc"], "expected working counter 3 (EL1004 +1, EL2004 +2), met" + tag)
                met, short = rows[lrw + 3], rows[lrw + 5]
                check(not met["ecatr.expert.wkc"] and len(short["ecatr.expert.wkc"]) == 1,
                      "sent with working counter 4: returned 7 is met, 6 is one short (the slaves' additions "
                      "count, not the returned counter)%s: %s, %s" % (tag, met["ecatr.expert.wkc"],
                                                                      short["ecatr.expert.wkc"]))
                texts = [[m for m in rows[lrw + 3 + 2 * k]["_ws.expert.message"] if "working counter" in m]
                         for k in range(4)]
                head = "LRW: expected working counter 3, got "
                want = [[], [head + "2: the slave at position 1 did not read its inputs"],
                        [head + "1: the slave at position 2 did not write its outputs"], [head + "0"]]
                check(texts == want, "the shortfall names the one slave whose part it is, none when it is "
                      "two slaves' parts%s: %s" % (tag, texts))
            else:
                tree = env.tshark(["-r", path, "-V"] + (["-2"] if two_pass else [])).stdout.split("\nFrame ")
                titles = [re.findall(r"\[(EL\d+ \(position \d\): \w+)\]", tree[k - 1]) for k in (lrw, lrw + 1)]
                check(titles == [["EL2004 (position 2): outputs"], ["EL1004 (position 1): inputs"]],
                      "subtrees named by the model and position the SII gave%s: %s" % (tag, titles))
                # "Slave 3" or "Slave 3, station 0x1003": no ": MODEL" after the position.
                unknown = sorted(set(re.findall(r"\[(Slave 3\b[^\]\n]*)\]", "\n".join(tree))))
                check(unknown and all(not u.startswith("Slave 3:") for u in unknown),
                      "the slave whose product the ESI file lacks is named by its position only%s: %s" % (
                          tag, unknown))


# ----------------------------------------------------------------------------- CoE PDO configuration

EL1252 = (BECKHOFF, 0x04E43052, 0x00160000)
MBX_OUT, MBX_IN = 0x1000, 0x1080   # SyncManager 0 (master to slave) and 1 mailboxes


def mailbox_config():
    """SyncManagers 0 and 1 as mailboxes (0x0800: start, length, control with mode 2)."""
    return struct.pack("<HHBBBB", MBX_OUT, 128, 0x26, 0, 1, 0) + struct.pack("<HHBBBB", MBX_IN, 128, 0x22, 0, 1, 0)


def coe_mailbox(service, sdo, counter=1):
    """A CoE mailbox of 128 bytes: mailbox header, CoE header, the SDO bytes, zero padding."""
    body = struct.pack("<H", service << 12) + sdo
    return (struct.pack("<HHBB", len(body), 0, 0, 3 | (counter & 7) << 4) + body).ljust(128, b"\0")


def sdo_expedited(index, sub, value, size, declared=None):
    """An expedited SDO download request of `size` bytes (1, 2 or 4) whose size bits say
    `declared` bytes (default: `size`)."""
    cmd = 0x20 | 0x02 | 0x01 | (4 - (declared or size)) << 2
    return coe_mailbox(2, struct.pack("<BHB", cmd, index, sub) + value.to_bytes(size, "little").ljust(4, b"\0"))


def sdo_complete_access(index, values, size):
    """A complete-access SDO download from subindex 0: subindex 0 padded to 16 bits, then the
    entries of `size` bytes (normal transfer: a size, then the data)."""
    data = struct.pack("<BB", len(values), 0) + b"".join(v.to_bytes(size, "little") for v in values)
    return coe_mailbox(2, struct.pack("<BHBI", 0x21 | 0x10, index, 0, len(data)) + data)


def sdo_upload_response(index, values, size):
    """The slave's answer to a complete-access upload of `index` (normal transfer)."""
    data = struct.pack("<BB", len(values), 0) + b"".join(v.to_bytes(size, "little") for v in values)
    return coe_mailbox(3, struct.pack("<BHBI", 0x41 | 0x10, index, 0, len(data)) + data)


def sdo_segmented_start(index, sub, data):
    """A normal SDO download whose size is more than the mailbox holds (segments would follow)."""
    return coe_mailbox(2, struct.pack("<BHBI", 0x21, index, sub, 4096) + data[:100])


def bits_of(data, bit, n):
    v = int.from_bytes(data, "little")
    return (v >> bit) & ((1 << n) - 1)


def exchanges(steps):
    """A master's frames and their returns: each step a frame, a list of (datagram as sent, data
    it comes back with or None for the data sent, working counter it comes back with); the
    datagrams of step i carry index i."""
    master, back = b"\x00\x00\x00\x00\x00\x01", b"\x02\x00\x00\x00\x00\x01"
    frames = []
    for i, frame in enumerate(steps):
        sent, returned = [], []
        for d, data, wkc in frame:
            d.idx = i & 0xFF
            sent.append(d)
            returned.append(pg.Datagram(d.cmd, idx=d.idx, adp=d.adp, ado=d.ado, lad=d.lad,
                                        data=data if data else d.data, wkc=wkc))
        frames += [pg.Frame(sent, src_mac=master), pg.Frame(returned, src_mac=back)]
    return frames


def coe_frames(config_steps, inputs_before, inputs_after, inputs_middle=None, station=0x1002, same_frame=False,
               identity=EL1252):
    """The EL1252 (or `identity`) at position 1 (station `station`): station, identity (SII), mailboxes, an FMMU
    reading 24 bytes of inputs at logical 0x10000; an LRD of them; the configuration steps
    ((mailbox, returned working counter): a write to SyncManager 0, or for a response a read of
    SyncManager 1; "lrd": an LRD returning `inputs_middle`); the LRD again (with `same_frame`, in
    the frame of the last step). Returns (frames, frame numbers of the returned LRDs)."""

    def lrd(data):
        return [(pg.Datagram(10, lad=0x10000, data=bytes(24)), data, 1)]

    steps = [[(pg.Datagram(2, adp=0xFFFF, ado=0x0010, data=struct.pack("<H", station)), None, 1)]]
    steps += [[step] for step in sii_reads(station, *identity)]
    steps += [[(pg.Datagram(5, adp=station, ado=0x0800, data=mailbox_config()), None, 1)],
              [(pg.Datagram(5, adp=station, ado=0x0600, data=fmmu(0x10000, 24, 1, 0, 0x1100)), None, 1)],
              lrd(inputs_before)]
    for step in config_steps:
        if step == "lrd":
            steps.append(lrd(inputs_middle))
            continue
        m, wkc = step
        if m[5] & 0x0F == 3 and struct.unpack("<H", m[6:8])[0] >> 12 == 3:   # a response: read from SM1
            steps.append([(pg.Datagram(4, adp=station, ado=MBX_IN, data=bytes(len(m))), m, wkc)])
        else:
            steps.append([(pg.Datagram(5, adp=station, ado=MBX_OUT, data=m), None, wkc)])
    if same_frame:
        steps[-1] += lrd(inputs_after)
    else:
        steps.append(lrd(inputs_after))
    lrds = [2 * (i + 1) for i, frame in enumerate(steps) if any(d.cmd == 10 for d, _data, _wkc in frame)]
    return exchanges(steps), lrds


def coe_checks(check, dissgen, source_dir, shared):
    """Process data as the master assigns and maps it over CoE (0x1C13, 0x1Axx), on an EL1252
    of Beckhoff_EL1xxx.xml: its default inputs are 0x1A00, 0x1A01, 0x1A02 (empty) and 0x1A13;
    0x1A14 (SysTime, 0x1D09:10) is one it does not assign by default."""
    print("\n== process data as configured over CoE (generated frames, EL1252)")
    esi = os.path.join(shared, "esi", "Beckhoff_EL1xxx.xml")
    ch1, ch2 = "ecatr.pdo.el1252.channel_0.input", "ecatr.pdo.el1252.channel_1.input"
    # The fields of revision 0x00160000's 0x1A13 (0x1D09:AE, AF, B0, B8): older revisions name
    # other objects of 0x1A13 Status1 and LatchPos1 (see `dissgen fields`), hence the _2.
    latch = ["ecatr.pdo.el1252.latch.status1_2", "ecatr.pdo.el1252.latch.status2",
             "ecatr.pdo.el1252.latch.latchpos1_2", "ecatr.pdo.el1252.latch.latchneg1_2"]
    fields = [ch1, ch2] + latch + ["ecatr.pdo.entry", "ecatr.pdo.value", "ecatr.process_data"]
    before = bytes(range(0xA1, 0xB9))   # 24 bytes of inputs, each byte other
    after = bytes((i * 37 + 11) & 0xFF for i in range(24))

    def defaults(data):  # 0x1A00 0x6000:01 bit 0, 0x1A01 0x6000:02 bit 1 + 6 padding, 0x1A13 from bit 8
        return {ch1: [bits_of(data, 0, 1)], ch2: [bits_of(data, 1, 1)],
                latch[0]: [data[1]], latch[1]: [data[2]], latch[2]: [bits_of(data, 24, 64)],
                latch[3]: [bits_of(data, 88, 64)]}

    # (a) one subindex at a time: 0x1A02 mapped to an object the ESI file does not have
    # (0x7777:01, 16 bits); 0x1C13 = 0x1A01, 0x1A00, 0x1A14 (SysTime, 32 bits: no field), 0x1A02.
    expedited = [(sdo_expedited(0x1A02, 0, 0, 1), 1), (sdo_expedited(0x1A02, 1, 0x77770110, 4), 1),
                 (sdo_expedited(0x1A02, 0, 1, 1), 1),
                 (sdo_expedited(0x1C13, 0, 0, 1), 1), (sdo_expedited(0x1C13, 1, 0x1A01, 2), 1),
                 (sdo_expedited(0x1C13, 2, 0x1A00, 2), 1), (sdo_expedited(0x1C13, 3, 0x1A14, 2), 1),
                 (sdo_expedited(0x1C13, 4, 0x1A02, 2), 1),
                 (sdo_expedited(0x1C13, 4, 0x1A13, 2), 0),     # not taken by the slave (wkc 0)
                 (sdo_segmented_start(0x1C13, 1, struct.pack("<H", 0x1A13)), 1),  # segmented: not followed
                 "lrd",                                         # 0x1C13 not complete yet
                 (sdo_expedited(0x1C13, 0, 4, 1), 1)]

    def middle_expedited(data):  # the defaults, 0x1A02 (in them, empty in the ESI) mapped anew
        return {ch1: [bits_of(data, 0, 1)], ch2: [bits_of(data, 1, 1)],
                "ecatr.pdo.entry": ["0x7777:01"], "ecatr.pdo.value": [bits_of(data, 8, 16)],
                latch[0]: [data[3]], latch[1]: [data[4]], latch[2]: [bits_of(data, 40, 64)],
                latch[3]: [bits_of(data, 104, 64)]}

    def after_expedited(data):
        return {ch2: [bits_of(data, 0, 1)], ch1: [bits_of(data, 7, 1)],
                "ecatr.pdo.entry": ["0x1d09:10", "0x7777:01"],
                "ecatr.pdo.value": [bits_of(data, 8, 32), bits_of(data, 40, 16)]}

    # (b) complete access: 0x1A02 = 0x6000:01 (1 bit) + 7 bits of padding, then 0x1C13 =
    # 0x1A02, 0x1A13.
    complete = [(sdo_complete_access(0x1A02, [0x60000101, 0x00000007], 4), 1),
                (sdo_complete_access(0x1C13, [0x1A02, 0x1A13], 2), 1)]

    # (b') the same with a complete access of no bytes to 0x1A02 between: nothing to learn
    # from it (it neither empties 0x1A02 nor completes it).
    complete_empty = [complete[0], (coe_mailbox(2, struct.pack("<BHBI", 0x21 | 0x10, 0x1A02, 0, 0)), 1),
                      complete[1]]

    def after_complete(data):
        return {ch1: [bits_of(data, 0, 1)], latch[0]: [data[1]], latch[1]: [data[2]],
                latch[2]: [bits_of(data, 24, 64)], latch[3]: [bits_of(data, 88, 64)]}

    # (c) the slave's answer to an upload: 0x1C13 = 0x1A13 alone.
    upload = [(sdo_upload_response(0x1C13, [0x1A13], 2), 1)]

    def after_upload(data):
        return {latch[0]: [data[0]], latch[1]: [data[1]], latch[2]: [bits_of(data, 16, 64)],
                latch[3]: [bits_of(data, 80, 64)]}

    # (d) odd traffic: a mailbox too short for an SDO, one whose length field is too small, an
    # empty mapping (0x1A02), a mapping that claims 200 entries (0x1A13, entries never written:
    # 0 bits each), a complete access that claims 60 entries and holds 4 (0x1A03: four of
    # 64 bits, past the 24 bytes of the slave's share), then 0x1C13 = 0x1A02, 0x1A00, 0x1A13,
    # 0x1A03: the entries that fit are shown, the rest not.
    short = coe_mailbox(2, struct.pack("<BHB", 0x2F, 0x1C13, 0) + b"\x01")
    odd = [(short[:12], 1), (bytes([4]) + short[1:], 1),
           (sdo_complete_access(0x1A02, [], 4), 1),
           (sdo_expedited(0x1A13, 0, 0, 1), 1), (sdo_expedited(0x1A13, 0, 200, 1), 1),
           (coe_mailbox(2, struct.pack("<BHBI", 0x31, 0x1A03, 0, 2 + 4 * 4) + struct.pack("<BB", 60, 0) +
                        struct.pack("<4I", *[0x70000140] * 4)), 1),
           (sdo_complete_access(0x1C13, [0x1A02, 0x1A00, 0x1A13, 0x1A03], 2), 1)]

    def after_odd(data):
        return {ch1: [bits_of(data, 0, 1)], "ecatr.pdo.entry": ["0x7000:01", "0x7000:01"],
                "ecatr.pdo.value": [bits_of(data, 1, 64), bits_of(data, 65, 64)]}

    def norm(row):
        out = {}
        for f in fields[:-1]:
            vals = []
            for v in row[f]:
                vals.append(v if f == "ecatr.pdo.entry" else int(v == "True") if v in ("True", "False")
                            else int(v, 0))
            if vals:
                out[f] = vals
        return out

    middle = bytes((i * 53 + 5) & 0xFF for i in range(24))
    ok = True
    with TsharkEnv() as env:
        env.install_plugin(dissgen, os.path.join(source_dir, "rules", "ethercat.xml"), ["--esi", esi])
        # (case, steps, expected after, expected in the middle, the last step in the LRD's frame)
        for case, steps, want, want_middle, same_frame in (
                ("one subindex at a time", expedited, after_expedited, middle_expedited, False),
                ("complete access", complete, after_complete, None, True),
                ("complete access of no bytes between", complete_empty, after_complete, None, True),
                ("an upload answered", upload, after_upload, None, False),
                ("odd traffic", odd, after_odd, None, False),
                ("no configuration", [], defaults, None, False)):
            frames, lrds = coe_frames(steps, before, after, middle, same_frame=same_frame)
            path = env.add_file("coe-%s.pcap" % case.replace(" ", "-"), pg.pcap_bytes(frames))
            results = []
            for two_pass in (False, True):
                rows = dict(decode(env, path, fields, two_pass))
                tag = " (-2)" if two_pass else ""
                got = [norm(rows[n]) for n in lrds]
                results.append(got)
                ok &= check(got[0] == defaults(before), "%s: the LRD before it shows the ESI defaults%s: %s" % (
                    case, tag, got[0]))
                if want_middle:
                    ok &= check(got[1] == want_middle(middle), "%s: an LRD before it is complete: %s, expected "
                                "%s%s" % (case, got[1], want_middle(middle), tag))
                ok &= check(got[-1] == want(after), "%s: the LRD after it%s: %s, expected %s%s" % (
                    case, " (in the frame that completes it)" if same_frame else "", got[-1], want(after), tag))
            check(results[0] == results[1], "%s: one pass and -2 agree" % case)
        # Random SDO transfers of the PDO objects (mostly download or upload command bytes, any
        # subindex, data and mailbox length), each followed by an LRD: tshark decodes every frame,
        # no dissector bug, and some of them show configured entries.
        rng = random.Random(12)
        steps = []
        for _ in range(300):
            index = rng.choice([0x1C12, 0x1C13, 0x1600, 0x1A00, 0x1A02, 0x1A13, 0x1BFF])
            cmd = rng.choice([0x2F, 0x2B, 0x23, 0x21, 0x31, 0x4F, 0x43, 0x41, 0x51, rng.randrange(256)])
            sdo = struct.pack("<BHB", cmd, index, rng.choice([0, 0, 1, 2, 64, 65, 255])) + \
                bytes(rng.randrange(256) for _ in range(rng.randrange(0, 40)))
            m = bytearray(coe_mailbox(rng.choice([2, 2, 3]), sdo))
            if rng.random() < 0.2:
                m[0:2] = struct.pack("<H", rng.randrange(0, 200))
            steps += [(bytes(m[:rng.choice([128, 128, 20, 15])]), 1), "lrd"]
        frames, lrds = coe_frames(steps, before, after, middle)
        path = env.add_file("coe-random.pcap", pg.pcap_bytes(frames))
        for args in (["-V"], ["-V", "-2"]):
            p = env.tshark(["-r", path] + args, check=False)
            check(p.returncode == 0 and "Dissector bug" not in p.stdout and "PDO entry: 0x" in p.stdout,
                  "300 random SDO transfers of PDO objects %s: decoded, no dissector bug, some entries "
                  "configured (exit %d)" % (" ".join(args), p.returncode))
    return ok


def coe_design_checks(check, dissgen, source_dir):
    """With a design (tests/network/small_design.xml, tests/esi_ok/small_io.xml): its EL1004 at
    position 1 ("Inputs left") assigned 0x1A10 (Counter, 0x6100:11, not assigned by default: no
    field) and 0x1A00 by complete access."""
    print("\n== process data as configured over CoE, with a design (generated frames)")
    ch = ["ecatr.pdo.el1004.channel_%d.input" % k for k in (1, 2, 3)]
    fields = ch + ["ecatr.pdo.entry", "ecatr.pdo.value"]
    before, after = bytes([0b101]) + bytes(23), bytes([0x34, 0x12, 0b1]) + bytes(21)
    steps = [(sdo_complete_access(0x1C13, [0x1A10, 0x1A00], 2), 1)]
    frames, lrds = coe_frames(steps, before, after, identity=(BECKHOFF, 0x03EC3052, 0x00130000))
    with TsharkEnv() as env:
        env.install_plugin(dissgen, os.path.join(source_dir, "rules", "ethercat.xml"),
                           ["--esi", os.path.join(source_dir, "tests", "esi_ok", "small_io.xml"),
                            "--network", os.path.join(source_dir, "tests", "network", "small_design.xml")])
        path = env.add_file("coe-design.pcap", pg.pcap_bytes(frames))
        for two_pass in (False, True):
            tag = " (-2)" if two_pass else ""
            rows = dict(decode(env, path, fields, two_pass))
            got = [{f: rows[n][f] for f in fields if rows[n][f]} for n in lrds]
            yes = lambda v: v in ("1", "True")  # noqa: E731
            check([yes(v) for f in ch for v in got[0].get(f, [])] == [True, False, True] and
                  not got[0].get("ecatr.pdo.entry"), "design: the LRD before it shows the defaults%s: %s" % (
                      tag, got[0]))
            check(got[1].get("ecatr.pdo.entry") == ["0x6100:11"] and got[1].get("ecatr.pdo.value") == [str(0x1234)]
                  and [yes(v) for v in got[1].get(ch[0], [])] == [True] and not got[1].get(ch[1]),
                  "design: the LRD after it shows 0x6100:11 = 0x1234 (generic) and channel 1 at bit 16%s: %s" % (
                      tag, got[1]))
            tree = env.tshark(["-r", path, "-V"] + (["-2"] if two_pass else [])).stdout
            check("0x6100:11 Counter (not assigned by default).Count (UINT, 16 bit)" in tree and
                  "Inputs left (position 1): inputs" in tree,
                  "design: the entry named from the ESI file, under the design's slave name%s" % tag)


SIGNED_IO = (BECKHOFF, 0x0C1E3052, 0x00100000)   # tests/esi_ok/signed_entries.xml


def signed(v, bits):
    return v - (1 << bits) if v >> (bits - 1) & 1 else v


def signed_inputs(data, bit=0):
    """signed_entries.xml's 0x1A00 from `bit`: Status (BIT3), then INT, SINT, DINT and LINT, each
    starting 3 bits past a byte boundary."""
    p = "ecatr.pdo.el3104.ai."
    return {p + "status": [bits_of(data, bit, 3)], p + "value": [signed(bits_of(data, bit + 3, 16), 16)],
            p + "small": [signed(bits_of(data, bit + 19, 8), 8)], p + "wide": [signed(bits_of(data, bit + 27, 32), 32)],
            p + "huge": [signed(bits_of(data, bit + 59, 64), 64)]}


def signed_entries_checks(check, dissgen, source_dir):
    """Signed entries off byte boundaries (tests/esi_ok/signed_entries.xml), each value against
    its bits; and a complete access from subindex 0 holding the count alone, which assigns the
    PDOs written one subindex at a time before it."""
    print("\n== signed entries off byte boundaries, and a complete access of the count alone")
    p = "ecatr.pdo.el3104.ai."
    fields = [p + f for f in ("status", "value", "small", "wide", "huge")] + ["ecatr.pdo.entry", "ecatr.pdo.value"]

    def place(bit, *parts):  # (value, width) pairs from `bit` on, as a slave's inputs
        v, at = 0, bit
        for value, width in parts:
            v |= (value & ((1 << width) - 1)) << at
            at += width
        return v.to_bytes(24, "little")

    extremes = place(0, (5, 3), (-2, 16), (-128, 8), (-2 ** 31, 32), (-2 ** 63 + 1, 64))
    positive = place(0, (2, 3), (0x7FFF, 16), (127, 8), (2 ** 31 - 1, 32), (2 ** 63 - 1, 64))
    rng = random.Random(9)
    noise = bytes(rng.randrange(256) for _ in range(24))

    def norm(row):
        return {f: [int(v, 0) if f != "ecatr.pdo.entry" else v for v in row[f]] for f in fields if row[f]}

    # (case, configuration steps, inputs of the LRD after them, expected)
    def count_alone(padded):   # a complete access of 0x1C13 from subindex 0 holding its count, 2
        data = b"\x02\x00" if padded else b"\x02"
        return coe_mailbox(2, struct.pack("<BHBI", 0x21 | 0x10, 0x1C13, 0, len(data)) + data)

    one_at_a_time = [(sdo_expedited(0x1C13, 0, 0, 1), 1), (sdo_expedited(0x1C13, 1, 0x1A01, 2), 1),
                     (sdo_expedited(0x1C13, 2, 0x1A00, 2), 1)]
    counter_first = {"ecatr.pdo.entry": ["0x6010:01"], "ecatr.pdo.value": [bits_of(noise, 0, 16)],
                     **signed_inputs(noise, 16)}
    cases = (
        ("the defaults, every value negative", [], extremes, signed_inputs(extremes)),
        ("the defaults, every value at its positive end", [], positive, signed_inputs(positive)),
        ("0x1C13's entries one at a time, then its count alone by complete access",
         one_at_a_time + [(count_alone(False), 1)], noise, counter_first),
        ("the same with the count padded to 16 bits", one_at_a_time + [(count_alone(True), 1)], noise,
         counter_first),
        ("0x1C13 by complete access of one entry", [(sdo_complete_access(0x1C13, [0x1A01], 2), 1)], noise,
         {"ecatr.pdo.entry": ["0x6010:01"], "ecatr.pdo.value": [bits_of(noise, 0, 16)]}),
        # An expedited download of 1 byte (its size bits say so; the next byte holds 0x1A) to
        # a 16-bit subindex: not a PDO index, not taken; the entries written before stay.
        ("a 16-bit subindex written with 1 byte",
         one_at_a_time[:2] + [(sdo_expedited(0x1C13, 2, 0x1A00, 2, declared=1), 1), (sdo_expedited(0x1C13, 0, 2, 1), 1)],
         noise, {"ecatr.pdo.entry": ["0x6010:01"], "ecatr.pdo.value": [bits_of(noise, 0, 16)]}),
    )
    with TsharkEnv() as env:
        env.install_plugin(dissgen, os.path.join(source_dir, "rules", "ethercat.xml"),
                           ["--esi", os.path.join(source_dir, "tests", "esi_ok", "signed_entries.xml")])
        for k, (case, steps, inputs, want) in enumerate(cases):
            frames, lrds = coe_frames(steps, noise, inputs, identity=SIGNED_IO)
            path = env.add_file("signed-%d.pcap" % k, pg.pcap_bytes(frames))
            for two_pass in (False, True):
                rows = dict(decode(env, path, fields, two_pass))
                got = norm(rows[lrds[-1]])
                check(got == want, "%s%s: %s" % (case, " (-2)" if two_pass else "",
                                                 "as the bits say" if got == want else "%s, expected %s" % (got, want)))


def twin(product, name):
    """An ESI device that assigns a 0x1A00 of its own: a neighbour of the EL3104 in the catalogue."""
    return """      <Device Physics="KK">
        <Type ProductCode="#x%08x" RevisionNo="#x00100000">%s</Type>
        <Name LcId="1033">%s</Name>
        <Sm DefaultSize="16" StartAddress="#x1100" ControlByte="#x20" Enable="1">Inputs</Sm>
        <TxPdo Fixed="1" Mandatory="1" Sm="0">
          <Index>#x1a00</Index>
          <Name>Twin</Name>
          <Entry><Index>#x6020</Index><SubIndex>1</SubIndex><BitLen>16</BitLen><Name>Twin</Name><DataType>UINT</DataType></Entry>
        </TxPdo>
      </Device>
""" % (product, name, name)


def neighbour_checks(check, dissgen, source_dir):
    """The EL3104 of tests/esi_ok/signed_entries.xml between two devices of its own 0x1A00 in
    one ESI file: configured over CoE without an assignment (a mapping of 0x1A01 only, which it
    does not assign), it keeps its own default PDOs, never a neighbour's."""
    print("\n== default PDOs of a configured slave between two other devices")
    with open(os.path.join(source_dir, "tests", "esi_ok", "signed_entries.xml"), encoding="utf-8") as f:
        esi = f.read()
    device = esi.index("      <Device ")
    esi = esi[:device] + twin(0x0C1E3051, "EL3103") + esi[device:]
    end = esi.index("    </Devices>")
    esi = esi[:end] + twin(0x0C1E3053, "EL3105") + esi[end:]
    rng = random.Random(4)
    noise = bytes(rng.randrange(256) for _ in range(24))
    fields = ["ecatr.pdo.el3104.ai." + f for f in ("status", "value", "small", "wide", "huge")] + \
        ["ecatr.pdo.entry", "ecatr.pdo.value"]
    steps = [(sdo_expedited(0x1A01, 0, 0, 1), 1), (sdo_expedited(0x1A01, 1, 0x60100110, 4), 1),
             (sdo_expedited(0x1A01, 0, 1, 1), 1),
             (sdo_expedited(0x8000, 1, 7, 2), 0)]   # a write the slave did not take (working counter 0)
    frames, lrds = coe_frames(steps, noise, noise, identity=SIGNED_IO)
    with TsharkEnv() as env:
        path = env.add_file("neighbours.xml", esi.encode())
        env.install_plugin(dissgen, os.path.join(source_dir, "rules", "ethercat.xml"), ["--esi", path])
        cap = env.add_file("neighbours.pcap", pg.pcap_bytes(frames))
        for two_pass in (False, True):
            rows = dict(decode(env, cap, fields, two_pass))
            got = {f: [int(v, 0) for v in rows[lrds[-1]][f]] for f in fields if rows[lrds[-1]][f]}
            check(got == signed_inputs(noise), "configured without an assignment, its own defaults only%s: %s" % (
                " (-2)" if two_pass else "", got))

        # -z ecatr,tree per slave, from the frames written: the slave at position 1 (station
        # 0x1002) is addressed by every datagram but the LRDs; four of them are mailbox writes,
        # and one (the refused write) came back with its working counter not raised.
        addressed = [d for f in frames[0::2] for d in f.datagrams if d.cmd != 10]
        want = {"Datagrams": len(addressed), "Working counter not raised": 1, "Mailbox datagrams": len(steps)}
        for two_pass in (False, True):
            got = slave_stats(env, cap, two_pass)
            check(got == {1: want}, "per-slave statistics from the frames%s: %s, expected %s" % (
                " (-2)" if two_pass else "", got, {1: want}))


def station_byte_checks(check, dissgen, source_dir):
    """A slave controller takes each byte written to a register: a master that sets the station
    address (0x0010) or reads the alias (0x0012) one byte at a time gives the slave the whole
    value, and a later write of one byte changes that byte only. The alias comes from the
    EEPROM: a write from the segment does not change it, and half of it read is not known."""
    print("\n== station address and alias a byte at a time")
    steps = [(pg.Datagram(2, adp=0, ado=0x0010, data=b"\x85"), None),           # position 0: low byte
             (pg.Datagram(2, adp=0, ado=0x0011, data=b"\x10"), None),           # high byte: 0x1085
             (pg.Datagram(2, adp=0xFFFF, ado=0x0010, data=b"\x01\xA0"), None),   # position 1: 0xA001
             (pg.Datagram(2, adp=0xFFFF, ado=0x0010, data=b"\x07"), None),       # its low byte: 0xA007
             (pg.Datagram(4, adp=0x1085, ado=0x0012, data=bytes(1)), b"\x34"),   # alias read, low byte
             (pg.Datagram(4, adp=0x1085, ado=0x0013, data=bytes(1)), b"\x12"),   # high byte: 0x1234
             (pg.Datagram(4, adp=0x1085, ado=0x0130, data=bytes(2)), None),
             (pg.Datagram(4, adp=0xA007, ado=0x0130, data=bytes(2)), None),
             (pg.Datagram(4, adp=0xA001, ado=0x0130, data=bytes(2)), None),      # no longer a station
             # re-addressed: position 2 takes 0x1085 from position 0, which then gets 0x3000
             (pg.Datagram(2, adp=0xFFFE, ado=0x0010, data=b"\x85\x10"), None),
             (pg.Datagram(2, adp=0, ado=0x0010, data=b"\x00\x30"), None),
             (pg.Datagram(4, adp=0x1085, ado=0x0130, data=bytes(2)), None),
             (pg.Datagram(4, adp=0x3000, ado=0x0130, data=bytes(2)), None),
             # position 3: a write to its alias (which the segment cannot change) and none to its
             # station: neither is known; then one byte of its alias read: still not known
             (pg.Datagram(2, adp=0xFFFD, ado=0x0012, data=b"\x78\x56"), None),
             (pg.Datagram(1, adp=0xFFFD, ado=0x0130, data=bytes(2)), None),
             (pg.Datagram(1, adp=0xFFFD, ado=0x0012, data=bytes(1)), b"\x9a"),
             (pg.Datagram(1, adp=0xFFFD, ado=0x0130, data=bytes(2)), None)]
    frames = exchanges([[(d, data, 1)] for d, data in steps])
    with TsharkEnv() as env:
        env.install_plugin(dissgen, os.path.join(source_dir, "rules", "ethercat.xml"))
        cap = env.add_file("station_bytes.pcap", pg.pcap_bytes(frames))
        fields = ["ecatr.slave.position", "ecatr.slave.station", "ecatr.slave.alias"]
        for two_pass in (False, True):
            rows = dict(decode(env, cap, fields, two_pass))
            got = {n: tuple(rows[n][f] for f in fields) for n in (14, 16, 18, 24, 26, 30, 34)}
            want = {14: (["0"], ["0x1085"], ["0x1234"]), 16: (["1"], ["0xa007"], []), 18: ([], [], []),
                    24: (["2"], ["0x1085"], []), 26: (["0"], ["0x3000"], ["0x1234"]), 30: (["3"], [], []),
                    34: (["3"], [], [])}
            check(got == want, "FPRDs to 0x1085, 0xa007, 0xa001 (no longer a station), then 0x1085 (given to "
                  "position 2) and 0x3000 (position 0's new address), and APRDs to position 3 (its alias written, then half read: neither known)%s: %s, expected %s" % (
                      " (-2)" if two_pass else "", got, want))


class TestBusModel(TsharkTestCase, unittest.TestCase):
    """cls.env: the plugin with the EK11xx and EL1xxx ESI files, the corpus captures in its HOME."""

    @classmethod
    def prepare(cls):
        cls.shared = os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus")
        cls.corpus = os.path.join(cls.shared, "ethercat")
        cls.files = corpus_captures(cls.corpus)
        cls.rules = os.path.join(ARGS.source_dir, "rules", "ethercat.xml")
        if cls.files:
            cls.env.install_plugin(ARGS.dissgen, cls.rules,
                                   ["--esi", os.path.join(cls.shared, "esi", "Beckhoff_EK11xx.xml"),
                                    "--esi", os.path.join(cls.shared, "esi", "Beckhoff_EL1xxx.xml")])
            cls.env.assert_plugin_loaded("ecatr")
            for f in cls.files:
                with open(os.path.join(cls.corpus, f), "rb") as fh:
                    cls.env.add_file(f, fh.read())

    def need_corpus(self):
        if not self.files:
            self.skipTest("no corpus at %s (no *.pcap/*.pcapng)" % self.corpus)

    def test_slave_identities_as_the_corpus_lists_them(self):
        """Part 1."""
        self.need_corpus()
        with self.checks() as check:
            identity_checks(check, self.env, self.env.home, self.files)
            names_checks(check, self.env, self.env.home)
            rows = decode(self.env, os.path.join(self.env.home, "soem-sdinfo-ek1100-el1004.pcapng"), EXPERTS, True)
            check(not any(any(r.values()) for _n, r in rows), "no network experts without a design")

    def test_one_line_per_slave_details_filterable(self):
        """-V names a datagram's slave on one line ("Slave 1: EL1004, station 0x1002"); its fields
        are printed under it only with the preference, and filterable either way."""
        self.need_corpus()
        path = os.path.join(self.env.home, "soem-sdinfo-ek1100-el1004.pcapng")
        with self.checks() as check:
            for prefs in ([], ["-o", "ecatr.show_details:TRUE"]):
                text = self.env.tshark(["-r", path, "-2", "-V", "-Y", "frame.number == 97"] + prefs).stdout
                check("[Slave 1: EL1004, station 0x1002]" in text, "%s: the slave on one line" % (prefs or "default"))
                check(("[Position: 1]" in text and "[Product code: 0x03ec3052]" in text) == bool(prefs),
                      "%s: its fields %s" % (prefs or "default", "printed" if prefs else "not printed"))
            rows = self.env.field_rows(path, ["frame.number"], two_pass=True,
                                       display_filter='ecatr.slave.name == "EL1004" && ecatr.slave.station == 0x1002')
            check(97 in rows, "a filter on the slave's fields finds frame 97 (%d frames)" % len(rows))

    def test_network_check_against_four_designs(self):
        """Part 2."""
        self.need_corpus()
        with self.checks() as check:
            network_checks(check, ARGS.dissgen, self.rules, self.corpus)

    def test_expected_working_counters(self):
        """Part 3."""
        self.need_corpus()
        with self.checks() as check:
            wkc_checks(check, self.env, self.env.home, self.files)

    def test_per_slave_statistics(self):
        """Part 4."""
        self.need_corpus()
        with self.checks() as check:
            stats_checks(check, self.env, self.env.home)

    def test_eni_cyclic_commands_expected_wkc(self):
        """Part 5."""
        self.need_corpus()
        with self.checks() as check:
            eni_checks(check, ARGS.dissgen, self.rules, self.shared)

    def test_process_data_by_name(self):
        """Part 6 (generated frames)."""
        with self.checks() as check:
            pdo_checks(check, ARGS.dissgen, ARGS.source_dir)
            pdo_checks(check, ARGS.dissgen, ARGS.source_dir, design=False)

    def test_process_data_as_mapped_over_coe_with_a_design(self):
        """Part 7 (generated frames), with tests/network/small_design.xml."""
        with self.checks() as check:
            coe_design_checks(check, ARGS.dissgen, ARGS.source_dir)

    def test_signed_entries_and_a_count_alone(self):
        """Part 7 (generated frames), with tests/esi_ok/signed_entries.xml."""
        with self.checks() as check:
            signed_entries_checks(check, ARGS.dissgen, ARGS.source_dir)

    def test_default_pdos_of_a_configured_slave_are_its_own(self):
        """Part 7 (generated frames), signed_entries.xml's EL3104 between two other devices."""
        with self.checks() as check:
            neighbour_checks(check, ARGS.dissgen, ARGS.source_dir)

    def test_station_address_and_alias_a_byte_at_a_time(self):
        """Generated frames, no ESI."""
        with self.checks() as check:
            station_byte_checks(check, ARGS.dissgen, ARGS.source_dir)

    def test_process_data_as_mapped_over_coe_on_an_el1252(self):
        """Part 7 (generated frames), the EL1252 of the corpus's Beckhoff_EL1xxx.xml."""
        esi = os.path.join(self.shared, "esi", "Beckhoff_EL1xxx.xml")
        if not os.path.isfile(esi):
            self.skipTest("no %s" % esi)
        with self.checks() as check:
            coe_checks(check, ARGS.dissgen, ARGS.source_dir, self.shared)


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

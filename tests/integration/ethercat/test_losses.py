#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Lost frames found exactly, and nothing else said about them.

  test_losses.py --dissgen build/bin/dissgen --source-dir . [--corpus DIR]

Returned frames are deleted from copies of captures: with returns marked by the slaves (the
locally administered bit of the master's source address) and with the marks removed (as a
simulator or some taps leave them). For each copy, against the same copy with nothing
deleted:

- with -2, ecatr.expert.no_response sits on exactly the requests whose return was deleted
  (plus those the copy already had), and no other expert info appears or disappears except
  the ones that were on the deleted frames;
- in one pass, the requests named by ecatr.no_response_to (the frame that proves the loss:
  the index reused, or the timeout passed) are exactly the same set, each proving frame carries
  ecatr.expert.no_response, and again nothing else changes;
- no field shows an impossible value (a negative working counter, round trip or count).

Then the first frames of each capture are cut, so that returns lose their requests: they are
orphans (no no_response, a row in -z ecatr,tree) and nothing is flagged that the uncut capture
did not flag.

Without --corpus (or when it is absent), generated captures only: cyclic process data with
the datagram index reused every cycle, and mailbox polling with several frames in flight;
the corpus test is reported skipped. The corpus alone:
  test_losses.py --dissgen build/bin/dissgen --source-dir . --with-corpus TestLosses.test_corpus_losses_found_exactly
"""

import os
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, corpus_captures, run_unittests  # noqa: E402
import pcaprewrite as pr  # noqa: E402

ARGS = None
MASTER = bytes.fromhex("00a0de000001")


# ----------------------------------------------------------------------------- generated captures

def ecat_frame(src, datagrams):
    """An Ethernet frame with EtherCAT datagrams [(cmd, idx, adp, ado, data, wkc)]."""
    body = b""
    for k, (cmd, idx, adp, ado, data, wkc) in enumerate(datagrams):
        more = 0x8000 if k < len(datagrams) - 1 else 0
        body += struct.pack("<BBHHHH", cmd, idx, adp, ado, len(data) | more, 0) + data + struct.pack("<H", wkc)
    frame = b"\xff" * 6 + src + b"\x88\xa4" + struct.pack("<H", len(body) | 0x1000) + body
    return frame + b"\x00" * max(0, 60 - len(frame))


def returned(src, datagrams, added):
    """The frame as it comes back: the mark on the source, working counters added."""
    back = bytes([src[0] | 0x02]) + src[1:]
    return ecat_frame(back, [(c, i, a, o, d, w + added) for c, i, a, o, d, w in datagrams])


def cyclic_capture(cycles=400):
    """LRW of the process image and FRMW of the reference clock every millisecond, one frame,
    the same index every cycle; back after 60 us."""
    packets, t = [], 1_700_000_000 * 10**9
    for n in range(cycles):
        out = bytes([n & 0xFF, (n >> 8) & 0xFF, 0, 0])
        dgs = [(12, 0x21, 0x0000, 0x0001, out, 0), (14, 0x21, 0x1001, 0x0910, b"\0" * 8, 0)]
        packets.append(pr.Packet(ecat_frame(MASTER, dgs), t + n * 1_000_000))
        packets.append(pr.Packet(returned(MASTER, dgs, 3), t + n * 1_000_000 + 60_000))
    return packets


def status_capture(cycles=400):
    """A BRD of the AL status every millisecond, sent with the very same bytes every cycle
    (one index, nothing the master sends changes): a cycle whose return was lost must not
    make the next request look like a copy of the previous one."""
    packets, t = [], 1_700_000_000 * 10**9
    for n in range(cycles):
        dgs = [(7, 0x05, 0x0000, 0x0130, b"\0\0", 0)]
        packets.append(pr.Packet(ecat_frame(MASTER, dgs), t + n * 1_000_000))
        packets.append(pr.Packet(returned(MASTER, dgs, 2), t + n * 1_000_000 + 60_000))
    return packets


def mailbox_capture(rounds=300):
    """Mailbox polling of three stations, two frames in flight at a time, indexes 0..15 in turn."""
    packets, t, idx = [], 1_700_000_000 * 10**9, 0
    for n in range(rounds):
        base = t + n * 500_000
        dgs = []
        for k in range(2):
            station = 0x1001 + (n * 2 + k) % 3
            dgs.append([(4, idx, station, 0x080D, b"\0", 0)])
            idx = (idx + 1) % 16
        packets.append(pr.Packet(ecat_frame(MASTER, dgs[0]), base))
        packets.append(pr.Packet(ecat_frame(MASTER, dgs[1]), base + 20_000))
        packets.append(pr.Packet(returned(MASTER, dgs[0], 1), base + 90_000))
        packets.append(pr.Packet(returned(MASTER, dgs[1], 1), base + 110_000))
    return packets


def generated(path, packets):
    """A classic pcap file of the packets (nanosecond timestamps)."""
    out = [struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 1)]
    for p in packets:
        out.append(struct.pack("<IIII", p.ts // 10**9, p.ts % 10**9, len(p.data), len(p.data)) + bytes(p.data))
    with open(path, "wb") as fh:
        fh.write(b"".join(out))


# ----------------------------------------------------------------------------- reading the bytes

def marked_pairs(cap):
    """{return index: request index}: a frame from the master's address with the mark set
    answers the latest frame from the master with the same commands, indexes and lengths."""
    pairs, waiting, masters = {}, {}, set()
    for i, p in enumerate(cap.packets):
        if pr.ecat_offset(p) != 14:
            continue
        src = bytes(p.data[6:12])
        key = tuple((d["cmd"], d["idx"], d["length"]) for d in pr.ecat_datagrams(p))
        if not key:
            continue
        if src[0] & 0x02 and bytes([src[0] & ~0x02]) + src[1:] in masters:
            j = waiting.pop((bytes([src[0] & ~0x02]) + src[1:], key), None)
            if j is not None:
                pairs[i] = j
        elif not src[0] & 0x02:
            masters.add(src)
            waiting[(src, key)] = i
    return pairs


def unmark(cap, returns):
    for i in returns:
        cap.packets[i].data[6] &= ~0x02


# ----------------------------------------------------------------------------- decoding

class Decoder:
    def __init__(self, env):
        self.env = env
        fields = env.tshark(["-G", "fields"]).stdout
        self.experts = sorted({line.split("\t")[2] for line in fields.splitlines()
                               if line.count("\t") >= 2 and line.split("\t")[2].startswith("ecatr.expert.")})
        self.values = ["ecatr.datagram.wkc", "ecatr.time", "ecatr.esc.slaves_passed", "ecatr.datagram.len"]
        self.count = 0
        self.cache = {}

    def run(self, cap, two_pass):
        """{tag: {"experts": [names], "lost": {tags named}, "negative": [fields]}} per EtherCAT frame
        (the unchanged captures' once each)."""
        key = (id(cap), two_pass)
        if getattr(cap, "unchanged", False) and key in self.cache:
            return self.cache[key]
        rows = self._run(cap, two_pass)
        if getattr(cap, "unchanged", False):
            self.cache[key] = rows
        return rows

    def _run(self, cap, two_pass):
        self.count += 1
        path = self.env.path("copy%d.%s" % (self.count, cap.kind))
        cap.write(path)
        os.chmod(path, 0o644)
        fields = ["frame.number", "ecatr.no_response_to", "ecatr.no_request"] + self.values + self.experts
        tag_of = {n + 1: p.tag for n, p in enumerate(cap.packets)}
        rows = {}
        for n, r in self.env.field_rows(path, fields, two_pass=two_pass, display_filter="ecatr").items():
            row = {"experts": [], "negative": []}
            row["lost"] = {tag_of[int(x)] for x in r["ecatr.no_response_to"] if x}
            row["no_request"] = bool(r["ecatr.no_request"])
            row["negative"] = [f for f in self.values if any(v.startswith("-") for v in r[f])]
            for f in self.experts:
                row["experts"] += [f] * len(r[f])
            rows[tag_of[n]] = row
        os.unlink(path)
        return rows


def flagged(rows, name="ecatr.expert.no_response"):
    return {t for t, r in rows.items() if name in r["experts"]}


def named(rows):
    return set().union(*(r["lost"] for r in rows.values())) if rows else set()


def other_experts(rows, skip=()):
    """(tag, expert) of every expert info except no_response, frames in `skip` left out."""
    out = set()
    for t, r in rows.items():
        if t in skip:
            continue
        for k, e in enumerate(sorted(r["experts"])):
            if e != "ecatr.expert.no_response":
                out.add((t, e, k))
    return out


def impossible(rows):
    return sorted((t, f) for t, r in rows.items() for f in r["negative"])


# ----------------------------------------------------------------------------- checks

def victims_of(pairs, k):
    """k returns spread over the capture, not among its last three pairs (a return missing at
    the very end may simply not have been captured yet)."""
    order = sorted(pairs)[:-3]
    if len(order) < k:
        return []
    return [order[(2 * n + 1) * len(order) // (2 * k)] for n in range(k)]


TIMEOUT = 0.1          # rules/ethercat.xml's <pairing timeout>
MAX_OVERTAKEN = 16     # later requests answered before an earlier one is given up


def provable(cap, pairs, lost):
    """Of the requests (tags) in `lost`, those a later frame of `cap` proves lost in one pass:
    their datagram indexes sent again, more than MAX_OVERTAKEN later requests answered, or two
    later EtherCAT frames past the timeout."""
    answered = {pairs[i] for i in pairs} - lost
    frames = []
    for p in cap.packets:
        if pr.ecat_offset(p) is None:
            continue
        key = tuple(d["idx"] for d in pr.ecat_datagrams(p))
        frames.append((p.tag, cap.seconds(p), key))
    out = set()
    for k, (tag, t, key) in enumerate(frames):
        if tag not in lost:
            continue
        later = frames[k + 1:]
        again = any(kk == key and tg not in pairs for tg, _t, kk in later)
        overtaken = sum(1 for tg, _t, _k in later if tg in answered) > MAX_OVERTAKEN
        expired = sum(1 for _tg, tt, _k in later if tt - t > TIMEOUT) >= 2
        if again or overtaken or expired:
            out.add(tag)
    return out


def deletion_checks(check, dec, name, base, pairs, k, summary):
    victims = victims_of(pairs, k)
    if not victims:
        print("(%s: too few pairs to delete %d returns)" % (name, k))
        return
    lost = {base.packets[pairs[v]].tag for v in victims}
    gone = {base.packets[v].tag for v in victims}
    copy = clone(base)
    copy.packets = [p for i, p in enumerate(copy.packets) if i not in set(victims)]
    for two_pass in (True, False):
        mode = "-2" if two_pass else "one pass"
        before = dec.run(base, two_pass)
        after = dec.run(copy, two_pass)
        if two_pass:
            got, had = flagged(after), flagged(before)
            missing, wrong = sorted(lost - got), sorted(got - lost - had)
            unexpected_links = sorted(named(after) - named(before) - lost)
        else:
            got, had = named(after), named(before)
            # One pass can only report what a later frame proves (provable()); the rest is
            # reported with -2 (checked above), at the capture's end.
            missing, wrong = sorted((lost - got) & provable(copy, pairs, lost)), sorted(got - lost - had)
            late = sorted(lost - got - provable(copy, pairs, lost))
            if late:
                print("(%s, one pass: %s proved lost only by the capture's end)" % (name, late))
            unlinked = sorted(t for t in flagged(after) if not after[t]["lost"])
            check(not unlinked, "%s, %s: every no_response names the lost frame (%s)" % (name, mode, unlinked[:5]))
            unexpected_links = []
        new = sorted(other_experts(after) - other_experts(before, gone))
        dropped = sorted(other_experts(before, gone) - other_experts(after))
        summary.append((name, mode, len(lost), len(lost) - len(missing), len(wrong), len(new)))
        check(not missing and not wrong and not unexpected_links,
              "%s, %s: %d returns deleted, exactly their requests flagged lost (missing %s, wrong %s%s)" % (
                  name, mode, len(lost), missing[:5], wrong[:5],
                  ", links %s" % unexpected_links[:5] if unexpected_links else ""))
        check(not new and not dropped, "%s, %s: no other expert info appears or disappears (new %s, gone %s)" % (
            name, mode, new[:5], dropped[:5]))
        check(not impossible(after), "%s, %s: no negative value in any field (%s)" % (
            name, mode, impossible(after)[:5]))


def orphan_checks(check, env, dec, name, base, pairs):
    """The capture cut between a request and its return, several times over: the returns
    whose request is gone are orphans, nothing is flagged lost that was not before."""
    order = sorted(pairs)
    if len(order) < 10:
        return
    for at in (order[1], order[len(order) // 2]):
        start = pairs[at]  # the request of `at` is cut away, its return kept
        copy = clone(base)
        copy.packets = copy.packets[start + 1:]
        for two_pass in (True, False):
            mode = "-2" if two_pass else "one pass"
            before = {t: r for t, r in dec.run(base, two_pass).items() if t > base.packets[start].tag}
            after = dec.run(copy, two_pass)
            orphan = base.packets[at].tag
            check(orphan not in flagged(after) and not after.get(orphan, {}).get("lost"),
                  "%s, cut before frame %d, %s: its return %d (request not captured) is not flagged" % (
                      name, start + 2, mode, orphan + 1))
            extra = sorted((flagged(after) | named(after)) - (flagged(before) | named(before)))
            check(not extra, "%s, cut before frame %d, %s: nothing flagged lost that was not before (%s)" % (
                name, start + 2, mode, extra[:5]))
            new = sorted(e for e in other_experts(after) - other_experts(before) if not e[1].startswith(
                "ecatr.expert.network") and e[1] != "ecatr.expert.wkc")
            check(not new, "%s, cut before frame %d, %s: no new pairing or ESC expert info (%s)" % (
                name, start + 2, mode, new[:5]))
        path = env.path("cut." + copy.kind)
        copy.write(path)
        os.chmod(path, 0o644)
        # (-2: in one pass a return that nobody processed, at the start of a capture whose
        # marking is not known yet, is taken for a request until the marking shows.)
        tree = env.tshark(["-r", path, "-2", "-q", "-z", "ecatr,tree"]).stdout
        label = "Responses to requests not captured"
        row = [line for line in tree.splitlines() if line.strip().startswith(label)]
        count = int(row[0].strip()[len(label):].split()[0]) if row else 0
        check(count >= 1, "%s, cut before frame %d: -z ecatr,tree counts the orphan return (%s)" % (
            name, start + 2, row[0].strip() if row else "no row"))
        os.unlink(path)


def foreign_return_checks(check, dec, name, base, pairs):
    """Another station's return (marked, working counter 1, an index and an address the
    capture does not use) right after a request in the middle of the capture, while that
    request waits: an orphan (ecatr.no_request), paired with nothing, nothing else changed."""
    order = sorted(pairs)
    if len(order) < 10:
        return
    request = pairs[order[len(order) // 2]]
    used = {d["idx"] for p in base.packets for d in pr.ecat_datagrams(p)}
    free = next((i for i in range(255, -1, -1) if i not in used), None)
    if free is None:
        return
    sent = base.packets[request]
    src = bytes(sent.data[6:12])
    frame = ecat_frame(bytes([src[0] | 0x02]) + src[1:], [(4, free, 0x7777, 0x0999, b"\0\0", 1)])
    foreign = pr.Packet(frame, sent.ts + 1, sent.ifid, tag=len(base.packets))
    copy = clone(base)
    copy.packets.insert(request + 1, foreign)
    for two_pass in (True, False):
        mode = "-2" if two_pass else "one pass"
        before, after = dec.run(base, two_pass), dec.run(copy, two_pass)
        orphan = after.get(foreign.tag, {})
        check(orphan.get("no_request") and not orphan.get("experts") and not orphan.get("lost"),
              "%s, %s: another station's return after frame %d is an orphan, nothing raised on it (%s)" % (
                  name, mode, request + 1, orphan))
        new = sorted(other_experts({t: r for t, r in after.items() if t != foreign.tag}) - other_experts(before))
        lost = sorted((flagged(after) | named(after)) - (flagged(before) | named(before)))
        check(not new and not lost, "%s, %s: nothing else changes (new %s, lost %s)" % (name, mode, new[:5], lost))


def clone(cap):
    copy = pr.Capture(cap.kind, cap.endian, cap.header, list(cap.blocks) if cap.blocks else cap.blocks)
    copy.units = dict(cap.units)
    copy.nano = getattr(cap, "nano", False)
    copy.packets = [p.copy() for p in cap.packets]
    return copy


def tagged(packets):
    for i, p in enumerate(packets):
        p.tag = i
    return packets


def run_capture(check, env, dec, name, cap, summary, k=10):
    pairs = marked_pairs(cap)
    cap.unchanged = True
    print("\n== %s: %d frames, %d pairs" % (name, len(cap.packets), len(pairs)))
    deletion_checks(check, dec, name + " (marked)", cap, pairs, k, summary)
    plain = clone(cap)
    unmark(plain, pairs)
    plain.unchanged = True
    deletion_checks(check, dec, name + " (unmarked)", plain, pairs, k, summary)
    orphan_checks(check, env, dec, name, cap, pairs)
    foreign_return_checks(check, dec, name, cap, pairs)


GENERATED = {"cyclic": ("generated cyclic LRW+FRMW", cyclic_capture),
             "status": ("generated status polling, the same bytes every cycle", status_capture),
             "mailbox": ("generated mailbox polling, two in flight", mailbox_capture)}


class TestLosses(TsharkTestCase, unittest.TestCase):
    @classmethod
    def prepare(cls):
        if ARGS.with_corpus and not ARGS.corpus:
            ARGS.corpus = os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus", "ethercat")
        cls.install(os.path.join("rules", "ethercat.xml"), "ecatr")
        cls.dec = Decoder(cls.env)
        cls.summary = []

    @classmethod
    def tearDownClass(cls):
        print("\n%-58s %-9s %5s %5s %6s %10s" % ("capture", "mode", "lost", "found", "wrong", "other new"))
        for row in cls.summary:
            print("%-58s %-9s %5d %5d %6d %10d" % row)
        super().tearDownClass()

    def generated(self, kind):
        name, packets = GENERATED[kind]
        path = self.env.path(name.split()[1] + ".pcap")
        generated(path, packets())
        cap = pr.Capture.read(path)
        tagged(cap.packets)
        with self.checks() as check:
            run_capture(check, self.env, self.dec, name, cap, self.summary)

    def test_cyclic_process_data_losses_found_exactly(self):
        self.generated("cyclic")

    def test_status_polling_with_the_same_bytes_losses_found_exactly(self):
        self.generated("status")

    def test_mailbox_polling_two_in_flight_losses_found_exactly(self):
        self.generated("mailbox")

    def test_corpus_losses_found_exactly(self):
        if not ARGS.corpus:
            self.skipTest("no --corpus (or --with-corpus) given: generated captures only")
        if not os.path.isdir(ARGS.corpus):
            self.skipTest("no corpus at %s" % ARGS.corpus)
        with self.checks() as check:
            for f in corpus_captures(ARGS.corpus):
                cap = pr.Capture.read(os.path.join(ARGS.corpus, f))
                tagged(cap.packets)
                run_capture(check, self.env, self.dec, f, cap, self.summary)


def add_arguments(parser):
    parser.add_argument("--corpus", help="../shared/corpus/ethercat: its captures too")
    parser.add_argument("--with-corpus", action="store_true", help="--corpus at its place beside the source tree")


if __name__ == "__main__":
    sys.exit(run_unittests(add_arguments)[1])

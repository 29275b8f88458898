#!/usr/bin/env python3
"""Out and back: EtherCAT frames paired with their returns, on the real captures
of ../shared/corpus/ethercat and on copies of them with faults injected.

  test_pairing.py --dissgen build/bin/dissgen --source-dir . [--corpus DIR] [--quick]

--quick (the mutation check's way to run it): part 1 and 2 on the captures below 1 MB only
(all but twincat-akd-nc-mode), part 3 on soem-sdinfo-ek1100-el1004 only. That does not
kill the mutant "forwarding never raised" (soem has no frame with two auto-increment
datagrams): it names the whole test instead (pairing_full in tests/mutation/run_mutants.py).

1. Every capture of the corpus, read with tshark -2: each returned frame that an independent
   reading of the bytes pairs with its sent frame (the slaves set the locally administered
   bit of the master's source MAC; same datagram commands, indexes and lengths; the latest
   unanswered sent frame, at most 10 ms before) carries ecatr.request_in of that frame, and
   the sent frame ecatr.response_in. Counts are printed per file. No expert info of the
   pairing or of the ESC analysis appears on any of them, except "no response" on sent frames
   that the bytes show never came back (and that only with -2: one pass cannot know it).
2. One pass and two passes (-2) give the same items on returned frames, and a display filter
   gives the same items on the frames it keeps.
3. Faults injected into copies (pcaprewrite.py): returned frames deleted, a working counter
   that came back lower than sent, an address, a length, an index changed, written data
   altered, an auto-increment address advanced differently, frames reordered or duplicated,
   a sent frame sent again at once with other bytes (not a duplicate), a return whose frame
   as sent is missing captured twice (its copy is a duplicate).
4. Variants of the same captures (unfaulted): the returned frames on a second interface of the
   pcapng, and returned frames not marked (a simulator's): the same pairs and expert infos.
   Each expert info appears on exactly the frames changed and nowhere else, with -2 and
   (for the returned-frame experts) in one pass.
5. Keys never used again (generated frames, every one with indexes of its own, a few answered
   40 ms later after 40 other requests): the answered ones are paired, and tshark's peak memory
   grows by less than 25 MB from 8 000 to 32 000 frames of 700 bytes (the first pass forgets
   keys and unanswered requests ten timeouts old: 16 MB measured; when it kept them, 49 MB).
   The same with one sent frame stamped an hour ahead, between a request and its answer, and
   with a real gap of an hour in the middle: every answer is still paired (forgetting goes by
   a clock that one odd timestamp does not move).
6. Orphan returns (generated frames): a return whose request was not captured, arriving while
   several requests wait (and while none does), answers none of them: it carries no
   ecatr.request_in, each waiting request is paired with its own return, and no expert info
   is raised; one pass and -2.

Parts 5 and 6 need no corpus; without it they run and pass all the same, and the tests of
parts 1 to 4 are reported skipped ("no corpus at ..."). One part alone:
test_pairing.py --dissgen ... --source-dir . TestPairing.test_orphan_returns_answer_no_waiting_request
"""

import os
import struct
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, corpus_captures, run_unittests  # noqa: E402
import pcapgen  # noqa: E402
import pcaprewrite as pr  # noqa: E402

EXPERTS = ["no_response", "duplicate", "out_of_order", "changed", "frame_length", "write_changed",
           "wkc_down", "forwarding"]
# Shown on the returned frame, so known in one pass already.
RESPONSE_FIELDS = ["ecatr.request_in", "ecatr.time", "ecatr.esc.wkc_added", "ecatr.esc.slaves_passed",
                   "ecatr.esc.data_changed"] + ["ecatr.expert." + e for e in EXPERTS if e != "no_response"]
FIELDS = ["frame.number", "ecatr.response_in", "ecatr.expert.no_response", "ecatr.no_response_to"] + RESPONSE_FIELDS
WRITES = {2, 5, 8, 11}            # APWR FPWR BWR LWR
READS = {1, 4, 7, 10}             # APRD FPRD BRD LRD
ADVANCING = {1, 2, 3, 7, 8, 9, 13}  # auto-increment and broadcast commands
ARGS = None


def decode(env, path, two_pass=True, display_filter=None):
    """{frame number: {field: its values, comma-separated}} for every frame."""
    rows = env.field_rows(path, FIELDS, two_pass=two_pass, display_filter=display_filter)
    return {n: {f: ",".join(v) for f, v in r.items()} for n, r in rows.items()}


def with_expert(rows, name):
    return {n for n, r in rows.items() if r["ecatr.expert." + name]}


# ----------------------------------------------------------------------------- the bytes' view

def frame_info(pkt):
    """(source MAC, key) of an EtherCAT frame on Ethernet, or None."""
    if pr.ecat_offset(pkt) is None:
        return None
    dgs = pr.ecat_datagrams(pkt)
    return bytes(pkt.data[6:12]), tuple((d["cmd"], d["idx"], d["length"]) for d in dgs)


def oracle(cap):
    """Pairs {returned index: sent index} and the sent indexes, from the bytes alone: a frame
    from a master's address with the locally administered bit set is a return; any other
    EtherCAT frame was sent."""
    frames = [(i, frame_info(p)) for i, p in enumerate(cap.packets)]
    frames = [(i, info) for i, info in frames if info]
    masters = {src for i, (src, _key) in frames if not src[0] & 0x02 and pr.ecat_offset(cap.packets[i]) == 14}
    marked = {bytes([m[0] | 0x02]) + m[1:]: m for m in masters}
    pairs, sent, waiting = {}, [], {}
    returned = 0
    for i, (src, key) in frames:
        returned += src in marked
        if src not in marked:
            sent.append(i)
            waiting[(src, key)] = i
            continue
        j = waiting.get((marked[src], key))
        if j is not None and cap.seconds(cap.packets[i]) - cap.seconds(cap.packets[j]) <= 0.010:
            pairs[i] = j
            del waiting[(marked[src], key)]
    return pairs, sent, returned


# ----------------------------------------------------------------------------- corpus

def corpus_checks(check, env, corpus_dir, files):
    print("\n== real captures: pairs per file (tshark -2)")
    print("%-40s %7s %7s %7s %7s %7s" % ("file", "sent", "back", "paired", "bytes", "lost"))
    print("(sent/back: frames from the master / returned, by their source address; paired: by the plugin;\n"
          " bytes: pairs the bytes show within 10 ms; lost: ecatr.expert.no_response)")
    for name in files:
        path = os.path.join(corpus_dir, name)
        cap = pr.Capture.read(path)
        pairs, sent, returned = oracle(cap)
        rows = decode(env, path)
        ours = {n - 1: int(r["ecatr.request_in"]) - 1 for n, r in rows.items() if r["ecatr.request_in"]}
        lost = with_expert(rows, "no_response")
        print("%-40s %7d %7d %7d %7d %7d" % (name, len(sent), returned, len(ours), len(pairs), len(lost)))
        missing = [(i + 1, j + 1) for i, j in pairs.items() if ours.get(i) != j]
        check(not missing, "%s: every frame the bytes pair is paired the same way (%d pairs%s)" % (
            name, len(pairs), ", wrong: %s" % missing[:5] if missing else ""))
        back_links = [j + 1 for i, j in pairs.items() if rows[j + 1]["ecatr.response_in"] != str(i + 1)]
        check(not back_links, "%s: each of those sent frames links to its return (ecatr.response_in)%s" % (
            name, ": not %s" % back_links[:5] if back_links else ""))
        for e in EXPERTS:
            got = with_expert(rows, e)
            if e == "no_response":
                answered = {j + 1 for j in pairs.values()}
                bad = sorted(n for n in got if n in answered or n - 1 not in sent)
                check(not bad, "%s: no_response only on sent frames that never came back (%d)%s" % (
                    name, len(got), ": %s" % bad[:5] if bad else ""))
            else:
                check(not got, "%s: no ecatr.expert.%s (%s)" % (name, e, sorted(got)[:5]))
        one = decode(env, path, two_pass=False)
        diff = [n for n in rows if any(rows[n][f] != one[n][f] for f in RESPONSE_FIELDS)]
        check(not diff, "%s: one pass shows the same items on returned frames as -2%s" % (
            name, ": %s" % diff[:5] if diff else ""))
        early = sorted(with_expert(one, "no_response"))
        unlinked = [n for n in early if not one[n]["ecatr.no_response_to"]]
        named = {int(x) for r in one.values() for x in r["ecatr.no_response_to"].split(",") if x}
        named2 = {int(x) for r in rows.values() for x in r["ecatr.no_response_to"].split(",") if x}
        check(not unlinked, "%s: one pass raises ecatr.expert.no_response only on frames that name the lost "
              "request (ecatr.no_response_to): %d%s" % (name, len(early), ": not %s" % unlinked[:5] if unlinked else ""))
        check(named <= lost and named == named2, "%s: the requests one pass names as lost (%d) are among those "
              "-2 flags (%d), and -2 names the same%s" % (name, len(named), len(lost),
                                                      ": %s" % sorted(named ^ named2 | (named - lost))[:5]
                                                      if not (named <= lost and named == named2) else ""))
        stats_checks(check, env, path, name, rows)
        filtered = decode(env, path, display_filter="ecatr.request_in || ecatr.expert.no_response")
        diff = [n for n in filtered if filtered[n] != rows[n]]
        check(filtered and not diff, "%s: a display filter keeps the same items (%d frames)%s" % (
            name, len(filtered), ": %s" % diff[:5] if diff else ""))


def stats_tree(env, path, two_pass):
    """{item: [count, average, min, max]} of the "Requests and responses" part of -z ecatr,tree."""
    args = ["-r", path, "-q", "-z", "ecatr,tree"] + (["-2"] if two_pass else [])
    items, inside = {}, False
    for line in env.tshark(args).stdout.splitlines():
        if line.startswith("Requests and responses"):
            inside = True
            continue
        if inside and not line.startswith(" "):
            break
        if inside and line.startswith(" ") and not line.startswith("  "):
            # (columns are as wide as the longest label: split at the gap after it)
            label, _, rest = line.strip().partition("  ")
            cols = rest.split()
            items[label] = cols
    return items


def stats_checks(check, env, path, name, rows):
    """The "Requests and responses" rows against the fields and expert infos of the same pass:
    responses and lost requests counted alike, every answered or lost request among the
    requests (a request still in flight when the capture ends is neither)."""
    times = [float(r["ecatr.time"]) * 1000 for r in rows.values() if r["ecatr.time"]]
    for two_pass in (False, True):
        same_pass = rows if two_pass else decode(env, path, two_pass=False)
        answered = sum(1 for r in rows.values() if r["ecatr.response_in"])
        responses = sum(1 for r in same_pass.values() if r["ecatr.request_in"])
        lost = len(with_expert(same_pass, "no_response"))
        lost_2 = len(with_expert(rows, "no_response"))
        requests = answered + lost_2
        st = stats_tree(env, path, two_pass)
        # (a row appears with its first count: none for what never happened)
        count = lambda row: int(st[row][0]) if row in st else 0  # noqa: E731
        got = (count("Requests"), count("Responses"), count("No response"))
        ok = got[0] >= requests and got[1:] == (responses, lost)
        if times:
            count, avg, low, high = st["Round trip (ms)"][:4]
            ok = ok and int(count) == len(times) and abs(float(low) - min(times)) < 0.001 and \
                abs(float(high) - max(times)) < 0.001 and abs(float(avg) - sum(times) / len(times)) < 0.01
        check(ok, "%s: -z ecatr,tree%s: sent %d, returned %d, lost %d, round trip min/avg/max %s (tree: %s)" % (
            name, " -2" if two_pass else "", requests, responses, lost,
            "%.3f/%.3f/%.3f ms" % (min(times), sum(times) / len(times), max(times)) if times else "-",
            {k: v[:4] for k, v in st.items() if k in ("Requests", "Responses", "No response", "Round trip (ms)")}))


# ----------------------------------------------------------------------------- faults

class Fault:
    """A copy of a capture with changes; `expect` maps expert -> set of packet tags."""

    def __init__(self, name, cap):
        self.name = name
        self.cap = cap
        self.expect = {e: set() for e in EXPERTS}


def returned_frames(cap, pairs, want):
    """Returned packet indexes whose datagrams satisfy want(datagrams, sent datagrams)."""
    out = []
    for i, j in sorted(pairs.items()):
        dgs = pr.ecat_datagrams(cap.packets[i])
        if dgs and want(dgs, pr.ecat_datagrams(cap.packets[j])):
            out.append(i)
    return out


def spread(items, n):
    if len(items) <= n:
        return items
    return [items[k * (len(items) - 1) // (n - 1)] for k in range(n)]


def make_faults(base_cap, pairs):
    faults = []
    copy = lambda: pr.Capture.read(base_cap.path)  # noqa: E731

    # returned frames deleted: their sent frames never came back
    f = Fault("returned frames deleted", copy())
    # (not the capture's last pair: with nothing after it, its return may just not be captured yet)
    victims = spread(sorted(pairs)[:-1], 3)
    for i in victims:
        f.expect["no_response"].add(pairs[i])
    f.cap.packets = [p for k, p in enumerate(f.cap.packets) if k not in victims]
    faults.append(f)

    # a working counter that came back lower than it was sent
    cands = returned_frames(base_cap, pairs, lambda d, s: d[0]["wkc"] >= 1)
    if cands:
        f = Fault("working counter came back lower than sent", copy())
        for i in spread(cands, 2):
            d = pr.ecat_datagrams(f.cap.packets[i])[0]
            sent = f.cap.packets[pairs[i]]
            pr.set_u16(sent, pr.ecat_datagrams(sent)[0]["wkc_offset"], d["wkc"] + 1)
            f.expect["wkc_down"].add(i)
        faults.append(f)

    # an address changed (configured-address or logical command)
    cands = returned_frames(base_cap, pairs, lambda d, s: d[0]["cmd"] in (4, 5, 6, 10, 11, 12, 14))
    if cands:
        f = Fault("address changed", copy())
        for i in spread(cands, 2):
            d = pr.ecat_datagrams(f.cap.packets[i])[0]
            pr.set_u16(f.cap.packets[i], d["offset"] + 4, d["ado"] ^ 0x0100)
            f.expect["changed"].add(i)
        faults.append(f)

    # an index changed in a single-datagram frame
    cands = returned_frames(base_cap, pairs, lambda d, s: len(d) == 1)
    if cands:
        f = Fault("index changed", copy())
        i = spread(cands, 3)[1]
        d = pr.ecat_datagrams(f.cap.packets[i])[0]
        f.cap.packets[i].data[d["offset"] + 1] ^= 0x80
        f.expect["changed"].add(i)
        faults.append(f)

    # a length changed: the returned datagram (and so the frame) one byte shorter
    cands = returned_frames(base_cap, pairs, lambda d, s: len(d) == 1 and d[0]["length"] >= 2)
    if cands:
        f = Fault("length changed", copy())
        i = spread(cands, 3)[1]
        pkt = f.cap.packets[i]
        d = pr.ecat_datagrams(pkt)[0]
        base = pr.ecat_offset(pkt)
        pr.set_u16(pkt, base, pr.get_u16(pkt, base) - 1)
        pr.set_u16(pkt, d["offset"] + 6, pr.get_u16(pkt, d["offset"] + 6) - 1)
        del pkt.data[d["data_offset"]]
        f.expect["changed"].add(i)
        f.expect["frame_length"].add(i)
        faults.append(f)

    # written data altered
    cands = returned_frames(base_cap, pairs, lambda d, s: d[0]["cmd"] in WRITES and d[0]["length"] >= 1)
    if cands:
        f = Fault("written data altered", copy())
        for i in spread(cands, 2):
            d = pr.ecat_datagrams(f.cap.packets[i])[0]
            f.cap.packets[i].data[d["data_offset"]] ^= 0x5A
            f.expect["write_changed"].add(i)
        faults.append(f)

    # an auto-increment address advanced differently from the frame's other datagrams
    cands = returned_frames(base_cap, pairs, lambda d, s: sum(x["cmd"] in ADVANCING for x in d) >= 2)
    if cands:
        f = Fault("auto-increment address advanced differently", copy())
        i = cands[len(cands) // 2]
        adv = [x for x in pr.ecat_datagrams(f.cap.packets[i]) if x["cmd"] in ADVANCING]
        pr.set_u16(f.cap.packets[i], adv[-1]["offset"] + 2, adv[-1]["adp"] + 1)
        f.expect["forwarding"].add(i)
        faults.append(f)
    else:
        print("note: %s has no returned frame with two auto-increment/broadcast datagrams" % base_cap.name)

    # reordered: A A' B B' -> A B B' A' (A' comes back after a later frame's return)
    order = sorted(pairs.items(), key=lambda kv: kv[1])
    for (a1, a0), (b1, b0) in zip(order, order[1:]):
        if a0 + 1 == a1 and a1 + 1 == b0 and b0 + 1 == b1:
            f = Fault("returns reordered", copy())
            p = f.cap.packets
            times = [p[k].ts for k in (a0, a1, b0, b1)]
            p[a0:b1 + 1] = [p[a0], p[b0], p[b1], p[a1]]
            for k, t in zip(range(a0, b1 + 1), times):
                p[k].ts = t
            f.expect["out_of_order"].add(a1)
            faults.append(f)
            break

    # a look-alike: a sent frame of reads sent again at once with one data byte other. Not a
    # duplicate (the bytes differ): a new frame of the same key, which gives the first one up
    # (no response) and is answered by the return instead.
    cands = [j for i, j in sorted(pairs.items()) if j > min(pairs.values())
             and all(d["cmd"] in READS for d in pr.ecat_datagrams(base_cap.packets[j]))
             and pr.ecat_datagrams(base_cap.packets[j])[0]["length"] >= 1]
    if cands:
        f = Fault("sent again at once with other bytes", copy())
        j = spread(cands, 3)[1]
        other = f.cap.packets[j].copy()
        other.data[pr.ecat_datagrams(other)[0]["data_offset"]] ^= 0x5A
        other.tag = len(f.cap.packets)
        f.cap.packets.insert(j + 1, other)
        f.expect["no_response"].add(j)
        faults.append(f)
    else:
        print("note: %s has no sent frame of reads only" % base_cap.name)

    # an orphan captured twice: a return whose frame as sent is missing, then its copy
    f = Fault("orphan return captured twice", copy())
    i = spread(sorted(pairs), 5)[3]
    dup = f.cap.packets[i].copy()
    dup.tag = len(f.cap.packets)
    f.expect["duplicate"].add(dup.tag)
    f.cap.packets.insert(i + 1, dup)
    del f.cap.packets[pairs[i]]
    faults.append(f)

    # duplicated: a returned frame and a sent frame captured twice
    f = Fault("frames duplicated", copy())
    i = spread(sorted(pairs), 3)[1]
    j = pairs[spread(sorted(pairs), 3)[2]]
    extra = len(f.cap.packets)
    for pos, k in sorted(((i, i), (j, j)), reverse=True):
        dup = f.cap.packets[k].copy()
        dup.tag = extra
        f.expect["duplicate"].add(extra)
        extra += 1
        f.cap.packets.insert(pos + 1, dup)
    faults.append(f)
    return faults


def fault_checks(check, env, corpus_dir, files):
    for name in files:
        path = os.path.join(corpus_dir, name)
        base = pr.Capture.read(path)
        base.path, base.name = path, name
        pairs, _, _ = oracle(base)
        clean = decode(env, path)
        baseline = {e: {n - 1 for n in with_expert(clean, e)} for e in EXPERTS}
        print("\n== faults injected into copies of %s" % name)
        for f in make_faults(base, pairs):
            out = env.path("fault.pcapng" if f.cap.kind == "pcapng" else "fault.pcap")
            f.cap.write(out)
            os.chmod(out, 0o644)
            tags = {k + 1: p.tag for k, p in enumerate(f.cap.packets)}
            present = {p.tag for p in f.cap.packets}
            rows = decode(env, out)
            one = decode(env, out, two_pass=False)
            for e in EXPERTS:
                got = {tags[n] for n in with_expert(rows, e)}
                want = (baseline[e] & present) | f.expect[e]
                check(got == want, "%s: %s: ecatr.expert.%s exactly on %s (extra %s, missing %s)" % (
                    name, f.name, e, sorted(f.expect[e]) or "none new",
                    sorted(got - want)[:5], sorted(want - got)[:5]))
                if e != "no_response":
                    got1 = {tags[n] for n in with_expert(one, e)}
                    check(got1 == got, "%s: %s: one pass gives ecatr.expert.%s on the same frames" % (
                        name, f.name, e))


# ----------------------------------------------------------------------------- variants

def ecat_bytes(pkt):
    """The EtherCAT frame: header and datagrams, without the Ethernet header and padding."""
    base = pr.ecat_offset(pkt)
    return bytes(pkt.data[base:base + 2 + (pr.get_u16(pkt, base) & 0x7FF)])


def on_second_interface(cap, returned):
    """The returned frames moved to a second interface of the pcapng (a tap with two ports)."""
    big = ">" if cap.endian == ">" else "<"
    idb = next(k for k, b in enumerate(cap.blocks) if b is not None and struct.unpack(big + "I", b[:4])[0] == 1)
    cap.blocks.insert(idb + 1, cap.blocks[idb])
    cap.units[1] = cap.units[0]
    for i in returned:
        cap.packets[i].ifid = 1


def unmarked(cap, returned):
    """The returned frames' source address set back to the master's, as a simulator leaves it."""
    for i in returned:
        cap.packets[i].data[6] &= ~0x02


def variant_checks(check, env, corpus_dir, files):
    """The same pairs and expert infos when the returns come on another interface of the
    capture, or unmarked (pairing must not rely on source addresses alone); unmarked, a frame
    that nobody processed comes back byte for byte as it was sent, and is still its return."""
    variants = [("returns on a second interface", on_second_interface, "pcapng"),
                ("returns not marked (a simulator)", unmarked, None)]
    for name in files:
        path = os.path.join(corpus_dir, name)
        base = pr.Capture.read(path)
        pairs, _, _ = oracle(base)
        clean = decode(env, path)
        identical = sum(1 for i, j in pairs.items() if ecat_bytes(base.packets[i]) == ecat_bytes(base.packets[j]))
        print("\n== variants of %s (%d pairs, %d of them came back unchanged)" % (
            name, len(pairs), identical))
        for what, change, kind in variants:
            if kind and base.kind != kind:
                continue
            cap = pr.Capture.read(path)
            change(cap, pairs)
            out = env.path("variant." + cap.kind)
            cap.write(out)
            os.chmod(out, 0o644)
            for two_pass in (True, False):
                rows = decode(env, out, two_pass=two_pass)
                want = clean if two_pass else decode(env, path, two_pass=False)
                diff = [n for n in want if rows.get(n) != want[n]]
                check(not diff, "%s: %s%s: the same pairs and expert infos as the original (%d frames)%s" % (
                    name, what, "" if two_pass else ", one pass", len(want),
                    ": differ on %s" % diff[:5] if diff else ""))


# ----------------------------------------------------------------------------- forgetting

def unique_key_frames(n, answer_every=1000, answer_after=40, outlier=None, gap_at=None):
    """n sent frames 1 ms apart, each with three LRW datagrams whose indexes no other frame
    has; after every answer_every-th one (from frame 500 on) the return of the frame sent
    answer_after frames earlier. Sent frame `outlier` is stamped an hour ahead; from sent
    frame `gap_at` on, every frame is an hour later. Returns (frames, {return's frame
    number: request's})."""
    def datagrams(i, wkc):
        return [pcapgen.Datagram(cmd=12, idx=(i >> (8 * k)) & 0xFF, lad=0x10000 * k, data=bytes(200), wkc=wkc)
                for k in range(3)]
    frames, pairs, number = [], {}, {}
    base = 1704067200.0
    for i in range(n):
        t = base + i * 0.001 + (3600 if gap_at is not None and i >= gap_at else 0)
        frames.append(pcapgen.Frame(datagrams(i, 0), src_mac=b"\x00\x00\x00\x00\x00\x01",
                                    ts=t + (3600 if i == outlier else 0)))
        number[i] = len(frames)  # frame numbers are 1-based
        if i % answer_every == 500:
            frames.append(pcapgen.Frame(datagrams(i - answer_after, 1), src_mac=b"\x02\x00\x00\x00\x00\x01",
                                        ts=t + 0.0005))
            pairs[len(frames)] = number[i - answer_after]
    return frames, pairs


def peak_rss_mb(check, env, args):
    p = subprocess.Popen(env.command(args), env=env.env(), cwd=env.home, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    _pid, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)   # reaped here, not by Popen
    check(status == 0, "tshark %s exited %d" % (" ".join(args), status))
    return usage.ru_maxrss / 1024.0


def check_paired(check, env, path, pairs, what, two_pass):
    """Every return of `pairs` ({return: request}) and no other frame carries ecatr.request_in."""
    rows = decode(env, path, two_pass=two_pass)
    got = {f: int(r["ecatr.request_in"]) for f, r in rows.items() if r["ecatr.request_in"]}
    check(got == pairs, "%s%s: %d returns paired as expected (got %d, first differences %s)"
          % (what, " (-2)" if two_pass else "", len(pairs), len(got), sorted(set(got.items()) ^ set(pairs.items()))[:4]))


def forgetting_checks(check, env):
    print("== keys never used again")
    rss = {}
    for n in (8000, 32000):
        frames, pairs = unique_key_frames(n)
        name = "unique-keys-%d.pcap" % n
        path = env.add_file(name, pcapgen.pcap_bytes(frames))
        check_paired(check, env, path, pairs, name, two_pass=False)
        rss[n] = min(peak_rss_mb(check, env, ["-r", path]) for _ in range(2))
        print("   %s: peak RSS %.1f MB" % (name, rss[n]))
    growth = rss[32000] - rss[8000]
    check(growth < 25, "peak memory grows by %.1f MB from 8 000 to 32 000 frames (less than 25)" % growth)
    # 2480: after request 2460, before its answer at 2500; the gap: between 5501 (after the
    # answer at 5500) and the next answered request, 6460.
    for name, what, kwargs in (("unique-keys-outlier.pcap", "one frame stamped an hour ahead", {"outlier": 2480}),
                               ("unique-keys-gap.pcap", "an hour's gap", {"gap_at": 5501})):
        frames, pairs = unique_key_frames(8000, **kwargs)
        path = env.add_file(name, pcapgen.pcap_bytes(frames))
        for two_pass in (False, True):
            check_paired(check, env, path, pairs, what, two_pass)


MASTER = b"\x00\x1b\x21\x00\x00\x01"
RETURNED = bytes([MASTER[0] | 0x02]) + MASTER[1:]


def orphan_frames(waiting):
    """A first exchange (the capture shows its slaves mark returned frames), then `waiting`
    requests sent, the return of a request that was not captured, and the returns of the
    waiting ones in order. Returns (frames, {return's frame number: request's})."""
    t = [1704067200.0]

    def frame(idx, src, wkc):
        t[0] += 0.0002
        return pcapgen.Frame([pcapgen.Datagram(cmd=4, idx=idx, adp=0x1001, ado=0x0130, data=bytes(2), wkc=wkc)],
                             src_mac=src, ts=t[0])
    frames = [frame(0x01, MASTER, 0), frame(0x01, RETURNED, 1)]
    pairs = {2: 1}
    requests = {}
    for k in range(waiting):
        frames.append(frame(0x10 + k, MASTER, 0))
        requests[0x10 + k] = len(frames)
    frames.append(frame(0x7f, RETURNED, 1))  # the orphan: its request is not in the capture
    for k in range(waiting):
        frames.append(frame(0x10 + k, RETURNED, 1))
        pairs[len(frames)] = requests[0x10 + k]
    return frames, pairs


def orphan_checks(check, env):
    print("\n== orphan returns among waiting requests (generated frames)")
    for waiting in (0, 2, 3):
        frames, pairs = orphan_frames(waiting)
        name = "orphan-%d-waiting.pcap" % waiting
        path = env.add_file(name, pcapgen.pcap_bytes(frames))
        for two_pass in (False, True):
            what = "an orphan return while %d requests wait" % waiting
            check_paired(check, env, path, pairs, what, two_pass)
            rows = decode(env, path, two_pass=two_pass)
            experts = {e: sorted(with_expert(rows, e)) for e in EXPERTS if with_expert(rows, e)}
            check(not experts, "%s%s: no expert infos (%s)" % (what, " (-2)" if two_pass else "", experts))


class TestPairing(TsharkTestCase, unittest.TestCase):
    """Parts 5 and 6 on generated frames; parts 1 to 4 on the corpus (skipped without it)."""

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("rules", "ethercat.xml"), "ecatr")
        cls.corpus_dir = ARGS.corpus or os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus",
                                                     "ethercat")
        files = corpus_captures(cls.corpus_dir)
        if ARGS.quick:
            files = [f for f in files if os.path.getsize(os.path.join(cls.corpus_dir, f)) < 1 << 20]
        cls.files = []
        for f in files:  # readable by the tshark user
            with open(os.path.join(cls.corpus_dir, f), "rb") as fh:
                cls.env.add_file(f, fh.read())
            cls.files.append(f)
        faulted = ("soem-sdinfo-ek1100-el1004.pcapng",) if ARGS.quick else (
            "soem-sdinfo-ek1100-el1004.pcapng", "replay-ek1100-el2828-el2889.pcapng", "twincat-scan-boxes.pcapng")
        cls.faulted = [f for f in faulted if f in cls.files]

    def need_corpus(self):
        if not self.files:
            self.skipTest("no corpus at %s (no *.pcap/*.pcapng)" % self.corpus_dir)

    def test_corpus_returns_paired_as_the_bytes_show(self):
        """Parts 1 and 2."""
        self.need_corpus()
        with self.checks() as check:
            corpus_checks(check, self.env, self.env.home, self.files)

    def test_injected_faults_raise_their_expert_infos_only(self):
        """Part 3."""
        self.need_corpus()
        with self.checks() as check:
            fault_checks(check, self.env, self.env.home, self.faulted)

    def test_variants_give_the_same_pairs_and_experts(self):
        """Part 4."""
        self.need_corpus()
        with self.checks() as check:
            variant_checks(check, self.env, self.env.home, self.faulted)

    def test_unused_keys_are_forgotten(self):
        """Part 5 (generated frames)."""
        with self.checks() as check:
            forgetting_checks(check, self.env)

    def test_orphan_returns_answer_no_waiting_request(self):
        """Part 6 (generated frames)."""
        with self.checks() as check:
            orphan_checks(check, self.env)


def add_arguments(parser):
    parser.add_argument("--corpus", help="the EtherCAT captures (default ../shared/corpus/ethercat)")
    parser.add_argument("--quick", action="store_true", help="small captures only (see above)")


if __name__ == "__main__":
    sys.exit(run_unittests(add_arguments)[1])

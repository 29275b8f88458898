# SPDX-License-Identifier: GPL-2.0-or-later
"""The manual's rules of <cycles> ("Cycles of any protocol"), computed independently of
the plugin from a capture's timestamps and values, for the tests that check the plugin's
marks and -z P,cycles against them; and nanosecond pcaps to feed it exact times.
Python 3 stdlib only."""

import re
import struct


def window_median(periods):
    v = sorted(periods)
    median = v[(len(v) - 1) // 2]
    if median == 0 or 2 * v[0] < median or 2 * v[-1] > 3 * median:
        return 0
    return median


def clamp(ns):
    """A period as kept: 0 when time went backwards; any length (64-bit ns)."""
    return max(ns, 0)


MOST_LOST_BY_PERIOD = 15  # lost="period": a gap of more lost is a pause, nothing lost


def model(messages, window, bits, step=1, lost_by_period=False, wrap=None, irregular=(), max_lost=None):
    """messages: (frame, time ns, stream key, sequence count) in capture order; step: how
    much the count advances per message, 0 when learned from the stream (step="learned");
    lost_by_period: lost="period", a cycle's period of n whole nominal periods is n - 1 lost;
    wrap: wrap="N", the count runs 0 .. N - 1 (a count of N or more is no count, and the
    next count is the stream's first again); irregular: frames whose period cannot be regular
    for a reason outside the stream's times and counts (requests="yes": the previous request
    was not answered before, or this one is a poll); max_lost: maxlost="N", a gap of more
    messages lost is a restart (a sequence) or a pause (lost="period"): nothing lost.
    Returns ({frame: mark}, [cycle]) as the manual describes them."""
    mask = (1 << bits) - 1
    modulus = wrap or (1 << bits)
    half = modulus // 2  # the largest advance forward: a larger one is the count going back
    streams, cycles, marks = {}, [], {}
    for frame, ts, key, seq in messages:
        s = streams.setdefault(key, {"key": key, "last_frame": 0, "last_ts": 0, "last_seq": None, "recent": [],
                                     "cycle": None, "lost": 0, "duplicates": 0, "step": step})
        lost, back = 0, False
        if seq is not None and wrap and (seq & mask) >= wrap:
            seq = None  # no count
        if seq is None and bits:
            s["last_seq"] = None  # a message without its count: the next one is the stream's first again
        if seq is not None:
            seq &= mask
            if s["last_seq"] is not None:
                advance = (seq - s["last_seq"]) % modulus
                if advance == 0:
                    s["duplicates"] += 1
                    marks[frame] = {"cycle": s["cycle"]["number"] if s["cycle"] else 0,
                                    "duplicate": s["last_frame"]}
                    continue
                if not step and advance <= half and (not s["step"] or s["step"] % advance == 0):
                    s["step"] = advance  # learned: the first advance, or a smaller one dividing it
                if s["step"] and advance <= half and advance % s["step"] == 0:
                    lost = min(advance // s["step"] - 1, 2**32 - 2)
                    if max_lost is not None and lost > max_lost:
                        lost, back = 0, True
                else:
                    back = True
            s["last_seq"] = seq
        first = s["last_frame"] == 0
        period = 0 if first else ts - s["last_ts"]
        if lost_by_period and s["cycle"] and period > 0:
            periods = sorted(s["cycle"]["periods"])
            nominal = periods[(len(periods) - 1) // 2]
            gap = (period + nominal // 2) // nominal
            if gap - 1 > (MOST_LOST_BY_PERIOD if max_lost is None else max_lost):
                back = True
            elif gap >= 2:
                lost = gap - 1
        s["lost"] += lost
        s["last_frame"], s["last_ts"] = frame, ts
        regular = not first and period > 0 and lost == 0 and not back and frame not in irregular
        if not first and s["cycle"] is None:
            if not regular:
                s["recent"] = []
            else:
                s["recent"] = (s["recent"] + [clamp(period)])[-window:]
                if len(s["recent"]) == window and window_median(s["recent"]):
                    c = {"number": len(cycles) + 1, "stream": s, "first": frame, "frames": 0,
                         "periods": s["recent"][:-1], "marked": [], "jitters": []}
                    cycles.append(c)
                    s["cycle"] = c
        mark = {"lost": lost} if lost else {}
        c = s["cycle"]
        if c:
            c["frames"] += 1
            mark.update(cycle=c["number"], period=period)
            if regular:
                c["periods"].append(clamp(period))
                c["marked"].append(clamp(period))
                nominal = sorted(c["periods"])[(len(c["periods"]) - 1) // 2]
                mark["jitter"] = period - nominal
                c["jitters"].append(period - nominal)
        if mark:
            marks[frame] = mark
    return marks, cycles


def tree_unit(largest_ns):
    """The unit of a cycle's time rows in the statistics tree, whose rows hold up to 2^31 - 1:
    (name, ns per unit), the first of ns, us, ms, s that holds the cycle's longest time rounded."""
    for name, scale in (("ns", 1), ("us", 10**3), ("ms", 10**6)):
        if (largest_ns + scale // 2) // scale <= 2**31 - 1:
            return name, scale
    return "s", 10**9


def tree_value(ns, scale):
    """A time in ns as its tree row shows it: rounded to the unit."""
    return (ns + scale // 2) // scale


def quantiles(values):
    """Minimum, lower median, nearest-rank 99th percentile and maximum; None for none."""
    v = sorted(values)
    n = len(v)
    return (v[0], v[(n - 1) // 2], v[(99 * n + 99) // 100 - 1], v[-1]) if n else None


def figures(c):
    """What -z enipr,cycles prints for cycle c."""
    n = len(c["marked"])
    quant = quantiles(c["marked"])
    total = squares = 0.0
    for j in c["jitters"]:
        total += float(j)
        squares += float(j) * float(j)
    mean = total / n if n else 0.0
    var = squares / n - mean * mean if n else 0.0
    return {"first frame": c["first"], "messages": c["frames"],
            "nominal": sorted(c["periods"])[(len(c["periods"]) - 1) // 2],
            "period": quant, "jitter sd": "%.1f" % (var ** 0.5 if var > 0 else 0.0),
            "lost": c["stream"]["lost"], "duplicates": c["stream"]["duplicates"]}


def pcap_ns(packets):
    """A nanosecond pcap of (time ns, Ethernet frame)."""
    out = [struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 1)]
    for ts, data in packets:
        out.append(struct.pack("<IIII", ts // 10**9, ts % 10**9, len(data), len(data)) + data)
    return b"".join(out)


def read_pcap(path):
    """[(time ns, Ethernet frame)] of a classic pcap (microsecond or nanosecond)."""
    with open(path, "rb") as fh:
        blob = fh.read()
    magic = struct.unpack("<I", blob[:4])[0]
    order = "<" if magic in (0xA1B2C3D4, 0xA1B23C4D) else ">"
    magic = struct.unpack(order + "I", blob[:4])[0]
    scale = 1 if magic == 0xA1B23C4D else 1000
    out, pos = [], 24
    while pos + 16 <= len(blob):
        sec, frac, caplen, _orig = struct.unpack(order + "IIII", blob[pos:pos + 16])
        out.append((sec * 10**9 + frac * scale, blob[pos + 16:pos + 16 + caplen]))
        pos += 16 + caplen
    return out


def parse_report(text):
    """The cycles of -z P,cycles: [{"name", "figures"}]."""
    cycles = []
    for line in text.splitlines():
        m = re.match(r"Cycle (\d+): (.*)$", line)
        if m:
            cycles.append({"name": m.group(2), "figures": {}})
            continue
        m = re.match(r"  ([a-z0-9 /()]+?): (.*)$", line)
        if not m or not cycles:
            continue
        what, value = m.groups()
        f = cycles[-1]["figures"]
        if what == "first frame":
            f["first frame"] = int(value)
        elif what == "messages":
            f["messages"] = int(value)
        elif what == "nominal period (ns)":
            f["nominal"] = int(value)
        elif what.startswith("period"):
            f["period"] = None if value == "none" else tuple(int(x) for x in value.split())
        elif what == "jitter std dev (ns)":
            f["jitter sd"] = value
        elif what == "messages lost":
            f["lost"] = int(value)
        elif what == "duplicates":
            f["duplicates"] = int(value)
        elif what.startswith("round trip"):
            f["round trip"] = None if value == "none" else tuple(int(x) for x in value.split())
        elif what == "requests answered":
            f["answered"] = int(value)
        elif what == "requests unanswered":
            f["unanswered"] = int(value)
    return cycles


def mark_fields(protocol):
    """The fields of a message's cycle mark, then its two cycle expert infos."""
    return ["%s.cycle" % protocol, "%s.cycle.period" % protocol, "%s.cycle.jitter" % protocol,
            "%s.cycle.lost" % protocol, "%s.cycle.duplicate" % protocol,
            "%s.expert.cycle_lost" % protocol, "%s.expert.cycle_duplicate" % protocol]


def mark_of(row, protocol):
    """A message's mark as model() gives it, from its row of mark_fields (field_rows)."""
    from tshark_env import relative_time_ns
    got = {}
    for key, field, value in (("cycle", "cycle", int), ("period", "cycle.period", relative_time_ns),
                              ("jitter", "cycle.jitter", relative_time_ns), ("lost", "cycle.lost", int),
                              ("duplicate", "cycle.duplicate", int)):
        shown = row["%s.%s" % (protocol, field)]
        if shown:
            got[key] = value(shown[0])
    return got

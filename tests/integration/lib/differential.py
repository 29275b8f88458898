# SPDX-License-Identifier: GPL-2.0-or-later
"""Value-by-value comparison of a rule file's protocol with Wireshark's own dissector on one
capture (Python 3 stdlib only), shared by test_profinet.py and test_powerlink.py.

COUNTERPARTS is a list of (Wireshark's fields, ours): per frame, the values of each side's
fields are pooled and matched as multisets (one concept may be spread over several fields on
either side); the agreement is the share of Wireshark's values that were matched.
"""
import collections
import re


def number_or_text(value):
    """A value as tshark -T fields prints it: booleans and numbers as ints, else the text."""
    if value in ("True", "False"):
        return int(value == "True")
    try:
        return int(value, 0)
    except ValueError:
        return value


def field_table(env, capture, fields, extra=()):
    """{frame number: [[values of field] for field in fields]} of `tshark -T fields`."""
    args = ["-r", capture, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=|"] + list(extra)
    for f in ["frame.number"] + fields:
        args += ["-e", f]
    out = {}
    for line in env.tshark(args).stdout.splitlines():
        cols = line.split("\t")
        out[int(cols[0])] = [c.split("|") if c else [] for c in cols[1:]]
    return out


def agreement(env, capture, counterparts, ours_protocol, normalize, extra=()):
    """(Wireshark's values, those matched, Counter of (their field, frame, value) not matched):
    Wireshark's side read with ours_protocol disabled. normalize(field, text) makes both
    sides' texts comparable."""
    theirs_fields = [f for ws, _ in counterparts for f in ws]
    ours_fields = [f for _, o in counterparts for f in o]
    theirs = field_table(env, capture, theirs_fields, ["--disable-protocol", ours_protocol] + list(extra))
    ours = field_table(env, capture, ours_fields, extra)
    total = matched = 0
    misses = collections.Counter()
    for number, row in theirs.items():
        values = dict(zip(theirs_fields, row))
        mine = dict(zip(ours_fields, ours[number]))
        for ws, o in counterparts:
            want = collections.Counter(normalize(f, v) for f in ws for v in values[f])
            have = collections.Counter(normalize(f, v) for f in o for v in mine[f])
            missing = want - have
            total += sum(want.values())
            matched += sum(want.values()) - sum(missing.values())
            for value, n in missing.items():
                misses[(ws[0], number, value)] += n
    return total, matched, misses


def fields_shown(env, capture, prefixes, ours_protocol):
    """Every field name starting with one of prefixes (e.g. "epl.") that Wireshark's
    dissectors show on the capture with ours_protocol disabled."""
    pdml = env.tshark(["-r", capture, "-T", "pdml", "--disable-protocol", ours_protocol]).stdout
    alternatives = "|".join(re.escape(p) for p in prefixes)
    return set(re.findall(r'<field name="((?:%s)[^"]+)"' % alternatives, pdml))

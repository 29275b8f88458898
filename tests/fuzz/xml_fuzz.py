#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Mutated rule, ESI and design/ENI files through `dissgen check` (a campaign, not a CI test).

    tests/fuzz/xml_fuzz.py --dissgen build-asan/bin/dissgen --kind esi --runs 200 \
        --out /tmp/fz/esi /work/shared/corpus/esi/BogusIO.xml ...
    --kind rules:   dissgen check MUTANT
    --kind esi:     dissgen check rules/ethercat.xml --esi MUTANT
    --kind network: dissgen check rules/ethercat.xml --esi ESI... --network MUTANT

Each mutant deletes elements or attributes, puts garbage where numbers were, duplicates
elements, truncates the file, changes its encoding or nests elements deeply. dissgen
must not crash, hang (60 s) or print a sanitizer report; a non-zero exit must come with
`FILE:LINE: error: ...` (a line inside the file). Findings keep their mutant in --out.
"""
import argparse
import os
import random
import re
import subprocess
import sys

GARBAGE = ["#xZZ", "-1", "99999999999999999999", "", "0x", "#x", "1e3", " 7 ", "0x-1", "4294967296",
           "18446744073709551616", "-0", "+5", "NaN", "0b101", "1.5", "0xFFFFFFFFFFFFFFFFF", "#x80000000",
           "\u00e9", "&amp;", "00000000000000000000000000001", "2147483648", "-2147483649", "65536"]
NUMBER = re.compile(rb"(?<![\w#.])(?:0x[0-9A-Fa-f]+|#x[0-9A-Fa-f]+|\d+)(?![\w.])")
START = re.compile(rb"<([A-Za-z_][\w.:-]*)(?=[\s/>])")
ATTR = re.compile(rb"\s[\w:.-]+\s*=\s*(\"[^\"]*\"|'[^']*')")


def element_span(text, start):
    """(start, end) of the element whose start tag begins at `start`, or None (no nesting of
    the same name is assumed beyond a simple counter)."""
    m = START.match(text, start)
    if not m:
        return None
    name = m.group(1)
    gt = text.find(b">", start)
    if gt < 0:
        return None
    if text[gt - 1:gt] == b"/":
        return start, gt + 1
    depth, at = 1, gt + 1
    pat = re.compile(rb"<(/?)" + re.escape(name) + rb"(?=[\s/>])")
    while depth:
        n = pat.search(text, at)
        if not n:
            return None
        close = text.find(b">", n.end())
        if close < 0:
            return None
        if n.group(1):
            depth -= 1
        elif text[close - 1:close] != b"/":
            depth += 1
        at = close + 1
    return start, at


def pick(regex, text, rng):
    ms = list(regex.finditer(text))
    return rng.choice(ms) if ms else None


def mutate(text, rng):
    """One mutation of the bytes of an XML file; returns (new bytes, what was done)."""
    op = rng.choice(["delete_element", "delete_attr", "number", "number", "number", "duplicate",
                     "truncate", "encoding", "nest", "empty_text", "swap_elements"])
    if op == "delete_element":
        m = pick(START, text, rng)
        span = m and element_span(text, m.start())
        if span:
            return text[:span[0]] + text[span[1]:], "deleted <%s> at byte %d" % (m.group(1).decode(), span[0])
    elif op == "delete_attr":
        m = pick(ATTR, text, rng)
        if m:
            return text[:m.start()] + text[m.end():], "deleted attribute %r" % m.group(0)[:40]
    elif op == "number":
        m = pick(NUMBER, text, rng)
        if m:
            g = rng.choice(GARBAGE).encode("utf-8")
            return text[:m.start()] + g + text[m.end():], "number %r -> %r at byte %d" % (m.group(0), g, m.start())
    elif op == "duplicate":
        m = pick(START, text, rng)
        span = m and element_span(text, m.start())
        if span:
            el = text[span[0]:span[1]]
            return text[:span[1]] + el * rng.choice((1, 2, 50)) + text[span[1]:], "duplicated <%s>" % m.group(1).decode()
    elif op == "truncate":
        at = rng.randrange(len(text) + 1)
        return text[:at], "truncated at byte %d" % at
    elif op == "encoding":
        how = rng.randrange(5)
        if how == 0:
            new = re.sub(rb'encoding="[^"]*"', b'encoding="' + rng.choice([b"UTF-16", b"bogus", b"ISO-8859-1",
                                                                          b"UTF-8", b"EBCDIC", b""]) + b'"', text, 1)
            return new, "declared encoding changed"
        if how == 1:
            try:
                return text.decode("utf-8").encode("utf-16"), "re-encoded as UTF-16"
            except UnicodeDecodeError:
                return text.decode("latin-1").encode("utf-16"), "re-encoded (latin-1) as UTF-16"
        if how == 2:
            at = rng.randrange(len(text) + 1)
            return text[:at] + rng.choice([b"\xff\xfe", b"\xc3", b"\x80\x80", b"\x00", b"\xef\xbb\xbf"]) + text[at:], \
                "bad bytes at %d" % at
        if how == 3:
            return b"\xef\xbb\xbf" + text, "BOM added"
        return re.sub(rb"^<\?xml[^>]*\?>", b"", text), "declaration removed"
    elif op == "nest":
        m = pick(START, text, rng)
        if m:
            gt = text.find(b">", m.start())
            if gt > 0 and text[gt - 1:gt] != b"/":
                depth = rng.choice((100, 5000, 50000))
                tag = rng.choice([m.group(1), b"x"])
                inner = b"<" + tag + b">"
                return (text[:gt + 1] + inner * depth + (b"</" + tag + b">") * depth +
                        text[gt + 1:]), "nested %d <%s>" % (depth, tag.decode())
    elif op == "empty_text":
        m = pick(re.compile(rb">([^<>]+)</"), text, rng)
        if m:
            return text[:m.start(1)] + text[m.end(1):], "emptied text %r" % m.group(1)[:30]
    elif op == "swap_elements":
        m = pick(START, text, rng)
        span = m and element_span(text, m.start())
        n = pick(START, text, rng)
        span2 = n and element_span(text, n.start())
        if span and span2 and (span[1] <= span2[0]):
            a, b = text[span[0]:span[1]], text[span2[0]:span2[1]]
            return text[:span[0]] + b + text[span[1]:span2[0]] + a + text[span2[1]:], "swapped two elements"
    return text, "unchanged"


DIAG = re.compile(r"^(?P<file>.+?):(?P<line>\d+): (?P<sev>error|warning|note): ")


def judge(p, mutant, text, timeout):
    """Problems with one `dissgen check` run."""
    if p is None:
        return ["HANG (>%ds)" % timeout]
    problems = []
    err = p.stderr.decode("utf-8", "replace")
    if any(s in err for s in ("AddressSanitizer", "runtime error:", "LeakSanitizer", "UndefinedBehaviorSanitizer")):
        problems.append("sanitizer report")
    if p.returncode not in (0, 1):
        problems.append("exit %d" % p.returncode)
    lines = [l for l in err.splitlines() if l.strip()]
    diags = [DIAG.match(l) for l in lines]
    if p.returncode == 1:
        errors = [d for d in diags if d and d.group("sev") == "error"]
        if not errors:
            problems.append("exit 1 without FILE:LINE: error: (%r)" % (lines[:1],))
        nlines = text.count(b"\n") + 1
        for d in errors:
            if d.group("file") == mutant and not 1 <= int(d.group("line")) <= nlines:
                problems.append("line %s outside the file (%d lines)" % (d.group("line"), nlines))
    for l, d in zip(lines, diags):
        if not d and not l.startswith(" "):   # continuation lines (excerpts, carets) are indented
            problems.append("output line not FILE:LINE: %r" % l[:160])
            break
    return problems


def run(cmd, timeout):
    try:
        return subprocess.run(cmd, capture_output=True, timeout=timeout,
                              env=dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0",
                                       UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"))
    except subprocess.TimeoutExpired:
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", required=True)
    ap.add_argument("--kind", choices=["rules", "esi", "network"], required=True)
    ap.add_argument("--rules", default="rules/ethercat.xml")
    ap.add_argument("--esi", action="append", default=[], help="ESI files for --kind network")
    ap.add_argument("--runs", type=int, default=100, help="mutants per input file")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=int, default=60)
    ap.add_argument("--out", required=True)
    ap.add_argument("inputs", nargs="+")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)

    def command(path):
        if a.kind == "rules":
            return [a.dissgen, "check", path]
        if a.kind == "esi":
            return [a.dissgen, "check", a.rules, "--esi", path]
        return [a.dissgen, "check", a.rules] + sum((["--esi", e] for e in a.esi), []) + ["--network", path]

    total, findings = 0, 0
    for inp in a.inputs:
        with open(inp, "rb") as fh:
            orig = fh.read()
        base = os.path.splitext(os.path.basename(inp))[0]
        p = run(command(inp), a.timeout)
        if p is None or p.returncode != 0:
            print("NOTE %s: the unmutated file does not pass (exit %s): %s" %
                  (inp, p and p.returncode, p and p.stderr[:300]), flush=True)
        rng = random.Random("%s-%d" % (base, a.seed))
        for i in range(a.runs):
            text, what = orig, []
            for _ in range(rng.choice((1, 1, 1, 2, 3))):
                text, w = mutate(text, rng)
                what.append(w)
            mutant = os.path.join(a.out, "%s.%d.xml" % (base, i))
            with open(mutant, "wb") as fh:
                fh.write(text)
            p = run(command(mutant), a.timeout)
            total += 1
            problems = judge(p, mutant, text, a.timeout)
            if problems:
                findings += 1
                print("FINDING %s (%s): %s" % (mutant, "; ".join(what), "; ".join(problems)), flush=True)
                if p is not None:
                    print("  " + p.stderr.decode("utf-8", "replace")[:1500].replace("\n", "\n  "), flush=True)
            else:
                os.remove(mutant)
        print("done %s" % inp, flush=True)
    print("mutants %d, findings %d" % (total, findings))
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())

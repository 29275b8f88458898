#!/usr/bin/env python3
"""Systematic mutants: every relational, arithmetic and boolean operator and every small
integer constant of plugin_runtime/ and generator/, changed one at a time.  Python 3 stdlib only.

    systematic.py --source-dir . --list            # every site: id, file:line:col, change
    systematic.py --source-dir . --count           # how many, by file and kind
    run_mutants.py --systematic --sample 60 --seed 1     # a random sample, through the runner
    run_mutants.py --systematic --window 3/200           # window 3 of 200 (ids in order)
    run_mutants.py --extra-systematic 3 ...              # CI: 3 more after the hand-written ones

A site is one token of one source file and one replacement:

  relational  <  <=  >  >=  ==  !=        each to its boundary neighbour or its negation
              (< to <=, <= to <, > to >=, >= to >, == to !=, != to ==)
  arithmetic  binary + and - swapped, += and -= swapped, * to /, / to *, % to /,
              << and >> swapped (plugin_runtime/ only: the generator's are stream output)
  boolean     && to ||, || to &&, a ! dropped
  constant    an integer literal 0..64 plus one and minus one (its spelling kept: 0x0f to 0x10)

Never a site: comments, string and character literals, preprocessor lines (#include,
#define, #if ..., with their continuations), template angle brackets, operator
declarations, and whole statements that log or assert (std::cerr, ws_log, ws_debug,
ws_info, ws_warning, printf, fprintf, g_print, g_warning, g_debug, assert, static_assert,
g_assert, DISSECTOR_ASSERT, ws_assert).  A + next to a string literal (text concatenation)
is not one either.

Each site has a stable id ("S" and 8 hex digits) made of its file, the text of its line
(spaces normalised), which occurrence of that line in the file, which occurrence of the
operator in the line, and the change: the id survives edits elsewhere in the file, and a
site whose line changed gets a new id.  tests/mutation/equivalent.txt lists the ids of
equivalent mutants (the change cannot alter any output), one a line with its reason;
they are left out.  A mutant that does not compile is reported INVALID by the runner and
is not counted in the kill ratio (a compiler kills it).

The tests a mutant runs are those of its file (TESTS_BY_FILE below), cheapest or likeliest
killer first: the runner stops at the first failure.
"""

import argparse
import collections
import hashlib
import os
import random
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
EQUIVALENT = os.path.join(HERE, "equivalent.txt")
RUNTIME_LIST = os.path.join("plugin_runtime", "runtime.list")   # the runtime's files, listed once
GENERATOR = "generator"                                          # every .cpp and .h under it
SMALL = 64   # integer literals up to this value are constants that get +1 and -1

# Source file (or folder prefix, the longest match wins) -> the runner's test names
# (run_mutants.TESTS) that exercise it, cheapest or likeliest killer first.
# Kept short (a mutant that survives runs them all): the whole run triages its survivors.
TESTS_BY_FILE = {
    "plugin_runtime/dissgen_values.h": ["unit", "widths", "everything"],
    "plugin_runtime/dissgen_text.h": ["unit", "typed_values", "widths"],
    "plugin_runtime/dissgen_text.cpp": ["typed_values", "widths", "everything", "computed", "dates_guids_shared_names",
                                        "info_column"],
    "plugin_runtime/dissgen_label.h": ["unit", "typed_values", "widths", "everything"],
    "plugin_runtime/dissgen_walk.cpp": ["widths", "everything", "malformed", "layout", "typed_values"],
    "plugin_runtime/dissgen_conditions.cpp": ["unit", "layout", "widths", "everything", "edges_peek"],
    "plugin_runtime/dissgen_handoff.cpp": ["typed_values", "edges_handoff", "enip"],
    "plugin_runtime/dissgen_expr.cpp": ["unit", "computed", "request_context"],
    "plugin_runtime/dissgen_expr.h": ["unit", "computed"],
    "plugin_runtime/dissgen_request.cpp": ["request_context", "computed"],
    "plugin_runtime/dissgen_learned.cpp": ["learned", "unit"],
    "plugin_runtime/dissgen_pairing.cpp": ["transactions", "pairing", "ecat_figures", "request_context", "cycles"],
    "plugin_runtime/dissgen_pairing.h": ["transactions", "pairing"],
    "plugin_runtime/dissgen_validity.cpp": ["validity", "validity_unit", "enip"],
    "plugin_runtime/dissgen_validity.h": ["validity", "validity_unit"],
    "plugin_runtime/dissgen_register.cpp": ["everything", "ecat_figures", "validity", "loading"],
    "plugin_runtime/dissgen_state.h": ["widths", "everything", "malformed", "layout", "typed_values"],
    "plugin_runtime/dissgen_rows.h": ["widths", "everything", "layout", "typed_values"],
    "plugin_runtime/dissgen_runtime.h": ["widths", "everything", "layout"],
    "plugin_runtime/dissgen_compat.h": ["widths", "everything"],
    "plugin_runtime/dissgen_names.h": ["loading", "reserved_names"],
    "plugin_runtime/ethercat/ethercat_analysis.cpp": ["esc_commands", "pairing", "ecat_figures"],
    "plugin_runtime/ethercat/ethercat_analysis.h": ["esc_commands", "pairing"],
    "plugin_runtime/ethercat/ethercat_bus.h": ["esc_commands", "bus_pdo", "bus_wkc", "bus_tables"],
    "plugin_runtime/ethercat/ethercat_bus.cpp": ["bus_pdo", "bus_wkc", "bus_stats", "bus_identities", "bus_coe",
                                                 "bus_signed", "bus_slave_line", "bus_network", "bus_station_bytes"],
    "plugin_runtime/ethercat/ethercat_cycles.cpp": ["cycles", "report"],
    "plugin_runtime/ethercat/": ["bus_pdo", "bus_tables", "bus_wkc"],
    "generator/validator.cpp": ["rules_err", "unit", "widths", "everything"],
    "generator/alternatives.cpp": ["rules_err", "unit", "dates_guids_shared_names"],
    "generator/quiet.cpp": ["unit", "quiet"],
    "generator/expression.cpp": ["unit", "rules_err", "computed", "learned"],
    "generator/emit_cpp.cpp": ["field_types", "widths", "everything", "typed_values", "computed", "layout",
                               "enip_pipelined", "learned"],
    "generator/emit_validity.cpp": ["validity_unit", "validity"],
    "generator/parser.cpp": ["unit", "rules_err", "widths", "everything"],
    "generator/xml_input.cpp": ["unit", "rules_err", "esi"],
    "generator/model.cpp": ["unit", "rules_err", "widths"],
    "generator/text_util.cpp": ["unit", "rules_err", "field_types"],
    "generator/diagnostics.cpp": ["rules_err", "unit"],
    "generator/runtime_names.cpp": ["unit", "reserved_names"],
    "generator/analyses.cpp": ["unit", "plugin_contents", "pairing"],
    "generator/build_plugin.cpp": ["loading", "plugin_contents", "everything"],
    "generator/wireshark_env.cpp": ["loading", "everything"],
    "generator/packaged_plugins.cpp": ["unit"],
    "generator/object_cache.cpp": ["unit", "loading", "everything"],
    "generator/main.cpp": ["unit", "help_matches_man", "usage_errors", "loading", "everything", "plugin_contents"],
    "generator/ethercat/": ["esi", "bus_tables", "bus_pdo", "bus_coe", "bus_signed"],
    "generator/report/": ["unit", "report"],
    "generator/": ["unit", "rules_err", "widths", "everything"],
    "plugin_runtime/": ["widths", "everything", "layout"],
}

SKIP_STATEMENT = re.compile(r"\b(std::cerr|std::clog|ws_log\w*|ws_debug|ws_info|ws_warning|ws_message|ws_noisy|"
                            r"printf|fprintf|g_print|g_printerr|g_warning|g_message|g_debug|assert|static_assert|"
                            r"g_assert\w*|DISSECTOR_ASSERT\w*|ws_assert\w*)\b")
KEYWORDS_BEFORE_UNARY = {"return", "case", "throw", "else", "sizeof", "co_return", "and", "or", "not"}
TYPE_WORDS = {"const", "char", "int", "void", "unsigned", "signed", "long", "short", "auto", "bool", "float",
              "double", "struct", "class", "typename", "volatile"}


def tests_for(path):
    best = max((k for k in TESTS_BY_FILE if path == k or (k.endswith("/") and path.startswith(k))), key=len,
               default=None)
    return list(TESTS_BY_FILE[best]) if best else ["unit", "widths", "everything"]


def mask(text):
    """The text with comments, string and character literals and preprocessor lines (with their
    continuations) turned into spaces (line breaks kept), and the set of offsets that were string
    literals' quotes (to see a + that joins text)."""
    out = list(text)
    quotes = set()
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c in " \t":
            i += 1
            continue
        if line_start and c == "#":
            j = i
            while j < n and not (text[j] == "\n" and text[j - 1] != "\\"):
                j += 1
            for k in range(i, j):
                if out[k] != "\n":
                    out[k] = " "
            i = j
            continue
        line_start = c == "\n"
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out[i:j] = " " * (j - i)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            for k in range(i, j):
                if out[k] != "\n":
                    out[k] = " "
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^()\\ ]{0,16})\(', text[i:])
            if not m:
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i)
            j = n if end < 0 else end + len(m.group(1)) + 2
            quotes.update((i, j - 1))
            for k in range(i, j):
                if out[k] != "\n":
                    out[k] = " "
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and text[i - 1] in "0123456789abcdefABCDEF" and \
                    re.search(r"\b0x[0-9a-fA-F']*$|\b\d[\d']*$", text[:i]):
                i += 1     # a digit separator (1'000)
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            if c == '"':
                quotes.update((i, j - 1))
            for k in range(i, j):
                if out[k] != "\n":
                    out[k] = " "
            i = j
        else:
            i += 1
    return "".join(out), quotes


def statements(masked):
    """(start, end) spans of statements: text between ; { } at any depth."""
    spans, start = [], 0
    for m in re.finditer(r"[;{}]", masked):
        spans.append((start, m.start()))
        start = m.end()
    spans.append((start, len(masked)))
    return spans


TEMPLATE_INSIDE = re.compile(r"^[\w:\s\*&,<>\[\]]*$")
# A template's own parameter list may give defaults: template <typename R = T>.
TEMPLATE_PARAMETERS = re.compile(r"^[\w:\s\*&,<>\[\]=]*$")


def template_brackets(masked):
    """Offsets of < and > that are template angle brackets (a name right before <, a matching >
    on the same line with only type-like text between, no && in it)."""
    out = set()
    for m in re.finditer(r"(\w)\s*<(?![<=])", masked):
        lt = m.end() - 1
        word = re.search(r"(\w+)\s*$", masked[:lt]).group(1)
        if word == "operator" or word.isdigit():
            continue
        depth, j = 1, lt + 1
        while j < len(masked) and masked[j] != "\n":
            ch = masked[j]
            if ch == "<":
                depth += 1
            elif ch == ">" and masked[j - 1] != "-":
                depth -= 1
                if depth == 0:
                    break
            j += 1
        if depth != 0 or j >= len(masked) or masked[j] == "\n":
            continue
        inside = masked[lt + 1:j]
        pattern = TEMPLATE_PARAMETERS if word == "template" else TEMPLATE_INSIDE
        if "&&" in inside or not pattern.match(inside) or not inside.strip():
            continue
        out.add(lt)
        # every > closing a nested level inside, and the last
        for k in range(lt + 1, j + 1):
            if masked[k] in "<>":
                out.add(k)
    return out


class Site:
    __slots__ = ("file", "line", "col", "offset", "old", "new", "kind", "text", "id")

    def describe(self):
        return "%s:%d:%d %s -> %s" % (self.file, self.line, self.col, self.old, self.new or "(dropped)")


def prev_token(masked, i):
    j = i - 1
    while j >= 0 and masked[j] in " \t\n":
        j -= 1
    if j < 0:
        return ""
    if masked[j].isalnum() or masked[j] == "_":
        k = j
        while k >= 0 and (masked[k].isalnum() or masked[k] == "_"):
            k -= 1
        return masked[k + 1:j + 1]
    return masked[j]


def next_char(masked, i):
    j = i
    while j < len(masked) and masked[j] in " \t\n":
        j += 1
    return masked[j] if j < len(masked) else ""


def is_operand_end(tok):
    return bool(tok) and (tok[-1].isalnum() or tok[-1] in "_)]") and tok not in KEYWORDS_BEFORE_UNARY \
        and tok not in TYPE_WORDS


def literal_neighbour(text, quotes, i, width):
    """True when the nearest non-space character before or after the operator is a string quote."""
    j = i - 1
    while j >= 0 and text[j] in " \t\n":
        j -= 1
    k = i + width
    while k < len(text) and text[k] in " \t\n":
        k += 1
    return j in quotes or k in quotes


def bump(literal, delta):
    m = re.match(r"^(0[xX])([0-9a-fA-F]+)([uUlL]*)$", literal)
    if m:
        v = int(m.group(2), 16) + delta
        return None if v < 0 else m.group(1) + ("%0*x" % (len(m.group(2)), v) if m.group(2).islower() or
                                                not any(c.isalpha() for c in m.group(2))
                                                else "%0*X" % (len(m.group(2)), v)) + m.group(3)
    m = re.match(r"^(\d+)([uUlL]*)$", literal)
    if m and not (len(m.group(1)) > 1 and m.group(1)[0] == "0"):
        v = int(m.group(1)) + delta
        if v < 0:
            return None if m.group(2) else "-1"
        return str(v) + m.group(2)
    return None


OPERATORS = [
    # (regex on the masked text, kind, replacement)
    (r"&&", "boolean", "||"),
    (r"\|\|", "boolean", "&&"),
    (r"==", "relational", "!="),
    (r"!=", "relational", "=="),
    (r"(?<![<>])<=(?!>)", "relational", "<"),
    (r"(?<![<>])>=", "relational", ">"),
    (r"(?<![<\-])<(?![<=])", "relational", "<="),
    (r"(?<![>\-])>(?![>=])", "relational", ">="),
    (r"(?<![+])\+(?![+=])", "arithmetic", "-"),
    (r"(?<![\-])-(?![\-=>])", "arithmetic", "+"),
    (r"\+=", "arithmetic", "-="),
    (r"-=", "arithmetic", "+="),
    (r"(?<![*/])\*(?![=/*])", "arithmetic", "/"),
    (r"(?<![*/])/(?![=/*])", "arithmetic", "*"),
    (r"%(?!=)", "arithmetic", "/"),
    (r"(?<![<])<<(?![<=])", "arithmetic", ">>"),
    (r"(?<![>])>>(?![>=])", "arithmetic", "<<"),
    (r"!(?!=)", "boolean", ""),
]


def sites_of(rel, text):
    masked, quotes = mask(text)
    line_starts = [0] + [m.end() for m in re.finditer("\n", text)]
    lines = text.split("\n")
    templates = template_brackets(masked)
    skipped = []
    for s, e in statements(masked):
        if SKIP_STATEMENT.search(masked[s:e]):
            skipped.append((s, e))
    skipped_at = set()
    for s, e in skipped:
        skipped_at.update(range(s, e))
    found = []

    def add(offset, old, new, kind):
        if offset in skipped_at:
            return
        found.append((offset, old, new, kind))

    runtime = rel.startswith("plugin_runtime/")
    for pattern, kind, new in OPERATORS:
        for m in re.finditer(pattern, masked):
            i, old = m.start(), m.group(0)
            before = prev_token(masked, i)
            if before == "operator":
                continue
            if old in ("<", ">", "<=", ">=") and (i in templates or (i + len(old) - 1) in templates):
                continue
            if old in ("<", ">") and (masked[i - 1:i] in ("<", ">") or masked[i + 1:i + 2] in ("<", ">")):
                continue
            if old in ("<<", ">>"):
                if not runtime or i in templates or i + 1 in templates or \
                        not (masked[i - 1] == " " and masked[i + 2:i + 3] == " "):
                    continue
            if old in ("+", "-", "*", "/", "%", "&&", "||", "<", ">"):
                if not is_operand_end(before):
                    continue
            if old == "*" and not (masked[i - 1] == " " and masked[i + 1:i + 2] == " "):
                continue   # a pointer declarator or a dereference, not a product
            if old in ("&&", "||") and not (masked[i - 1] == " " and masked[i + 2:i + 3] == " "):
                continue
            if old in ("+", "+=") and literal_neighbour(text, quotes, i, len(old)):
                continue
            if old == "-" and masked[i + 1:i + 2] == ">":
                continue
            if old == "!" and (masked[i + 1:i + 2] == "=" or next_char(masked, i + 1) == ""):
                continue
            add(i, old, new, kind)
    for m in re.finditer(r"(?<![\w.])(0[xX][0-9a-fA-F]+|\d+)([uUlL]*)(?![\w.'])", masked):
        lit = m.group(0)
        value = int(m.group(1), 16) if m.group(1)[:2].lower() == "0x" else int(m.group(1))
        if value > SMALL:
            continue
        if prev_token(masked, m.start()) in ("[", "operator") and masked[m.end():m.end() + 1] == "]" and False:
            continue
        for delta in (1, -1):
            new = bump(lit, delta)
            if new is not None:
                add(m.start(), lit, new, "constant")

    found.sort()
    # stable ids: file, the line's text, which copy of that line, which occurrence on it, the change
    seen_lines = collections.Counter()
    line_copy = {}
    for no, line in enumerate(lines):
        norm = " ".join(line.split())
        line_copy[no] = seen_lines[norm]
        seen_lines[norm] += 1
    per_line = collections.Counter()
    out = []
    import bisect
    for offset, old, new, kind in found:
        no = bisect.bisect_right(line_starts, offset) - 1
        norm = " ".join(lines[no].split())
        key = (no, old, new)
        occurrence = per_line[key]
        per_line[key] += 1
        s = Site()
        s.file, s.line, s.col, s.offset = rel, no + 1, offset - line_starts[no] + 1, offset
        s.old, s.new, s.kind, s.text = old, new, kind, lines[no]
        s.id = "S" + hashlib.sha1(("%s|%s|%d|%d|%s|%s" % (rel, norm, line_copy[no], occurrence, old, new))
                                  .encode()).hexdigest()[:8]
        out.append(s)
    return out


def runtime_files(source_dir):
    """The plugin runtime's sources and headers, generic and every analysis's, as
    plugin_runtime/runtime.list names them (its 'source' and 'header' lines): the files
    CMake builds and installs and `dissgen install` compiles."""
    out = []
    with open(os.path.join(source_dir, RUNTIME_LIST), encoding="utf-8") as fh:
        for line in fh:
            words = line.split()
            if words and words[0] in ("source", "header"):
                out += ["plugin_runtime/" + w for w in words[1:]]
    return out


def source_files(source_dir):
    out = runtime_files(source_dir)
    for root, dirs, files in os.walk(os.path.join(source_dir, GENERATOR)):
        dirs.sort()
        for f in sorted(files):
            if f.endswith((".cpp", ".h")):
                out.append(os.path.relpath(os.path.join(root, f), source_dir).replace(os.sep, "/"))
    return sorted(out)


def unlisted_test_keys(source_dir):
    """TESTS_BY_FILE keys under plugin_runtime/ that name no listed file or folder: tests
    that no mutant would run after a rename."""
    files = runtime_files(source_dir)
    return sorted(k for k in TESTS_BY_FILE if k.startswith("plugin_runtime/") and
                  not any(f == k or (k.endswith("/") and f.startswith(k)) for f in files))


def all_sites(source_dir):
    out = []
    for rel in source_files(source_dir):
        with open(os.path.join(source_dir, rel), encoding="utf-8") as fh:
            out += sites_of(rel, fh.read())
    return out


def equivalent_ids(path=EQUIVALENT):
    """{id: reason} from equivalent.txt: lines 'ID  file:line  change  # reason' (the rest is
    for the reader); blank lines and lines starting with # are ignored."""
    out = {}
    if not os.path.isfile(path):
        return out
    for line in open(path, encoding="utf-8"):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        sid = line.split()[0]
        out[sid] = line.split("#", 1)[1].strip() if "#" in line else ""
    return out


class SiteMutant:
    """A generated mutant with the interface of run_mutants.Mutant."""

    def __init__(self, site):
        self.site = site
        self.name = site.id
        self.path = site.describe()
        self.file = site.file
        self.tests = tests_for(site.file)
        self.why = ["%s (%s): %s" % (site.describe(), site.kind, site.text.strip())]
        self.problem = None
        self.equivalent = None   # the reason, when equivalent.txt lists it

    def mutate(self, original):
        s = self.site
        if original[s.offset:s.offset + len(s.old)] != s.old:
            raise ValueError("the file changed since the sites were listed")
        return original[:s.offset] + s.new + original[s.offset + len(s.old):]


def mutants(source_dir, include_equivalent=False):
    """Every site as a mutant, ordered by id; those equivalent.txt lists left out, or (with
    include_equivalent, so that samples and windows stay the same as the list grows) kept
    with their reason in .equivalent."""
    eq = equivalent_ids()
    out = []
    for s in all_sites(source_dir):
        m = SiteMutant(s)
        m.equivalent = eq.get(s.id)
        if m.equivalent is None or include_equivalent:
            out.append(m)
    return sorted(out, key=lambda m: m.name)


def sample(items, n, seed):
    return sorted(random.Random(seed).sample(items, min(n, len(items))), key=lambda m: m.name)


def window(items, k, n):
    """Window k (0-based) of n: every n-th item from k, so windows cover the files evenly."""
    return items[k % n::n]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--source-dir", default=os.path.normpath(os.path.join(HERE, "..", "..")))
    ap.add_argument("--list", action="store_true", help="every site: id, place, change, tests")
    ap.add_argument("--count", action="store_true", help="sites by file and kind")
    ap.add_argument("--show", nargs="*", help="these ids: place, change, line")
    ap.add_argument("--check-equivalent", action="store_true",
                    help="every id of equivalent.txt is still a site (exit 1 otherwise)")
    ap.add_argument("--files", action="store_true",
                    help="the files mutated: the runtime's from plugin_runtime/runtime.list, then generator/")
    args = ap.parse_args(argv)
    stale_keys = unlisted_test_keys(args.source_dir)
    if stale_keys:
        print("systematic.py: TESTS_BY_FILE names files %s does not list: %s" % (RUNTIME_LIST, " ".join(stale_keys)),
              file=sys.stderr)
        return 2
    if args.files:
        print("\n".join(source_files(args.source_dir)))
        return 0
    sites = all_sites(args.source_dir)
    eq = equivalent_ids()
    if args.check_equivalent:
        ids = {s.id for s in sites}
        stale = sorted(set(eq) - ids)
        for sid in stale:
            print("equivalent.txt: %s is no longer a site (its line changed): triage it again" % sid)
        print("%d equivalent ids, %d stale" % (len(eq), len(stale)))
        return 1 if stale else 0
    if args.show:
        for s in sites:
            if s.id in args.show:
                print("%s %s (%s)%s\n    %s" % (s.id, s.describe(), s.kind, " EQUIVALENT" if s.id in eq else "",
                                              s.text.strip()))
        return 0
    if args.count:
        by_file = collections.Counter(s.file for s in sites)
        by_kind = collections.Counter(s.kind for s in sites)
        for f, c in sorted(by_file.items()):
            print("%5d %s" % (c, f))
        print("%5d sites (%s); %d listed equivalent" % (
            len(sites), ", ".join("%s %d" % kv for kv in sorted(by_kind.items())), len(set(eq) & {s.id for s in sites})))
        return 0
    for s in sites:
        print("%s %-52s %-10s %s%s" % (s.id, s.describe(), s.kind, " ".join(tests_for(s.file)),
                                      "  [equivalent]" if s.id in eq else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Mutation check: does the test suite kill small, realistic bugs in the runtime and
the generator?  Python 3 stdlib only.

    run_mutants.py --source-dir .  [--only NAME ...] [--jobs 2] [--budget SECONDS] [--keep] [--list]

Every tests/mutation/mutants/*.mut file is one mutant: in one source file, replace
one snippet that occurs there exactly once by another (format: tests/mutation/README.md).
The source tree (as it is on disk, uncommitted edits included; no build/ and no .git)
is copied into a temporary folder, configured and built once (dissgen, unit_tests,
dissgen_runtime); the checkout itself is never touched.  Then for each mutant: the
mutated file is written, the build is brought up to date (only what the file feeds),
and the mutant's tests run in the order given until one fails: the mutant is KILLED.
When all pass it SURVIVED.  A test that skipped (exit 77, a "SKIPPED:" line, a skipped
gtest or unittest) decides nothing: when every test of a mutant skipped it is NOT DECIDED,
which fails the check like a survivor.  A mutant whose snippet is not found exactly once, or that
does not build, is INVALID (the code moved on: refresh the mutant).  A kill counts only
if the killing test passes on the unmutated copy: the first time a test kills a mutant, it
runs once there (the check stops when it fails).  --work DIR keeps the copy and its build
for the next run.  A test's time limit is max(300 s, 3 x its own time on the unmutated
copy): a test that runs out of the 300 s first is timed there, then run on the mutant again.
The check refuses to start when a mutant's tests need the corpus (../shared/corpus) and it
is absent.

--budget SECONDS (CI: the whole check must fit its time limit) starts no mutant once
that much time has gone; the mutants then run from a place in the list that the source
tree's commit picks, so that successive commits cover all of them, and those not run
are listed.  Without --budget (the default, and before a merge) every mutant runs.

Exit status: 0 when every mutant is killed, 1 otherwise, 77 (skip) without tshark.
"""

import argparse
import fnmatch
import glob
import hashlib
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import systematic  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
COVERAGE_MAP = os.path.join(HERE, "coverage.json")   # coverage_map.py writes it
SKIP_CODE = 77
TEST_TIMEOUT = 300   # seconds per test run: a mutant that hangs the decoder is killed by it
TIMEOUT_FACTOR = 3   # ... unless the test's unmutated run took more than a third of it
BASELINE_TIMEOUT = 3600   # the unmutated run is the yardstick: it gets all the time it needs


def integration_script(src, script):
    """tests/integration/AREA/SCRIPT: the scripts live by what they test (language/, ethercat/, ...)."""
    found = glob.glob(os.path.join(src, "tests", "integration", "*", script))
    if len(found) > 1:
        raise SystemExit("two integration scripts named %s: %s" % (script, " ".join(sorted(found))))
    # none: a placeholder source folder ("SRC", to read the command's shape)
    return found[0] if found else os.path.join(src, "tests", "integration", script)


def integration(script, *extra):
    def command(src, build):
        return [sys.executable, integration_script(src, script),
                "--dissgen", os.path.join(build, "bin", "dissgen"), "--source-dir", src] + list(extra)
    return command


def unit(gtest_filter):
    def command(src, build):
        return [os.path.join(build, "bin", "unit_tests"), "--gtest_brief=1", "--gtest_filter=" + gtest_filter]
    return command


# The runner builds dissgen, unit_tests and the runtime; a test that also reads the plugins
# CMake builds from rules/ (build/plugins/) gets them built first, from the copy as it is.
BUILD_CMAKE_PLUGINS = ("import os, subprocess, sys\n"
                       "r = subprocess.run(['cmake', '--build', sys.argv[1], '--target', 'dissgen_enip',\n"
                       "                    'dissgen_ethercat'], stdout=subprocess.DEVNULL)\n"
                       "if r.returncode:\n"
                       "    sys.exit('cannot build the CMake plugins')\n"
                       "os.execv(sys.argv[2], sys.argv[2:])\n")


def with_cmake_plugins(test):
    def command(src, build):
        return [sys.executable, "-c", BUILD_CMAKE_PLUGINS, build] + test(src, build)
    return command


def cli(script, *extra):
    """A script of tests/cli/ run on the copy's dissgen; "{src}" in `extra` is the copy."""
    def command(src, build):
        return [sys.executable, os.path.join(src, "tests", "cli", script),
                "--dissgen", os.path.join(build, "bin", "dissgen")] + [e.format(src=src) for e in extra]
    return command


def corpus_differential(src, build):
    return integration("ecat_differential.py", "--corpus",
                       os.path.join(src, "..", "shared", "corpus", "ethercat"))(src, build)


# The tests a mutant may name, each short (seconds), each a real test of the suite.
# Golden files are not among them: they record the emitter's output and a changed
# output is regenerated on purpose, so a mutant must be killed by behaviour.
# Every integration script, and every test of it (a unittest method, chosen by its name
# "Class.test_name" or by "-k pattern"), is run by a name here (check_coverage): a bug only
# one test catches must be able to name that test.
TESTS = {
    "unit": unit("-Golden*"),
    "help_matches_man": cli("help_vs_man.py", "--man", "{src}/packaging/dissgen.1"),
    "usage_errors": cli("usage_errors.py"),
    "rules_err": unit("Files/RulesErr.*:Files/RulesOk.*:RuleFolders.*"),
    "field_types": unit("FieldType.*:Emit.*:ListFields.*:TypedValues.*:DatesAndGuids.*"),
    "widths": integration("test_widths.py"),
    "bit_fields": integration("test_bit_fields.py"),
    "everything": integration("test_everything.py"),
    "malformed": integration("test_malformed.py"),
    "enip": integration("test_enip.py"),
    "enip_pipelined": integration("test_enip.py", "PipelinedReplies"),
    "profinet": integration("test_profinet.py"),
    "powerlink": integration("test_powerlink.py"),
    "goose": integration("test_goose.py"),
    "validity": integration("test_validity.py"),
    "validity_unit": unit("Validity.*"),
    "loading": integration("test_plugin_loading.py"),
    "esi": unit("Esi*:Files/EsiErr.*:Design.*:Eni.*:Files/NetworkErr.*:BusTables.*:ManualBus.*:-*Golden*"),
    "typed_values": integration("test_typed_values.py"),
    "dates_guids_shared_names": integration("test_dates_guids_shared_names.py"),
    "addresses": integration("test_addresses.py"),
    "info_column": integration("test_info_column.py"),
    "empty_summaries": integration("test_info_column.py", "EmptySummaries.test_nothing_where_nothing_is_summarised"),
    "summary_across_repeats": integration("test_info_column.py", "SummaryAcrossRepeats.test_last_value_of_the_instance"),
    "layout": integration("test_layout.py"),
    "bus_tables": integration("test_bus_tables.py"),
    "bus_identities": integration("test_bus_model.py", "TestBusModel.test_slave_identities_as_the_corpus_lists_them"),
    "bus_network": integration("test_bus_model.py", "TestBusModel.test_network_check_against_four_designs"),
    "bus_wkc": integration("test_bus_model.py", "TestBusModel.test_expected_working_counters"),
    "bus_stats": integration("test_bus_model.py", "TestBusModel.test_per_slave_statistics"),
    "bus_eni": integration("test_bus_model.py", "TestBusModel.test_eni_cyclic_commands_expected_wkc"),
    "bus_slave_line": integration("test_bus_model.py", "TestBusModel.test_one_line_per_slave_details_filterable"),
    "bus_pdo": integration("test_bus_model.py", "TestBusModel.test_process_data_by_name"),
    "bus_station_bytes": integration("test_bus_model.py",
                                     "TestBusModel.test_station_address_and_alias_a_byte_at_a_time"),
    "bus_coe": integration("test_bus_model.py", "-k", "test_process_data_as_mapped_over_coe_"),
    "bus_signed": integration("test_bus_model.py", "TestBusModel.test_signed_entries_and_a_count_alone",
                              "TestBusModel.test_default_pdos_of_a_configured_slave_are_its_own"),
    "pairing": integration("test_pairing.py", "--quick"),
    "pairing_full": integration("test_pairing.py"),
    "esc_commands": integration("test_esc_commands.py"),
    "ecat_figures": integration("test_ecat_figures.py"),
    "report": integration("test_report.py"),
    "report_cycles": integration("test_report_cycles.py"),
    "edges_handoff": integration("test_edges.py", "TestEdges.test_handoff_gives_the_other_dissector_the_leaf_only"),
    "edges_peek": integration("test_edges.py", "TestEdges.test_peek_at_shifted_bit_group_members"),
    "edges_offsets": integration("test_edges.py", "TestEdges.test_offsets_from_enclosing_containers"),
    "edges_message_tail": integration("test_edges.py", "TestEdges.test_bytes_after_the_message"),
    "edges_no_padding": integration("test_edges.py", "TestEdges.test_protocol_without_padding"),
    "malformed_skip": integration("test_malformed_skip.py"),
    "snapshot_length": integration("test_snapshot_length.py"),
    "quiet": integration("test_quiet.py"),
    "live_capture": integration("test_live_capture.py"),
    "differential": integration("ecat_differential.py", "--frames", "2000", "--max-datagrams", "20",
                                "--malformed", "200"),
    "corpus_differential": corpus_differential,
    "transactions": integration("test_transactions.py"),
    "two_clients": integration("test_transactions.py", "TestTwoClients.test_each_response_answers_its_own_client",
                               "TestServerRequestsOnTwoConnections.test_each_connection_pairs_apart",
                               "TestGroupAddressed", "TestGroupRequestManyAnswers"),
    "computed": integration("test_computed.py"),
    "learned": integration("test_learned.py"),
    "varint": integration("test_varint.py"),
    "learned_layout": integration("test_learned_layout.py"),
    "learned_ranges": integration("test_learned_ranges.py"),
    "rule_findings": integration("test_rule_findings.py"),
    "rule_cycles": integration("test_rule_cycles.py"),
    "small_count": integration("test_rule_cycles.py", "TestSmallCount"),
    "message_edges": integration("test_message_edges.py"),
    "polled_cycles": integration("test_polled_cycles.py"),
    "overlays": integration("test_overlays.py"),
    "request_context": integration("test_request_context.py"),
    "request_by_position": integration("test_request_context.py", "TestRequestByPosition"),
    "losses": integration("test_losses.py"),
    "losses_corpus": integration("test_losses.py", "--with-corpus"),
    "findings": integration("test_findings.py"),
    "corpus_padding": integration("test_corpus_padding.py"),
    "plugin_contents": with_cmake_plugins(integration("test_plugin_contents.py")),
    "reserved_names": integration("test_reserved_names.py"),
    "cycles": integration("test_cycles.py"),
    "cycles_mailbox": integration("test_cycles.py", "TestCycles.test_mailbox_and_polls_are_not_cycles"),
    "cycles_late_returns": integration("test_cycles.py", "TestCycles.test_returns_after_many_frames_sent"),
    "cycles_declared": integration("test_cycles.py", "TestCyclesAsDeclared.test_mailbox_traffic_cyclic_from_its_third_frame",
                                   "TestCyclesUndeclared.test_no_cycle_without_the_declaration"),
    "compiled_walk": integration("test_compiled_walk.py", "CompiledWalk.test_every_rule_file"),
    "compiled_walk_corpus": integration("test_compiled_walk.py", "CompiledWalk.test_shipped_rules_on_samples_and_corpus"),
}


def selected(run, tests):
    """The tests ("Class.test_name") of a script that its arguments `run` select: those named
    (Class.test_name), those matching a -k pattern (as unittest matches them), else all."""
    names = [a for a in run if re.match(r"^[A-Za-z_]\w*\.test_\w+$", a)]
    patterns = [run[i + 1] for i, a in enumerate(run[:-1]) if a == "-k"]
    if not names and not patterns:
        return set(tests)
    patterns = [p if "*" in p else "*%s*" % p for p in patterns]
    return {t for t in tests if t in names or any(fnmatch.fnmatchcase("__main__." + t, p) for p in patterns)}


def check_coverage(source_dir):
    """What no TESTS name reaches: integration scripts not named, their tests (unittest
    methods, "Class.test_name") that no name runs, and names that select no test."""
    commands = [c("SRC", "BUILD") for c in TESTS.values()]
    folder = os.path.join(source_dir, "tests", "integration")
    missing = []
    for path in sorted(glob.glob(os.path.join(folder, "*", "test_*.py"))) + [integration_script(source_dir, "ecat_differential.py")]:
        script = os.path.basename(path)
        runs = [c[c.index(x) + 1:] for c in commands for x in c if x.endswith("/" + script)]
        if not runs:
            missing.append(script)
            continue
        tests, cls = [], None
        for line in open(path, encoding="utf-8"):
            m = re.match(r"^class (\w+)\(.*unittest\.TestCase", line)
            cls = m.group(1) if m else (None if re.match(r"^\S", line) else cls)
            m = re.match(r"^    def (test_\w+)\(", line)
            if cls and m:
                tests.append("%s.%s" % (cls, m.group(1)))
        reached = set()
        for run in runs:
            these = selected(run, tests)
            if tests and not these:
                missing.append("%s %s (selects no test)" % (script, " ".join(run)))
            reached |= these
        missing += ["%s %s" % (script, t) for t in tests if t not in reached]
    return missing


class Mutant:
    def __init__(self, path):
        self.path = path
        self.name = os.path.splitext(os.path.basename(path))[0]
        self.why, self.file, self.tests, self.find, self.replace = [], None, [], None, None
        self.problem = None
        try:
            self._parse(open(path, encoding="utf-8").read())
        except ValueError as e:
            self.problem = "%s: %s" % (path, e)

    def _parse(self, text):
        m = re.search(r"^<<<<\n(.*?)^====\n(.*?)^>>>>$", text, re.S | re.M)
        if not m:
            raise ValueError("no <<<< snippet ==== replacement >>>> block")
        # The snippet is the text between the marker lines, without the last line break.
        self.find, self.replace = m.group(1)[:-1], m.group(2)[:-1]
        if not self.find:
            raise ValueError("empty snippet")
        for line in text[:m.start()].splitlines():
            if line.startswith("#"):
                self.why.append(line[1:].strip())
            elif line.startswith("file:"):
                self.file = line[5:].strip()
            elif line.startswith("tests:"):
                self.tests = line[6:].split()
            elif line.strip():
                raise ValueError("unexpected line %r" % line)
        if not self.file or not self.tests:
            raise ValueError("needs 'file:' and 'tests:' lines")
        unknown = [t for t in self.tests if t not in TESTS]
        if unknown:
            raise ValueError("unknown tests %s (known: %s)" % (unknown, " ".join(sorted(TESTS))))
        if self.find == self.replace:
            raise ValueError("the replacement equals the snippet")

    def mutate(self, original):
        """The mutated text of the file, or raise ValueError when the snippet is not there once."""
        n = original.count(self.find)
        if n != 1:
            raise ValueError("the snippet occurs %d times in %s (expected exactly once): refresh the mutant"
                             % (n, self.file))
        return original.replace(self.find, self.replace)


# What one run of a test says about the code it ran.
PASS, FAIL, SKIP, TIMEOUT = "pass", "fail", "skip", "timeout"

# The marks a skip leaves: our scripts' "SKIPPED:" line, gtest's "[  SKIPPED ]" and
# unittest's "OK (skipped=N)" / "FAILED (..., skipped=N)".
SKIP_MARKS = re.compile(r"^SKIPPED:.*$|^\[  SKIPPED \].*$|^(?:OK|FAILED) \(.*skipped=\d+.*\)$", re.M)


def classify(returncode, output, timed_out=False):
    """(kind, reason) of one test run. A failure is a failure whatever else skipped; a
    pass that skipped anything (exit 77 included: a script that skipped a part it cannot
    run here, e.g. one needing the corpus) is a SKIP, since the skipped part might have
    been the one to fail."""
    if timed_out:
        return TIMEOUT, "timed out"
    if returncode not in (0, SKIP_CODE):
        return FAIL, "exit status %d" % returncode
    marks = SKIP_MARKS.findall(output or "")
    if returncode == SKIP_CODE or marks:
        return SKIP, (marks[0].strip() if marks else "exit status 77")
    return PASS, ""


def time_limit(test, baseline_secs):
    """Seconds test may take on a mutant: a slow machine makes every test slower, so the
    limit grows with the test's own unmutated time when that is known."""
    return max(TEST_TIMEOUT, TIMEOUT_FACTOR * baseline_secs.get(test, 0))


def run(cmd, cwd=None, timeout=None, log=None):
    """(kind, seconds, output, reason) of one test run (classify); output to the log file too."""
    start = time.monotonic()
    try:
        p = subprocess.run(cmd, cwd=cwd, timeout=timeout, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True, errors="replace")
        kind, reason = classify(p.returncode, p.stdout)
        out = p.stdout
    except subprocess.TimeoutExpired as e:
        out = (e.stdout or "") if isinstance(e.stdout, str) else ""
        out += "\n(timed out after %ss)\n" % timeout
        kind, reason = classify(None, out, timed_out=True)
    if log:
        with open(log, "a", encoding="utf-8") as fh:
            fh.write("$ %s\n%s\n" % (" ".join(cmd), out))
    return kind, time.monotonic() - start, out, reason


def run_command(cmd, log=None):
    """(ok, seconds, output) of a build step: anything but exit 0 is a failure."""
    kind, secs, out, _ = run(cmd, log=log)
    return kind == PASS, secs, out


def copy_tree(source, dest):
    """Copy source into dest, without build*/ and .git; a file already there with the same
    bytes is left alone (its time too), so that a kept build stays up to date."""
    def ignore(folder, names):
        if os.path.abspath(folder) == os.path.abspath(source):
            return [n for n in names if n.startswith("build") or n == ".git"]
        return [n for n in names if n == "__pycache__"]

    def copy_if_changed(a, b):
        if os.path.isfile(b) and not os.path.islink(b):
            with open(a, "rb") as x, open(b, "rb") as y:
                if x.read() == y.read():
                    return b
        return shutil.copy2(a, b)
    shutil.copytree(source, dest, symlinks=True, ignore=ignore, copy_function=copy_if_changed, dirs_exist_ok=True)


def build(src, build_dir, jobs, log):
    return run_command(["cmake", "--build", build_dir, "-j%d" % jobs, "--target", "dissgen", "unit_tests",
                        "dissgen_runtime"], log=log)


def commit_number(source_dir):
    """The source tree's commit as a number (0 outside a git checkout)."""
    try:
        head = subprocess.run(["git", "-c", "safe.directory=*", "-C", source_dir, "rev-parse", "HEAD"],
                              capture_output=True, text=True, timeout=30).stdout.strip()
        return int(head[:8], 16) if head else 0
    except (OSError, ValueError, subprocess.SubprocessError):
        return 0


def tail(text, lines=15):
    return "\n".join("    " + l for l in text.strip().splitlines()[-lines:])


def run_baseline(t, src, build_dir, jobs, log):
    """(kind, seconds) of test t on the unmutated copy (rebuilt first)."""
    ok, _, out = build(src, build_dir, jobs, log)
    kind, secs, out, _ = run(TESTS[t](src, build_dir), cwd=build_dir, timeout=BASELINE_TIMEOUT, log=log) \
        if ok else (FAIL, 0, out, "")
    print("baseline %-13s %s (%.0fs)" % (t, kind, secs), flush=True)
    if kind in (FAIL, TIMEOUT):
        print("the unmutated tree fails '%s': fix that first\n%s" % (t, tail(out)))
    return kind, secs


def decide(tests, on_mutant, on_baseline, baseline_secs):
    """The verdict of a mutant from its tests' runs: (verdict, detail), or None when a test
    that matters fails on the unmutated copy.  on_mutant(t, limit) runs t on the mutant,
    (kind, reason); on_baseline(t) on the unmutated copy, (kind, seconds), and fills
    baseline_secs (test -> seconds), which time_limit reads.

    A failure kills only if the test passes unmutated (measured once per test).  A timeout
    of a test never timed unmutated may be the machine's slowness: the test is timed
    unmutated and run on the mutant again when its limit grew.  A skip decides nothing."""
    def measured(t):
        if t not in baseline_secs:
            kind, secs = on_baseline(t)
            if kind in (FAIL, TIMEOUT):
                return False
            baseline_secs[t] = secs
        return True

    passed, skipped = [], []
    for t in tests:
        limit = time_limit(t, baseline_secs)
        kind, reason = on_mutant(t, limit)
        if kind == TIMEOUT and t not in baseline_secs:
            if not measured(t):
                return None
            if time_limit(t, baseline_secs) > limit:
                kind, reason = on_mutant(t, time_limit(t, baseline_secs))
        if kind in (FAIL, TIMEOUT):
            if not measured(t):
                return None
            return "KILLED", "by %s%s" % (t, " (timed out)" if kind == TIMEOUT else "")
        (skipped if kind == SKIP else passed).append((t, reason))
    said = "; skipped (decides nothing): " + ", ".join("%s (%s)" % s for s in skipped) if skipped else ""
    if passed:
        return "SURVIVED", "passed: " + " ".join(t for t, _ in passed) + said
    return "NOT DECIDED", "every test skipped" + said[len("; skipped (decides nothing)"):]


class Planted:
    """The copy with mutant m's file written, built on demand: the tests of the mutant and
    the baseline runs of decide() take turns on the same copy."""

    def __init__(self, m, mutated, src, build_dir, jobs, log, original):
        self.m, self.mutated, self.original = m, mutated, original
        self.src, self.build_dir, self.jobs, self.log = src, build_dir, jobs, log
        self.path = os.path.join(src, m.file)
        self.current = None

    def _write(self, text):
        if self.current != text:
            with open(self.path, "w", encoding="utf-8") as fh:
                fh.write(text)
            self.current = text

    def build_mutant(self):
        """(ok, output) of building the copy with the mutant in."""
        self._write(self.mutated)
        ok, _, out = build(self.src, self.build_dir, self.jobs, self.log)
        return ok, out

    def on_mutant(self, t, limit):
        if self.current != self.mutated:
            ok, out = self.build_mutant()
            if not ok:   # it built before: the same file, the same build
                return FAIL, "does not rebuild"
        kind, _, _, reason = run(TESTS[t](self.src, self.build_dir), cwd=self.build_dir, timeout=limit,
                                 log=self.log)
        return kind, reason

    def on_baseline(self, t):
        self.restore()
        return run_baseline(t, self.src, self.build_dir, self.jobs, self.log)

    def restore(self):
        self._write(self.original)


def judge(m, src, build_dir, jobs, log, originals, baseline_secs, no_baseline=False):
    """Plant mutant m in the copy, rebuild, run its tests (decide); the copy is restored
    after.  Returns (verdict, detail), or None when a test fails on the unmutated copy."""
    if getattr(m, "equivalent", None) is not None:
        return "EQUIV", "not run (equivalent.txt): " + m.equivalent
    if m.problem:
        return "INVALID", m.problem
    path = os.path.join(src, m.file)
    if m.file not in originals:
        originals[m.file] = open(path, encoding="utf-8").read() if os.path.isfile(path) else None
    if originals[m.file] is None:
        return "INVALID", "no file %s: refresh the mutant" % m.file
    try:
        mutated = m.mutate(originals[m.file])
    except ValueError as e:
        return "INVALID", str(e)
    planted = Planted(m, mutated, src, build_dir, jobs, log, originals[m.file])
    try:
        ok, out = planted.build_mutant()
        if not ok:
            return "INVALID", "does not build: refresh the mutant\n" + tail(out)
        on_baseline = (lambda t: (PASS, 0)) if no_baseline else planted.on_baseline
        return decide(m.tests, planted.on_mutant, on_baseline, baseline_secs)
    finally:
        planted.restore()


def unit_suites_reading_corpus(source_dir):
    """gtest suite names defined in unit test files that read the corpus."""
    suites = set()
    for path in glob.glob(os.path.join(source_dir, "tests", "unit", "*.cpp")):
        text = open(path, encoding="utf-8", errors="replace").read()
        if "corpus" in text:
            suites |= set(re.findall(r"^TEST(?:_F|_P)?\((\w+)", text, re.M))
    return suites


def needs_corpus(test, source_dir):
    """Whether test reads ../shared/corpus: an integration script that names the corpus,
    or a gtest filter that selects a suite of a unit test file that does."""
    command = TESTS[test]("SRC", "BUILD")
    for arg in command:
        if arg.startswith("SRC/tests/integration/"):
            path = integration_script(source_dir, os.path.basename(arg))
            return "corpus" in open(path, encoding="utf-8").read()
        if arg.startswith("--gtest_filter="):
            positive = arg[len("--gtest_filter="):].split("-")[0]
            patterns = [p for p in positive.split(":") if p] or ["*"]
            return any(fnmatch.fnmatchcase(s + ".x", p) or fnmatch.fnmatchcase(s + "/x.x", p)
                       for s in unit_suites_reading_corpus(source_dir) for p in patterns)
    return False


def corpus_dir(source_dir):
    return os.path.normpath(os.path.join(os.path.abspath(source_dir), "..", "shared", "corpus"))


def corpus_missing(mutants, source_dir, corpus=None):
    """The tests of mutants that read the corpus (../shared/corpus) when it is absent (else [])."""
    if os.path.isdir(corpus or corpus_dir(source_dir)):
        return []
    return sorted({t for m in mutants for t in m.tests if needs_corpus(t, source_dir)})


def decidable_without_corpus(mutants, source_dir, missing):
    """The mutants none of whose tests is in `missing` (those that read the absent corpus
    would skip a part of their cases, so a mutant only they kill would seem to survive)."""
    return [m for m in mutants if not set(m.tests) & set(missing)]


def changed_lines(original, mutated):
    """(first, last) line numbers of original that mutated changes."""
    p = 0
    while p < min(len(original), len(mutated)) and original[p] == mutated[p]:
        p += 1
    e = 0
    while e < min(len(original), len(mutated)) - p and original[-1 - e] == mutated[-1 - e]:
        e += 1
    first, end = original.count("\n", 0, p) + 1, len(original) - e
    return first, (original.count("\n", 0, end - 1) + 1 if end > p else first)   # end - 1: the last byte changed


def load_coverage(path):
    """The map coverage_map.py writes (test -> runtime file -> executed lines), or None."""
    if not os.path.isfile(path):
        return None
    with open(path, encoding="utf-8") as fh:
        return json.load(fh)


CONSTANT = re.compile(r"^\s*(static\s+)?(const|constexpr)\s")


def tests_running(coverage, file, lines, text):
    """Names of the tests that the coverage map says execute a line of lines in file
    (every test running file whose lines were recorded for another text of it, since
    then: its line numbers may have moved). Each test keeps the hashes of the sources it
    was mapped with (its "sources"; maps before that have only the map's)."""
    if not coverage or file not in coverage.get("sources", {}):
        return []
    now = hashlib.sha256(text.encode("utf-8")).hexdigest()
    first, last = lines
    runs_file = [t for t, row in coverage.get("tests", {}).items() if t in TESTS and file in row["lines"]]

    def moved(t):
        return coverage["tests"][t].get("sources", coverage["sources"]).get(file) != now
    running = [t for t in runs_file
               if moved(t) or any(first <= l <= last for l in coverage["tests"][t]["lines"][file])]
    # A constant is run through its uses, and gcov counts no line for its definition:
    # every test of its file, then.
    if not running and any(CONSTANT.match(l) for l in text.splitlines()[first - 1:last]):
        return runs_file
    return running


def choose_tests(m, coverage, source_dir):
    """The mutant's own tests and every test the coverage map says executes the mutated
    lines, cheapest (by the map's seconds) first; tests the map has not timed keep their
    order, after those."""
    if getattr(m, "problem", None) or not m.file:
        return m.tests
    try:
        original = open(os.path.join(source_dir, m.file), encoding="utf-8").read()
        lines = changed_lines(original, m.mutate(original))
    except (OSError, ValueError):
        return m.tests   # judge() reports it INVALID
    chosen = list(dict.fromkeys(m.tests + tests_running(coverage, m.file, lines, original)))
    timed = coverage.get("tests", {}) if coverage else {}
    return sorted(chosen, key=lambda t: (timed[t]["seconds"], 0) if t in timed else (float("inf"), chosen.index(t)))


def pick_window(spec, count, source_dir):
    """--window K/N: (k, n); K may be 'commit' (the source tree's commit picks it)."""
    m = re.match(r"^(\d+|commit)/(\d+)$", spec)
    if not m or int(m.group(2)) < 1:
        raise SystemExit("--window wants K/N (K a number below N, or 'commit'), not %r" % spec)
    n = int(m.group(2))
    k = commit_number(source_dir) % n if m.group(1) == "commit" else int(m.group(1))
    if k >= n:
        raise SystemExit("--window %s: K must be below N" % spec)
    return k, n


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--source-dir", default=os.path.normpath(os.path.join(HERE, "..", "..")))
    ap.add_argument("--mutants", default=os.path.join(HERE, "mutants"), help="folder of *.mut files")
    ap.add_argument("--only", nargs="*", help="mutant names (file names without .mut, or systematic ids) to run")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--keep", action="store_true", help="keep the temporary copy (and its log)")
    ap.add_argument("--work", metavar="DIR", help="copy and build in DIR and keep them (a later run with the same "
                    "DIR rewrites only the files that changed, and rebuilds only what they feed)")
    ap.add_argument("--list", action="store_true", help="list the mutants and their tests, run nothing")
    ap.add_argument("--check", action="store_true", help="only check that every mutant still applies")
    ap.add_argument("--no-baseline", action="store_true", help="skip the run on the unmutated copy")
    ap.add_argument("--budget", type=float, default=0, metavar="SECONDS",
                    help="start no mutant after this many seconds (0: run all)")
    ap.add_argument("--without", nargs="*", default=[], metavar="TEST",
                    help="leave these tests out (to measure what the others kill)")
    ap.add_argument("--coverage", default=COVERAGE_MAP, metavar="FILE",
                    help="the coverage map that adds the tests executing a mutated line (coverage_map.py)")
    ap.add_argument("--no-coverage", action="store_true",
                    help="run only the tests each mutant names (to measure what the map adds)")
    ap.add_argument("--systematic", action="store_true",
                    help="the generated mutants of systematic.py instead of the hand-written ones")
    ap.add_argument("--sample", type=int, default=0, metavar="N", help="a random sample of N of the mutants")
    ap.add_argument("--seed", type=int, default=1, help="the sample's random seed")
    ap.add_argument("--window", metavar="K/N",
                    help="every N-th mutant from the K-th (in name order); K 'commit': the commit picks it")
    ap.add_argument("--extra-systematic", type=int, default=0, metavar="N",
                    help="after the hand-written mutants, N systematic ones (a window the commit picks); "
                         "their survivors are reported, not failed")
    ap.add_argument("--extra-budget", type=float, default=300, metavar="SECONDS",
                    help="start no extra systematic mutant after this many more seconds")
    args = ap.parse_args(argv)

    if args.systematic:   # the equivalent ones too, so that samples and windows stay put
        mutants = systematic.mutants(args.source_dir, include_equivalent=True)
    else:
        mutants = [Mutant(p) for p in sorted(glob.glob(os.path.join(args.mutants, "*.mut")))]
    if args.only:
        missing = set(args.only) - {m.name for m in mutants}
        if missing and not args.systematic:   # a systematic id given without --systematic
            generated = {m.name: m for m in systematic.mutants(args.source_dir, include_equivalent=True)}
            mutants += [generated[n] for n in sorted(missing) if n in generated]
            missing = set(args.only) - {m.name for m in mutants}
        if missing:
            print("no such mutant: %s" % " ".join(sorted(missing)))
            return 2
        mutants = [m for m in mutants if m.name in args.only]
    if args.window:
        k, n = pick_window(args.window, len(mutants), args.source_dir)
        mutants = systematic.window(mutants, k, n)
    if args.sample:
        mutants = systematic.sample(mutants, args.sample, args.seed)
    extra = []
    if args.extra_systematic:
        generated = systematic.mutants(args.source_dir, include_equivalent=True)
        n = max(1, -(-len(generated) // args.extra_systematic))
        extra = systematic.window(generated, commit_number(args.source_dir) % n, n)[:args.extra_systematic]
    coverage = None if args.no_coverage else load_coverage(args.coverage)
    for m in mutants + extra:
        m.tests = [t for t in choose_tests(m, coverage, args.source_dir) if t not in args.without]
    if args.list:
        for m in mutants + extra:
            print("%-34s %-36s %s" % (m.name, m.path if args.systematic or m in extra else m.file,
                                      " ".join(m.tests)))
        return 0
    uncovered = check_coverage(args.source_dir)
    if uncovered:
        print("the TESTS table names no way to run: %s (add a name for each)" % ", ".join(uncovered))
        return 1
    unknown = sorted({t for tests in systematic.TESTS_BY_FILE.values() for t in tests} - set(TESTS))
    if unknown:
        print("systematic.TESTS_BY_FILE names tests the runner does not know: %s" % " ".join(unknown))
        return 1
    if args.check:
        bad = 0
        for m in mutants:
            try:
                if m.problem:
                    raise ValueError(m.problem)
                m.mutate(open(os.path.join(args.source_dir, m.file), encoding="utf-8").read())
            except (OSError, ValueError) as e:
                bad += 1
                print("INVALID  %s: %s" % (m.name, e))
        print("%d of %d mutants apply" % (len(mutants) - bad, len(mutants)))
        stale = systematic.main(["--source-dir", args.source_dir, "--check-equivalent"])
        return 1 if bad or stale else 0
    if args.budget and mutants:
        start = commit_number(args.source_dir) % len(mutants)
        mutants = mutants[start:] + mutants[:start]
    if shutil.which("tshark") is None:
        print("SKIPPED: tshark is not installed (the mutants' tests need it)")
        return SKIP_CODE
    without_corpus = corpus_missing(mutants + extra, args.source_dir)
    if without_corpus:
        # A checkout without ../shared (a clone on its own): the mutants that tests of the
        # corpus decide are left out, with a clear message, and the others run.
        kept = decidable_without_corpus(mutants, args.source_dir, without_corpus)
        extra = decidable_without_corpus(extra, args.source_dir, without_corpus)
        print("no corpus at %s: %d of %d mutants are left out, for their tests (%s) read it and "
              "would skip cases; put the corpus there to run them" % (
                  corpus_dir(args.source_dir), len(mutants) - len(kept), len(mutants), " ".join(without_corpus)))
        mutants = kept
        if not mutants and not extra:
            print("SKIPPED: every chosen mutant's tests read the corpus")
            return SKIP_CODE

    t0 = time.monotonic()
    work = os.path.abspath(args.work) if args.work else tempfile.mkdtemp(prefix="dissgen-mutation-")
    os.makedirs(work, exist_ok=True)
    src, build_dir, log = os.path.join(work, "src"), os.path.join(work, "build"), os.path.join(work, "log.txt")
    print("mutation check: %d mutants%s, copy and log in %s" % (
        len(mutants), " and %d systematic ones" % len(extra) if extra else "", work), flush=True)
    results, not_run = [], []
    try:
        copy_tree(os.path.abspath(args.source_dir), src)
        # Corpus tests look for ../shared/corpus beside the source tree: the copy gets the same.
        shared = os.path.join(os.path.abspath(args.source_dir), "..", "shared")
        if os.path.isdir(shared) and not os.path.lexists(os.path.join(work, "shared")):
            os.symlink(os.path.realpath(shared), os.path.join(work, "shared"))
        ok, secs, out = run_command(["cmake", "-S", src, "-B", build_dir, "-DCMAKE_BUILD_TYPE=RelWithDebInfo"],
                                    log=log)
        ok, bsecs, bout = build(src, build_dir, args.jobs, log) if ok else (False, 0, out)
        print("build of the copy: %s (%.0fs)" % ("ok" if ok else "FAILED", secs + bsecs), flush=True)
        if not ok:
            print(tail(bout))
            return 1

        baseline_secs = {}
        originals = {}
        extra_start = None
        for i, m in enumerate(mutants + extra):
            if m in extra:
                if extra_start is None:
                    extra_start = time.monotonic()
                    print("systematic mutants (window of %d):" % len(extra), flush=True)
                if time.monotonic() - extra_start > args.extra_budget:
                    not_run += [x for x in extra if x not in [r[0] for r in results]]
                    break
            elif args.budget and time.monotonic() - t0 > args.budget:
                not_run.append(m)
                continue
            start = time.monotonic()
            outcome = judge(m, src, build_dir, args.jobs, log, originals, baseline_secs, args.no_baseline)
            if outcome is None:
                return 1
            verdict, detail = outcome
            results.append((m, verdict))
            print("%-8s %-34s %s (%.0fs)" % (verdict, m.name, detail, time.monotonic() - start), flush=True)
    finally:
        if not args.keep and not args.work:
            shutil.rmtree(work, ignore_errors=True)

    killed = sum(1 for _, v in results if v == "KILLED")
    undecided = sum(1 for _, v in results if v == "NOT DECIDED")
    invalid = sum(1 for _, v in results if v == "INVALID")
    equivalent = sum(1 for _, v in results if v == "EQUIV")
    judged = len(results) - equivalent
    total = judged - invalid
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    survived = sum(1 for _, v in results if v == "SURVIVED")
    print("\nkilled %d of %d mutants (%.1f%%), %d survived, %d not decided (their tests skipped); besides, "
          "%d invalid (do not build) and %d equivalent not run; %.0fs in all, %.0fs of CPU (builds, tests, tshark)"
          % (killed, total, 100.0 * killed / max(total, 1), survived, undecided, invalid, equivalent,
             time.monotonic() - t0, cpu.ru_utime + cpu.ru_stime))
    for m, v in results:
        if v not in ("KILLED", "EQUIV"):
            print("  %s %s (%s): %s" % (v, m.name, m.file, " ".join(m.why)))
    if not_run:
        print("not run within the budget (%d): %s" % (len(not_run), " ".join(m.name for m in not_run)))
    # Generated mutants that do not compile are killed by the compiler: only hand-written ones
    # must apply and build.
    # The CI window of systematic mutants (--extra-systematic) reports its survivors without
    # failing the check: most generated sites are not triaged yet (tests/mutation/README.md).
    bad = [m for m, v in results if v == "NOT DECIDED" or (m not in extra and
           (v == "SURVIVED" or (v == "INVALID" and not isinstance(m, systematic.SiteMutant))))]
    if any(v == "SURVIVED" for m, v in results if m in extra):
        print("systematic survivors above: triage them (a test, or a line in equivalent.txt)")
    return 0 if judged and not bad else 1


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""The mutation runner's decisions on fake test outcomes: what a run of a test says
(classify), how long a test may take (time_limit), the verdict of a mutant from its
tests' runs (decide), the tests a coverage map adds (choose_tests), when the map is
stale (coverage_map.stale), which tests need the corpus (needs_corpus), and that no
table names a key twice."""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run_mutants as rm  # noqa: E402
import coverage_map  # noqa: E402

SOURCE_DIR = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


class Fake:
    """Test outcomes by name: mutant[t] is a list of (kind, reason) given in turn,
    baseline[t] a (kind, seconds); every call is recorded."""

    def __init__(self, mutant, baseline=None):
        self.mutant = {t: list(v) for t, v in mutant.items()}
        self.baseline = baseline or {}
        self.calls = []

    def on_mutant(self, t, limit):
        self.calls.append(("mutant", t, limit))
        return self.mutant[t].pop(0)

    def on_baseline(self, t):
        self.calls.append(("baseline", t))
        return self.baseline.get(t, (rm.PASS, 10))


def decide(fake, tests, secs=None):
    secs = {} if secs is None else secs
    return rm.decide(tests, fake.on_mutant, fake.on_baseline, secs)


class Classify(unittest.TestCase):
    def test_exit_status(self):
        self.assertEqual(rm.classify(0, "ok\n")[0], rm.PASS)
        self.assertEqual(rm.classify(1, "")[0], rm.FAIL)
        self.assertEqual(rm.classify(-11, "")[0], rm.FAIL)
        self.assertEqual(rm.classify(77, "")[0], rm.SKIP)
        self.assertEqual(rm.classify(None, "", timed_out=True)[0], rm.TIMEOUT)

    def test_skip_marks_on_a_zero_exit(self):
        self.assertEqual(rm.classify(0, "x\nSKIPPED: no corpus at /c\n"), (rm.SKIP, "SKIPPED: no corpus at /c"))
        self.assertEqual(rm.classify(0, "[  SKIPPED ] 3 tests, listed below:\n")[0], rm.SKIP)
        self.assertEqual(rm.classify(0, "Ran 4 tests in 1.0s\n\nOK (skipped=2)\n")[0], rm.SKIP)
        # the words alone, inside a line, are no skip
        self.assertEqual(rm.classify(0, "checked that nothing is SKIPPED: fine\nOK\n")[0], rm.PASS)

    def test_a_failure_stays_a_failure_when_parts_skipped(self):
        self.assertEqual(rm.classify(1, "FAILED (failures=1, skipped=2)\n")[0], rm.FAIL)


class TimeLimit(unittest.TestCase):
    def test_grows_with_the_baseline(self):
        self.assertEqual(rm.time_limit("quiet", {}), rm.TEST_TIMEOUT)
        self.assertEqual(rm.time_limit("quiet", {"quiet": 50}), rm.TEST_TIMEOUT)
        self.assertEqual(rm.time_limit("quiet", {"quiet": 305}), 3 * 305)


class Decide(unittest.TestCase):
    def test_killed_by_the_first_failure_after_a_passing_baseline(self):
        fake = Fake({"a": [(rm.PASS, "")], "b": [(rm.FAIL, "exit 1")], "c": [(rm.PASS, "")]})
        self.assertEqual(decide(fake, ["a", "b", "c"]), ("KILLED", "by b"))
        self.assertEqual(fake.calls, [("mutant", "a", 300), ("mutant", "b", 300), ("baseline", "b")])

    def test_a_failing_baseline_stops_the_check(self):
        fake = Fake({"b": [(rm.FAIL, "")]}, {"b": (rm.FAIL, 1)})
        self.assertIsNone(decide(fake, ["b"]))

    def test_the_baseline_runs_once_per_test(self):
        secs = {}
        for _ in range(2):
            fake = Fake({"b": [(rm.FAIL, "")]})
            self.assertEqual(decide(fake, ["b"], secs)[0], "KILLED")
        self.assertEqual([c for c in fake.calls if c[0] == "baseline"], [])

    def test_all_pass_survives(self):
        fake = Fake({"a": [(rm.PASS, "")], "b": [(rm.PASS, "")]})
        self.assertEqual(decide(fake, ["a", "b"]), ("SURVIVED", "passed: a b"))

    def test_all_skipped_is_not_decided(self):
        fake = Fake({"a": [(rm.SKIP, "SKIPPED: no corpus")], "b": [(rm.SKIP, "exit status 77")]})
        verdict, detail = decide(fake, ["a", "b"])
        self.assertEqual(verdict, "NOT DECIDED")
        self.assertIn("a (SKIPPED: no corpus)", detail)
        self.assertIn("b (exit status 77)", detail)

    def test_a_skip_is_never_a_pass(self):
        fake = Fake({"a": [(rm.PASS, "")], "b": [(rm.SKIP, "exit status 77")]})
        verdict, detail = decide(fake, ["a", "b"])
        self.assertEqual(verdict, "SURVIVED")
        self.assertTrue(detail.startswith("passed: a;"), detail)
        self.assertIn("skipped (decides nothing): b", detail)

    def test_a_skip_does_not_stop_the_search_for_a_killer(self):
        fake = Fake({"a": [(rm.SKIP, "x")], "b": [(rm.FAIL, "")]})
        self.assertEqual(decide(fake, ["a", "b"]), ("KILLED", "by b"))

    def test_a_baseline_that_skips_still_backs_a_kill(self):
        fake = Fake({"a": [(rm.FAIL, "")]}, {"a": (rm.SKIP, 5)})
        self.assertEqual(decide(fake, ["a"]), ("KILLED", "by a"))

    def test_timeout_of_a_slow_test_is_run_again_with_its_own_limit(self):
        # unmutated, the test takes 305 s: past 300 s is no kill; within 915 s it passes
        fake = Fake({"quiet": [(rm.TIMEOUT, ""), (rm.PASS, "")]}, {"quiet": (rm.PASS, 305)})
        secs = {}
        self.assertEqual(decide(fake, ["quiet"], secs), ("SURVIVED", "passed: quiet"))
        self.assertEqual(fake.calls, [("mutant", "quiet", 300), ("baseline", "quiet"), ("mutant", "quiet", 915)])
        self.assertEqual(secs, {"quiet": 305})

    def test_timeout_of_a_fast_test_kills(self):
        fake = Fake({"a": [(rm.TIMEOUT, "")]}, {"a": (rm.PASS, 4)})
        self.assertEqual(decide(fake, ["a"]), ("KILLED", "by a (timed out)"))
        self.assertEqual(fake.calls, [("mutant", "a", 300), ("baseline", "a")])

    def test_timeout_past_the_scaled_limit_kills(self):
        fake = Fake({"quiet": [(rm.TIMEOUT, ""), (rm.TIMEOUT, "")]}, {"quiet": (rm.PASS, 305)})
        self.assertEqual(decide(fake, ["quiet"]), ("KILLED", "by quiet (timed out)"))

    def test_known_baseline_sets_the_limit_at_once(self):
        fake = Fake({"quiet": [(rm.PASS, "")]})
        decide(fake, ["quiet"], {"quiet": 400})
        self.assertEqual(fake.calls, [("mutant", "quiet", 1200)])


class ChosenByCoverage(unittest.TestCase):
    TEXT = "line one\nline two\nline three\nline four\n"

    def coverage(self, text=None):
        return {"sources": {"plugin_runtime/x.cpp": rm.hashlib.sha256((text or self.TEXT).encode()).hexdigest()},
                "tests": {"overlays": {"seconds": 90, "lines": {"plugin_runtime/x.cpp": [2]}},
                          "widths": {"seconds": 20, "lines": {"plugin_runtime/x.cpp": [2, 3]}},
                          "edges_offsets": {"seconds": 5, "lines": {"plugin_runtime/x.cpp": [4]}}}}

    def test_changed_lines(self):
        self.assertEqual(rm.changed_lines(self.TEXT, self.TEXT.replace("two", "2")), (2, 2))
        self.assertEqual(rm.changed_lines(self.TEXT, self.TEXT.replace("two\nline three", "2\nline 3")), (2, 3))
        self.assertEqual(rm.changed_lines(self.TEXT, self.TEXT.replace("line four\n", "")), (4, 4))

    def test_tests_executing_the_line(self):
        self.assertEqual(sorted(rm.tests_running(self.coverage(), "plugin_runtime/x.cpp", (2, 2), self.TEXT)),
                         ["overlays", "widths"])
        self.assertEqual(rm.tests_running(self.coverage(), "plugin_runtime/x.cpp", (1, 1), self.TEXT), [])
        self.assertEqual(rm.tests_running(self.coverage(), "generator/y.cpp", (2, 2), self.TEXT), [])
        self.assertEqual(rm.tests_running(None, "plugin_runtime/x.cpp", (2, 2), self.TEXT), [])

    def test_a_constant_no_line_counts_takes_every_test_of_its_file(self):
        text = "line one\nconst gint width = 2;\nline three\nline four\n"
        coverage = self.coverage(text)
        coverage["tests"]["overlays"]["lines"]["plugin_runtime/x.cpp"] = [3]
        coverage["tests"]["widths"]["lines"]["plugin_runtime/x.cpp"] = [3]
        self.assertEqual(sorted(rm.tests_running(coverage, "plugin_runtime/x.cpp", (2, 2), text)),
                         ["edges_offsets", "overlays", "widths"])
        self.assertEqual(rm.tests_running(coverage, "plugin_runtime/x.cpp", (1, 1), text), [])

    def test_a_file_changed_since_the_map_takes_every_test_of_it(self):
        moved = "new first line\n" + self.TEXT
        self.assertEqual(sorted(rm.tests_running(self.coverage(), "plugin_runtime/x.cpp", (1, 1), moved)),
                         ["edges_offsets", "overlays", "widths"])

    def test_a_test_mapped_before_the_file_changed_is_taken_whole(self):
        # widths was mapped alone afterwards: its lines are current, the others' are not
        moved = "new first line\n" + self.TEXT
        coverage = self.coverage(moved)
        coverage["tests"]["widths"]["sources"] = dict(coverage["sources"])
        coverage["tests"]["widths"]["lines"]["plugin_runtime/x.cpp"] = [3, 4]
        for stale in ("overlays", "edges_offsets"):
            coverage["tests"][stale]["sources"] = self.coverage()["sources"]
        self.assertEqual(sorted(rm.tests_running(coverage, "plugin_runtime/x.cpp", (1, 1), moved)),
                         ["edges_offsets", "overlays"])
        self.assertEqual(sorted(rm.tests_running(coverage, "plugin_runtime/x.cpp", (3, 3), moved)),
                         ["edges_offsets", "overlays", "widths"])

    def test_own_tests_and_covering_ones_cheapest_first(self):
        class M:
            problem, file, tests = None, "plugin_runtime/x.cpp", ["everything", "overlays"]

            def mutate(self, text):
                return text.replace("two", "2")
        folder = rm.tempfile.mkdtemp()
        os.makedirs(os.path.join(folder, "plugin_runtime"))
        with open(os.path.join(folder, "plugin_runtime", "x.cpp"), "w") as fh:
            fh.write(self.TEXT)
        self.assertEqual(rm.choose_tests(M(), self.coverage(), folder), ["widths", "overlays", "everything"])
        self.assertEqual(rm.choose_tests(M(), None, folder), ["everything", "overlays"])
        rm.shutil.rmtree(folder)


class CoverageMapStale(unittest.TestCase):
    def current(self):
        sources = {f: "hash" for f in coverage_map.runtime_sources(SOURCE_DIR)}
        return {"sources": sources, "tests": {"overlays": {"seconds": 1, "lines": {}}},
                "unmapped": sorted(set(rm.TESTS) - {"overlays"})}

    def test_a_map_that_knows_everything_is_fresh(self):
        self.assertEqual(coverage_map.stale(SOURCE_DIR, self.current()), [])

    def test_a_test_added_since_is_stale(self):
        data = self.current()
        data["unmapped"].remove("widths")
        self.assertEqual(coverage_map.stale(SOURCE_DIR, data), ["test widths"])

    def test_a_source_added_since_is_stale(self):
        data = self.current()
        del data["sources"]["plugin_runtime/dissgen_walk.cpp"]
        self.assertEqual(coverage_map.stale(SOURCE_DIR, data), ["source plugin_runtime/dissgen_walk.cpp"])


class Tables(unittest.TestCase):
    def test_no_key_written_twice(self):
        """A dict literal keeps the last of two equal keys without a word: the first list of
        tests would be silently lost."""
        import ast
        for name, table in (("run_mutants.py", "TESTS"), ("systematic.py", "TESTS_BY_FILE")):
            with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), name), encoding="utf-8") as fh:
                tree = ast.parse(fh.read())
            for node in ast.walk(tree):
                if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == table for t in node.targets):
                    keys = [k.value for k in node.value.keys if isinstance(k, ast.Constant)]
                    self.assertEqual(sorted({k for k in keys if keys.count(k) > 1}), [], "%s: %s" % (name, table))


class Corpus(unittest.TestCase):
    def test_which_tests_read_the_corpus(self):
        self.assertTrue(rm.needs_corpus("pairing", SOURCE_DIR))
        self.assertTrue(rm.needs_corpus("esi", SOURCE_DIR))
        self.assertTrue(rm.needs_corpus("unit", SOURCE_DIR))
        self.assertFalse(rm.needs_corpus("widths", SOURCE_DIR))
        self.assertFalse(rm.needs_corpus("rules_err", SOURCE_DIR))

    def test_absent_corpus_names_the_tests_that_need_it(self):
        class M:
            tests = ["widths", "pairing"]
        absent = os.path.join(SOURCE_DIR, "no", "such", "corpus")
        self.assertEqual(rm.corpus_missing([M()], SOURCE_DIR, absent), ["pairing"])
        self.assertEqual(rm.corpus_missing([M()], SOURCE_DIR, SOURCE_DIR), [])

    def test_without_corpus_only_the_mutants_it_cannot_decide_are_left_out(self):
        class M:
            def __init__(self, *tests):
                self.tests = list(tests)
        plain, reads, both = M("widths"), M("pairing"), M("widths", "pairing")
        self.assertEqual(rm.decidable_without_corpus([plain, reads, both], SOURCE_DIR, ["pairing"]), [plain])
        self.assertEqual(rm.decidable_without_corpus([plain, reads], SOURCE_DIR, []), [plain, reads])


if __name__ == "__main__":
    unittest.main()

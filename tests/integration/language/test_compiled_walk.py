#!/usr/bin/env python3
"""Compiled walks decode what the table walk decodes, byte for byte.

The generator compiles each list of siblings into a function (generator/emit_cpp.cpp,
*_walk_*; plugin_runtime/dissgen_state.h dissect_child) and each summary into another
(*_summary_*); DISSGEN_TABLE_WALK=1 makes a plugin walk its tables and build summaries
from the pieces' table instead, as before. Both must give the same output: the whole
tree (-V) and the summary lines (no tree: quiet nodes stepped over), the tree with -2 (after a
first pass without one) and the summary lines in one pass, for every rule file of tests/rules/ and rules/ on the captures test_quiet.py builds for
it (each also cut short at up to 24 places), and for the shipped rules also on the
samples and the corpus captures (when ../shared/corpus is there).

    test_compiled_walk.py --dissgen build/bin/dissgen --source-dir .
"""
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
import test_quiet  # noqa: E402  (the captures of every rule file)
from tshark_env import TsharkEnv, run_unittests  # noqa: E402

ARGS = None

# Each walk is run where it shows what it did: building the tree after a first pass without
# one (-V -2: that first pass walks as the summary does, the second builds the tree), and
# without a tree (the summary lines). This test compares the two walks, not the passes:
# whether one pass and two agree is each construct's own test's job (test_pairing,
# test_snapshot_length, ...), and the walks differ only in how they walk, not by pass.
MODES = {"-V -2": ["-V", "-2"], "summary lines": []}


def install_alone(env, rules):
    """The plugin of `rules` as the only plugin tshark loads (a rule file whose names
    Wireshark's own plugins take, the paper's ECAT, decodes too)."""
    folder = os.path.join(env.home, "alone")
    epan = os.path.join(folder, env.abi, "epan")
    os.makedirs(epan, exist_ok=True)
    subprocess.run([ARGS.dissgen, "install", os.path.join(ARGS.source_dir, rules), "--dir", epan],
                   check=True, capture_output=True)
    subprocess.run(["chmod", "-R", "a+rX", env.home], check=True)
    return folder


class CompiledWalk(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        test_quiet.ARGS = ARGS  # its captures read the source folder
    def outputs(self, env, folder, capture, table_walk):
        base = env.env
        extra = {"WIRESHARK_PLUGIN_DIR": folder} if folder else {}
        if table_walk:
            extra["DISSGEN_TABLE_WALK"] = "1"
        env.env = lambda: dict(base(), **extra)
        try:
            cap = env.readable(capture)
            return [env.tshark(["-r", cap] + args).stdout for args in MODES.values()]
        finally:
            env.env = base

    def same(self, env, folder, capture, what):
        compiled = self.outputs(env, folder, capture, False)
        table = self.outputs(env, folder, capture, True)
        self.assertGreater(len(compiled[0]), 0, what)
        for mode, a, b in zip(MODES, compiled, table):
            if a != b:
                lines = [(k, x, y) for k, (x, y) in enumerate(zip(a.splitlines(), b.splitlines()), 1) if x != y]
                first = lines[0] if lines else ("(length)", len(a), len(b))
                self.fail("%s, %s: the compiled walk differs from the table walk at line %s:\n  %r\n  %r"
                          % (what, mode, *first))

    def test_every_rule_file(self):
        for rules, frames in sorted(test_quiet.CAPTURES.items()):
            if frames is None:
                continue
            with self.subTest(rules=rules), TsharkEnv() as env:
                folder = install_alone(env, rules)
                cap = env.add_file("rules.pcap", test_quiet.pcap(test_quiet.with_cuts(frames())))
                self.same(env, folder, cap, rules)

    def test_shipped_rules_on_samples_and_corpus(self):
        with TsharkEnv() as env:
            for rules in ("ethercat.xml", "enip.xml"):
                env.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "rules", rules))
            samples = os.path.join(os.path.abspath(ARGS.source_dir), "samples")
            captures = [os.path.join(samples, n) for n in sorted(os.listdir(samples)) if n.endswith((".pcap", ".pcapng"))]
            captures += test_quiet.corpus_captures("ethercat") + test_quiet.corpus_captures("enip")
            for path in captures:
                with self.subTest(capture=os.path.basename(path)):
                    self.same(env, None, path, os.path.basename(path))


if __name__ == "__main__":
    ARGS, status = run_unittests()
    sys.exit(status)

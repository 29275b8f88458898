#!/usr/bin/env python3
"""A plugin carries only the runtime its rules use.

`dissgen install` compiles an analysis's runtime (plugin_runtime/<folder>/)
only into the plugins whose <pairing analysis="..."> names it, and CMake's
plugins (build/plugins/, linked with every analysis library) get it only
where the generated code names it:

- the EtherNet/IP plugin (rules/enip.xml, no analysis) defines no symbol of
  the EtherCAT analysis or its bus model;
- the EtherCAT plugin (rules/ethercat.xml, analysis="ethercat-esc") defines
  the analysis object the generated code points at, dg_ethercat_esc.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import run_unittests  # noqa: E402

ARGS = None

# What names the EtherCAT runtime: its analysis, namespace, ESC and bus model.
ETHERCAT_SYMBOL = re.compile(r"ecat|ethercat|esc_|bus_", re.IGNORECASE)


def defined_symbols(plugin):
    """Every symbol the shared object defines, demangled: its dynamic table
    and, when not stripped, its full symbol table."""
    names = set()
    for extra in (["-D"], []):
        out = subprocess.run(["nm", "-C", "--defined-only"] + extra + [plugin], capture_output=True, text=True)
        for line in out.stdout.splitlines():
            parts = line.split(None, 2)
            if len(parts) == 3:
                names.add(parts[2])
    return names


class PluginContents(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if shutil.which("nm") is None:
            raise unittest.SkipTest("nm (binutils) is not installed")
        cls.dir = tempfile.mkdtemp(prefix="dissgen-contents-")
        # {stem: {builder: symbols}}: `dissgen install`'s plugin and CMake's, built beside dissgen.
        cls.plugins = {}
        cmake_dir = os.path.join(os.path.dirname(os.path.abspath(ARGS.dissgen)), "..", "plugins")
        for stem in ("enip", "ethercat"):
            rules = os.path.join(ARGS.source_dir, "rules", stem + ".xml")
            r = subprocess.run([ARGS.dissgen, "install", rules, "--dir", cls.dir], capture_output=True, text=True)
            assert r.returncode == 0, r.stdout + r.stderr
            built = {"dissgen install": os.path.join(cls.dir, "dissgen_" + stem + ".so"),
                     "CMake": os.path.join(cmake_dir, "dissgen_" + stem + ".so")}
            assert os.path.exists(built["CMake"]), "no CMake-built plugin at " + built["CMake"]
            cls.plugins[stem] = {builder: defined_symbols(path) for builder, path in built.items()}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_enip_plugin_has_no_ethercat_code(self):
        for builder, symbols in self.plugins["enip"].items():
            with self.subTest(builder=builder):
                self.assertIn("dg_pairing_register", symbols, "the generic pairing runtime is there")
                self.assertEqual(sorted(s for s in symbols if ETHERCAT_SYMBOL.search(s)), [])

    def test_ethercat_plugin_has_its_analysis(self):
        for builder, symbols in self.plugins["ethercat"].items():
            with self.subTest(builder=builder):
                self.assertIn("dg_ethercat_esc", symbols)
                self.assertTrue(any(s.startswith("dg_ecat::bus_") for s in symbols), "the bus model is compiled in")


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

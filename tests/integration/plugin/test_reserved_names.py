#!/usr/bin/env python3
"""The names the plugin registers beside the rule fields, through real tshark.

- a rule file whose field takes a name of the ethercat-esc analysis' bus model
  (`filter="slave"`) is refused by `dissgen check` and `dissgen install`, with
  the node's line, and nothing is installed: before, it was installed, and
  `tshark -Y 'P.slave == 3'` failed ("P.slave (type=Label) cannot participate
  in == comparison");
- renamed, the same rule file installs, and both its field and the bus
  model's work in display filters;
- `dissgen fields` lists exactly what the installed plugin registers (names,
  types and display names in `tshark -G fields`), the rule fields and every
  part of the runtime alike, each line saying where it comes from.
"""
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkEnv, run_unittests  # noqa: E402

ARGS = None

# An empty pcap (Ethernet): display filters are compiled, nothing is decoded.
EMPTY_PCAP = bytes.fromhex("d4c3b2a1020004000000000000000000ffff000001000000")


def src(*parts):
    return os.path.join(ARGS.source_dir, *parts)


def dissgen(*args):
    return subprocess.run([ARGS.dissgen] + list(args), capture_output=True, text=True)


def registered_fields(env, protocol):
    """{filter name: (type, display name)} of what tshark -G fields shows for a protocol."""
    out = {}
    for line in env.tshark(["-G", "fields"]).stdout.splitlines():
        cols = line.split("\t")
        if cols[0] == "P" and len(cols) > 2 and cols[2] == protocol:
            out[protocol] = ("FT_PROTOCOL", cols[1])
        elif cols[0] == "F" and len(cols) > 3 and cols[2].startswith(protocol + "."):
            out[cols[2]] = (cols[3], cols[1])
    return out


class ReservedNames(unittest.TestCase):
    def setUp(self):
        self.env = TsharkEnv()

    def tearDown(self):
        self.env.cleanup()

    def test_a_field_named_like_the_bus_model_is_refused(self):
        rules = src("tests", "rules_err", "pairing_esc_reserved_bus_field_name.xml")
        expected = ("%s:15: error: filter name 'tst.slave' is reserved for the ethercat-esc analysis (its field "
                    "'Slave')" % rules)
        check = dissgen("check", rules)
        self.assertEqual(check.returncode, 1)
        self.assertIn(expected, check.stderr)
        os.makedirs(self.env.plugin_dir, exist_ok=True)
        install = dissgen("install", rules, "--dir", self.env.plugin_dir)
        self.assertEqual(install.returncode, 1, install.stdout + install.stderr)
        self.assertIn(expected, install.stderr)
        self.assertEqual(os.listdir(self.env.plugin_dir), [])

    def test_renamed_it_installs_and_both_names_filter(self):
        with open(src("tests", "rules_err", "pairing_esc_reserved_bus_field_name.xml"), encoding="utf-8") as fh:
            text = fh.read().split("\n", 1)[1].replace('filter="slave"', 'filter="slave_number"')
        rules = self.env.add_file("renamed.xml", text.encode("utf-8"))
        self.env.install_plugin(ARGS.dissgen, rules)
        self.env.assert_plugin_loaded("tst")
        capture = self.env.add_file("empty.pcap", EMPTY_PCAP)
        for expression in ("tst.slave_number == 3", "tst.slave.position == 3", "tst.slave"):
            p = self.env.tshark(["-r", capture, "-Y", expression], check=False)
            self.assertEqual((p.returncode, p.stderr.strip()), (0, ""), expression)

    def test_fields_lists_what_the_plugin_registers(self):
        bus = ["--esi", src("tests", "esi_ok", "small_io.xml"), "--network", src("tests", "network", "small_design.xml")]
        rules = src("rules", "ethercat.xml")
        self.env.install_plugin(ARGS.dissgen, rules, bus)
        self.env.assert_plugin_loaded("ecatr")
        listing = dissgen("fields", rules, *bus)
        self.assertEqual(listing.returncode, 0, listing.stderr)
        listed, sources = {}, []
        for line in listing.stdout.splitlines():
            name, ftype, label, source = line.split("\t")
            listed[name] = (ftype, label)
            if source not in sources:
                sources.append(source)
        self.assertEqual(listed, registered_fields(self.env, "ecatr"))
        self.assertEqual(sources, ["rules", "runtime", "reassembly", "pairing", "ethercat-esc", "esi"])


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

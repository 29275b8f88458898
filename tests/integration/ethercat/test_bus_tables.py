#!/usr/bin/env python3
"""The ESI catalogue and network design embedded into a real plugin (real tshark).

- `dissgen install --esi ... --network ...` builds a plugin that loads cleanly and
  registers one field per PDO entry of the design's slaves, with the types the
  ESI data types call for (`tshark -G fields`);
- the ENI file of ../shared/corpus/eni registers its slaves' entries under their
  TwinCAT names (skipped when the corpus is absent);
- a broken ESI file or design stops `dissgen install` before anything is written;
- the embedded tables change nothing in the rule file's own fields on a real capture
  (what the bus knowledge adds, slave items and the network check, is test_bus_model's).
"""
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkEnv, run_unittests  # noqa: E402

ARGS = None


def src(*parts):
    return os.path.join(ARGS.source_dir, *parts)


def registered_fields(env, prefix):
    """{filter name: (type, display name)} of the registered fields under prefix."""
    out = {}
    for line in env.tshark(["-G", "fields"]).stdout.splitlines():
        cols = line.split("\t")
        if len(cols) > 3 and cols[0] == "F" and cols[2].startswith(prefix):
            out[cols[2]] = (cols[3], cols[1])
    return out


class BusTables(unittest.TestCase):
    def setUp(self):
        self.env = TsharkEnv()
        self.rules = src("rules", "ethercat.xml")

    def tearDown(self):
        self.env.cleanup()

    def test_design_registers_a_field_per_pdo_entry(self):
        self.env.install_plugin(ARGS.dissgen, self.rules, ["--esi", src("tests", "esi_ok", "small_io.xml"),
                                                            "--network", src("tests", "network", "small_design.xml")])
        self.env.assert_plugin_loaded("ecatr")
        fields = registered_fields(self.env, "ecatr.pdo.")
        self.assertEqual(fields, {
            "ecatr.pdo.el1004.channel_1.input": ("FT_BOOLEAN", "EL1004 Channel 1.Input"),
            "ecatr.pdo.el1004.channel_2.input": ("FT_BOOLEAN", "EL1004 Channel 2.Input"),
            "ecatr.pdo.el1004.channel_3.input": ("FT_BOOLEAN", "EL1004 Channel 3.Input"),
            "ecatr.pdo.el2004.channel_1.output": ("FT_BOOLEAN", "EL2004 Channel 1.Output"),
            "ecatr.pdo.el2004.channel_1.mode": ("FT_UINT8", "EL2004 Channel 1.Mode"),
            "ecatr.pdo.el2004.channel_1.setpoint": ("FT_INT16", "EL2004 Channel 1.Setpoint"),
            # entries a master maps over CoE that have no field of their own
            "ecatr.pdo.entry": ("FT_STRING", "PDO entry"),
            "ecatr.pdo.value": ("FT_UINT64", "Value"),
        })
        # Each says in its description where it comes from: PDO, object, data type and width.
        # (-G fields: F, name, filter, type, protocol, base, bitmask, description)
        blurbs = {cols[2]: cols[7] for cols in (line.split("\t") for line in self.env.tshark(["-G", "fields"]).stdout.splitlines())
                  if len(cols) > 7 and cols[0] == "F" and cols[2].startswith("ecatr.pdo.el")}
        self.assertEqual(blurbs["ecatr.pdo.el1004.channel_1.input"], "Input of PDO 0x1a00, object 0x6000:0x01, BOOL, 1 bit")
        self.assertEqual(blurbs["ecatr.pdo.el2004.channel_1.setpoint"],
                         "Output of PDO 0x1600, object 0x7000:0x03, INT, 16 bit")
        # The fields are usable in display filters.
        p = self.env.tshark(["-Y", "ecatr.pdo.el1004.channel_1.input", "-r",
                             self.env.add_file("empty.pcap", bytes.fromhex(
                                 "d4c3b2a1020004000000000000000000ffff000001000000"))])
        self.assertEqual(p.stdout, "")

    def test_eni_registers_twincat_names(self):
        eni = src("..", "shared", "corpus", "eni", "twincat_5_slaves_eni.xml")
        if not os.path.exists(eni):
            self.skipTest("%s absent" % eni)
        self.env.install_plugin(ARGS.dissgen, self.rules, ["--network", eni])
        self.env.assert_plugin_loaded("ecatr")
        fields = registered_fields(self.env, "ecatr.pdo.")
        # ProcessImage variables "Imu.Transmit PDO Mapping.Acceleration X" (INT), ...; 7 + 4 x 6 entries,
        # and ecatr.pdo.entry and ecatr.pdo.value (entries mapped over CoE without a field).
        self.assertEqual(fields["ecatr.pdo.imu.transmit_pdo_mapping.acceleration_x"][0], "FT_INT16")
        self.assertEqual(fields["ecatr.pdo.wheelfrontright.outputs.control_word"][0], "FT_UINT16")
        self.assertEqual(len(fields), 33)

    def test_broken_inputs_stop_install(self):
        for extra, message in (
                (["--esi", src("tests", "esi_err", "bad_number.xml")],
                 "bad_number.xml:6: error: ProductCode is not a number"),
                (["--esi", src("tests", "esi_ok", "small_io.xml"),
                  "--network", src("tests", "network_err", "unknown_type.xml")],
                 "unknown_type.xml:4: error: unknown slave type 'EL1O04'")):
            os.makedirs(self.env.plugin_dir, exist_ok=True)
            p = subprocess.run([ARGS.dissgen, "install", self.rules, "--dir", self.env.plugin_dir] + extra,
                               capture_output=True, text=True)
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertIn(message, p.stderr)
            self.assertEqual(os.listdir(self.env.plugin_dir), [])

    def test_esi_command(self):
        p = subprocess.run([ARGS.dissgen, "esi", src("tests", "esi_ok")], capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stdout.splitlines(), [
            "0x00000002 0x03ec3052 0x00130000 EL1004 4Ch. Dig. Input 24V, 3ms",
            "0x00000002 0x044c2c52 0x00120000 EtherCAT Coupler",
            "0x00000002 0x07d43052 0x00100000 EL2004 4Ch. Dig. Output 24V, 0.5A",
            "0x00000002 0x07d43052 0x00110000 EL2004 4Ch. Dig. Output 24V, 0.5A",
            "0x00000002 0x0c1e3052 0x00100000 EL3104 4Ch. Ana. Input, signed values",
            "0x0000001a 0x00000101 0x00000002 \u4e1c\u897f",
            "0x0000001a 0x00000102 0x00000000 Eing\u00e4nge",
        ])
        p = subprocess.run([ARGS.dissgen, "esi", src("tests", "esi_err", "doctype.xml")],
                           capture_output=True, text=True)
        self.assertEqual((p.returncode, p.stdout), (1, ""))
        self.assertIn("doctype.xml:2: error: DTDs and entity declarations are not allowed", p.stderr)
        p = subprocess.run([ARGS.dissgen, "generate", self.rules, "--compact", "-o", self.env.path("out")],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 1)
        self.assertIn("--compact keeps the models a network uses", p.stderr)
        self.assertFalse(os.path.exists(self.env.path("out")))

    def test_decode_unchanged_on_a_real_capture(self):
        capture = src("..", "shared", "corpus", "ethercat", "soem-sdinfo-ek1100-el1004.pcapng")
        if not os.path.exists(capture):
            self.skipTest("%s absent" % capture)
        with open(capture, "rb") as fh:
            local = self.env.add_file("soem.pcapng", fh.read())
        listed = subprocess.run([ARGS.dissgen, "fields", self.rules], capture_output=True, text=True, check=True)
        args = ["-r", local, "-T", "fields", "-E", "occurrence=a"]
        for line in listed.stdout.splitlines():
            name, _, _, source = line.split("\t")
            if source == "rules":  # the bus model's own fields do change with --esi and --network
                args += ["-e", name]
        self.env.install_plugin(ARGS.dissgen, self.rules)
        plain = self.env.tshark(args).stdout
        self.env.install_plugin(ARGS.dissgen, self.rules, ["--esi", src("tests", "esi_ok", "small_io.xml"),
                                                            "--network", src("tests", "network", "small_design.xml")])
        with_bus = self.env.tshark(args).stdout
        self.assertGreater(len(plain), 10000)
        self.assertEqual(plain, with_bus)


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

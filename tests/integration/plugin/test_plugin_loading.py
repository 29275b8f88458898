#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""How a dissgen plugin lives in the installed Wireshark (real tshark, real plugins).

- `dissgen install` puts a plugin that tshark loads with no warning;
- ethertype 0x88A4 and UDP 34980 decode with the rules by default, whatever the
  plugin load order, while Wireshark's own EtherCAT plugin stays selectable (-d);
- a rule file whose names clash with a Wireshark protocol (one name, or all three) is
  reported and skipped at load, and tshark keeps running; two plugins of the same rules
  load once, without a word;
- a rule file's dissector="NAME" finds the protocol of another dissgen plugin, whichever
  loads first;
- editing the rules and installing again changes the decode;
- the paper's own example generates a working plugin;
- as root in CI, `dissgen install --system` serves root's tshark.
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
import pcapgen  # noqa: E402
from pcapgen import Datagram, Frame  # noqa: E402
from tshark_env import TsharkEnv, run_unittests  # noqa: E402

ARGS = None
SYSTEM_ETHERCAT = "/usr/lib/x86_64-linux-gnu/wireshark/plugins/4.0/epan/ethercat.so"


# Rules that take LLDP's own three names, and an LLDPDU: Chassis ID, Port ID, TTL, End.
LLDP_RULES = """<root name="Link Layer Discovery Protocol" abbreviation="LLDP" ethertype="0x88cc">
  <node name="TLV" repeat="node[@name='Type']">
    <node name="Type" length="7bit" displaytype="numberdec"/>
    <node name="Length" length="9bit" displaytype="numberdec"/>
    <node name="Value" length="../node[@name='Length']" displaytype="origin"/>
  </node>
</root>
"""
LLDP_FRAME = (b"\x01\x80\xc2\x00\x00\x0e\x00\x1b\x1b\x0a\x0b\x0c\x88\xcc"
              b"\x02\x07\x04\x00\x1b\x1b\x0a\x0b\x0c" b"\x04\x05\x05eth0" b"\x06\x02\x00\x78" b"\x00\x00")


def sample_frames():
    """Three frames with known values: physical, logical and broadcast commands, one over UDP."""
    return [
        Frame([Datagram(cmd=4, idx=0x11, adp=0x1001, ado=0x0130, data=b"\x08\x00", wkc=1),
               Datagram(cmd=12, idx=0x12, lad=0x00010000, data=bytes(range(6)), irq=0x0102, wkc=3)]),
        Frame([Datagram(cmd=7, idx=0x20, adp=0, ado=0x0000, data=b"\x11", wkc=2, circulating=True)]),
        Frame([Datagram(cmd=14, idx=0x30, adp=0x1002, ado=0x0910, data=bytes(8), wkc=4)], encap="udp"),
    ]


def fields(env, capture, names, extra=()):
    args = ["-r", capture, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=,"] + list(extra)
    for n in names:
        args += ["-e", n]
    p = env.tshark(args)
    return [line.split("\t") for line in p.stdout.splitlines()], p.stderr


def dissgen(*args, check=True):
    p = subprocess.run([ARGS.dissgen] + list(args), capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError("dissgen %s failed:\n%s%s" % (" ".join(args), p.stdout, p.stderr))
    return p


class PluginLoading(unittest.TestCase):
    def setUp(self):
        self.env = TsharkEnv()
        self.rules = os.path.join(ARGS.source_dir, "rules", "ethercat.xml")
        self.capture = self.env.add_file("sample.pcap", pcapgen.pcap_bytes(sample_frames()))

    def tearDown(self):
        self.env.cleanup()

    def test_installed_plugin_loads_without_warnings(self):
        self.env.install_plugin(ARGS.dissgen, self.rules)
        rows, stderr = self.env.plugins()
        names = [r[0] for r in rows]
        self.assertIn("dissgen_ethercat.so", names)
        self.assertIn("ethercat.so", names, "Wireshark's own EtherCAT plugin must still load")
        self.assertEqual(self.env.loader_warnings(stderr), [], stderr)

    def test_rules_decode_by_default_with_correct_fields(self):
        self.env.install_plugin(ARGS.dissgen, self.rules)
        rows, stderr = fields(self.env, self.capture, [
            "_ws.col.Protocol", "_ws.col.Info", "ecatr.header.length", "ecatr.datagram.cmd",
            "ecatr.datagram.idx", "ecatr.datagram.adp", "ecatr.datagram.ado", "ecatr.datagram.lad",
            "ecatr.datagram.len", "ecatr.datagram.circulating", "ecatr.datagram.more",
            "ecatr.datagram.irq", "ecatr.datagram.data", "ecatr.datagram.wkc"])
        self.assertEqual(stderr.strip(), "")
        self.assertEqual(len(rows), 3)
        first = rows[0]
        self.assertEqual(first[0], "ECATR")
        # the FPRD reads AL status (0x0130) = 0x0008: OP
        self.assertEqual(first[1], "Datagram \u00d72: FPRD 0x1001:0x0130 len 2 AL status OP, LRW 0x00010000 len 6")
        self.assertEqual(first[2], str(2 * 12 + 2 + 6))
        self.assertEqual(first[3], "0x04,0x0c")
        self.assertEqual(first[4], "0x11,0x12")
        self.assertEqual(first[5], "0x1001")        # adp/ado only for the physical command
        self.assertEqual(first[6], "0x0130")
        self.assertEqual(first[7], "0x00010000")    # lad only for LRW
        self.assertEqual(first[8], "2,6")
        self.assertEqual(first[10], "1,0")           # more: set on all but the last
        self.assertEqual(first[11], "0x0000,0x0102")
        self.assertEqual(first[13], "1,3")
        self.assertEqual(rows[1][1], "BRD 0x0000:0x0000 len 1")
        self.assertEqual(rows[1][9], "1")             # circulating
        self.assertEqual(rows[2][0], "ECATR", "EtherCAT over UDP 34980 must decode with the rules too")
        self.assertEqual(rows[2][3], "0x0e")

    def test_stats_tree_counts_messages_instances_and_enum_values(self):
        self.env.install_plugin(ARGS.dissgen, self.rules)
        out = self.env.tshark(["-q", "-z", "ecatr,tree", "-r", self.capture]).stdout
        counts = {}
        for line in out.splitlines():
            m = re.match(r"^(\s*)(\S.*?)\s{2,}(\d+)\s", line)
            if m:
                counts[(len(m.group(1)), m.group(2))] = int(m.group(3))
        self.assertEqual(counts[(0, "Messages")], 3)
        self.assertEqual(counts[(0, "Datagram per message (ecatr.datagram)")], 3)
        self.assertEqual(counts[(1, "1")], 2)      # two frames with one datagram
        self.assertEqual(counts[(1, "2")], 1)      # one with two
        self.assertEqual(counts[(0, "Command (ecatr.datagram.cmd)")], 4)
        for command in ("FPRD", "LRW", "BRD", "FRMW"):
            self.assertEqual(counts[(1, command)], 1, command)
        self.assertEqual(counts[(1, "EtherCAT datagrams")], 3)

    def test_wireshark_plugin_stays_selectable(self):
        self.env.install_plugin(ARGS.dissgen, self.rules)
        rows, _ = fields(self.env, self.capture, ["_ws.col.Protocol", "ecat.cmd", "ecatr.datagram.cmd"],
                         ["-d", "ethertype==0x88a4,ecatf", "-d", "udp.port==34980,ecatf"])
        self.assertEqual([r[0] for r in rows], ["ECAT", "ECAT", "ECAT"])
        self.assertEqual(rows[0][1], "0x04,0x0c")
        self.assertEqual(rows[0][2], "")
        protocols = self.env.tshark(["-G", "protocols"]).stdout
        for name in ("\tecatf\n", "\tecat\n", "\tecatr\n"):
            self.assertIn(name, protocols)

    def test_disabling_ours_selects_wiresharks(self):
        """Enabled Protocols: with ecatr disabled Wireshark's plugin decodes the frames (two on
        the Ethernet type, one on UDP port 34980); disabled too, nothing does; a Decode As
        choice still wins."""
        self.env.install_plugin(ARGS.dissgen, self.rules)
        cases = ((["--disable-protocol", "ecatr"], ["ECAT", "ECAT", "ECAT"]),
                 (["--disable-protocol", "ecatr", "--disable-protocol", "ecatf"], ["0x88a4", "0x88a4", None]),
                 (["--disable-protocol", "ecatf"], ["ECATR", "ECATR", "ECATR"]),
                 (["-d", "ethertype==0x88a4,ecatf"], ["ECAT", "ECAT", "ECATR"]))
        for args, protocols in cases:
            with self.subTest(args=args):
                for passes in ([], ["-2"]):
                    rows, stderr = fields(self.env, self.capture, ["_ws.col.Protocol"], args + passes)
                    got = [r[0] for r in rows]
                    self.assertEqual(len(got), 3, stderr)
                    for frame, (seen, wanted) in enumerate(zip(got, protocols), 1):
                        if wanted:
                            self.assertEqual(seen, wanted, "frame %d: %s" % (frame, stderr))
                        else:  # UDP with both off: whatever else Wireshark makes of it
                            self.assertNotIn(seen, ("ECAT", "ECATR"), "frame %d" % frame)

    def test_disabling_ours_gives_values_back_to_built_in_dissectors(self):
        """POWERLINK (epl, 0x88AB) and SERCOS III (siii, 0x88CD) are built into libwireshark and
        hold their values before any plugin: with ours disabled (on the command line, or in the
        profile as the Enabled Protocols dialog saves it) they decode the frames again; enabled
        again (the profile's entry removed), or with theirs disabled, ours does. One pass and -2."""
        self.env.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "tests", "rules",
                                                           "builtin_ethertypes.xml"))
        ethernet = b"\xff" * 6 + b"\x02\x00\x00\x00\x00\x01"
        # an EPL SoC (message type 1) to broadcast, and a SERCOS III MDT telegram
        epl = ethernet + b"\x88\xab" + b"\x01\xff\xf0" + bytes(43)
        siii = ethernet + b"\x88\xcd" + b"\x00\x00\x00\x00\x00\x00" + bytes(40)
        capture = self.env.add_file("builtin.pcap", pcapgen.raw_pcap_bytes([epl, siii]))
        profile = os.path.join(self.env.home, ".config", "wireshark")
        disabled_protos = os.path.join(profile, "disabled_protos")
        names = ["_ws.col.Protocol", "bltn.kind", "epl.mtyp", "siii"]
        ours, theirs = ["BLTN", "BLTN"], ["POWERLINK", "SIII MDT"]
        # (command-line options, the profile's disabled protocols or None, protocols of the two frames)
        cases = (([], None, ours),
                 (["--disable-protocol", "bltn"], None, theirs),
                 ([], "bltn", theirs),
                 ([], None, ours),  # enabled again
                 (["--disable-protocol", "epl", "--disable-protocol", "siii"], None, ours))
        for args, disabled, protocols in cases:
            if disabled:
                os.makedirs(profile, exist_ok=True)
                with open(disabled_protos, "w", encoding="utf-8") as f:
                    f.write(disabled + "\n")
                subprocess.run(["chmod", "-R", "a+rX", os.path.join(self.env.home, ".config")], check=True)
            elif os.path.exists(disabled_protos):
                os.remove(disabled_protos)
            with self.subTest(args=args, profile_disables=disabled):
                for passes in ([], ["-2"]):
                    rows, stderr = fields(self.env, capture, names, args + passes)
                    self.assertEqual([r[0] for r in rows], protocols, stderr)
                    decoded_by_us = protocols == ours
                    self.assertEqual([r[1] for r in rows], ["0x01", "0x00"] if decoded_by_us else ["", ""])
                    self.assertEqual(rows[0][2], "" if decoded_by_us else "1")
                    self.assertEqual(rows[1][3] != "", not decoded_by_us)

    def test_rules_win_whatever_the_load_order(self):
        """Both plugins in one folder under names that sort either way round."""
        if not os.path.exists(SYSTEM_ETHERCAT):
            self.skipTest("Debian's ethercat.so is not installed")
        built = self.env.install_plugin(ARGS.dissgen, self.rules)[0]
        for ours, theirs in (("aaa_rules.so", "zzz_ethercat.so"), ("zzz_rules.so", "aaa_ethercat.so")):
            with self.subTest(ours=ours):
                folder = tempfile.mkdtemp(dir=self.env.home)
                epan = os.path.join(folder, self.env.abi, "epan")
                os.makedirs(epan)
                shutil.copy(built, os.path.join(epan, ours))
                shutil.copy(SYSTEM_ETHERCAT, os.path.join(epan, theirs))
                subprocess.run(["chmod", "-R", "a+rX", folder], check=True)
                base_env = self.env.env
                self.env.env = lambda: dict(base_env(), WIRESHARK_PLUGIN_DIR=folder)
                try:
                    rows, stderr = fields(self.env, self.capture, ["_ws.col.Protocol"])
                    decode_as, _ = fields(self.env, self.capture, ["_ws.col.Protocol"],
                                          ["-d", "ethertype==0x88a4,ecatf"])
                finally:
                    self.env.env = base_env
                self.assertEqual([r[0] for r in rows], ["ECATR"] * 3, stderr)
                self.assertEqual(decode_as[0][0], "ECAT")

    def test_plugins_hand_bytes_to_each_other_by_name(self):
        """Two rule files, each handing the rest of its message to the other's protocol by
        name: each dissgen protocol registers its name at its own handoff, so whichever plugin
        Wireshark hands off first, both names are found, and no warning is printed."""
        halves = {"handa": ("Kind", "handb", "9997"), "handb": ("Code", "handa", "9996")}
        for filter_name, (field, other, port) in halves.items():
            rules = os.path.join(self.env.home, filter_name + ".xml")
            with open(rules, "w", encoding="utf-8") as fh:
                fh.write("""<root name="Half %s" abbreviation="%s" filter="%s">
  <hook table="udp.port" value="%s"/>
  <node name="%s" length="1byte" displaytype="numberdec"/>
  <node name="Inner" if="../node[@name='%s']" in="1-2" length="rest" dissector="%s"/>
</root>
""" % (filter_name, filter_name.upper(), filter_name, port, field, field, other))
            self.env.install_plugin(ARGS.dissgen, rules)
        # 1 -> handb 2 -> handa 1 -> handb 7 (stops: 7 is not in 1-2)
        capture = self.env.add_file("halves.pcap", pcapgen.raw_pcap_bytes(
            [pcapgen.udp_ethernet_frame(bytes([1, 2, 1, 7]), 9997)]))
        rows, stderr = fields(self.env, capture, ["handa.kind", "handb.code"])
        self.assertNotIn("which this Wireshark does not have", stderr)
        self.assertEqual(rows, [["1,1", "2,7"]], stderr)

    def test_name_clash_is_reported_and_tshark_keeps_running(self):
        paper = os.path.join(ARGS.source_dir, "tests", "rules", "paper_example.xml")
        check = dissgen("check", paper)
        self.assertRegex(check.stderr, r"paper_example\.xml:\d+: warning: the protocol filter name 'ecat' is "
                                       r"already used by Wireshark's 'EtherCAT datagram\(s\)'")
        with open(paper, encoding="utf-8") as fh:
            text = fh.read()
        # Each of the three names clashing in turn (Wireshark's ecat is "EtherCAT datagram(s)", ECAT,
        # ecat); the message names every name taken, and the attributes to change.
        root = '<root name="EtherCAT" abbreviation="ECAT"'
        for kind, name, taken, attributes, header in (
                ("filter name", "EtherCAT", 'the filter name "ecat" and the abbreviation "ECAT". Change them',
                 "filter=... abbreviation=...", root),
                ("abbreviation", "EtherCAT", 'the abbreviation "ECAT". Change it', "abbreviation=...",
                 root + ' filter="paperx"'),
                ("name", "EtherCAT datagram(s)", 'the name "EtherCAT datagram(s)". Change it', "name=...",
                 '<root name="EtherCAT datagram(s)" abbreviation="PAPX" filter="paperx"')):
            with self.subTest(clash=kind):
                folder = os.path.join(self.env.home, "clash-" + kind.replace(" ", "-"))
                os.makedirs(folder, exist_ok=True)
                variant = os.path.join(folder, "paper_example.xml")
                with open(variant, "w", encoding="utf-8") as fh:
                    fh.write(text.replace(root, header, 1))
                self.env.install_plugin(ARGS.dissgen, variant)
                p = self.env.tshark(["-r", self.capture, "-T", "fields", "-e", "_ws.col.Protocol"], check=False)
                self.assertEqual(p.returncode, 0, p.stderr)
                self.assertIn('The dissgen plugin for "%s" was not loaded: another protocol already has %s '
                              'in the rule file (<root %s>) and regenerate the plugin.'
                              % (name, taken, attributes), p.stderr)
                self.assertEqual(p.stdout.split(), ["ECAT", "ECAT", "ECAT"])

    def test_wiresharks_own_three_names_are_a_clash(self):
        """Rules named exactly as a dissector built into Wireshark (LLDP's name, abbreviation and
        filter name) are not an earlier dissgen plugin of the same rules: check warns, and at
        load the plugin names every name it cannot have and steps aside for Wireshark's."""
        rules = os.path.join(self.env.home, "lldp.xml")
        with open(rules, "w", encoding="utf-8") as fh:
            fh.write(LLDP_RULES)
        check = dissgen("check", rules)
        self.assertIn("lldp.xml:1: warning: the protocol's name, abbreviation and filter name are those of "
                      "Wireshark's own 'Link Layer Discovery Protocol' (lldp)", check.stderr)
        self.env.install_plugin(ARGS.dissgen, rules)
        capture = self.env.add_file("lldp.pcap", pcapgen.raw_pcap_bytes([LLDP_FRAME]))
        p = self.env.tshark(["-r", capture, "-T", "fields", "-e", "lldp.tlv.type"], check=False)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn('The dissgen plugin for "Link Layer Discovery Protocol" was not loaded: another protocol '
                      'already has the filter name "lldp", the abbreviation "LLDP" and the name "Link Layer '
                      'Discovery Protocol". Change them in the rule file (<root filter=... abbreviation=... '
                      'name=...>) and regenerate the plugin.', p.stderr)
        self.assertEqual(p.stdout.split(), ["1,2,3,0"], "Wireshark's lldp decodes the frame")

    def test_the_same_rules_twice_load_once_without_a_word(self):
        """Two plugins of the same rules (a packaged one and the user's own build): the first
        registered decodes, the other steps aside with no failure message."""
        built = self.env.install_plugin(ARGS.dissgen, self.rules)[0]
        folder = tempfile.mkdtemp(dir=self.env.home)
        epan = os.path.join(folder, self.env.abi, "epan")
        os.makedirs(epan)
        for name in ("dissgen_ethercat.so", "packaged_ethercat.so"):
            shutil.copy(built, os.path.join(epan, name))
        subprocess.run(["chmod", "-R", "a+rX", folder], check=True)
        base_env = self.env.env
        self.env.env = lambda: dict(base_env(), WIRESHARK_PLUGIN_DIR=folder)
        try:
            rows, stderr = fields(self.env, self.capture, ["_ws.col.Protocol", "ecatr.datagram.cmd"])
        finally:
            self.env.env = base_env
        self.assertNotIn("was not loaded", stderr)
        self.assertEqual(rows, [["ECATR", "0x04,0x0c"], ["ECATR", "0x07"], ["ECATR", "0x0e"]], stderr)

    def test_install_where_tmp_is_not_writable(self):
        """A user who may not write to TMPDIR (nor /tmp, on some machines) still installs: the
        build, and the compiler's own temporary files, go to the user's cache folder."""
        if os.geteuid() != 0:
            self.skipTest("needs root, to run dissgen as another user")
        home = tempfile.mkdtemp(dir=self.env.home)
        closed = tempfile.mkdtemp(dir=self.env.home)  # root's, 0700: nobody may write there
        # dissgen and its runtime where that user can read them (the checkout may be private)
        prefix = tempfile.mkdtemp(dir=self.env.home)
        os.makedirs(os.path.join(prefix, "bin"))
        shutil.copy(ARGS.dissgen, os.path.join(prefix, "bin", "dissgen"))
        shutil.copytree(os.path.join(os.path.dirname(os.path.abspath(ARGS.dissgen)), "..", "share", "dissgen"),
                        os.path.join(prefix, "share", "dissgen"), symlinks=False)
        rules = os.path.join(home, "ethercat.xml")
        shutil.copy(self.rules, rules)
        subprocess.run(["chmod", "-R", "a+rX", prefix, rules], check=True)
        os.chmod(home, 0o777)
        p = subprocess.run(["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", "env", "-i",
                            "HOME=" + home, "PATH=/usr/bin:/bin", "TMPDIR=" + closed,
                            os.path.join(prefix, "bin", "dissgen"), "install", rules],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertTrue(os.path.exists(os.path.join(home, ".local", "lib", "wireshark", "plugins", self.env.abi,
                                                    "epan", "dissgen_ethercat.so")), p.stdout)
        cache = os.path.join(home, ".cache")
        left = [f for f in os.listdir(cache) if f.startswith("dissgen-build-")] if os.path.isdir(cache) else []
        self.assertEqual(left, [], "the build folder is removed")

    def test_editing_rules_and_installing_again_changes_the_decode(self):
        edited = os.path.join(self.env.home, "ethercat.xml")
        with open(self.rules, encoding="utf-8") as src:
            text = src.read()
        with open(edited, "w", encoding="utf-8") as dst:
            dst.write(text.replace('name="LRW"', 'name="LRW (edited)"'))
        self.env.install_plugin(ARGS.dissgen, edited)
        rows, _ = fields(self.env, self.capture, ["_ws.col.Info"])
        self.assertEqual(rows[0][0], "Datagram \u00d72: FPRD 0x1001:0x0130 len 2 AL status OP, "
                                     "LRW (edited) 0x00010000 len 6")
        with open(edited, "w", encoding="utf-8") as dst:
            dst.write(re.sub(r'(<node name="Datagram"[^>]*?summary=")[^"]*"', r'\1{Command} #{Index}"', text, count=1))
        self.env.install_plugin(ARGS.dissgen, edited)
        rows, _ = fields(self.env, self.capture, ["_ws.col.Info"])
        self.assertEqual(rows[0][0], "Datagram \u00d72: FPRD #0x11, LRW #0x12")

    def test_paper_example_generates_a_working_plugin(self):
        """Alone (WIRESHARK_PLUGIN_DIR keeps Debian's ecat out), the paper's rules decode EtherCAT."""
        paper = os.path.join(ARGS.source_dir, "tests", "rules", "paper_example.xml")
        folder = os.path.join(self.env.home, "isolated")
        epan = os.path.join(folder, self.env.abi, "epan")
        dissgen("install", paper, "--dir", epan)
        subprocess.run(["chmod", "-R", "a+rX", folder], check=True)
        base_env = self.env.env
        self.env.env = lambda: dict(base_env(), WIRESHARK_PLUGIN_DIR=folder)
        try:
            rows, stderr = fields(self.env, self.capture, [
                "_ws.col.Protocol", "ecat.ethercat.f2", "ecat.f5.f6.f7", "ecat.f5.f6.f8", "ecat.f5.f6.f9",
                "ecat.f5.f6.f10", "ecat.f5.f6.m", "ecat.f5.f6.f13", "ecat.f5.f14", "ecat.f5.wkc"])
            hidden = self.env.tshark(["-r", self.capture, "-Y", "ecat.f5.f6.r == 0", "-V"]).stdout
        finally:
            self.env.env = base_env
        self.assertEqual(stderr.strip(), "")
        first = rows[0]
        self.assertEqual(first[0], "ECAT")
        self.assertEqual(first[1], "32")
        self.assertEqual(first[2], "0x04,0x0c")                       # 命令
        self.assertEqual(first[3], "0x11,0x12")                       # 索引
        self.assertEqual(first[4], "01:10:30:01,00:00:01:00")         # 地址区, wire order
        self.assertEqual(first[5], "2,6")                             # 长度
        self.assertEqual(first[6], "1,0")                             # M
        self.assertEqual(first[9], "1,3")                             # WKC
        self.assertIn("命令: LRW 读写数据 (0x0c)", hidden)
        self.assertNotIn(" R: ", hidden, "a nondisplay leaf is filterable but not shown")

    @unittest.skipUnless(os.geteuid() == 0 and os.environ.get("CI"), "installs into the system folder: CI only")
    def test_system_install_serves_root(self):
        rules = os.path.join(self.env.home, "systemtest.xml")
        with open(rules, "w") as fh:
            fh.write('<root name="dissgen system test" abbreviation="DGSYS" ethertype="0x88b5">\n'
                     '  <node name="Value" length="2byte" displaytype="numberhex"/>\n</root>\n')
        p = dissgen("install", rules, "--system")
        target = re.search(r"installed (\S+)", p.stdout).group(1)
        try:
            self.assertTrue(target.startswith("/usr/lib"), target)
            frame = b"\xff" * 6 + b"\x02" * 6 + b"\x88\xb5" + b"\xbe\xef" + bytes(44)
            cap = self.env.add_file("sys.pcap", pcapgen_raw(frame))
            out = subprocess.run(["tshark", "-r", cap, "-T", "fields", "-e", "dgsys.value"],
                                 capture_output=True, text=True)
            self.assertEqual(out.stdout.strip(), "0xbeef", out.stderr)
        finally:
            os.remove(target)


def pcapgen_raw(frame):
    import struct
    return struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1) + \
        struct.pack("<IIII", 1, 0, len(frame), len(frame)) + frame


def main():
    return run_unittests()[1]


if __name__ == "__main__":
    sys.exit(main())

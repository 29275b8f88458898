#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""What each construct of the rule language costs, and that it costs nothing where unused
(Python 3 stdlib only).

    python3 bench/construct_bench.py [--packets 4000] [--registers 8] [--modes summary,-V]

Expects build/bin/dissgen. Writes rule files for one UDP protocol (transaction,
function, status word, start, count, then count registers of 2 bytes) that differ
only in one construct, builds a plugin from each, and counts the instructions of one
tshark run per file and mode under valgrind (callgrind): immune to other load on the
machine, so differences of a few percent show.

    base       the protocol, no construct
    branch     base + a branch never taken holding a plain leaf (the reference of unused)
    unused     base + the same branch holding a computed value and an overlay instead
               (the constructs present in the plugin, not used)
    validity   base + valid="..." on the function (checked before each message is taken)
    computed   base + a scaled value and, per register, its number ({Start} + index)
    overlay    base + the status word's bits, over its 2 bytes
    pairing    base + <pairing> by transaction (the reference of request)
    request    pairing + request{...}: per register of a response, the number its
               request's start gives (request{Start} + index)
    finding    base + two <finding>s: one checked on every register (value 0xffff: seldom
               raised), one on the status word (a note in a quarter of the packets)
    cycles     base + <cycles>: a stream per function and sender, the transaction as its
               sequence count (every packet is in a cycle, timed, none lost)
    bitgroup   base with the status word as a bit group of four fields (Ready, Error, Code,
               State): the reference of bitif
    bitif      bitgroup with Ready under an `if` (always true) and a Fault meaning its bit
               otherwise (a conditional member, and an alternative never decoded)
    bitlist    base with the status word as a packed list of 16 one-bit flags (count from
               a computed value): 16 items where base has one
    learned    base + a <learn> of the start by function, read back (learned{...}) in every
               packet: the start the previous packet of that function had
    window     base + a window of 16 registers per function (a <learn> key with a span and
               an id, taught again alike by every packet) and, per register, the function
               whose window holds its number (learned{...} with a lookup)
    offset     base + per register a computed value holding where it sits (`offset`)

Each row gives the instructions per packet that tshark spends in
epan_dissect_run_with_taps (the dissection of a packet, from the frame through Ethernet,
IP and UDP to ours, its tree and columns; not start-up, not the printing), and what the
construct adds to its reference (request: pairing; unused: branch; the others: base), per
packet and as a share of the reference.
Takes about 10 minutes on 2 cores with the defaults.
"""
import argparse
import os
import random
import re
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "integration", "lib"))
from pcapgen import ETHERTYPE_IPV4, ip_checksum  # noqa: E402
from tshark_env import TsharkEnv  # noqa: E402

PORT = 47481

HEAD = ('<root name="Construct bench" abbreviation="CONB" filter="conb" byteorder="big">\n'
        '  <hook table="udp.port" value="%d"/>\n' % PORT)
PAIRING = ('  <pairing>\n'
           '    <key field="node[@name=\'Transaction\']"/>\n'
           '  </pairing>\n')
CYCLES = ('  <cycles sender="yes">\n'
          '    <signature field="node[@name=\'Function\']"/>\n'
          '    <sequence field="node[@name=\'Transaction\']"/>\n'
          '  </cycles>\n')


def rules(kind):
    valid = ' valid="1-16"' if kind == "validity" else ""
    out = [HEAD, PAIRING if kind in ("pairing", "request") else "", CYCLES if kind == "cycles" else "",
           '  <node name="Transaction" length="2byte" displaytype="numberhex"/>\n'
           '  <node name="Function" length="1byte" displaytype="numberdec"%s/>\n'
           '  <node name="Status" length="2byte" displaytype="numberhex"/>\n'
           '  <node name="Start" length="2byte" displaytype="numberdec"/>\n'
           '  <node name="Count" length="1byte" displaytype="numberdec"/>\n' % valid]
    if kind == "computed":
        out.append('  <node name="Temperature" value="{Start} * 0.1 - 40" unit="°C"/>\n')
    if kind == "finding":  # on the status word: raised when its two top bits are set
        out[-1] = out[-1].replace(
            '  <node name="Status" length="2byte" displaytype="numberhex"/>\n',
            '  <node name="Status" length="2byte" displaytype="numberhex">\n'
            '    <finding name="fault" severity="note" condition="{Status} &gt;= 0xc000" text="status {Status}"/>\n'
            '  </node>\n')
    if kind in ("bitgroup", "bitif", "bitlist"):  # the status word as bit fields instead
        status = {
            "bitgroup": '  <node name="Ready" length="1bit" displaytype="bool"/>\n',
            "bitif": '  <node name="Ready" length="1bit" displaytype="bool" if="../node[@name=\'Function\']" in="3"/>\n'
                     '  <node name="Fault" length="1bit" displaytype="bool" otherwise="true"/>\n',
        }.get(kind, "")
        if kind == "bitlist":
            status = ('  <node name="Sixteen" value="16" displaytype="nondisplay"/>\n'
                      '  <node name="Flag" length="1bit" count="../node[@name=\'Sixteen\']" displaytype="bool"'
                      ' byteorder="little"/>\n')
        else:
            status += ('  <node name="Error" length="1bit" displaytype="bool"/>\n'
                       '  <node name="Code" length="6bit" displaytype="numberdec"/>\n'
                       '  <node name="State" length="8bit" displaytype="numberdec"/>\n')
        out[-1] = out[-1].replace('  <node name="Status" length="2byte" displaytype="numberhex"/>\n', status)
    if kind == "overlay":
        out.append('  <node name="Status bits" filter="bits" overlay="../node[@name=\'Status\']">\n'
                   '    <node name="Ready" length="1bit" displaytype="bool"/>\n'
                   '    <node name="Error" length="1bit" displaytype="bool"/>\n'
                   '    <node name="Code" length="6bit" displaytype="numberdec"/>\n'
                   '    <node name="State" length="8bit" displaytype="numberdec"/>\n'
                   '  </node>\n')
    if kind == "branch":
        out.append('  <node name="Never" if="../node[@name=\'Function\']" in="255">\n'
                   '    <node name="Never flag" length="16bit" displaytype="numberhex"/>\n'
                   '  </node>\n')
    if kind == "unused":
        out.append('  <node name="Never" if="../node[@name=\'Function\']" in="255">\n'
                   '    <node name="Never value" value="{Start} * 0.1 - 40"/>\n'
                   '    <node name="Never bits" overlay="../../node[@name=\'Status\']">\n'
                   '      <node name="Never flag" length="16bit" displaytype="numberhex"/>\n'
                   '    </node>\n'
                   '  </node>\n')
    if kind in ("learned", "window"):  # taught by the count, once the function and start are known
        key = ('      <key value="{Function}"/>\n' if kind == "learned" else
               '      <key value="{Function} * 16" span="16" id="{Function}" lookup="{Function} * 16 + index"/>\n')
        value = "{Start}" if kind == "learned" else "{Function}"
        out[-1] = out[-1].replace(
            '  <node name="Count" length="1byte" displaytype="numberdec"/>\n',
            '  <node name="Count" length="1byte" displaytype="numberdec">\n'
            '    <learn name="Taught" value="%s">\n%s    </learn>\n'
            '  </node>\n' % (value, key))
    if kind == "learned":
        out.append('  <node name="Previous start" value="learned{Taught}" displaytype="numberdec"/>\n')
    out.append('  <node name="Register" count="../node[@name=\'Count\']">\n'
               '    <node name="Value" length="2byte" displaytype="numberhex"/>\n')
    if kind == "window":
        out.append('    <node name="Owner" value="learned{Taught}" displaytype="numberdec"/>\n')
    if kind == "offset":
        out.append('    <node name="Place" value="offset" displaytype="numberdec"/>\n')
    if kind == "finding":
        out[-1] = out[-1].replace('displaytype="numberhex"/>\n', 'displaytype="numberhex">\n'
                                  '      <finding name="saturated" severity="warning" condition="{Value} == 0xffff"'
                                  ' text="register value {Value}"/>\n    </node>\n')
    if kind == "computed":
        out.append('    <node name="Number" value="{Start} + index"/>\n')
    if kind == "request":
        out.append('    <node name="Number" value="request{Start} + index" direction="response"/>\n')
    out.append('  </node>\n</root>\n')
    return "".join(out)


KINDS = ["base", "branch", "unused", "validity", "computed", "overlay", "pairing", "request", "finding", "cycles",
         "bitgroup", "bitif", "bitlist", "learned", "window", "offset"]
REFERENCE = {"request": "pairing", "unused": "branch", "bitif": "bitgroup"}


def udp_frame(payload, sport, dport):
    """payload in UDP from sport to dport in IPv4 in Ethernet II (the client 10.0.0.1)."""
    src, dst = (b"\x0a\x00\x00\x01", b"\x0a\x00\x00\x02") if dport == PORT else (b"\x0a\x00\x00\x02", b"\x0a\x00\x00\x01")
    u = struct.pack("!HHHH", sport, dport, 8 + len(payload), 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0, src, dst)
    ip = ip[:10] + struct.pack("!H", ip_checksum(ip)) + ip[12:]
    return b"\x02\xee\xee\xee\xee\xee\x02\x00\x00\x00\x00\x01" + struct.pack("!H", ETHERTYPE_IPV4) + ip + u


def capture(packets, registers, seed=1):
    """Requests to PORT and their responses from it, alternating, each transaction once."""
    rng = random.Random(seed)
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i in range(packets):
        txn = (i // 2) & 0xFFFF
        body = struct.pack(">HBHHB", txn, 3, rng.randrange(0x10000), rng.randrange(1000), registers)
        body += bytes(rng.randrange(256) for _ in range(2 * registers))
        sport, dport = (50000, PORT) if i % 2 == 0 else (PORT, 50000)
        frame = udp_frame(body, sport, dport)
        out.append(struct.pack("<IIII", 1700000000 + i // 1000, (i % 1000) * 1000, len(frame), len(frame)) + frame)
    return b"".join(out)


def instructions(env, args):
    cmd = env.command(args)
    i = cmd.index(env.tshark_bin)
    # only the dissection of each packet: not start-up
    cmd[i:i] = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", "--collect-atstart=no",
                "--toggle-collect=epan_dissect_run_with_taps"]
    r = subprocess.run(cmd, env=env.env(), cwd=env.home, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                       text=True)
    m = re.search(r"I\s+refs:\s+([\d,]+)", r.stderr)
    if r.returncode != 0 or not m:
        raise RuntimeError("valgrind tshark %r failed:\n%s" % (args, r.stderr[-2000:]))
    return int(m.group(1).replace(",", ""))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", default=os.path.join(HERE, "..", "build", "bin", "dissgen"))
    ap.add_argument("--packets", type=int, default=4000)
    ap.add_argument("--registers", type=int, default=8)
    ap.add_argument("--modes", default="summary,-V", help="summary, -V, fields (comma-separated)")
    ap.add_argument("--kinds", default=",".join(KINDS))
    a = ap.parse_args()
    kinds = a.kinds.split(",")
    modes = {"summary": [], "-V": ["-V"], "fields": ["-T", "fields", "-e", "conb.transaction"]}
    modes = {m: modes[m] for m in a.modes.split(",")}
    envs = {}
    try:
        counts = {}
        for k in kinds:
            env = TsharkEnv()
            envs[k] = env
            env.install_plugin(a.dissgen, env.add_file("conb_%s.xml" % k, rules(k).encode()))
            cap = env.add_file("conb.pcap", capture(a.packets, a.registers))
            for m, extra in modes.items():
                counts[(k, m)] = instructions(env, ["-r", cap] + extra) / a.packets
                print("%-9s %-8s %9.0f instructions per packet" % (k, m, counts[(k, m)]), file=sys.stderr)
        print("Instructions per packet (callgrind, tshark's epan_dissect_run_with_taps), %d packets of %d registers"
              % (a.packets, a.registers))
        print()
        print("| rules | " + " | ".join("%s: per packet | added | share" % m for m in modes) + " |")
        print("|---|" + "---:|---:|---:|" * len(modes))
        for k in kinds:
            ref = REFERENCE.get(k, "base")
            cells = []
            for m in modes:
                v = counts[(k, m)]
                if k == "base" or ref not in kinds:
                    cells += ["%.0f" % v, "", ""]
                else:
                    r = counts[(ref, m)]
                    cells += ["%.0f" % v, "%+.0f" % (v - r), "%+.1f %%" % (100.0 * (v - r) / r)]
            print("| %s%s | %s |" % (k, "" if ref == "base" or k == "base" else " (vs %s)" % ref, " | ".join(cells)))
    finally:
        for env in envs.values():
            env.cleanup()


if __name__ == "__main__":
    main()

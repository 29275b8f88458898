#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Cost per frame of rules/profinet.xml (pnr) against Wireshark's pn_rt/pn_dcp/pn_io, in
instructions counted by valgrind (callgrind): immune to the other load of a shared machine.

    python3 bench/profinet_cost.py [--dissgen build/bin/dissgen] [--frames 2000]

Generates --frames PROFINET frames (tests/integration/pngen.py: DCP of every service,
cyclic RT frames, alarms, PTCP), installs the plugin into a temporary HOME and counts one tshark
run per cell: summary lines (`-r`) and packet details (`-V`), each with
    ours       pnr (the default for ethertype 0x8892 once installed)
    wireshark  --disable-protocol pnr: pn_rt and its sub-dissectors (pn_dcp, pn_io, pn_ptcp)
    floor      --disable-protocol pnr --disable-protocol pn_rt: 0x8892 left undissected
and prints (total - floor) / frames for ours and Wireshark's, and their ratio.
"""
import argparse
import os
import random
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "integration"))
import pngen  # noqa: E402
from tshark_env import TsharkEnv  # noqa: E402

CONFIGS = {
    "ours": [],
    "wireshark": ["--disable-protocol", "pnr"],
    "floor": ["--disable-protocol", "pnr", "--disable-protocol", "pn_rt"],
}
MODES = {"summary": [], "-V": ["-V"]}


def instructions(env, args):
    """Instructions (Ir) of one tshark run under callgrind."""
    # tshark runs as nobody when we are root: callgrind writes where it may.
    folder = tempfile.mkdtemp()
    os.chmod(folder, 0o777)
    out = os.path.join(folder, "callgrind.out")
    cmd = env.command(args)
    at = cmd.index(env.tshark_bin)
    cmd[at:at] = ["valgrind", "--tool=callgrind", "--callgrind-out-file=" + out]
    p = subprocess.run(cmd, env=env.env(), cwd=env.home, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                       text=True, check=True)
    found = re.search(r"Collected\s*:\s*(\d+)", p.stderr)
    if not found:
        raise RuntimeError("no instruction count from callgrind:\n" + p.stderr[-2000:])
    return int(found.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", default=os.path.join(HERE, "..", "build", "bin", "dissgen"))
    ap.add_argument("--frames", type=int, default=2000)
    a = ap.parse_args()
    with TsharkEnv() as env:
        env.install_plugin(a.dissgen, os.path.join(HERE, "..", "rules", "profinet.xml"))
        env.assert_plugin_loaded("pnr")
        rng = random.Random(5)
        frames = []
        while len(frames) < a.frames:
            frames += pngen.all_frames(rng)
        cap = env.add_file("bench.pcap", pngen.pcap(frames[:a.frames]))
        for mode, extra in MODES.items():
            counts = {name: instructions(env, ["-r", cap] + extra + flags) for name, flags in CONFIGS.items()}
            per = {name: (counts[name] - counts["floor"]) / a.frames for name in ("ours", "wireshark")}
            print("%-8s ours %8.0f  wireshark %8.0f  instructions/frame above the floor  (ratio %.2f; "
                  "totals: %s)" % (mode, per["ours"], per["wireshark"], per["ours"] / per["wireshark"],
                                   ", ".join("%s %d" % kv for kv in counts.items())), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

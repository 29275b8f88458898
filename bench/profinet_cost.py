#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Cost per frame of rules/profinet.xml (pnr) against Wireshark's pn_rt/pn_dcp/pn_io, in
instructions counted by valgrind (callgrind): immune to the other load of a shared machine.

    python3 bench/profinet_cost.py [--dissgen build/bin/dissgen] [--frames 2000]

Generates --frames PROFINET frames (tests/integration/lib/pngen.py: DCP of every service,
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
sys.path.insert(0, os.path.join(HERE, "..", "tests", "integration", "lib"))
import pngen  # noqa: E402
from tshark_env import TsharkEnv  # noqa: E402

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


def compare(dissgen, rules, ours, theirs, capture, frames):
    """Print, per mode, the instructions per frame of protocol `ours` (the plugin of
    `rules`) and of Wireshark's `theirs` on `capture` (a pcap's bytes of `frames` frames),
    each above the floor (both disabled: the frames left undissected), and their ratio."""
    configs = {
        "ours": [],
        "wireshark": ["--disable-protocol", ours],
        "floor": ["--disable-protocol", ours, "--disable-protocol", theirs],
    }
    with TsharkEnv() as env:
        env.install_plugin(dissgen, rules)
        env.assert_plugin_loaded(ours)
        cap = env.add_file("bench.pcap", capture)
        for mode, extra in MODES.items():
            counts = {name: instructions(env, ["-r", cap] + extra + flags) for name, flags in configs.items()}
            per = {name: (counts[name] - counts["floor"]) / frames for name in ("ours", "wireshark")}
            print("%-8s ours %8.0f  wireshark %8.0f  instructions/frame above the floor  (ratio %.2f; "
                  "totals: %s)" % (mode, per["ours"], per["wireshark"], per["ours"] / per["wireshark"],
                                   ", ".join("%s %d" % kv for kv in counts.items())), flush=True)


def main_for(doc, rules, ours, theirs, all_frames, pcap):
    """A cost script's command line: --frames frames of all_frames(rng) (a generator's
    frames of every kind), the plugin of rules/<rules> compared with Wireshark's theirs."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", default=os.path.join(HERE, "..", "build", "bin", "dissgen"))
    ap.add_argument("--frames", type=int, default=2000)
    a = ap.parse_args()
    rng = random.Random(5)
    frames = []
    while len(frames) < a.frames:
        frames += all_frames(rng)
    compare(a.dissgen, os.path.join(HERE, "..", "rules", rules), ours, theirs, pcap(frames[:a.frames]), a.frames)
    return 0


if __name__ == "__main__":
    sys.exit(main_for(__doc__, "profinet.xml", "pnr", "pn_rt", pngen.all_frames, pngen.pcap))

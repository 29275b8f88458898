#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Cost per frame of rules/powerlink.xml (eplr) against Wireshark's epl, in instructions
counted by valgrind (callgrind), as bench/profinet_cost.py counts PROFINET's.

    python3 bench/powerlink_cost.py [--dissgen build/bin/dissgen] [--frames 2000]

Generates --frames POWERLINK frames (tests/integration/lib/eplgen.py: every message type and
ASnd service), installs the plugin into a temporary HOME and counts one tshark run per
cell: summary lines (`-r`) and packet details (`-V`), each with
    ours       eplr (the default for ethertype 0x88AB once installed)
    wireshark  --disable-protocol eplr: epl
    floor      --disable-protocol eplr --disable-protocol epl: 0x88AB left undissected
and prints (total - floor) / frames for ours and Wireshark's, and their ratio.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "tests", "integration", "lib"))
import eplgen  # noqa: E402
from profinet_cost import main_for  # noqa: E402

if __name__ == "__main__":
    sys.exit(main_for(__doc__, "powerlink.xml", "eplr", "epl", eplgen.all_frames, eplgen.pcap))

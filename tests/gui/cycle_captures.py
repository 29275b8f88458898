#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Captures whose cycles the Statistics menu shows, for tests/gui/screenshot.sh
--statistics (Python 3 stdlib only): the generated captures the integration tests
time to the nanosecond.

    cycle_captures.py OUTDIR   writes OUTDIR/enip-io.pcap (EtherNet/IP class-1 I/O of
                               four connections, test_rule_cycles),
                               OUTDIR/profinet-cyclic.pcap (three devices' cyclic
                               data, pngen.cyclic_devices) and
                               OUTDIR/ethercat-two-tasks.pcap (two EtherCAT tasks at
                               1 and 10 ms, test_cycles.two_tasks) and
                               OUTDIR/powerlink-cycle.pcap (a POWERLINK cycle of
                               three nodes, eplgen.cycle)
"""
import os
import random
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "integration", "lib"))
import testpaths  # noqa: E402,F401  (the integration tests' folders: their captures)
import cyclemodel  # noqa: E402
import eplgen  # noqa: E402
import pngen  # noqa: E402
import test_cycles  # noqa: E402
import test_losses  # noqa: E402
import test_rule_cycles  # noqa: E402


def main(out):
    os.makedirs(out, exist_ok=True)
    captures = {"enip-io.pcap": test_rule_cycles.generated_capture(),
                "profinet-cyclic.pcap": pngen.cyclic_devices(),
                "powerlink-cycle.pcap": eplgen.cycle(random.Random(88))[0]}
    for name, packets in captures.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(cyclemodel.pcap_ns(packets))
    test_losses.generated(os.path.join(out, "ethercat-two-tasks.pcap"), test_cycles.two_tasks(cycles=100))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: cycle_captures.py OUTDIR")
    main(sys.argv[1])

#!/usr/bin/env python3
"""What a register window costs when few of its many children are inside (Python 3 stdlib only).

    python3 bench/window_bench.py [--registers 2000] [--packets 20000] [--runs 3]

Expects build/bin/dissgen. Generates three rule files for one UDP protocol
(address, length, data) that differ only in how the data is described:
    raw      one leaf of the data's bytes (the floor of the comparison)
    window1  a window (base = address) with one register
    windowN  a window with --registers 2-byte registers at 0x0000, 0x0002, ...
             plus 16 blocks of 16 bytes at a stride (FMMU-like)
and a capture of --packets small reads (2 or 4 bytes at random addresses) plus
one read of the whole map. Times whole tshark processes (user+sys CPU,
alternating the files, --runs times each) in `-T fields`, `-V` and summary
mode and prints medians: windowN should cost about what window1 does, since
the runtime finds the few registers inside by binary search.
"""
import argparse
import os
import random
import statistics
import struct
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "integration", "lib"))
from pcapgen import udp_ethernet_frame  # noqa: E402
from tshark_env import TsharkEnv  # noqa: E402

PORT = 47476


def rules(kind, registers):
    head = ('<root name="Window bench" abbreviation="WINB" filter="winb" byteorder="little">\n'
            '  <hook table="udp.port" value="%d"/>\n'
            '  <node name="Address" length="2byte" displaytype="numberhex"/>\n'
            '  <node name="Length" length="2byte" displaytype="numberdec"/>\n' % PORT)
    if kind == "raw":
        body = '  <node name="Data" length="../node[@name=\'Length\']"/>\n'
    else:
        count = 1 if kind == "window1" else registers
        regs = "".join('    <node name="R%04x" at="0x%04x" length="2byte" displaytype="numberhex"/>\n'
                       % (2 * i, 2 * i) for i in range(count))
        if kind != "window1":
            regs += ('    <node name="Block {i}" filter="block" at="0x%04x" stride="16" instances="16">\n'
                     '      <node name="Start" length="4byte" displaytype="numberhex"/>\n'
                     '      <node name="Settings" length="12byte"/>\n'
                     '    </node>\n' % (2 * count))
        body = ('  <node name="Data" length="../node[@name=\'Length\']" base="../node[@name=\'Address\']">\n'
                + regs + '  </node>\n')
    return head + body + "</root>\n"


def udp_frame(payload):
    return udp_ethernet_frame(payload, PORT)


def capture(packets, registers, seed=1):
    rng = random.Random(seed)
    span = 2 * registers + 256
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    reads = [(rng.randrange(0, span, 2), rng.choice([2, 4])) for _ in range(packets)] + [(0, span)]
    for i, (address, n) in enumerate(reads):
        frame = udp_frame(struct.pack("<HH", address, n) + bytes(rng.randrange(256) for _ in range(n)))
        out.append(struct.pack("<IIII", 1700000000 + i, 0, len(frame), len(frame)) + frame)
    return b"".join(out)


def cpu_time(env, args):
    start = time.monotonic()
    pid = os.fork()
    if pid == 0:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        cmd = env.command(args)
        os.execvpe(cmd[0], cmd, env.env())
    _, status, usage = os.wait4(pid, 0)
    if status != 0:
        raise RuntimeError("tshark failed: %r" % args)
    return usage.ru_utime + usage.ru_stime, time.monotonic() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", default=os.path.join(HERE, "..", "build", "bin", "dissgen"))
    ap.add_argument("--registers", type=int, default=2000)
    ap.add_argument("--packets", type=int, default=20000)
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args()
    kinds = ["raw", "window1", "windowN"]
    envs = {}
    try:
        for k in kinds:
            env = TsharkEnv()
            envs[k] = env
            path = env.add_file("winb_%s.xml" % k, rules(k, a.registers).encode())
            env.install_plugin(a.dissgen, path)
        caps = {k: envs[k].add_file("winb.pcap", capture(a.packets, a.registers)) for k in kinds}
        modes = {"-T fields": ["-T", "fields", "-e", "winb.address"], "-V": ["-V"], "summary": []}
        samples = {(k, m): [] for k in kinds for m in modes}
        for _ in range(a.runs):
            for m, extra in modes.items():
                for k in kinds:
                    samples[(k, m)].append(cpu_time(envs[k], ["-r", caps[k]] + extra)[0])
        print("CPU seconds (median of %d) for %d small reads + 1 whole-map read; %d registers + 16 blocks"
              % (a.runs, a.packets, a.registers))
        print("%-10s %10s %10s %10s %14s" % ("mode", "raw", "window1", "windowN", "windowN/window1"))
        for m in modes:
            med = {k: statistics.median(samples[(k, m)]) for k in kinds}
            print("%-10s %10.2f %10.2f %10.2f %14.2f" % (m, med["raw"], med["window1"], med["windowN"],
                                                          med["windowN"] / med["window1"]))
    finally:
        for env in envs.values():
            env.cleanup()


if __name__ == "__main__":
    main()

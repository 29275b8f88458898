#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""dissgen's EtherCAT plugin against Wireshark's own, a Lua dissector and the floor (Python 3 stdlib only).

    python3 bench/bench.py [--runs 3] [--frames 200000] [--json results.json]
    python3 bench/bench.py --corpus ../shared/corpus/ethercat [--corpus-copies 3]   (real traffic:
        register, mailbox and process-data datagrams, as Wireshark's plugin decodes them too)
    python3 bench/bench.py --corpus ../shared/corpus/ethercat --same-depth   (the rules without
        their <pairing> block: what Wireshark's plugin decodes, and nothing more)
    python3 bench/bench.py --scale 100 --esi ../shared/corpus/esi --configs ours,wireshark,floor
        (hours of traffic: a real capture repeated 100 times, each copy's timestamps shifted
        past the previous one's, so every frame pairs as in the original; peak memory per frame)

Expects build/bin/dissgen (build it first: bash scripts/build.sh); builds nothing
itself. In one run it

 1. generates a capture of --frames varied EtherCAT frames (1-12 datagrams, all 15
    commands, data 0..--max-data bytes; Ethernet, 802.1Q and UDP as pcapgen makes them);
 2. installs the plugin from rules/ethercat.xml into a temporary HOME, bench/ecat_lua.lua
    into another, and a plugin from a generated 2 000-field rule file into a third;
 3. checks on a small capture that each configuration below decodes with exactly the
    dissector it is meant to (frame.protocols) and that the three agree on the commands;
 4. times whole tshark processes, alternating the configurations (A B C D A B C D ...),
    --runs times each, in three modes: `-T fields -e <command field>`, `-V` and plain
    `-r` (summary lines), all output to /dev/null:
        ours       dissgen plugin (the default for ethertype 0x88a4 / UDP 34980)
        wireshark  Wireshark's ethercat.so: -d ethertype==0x88a4,ecatf -d udp.port==34980,ecatf
        lua        bench/ecat_lua.lua (a HOME without our plugin), selected the same way
        floor      --disable-protocol ecatr --disable-protocol ecatf: 0x88a4 left undissected
 5. times tshark start-up (`tshark -r empty.pcap`) without a per-user plugin, with ours
    and with the 2 000-field one, and `dissgen generate` / `dissgen install` for
    rules/ethercat.xml and the 2 000-field file;
 6. prints medians and ratios; --json writes every sample.
 7. with --instructions FRAMES, also counts the instructions of one tshark run per cell
    under valgrind (callgrind) on a FRAMES-frame capture: immune to other load, so it
    settles differences that CPU times on a busy machine cannot (summary lines). With
    --corpus, --scale or --capture that capture's first FRAMES frames (editcap -r), else
    FRAMES generated ones. --cache-sim counts under cachegrind instead, with its cache and
    branch simulation: also first-level instruction and data cache misses and mispredicted
    branches, which tell why equal instruction counts can still cost unequal CPU time.

CPU time is user+sys of the tshark process (os.wait4), peak memory its ru_maxrss.
As root, tshark runs as uid 65534 (Wireshark ignores per-user plugins for root), see
tests/integration/lib/tshark_env.py. Other load on the machine shows up as spread between
runs: compare medians, and prefer more --runs on a busy machine. "net" ratios subtract the
floor; they are left out ("-") when the reference is within 2% of the floor.
Defaults take about 6 minutes (10 with --instructions 3000) on 2 cores.
"""
import argparse
import json
import os
import random
import re
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True  # no __pycache__ in bench/ or tests/integration/
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "integration", "lib"))

import pcapgen  # noqa: E402
from tshark_env import TsharkEnv, TsharkError  # noqa: E402

CONFIGS = ("ours", "wireshark", "lua", "floor")
MODES = ("fields", "verbose", "summary")
CMD_FIELD = {"ours": "ecatr.datagram.cmd", "wireshark": "ecat.cmd", "lua": "ecatlua.datagram.cmd",
             "floor": "ecatr.datagram.cmd"}
SELECT = {
    "ours": [],
    "wireshark": ["-d", "ethertype==0x88a4,ecatf", "-d", "udp.port==34980,ecatf"],
    "lua": ["-d", "ethertype==0x88a4,ecatlua", "-d", "udp.port==34980,ecatlua"],
    "floor": ["--disable-protocol", "ecatr", "--disable-protocol", "ecatf"],
}
# Who must (and who must not) appear in frame.protocols of an EtherCAT frame, per configuration.
ECAT_PROTOS = {"ecatr", "ecatf", "ecat", "ecatlua"}
EXPECT = {"ours": {"ecatr"}, "wireshark": {"ecatf", "ecat"}, "lua": {"ecatlua"}, "floor": set()}


class BenchError(RuntimeError):
    pass


def log(msg):
    print("[bench %s] %s" % (time.strftime("%H:%M:%S"), msg), file=sys.stderr, flush=True)


# --------------------------------------------------------------------------- measuring

class Sample(dict):
    """cpu, user, sys (s), wall (s), rss_kb of one child process."""


def measure(cmd, env=None, cwd=None, stdout=os.devnull, what=None):
    """Run cmd to completion; return a Sample from the child's own rusage (os.wait4)."""
    with open(stdout, "wb") as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=out, stderr=err, stdin=subprocess.DEVNULL)
        _, status, ru = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        p.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        errtext = err.read().decode("utf-8", "replace")
    if p.returncode != 0:
        raise BenchError("%s exited %d: %s\n%s" % (what or cmd[0], p.returncode, " ".join(cmd), errtext[-2000:]))
    s = Sample(cpu=ru.ru_utime + ru.ru_stime, user=ru.ru_utime, sys=ru.ru_stime, wall=wall,
               rss_kb=ru.ru_maxrss)
    s.stderr = errtext
    return s


def med(samples, key):
    return statistics.median(s[key] for s in samples) if samples else float("nan")


def ratio(a, b):
    return a / b if b and b == b and a == a and b > 0 else float("nan")


def net_ratio(a, b, floor):
    """(a - floor) / (b - floor), or nan when b is within 2% of the floor: then the
    difference is lost in the noise and the ratio means nothing."""
    if not (b == b and floor == floor) or b - floor <= 0.02 * floor:
        return float("nan")
    return (a - floor) / (b - floor)


# --------------------------------------------------------------------------- inputs

def bench_frames(seed, n, max_datagrams, max_data):
    """pcapgen's varied frames with every datagram's data cut to 0..max_data bytes (the ones
    longer than max_data get a new length drawn uniformly from 0..max_data)."""
    frames = pcapgen.random_frames(seed, n, max_datagrams=max_datagrams)
    rng = random.Random(seed ^ 0x5EED)
    for f in frames:
        for d in f.datagrams:
            if len(d.data) > max_data:
                d.data = d.data[:rng.randint(0, max_data)]
    return frames


def generate_capture(path, seed, n, max_datagrams, max_data):
    """Write the capture from a separate Python process and return describe() of it.

    The frames take hundreds of MB of Python objects; a child forked from a process that
    big starts its ru_maxrss at the parent's peak (Linux keeps the pre-exec high-water
    mark), which would hide tshark's own peak. So this process stays small."""
    code = ("import json, sys; sys.dont_write_bytecode = True; sys.path.insert(0, %r); import bench; "
            "f = bench.bench_frames(%d, %d, %d, %d); bench.pcapgen.write_pcap(%r, f); "
            "print(json.dumps(bench.describe(f)))" % (HERE, seed, n, max_datagrams, max_data, path))
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if p.returncode != 0:
        raise BenchError("generating the capture failed:\n" + p.stderr[-2000:])
    return json.loads(p.stdout)


def without_pairing(rules, work):
    """A copy of rules (same file name, so the same plugin) without its <pairing> block."""
    with open(rules, encoding="utf-8") as fh:
        text = fh.read()
    stripped = re.sub(r"<pairing\b[^>]*/>|<pairing\b.*?</pairing>", "", text, flags=re.S)
    if stripped == text:
        raise BenchError("--same-depth: %s has no <pairing> block" % rules)
    folder = os.path.join(work, "same-depth")
    os.makedirs(folder, exist_ok=True)
    out = os.path.join(folder, os.path.basename(rules))
    with open(out, "w", encoding="utf-8") as fh:
        fh.write(stripped)
    os.chmod(folder, 0o755)
    os.chmod(out, 0o644)
    return out


def merge_corpus(folder, copies, out):
    """Concatenate (mergecap -a) every capture of folder, copies times, into the classic pcap out."""
    import glob
    files = sorted(glob.glob(os.path.join(folder, "*.pcapng")) + glob.glob(os.path.join(folder, "*.pcap")))
    if not files:
        raise BenchError("no *.pcap/*.pcapng in %s" % folder)
    if shutil.which("mergecap") is None:
        raise BenchError("--corpus needs mergecap (Debian package wireshark-common)")
    p = subprocess.run(["mergecap", "-a", "-F", "pcap", "-w", out] + files * max(1, copies),
                       capture_output=True, text=True)
    if p.returncode != 0:
        raise BenchError("mergecap failed:\n" + p.stderr[-2000:])


def scale_capture(base, copies, work, out):
    """`copies` copies of `base` one after the other (editcap -t shifts each copy past the
    previous one's last frame, mergecap -a appends), as the classic pcap `out`."""
    for tool in ("editcap", "mergecap", "capinfos"):
        if shutil.which(tool) is None:
            raise BenchError("--scale needs %s (Debian package wireshark-common)" % tool)
    p = subprocess.run(["capinfos", "-T", "-r", "-a", "-e", "-S", base], capture_output=True, text=True)
    cols = p.stdout.strip().split("\t") if p.returncode == 0 else []
    if len(cols) < 3:
        raise BenchError("capinfos cannot read %s: %s" % (base, p.stderr.strip()))
    span = float(cols[2]) - float(cols[1]) + 0.001
    pieces = []
    for k in range(copies):
        piece = os.path.join(work, "scale-%d.pcap" % k)
        p = subprocess.run(["editcap", "-F", "pcap", "-t", "%.6f" % (k * span), base, piece],
                           capture_output=True, text=True)
        if p.returncode != 0:
            raise BenchError("editcap failed: " + p.stderr[-2000:])
        pieces.append(piece)
    p = subprocess.run(["mergecap", "-a", "-F", "pcap", "-w", out] + pieces, capture_output=True, text=True)
    for piece in pieces:
        os.unlink(piece)
    if p.returncode != 0:
        raise BenchError("mergecap failed:\n" + p.stderr[-2000:])


def count_pcap_records(path):
    """Records of a classic pcap file, read header by header (-1 for other formats)."""
    with open(path, "rb") as fh:
        magic = fh.read(24)[:4]
        if magic not in (b"\xd4\xc3\xb2\xa1", b"\xa1\xb2\xc3\xd4", b"\x4d\x3c\xb2\xa1", b"\xa1\xb2\x3c\x4d"):
            return -1
        e = "<" if magic in (b"\xd4\xc3\xb2\xa1", b"\x4d\x3c\xb2\xa1") else ">"
        n = 0
        while True:
            h = fh.read(16)
            if len(h) < 16:
                return n
            fh.seek(struct.unpack(e + "IIII", h)[2], 1)
            n += 1


def describe(frames):
    cmds, lens, per_frame, encaps = set(), [], [], {}
    for f in frames:
        per_frame.append(len(f.datagrams))
        encaps[f.encap] = encaps.get(f.encap, 0) + 1
        for d in f.datagrams:
            cmds.add(d.cmd)
            lens.append(len(d.data))
    return {"frames": len(frames), "datagrams": len(lens), "commands": sorted(cmds),
            "datagrams_per_frame": [min(per_frame), max(per_frame)],
            "data_len": [min(lens), max(lens), round(statistics.mean(lens), 1)], "encap": encaps}


def make_readable(path):
    for root, dirs, files in os.walk(path):
        os.chmod(root, os.stat(root).st_mode | 0o555)
        for f in files:
            p = os.path.join(root, f)
            os.chmod(p, os.stat(p).st_mode | 0o444)


def lua_env(lua_script):
    """A HOME whose personal plugin folder (~/.local/lib/wireshark/plugins, where 4.0 looks
    for Lua plugins) holds the Lua dissector, and no dissgen plugin."""
    env = TsharkEnv(prefix="dissgen-bench-lua-")
    folder = os.path.join(env.home, ".local", "lib", "wireshark", "plugins")
    os.makedirs(folder, exist_ok=True)
    shutil.copy(lua_script, os.path.join(folder, "ecat_lua.lua"))
    make_readable(env.home)
    return env


# --------------------------------------------------------------------------- checks

def check_configs(envs, capture):
    """Every EtherCAT frame of the small capture decodes with the intended dissector only,
    tshark says nothing on stderr, and ours, Wireshark's and the Lua one agree on the commands."""
    cmds = {}
    for cfg in CONFIGS:
        env = envs[cfg]
        p = env.tshark(["-r", capture] + SELECT[cfg] +
                       ["-T", "fields", "-E", "occurrence=a", "-E", "aggregator=,",
                        "-e", "frame.protocols", "-e", CMD_FIELD[cfg]])
        if p.stderr.strip():
            raise BenchError("%s: tshark wrote to stderr:\n%s" % (cfg, p.stderr.strip()))
        rows = [line.split("\t") for line in p.stdout.splitlines()]
        for i, (protos, cmd) in enumerate(rows, 1):
            chain = protos.split(":")
            seen = ECAT_PROTOS & set(chain)
            ok = seen == EXPECT[cfg] or (cfg == "wireshark" and seen == {"ecatf"})
            if not ok:
                raise BenchError("%s: frame %d decoded as %s" % (cfg, i, protos))
        if cfg != "floor":
            cmds[cfg] = [[int(x, 0) for x in c.split(",") if x] for _, c in rows]
    if not (cmds["ours"] == cmds["wireshark"] == cmds["lua"]):
        bad = next(i for i, (a, b, c) in enumerate(zip(cmds["ours"], cmds["wireshark"], cmds["lua"]), 1)
                   if not a == b == c)
        raise BenchError("the dissectors disagree on the commands of frame %d: ours %s, wireshark %s, lua %s"
                         % (bad, cmds["ours"][bad - 1], cmds["wireshark"][bad - 1], cmds["lua"][bad - 1]))
    return sum(len(c) for c in cmds["ours"])


# --------------------------------------------------------------------------- runs

def tshark_args(cfg, mode, capture):
    args = ["-r", capture] + SELECT[cfg]
    if mode == "fields":
        args += ["-T", "fields", "-e", CMD_FIELD[cfg]]
    elif mode == "verbose":
        args += ["-V"]
    return args


def run_tshark(env, args, what):
    return measure(env.command(args), env=env.env(), cwd=env.home, what=what)


def bench_decode(envs, capture, runs, modes, configs):
    results = {m: {c: [] for c in configs} for m in modes}
    warned = set()
    for mode in modes:
        for r in range(runs):
            for cfg in configs:
                s = run_tshark(envs[cfg], tshark_args(cfg, mode, capture), "%s/%s" % (mode, cfg))
                if s.stderr.strip() and (mode, cfg) not in warned:
                    warned.add((mode, cfg))
                    log("warning: %s/%s: tshark stderr: %s" % (mode, cfg, s.stderr.strip()[:300]))
                results[mode][cfg].append(s)
            log("%-7s run %d/%d: %s" % (mode, r + 1, runs, "  ".join(
                "%s %.2fs" % (c, results[mode][c][-1]["cpu"]) for c in configs)))
    return results


# What valgrind prints of a whole run: "==pid== D1  misses:  38,169,217  (30,064,629 rd ..."
VALGRIND_COUNTS = {"instructions": r"I\s+refs:\s+([\d,]+)", "i1_misses": r"I1\s+misses:\s+([\d,]+)",
                   "d1_misses": r"D1\s+misses:\s+([\d,]+)", "mispredicts": r"Mispredicts:\s+([\d,]+)"}


def bench_instructions(envs, capture, modes, configs, cache_sim=False):
    """Instructions of one tshark run per configuration and mode under callgrind: no noise
    from other load, so small differences (summary lines) show. With cache_sim, under
    cachegrind's cache and branch simulation: also the first-level instruction and data
    cache misses and mispredicted branches, {mode: {config: {count: n}}} as the second result."""
    results = {m: {} for m in modes}
    locality = {m: {} for m in modes} if cache_sim else {}
    tool = (["--tool=cachegrind", "--cache-sim=yes", "--branch-sim=yes", "--cachegrind-out-file=/dev/null"]
            if cache_sim else ["--tool=callgrind", "--callgrind-out-file=/dev/null"])
    for mode in modes:
        for cfg in configs:
            env = envs[cfg]
            cmd = env.command(tshark_args(cfg, mode, capture))
            i = cmd.index(env.tshark_bin)
            cmd[i:i] = ["valgrind"] + tool
            s = measure(cmd, env=env.env(), cwd=env.home, what="valgrind %s/%s" % (mode, cfg))
            counts = {}
            for name, pattern in VALGRIND_COUNTS.items():
                m = re.search(pattern, s.stderr)
                if m:
                    counts[name] = int(m.group(1).replace(",", ""))
                elif name == "instructions" or cache_sim:
                    raise BenchError("valgrind %s/%s: no %s in:\n%s" % (mode, cfg, name, s.stderr[-1000:]))
            results[mode][cfg] = counts["instructions"]
            if cache_sim:
                locality[mode][cfg] = {k: v for k, v in counts.items() if k != "instructions"}
        log("instructions %-7s %s" % (mode, "  ".join("%s %.0fM" % (c, results[mode][c] / 1e6) for c in configs)))
    return results, locality


def bench_startup(envs, empty, runs):
    order = [k for k in ("none", "ours", "lua", "big") if k in envs]
    results = {k: [] for k in order}
    for _ in range(runs):
        for k in order:
            results[k].append(run_tshark(envs[k], ["-r", empty], "start-up/" + k))
    log("start-up: " + "  ".join("%s %.3fs" % (k, med(results[k], "cpu")) for k in order))
    return results


def bench_install(dissgen, rule_files, workdir, runs):
    results = {}
    for _ in range(runs):
        for name, rules in rule_files:
            out = os.path.join(workdir, "gen-" + name)
            plug = os.path.join(workdir, "install-" + name)
            os.makedirs(out, exist_ok=True)
            results.setdefault(("generate", name), []).append(
                measure([dissgen, "generate", rules, "-o", out], what="dissgen generate"))
            results.setdefault(("install", name), []).append(
                measure([dissgen, "install", rules, "--dir", plug], what="dissgen install"))
    for (what, name), s in results.items():
        log("%s %s: %.2fs CPU, %.2fs wall" % (what, name, med(s, "cpu"), med(s, "wall")))
    return results


# --------------------------------------------------------------------------- report

def fmt(x, spec):
    return "-" if x != x else format(x, spec)


def table(rows, header):
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    line = lambda r: "  ".join(str(c).rjust(w) if i else str(c).ljust(w) for i, (c, w) in enumerate(zip(r, widths)))
    return "\n".join([line(header), line(["-" * w for w in widths])] + [line(r) for r in rows])


def paired_net_ratios(decode):
    """{mode: [net ours/ws of run 1, of run 2, ...]}: each run's ours, Wireshark's and floor
    ran one after the other, so a machine that is slower for a while (a shared host) slows
    all three. The medians of the cells come from different runs and do not cancel that."""
    paired = {}
    for mode, per in decode.items():
        if not all(k in per for k in ("ours", "wireshark", "floor")):
            continue
        v = [net_ratio(o["cpu"], w["cpu"], f["cpu"]) for o, w, f in zip(per["ours"], per["wireshark"], per["floor"])]
        v = [x for x in v if x == x]
        if v:
            paired[mode] = v
    return paired


def report(info, decode, startup, install, runs, instr=None, locality=None):
    out = []
    cap = info["capture"]
    out.append("Capture: %d frames, %d datagrams (%d-%d a frame), %d commands, data %d-%d bytes (mean %s), %.1f MB; "
               "encapsulation %s" % (cap["frames"], cap["datagrams"], cap["datagrams_per_frame"][0],
                                     cap["datagrams_per_frame"][1], len(cap["commands"]), cap["data_len"][0],
                                     cap["data_len"][1], cap["data_len"][2], info["capture_bytes"] / 1e6,
                                     ", ".join("%s %d" % kv for kv in sorted(cap["encap"].items()))))
    out.append("tshark %s, %d runs per cell, medians. CPU = user+sys of the tshark process; net = minus the floor."
               % (info["tshark"], runs))
    out.append("Rules: %s" % info.get("rules", "?"))
    if decode:
        configs = list(next(iter(decode.values())).keys())
        rows = []
        for mode, per in decode.items():
            c = {k: med(per[k], "cpu") for k in configs}
            m = {k: med(per[k], "rss_kb") / 1024 for k in configs}
            fl = c.get("floor", float("nan"))
            row = [mode] + [fmt(c.get(k, float("nan")), ".2f") for k in CONFIGS]
            row += [fmt(ratio(c["ours"], c.get("wireshark", float("nan"))), ".2f"),
                    fmt(net_ratio(c["ours"], c.get("wireshark", float("nan")), fl), ".2f"),
                    fmt(ratio(c["ours"], c.get("lua", float("nan"))), ".2f"),
                    fmt(net_ratio(c["ours"], c.get("lua", float("nan")), fl), ".2f")]
            row += [fmt(m.get(k, float("nan")), ".1f") for k in ("ours", "wireshark", "lua", "floor")]
            row += [fmt(ratio(m["ours"], m.get("wireshark", float("nan"))), ".3f")]
            rows.append(row)
        out.append("")
        out.append("Decoding (CPU seconds; peak RSS MB)")
        out.append(table(rows, ["mode", "ours", "wireshark", "lua", "floor", "ours/ws", "net ours/ws",
                                "ours/lua", "net ours/lua", "RSS ours", "RSS ws", "RSS lua", "RSS floor",
                                "RSS ours/ws"]))
        spread = []
        for mode, per in decode.items():
            for k in configs:
                v = [s["cpu"] for s in per[k]]
                spread.append("%s/%s %.2f-%.2f" % (mode, k, min(v), max(v)))
        out.append("CPU min-max: " + "; ".join(spread))
        paired = paired_net_ratios(decode)
        if paired:
            out.append("net ours/ws of each run (its three runs back to back), median [min-max]: " + "; ".join(
                "%s %.2f [%.2f-%.2f]" % (mode, statistics.median(v), min(v), max(v)) for mode, v in paired.items()))
        wall = []
        for mode, per in decode.items():
            wall.append("%s " % mode + " ".join("%s %.2f" % (k, med(per[k], "wall")) for k in configs))
        out.append("wall (s): " + "; ".join(wall))
    if instr:
        rows = []
        for mode, c in instr.items():
            fl = c.get("floor", float("nan"))
            ws, lua = c.get("wireshark", float("nan")), c.get("lua", float("nan"))
            rows.append([mode] + [fmt(c.get(k, float("nan")) / 1e6, ".0f") for k in CONFIGS] +
                        [fmt(ratio(c["ours"], ws), ".3f"), fmt(net_ratio(c["ours"], ws, fl), ".2f"),
                         fmt(ratio(c["ours"], lua), ".2f"), fmt(net_ratio(c["ours"], lua, fl), ".2f")])
        out.append("")
        out.append("Instructions (millions, valgrind %s, %d frames, one run each)"
                   % (info.get("instr_tool", "callgrind"), info["instr_frames"]))
        out.append(table(rows, ["mode", "ours", "wireshark", "lua", "floor", "ours/ws", "net ours/ws",
                                "ours/lua", "net ours/lua"]))
    if locality:
        rows = []
        for mode, c in locality.items():
            row = [mode]
            for count in ("i1_misses", "d1_misses", "mispredicts"):
                v = {k: c[k][count] for k in c}
                row += [fmt(v.get(k, float("nan")) / 1e6, ".2f") for k in ("ours", "wireshark", "floor")]
                row.append(fmt(net_ratio(v["ours"], v.get("wireshark", float("nan")), v.get("floor", float("nan"))),
                               ".2f"))
            rows.append(row)
        out.append("")
        out.append("Instruction and data cache misses (first level) and mispredicted branches, millions"
                   " (cachegrind, same runs)")
        out.append(table(rows, ["mode", "I1 ours", "I1 ws", "I1 floor", "I1 net ours/ws",
                                "D1 ours", "D1 ws", "D1 floor", "D1 net ours/ws",
                                "mispred ours", "mispred ws", "mispred floor", "mispred net ours/ws"]))
    if startup:
        base = med(startup["none"], "cpu")
        rows = []
        for k, s in startup.items():
            c = med(s, "cpu")
            rows.append([{"none": "no per-user plugin", "ours": "dissgen EtherCAT plugin",
                          "lua": "bench/ecat_lua.lua", "big": "dissgen 2000-field plugin"}[k],
                         "%.3f" % c, "%+.1f%%" % (100 * (c / base - 1)), "%.3f" % med(s, "wall"),
                         "%.1f" % (med(s, "rss_kb") / 1024)])
        out.append("")
        out.append("Start-up: tshark -r empty.pcap")
        out.append(table(rows, ["installed", "CPU s", "vs none", "wall s", "RSS MB"]))
    if install:
        rows = []
        for (what, name), s in install.items():
            rows.append(["dissgen %s" % what, name, "%.2f" % med(s, "cpu"), "%.2f" % med(s, "wall"),
                         "%.0f" % (med(s, "rss_kb") / 1024)])
        out.append("")
        out.append("dissgen (CPU includes the compiler and the tshark name check)")
        out.append(table(rows, ["command", "rule file", "CPU s", "wall s", "peak RSS MB"]))
    if decode:
        out.append("")
        verdict = []
        for mode, per in decode.items():
            if "wireshark" not in per:
                continue
            c = ratio(med(per["ours"], "cpu"), med(per["wireshark"], "cpu"))
            n = net_ratio(med(per["ours"], "cpu"), med(per["wireshark"], "cpu"),
                          med(per["floor"], "cpu")) if "floor" in per else float("nan")
            f = ratio(med(per["floor"], "cpu"), med(per["wireshark"], "cpu")) if "floor" in per else float("nan")
            m = ratio(med(per["ours"], "rss_kb"), med(per["wireshark"], "rss_kb"))
            dm = (med(per["ours"], "rss_kb") - med(per["wireshark"], "rss_kb")) / 1024
            # ru_maxrss moves by a few hundred kB between identical runs: within 0.5% is "equal".
            verdict.append("%s CPU %.2fx %s (net %s; the floor alone is %.2fx), RSS %.3fx (%+.1f MB) %s" % (
                mode, c, "ok" if c <= 0.8 else "MISSED", "n/a" if n != n else "%.2fx" % n, f, m, dm,
                "ok" if m <= 1.0 else ("equal within noise" if m <= 1.005 else "MISSED")))
        frames = cap["frames"]
        if frames > 0:
            per_frame = []
            for mode, per in decode.items():
                ours = med(per["ours"], "rss_kb") * 1024
                line = "%s ours %.0f" % (mode, ours / frames)
                for k in ("wireshark", "floor"):
                    if k in per:
                        line += ", %s %.0f (ours %+.0f)" % (k, med(per[k], "rss_kb") * 1024 / frames,
                                                            (ours - med(per[k], "rss_kb") * 1024) / frames)
                per_frame.append(line)
            out.append("Peak RSS per frame (bytes, %d frames): %s" % (frames, "; ".join(per_frame)))
        if startup and "ours" in startup:
            o = med(startup["ours"], "cpu") / med(startup["none"], "cpu") - 1
            verdict.append("start-up %+.1f%% %s" % (100 * o, "ok" if o <= 0.05 else "MISSED"))
        out.append("Targets (CPU <= 0.8x Wireshark's plugin, RSS <= 1.0x, start-up <= +5%): " + "; ".join(verdict))
    return "\n".join(out)


# --------------------------------------------------------------------------- main

def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", default=os.path.join(ROOT, "build", "bin", "dissgen"))
    ap.add_argument("--rules", default=os.path.join(ROOT, "rules", "ethercat.xml"))
    ap.add_argument("--same-depth", action="store_true",
                    help="the rules without their <pairing> block: no pairing, ESC analysis or bus model, which "
                         "Wireshark's plugin does not do; the two then decode the same, a like-for-like comparison")
    ap.add_argument("--runs", type=int, default=3, help="tshark runs per configuration and mode (default 3)")
    ap.add_argument("--frames", type=int, default=200000, help="frames in the capture (default 200000)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-data", type=int, default=300, help="longest datagram data, bytes (default 300)")
    ap.add_argument("--max-datagrams", type=int, default=12)
    ap.add_argument("--capture", help="use this pcap instead of generating one")
    ap.add_argument("--corpus", metavar="DIR",
                    help="real traffic instead: the *.pcap/*.pcapng of DIR (e.g. ../shared/corpus/ethercat, with "
                         "register and mailbox datagrams) concatenated with mergecap into one pcap")
    ap.add_argument("--corpus-copies", type=int, default=1, metavar="N",
                    help="with --corpus: concatenate the captures N times (a longer run; default 1)")
    ap.add_argument("--scale", type=int, default=0, metavar="N",
                    help="decode --scale-base repeated N times, timestamps shifted (hours of traffic)")
    ap.add_argument("--scale-base", metavar="FILE",
                    default=os.path.join(ROOT, "..", "shared", "corpus", "ethercat", "twincat-akd-nc-mode.pcapng"),
                    help="the capture --scale repeats (default the corpus' twincat-akd-nc-mode.pcapng)")
    ap.add_argument("--esi", action="append", default=[], metavar="PATH",
                    help="install our plugin with this ESI catalogue (repeatable)")
    ap.add_argument("--modes", default=",".join(MODES), help="of %s (default all)" % ",".join(MODES))
    ap.add_argument("--configs", default=",".join(CONFIGS), help="of %s (default all)" % ",".join(CONFIGS))
    ap.add_argument("--startup-runs", type=int, default=20, help="default 20; 0 skips start-up timing")
    ap.add_argument("--install-runs", type=int, default=3, help="default 3; 0 skips dissgen timing")
    ap.add_argument("--big-fields", type=int, default=2000, help="fields of the generated rule file (default 2000)")
    ap.add_argument("--instructions", type=int, default=0, metavar="FRAMES",
                    help="also count instructions (valgrind callgrind) on a capture of FRAMES frames, one run "
                         "per cell, e.g. 3000 (about 3 minutes); default 0: off")
    ap.add_argument("--cache-sim", action="store_true",
                    help="with --instructions: count under cachegrind's cache and branch simulation, which also "
                         "gives first-level instruction and data cache misses and mispredicted branches (about twice "
                         "as slow)")
    ap.add_argument("--json", help="write every sample here")
    ap.add_argument("--keep", action="store_true", help="keep the temporary folders (printed)")
    a = ap.parse_args(argv)
    if a.cache_sim and a.instructions <= 0:
        ap.error("--cache-sim counts with --instructions FRAMES: give both")

    if not (os.path.isfile(a.dissgen) and os.access(a.dissgen, os.X_OK)):
        print("bench: %s is missing; build it first (bash scripts/build.sh)" % a.dissgen, file=sys.stderr)
        return 2
    if not shutil.which("tshark"):
        print("bench: tshark is not installed", file=sys.stderr)
        return 2
    modes = [m for m in a.modes.split(",") if m]
    configs = [c for c in a.configs.split(",") if c]
    for m in modes:
        if m not in MODES:
            ap.error("unknown mode %r" % m)
    for c in configs:
        if c not in CONFIGS:
            ap.error("unknown configuration %r" % c)
    if "ours" not in configs:
        ap.error("--configs must include ours")

    t_start = time.time()
    work = tempfile.mkdtemp(prefix="dissgen-bench-", dir="/tmp")
    os.chmod(work, 0o755)
    envs, cleanup = {}, []
    info = {"argv": sys.argv[1:]}
    try:
        tv = subprocess.run(["tshark", "-v"], capture_output=True, text=True).stdout.splitlines()
        info["tshark"] = tv[0].split("(Wireshark) ")[-1].split(" ")[0] if tv else "?"

        # Inputs.
        if a.scale > 0:
            if not os.path.isfile(a.scale_base):
                raise BenchError("--scale: no capture at %s (give --scale-base)" % a.scale_base)
            capture = os.path.join(work, "bench.pcap")
            log("repeating %s %d times ..." % (os.path.basename(a.scale_base), a.scale))
            scale_capture(a.scale_base, a.scale, work, capture)
            info["capture"] = {"frames": count_pcap_records(capture), "datagrams": 0,
                               "commands": [], "datagrams_per_frame": [0, 0], "data_len": [0, 0, 0],
                               "encap": {}, "scaled": os.path.abspath(a.scale_base), "copies": a.scale}
        elif a.corpus:
            capture = os.path.join(work, "bench.pcap")
            merge_corpus(a.corpus, a.corpus_copies, capture)
            info["capture"] = {"frames": count_pcap_records(capture), "datagrams": 0,
                               "commands": [], "datagrams_per_frame": [0, 0], "data_len": [0, 0, 0],
                               "encap": {}, "corpus": os.path.abspath(a.corpus), "copies": a.corpus_copies}
        elif a.capture:
            capture = os.path.join(work, "bench.pcap")
            shutil.copy(a.capture, capture)
            info["capture"] = {"frames": count_pcap_records(capture), "datagrams": 0,
                               "commands": [], "datagrams_per_frame": [0, 0], "data_len": [0, 0, 0],
                               "encap": {}}
        else:
            log("generating %d frames (seed %d, data 0-%d bytes) ..." % (a.frames, a.seed, a.max_data))
            capture = os.path.join(work, "bench.pcap")
            info["capture"] = generate_capture(capture, a.seed, a.frames, a.max_datagrams, a.max_data)
        info["capture_bytes"] = os.path.getsize(capture)
        info["rules"] = os.path.abspath(a.rules)
        if a.same_depth:
            a.rules = without_pairing(a.rules, work)
            info["rules"] += " without <pairing>"
        check_cap = os.path.join(work, "check.pcap")
        pcapgen.write_pcap(check_cap, bench_frames(a.seed + 1, 400, a.max_datagrams, a.max_data))
        empty = os.path.join(work, "empty.pcap")
        pcapgen.write_pcap(empty, [])
        big_rules = os.path.join(work, "big.xml")
        sys.path.insert(0, HERE)
        import gen_rules
        with open(big_rules, "w", encoding="utf-8") as fh:
            fh.write(gen_rules.rule_file(a.big_fields)[0])
        for f in (capture, check_cap, empty, big_rules):
            os.chmod(f, 0o644)
        log("capture: %s" % json.dumps(info["capture"]))

        # Plugins.
        log("installing the plugins ...")
        ours = TsharkEnv(prefix="dissgen-bench-ours-")
        cleanup.append(ours)
        ours.install_plugin(a.dissgen, a.rules, [arg for p in a.esi for arg in ("--esi", p)])
        if a.esi:
            info["rules"] += " with --esi " + " --esi ".join(a.esi)
        ours.assert_plugin_loaded("ecatr")
        envs.update(ours=ours, wireshark=ours, floor=ours)
        if "lua" in configs:
            envs["lua"] = lua_env(os.path.join(HERE, "ecat_lua.lua"))
            cleanup.append(envs["lua"])
        plain = TsharkEnv(prefix="dissgen-bench-none-")
        cleanup.append(plain)
        big = TsharkEnv(prefix="dissgen-bench-big-")
        cleanup.append(big)
        big.install_plugin(a.dissgen, big_rules)
        big.assert_plugin_loaded("dgbench")

        if "lua" in configs and "wireshark" in configs:
            n = check_configs(envs, check_cap)
            log("check: each configuration decodes with its own dissector; all agree on %d commands" % n)

        decode = bench_decode(envs, capture, a.runs, modes, configs) if a.runs > 0 else {}
        startup = {}
        if a.startup_runs > 0:
            senvs = {"none": plain, "ours": ours, "big": big}
            if "lua" in envs:
                senvs["lua"] = envs["lua"]
            startup = bench_startup(senvs, empty, a.startup_runs)
        install = {}
        if a.install_runs > 0:
            install = bench_install(a.dissgen, [("ethercat.xml", a.rules),
                                                ("%d-field" % a.big_fields, big_rules)],
                                    work, a.install_runs)

        instr, locality = {}, {}
        if a.instructions > 0:
            if not shutil.which("valgrind"):
                raise BenchError("--instructions needs valgrind (apt-get install valgrind)")
            small = os.path.join(work, "instr.pcap")
            if a.corpus or a.scale or a.capture:
                p = subprocess.run(["editcap", "-r", capture, small, "1-%d" % a.instructions],
                                   capture_output=True, text=True)
                if p.returncode != 0:
                    raise BenchError("editcap failed:\n" + p.stderr[-2000:])
            else:
                generate_capture(small, a.seed, a.instructions, a.max_datagrams, a.max_data)
            os.chmod(small, 0o644)
            info["instr_frames"] = a.instructions
            info["instr_tool"] = "cachegrind" if a.cache_sim else "callgrind"
            instr, locality = bench_instructions(envs, small, modes, configs, a.cache_sim)

        print(report(info, decode, startup, install, a.runs, instr, locality))
        print("\nTotal bench time %.0f s" % (time.time() - t_start))
        if a.json:
            with open(a.json, "w") as fh:
                json.dump({"info": info,
                           "decode": {m: {c: list(v) for c, v in per.items()} for m, per in decode.items()},
                           "startup": {k: list(v) for k, v in startup.items()},
                           "install": {"%s %s" % k: list(v) for k, v in install.items()},
                           "instructions": instr, "locality": locality}, fh, indent=1)
        return 0
    except (BenchError, TsharkError) as e:
        print("bench: %s" % e, file=sys.stderr)
        return 1
    finally:
        if a.keep:
            log("kept %s and %s" % (work, ", ".join(e.home for e in cleanup)))
        else:
            for e in cleanup:
                e.cleanup()
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

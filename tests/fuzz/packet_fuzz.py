#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Fault-injected captures through a sanitized rules plugin (a campaign, not a CI test).

    DISSGEN_SANITIZE=1 tests/fuzz/packet_fuzz.py --dissgen build/bin/dissgen \
        --rules rules/ethercat.xml --proto ecatr --out /tmp/fz/ecat CAPTURE...

Makes mutated copies of each capture (editcap -E, editcap -s, and byte changes aimed at
EtherCAT lengths / mailbox / CoE-EoE-FoE-SoE headers, or at ENIP encapsulation / CPF item
counts and lengths / CIP path sizes), runs tshark over each in several modes (-V, -2 -V,
-T fields, -z PROTO,tree -q, -T pdml) and reports: a non-zero exit, sanitizer output,
"Dissector bug", a Wireshark exception escaping our protocol ("[Malformed Packet: PROTO]"),
a run over 120 s, and frames whose PROTO subtree differs between one pass and -2.
The mutated captures stay in --out, so every finding has its reproducer.
"""
import argparse
import os
import random
import re
import struct
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "integration", "lib"))
from tshark_env import TsharkEnv  # noqa: E402

TIMEOUT = 120


# -- pcap (classic) ------------------------------------------------------------
def read_pcap(path):
    with open(path, "rb") as fh:
        blob = fh.read()
    magic = struct.unpack("<I", blob[:4])[0]
    end = "<" if magic in (0xA1B2C3D4, 0xA1B23C4D) else ">"
    header, packets, at = blob[:24], [], 24
    while at + 16 <= len(blob):
        ts, tu, incl, orig = struct.unpack(end + "IIII", blob[at:at + 16])
        packets.append([ts, tu, bytearray(blob[at + 16:at + 16 + incl]), orig])
        at += 16 + incl
    return header, end, packets


def write_pcap(path, header, end, packets):
    with open(path, "wb") as fh:
        fh.write(header)
        for ts, tu, data, orig in packets:
            fh.write(struct.pack(end + "IIII", ts, tu, len(data), max(orig, len(data))))
            fh.write(bytes(data))
    os.chmod(path, 0o644)


# -- where the interesting fields are -------------------------------------------
def l3_payload(d):
    """(ethertype, offset of its payload) after Ethernet and VLAN tags."""
    if len(d) < 14:
        return None, None
    et, at = struct.unpack(">H", d[12:14])[0], 14
    while et in (0x8100, 0x88A8) and at + 4 <= len(d):
        et, at = struct.unpack(">H", d[at + 2:at + 4])[0], at + 4
    return et, at


def transport(d):
    """(proto 6/17, src port, dst port, payload offset) of an IPv4 TCP/UDP packet, else None."""
    et, at = l3_payload(d)
    if et != 0x0800 or at + 20 > len(d):
        return None
    ihl = (d[at] & 0x0F) * 4
    proto = d[at + 9]
    t = at + ihl
    if proto == 17 and t + 8 <= len(d):
        sp, dp = struct.unpack(">HH", d[t:t + 4])
        return 17, sp, dp, t + 8
    if proto == 6 and t + 20 <= len(d):
        sp, dp = struct.unpack(">HH", d[t:t + 4])
        return 6, sp, dp, t + ((d[t + 12] >> 4) * 4)
    return None


def ecat_fields(d):
    """[(offset, size)] of length/count/type fields of an EtherCAT frame (raw or over UDP 0x88a4)."""
    et, at = l3_payload(d)
    if et != 0x88A4:
        tr = transport(d)
        if not tr or tr[0] != 17 or 0x88A4 not in tr[1:3]:
            return []
        at = tr[3]
    out = [(at, 2)]                       # frame header: length and type
    p = at + 2
    for _ in range(64):
        if p + 10 > len(d):
            break
        out += [(p, 1), (p + 6, 2), (p + 7, 1)]   # cmd, length (+ C/M flags)
        dlen = struct.unpack("<H", d[p + 6:p + 8])[0] & 0x7FF
        data = p + 10
        if dlen >= 6 and data + 6 <= len(d):
            # a mailbox header: length, address, channel/priority, type/counter,
            # then CoE/EoE/FoE/SoE/AoE header bytes
            out += [(data, 2), (data + 4, 1), (data + 5, 1), (data + 6, 2), (data + 8, 1),
                    (data + 9, 2), (data + 11, 1), (data + 12, 4), (data + 16, 2)]
        more = struct.unpack("<H", d[p + 6:p + 8])[0] & 0x8000
        p = data + dlen + 2
        if not more:
            break
    return [(o, n) for o, n in out if o + n <= len(d)]


def enip_fields(d):
    """[(offset, size)] of ENIP encapsulation / CPF / CIP length and count fields."""
    tr = transport(d)
    if not tr:
        return []
    proto, sp, dp, at = tr
    out = []
    if 2222 in (sp, dp) and proto == 17:
        cpf = at
    elif 44818 in (sp, dp):
        out += [(at, 2), (at + 2, 2), (at + 8, 4)]        # command, length, status
        cpf = at + 24 + 6 if at + 24 <= len(d) and struct.unpack("<H", d[at:at + 2])[0] in (0x6F, 0x70) else None
        if cpf is None:
            out += [(at + 24, 2), (at + 26, 2), (at + 28, 2)]   # ListIdentity etc.: item count, type, length
    else:
        return []
    if cpf is not None and cpf + 2 <= len(d):
        out.append((cpf, 2))
        n = struct.unpack("<H", d[cpf:cpf + 2])[0]
        p = cpf + 2
        for _ in range(min(n, 8)):
            if p + 4 > len(d):
                break
            out += [(p, 2), (p + 2, 2)]
            typ, ln = struct.unpack("<HH", d[p:p + 4])
            if typ in (0xB2, 0xB1) and ln >= 2:
                c = p + 4 + (2 if typ == 0xB1 else 0)
                # CIP: service, path size, first path segment, status/ext status size, MSP count
                out += [(c, 1), (c + 1, 1), (c + 2, 1), (c + 3, 1), (c + 4, 2), (c + 6, 2), (c + 8, 2)]
            p += 4 + ln
    return [(o, n) for o, n in out if o + n <= len(d)]


def mutate_field(d, off, size, rng):
    old = int.from_bytes(d[off:off + size], "little")
    top = (1 << (8 * size)) - 1
    choice = rng.randrange(8)
    if choice == 0:
        new = 0
    elif choice == 1:
        new = top
    elif choice == 2:
        new = (old + rng.choice((1, 2, 4, -1, -2, -4))) & top
    elif choice == 3:
        new = old ^ (1 << rng.randrange(8 * size))
    elif choice == 4:
        new = (old + len(d)) & top
    elif choice == 5:
        new = rng.randrange(top + 1)
    elif choice == 6:
        new = old & ~0x7FF & top if size == 2 else 1       # length 0 (keeping the flags)
    else:
        new = (old | 0x7FF) & top if size == 2 else 0x80
    d[off:off + size] = new.to_bytes(size, "little")


def replicate(packets, copies):
    """A tiny capture repeated `copies` times, each copy on its own client port (so TCP
    does not take the copies for retransmissions), for more mutants per message."""
    out = []
    for c in range(copies):
        for ts, tu, data, orig in packets:
            d = bytearray(data)
            tr = transport(d)
            if tr:
                ip = l3_payload(d)[1]
                th = ip + (d[ip] & 0x0F) * 4
                for at in (th, th + 2):       # the port that is not the server's
                    port = struct.unpack(">H", d[at:at + 2])[0]
                    if port not in (44818, 2222, 0x88A4):
                        d[at:at + 2] = struct.pack(">H", 1024 + (port + c * 7) % 60000)
            out.append([ts + c, tu, d, orig])
    return out


def targeted(packets, finder, rng, rate):
    """Mutate one to three found fields in about `rate` of the packets that have some."""
    n = 0
    for p in packets:
        fields = finder(p[2])
        if fields and rng.random() < rate:
            for _ in range(rng.randint(1, 3)):
                off, size = rng.choice(fields)
                mutate_field(p[2], off, size, rng)
            n += 1
    return n


def make_mutants(base, out, finder, seed, max_frames):
    """Mutated copies of base (a pcap) in folder out; returns their paths."""
    name = os.path.splitext(os.path.basename(base))[0]
    src = os.path.join(out, name + ".orig.pcap")
    subprocess.run(["editcap", "-F", "pcap", "-r", base, src, "1-%d" % max_frames], check=True)
    made = [src]
    for rate in ("0.005", "0.02", "0.1"):
        dst = os.path.join(out, "%s.E%s.pcap" % (name, rate))
        subprocess.run(["editcap", "-E", rate, src, dst], check=True, capture_output=True)
        made.append(dst)
    for snap in (24, 40, 70):
        dst = os.path.join(out, "%s.s%d.pcap" % (name, snap))
        subprocess.run(["editcap", "-s", str(snap), src, dst], check=True)
        made.append(dst)
    header, end, _ = read_pcap(src)
    for k, rate in enumerate((0.05, 0.3, 1.0)):
        rng = random.Random("%s-%d-%d" % (name, seed, k))
        _, _, packets = read_pcap(src)
        if len(packets) < 50:
            packets = replicate(packets, 300 // len(packets) + 1)
        n = targeted(packets, finder, rng, rate)
        if n:
            dst = os.path.join(out, "%s.t%d.pcap" % (name, k))
            write_pcap(dst, header, end, packets)
            made.append(dst)
    # random cuts of each packet inside the fields found (short frames, not snaplen)
    rng = random.Random("%s-%d-cut" % (name, seed))
    _, _, packets = read_pcap(src)
    for p in packets:
        f = finder(p[2])
        if f:
            off, size = rng.choice(f)
            cut = off + rng.randint(0, size + 12)
            p[2] = p[2][:cut]
            p[3] = len(p[2]) if rng.random() < 0.5 else p[3]
    dst = os.path.join(out, "%s.cut.pcap" % name)
    write_pcap(dst, header, end, packets)
    made.append(dst)
    for p in made:
        os.chmod(p, 0o644)
    return made


# -- running ---------------------------------------------------------------------
# What only the second pass can know (docs/manual.md): a request's answer, the frame that
# completes a reassembly, "No response seen", and the slave model of the whole capture.
LATER_LINE = re.compile(r"\s*\[(Response in|Reassembled in)")
LATER_TREE = re.compile(r"\s*(\[Slave at|No response seen)")


def our_sections(verbose, title):
    """{frame number: text of our protocol's subtrees} from tshark -V output, without
    what only the second pass can know."""
    frames, cur, inside, skip_below = {}, None, False, None
    for line in verbose.splitlines():
        m = re.match(r"Frame (\d+):", line)
        if m:
            cur, inside = int(m.group(1)), False
            frames[cur] = []
            continue
        if line and not line[0].isspace():
            inside = line.startswith(title)
        indent = len(line) - len(line.lstrip())
        if skip_below is not None:
            if indent > skip_below:
                continue
            skip_below = None
        if LATER_TREE.match(line):
            skip_below = indent
            continue
        if inside and cur is not None and not LATER_LINE.match(line):
            frames[cur].append(line)
    return {k: "\n".join(v) for k, v in frames.items() if v}


def check_run(env, cap, args, proto, title):
    try:
        # errors="replace": Wireshark 4.0 may cut a long label inside a UTF-8 character
        p = subprocess.run(env.command(["-r", cap] + args), env=env.env(), cwd=env.home, timeout=TIMEOUT,
                           capture_output=True, encoding="utf-8", errors="replace")
    except subprocess.TimeoutExpired:
        return None, ["HANG (>%ds)" % TIMEOUT]
    problems = []
    if p.returncode != 0:
        problems.append("exit %d" % p.returncode)
    err = p.stderr
    for pat in ("AddressSanitizer", "runtime error", "UndefinedBehaviorSanitizer", "LeakSanitizer"):
        if pat in err:
            problems.append("sanitizer: " + pat)
    text = (p.stdout or "") + err
    for pat in ("Dissector bug", "DISSECTOR_ASSERT", "[Malformed Packet: %s]" % proto.upper()):
        if pat in text:
            problems.append(pat)
    if "-V" in args:
        # an exception from a dissector we called (EoE's Ethernet, CIP, ...) names that one
        for frame in re.split(r"^Frame \d+:", p.stdout, flags=re.M):
            if re.search(r"^%s" % re.escape(title), frame, re.M) and "[Malformed Packet" in frame:
                problems.append("[Malformed Packet in a frame with %s: %s" %
                                (title, re.search(r"\[Malformed Packet[^\]]*\]", frame).group(0)))
                break
    if "-T" in args and "pdml" in args:
        # Our malformed expert infos carry a hidden _ws.malformed; a visible one is an
        # exception that escaped (reported when the packet holds our protocol at all).
        for pk in p.stdout.split("<packet>"):
            if '<proto name="%s"' % proto in pk and re.search(r'<proto name="_ws\.malformed"(?![^>]*hide="yes")', pk):
                num = re.search(r'name="frame\.number"[^>]*show="(\d+)"', pk)
                problems.append("visible _ws.malformed in frame %s" % (num.group(1) if num else "?"))
                break
    if err.strip() and not problems:
        problems.append("stderr: " + err.strip().splitlines()[0][:200])
    return p, problems


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", required=True)
    ap.add_argument("--rules", required=True)
    ap.add_argument("--proto", required=True, help="filter name, e.g. ecatr or enipr")
    ap.add_argument("--title", help="first words of the protocol's -V line (default from --proto)")
    ap.add_argument("--out", required=True, help="folder for the mutated captures (kept)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-frames", type=int, default=8000)
    ap.add_argument("--modes", default="V,2V,fields,stats")
    ap.add_argument("captures", nargs="+")
    a = ap.parse_args()
    finder = ecat_fields if a.proto == "ecatr" else enip_fields
    title = a.title or {"ecatr": "EtherCAT", "enipr": "EtherNet/IP (rules)"}.get(a.proto, a.proto)
    os.makedirs(a.out, exist_ok=True)
    os.chmod(a.out, 0o755)
    caps = []
    for c in a.captures:
        caps += make_mutants(c, a.out, finder, a.seed, a.max_frames)
    # -T fields prints one field: one of the protocol's own where known, else the protocol itself
    field = {"ecatr": "ecatr.datagram.cmd", "enipr": "enipr.command"}.get(a.proto, a.proto)
    modes = {"V": ["-V"], "2V": ["-2", "-V"], "fields": ["-T", "fields", "-e", field],
             "stats": ["-z", "%s,tree" % a.proto, "-q"], "pdml": ["-T", "pdml"]}
    wanted = a.modes.split(",")
    findings, runs, frames = [], 0, 0
    with TsharkEnv() as env:
        env.install_plugin(a.dissgen, a.rules)
        for cap in caps:
            one = two = None
            for m in wanted:
                p, problems = check_run(env, cap, modes[m], a.proto, title)
                runs += 1
                for pr in problems:
                    findings.append((cap, m, pr))
                    print("FINDING %s [%s]: %s" % (cap, m, pr), flush=True)
                    if p is not None and "sanitizer" in pr:
                        print(p.stderr[:3000], flush=True)
                if p is not None and m == "V":
                    one = our_sections(p.stdout, title)
                    frames += len(re.findall(r"^Frame \d+:", p.stdout, re.M))
                if p is not None and m == "2V":
                    two = our_sections(p.stdout, title)
            if one is not None and two is not None:
                diff = sorted(k for k in set(one) | set(two) if one.get(k) != two.get(k))
                if diff:
                    findings.append((cap, "V/2V", "frames differ: %s" % diff[:20]))
                    print("FINDING %s: one pass vs -2 differ in frames %s" % (cap, diff[:20]), flush=True)
            print("done %s" % os.path.basename(cap), flush=True)
    print("captures %d, frames %d, tshark runs %d, findings %d" % (len(caps), frames, runs, len(findings)))
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())

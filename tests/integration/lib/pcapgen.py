#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""EtherCAT capture generator, reader and reference decoder (Python 3 stdlib only).

Library:
  Datagram, Frame          what to write (one EtherCAT frame = header + datagrams)
  encode_frame(f)          -> (link-layer bytes as captured, original length)
  random_frames(seed, n, ...)  deterministic varied frames (+ malformed knobs)
  demo_frames()            the deterministic frames of samples/ethercat-demo.pcap
  write_pcap(path, frames) classic pcap, linktype Ethernet, one write
  truth(f)                 the values written, as a JSON-able dict
  read_capture(path)       packets of a pcap or pcapng file
  decode_packet(bytes)     reference decode of a captured Ethernet frame following
                           the ecatr contract (datagrams only inside the header's
                           Length, only for header type 1, partial when truncated)

CLI:
  pcapgen.py random --seed S --frames N -o out.pcap [--truth out.json] [knobs]
  pcapgen.py demo -o samples/ethercat-demo.pcap [--truth out.json]
  pcapgen.py decode capture.pcap[ng]          reference decode, one JSON line a frame
  pcapgen.py selftest [--frames N]            encode/decode round trip checks
"""

import argparse
import json
import random
import signal
import struct
import sys
from dataclasses import dataclass
from typing import List, Optional

ETHERTYPE_ECAT = 0x88A4
ETHERTYPE_VLAN = 0x8100
ETHERTYPE_IPV4 = 0x0800
ECAT_UDP_PORT = 34980
ETH_MIN_FRAME = 60          # without FCS
ETH_MAX_PAYLOAD = 1500
DGRAM_OVERHEAD = 12         # 10-byte datagram header + 2-byte working counter
MAX_DATA_LEN = 1486          # a lone datagram filling a 1500-byte payload

CMD_NAMES = {
    0: "NOP", 1: "APRD", 2: "APWR", 3: "APRW", 4: "FPRD", 5: "FPWR", 6: "FPRW",
    7: "BRD", 8: "BWR", 9: "BRW", 10: "LRD", 11: "LWR", 12: "LRW", 13: "ARMW", 14: "FRMW",
}
LOGICAL_CMDS = (10, 11, 12)



def is_logical(cmd):
    return cmd in LOGICAL_CMDS


@dataclass
class Datagram:
    cmd: int
    idx: int = 0
    adp: int = 0            # non-logical commands: position / station address
    ado: int = 0            # non-logical commands: register / memory offset
    lad: int = 0            # logical commands (LRD/LWR/LRW): 32-bit logical address
    data: bytes = b""
    reserved: int = 0       # 3 bits
    circulating: bool = False
    more: Optional[bool] = None   # None: set by the frame (1 on every datagram but the last)
    irq: int = 0
    wkc: int = 0
    len_field: Optional[int] = None  # None: len(data); otherwise the 11-bit value written

    def addr32(self):
        if is_logical(self.cmd):
            return self.lad & 0xFFFFFFFF
        return (self.adp & 0xFFFF) | ((self.ado & 0xFFFF) << 16)

    def length_value(self):
        return len(self.data) if self.len_field is None else self.len_field

    def encode(self, more):
        word = (self.length_value() & 0x7FF) | ((self.reserved & 7) << 11) \
            | (int(bool(self.circulating)) << 14) | (int(bool(more)) << 15)
        return struct.pack("<BBIHH", self.cmd, self.idx, self.addr32(), word, self.irq) \
            + self.data + struct.pack("<H", self.wkc)


@dataclass
class Frame:
    datagrams: List[Datagram]
    encap: str = "eth"              # "eth", "vlan" or "udp"
    header_type: int = 1
    header_reserved: int = 0
    header_length: Optional[int] = None   # None: sum of the datagrams
    m_on_last: bool = False          # malformed: M=1 on the last datagram
    truncate_to: Optional[int] = None     # malformed: keep only this many bytes of the
                                          # EtherCAT payload (2-byte header included)
    truncate_mode: str = "snap"      # "snap": pcap orig_len keeps the full size; "short": it doesn't
    pad: bool = True                 # pad short frames to 60 bytes
    vlan_tci: int = 0x0064
    src_mac: bytes = b"\x02\x00\x00\x00\x00\x01"
    dst_mac: bytes = b"\xff\xff\xff\xff\xff\xff"
    src_ip: bytes = bytes([192, 168, 10, 1])
    dst_ip: bytes = bytes([192, 168, 10, 255])
    udp_sport: int = ECAT_UDP_PORT
    udp_dport: int = ECAT_UDP_PORT
    ts: float = 0.0
    note: str = ""                   # why this frame exists (e.g. "m_on_last", "truncated")
    odd_lengths: bool = False        # a header or datagram Length disagrees with the bytes
    padding: bytes = b""             # bytes after the datagrams, inside the header's Length
                                     # (zeros: a master keeping the Length at a minimum)

    def more_bits(self):
        bits = []
        n = len(self.datagrams)
        for i, d in enumerate(self.datagrams):
            if d.more is not None:
                bits.append(bool(d.more))
            else:
                bits.append(i < n - 1 or (i == n - 1 and self.m_on_last))
        return bits

    def body(self):
        return b"".join(d.encode(m) for d, m in zip(self.datagrams, self.more_bits()))

    def ecat_payload(self):
        body = self.body() + self.padding
        length = len(body) if self.header_length is None else self.header_length
        hdr = (length & 0x7FF) | ((self.header_reserved & 1) << 11) | ((self.header_type & 0xF) << 12)
        return struct.pack("<H", hdr) + body


def ip_checksum(hdr):
    s = sum(struct.unpack("!%dH" % (len(hdr) // 2), hdr))
    while s >> 16:
        s = (s & 0xFFFF) + (s >> 16)
    return (~s) & 0xFFFF


def udp_ethernet_frame(payload, port, src_ip=b"\x0a\x00\x00\x01", dst_ip=b"\x0a\x00\x00\x02"):
    """payload in UDP (source and destination `port`) in IPv4 in Ethernet II."""
    u = struct.pack("!HHHH", port, port, 8 + len(payload), 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0, src_ip, dst_ip)
    ip = ip[:10] + struct.pack("!H", ip_checksum(ip)) + ip[12:]
    return b"\x02\xee\xee\xee\xee\xee\x02\x00\x00\x00\x00\x01" + struct.pack("!H", ETHERTYPE_IPV4) + ip + u


def tcp_ethernet_frame(payload, sport, dport, seq, src_ip=b"\x0a\x00\x00\x01", dst_ip=b"\x0a\x00\x00\x02"):
    """payload in one TCP segment (sequence number `seq`, PSH+ACK, no checksum) in IPv4 in
    Ethernet II; a flow is the segments of consecutive `seq` (no handshake needed)."""
    t = struct.pack("!HHIIBBHHH", sport, dport, seq, 1, 5 << 4, 0x18, 65535, 0, 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(t), 0, 0x4000, 64, 6, 0, src_ip, dst_ip)
    ip = ip[:10] + struct.pack("!H", ip_checksum(ip)) + ip[12:]
    return b"\x02\xee\xee\xee\xee\xee\x02\x00\x00\x00\x00\x01" + struct.pack("!H", ETHERTYPE_IPV4) + ip + t


def encode_frame(f):
    """Return (captured bytes, original length) of an Ethernet frame."""
    payload = f.ecat_payload()
    cut = None
    if f.truncate_to is not None and f.truncate_to < len(payload):
        cut = f.truncate_to
    if f.encap == "udp":
        full_udp = 8 + len(payload)
        udp = struct.pack("!HHHH", f.udp_sport, f.udp_dport, full_udp, 0)
        ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + full_udp, 0, 0x4000, 64, 17, 0,
                         f.src_ip, f.dst_ip)
        ip = ip[:10] + struct.pack("!H", ip_checksum(ip)) + ip[12:]
        l2 = f.dst_mac + f.src_mac + struct.pack("!H", ETHERTYPE_IPV4)
        head = l2 + ip + udp
    elif f.encap == "vlan":
        head = f.dst_mac + f.src_mac + struct.pack("!HHH", ETHERTYPE_VLAN, f.vlan_tci, ETHERTYPE_ECAT)
    elif f.encap == "eth":
        head = f.dst_mac + f.src_mac + struct.pack("!H", ETHERTYPE_ECAT)
    else:
        raise ValueError("unknown encap %r" % f.encap)
    full = head + payload
    if f.pad and len(full) < ETH_MIN_FRAME:
        full += b"\x00" * (ETH_MIN_FRAME - len(full))
    if cut is None:
        return full, len(full)
    captured = full[:len(head) + cut]
    return captured, (len(full) if f.truncate_mode == "snap" else len(captured))


def truth(f, number=None):
    """The values written into the frame (before any truncation), JSON-able."""
    body = f.body()
    dgs = []
    for d, m in zip(f.datagrams, f.more_bits()):
        g = {"cmd": d.cmd, "idx": d.idx}
        if is_logical(d.cmd):
            g["lad"] = d.lad
        else:
            g["adp"] = d.adp
            g["ado"] = d.ado
        g.update({"len": d.length_value(), "reserved": d.reserved, "circulating": bool(d.circulating),
                  "more": m, "irq": d.irq, "data": d.data.hex(), "wkc": d.wkc})
        dgs.append(g)
    t = {"encap": f.encap,
         "header": {"length": len(body) + len(f.padding) if f.header_length is None else f.header_length,
                    "reserved": f.header_reserved, "type": f.header_type},
         "datagrams": dgs,
         "note": f.note}
    if number is not None:
        t["frame"] = number
    if f.m_on_last:
        t["m_on_last"] = True
    if f.truncate_to is not None:
        t["truncate_to"] = f.truncate_to
    if f.odd_lengths:
        t["odd_lengths"] = True
    return t


# --------------------------------------------------------------------------- pcap I/O

def pcap_bytes(frames, base_ts=1704067200.0):
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i, f in enumerate(frames):
        data, orig = encode_frame(f)
        ts = f.ts if f.ts else base_ts + i * 0.001
        sec = int(ts)
        usec = int(round((ts - sec) * 1e6))
        if usec >= 1000000:
            sec, usec = sec + 1, usec - 1000000
        out.append(struct.pack("<IIII", sec, usec, len(data), orig))
        out.append(data)
    return b"".join(out)


def raw_pcap_bytes(frames, base_ts=1704067200.0):
    """A pcap of Ethernet frames given as bytes, 1 ms apart."""
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i, data in enumerate(frames):
        out.append(struct.pack("<IIII", int(base_ts), i * 1000, len(data), len(data)) + data)
    return b"".join(out)


def write_pcap(path, frames):
    blob = pcap_bytes(frames)
    with open(path, "wb") as fh:
        fh.write(blob)
    return len(blob)


def read_capture(path):
    """Yield (linktype, captured bytes, original length) of every packet of a pcap/pcapng file."""
    with open(path, "rb") as fh:
        blob = fh.read()
    magic = blob[:4]
    if magic in (b"\xd4\xc3\xb2\xa1", b"\x4d\x3c\xb2\xa1", b"\xa1\xb2\xc3\xd4", b"\xa1\xb2\x3c\x4d"):
        e = "<" if magic in (b"\xd4\xc3\xb2\xa1", b"\x4d\x3c\xb2\xa1") else ">"
        linktype = struct.unpack(e + "I", blob[20:24])[0] & 0x0FFFFFFF
        off = 24
        while off + 16 <= len(blob):
            _, _, incl, orig = struct.unpack(e + "IIII", blob[off:off + 16])
            off += 16
            yield linktype, blob[off:off + incl], orig
            off += incl
        return
    if magic != b"\x0a\x0d\x0d\x0a":
        raise ValueError("%s: not a pcap or pcapng file" % path)
    off = 0
    e = "<"
    linktypes = []
    while off + 12 <= len(blob):
        btype = struct.unpack(e + "I", blob[off:off + 4])[0]
        if btype == 0x0A0D0D0A:     # section header: byte order from its magic
            e = "<" if blob[off + 8:off + 12] == b"\x4d\x3c\x2b\x1a" else ">"
            linktypes = []
        blen = struct.unpack(e + "I", blob[off + 4:off + 8])[0]
        if blen < 12 or off + blen > len(blob):
            break
        body = blob[off + 8:off + blen - 4]
        if btype == 1:              # interface description
            linktypes.append(struct.unpack(e + "H", body[:2])[0])
        elif btype == 6:            # enhanced packet
            ifid, _, _, cap, orig = struct.unpack(e + "IIIII", body[:20])
            yield linktypes[ifid], body[20:20 + cap], orig
        elif btype == 3:            # simple packet
            orig = struct.unpack(e + "I", body[:4])[0]
            yield linktypes[0], body[4:4 + min(orig, len(body) - 4)], orig
        off += blen


# --------------------------------------------------------------------------- reference decoder

def ecat_payload_of(pkt, linktype=1):
    """Locate the EtherCAT payload the way the ecatr hooks do: ethertype 0x88A4 (after any
    802.1Q tags) or IPv4/UDP port 34980.  Return (payload, encap) or (None, None)."""
    if linktype != 1 or len(pkt) < 14:
        return None, None
    off = 12
    etype = struct.unpack("!H", pkt[off:off + 2])[0]
    encap = "eth"
    while etype in (ETHERTYPE_VLAN, 0x88A8) and len(pkt) >= off + 6:
        off += 4
        etype = struct.unpack("!H", pkt[off:off + 2])[0]
        encap = "vlan"
    off += 2
    if etype == ETHERTYPE_ECAT:
        return pkt[off:], encap
    if etype == ETHERTYPE_IPV4 and len(pkt) >= off + 20:
        ihl = (pkt[off] & 0x0F) * 4
        if pkt[off + 9] != 17 or len(pkt) < off + ihl + 8:
            return None, None
        frag = struct.unpack("!H", pkt[off + 6:off + 8])[0]
        if frag & 0x3FFF:           # fragments are not EtherCAT datagrams on their own
            return None, None
        total = struct.unpack("!H", pkt[off + 2:off + 4])[0]
        u = off + ihl
        sport, dport, ulen = struct.unpack("!HHH", pkt[u:u + 6])
        if ECAT_UDP_PORT not in (sport, dport):
            return None, None
        end = u + max(8, min(ulen, total - ihl))
        return pkt[u + 8:end], "udp"
    return None, None


class Partial:
    """A field that starts inside the decoded region but does not fit in it: the decoder
    may leave it out or show the part that is there (value = the bytes that are there)."""
    def __init__(self, value):
        self.value = value

    def __repr__(self):
        return "Partial(%r)" % (self.value,)


def decode_ecat(payload):
    """Decode an EtherCAT payload per the ecatr contract.

    Returns {"header": {...} or None, "datagrams": [ {field: value} ], "stop": reason}.
    A datagram cut short has only the fields that fit; a data field that starts but does not
    fit is a Partial."""
    res = {"header": None, "datagrams": [], "stop": None}
    if len(payload) < 2:
        res["stop"] = "no header"
        return res
    h = struct.unpack("<H", payload[:2])[0]
    res["header"] = {"length": h & 0x7FF, "reserved": (h >> 11) & 1, "type": h >> 12}
    if h >> 12 != 1:
        res["stop"] = "type"
        return res
    end = min(2 + (h & 0x7FF), len(payload))
    off = 2
    while True:
        d = {}
        res["datagrams"].append(d)

        def take(n):
            nonlocal off
            if off + n > end:
                return None
            v = payload[off:off + n]
            off += n
            return v

        b = take(1)
        if b is None:
            res["datagrams"].pop()
            res["stop"] = "more flag but no data left"
            break
        d["cmd"] = b[0]
        b = take(1)
        if b is None:
            res["stop"] = "truncated"
            break
        d["idx"] = b[0]
        if is_logical(d["cmd"]):
            b = take(4)
            if b is None:
                res["stop"] = "truncated"
                break
            d["lad"] = struct.unpack("<I", b)[0]
        else:
            b = take(2)
            if b is None:
                res["stop"] = "truncated"
                break
            d["adp"] = struct.unpack("<H", b)[0]
            b = take(2)
            if b is None:
                res["stop"] = "truncated"
                break
            d["ado"] = struct.unpack("<H", b)[0]
        b = take(2)
        if b is None:
            res["stop"] = "truncated"
            break
        w = struct.unpack("<H", b)[0]
        d.update({"len": w & 0x7FF, "reserved": (w >> 11) & 7,
                  "circulating": bool(w & 0x4000), "more": bool(w & 0x8000)})
        b = take(2)
        if b is None:
            res["stop"] = "truncated"
            break
        d["irq"] = struct.unpack("<H", b)[0]
        b = take(d["len"])
        if b is None:
            d["data"] = Partial(payload[off:end])
            res["stop"] = "truncated"
            break
        d["data"] = bytes(b)
        b = take(2)
        if b is None:
            res["stop"] = "truncated"
            break
        d["wkc"] = struct.unpack("<H", b)[0]
        if not d["more"]:
            break
    return res


def decode_packet(pkt, linktype=1):
    payload, encap = ecat_payload_of(pkt, linktype)
    if payload is None:
        return None
    r = decode_ecat(payload)
    r["encap"] = encap
    return r


def jsonable(obj):
    if isinstance(obj, bytes):
        return obj.hex()
    if isinstance(obj, Partial):
        return {"partial": jsonable(obj.value)}
    if isinstance(obj, dict):
        return {k: jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [jsonable(v) for v in obj]
    return obj


# --------------------------------------------------------------------------- random frames

REGISTER_ADOS = [0x0000, 0x0004, 0x0008, 0x0010, 0x0012, 0x0100, 0x0101, 0x0110, 0x0120, 0x0130,
                 0x0134, 0x0140, 0x0200, 0x0300, 0x0310, 0x0400, 0x0420, 0x0440, 0x0500, 0x0502,
                 0x0504, 0x0508, 0x0510, 0x0600, 0x0610, 0x0800, 0x0808, 0x0810, 0x0900, 0x0910,
                 0x0918, 0x0920, 0x0928, 0x092C, 0x0980, 0x0981, 0x0990, 0x09A0, 0x0E00, 0x0F00]
MAILBOX_ADOS = [0x1000, 0x1080, 0x1100, 0x1200, 0x1400, 0x1800, 0x1C00]


class RandomFrames:
    def __init__(self, seed, max_datagrams=12):
        self.rng = random.Random(seed)
        self.max_datagrams = max_datagrams
        self.idx = 0

    def data_len(self):
        r = self.rng.random()
        if r < 0.12:
            return 0
        if r < 0.55:
            return self.rng.choice([1, 2, 4, 8, 16, 32])
        if r < 0.80:
            return self.rng.randint(1, 64)
        if r < 0.95:
            return self.rng.randint(65, 400)
        return self.rng.randint(401, MAX_DATA_LEN)

    def data(self, n):
        r = self.rng.random()
        if r < 0.15:
            return bytes(n)
        if r < 0.20:
            return b"\xff" * n
        return self.rng.getrandbits(8 * n).to_bytes(n, "little") if n else b""

    def u16(self):
        r = self.rng.random()
        if r < 0.4:
            return 0
        if r < 0.5:
            return 0xFFFF
        return self.rng.getrandbits(16)

    def datagram(self, cmd, n):
        rng = self.rng
        d = Datagram(cmd=cmd, idx=rng.getrandbits(8) if rng.random() < 0.5 else self.idx & 0xFF)
        self.idx += 1
        if is_logical(cmd):
            d.lad = rng.choice([0x00010000, 0x00010000 + rng.getrandbits(12), 0x09000000,
                                rng.getrandbits(32), 0, 0xFFFFFFFF])
        else:
            d.adp = rng.choice([0, 0xFFFF, (-rng.randint(1, 20)) & 0xFFFF, 0x1000 + rng.randint(0, 40),
                                0x03E9 + rng.randint(0, 10), rng.getrandbits(16)])
            r = rng.random()
            if r < 0.45:
                d.ado = rng.choice(REGISTER_ADOS) + (rng.randint(0, 8) if rng.random() < 0.2 else 0)
            elif r < 0.65:
                d.ado = rng.choice(MAILBOX_ADOS)
            elif r < 0.8:
                d.ado = rng.randint(0x1000, 0xFFFF)
            else:
                d.ado = rng.getrandbits(16)
        d.data = self.data(n)
        if rng.random() < 0.1:
            d.reserved = rng.randint(1, 7)
        d.circulating = rng.random() < 0.1
        r = rng.random()
        d.irq = 0 if r < 0.6 else (rng.getrandbits(16) if r < 0.9 else 0xFFFF)
        r = rng.random()
        d.wkc = 0 if r < 0.3 else (rng.randint(1, 3) if r < 0.8 else
                                   (rng.getrandbits(16) if r < 0.95 else 0xFFFF))
        return d

    def frame(self, cmds=None):
        rng = self.rng
        r = rng.random()
        encap = "eth" if r < 0.75 else ("vlan" if r < 0.87 else "udp")
        max_payload = ETH_MAX_PAYLOAD - (28 if encap == "udp" else 0)
        n = len(cmds) if cmds else rng.randint(1, self.max_datagrams)
        if not cmds:
            cmds = [rng.randint(0, 14) for _ in range(n)]
        budget = max_payload - 2 - DGRAM_OVERHEAD * n
        lens = []
        for _ in range(n):
            want = self.data_len()
            want = min(want, budget, MAX_DATA_LEN)
            lens.append(want)
            budget -= want
        rng.shuffle(lens)
        f = Frame([self.datagram(c, l) for c, l in zip(cmds, lens)], encap=encap)
        if encap == "vlan":
            f.vlan_tci = (rng.randint(0, 7) << 13) | rng.randint(1, 4094)
        if encap == "udp":
            f.src_ip = bytes([10, 0, rng.randint(0, 255), rng.randint(1, 254)])
            f.dst_ip = bytes([10, 0, rng.randint(0, 255), rng.randint(1, 254)])
            if rng.random() < 0.5:      # above 34980: UDP tries the lower port's dissector first
                f.udp_sport = rng.randint(49152, 65535)
        f.src_mac = bytes([rng.choice([0x00, 0x02, 0x03])]) + bytes(rng.getrandbits(8) for _ in range(5))
        if rng.random() < 0.5:
            f.dst_mac = bytes([0x01, 0x01, 0x05, 0x01, 0x00, 0x00])
        return f


def random_frames(seed, n, max_datagrams=12, m_on_last=0, truncated=0, other_types=0, odd_lengths=0):
    """n frames: the valid ones first cover all 15 commands, then the malformed/odd ones
    (m_on_last, truncated, other header types, and odd_lengths of each: the header's reserved
    bit set, a header Length that disagrees with the datagrams, a datagram Length that
    disagrees with its data) are spread through the capture deterministically.
    Frame i has ts base+i ms."""
    g = RandomFrames(seed, max_datagrams)
    frames = []
    special = ["m_on_last"] * m_on_last + ["truncated"] * truncated + ["type"] * other_types
    special += ["reserved_bit", "header_length", "datagram_length"] * odd_lengths
    special = special[:n]
    pool = range(15, n) if n - 15 >= len(special) else range(n)
    positions = g.rng.sample(pool, len(special))
    kinds = dict(zip(positions, g.rng.sample(special, len(special))))
    for i in range(n):
        kind = kinds.get(i)
        if i < 15 and kind is None:
            cmds = [i] + [g.rng.randint(0, 14) for _ in range(g.rng.randint(0, min(3, max_datagrams - 1)))]
            g.rng.shuffle(cmds)
            f = g.frame(cmds)
        else:
            f = g.frame()
        if kind == "m_on_last":
            make_m_on_last(f, g.rng)
        elif kind == "truncated":
            make_truncated(f, g.rng)
        elif kind == "reserved_bit":
            f.header_reserved = 1
            f.note = "header reserved bit set"
        elif kind == "header_length":
            make_header_length(f, g.rng)
        elif kind == "datagram_length":
            make_datagram_length(f, g.rng)
        elif kind == "type":
            f.header_type = g.rng.choice([0, 4, 7, 0xD])
            f.note = "header type %d" % f.header_type
            if f.header_type == 4:      # NV: Wireshark has its own sub-dissector; keep it odd-only
                f.header_type = 7
                f.note = "header type 7"
        frames.append(f)
    return frames


def make_m_on_last(f, rng):
    """M=1 on the last datagram; keep the frame short on plain Ethernet so that at least 12
    bytes of padding follow (which Wireshark's plugin reads as one more datagram)."""
    f.m_on_last = True
    f.encap = "eth" if rng.random() < 0.7 else "vlan"
    f.datagrams = f.datagrams[:rng.randint(1, 2)]
    for d in f.datagrams:
        d.data = d.data[:rng.randint(0, 6)]
    f.note = "m_on_last"


def make_header_length(f, rng):
    """A header Length that disagrees with the datagrams: a little or a lot shorter (the last
    datagrams are cut or missing), or longer (padding or nothing follows)."""
    body = len(f.body())
    delta = rng.choice([-1, -2, -12, -body // 2, 1, 2, 12, 40, 0x7FF - body])
    f.header_length = max(0, min(0x7FF, body + delta))
    if f.header_length == body:
        f.header_length = body - 1 if body else 1
    f.odd_lengths = True
    f.note = "header Length %d for %d bytes of datagrams" % (f.header_length, body)


def make_datagram_length(f, rng):
    """One datagram's Length disagrees with its data: the datagrams after it are misread."""
    k = rng.randrange(len(f.datagrams))
    d = f.datagrams[k]
    delta = rng.choice([-1, -2, 1, 2, 12, 100, 0x7FF])
    d.len_field = max(0, min(0x7FF, len(d.data) + delta))
    if d.len_field == len(d.data):
        d.len_field = len(d.data) + 1
    f.odd_lengths = True
    f.note = "datagram %d has Length %d for %d bytes of data" % (k + 1, d.len_field, len(d.data))


def make_truncated(f, rng):
    """Cut the capture inside one of the datagrams (not on a datagram boundary)."""
    f.encap = rng.choice(["eth", "eth", "vlan"])
    body_len = len(f.body())
    bounds = set()
    off = 2
    for d in f.datagrams:
        bounds.add(off)
        off += DGRAM_OVERHEAD + d.length_value()
    bounds.add(off)
    choices = [c for c in range(3, 2 + body_len) if c not in bounds]
    if not choices:
        f.datagrams[0].data = bytes(8)
        return make_truncated(f, rng)
    f.truncate_to = rng.choice(choices)
    f.truncate_mode = rng.choice(["snap", "short"])
    f.pad = False
    f.note = "truncated at payload byte %d (%s)" % (f.truncate_to, f.truncate_mode)


# --------------------------------------------------------------------------- demo capture

def demo_frames():
    """~40 frames of a 3-slave bus (EK1100 + 2 terminals): scan, PREOP/SAFEOP/OP, DC,
    cyclic LRW + FRMW/ARMW, one EtherCAT-over-UDP exchange.  Every exchange is captured
    going out (WKC 0) and coming back (WKC counted, src MAC with the U/L bit set)."""
    master = b"\x00\x1b\x21\x3c\x55\x10"
    back = bytes([master[0] | 0x02]) + master[1:]
    slaves = [0x1001, 0x1002, 0x1003]
    frames = []
    t_us = 0                # microseconds since 2024-01-01 00:00:00 UTC
    idx = 0

    def exchange(specs, encap="eth", dt=500):
        """specs: list of (Datagram, returned data or None, returned wkc); dt: round trip in us."""
        nonlocal t_us, idx
        out, ret = [], []
        for d, rdata, rwkc in specs:
            d.idx = idx & 0xFF
            idx += 1
            out.append(Datagram(d.cmd, d.idx, d.adp, d.ado, d.lad, d.data, irq=0, wkc=0))
            ret.append(Datagram(d.cmd, d.idx, d.adp, d.ado, d.lad,
                                d.data if rdata is None else rdata, irq=0, wkc=rwkc))
        if encap == "udp":      # master PC <-> a remote EtherCAT gateway, by IP
            a = dict(mac=master, ip=bytes([192, 168, 1, 10]))
            b = dict(mac=b"\x00\x01\x05\x22\x33\x44", ip=bytes([192, 168, 1, 20]))
            frames.append(Frame(out, encap=encap, src_mac=a["mac"], dst_mac=b["mac"], src_ip=a["ip"],
                                dst_ip=b["ip"], ts=1704067200 + t_us * 1e-6))
            t_us += dt
            frames.append(Frame(ret, encap=encap, src_mac=b["mac"], dst_mac=a["mac"], src_ip=b["ip"],
                                dst_ip=a["ip"], ts=1704067200 + t_us * 1e-6))
        else:
            frames.append(Frame(out, encap=encap, src_mac=master, ts=1704067200 + t_us * 1e-6))
            t_us += dt
            frames.append(Frame(ret, encap=encap, src_mac=back, ts=1704067200 + t_us * 1e-6))
        t_us += 1000

    # Bus scan: count slaves, reset, assign station addresses, read ESC info.
    exchange([(Datagram(7, ado=0x0000, data=bytes(2)), bytes([0x11, 0x00]), 3)])
    exchange([(Datagram(8, ado=0x0101, data=b"\x00"), None, 3),
              (Datagram(8, ado=0x0600, data=bytes(64)), None, 3),
              (Datagram(8, ado=0x0800, data=bytes(32)), None, 3),
              (Datagram(8, ado=0x0120, data=b"\x11\x00"), None, 3)])
    exchange([(Datagram(2, adp=(-i) & 0xFFFF, ado=0x0010, data=struct.pack("<H", s)), None, 1)
              for i, s in enumerate(slaves)])
    exchange([(Datagram(1, adp=(-i) & 0xFFFF, ado=0x0000, data=bytes(12)),
               bytes([0x11, 0x00, 0x01, 0x00, 0x08, 0x08, 0x0F, 0x01, 0xFC, 0x01, 0x00, 0x00]), 1)
              for i in range(3)])
    # SII (EEPROM) read of the vendor id of slave 1.
    exchange([(Datagram(5, adp=slaves[0], ado=0x0502, data=b"\x00\x01\x08\x00\x00\x00"), None, 1)])
    exchange([(Datagram(4, adp=slaves[0], ado=0x0502, data=bytes(10)),
               b"\x40\x00\x08\x00\x00\x00\x02\x00\x00\x00", 1)])
    # DC: latch receive times, read them, write offsets and delays.
    exchange([(Datagram(8, ado=0x0900, data=bytes(4)), None, 3)])
    exchange([(Datagram(4, adp=s, ado=0x0900, data=bytes(16)),
               struct.pack("<4I", 0x1A2B0000 + 140 * i, 0x1A2B0000 + 820 - 140 * i, 0, 0), 1)
              for i, s in enumerate(slaves)])
    exchange([(Datagram(5, adp=s, ado=0x0920, data=struct.pack("<q", -123456789 + 17 * i)), None, 1)
              for i, s in enumerate(slaves)] +
             [(Datagram(5, adp=s, ado=0x0928, data=struct.pack("<I", 70 * i)), None, 1)
              for i, s in enumerate(slaves)])
    # Sync manager / FMMU set-up of slave 2 and state changes PREOP -> SAFEOP -> OP.
    exchange([(Datagram(5, adp=slaves[1], ado=0x0800,
                        data=struct.pack("<HHBBBB", 0x1100, 2, 0x24, 0, 1, 0)), None, 1),
              (Datagram(5, adp=slaves[1], ado=0x0600,
                        data=struct.pack("<IHBBHBBB3x", 0x00010000, 2, 0, 7, 0x1100, 0, 2, 1)), None, 1)])
    for state in (0x0002, 0x0004, 0x0008):
        exchange([(Datagram(8, ado=0x0120, data=struct.pack("<H", state)), None, 3),
                  (Datagram(7, ado=0x0130, data=bytes(2)), struct.pack("<H", state), 3)])
    # Cyclic: DC time distribution (FRMW from the reference clock, sometimes ARMW) + LRW.
    systime = 0x000000A1B2C3D400
    for cyc in range(6):
        systime += 1000000
        outputs = bytes([(cyc * 3) & 0xFF, (1 << (cyc % 8)), 0, 0])
        inputs = bytes([0x5A ^ cyc, cyc, 0x00, 0x80])
        dc = (Datagram(14, adp=slaves[0], ado=0x0910, data=bytes(8)) if cyc % 4 else
              Datagram(13, adp=0x0000, ado=0x0910, data=bytes(8)))
        specs = [(dc, struct.pack("<Q", systime), 3),
                 (Datagram(12, lad=0x00010000, data=outputs + bytes(4)), outputs + inputs, 6)]
        if cyc % 3 == 2:
            specs.append((Datagram(7, ado=0x0130, data=bytes(2)), b"\x08\x00", 3))
        exchange(specs, dt=120)
    # One EtherCAT-over-UDP exchange (read AL status of all slaves).
    exchange([(Datagram(7, ado=0x0130, data=bytes(2)), b"\x08\x00", 3)], encap="udp")
    for f in frames:
        f.note = "demo"
    return frames


# --------------------------------------------------------------------------- self test

def expected_from_truth(t):
    """What decode_ecat must give for a valid, untruncated frame written with truth t."""
    dgs = []
    for g in t["datagrams"]:
        d = dict(g)
        d["data"] = bytes.fromhex(d["data"])
        dgs.append(d)
    return dgs


def selftest(n=2000, seed=7):
    frames = random_frames(seed, n, max_datagrams=20, m_on_last=20, truncated=20, other_types=5)
    frames += demo_frames()
    cmds = set()
    errors = 0
    for i, f in enumerate(frames):
        pkt, orig = encode_frame(f)
        t = truth(f, i + 1)
        r = decode_packet(pkt)
        assert r is not None and r["encap"] == f.encap, (i, r)
        if f.truncate_to is None:
            assert orig == len(pkt) and len(pkt) >= ETH_MIN_FRAME
            assert len(f.ecat_payload()) <= ETH_MAX_PAYLOAD - (28 if f.encap == "udp" else 0)
            assert r["header"] == t["header"], (i, r["header"], t["header"])
            if f.header_type == 1:
                if r["datagrams"] != expected_from_truth(t):
                    errors += 1
                    print("frame %d: decode != truth" % (i + 1), file=sys.stderr)
            else:
                assert r["datagrams"] == []
            for g in t["datagrams"]:
                cmds.add(g["cmd"])
        else:
            # a truncated frame decodes to a prefix of the truth
            exp = expected_from_truth(t)
            for k, d in enumerate(r["datagrams"]):
                for key, v in d.items():
                    want = exp[k][key]
                    if isinstance(v, Partial):
                        assert want.startswith(v.value) and len(v.value) < len(want), (i, k, key)
                    else:
                        assert v == want, (i, k, key, v, want)
            assert r["stop"] == "truncated", (i, r["stop"])
    assert cmds == set(range(15)), sorted(cmds)
    print("selftest: %d frames, %d errors" % (len(frames), errors))
    return errors == 0


def main(argv=None):
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)     # `pcapgen.py decode X | head` is fine
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="what", required=True)
    r = sub.add_parser("random", help="seeded random frames")
    r.add_argument("--seed", type=int, default=1)
    r.add_argument("--frames", type=int, default=3000)
    r.add_argument("--max-datagrams", type=int, default=12, choices=range(1, 21), metavar="1..20")
    r.add_argument("--m-on-last", type=int, default=0, help="frames with M=1 on the last datagram")
    r.add_argument("--truncated", type=int, default=0, help="frames cut inside a datagram")
    r.add_argument("--other-types", type=int, default=0, help="frames with header type != 1")
    r.add_argument("-o", "--output", required=True)
    r.add_argument("--truth", help="write the values written (JSON) here")
    d = sub.add_parser("demo", help="the realistic demo capture")
    d.add_argument("-o", "--output", required=True)
    d.add_argument("--truth")
    dec = sub.add_parser("decode", help="reference decode of a pcap/pcapng")
    dec.add_argument("capture")
    st = sub.add_parser("selftest")
    st.add_argument("--frames", type=int, default=2000)
    a = ap.parse_args(argv)
    if a.what == "selftest":
        return 0 if selftest(a.frames) else 1
    if a.what == "decode":
        for n, (lt, pkt, orig) in enumerate(read_capture(a.capture), 1):
            res = decode_packet(pkt, lt)
            if res is not None:
                res["frame"] = n
                print(json.dumps(jsonable(res)))
        return 0
    if a.what == "random":
        frames = random_frames(a.seed, a.frames, a.max_datagrams, a.m_on_last, a.truncated, a.other_types)
    else:
        frames = demo_frames()
    size = write_pcap(a.output, frames)
    if a.truth:
        with open(a.truth, "w") as fh:
            json.dump([truth(f, i + 1) for i, f in enumerate(frames)], fh, indent=None)
            fh.write("\n")
    print("%s: %d frames, %d bytes" % (a.output, len(frames), size))
    return 0


if __name__ == "__main__":
    sys.exit(main())

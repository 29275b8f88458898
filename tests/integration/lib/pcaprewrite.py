#!/usr/bin/env python3
"""Rewrite real captures for fault injection (Python 3 standard library only).

    cap = Capture.read("replay-dc.pcapng")
    pkt = cap.packets[10]           # Packet: .data (bytearray), .ts (ns), .ifid, .tag
    del cap.packets[11]             # drop a frame
    cap.write("copy.pcapng")

pcapng files keep every block (section header, interfaces, statistics, ...) in
place and only rewrite enhanced packet blocks, options included; the section
length is set to "unknown" because packets change size. Classic pcap files
keep their header. Each packet remembers its position in the original file
(`tag`), so tests can map frame numbers before and after a change.

EtherCAT helpers: `ecat_datagrams(pkt)` lists the datagrams of an Ethernet
frame with ethertype 0x88A4 (offsets into pkt.data), `set_u16` writes a
little-endian word.
"""

import struct

ETHERTYPE_ECAT = 0x88A4


class Packet:
    def __init__(self, data, ts, ifid=0, options=b"", tag=None):
        self.data = bytearray(data)
        self.ts = ts            # nanoseconds since the epoch (pcapng: in the interface's resolution)
        self.ifid = ifid
        self.options = options  # pcapng EPB options, as read
        self.tag = tag

    def copy(self):
        return Packet(self.data, self.ts, self.ifid, self.options, self.tag)


class Capture:
    def __init__(self, kind, endian, header, blocks):
        self.kind = kind          # "pcap" or "pcapng"
        self.endian = endian
        self.header = header      # pcap: the 24-byte file header
        self.blocks = blocks      # pcapng: list of bytes (other blocks) or None (a packet's place)
        self.packets = []
        self.units = {}           # pcapng: interface id -> timestamp units per second

    def seconds(self, pkt):
        """A packet's time in seconds."""
        if self.kind == "pcap":
            return pkt.ts / 1e9
        return pkt.ts / self.units.get(pkt.ifid, 10**6)

    @classmethod
    def read(cls, path):
        with open(path, "rb") as fh:
            blob = fh.read()
        magic = blob[:4]
        if magic in (b"\xd4\xc3\xb2\xa1", b"\xa1\xb2\xc3\xd4", b"\x4d\x3c\xb2\xa1", b"\xa1\xb2\x3c\x4d"):
            e = "<" if magic in (b"\xd4\xc3\xb2\xa1", b"\x4d\x3c\xb2\xa1") else ">"
            nano = magic in (b"\x4d\x3c\xb2\xa1", b"\xa1\xb2\x3c\x4d")
            cap = cls("pcap", e, blob[:24], None)
            cap.nano = nano
            off = 24
            while off + 16 <= len(blob):
                sec, frac, incl, orig = struct.unpack(e + "IIII", blob[off:off + 16])
                data = blob[off + 16:off + 16 + incl]
                ts = sec * 10**9 + (frac if nano else frac * 1000)
                cap.packets.append(Packet(data, ts, tag=len(cap.packets)))
                off += 16 + incl
            return cap
        if magic != b"\x0a\x0d\x0d\x0a":
            raise ValueError("%s: not a pcap or pcapng file" % path)
        e = "<" if blob[8:12] == b"\x4d\x3c\x2b\x1a" else ">"
        cap = cls("pcapng", e, None, [])
        off = 0
        interfaces = 0
        while off + 12 <= len(blob):
            btype, blen = struct.unpack(e + "II", blob[off:off + 8])
            if blen < 12 or off + blen > len(blob):
                raise ValueError("%s: bad block at offset %d" % (path, off))
            block = blob[off:off + blen]
            if btype == 0x0A0D0D0A:
                interfaces = 0
            if btype == 1:              # interface description: if_tsresol (option 9)
                units, opt = 10**6, 16
                while opt + 4 <= blen - 4:
                    code, olen = struct.unpack(e + "HH", block[opt:opt + 4])
                    if code == 0:
                        break
                    if code == 9 and olen >= 1:
                        r = block[opt + 4]
                        units = 2 ** (r & 0x7F) if r & 0x80 else 10 ** r
                    opt += 4 + ((olen + 3) & ~3)
                cap.units[interfaces] = units
                interfaces += 1
            if btype == 6:
                body = block[8:-4]
                ifid, hi, lo, caplen, _orig = struct.unpack(e + "IIIII", body[:20])
                padded = (caplen + 3) & ~3
                cap.packets.append(Packet(body[20:20 + caplen], (hi << 32) | lo, ifid,
                                          body[20 + padded:], tag=len(cap.packets)))
                cap.blocks.append(None)
            else:
                if btype == 0x0A0D0D0A:   # section length: unknown, packets change size
                    block = block[:16] + struct.pack(e + "q", -1) + block[24:]
                cap.blocks.append(block)
            off += blen
        return cap

    def to_bytes(self):
        e = self.endian
        if self.kind == "pcap":
            out = [self.header]
            for p in self.packets:
                sec, rest = divmod(p.ts, 10**9)
                frac = rest if self.nano else rest // 1000
                out.append(struct.pack(e + "IIII", sec, frac, len(p.data), len(p.data)) + bytes(p.data))
            return b"".join(out)
        out = []
        packets = iter(self.packets)
        # Packets go, in their new order, where packets were; extra ones at the end.
        for b in self.blocks:
            if b is not None:
                out.append(b)
                continue
            p = next(packets, None)
            if p is not None:
                out.append(self._epb(p))
        for p in packets:
            out.append(self._epb(p))
        return b"".join(out)

    def _epb(self, p):
        e = self.endian
        data = bytes(p.data)
        pad = b"\0" * (((len(data) + 3) & ~3) - len(data))
        body = struct.pack(e + "IIIII", p.ifid, p.ts >> 32, p.ts & 0xFFFFFFFF, len(data), len(data)) + data + pad
        body += p.options
        blen = 12 + len(body)
        return struct.pack(e + "II", 6, blen) + body + struct.pack(e + "I", blen)

    def write(self, path):
        with open(path, "wb") as fh:
            fh.write(self.to_bytes())


def ecat_offset(pkt):
    """Offset of the EtherCAT header in an Ethernet frame (ethertype 0x88A4 after any 802.1Q
    tags, or IPv4/UDP port 34980), or None."""
    d = pkt.data
    off = 12
    while len(d) >= off + 2:
        etype = struct.unpack("!H", d[off:off + 2])[0]
        if etype in (0x8100, 0x88A8):
            off += 4
            continue
        if etype == ETHERTYPE_ECAT:
            return off + 2
        ip = off + 2
        if etype != 0x0800 or len(d) < ip + 20 or d[ip + 9] != 17:
            return None
        udp = ip + (d[ip] & 0x0F) * 4
        if len(d) < udp + 8 or 34980 not in struct.unpack("!HH", d[udp:udp + 4]):
            return None
        return udp + 8
    return None


def ecat_datagrams(pkt):
    """The datagrams of an EtherCAT frame: dicts with offset (of the datagram in pkt.data),
    cmd, idx, adp, ado, length, data_offset, wkc, wkc_offset. [] when not EtherCAT type 1."""
    base = ecat_offset(pkt)
    d = pkt.data
    if base is None or len(d) < base + 2:
        return []
    header = struct.unpack("<H", d[base:base + 2])[0]
    if header >> 12 != 1:
        return []
    end = min(len(d), base + 2 + (header & 0x7FF))
    out = []
    off = base + 2
    while off + 12 <= end:
        cmd, idx, adp, ado, flags, _irq = struct.unpack("<BBHHHH", d[off:off + 10])
        length = flags & 0x7FF
        if off + 12 + length > end:
            break
        wkc_off = off + 10 + length
        out.append({"offset": off, "cmd": cmd, "idx": idx, "adp": adp, "ado": ado, "length": length,
                    "data_offset": off + 10, "wkc": struct.unpack("<H", d[wkc_off:wkc_off + 2])[0],
                    "wkc_offset": wkc_off, "more": bool(flags & 0x8000)})
        off += 12 + length
        if not flags & 0x8000:
            break
    return out


def set_u16(pkt, offset, value):
    pkt.data[offset:offset + 2] = struct.pack("<H", value & 0xFFFF)


def get_u16(pkt, offset):
    return struct.unpack("<H", pkt.data[offset:offset + 2])[0]

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Random PROFINET frames on ethertype 0x8892 (Python 3 stdlib only), for the tests of
rules/profinet.xml: every DCP service with every option/suboption block, cyclic RT frames
of the three RT classes with random trailers, alarms (high/low, every RTA PDU type) and
PTCP time synchronisation (every PDU kind with every TLV block).

    frames = pngen.all_frames(random.Random(1), cyclic=200)   # [bytes]
    pngen.pcap(frames)                                          # a pcap file's bytes
"""
import random
import struct

ETHERTYPE = 0x8892
GET, SET, IDENTIFY, HELLO = 3, 4, 5, 6
REQUEST, SUCCESS, UNSUPPORTED = 0, 1, 5


def ethernet(frame_id, body, rng):
    dst = bytes([0x01, 0x0E, 0xCF, 0x00, 0x00, 0x00]) if rng.random() < 0.3 else rand_bytes(rng, 6)
    frame = dst + bytes([0x00, 0x0E, 0xCF]) + rand_bytes(rng, 3) + struct.pack(">HH", ETHERTYPE, frame_id) + body
    return frame + bytes(max(0, 60 - len(frame)))


def rand_bytes(rng, n):
    return bytes(rng.randrange(256) for _ in range(n))


def rand_text(rng, n, alphabet="abcdefghijklmnopqrstuvwxyz0123456789-."):
    return "".join(rng.choice(alphabet) for _ in range(n)).encode("ascii")


# --- DCP -------------------------------------------------------------------

def has_info(service, stype):
    response = stype != REQUEST
    return (service in (IDENTIFY, GET) and response) or (service == HELLO and not response)


def block(option, suboption, value, service, stype):
    """One block: option, suboption, length, BlockInfo/BlockQualifier where the service
    has them (IP, device, DHCP and device-initiative blocks), the value, a pad byte."""
    prefix = b""
    if option in (1, 2, 3, 6):
        if has_info(service, stype):
            prefix = struct.pack(">H", 0)
        elif service == SET and stype == REQUEST:
            prefix = struct.pack(">H", 1)
    body = prefix + value
    out = struct.pack(">BBH", option, suboption, len(body)) + body
    return out + (b"\x00" if len(body) % 2 else b"")


def device_blocks(rng):
    """(option, suboption, value) of every IP, device, DHCP and device-initiative block."""
    client = rand_text(rng, rng.randrange(2, 12))
    return [
        (1, 1, rand_bytes(rng, 6)),
        (1, 2, rand_bytes(rng, 12)),
        (1, 3, rand_bytes(rng, 28)),
        (2, 1, rand_text(rng, rng.randrange(1, 25), "ABCDEFGHIJKLMNOPQRSTUVWXYZ abcdef0123")),
        (2, 2, rand_text(rng, rng.randrange(1, 40))),
        (2, 3, rand_bytes(rng, 4)),
        (2, 4, bytes([rng.randrange(16), 0])),
        (2, 5, b"".join(bytes(p) for p in rng.sample([(1, 1), (1, 2), (2, 1), (2, 2), (2, 3), (2, 4),
                                                       (2, 5), (5, 1), (5, 2), (5, 3), (5, 4), (6, 1)],
                                                      rng.randrange(1, 8)))),
        (2, 6, rand_text(rng, rng.randrange(8, 30))),
        (2, 7, rand_bytes(rng, 2)),
        (2, 8, rand_bytes(rng, 4)),
        (2, 10, rand_bytes(rng, 2)),
        (3, 61, bytes([61, 1, rng.choice([1, 2])])),
        (3, 61, bytes([61, 1 + len(client), 0]) + client),
        (3, 255, bytes([255, 1, rng.randrange(3)])),
        (6, 1, struct.pack(">H", rng.randrange(2))),
    ]


def dcp(service, stype, blocks, xid, delay=None):
    data = b"".join(blocks)
    second = delay if delay is not None else 0
    return struct.pack(">BBIHH", service, stype, xid, second, len(data)) + data


def dcp_frames(rng):
    """(frame ID, DCP PDU) of every service, with random values."""
    out = []
    xid = rng.randrange(1 << 32)
    every = device_blocks(rng)
    for service, stype, frame_id in ((IDENTIFY, SUCCESS, 0xFEFF), (GET, SUCCESS, 0xFEFD), (HELLO, REQUEST, 0xFEFC)):
        blocks = [block(o, s, v, service, stype) for o, s, v in every]
        rng.shuffle(blocks)
        out.append((frame_id, dcp(service, stype, blocks[:rng.randrange(3, len(blocks) + 1)], xid)))
    # Identify request: filters (no info, no qualifier), or the All selector.
    filters = [block(2, 2, rand_text(rng, rng.randrange(1, 30)), IDENTIFY, REQUEST),
               block(2, 6, rand_text(rng, 12), IDENTIFY, REQUEST),
               block(2, 3, rand_bytes(rng, 4), IDENTIFY, REQUEST),
               block(2, 4, bytes([rng.randrange(16), 0]), IDENTIFY, REQUEST)]
    out.append((0xFEFE, dcp(IDENTIFY, REQUEST, rng.sample(filters, rng.randrange(1, 5)), xid,
                            rng.randrange(1 << 16))))
    out.append((0xFEFE, dcp(IDENTIFY, REQUEST, [block(0xFF, 0xFF, b"", IDENTIFY, REQUEST)], xid,
                            rng.randrange(1 << 16))))
    # Get request: option/suboption pairs.
    selectors = b"".join(bytes(p) for p in rng.sample([(1, 1), (1, 2), (2, 1), (2, 2), (2, 3), (2, 4), (2, 5),
                                                      (2, 6), (2, 7), (2, 8), (3, 61), (6, 1), (0xFF, 0xFF)],
                                                     rng.randrange(1, 10)))
    out.append((0xFEFD, struct.pack(">BBIHH", GET, REQUEST, xid, 0, len(selectors)) + selectors))
    # Set request: start transaction, values with a qualifier, signal, resets, end transaction.
    q = lambda: struct.pack(">H", rng.randrange(2))  # noqa: E731
    sets = [block(5, 1, q(), SET, REQUEST)]
    sets += [block(o, s, v, SET, REQUEST) for o, s, v in every if (o, s) in ((1, 2), (2, 2), (2, 6), (3, 61), (6, 1))]
    sets += [block(5, 3, q() + b"\x01\x00", SET, REQUEST), block(5, 5, q(), SET, REQUEST),
             block(5, 6, struct.pack(">H", rng.randrange(2, 0x17)), SET, REQUEST), block(5, 2, q(), SET, REQUEST)]
    out.append((0xFEFD, dcp(SET, REQUEST, sets, xid)))
    # Set response: one Control/Response per block set.
    answers = [block(5, 4, bytes([o, s, rng.randrange(7)]), SET, SUCCESS)
               for o, s in ((5, 1), (1, 2), (2, 2), (3, 61), (5, 2))]
    out.append((0xFEFD, dcp(SET, SUCCESS, answers, xid)))
    # Manufacturer-specific block in a Get response, and a Get response "not supported".
    out.append((0xFEFD, dcp(GET, SUCCESS, [block(rng.randrange(0x80, 0xFF), rng.randrange(256),
                                                 rand_bytes(rng, rng.randrange(1, 20)), GET, SUCCESS)], xid)))
    out.append((0xFEFD, dcp(GET, UNSUPPORTED, [block(5, 4, bytes([2, 2, 2]), GET, UNSUPPORTED)], xid)))
    return out


# --- RT cyclic and alarms ---------------------------------------------------

CLASS_RANGES = ((0x0100, 0x0FFF), (0x8000, 0xBFFF), (0xC000, 0xFBFF))


def cyclic_frame(rng):
    low, high = rng.choice(CLASS_RANGES)
    data = rand_bytes(rng, rng.randrange(40, 200))
    trailer = struct.pack(">HBB", rng.randrange(1 << 16), rng.randrange(256), rng.randrange(256))
    return rng.randrange(low, high + 1), data + trailer


def alarm_frame(rng):
    pdu_type = rng.randrange(1, 5)
    if pdu_type == 1:
        user = rand_bytes(rng, rng.randrange(0, 30))
        body = struct.pack(">HIHHIIH", rng.randrange(1 << 16), rng.randrange(1 << 32), rng.randrange(1 << 16),
                           rng.randrange(1 << 16), rng.randrange(1 << 32), rng.randrange(1 << 32),
                           rng.randrange(1 << 16)) + user
        var = struct.pack(">HHBB", rng.choice([1, 2]), len(body) + 2, 1, 0) + body
    elif pdu_type == 4:
        var = rand_bytes(rng, 4)
    else:
        var = b""
    header = struct.pack(">HHBBHHH", rng.randrange(1 << 16), rng.randrange(1 << 16), 0x10 | pdu_type,
                         rng.randrange(2) << 4 | 1, rng.randrange(1 << 16), rng.randrange(1 << 16), len(var))
    return rng.choice([0xFC01, 0xFE01]), header + var


# --- PTCP (IEC 61158-6-10 time synchronisation) ----------------------------

PTCP_RTSYNC = (0x0020, 0x0021, 0x0080, 0x0081)  # with follow-up, then without (Clock, Time)
PTCP_ANNOUNCE = (0xFF00, 0xFF01)
PTCP_FOLLOW_UP = (0xFF20, 0xFF21)
PTCP_DELAY = (0xFF40, 0xFF41, 0xFF42, 0xFF43)  # DelayReq, DelayRes, DelayFuRes, DelayRes
PTCP_IDS = PTCP_RTSYNC + PTCP_ANNOUNCE + PTCP_FOLLOW_UP + PTCP_DELAY
PROFINET_OUIS = (0x000ECF, 0x010ECF)


def tlv(block_type, body):
    """A TLV block: 7 bits of type, 9 bits of length, the body."""
    return struct.pack(">H", block_type << 9 | len(body)) + body


def ptcp_blocks(rng):
    """Every TLV block but End, with random values; each a multiple of 4 bytes long, as the
    specification lays them out (so the paddings inside sit where it puts them). No block of
    a reserved type (0x08-0x7E): pn_ptcp skips its length twice and decodes what follows
    from the wrong place, so there would be nothing right to compare with."""
    u32 = lambda: rng.randrange(1 << 32)  # noqa: E731
    organization = rng.choice(PROFINET_OUIS)
    return [
        tlv(1, rand_bytes(rng, 6) + rand_bytes(rng, 16)),                                  # Subdomain
        tlv(2, struct.pack(">HII", rng.randrange(1 << 16), u32(), rng.randrange(10**9))),  # Time
        tlv(3, struct.pack(">HHH", rng.randrange(1 << 16), rng.randrange(1 << 16), 0)),     # TimeExtension
        tlv(4, struct.pack(">BBBBh", rng.randrange(256), rng.choice([0xFF, rng.randrange(256)]),
                           rng.choice([0xFF, rng.randrange(256)]),
                           rng.choice([0x20, 0x21, 0x22, 0x25, 0x29, 0xFE, rng.randrange(256)]),
                           rng.randrange(-32768, 32768))),                                 # Master
        tlv(5, struct.pack(">HII", 0, u32(), u32())),                                      # PortParameter
        tlv(6, rand_bytes(rng, 6)),                                                        # DelayParameter
        tlv(7, struct.pack(">HI", 0, u32())),                                              # PortTime
        tlv(0x7F, struct.pack(">I", organization)[1:] + b"\x01\x00\x00" + rand_bytes(rng, 16)),  # PROFINET RTData
        tlv(0x7F, struct.pack(">I", rng.randrange(1 << 24))[1:] + rand_bytes(rng, 3)),     # other organization
    ]


def ptcp_frame(rng):
    """(frame ID, PTCP PDU): a header of the frame ID's kind, TLV blocks, End."""
    frame_id = rng.choice(PTCP_IDS)
    sequence = rng.randrange(1 << 16)
    if frame_id in PTCP_RTSYNC:
        header = struct.pack(">IIIHBBI", rng.randrange(1 << 32), rng.randrange(1 << 32), rng.randrange(1 << 32),
                             sequence, rng.randrange(256), 0, rng.randrange(1 << 32))
    elif frame_id in PTCP_ANNOUNCE:
        header = bytes(12) + struct.pack(">H", sequence) + bytes(6)
    elif frame_id in PTCP_FOLLOW_UP:
        header = bytes(12) + struct.pack(">HHi", sequence, 0, rng.randrange(-(1 << 31), 1 << 31))
    else:
        header = bytes(12) + struct.pack(">HHI", sequence, 0, rng.randrange(1 << 32))
    blocks = ptcp_blocks(rng)
    rng.shuffle(blocks)
    return frame_id, header + b"".join(blocks[:rng.randrange(1, len(blocks) + 1)]) + tlv(0, b"")


def all_frames(rng, rounds=20, cyclic=200, alarms=60, ptcp=60):
    """DCP, cyclic and alarm frames, then `ptcp` PTCP frames from a generator of their own
    (seeded from `rng`'s draws after the others), all shuffled: the frames before PTCP
    are the same with and without it."""
    frames = []
    for _ in range(rounds):
        frames += [ethernet(fid, body, rng) for fid, body in dcp_frames(rng)]
    frames += [ethernet(*cyclic_frame(rng), rng) for _ in range(cyclic)]
    frames += [ethernet(*alarm_frame(rng), rng) for _ in range(alarms)]
    if ptcp:
        own = random.Random(rng.randrange(1 << 32))
        frames += [ethernet(*ptcp_frame(own), own) for _ in range(ptcp)]
    rng.shuffle(frames)
    return frames


def pcap(frames, base_ts=1704067200, captured=None):
    """A pcap of `frames`; `captured` maps a frame's index to the bytes the capture kept
    of it (cut by a snapshot length: its length on the wire stays the whole frame's)."""
    captured = captured or {}
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i, f in enumerate(frames):
        kept = f[:captured.get(i, len(f))]
        out.append(struct.pack("<IIII", base_ts + i // 1000, (i % 1000) * 1000, len(kept), len(f)) + kept)
    return b"".join(out)


def cyclic_devices(seed=8892):
    """(time ns, frame) of three devices sending cyclic data at 1, 2 and 4 ms (each frame
    ID of another RT class, jitter up to 5 % of the period, the cycle counter advancing
    by 32, 64 and 128 and wrapping past 0xFFFF), and a DCP Hello every 3 ms exactly
    (regular, but no cyclic data). Faults: the first device's frames 30 and 31 are lost
    and its frame 45 is sent twice; the second's frame 1 is lost (its first advance is
    two steps) and so are 20 to 22."""
    rng = random.Random(seed)
    packets = []
    devices = [(0xC001, 1_000_000, 60, 32, 0xF000, {30, 31}, {45}),
               (0x8002, 2_000_000, 40, 64, 100, {1, 20, 21, 22}, set()),
               (0x0103, 4_000_000, 25, 128, 0xFE00, set(), set())]
    for n, (frame_id, period, count, step, first, lost, repeated) in enumerate(devices):
        mac = bytes([0x00, 0x0E, 0xCF, 0, 0, n + 1])
        for i in range(count):
            t = 10**9 + n * 137_000 + i * period + rng.randint(-period // 20, period // 20)
            if i in lost:
                continue
            body = bytes(40) + struct.pack(">HBB", (first + i * step) & 0xFFFF, 0x35, 0)
            frame = bytes([0x01, 0x0E, 0xCF, 0, 0, 0]) + mac + struct.pack(">HH", 0x8892, frame_id) + body
            packets.append((t, frame))
            if i in repeated:
                packets.append((t + 30_000, frame))
    hello_mac = bytes([0x00, 0x0E, 0xCF, 0, 0, 9])
    for i in range(30):
        body = dcp(HELLO, REQUEST, [], 0x1000 + i)
        packets.append((10**9 + i * 3_000_000, bytes([0x01, 0x0E, 0xCF, 0, 0, 1]) + hello_mac +
                        struct.pack(">HH", 0x8892, 0xFEFC) + body))
    packets.sort(key=lambda p: p[0])
    return [(t, f + bytes(max(0, 60 - len(f)))) for t, f in packets]

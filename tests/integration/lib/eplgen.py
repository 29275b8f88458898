#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Random Ethernet POWERLINK frames on ethertype 0x88AB (Python 3 stdlib only), for the tests
of rules/powerlink.xml: every message type (SoC, PReq, PRes, SoA, ASnd, AInv, AMNI) with every flag set
at random, ASnd with IdentResponse, StatusResponse, NMTRequest, NMTCommand and SDO (sequence
and command layer), and a regular cycle with known jitter and a dropped PRes.

    frames = eplgen.all_frames(random.Random(1))        # [bytes]
    eplgen.pcap(frames)                                  # a pcap file's bytes
    packets, truth = eplgen.cycle(random.Random(1))      # [(t_ns, bytes)], what was made

Everything is little-endian (EPSG DS 301: POWERLINK frames are).
"""
import struct

ETHERTYPE = 0x88AB
SOC, PREQ, PRES, SOA, ASND, AMNI, AINV = 0x01, 0x03, 0x04, 0x05, 0x06, 0x07, 0x0D
IDENT_RESPONSE, STATUS_RESPONSE, NMT_REQUEST, NMT_COMMAND, SDO = 1, 2, 3, 4, 5
MN = 240
BROADCAST = 255
# The multicast addresses of DS 301 (Appendix 3.1): SoC, PRes, SoA, ASnd.
MULTICAST = {SOC: 1, PRES: 2, SOA: 3, ASND: 4}
NMT_STATES = [0x00, 0x19, 0x29, 0x39, 0x1C, 0x1D, 0x5D, 0x6D, 0xFD, 0x4D, 0x1E]
NMT_COMMANDS = [0x21, 0x22, 0x23, 0x24, 0x28, 0x29, 0x2A, 0x2B, 0x41, 0x42, 0x43, 0x44, 0x48, 0x49,
                0x4A, 0x4B, 0x80, 0x90, 0x91, 0x92, 0x93, 0x94, 0x95, 0xA0, 0xFF]
SDO_COMMANDS = [0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x20, 0x21, 0x31, 0x32, 0x70, 0x71]


def rand_bytes(rng, n):
    return bytes(rng.randrange(256) for _ in range(n))


def ethernet(mtype, source, body):
    """The Ethernet frame of one POWERLINK message from node `source`: multicast as DS 301
    sends SoC, PRes, SoA and ASnd, unicast to a made-up MAC for PReq."""
    if mtype in MULTICAST:
        dst = bytes([0x01, 0x11, 0x1E, 0x00, 0x00, MULTICAST[mtype]])
    else:
        dst = bytes([0x00, 0x60, 0x65, 0x00, 0x00, body[0]])
    frame = dst + bytes([0x00, 0x60, 0x65, 0x00, 0x00, source]) + struct.pack(">H", ETHERTYPE) + body
    return frame + bytes(max(0, 60 - len(frame)))


def header(mtype, dest, source, reserved_bit=0):
    return bytes([reserved_bit << 7 | mtype, dest, source])


def soc(rng, net_time=None, relative=None):
    flags = rng.randrange(256)  # MC, PS and the reserved bits, all at random
    seconds, ns = net_time if net_time else (rng.randrange(1 << 31), rng.randrange(10**9))
    rel = relative if relative is not None else rng.randrange(1 << 64)
    return header(SOC, BROADCAST, MN, rng.randrange(2)) + bytes([0, flags, 0]) + \
        struct.pack("<IIQ", seconds, ns, rel)


def pdo_payload(rng):
    return rand_bytes(rng, rng.randrange(0, 40))


def preq(rng, node):
    payload = pdo_payload(rng)
    return header(PREQ, node, MN, rng.randrange(2)) + bytes([0, rng.randrange(256), 0, rng.randrange(256), 0]) + \
        struct.pack("<H", len(payload)) + payload


def pres(rng, node):
    payload = pdo_payload(rng)
    return header(PRES, BROADCAST, node, rng.randrange(2)) + \
        bytes([rng.choice(NMT_STATES), rng.randrange(256), rng.randrange(256), rng.randrange(256), 0]) + \
        struct.pack("<H", len(payload)) + payload


def soa(rng):
    service = rng.choice([0, 1, 2, 3, 0xFF])
    return header(SOA, BROADCAST, MN, rng.randrange(2)) + \
        bytes([rng.choice(NMT_STATES), rng.randrange(256), 0, service, rng.randrange(1, 240),
               rng.choice([0x10, 0x20, 0x21]), rng.randrange(16)]) + bytes(35)


def ainv(rng):
    """DS 302-A's AInv, as Wireshark's epl lays it out: NMTStatus, a reserved byte, the
    flags (EA, ER), the ASnd service invited. (epl goes on to read the bytes after a
    service ID of 1 to 6 as that service's ASnd payload, which eplr keeps raw: those
    services are left out here, and test_powerlink.py says so.)"""
    return header(AINV, BROADCAST, MN, rng.randrange(2)) + \
        bytes([rng.choice(NMT_STATES), 0, rng.randrange(256), rng.choice([0, rng.randrange(0xA0, 0xFF)])]) + \
        bytes(36)


def amni(rng):
    """DS 302-A's AMNI: the header only, here with a reserved payload of zeros."""
    return header(AMNI, BROADCAST, MN, rng.randrange(2)) + bytes(40)


def ident_response(rng):
    hostname = bytes(rng.choice(b"abcdefgh-0123456789") for _ in range(rng.randrange(1, 32)))
    return bytes([rng.randrange(256), rng.randrange(256), rng.choice(NMT_STATES), 0, 0x20, 0]) + \
        struct.pack("<IHHHIH", rng.randrange(1 << 32), rng.randrange(300, 1500), rng.randrange(1500),
                    rng.randrange(1500), rng.randrange(1 << 32), 0) + \
        struct.pack("<HHIIIIQIIII", rng.randrange(1 << 16), rng.randrange(1 << 16), *(rng.randrange(1 << 32)
                    for _ in range(4)), rng.randrange(1 << 64), *(rng.randrange(1 << 32) for _ in range(4))) + \
        rand_bytes(rng, 12) + hostname.ljust(32, b"\0") + rand_bytes(rng, 48)


def status_response(rng):
    """The ErrorCodeList ends with an entry of type 0, as DS 301 terminates it."""
    entries = b"".join(struct.pack("<HHIIQ", rng.randrange(1, 1 << 16), rng.randrange(1 << 16),
                                   rng.randrange(1 << 31), rng.randrange(10**9), rng.randrange(1 << 64))
                       for _ in range(rng.randrange(0, 4))) + bytes(20)
    return bytes([rng.randrange(256), rng.randrange(256), rng.choice(NMT_STATES), 0, 0, 0]) + \
        rand_bytes(rng, 8) + entries


def nmt_request(rng):
    return bytes([rng.choice(NMT_COMMANDS), rng.randrange(1, 240)]) + rand_bytes(rng, rng.randrange(0, 20))


def nmt_command(rng):
    return bytes([rng.choice(NMT_COMMANDS), 0]) + rand_bytes(rng, rng.randrange(0, 20))


def sdo(rng):
    """Sequence layer, then the command layer header (DataSize on an initiate segment), then
    the data as bytes."""
    segmentation = rng.randrange(4)
    data = rand_bytes(rng, rng.randrange(0, 30))
    sequence = bytes([rng.randrange(256), rng.randrange(256), 0, 0])
    flags = rng.randrange(2) << 7 | rng.randrange(2) << 6 | segmentation << 4
    command = bytes([0, rng.randrange(256), flags, rng.choice(SDO_COMMANDS)]) + struct.pack("<HH", len(data), 0)
    if segmentation == 1:
        command += struct.pack("<I", rng.randrange(1 << 32))
    return sequence + command + data


ASND_SERVICES = {IDENT_RESPONSE: ident_response, STATUS_RESPONSE: status_response, NMT_REQUEST: nmt_request,
                 NMT_COMMAND: nmt_command, SDO: sdo}


def asnd(rng, service, source):
    dest = rng.choice([MN, BROADCAST, rng.randrange(1, 240)])
    return header(ASND, dest, source, rng.randrange(2)) + bytes([service]) + ASND_SERVICES[service](rng)


def all_frames(rng, rounds=40):
    """Every message type and ASnd service, `rounds` times each, shuffled."""
    frames = []
    for _ in range(rounds):
        node = rng.randrange(1, 240)
        frames += [ethernet(SOC, MN, soc(rng)), ethernet(PREQ, MN, preq(rng, node)),
                   ethernet(PRES, node, pres(rng, node)), ethernet(SOA, MN, soa(rng))]
        frames += [ethernet(ASND, node, asnd(rng, service, node)) for service in ASND_SERVICES]
        frames += [ethernet(AINV, MN, ainv(rng)), ethernet(AMNI, MN, amni(rng))]
    rng.shuffle(frames)
    return frames


def pcap(frames, base_ts=1704067200):
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for i, f in enumerate(frames):
        out.append(struct.pack("<IIII", base_ts + i // 1000, (i % 1000) * 1000, len(f), len(f)) + f)
    return b"".join(out)


def cycle(rng, cycles=40, period_ns=400_000, nodes=(1, 2, 3), jitter_ns=2_000, dropped=(2, 17), missing=()):
    """A regular POWERLINK cycle: an SoC every period_ns (each moved by a known jitter of up to
    jitter_ns either way), then a PReq and a PRes per node 20 µs apart, then an SoA. The PRes of
    `dropped` = (node, cycle) is missing, and those of every (node, cycle) in `missing`.
    Returns [(t_ns, frame)] in time order and a dict: 'soc' [t_ns], 'pres' {node: [t_ns]}."""
    packets = []
    truth = {"soc": [], "pres": {n: [] for n in nodes}}
    start = 10**9
    for c in range(cycles):
        t = start + c * period_ns + rng.randint(-jitter_ns, jitter_ns)
        truth["soc"].append(t)
        packets.append((t, ethernet(SOC, MN, soc(rng, (t // 10**9, t % 10**9), c * period_ns))))
        for k, node in enumerate(nodes):
            t_req = t + 10_000 + k * 40_000
            packets.append((t_req, ethernet(PREQ, MN, preq(rng, node))))
            if (node, c) == tuple(dropped) or (node, c) in missing:
                continue
            t_res = t_req + 20_000
            truth["pres"][node].append(t_res)
            packets.append((t_res, ethernet(PRES, node, pres(rng, node))))
        packets.append((t + 10_000 + len(nodes) * 40_000, ethernet(SOA, MN, soa(rng))))
    return packets, truth


def sdo_write(dest, index, subindex, data, transaction):
    """An MN's expedited SDO Write by Index request (over ASnd) to node `dest`."""
    sequence = bytes([(transaction & 63) << 2 | 2, (transaction & 63) << 2 | 2, 0, 0])  # connection valid
    payload = struct.pack("<HBB", index, subindex, 0) + data
    command = bytes([0, transaction & 0xFF, 0, 0x01]) + struct.pack("<HH", len(payload), 0)
    return ethernet(ASND, MN, header(ASND, dest, MN) + bytes([SDO]) + sequence + command + payload)


def mapping_entry(index, subindex, offset_bits, length_bits):
    """An object mapping entry (DS 301: index, subindex, reserved, offset and length in bits)."""
    return struct.pack("<HBBHH", index, subindex, 0, offset_bits, length_bits)


def pdo_frame(kind, node, payload):
    """A PReq to `node` or a PRes from it carrying `payload`."""
    if kind == PREQ:
        return ethernet(PREQ, MN, header(PREQ, node, MN) + bytes(5) + struct.pack("<H", len(payload)) + payload)
    return ethernet(PRES, node, header(PRES, BROADCAST, node) + bytes([0xFD, 0, 0, 0, 0]) +
                    struct.pack("<H", len(payload)) + payload)


def random_layout(rng, bit_granular):
    """[(index, subindex, offset bits, length bits)], the entries packed one after another:
    8, 16 or 32 bits each (byte-aligned), or 1 to 32 bits anywhere (bit_granular)."""
    entries, at = [], 0
    for _ in range(rng.randrange(1, 6)):
        length = rng.randrange(1, 33) if bit_granular else rng.choice([8, 16, 32])
        entries.append((rng.randrange(0x2000, 0x7000), rng.randrange(256), at, length))
        at += length
    return entries


def mapped_traffic(rng, bit_granular=False, nodes=(1, 2, 3, 4), unmapped=(7, 9), rounds=25):
    """SDO writes that map each node's receive (0x1600) and transmit (0x1A00) PDO as DS 301
    says (subindex 0 to 0, the entries, subindex 0 to their count), then PReq/PRes rounds whose
    payloads follow those layouts; node 2's transmit PDO is mapped anew halfway. Nodes in
    `unmapped` send and get payloads whose mapping is never written.
    Returns (frames, truth): truth[frame number] for each PReq and PRes is
    {"entries": [(index, subindex, value)] or None (not mapped), "note": whether it is the
    node's first of its kind without a mapping (and carries data)}."""
    frames, truth, layouts, noted = [], {}, {}, set()
    transaction = [0]

    def write_mapping(node, obj, layout):
        for sub, data in [(0, bytes([0]))] + [(k + 1, mapping_entry(*e)) for k, e in enumerate(layout)] + \
                [(0, bytes([len(layout)]))]:
            transaction[0] += 1
            frames.append(sdo_write(node, obj, sub, data, transaction[0]))
        layouts[(node, obj)] = layout

    def send(kind, node):
        layout = layouts.get((node, 0x1600 if kind == PREQ else 0x1A00))
        if layout is None:
            payload = rand_bytes(rng, rng.randrange(9, 17))  # (epl guesses a number in up to 8 bytes)
            note = (kind, node) not in noted
            noted.add((kind, node))
            frames.append(pdo_frame(kind, node, payload))
            truth[len(frames)] = {"entries": None, "note": note}
            return
        bits = max(offset + length for _, _, offset, length in layout)
        payload = rand_bytes(rng, (bits + 7) // 8)
        number = int.from_bytes(payload, "little")
        entries = [(index, sub, number >> offset & ((1 << length) - 1)) for index, sub, offset, length in layout]
        frames.append(pdo_frame(kind, node, payload))
        truth[len(frames)] = {"entries": entries, "note": False}

    for node in nodes:
        for obj in (0x1600, 0x1A00):
            write_mapping(node, obj, random_layout(rng, bit_granular))
    for r in range(rounds):
        if r == rounds // 2:
            write_mapping(2, 0x1A00, random_layout(rng, bit_granular))
        for node in nodes + unmapped:
            send(PREQ, node)
            send(PRES, node)
    return frames, truth

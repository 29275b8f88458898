#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""EtherNet/IP from rules alone: rules/enip.xml decodes real traffic (real tshark, real plugins).

- the ENIPR plugin and the shipped EtherCAT plugin load together, beside Wireshark's own
  enip/cip dissectors, which stay selectable with Decode As;
- the message of the Linux EtherNet/IP paper (seeds/002: SendRRData carrying a CIP
  Forward Open) decodes field by field, and Wireshark's enip/cip agree on it;
- TCP 44818: a message split over three segments is reassembled and decoded once; three
  messages in one segment are each decoded once; messages straddling segments too; a
  corrupted header (unknown command, a huge length) is not EtherNet/IP and starts no
  reassembly: the messages after it decode;
- UDP 44818 (ListIdentity request and reply with the CIP Identity item) and UDP 2222
  (class-1 I/O: a bare Common Packet Format, chosen with `ifhook`);
- differential against Wireshark's own enip/cip dissectors on the real captures of
  <source-dir>/../shared/corpus/enip (read in place): every encapsulation header field,
  item count, CPF type id and length, connection ids and sequence numbers, socket addresses
  and ListIdentity product names, CIP service, request/response bit, request path size and
  class; a Multiple Service Packet's count, offsets, where each embedded service lies, its
  service code and class; Unconnected Send (cipcm: priority/tick, time-out ticks, message
  size, the embedded request's header, route path size, ports and link addresses), Forward Open and Forward Close requests and
  successful replies (every cipcm field of theirs), message by message, frame by frame;
- Unconnected Send with odd (padded) and even messages and an extended link address,
  0x52 to a tag (not Unconnected Send), Multiple Service Packet requests and replies (an
  error reply without services), Forward Close: against the bytes and against Wireshark.

When the corpus is absent, everything else still runs; the script then prints SKIPPED and
exits 77 if all else passed.
"""
import os
import re
import struct
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import SANITIZE, TsharkEnv, TsharkTestCase, run_unittests  # noqa: E402

ARGS = None
ENV = None       # our plugins installed (ENIPR + EtherCAT)
BARE = None      # no plugin at all: Wireshark's own (built-in) enip and cip
SKIP_CODE = 77

# The paper's SendRRData (seeds/002): 86 bytes, Length 62, session 0x20020000, timeout
# 1024, a Null Address item and a 46-byte Unconnected Data item holding a CIP Forward
# Open (0x54) to class 6 instance 1.
SEED = bytes.fromhex(
    "6F003E000000022000000000000000000000000000000000000000000004020000000000B2002E00"
    "5402200624010AF00000000000000180ABCD0100987654320700000040821F00FB4240821F00FB42"
    "A30220022401")


# --- building captures (Python stdlib only) ---------------------------------------

def checksum(data):
    if len(data) % 2:
        data += b"\0"
    s = sum(struct.unpack("!%dH" % (len(data) // 2), data))
    s = (s >> 16) + (s & 0xFFFF)
    s += s >> 16
    return ~s & 0xFFFF


def ethernet(payload, ethertype=0x0800, dst=b"\x02\0\0\0\0\x02", src=b"\x02\0\0\0\0\x01"):
    frame = dst + src + struct.pack("!H", ethertype) + payload
    return frame + bytes(max(0, 60 - len(frame)))


def ipv4(proto, payload, src, dst):
    header = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(payload), 1, 0x4000, 64, proto, 0,
                         bytes(src), bytes(dst))
    header = header[:10] + struct.pack("!H", checksum(header)) + header[12:]
    return header + payload


def udp(sport, dport, payload, src=(10, 1, 1, 167), dst=(10, 1, 1, 164)):
    segment = struct.pack("!HHHH", sport, dport, 8 + len(payload), 0) + payload
    pseudo = struct.pack("!4s4sBBH", bytes(src), bytes(dst), 0, 17, len(segment))
    c = checksum(pseudo + segment) or 0xFFFF
    segment = segment[:6] + struct.pack("!H", c) + segment[8:]
    return ethernet(ipv4(17, segment, src, dst))


class TcpFlow:
    """One direction of a TCP connection: consecutive sequence numbers, no handshake."""

    def __init__(self, sport, dport, src=(10, 1, 1, 167), dst=(10, 1, 1, 164), seq=1000):
        self.sport, self.dport, self.src, self.dst, self.seq = sport, dport, src, dst, seq

    def segment(self, payload):
        header = struct.pack("!HHIIBBHHH", self.sport, self.dport, self.seq, 1, 5 << 4, 0x18, 65535, 0, 0)
        pseudo = struct.pack("!4s4sBBH", bytes(self.src), bytes(self.dst), 0, 6, len(header) + len(payload))
        header = header[:16] + struct.pack("!H", checksum(pseudo + header + payload)) + header[18:]
        self.seq += len(payload)
        return ethernet(ipv4(6, header + payload, self.src, self.dst))


def pcap(frames):
    out = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)
    for i, f in enumerate(frames):
        out += struct.pack("<IIII", 1_600_000_000 + i, 0, len(f), len(f)) + f
    return out


# --- EtherNet/IP messages ----------------------------------------------------------

# The encapsulation commands Wireshark 4.0's enip knows (rules/enip.xml: valid="...").
ENIP_COMMANDS = {0x0000, 0x0004, 0x0063, 0x0064, 0x0065, 0x0066, 0x006F, 0x0070, 0x00C8}


def encap(command, data=b"", session=0, status=0, context=bytes(8), options=0):
    return struct.pack("<HHII8sI", command, len(data), session, status, context, options) + data


def cpf(*items):
    return struct.pack("<H", len(items)) + b"".join(struct.pack("<HH", t, len(d)) + d for t, d in items)


def send_data(command, items, session, timeout=0, context=bytes(8)):
    return encap(command, struct.pack("<IH", 0, timeout) + cpf(*items), session=session, context=context)


def cip_request(service, path, data=b""):
    return bytes([service, len(path) // 2]) + path + data


def cip_response(service, status=0, addstat=b"", data=b""):
    return bytes([service | 0x80, 0, status, len(addstat) // 2]) + addstat + data


REGISTER = encap(0x65, struct.pack("<HH", 1, 0))
GET_ATTR = send_data(0x70, [(0x00A1, struct.pack("<I", 0x80FE0028)),
                            (0x00B1, struct.pack("<H", 1929) + cip_response(0x0E, data=b"\x2a\x00"))],
                     session=0x11020100)
GET_ATTR_ERROR = send_data(0x70, [(0x00A1, struct.pack("<I", 0x80FE0028)),
                                  (0x00B1, struct.pack("<H", 1930) + cip_response(0x0E, 0x1F, b"\x34\x12"))],
                           session=0x11020100)
IDENTITY_ITEM = (struct.pack("<H", 1) + struct.pack("!HH4s8s", 2, 44818, bytes([10, 1, 1, 164]), bytes(8)) +
                 struct.pack("<HHHBBHIB", 1, 0x0C, 58, 4, 3, 0x0030, 0x00524D8E, 11) + b"1756-ENBT/A" + b"\x03")
LIST_IDENTITY_REQ = encap(0x63, context=bytes.fromhex("0000c1debed1f00d"))
LIST_IDENTITY_REPLY = encap(0x63, cpf((0x000C, IDENTITY_ITEM)), context=bytes.fromhex("0000c1debed1f00d"))
LIST_SERVICES_REPLY = encap(0x04, cpf((0x0100, struct.pack("<HH", 1, 0x0120) + b"Communications\0\0")))
# A Forward Open reply whose T->O data goes to a multicast group: Sockaddr Info item (network order).
FORWARD_OPEN_REPLY = send_data(0x6F, [(0x0000, b""),
                                      (0x00B2, cip_response(0x54, data=bytes(26))),
                                      (0x8001, struct.pack("!HH4s8s", 2, 2222, bytes([239, 192, 1, 2]), bytes(8)))],
                               session=0x20020000)
IO_FRAME = cpf((0x8002, struct.pack("<II", 0x004B0603, 4166875)), (0x00B1, bytes.fromhex("a587e80f0300")))


def unconnected(cip, session=0x11020100, context=bytes(8)):
    """SendRRData: a Null Address item and an Unconnected Data item holding cip."""
    return send_data(0x6F, [(0x0000, b""), (0x00B2, cip)], session=session, timeout=32, context=context)


CONNECTION_MANAGER = bytes.fromhex("20062401")       # class 6, instance 1
ROUTE_BACKPLANE_SLOT0 = bytes.fromhex("0100")        # port 1, link address 0


def unconnected_send(message, route=ROUTE_BACKPLANE_SLOT0, tick=0x07, timeout_ticks=249):
    """Unconnected Send (0x52) to the Connection Manager; a pad byte follows an odd message."""
    pad = b"\0" if len(message) % 2 else b""
    return cip_request(0x52, CONNECTION_MANAGER, bytes([tick, timeout_ticks]) + struct.pack("<H", len(message)) +
                       message + pad + bytes([len(route) // 2, 0]) + route)


def multiple_service(services, reply=False, status=0):
    """Multiple Service Packet (0x0a) to the Message Router: count, offsets, services."""
    offsets, at = [], 2 + 2 * len(services)
    for m in services:
        offsets.append(at)
        at += len(m)
    body = struct.pack("<H%dH" % len(services), len(services), *offsets) + b"".join(services)
    if reply:
        return cip_response(0x0A, status, data=body)
    return cip_request(0x0A, bytes.fromhex("20022401"), body)


# Set Attribute Single (Identity 1, attribute 5) with a 1-byte value: a 9-byte message, padded.
UCS_ODD = unconnected(unconnected_send(cip_request(0x10, bytes.fromhex("200124013005"), b"\x07")))
# Get Attributes All (Identity 1): 6 bytes, no pad; routed over two hops.
UCS_EVEN = unconnected(unconnected_send(cip_request(0x01, bytes.fromhex("20012401")),
                                        route=bytes.fromhex("01000203"), tick=0x1A, timeout_ticks=10),
                       context=b"\x01" + bytes(7))
# ... and to 10.1.1.5 behind the front port: an extended link address (its size, then ASCII).
UCS_EXTENDED = unconnected(unconnected_send(cip_request(0x01, bytes.fromhex("20012401")),
                                            route=bytes.fromhex("0100") + b"\x12\x0810.1.1.5"),
                           context=b"\x02" + bytes(7))
# 0x52 to a tag (ANSI symbol segment): Logix's Read Tag Fragmented, no Unconnected Send.
READ_TAG_FRAGMENTED = unconnected(cip_request(0x52, b"\x91\x04TAG1", struct.pack("<HI", 1, 0)))
MSP_SERVICES = [cip_request(0x0E, bytes.fromhex("200124013001")),                      # Identity 1, attribute 1
                cip_request(0x03, bytes.fromhex("20f52401"), struct.pack("<HHH", 2, 3, 5))]  # TCP/IP 1: 3 and 5
MSP_REQUEST = unconnected(multiple_service(MSP_SERVICES))
MSP_REPLY = unconnected(multiple_service([cip_response(0x0E, data=b"\x01\x00"),
                                          cip_response(0x03, 0x05)], reply=True, status=0x1E))
MSP_ERROR_REPLY = unconnected(cip_response(0x0A, 0x08))     # Service not supported: no data
# Forward Close of connection serial 0x0014 (vendor 0x4d), path: backplane slot 0, Message Router
FORWARD_CLOSE = unconnected(cip_request(0x4E, CONNECTION_MANAGER, struct.pack("<BBHHIBB", 0x0A, 0xF0, 0x14, 0x4D,
                                                                              0x32952BF3, 3, 0) +
                                        bytes.fromhex("010020022401")))
FORWARD_CLOSE_REPLY = unconnected(cip_response(0x4E, data=struct.pack("<HHIBB", 0x14, 0x4D, 0x32952BF3, 0, 0)))


# --- running tshark ----------------------------------------------------------------

def fields(env, capture, names, extra=()):
    """One row per frame: the values of each field, all occurrences joined by ','."""
    args = ["-r", capture, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=,"] + list(extra)
    for n in names:
        args += ["-e", n]
    p = env.tshark(args)
    if p.stderr.strip():
        raise AssertionError("tshark wrote to stderr:\n" + p.stderr)
    return [dict(zip(names, line.split("\t"))) for line in p.stdout.splitlines()]


def capture(name, frames):
    return ENV.add_file(name, pcap(frames))


# --- PDML: messages as each side decodes them ---------------------------------------

THEIR_FO_NAMES = ("cip.cm.ot_connid", "cip.cm.to_connid", "cip.cm.conn_serial_num", "cip.cm.vendor",
                  "cip.cm.orig_serial_num", "cip.cm.timeout_multiplier", "cip.cm.otrpi", "cip.cm.torpi",
                  "cip.cm.connpath_size", "cip.cm.otapi", "cip.cm.toapi", "cip.cm.app_reply_size",
                  "cip.cm.fwo.transport", "cip.cm.fwo.trigger", "cip.cm.fwo.dir", "cip.cm.fwo.consize",
                  "cip.cm.fwo.f_v", "cip.cm.fwo.prio", "cip.cm.fwo.type", "cip.cm.fwo.owner")
WS_FIELDS = ("enip.command|enip.length|enip.session|enip.status|enip.context|enip.listid_delay|"
             "enip.options|enip.cpf.itemcount|enip.cpf.typeid|enip.cpf.length|enip.cpf.cai.connid|"
             "enip.cpf.sai.connid|enip.cpf.sai.seq|enip.sinfamily|enip.sinport|enip.sinaddr|enip.lir.name|"
             "cip.seq|cip.sc|cip.rr|cip.request_path_size|cip.path_segment|cip.class|"
             "cip.msp.num_services|cip.msp.offset|cip.cm.sc|cip.cm.priority|cip.cm.tick_time|"
             "cip.cm.timeout_tick|cip.cm.msg_req_size|cip.cm.route_path_size|cip.port|cip.linkaddress.byte|"
             "cip.genstat|" + "|".join(THEIR_FO_NAMES))
# Wireshark shows each service of a Multiple Service Packet as a text item whose value is its bytes.
LINE = re.compile(rb'^( *)<(?:(packet)>|proto name="([^"]+)"|field name="((?:' +
                  WS_FIELDS.replace(".", r"\.").encode() +
                  rb')|enipr\.[a-z0-9_.]+|(?=" show="Service Packet #))"([^\n]*))', re.M)
ATTR = re.compile(rb'(show|value|size|pos)="([^"]*)"')

# Our field -> the record key it fills (Wireshark's names map to the same keys below).
OURS = {
    "enipr.command": "command", "enipr.length": "length", "enipr.session": "session",
    "enipr.status": "status", "enipr.context": "context", "enipr.options": "options",
    "enipr.cpf.itemcount": "itemcount", "enipr.io.cpf.itemcount": "itemcount",
    "enipr.cpf.item.typeid": "typeid", "enipr.io.cpf.item.typeid": "typeid",
    "enipr.cpf.item.length": "itemlength", "enipr.io.cpf.item.length": "itemlength",
    "enipr.cpf.item.connid": "connid", "enipr.io.cpf.item.connid": "connid",
    "enipr.cpf.item.seqnum": "seqnum", "enipr.io.cpf.item.seqnum": "seqnum",
    "enipr.cpf.item.seqcount": "seqcount",
    "enipr.cpf.item.sockaddr.family": "sinfamily", "enipr.cpf.item.identity.sockaddr.family": "sinfamily",
    "enipr.cpf.item.sockaddr.port": "sinport", "enipr.cpf.item.identity.sockaddr.port": "sinport",
    "enipr.cpf.item.sockaddr.addr": "sinaddr", "enipr.cpf.item.identity.sockaddr.addr": "sinaddr",
    "enipr.cpf.item.identity.name": "name",
}
THEIRS = {
    "enip.command": "command", "enip.length": "length", "enip.session": "session",
    "enip.status": "status", "enip.options": "options", "enip.cpf.itemcount": "itemcount",
    "enip.cpf.typeid": "typeid", "enip.cpf.length": "itemlength", "enip.cpf.cai.connid": "connid",
    "enip.cpf.sai.connid": "connid", "enip.cpf.sai.seq": "seqnum", "cip.seq": "seqcount",
    "enip.sinfamily": "sinfamily", "enip.sinport": "sinport", "enip.sinaddr": "sinaddr", "enip.lir.name": "name",
}
TEXTS = ("sinaddr", "name")        # compared as shown (dotted address, product name), not as numbers
SCALARS = ("command", "length", "session", "status", "context", "options", "itemcount")
LISTS = ("typeid", "itemlength", "connid", "seqnum", "seqcount", "sinfamily", "sinport", "sinaddr", "name", "cip")

# One CIP message: what is compared, slot by slot. msp_offsets is a tuple (one value per offset),
# msp_services where each service lies in the frame ((first byte, length) each), msp_sc the embedded services' codes and msp_class
# their classes (a tuple each, the class where the first path segment is an 8-bit class); cm_* are the Connection Manager's priority/tick and
# time-out ticks (Unconnected Send, Forward Open and Close), ucs_* the rest of an Unconnected
# Send request and the message it carries, fo_* a Forward Open or Close request or its successful
# reply (times in us; the connection parameters as tuples, O->T then T->O).
FO_SCALARS = ("ot_connid", "to_connid", "conn_serial", "vendor", "orig_serial", "timeout_multiplier", "ot_rpi",
              "to_rpi", "path_size", "ot_api", "to_api", "app_reply_size", "class", "trigger", "direction")
FO_PARAMS = ("size", "variable", "priority", "type", "owner")
CIP_SLOTS = ("service", "rr", "pathsize", "segment", "class", "msp_count", "msp_offsets", "msp_services",
             "msp_sc", "msp_class",
             "cm_priority", "cm_tick_time", "cm_timeout_ticks", "ucs_msg_size", "ucs_route_size",
             "ucs_service", "ucs_rr", "ucs_pathsize", "ucs_ports", "ucs_links") + \
    tuple("fo_" + k for k in FO_SCALARS + FO_PARAMS)
# Our field (after "enipr.cpf.item.cip.") -> its slot.
OUR_CIP = {
    "service": "service", "rr": "rr", "pathsize": "pathsize", "path.segment": "segment", "path.class": "class",
    "msp.count": "msp_count", "msp_reply.count": "msp_count", "ucs.priority": "cm_priority",
    "ucs.tick_time": "cm_tick_time", "ucs.timeout_ticks": "cm_timeout_ticks", "ucs.msg_size": "ucs_msg_size",
    "ucs.route_size": "ucs_route_size", "ucs.message.service": "ucs_service", "ucs.message.rr": "ucs_rr",
    "ucs.message.pathsize": "ucs_pathsize", "fwd_open.priority": "cm_priority",
    "fwd_open.tick_time": "cm_tick_time", "fwd_open.timeout_ticks": "cm_timeout_ticks",
    "fwd_open.transport.class": "fo_class", "fwd_open.transport.trigger": "fo_trigger",
    "fwd_open.transport.direction": "fo_direction",
}
for _k in FO_SCALARS[:-3]:
    OUR_CIP["fwd_open." + _k] = OUR_CIP["fwd_open_reply." + _k] = "fo_" + _k
for _k in ("conn_serial", "vendor", "orig_serial", "path_size", "app_reply_size"):
    OUR_CIP["fwd_close." + _k] = OUR_CIP["fwd_close_reply." + _k] = "fo_" + _k
for _k in ("priority", "tick_time", "timeout_ticks"):
    OUR_CIP["fwd_close." + _k] = "cm_" + _k
# Wireshark's fields of the Connection Manager (cipcm) -> slot.
THEIR_CM = {"cip.cm.priority": "cm_priority", "cip.cm.tick_time": "cm_tick_time",
            "cip.cm.timeout_tick": "cm_timeout_ticks"}
THEIR_UCS = {"cip.cm.msg_req_size": "ucs_msg_size", "cip.cm.route_path_size": "ucs_route_size"}
THEIR_FO = {
    "cip.cm.ot_connid": "fo_ot_connid", "cip.cm.to_connid": "fo_to_connid", "cip.cm.conn_serial_num": "fo_conn_serial",
    "cip.cm.vendor": "fo_vendor", "cip.cm.orig_serial_num": "fo_orig_serial",
    "cip.cm.timeout_multiplier": "fo_timeout_multiplier", "cip.cm.otrpi": "fo_ot_rpi", "cip.cm.torpi": "fo_to_rpi",
    "cip.cm.connpath_size": "fo_path_size", "cip.cm.otapi": "fo_ot_api", "cip.cm.toapi": "fo_to_api",
    "cip.cm.app_reply_size": "fo_app_reply_size", "cip.cm.fwo.transport": "fo_class",
    "cip.cm.fwo.trigger": "fo_trigger", "cip.cm.fwo.dir": "fo_direction",
}
THEIR_FO_PARAMS = {"cip.cm.fwo.consize": "fo_size", "cip.cm.fwo.f_v": "fo_variable", "cip.cm.fwo.prio": "fo_priority",
                   "cip.cm.fwo.type": "fo_type", "cip.cm.fwo.owner": "fo_owner"}
OUR_FO_PARAMS = {"fwd_open.%s.%s" % (d, k): "fo_" + k for d in ("ot_params", "to_params") for k in FO_PARAMS}
# ... and of an Unconnected Send's route path's port segments -> slot (a tuple, a value per hop)
THEIR_HOPS = {"cip.port": "ucs_ports", "cip.linkaddress.byte": "ucs_links"}
OUR_HOPS = {"ucs.route.hop.port": "ucs_ports", "ucs.route.hop.link": "ucs_links"}
OUR_TUPLES = dict(OUR_HOPS, **OUR_FO_PARAMS)
OUR_TIMES = ("fo_ot_rpi", "fo_to_rpi", "fo_ot_api", "fo_to_api")    # shown in seconds, compared in us


def new_message():
    m = {k: None for k in SCALARS}
    m.update({k: [] for k in LISTS})
    return m


def new_cip():
    return dict.fromkeys(CIP_SLOTS)


def span(attrs):
    """Where an item lies in the frame: (first byte, length)."""
    return number(attrs["pos"]), number(attrs["size"])


def number(text):
    return int(text, 0)


def pdml_packets(env, capture_path, extra=()):
    """Yields, per frame, the list of (indent, kind, name, attrs) lines that matter."""
    cmd = env.command(["-r", capture_path, "-T", "pdml"] + list(extra))
    packet, rest = None, b""
    # PDML of a 10 000-frame capture is some 270 MB: scan it in chunks with one regex.
    with tempfile.TemporaryFile() as err, \
            subprocess.Popen(cmd, env=env.env(), cwd=env.home, stdout=subprocess.PIPE, stderr=err) as p:
        while True:
            chunk = p.stdout.read(1 << 22)
            if not chunk:
                break
            buf = rest + chunk
            cut = buf.rfind(b"\n") + 1
            buf, rest = buf[:cut], buf[cut:]
            for m in LINE.finditer(buf):
                indent = len(m.group(1))
                if m.group(2):
                    if packet is not None:
                        yield packet
                    packet = []
                elif m.group(3):
                    packet.append((indent, "proto", m.group(3).decode(), None))
                else:
                    attrs = {k.decode(): v.decode() for k, v in ATTR.findall(m.group(5))}
                    packet.append((indent, "field", m.group(4).decode(), attrs))
        if p.wait() != 0:
            err.seek(0)
            raise AssertionError("tshark -T pdml failed on %s:\n%s" % (capture_path,
                                                                        err.read().decode(errors="replace")))
    if packet is not None:
        yield packet


def wireshark_messages(packet):
    """Messages of Wireshark's enip (one top-level enip proto each) and, attached to the
    message before, each top-level cip proto: its service, request path size, first path
    segment (and class), a Multiple Service Packet's count, offsets, where each embedded
    service lies, its code and class, and for an Unconnected Send request the cipcm fields and the embedded request's header
    (the services inside a Multiple Service Packet and cipcm's copies are left out)."""
    out, msg, cip, where, top = [], None, None, None, None
    delay = None
    segments = 0            # path segments seen in the current top-level cip
    in_services = False     # past the offset list of a Multiple Service Packet
    msp_segments = 0        # path segments seen in the current embedded service
    msp_first_segment = None
    cm = None               # in cipcm: "ucs" (Unconnected Send request), "fo" (Forward Open, or its
                            # successful reply)
    genstat = None          # of the current top-level cip
    for indent, kind, name, attrs in packet:
        if kind == "proto":
            if indent == 2:
                where = top = name
                if name == "enip":
                    msg = new_message()
                    out.append(msg)
                    delay = None
                    cip = None
                elif name == "cip" and msg is not None:
                    cip = new_cip()
                    msg["cip"].append(cip)
                    segments, in_services, genstat = 0, False, None
                elif name == "cipcm":
                    cm = None
                else:
                    cip = None
            elif where == "cipcm" and cm == "ucs" and name == "cip":
                where = "embedded"      # the request an Unconnected Send carries
            elif top == "cip" and in_services and indent == 8 and name == "cip":
                where, msp_segments = "msp", 0      # a service of a Multiple Service Packet
            elif where != "enip":
                where = "nested"
            continue
        if not name:
            # "Service Packet #n", at the top level of a Multiple Service Packet (not inside one)
            if top == "cip" and indent == 6 and cip is not None:
                in_services = True
                cip["msp_services"] = (cip["msp_services"] or ()) + (span(attrs),)
            continue
        if attrs.get("size") == "0":
            continue            # generated, e.g. a response's request path size copied from its request
        if where == "enip" and msg is not None:
            if name == "enip.listid_delay":
                delay = attrs.get("value", "")
            elif name == "enip.context":
                # ListIdentity requests: Wireshark splits the 8 context bytes into a 2-byte
                # Max Response Delay and 6 bytes of Sender Context. Same bytes, one field here.
                msg["context"] = (delay or "") + attrs.get("value", "")
            elif name in THEIRS:
                key = THEIRS[name]
                value = attrs["show"] if key in TEXTS else number(attrs["show"])
                if key in SCALARS:
                    msg[key] = value
                else:
                    msg[key].append(value)
        elif where == "cip" and cip is not None:
            slot = {"cip.sc": "service", "cip.rr": "rr", "cip.request_path_size": "pathsize",
                    "cip.msp.num_services": "msp_count"}.get(name)
            if slot is not None and cip[slot] is None:
                cip[slot] = number(attrs["show"])
            elif name == "cip.genstat":
                genstat = number(attrs["show"])
            elif name == "cip.path_segment":
                segments += 1
                if segments == 1:
                    cip["segment"] = number(attrs["show"])
            elif name == "cip.class" and segments == 1 and cip["segment"] == 0x20:
                cip["class"] = number(attrs["show"])
            elif name == "cip.msp.offset" and not in_services:
                cip["msp_offsets"] = (cip["msp_offsets"] or ()) + (number(attrs["show"]),)
        elif top == "cipcm" and cip is not None and name == "cip.cm.route_path_size":
            where = "cipcm"             # the embedded request has ended
            if cm == "ucs":
                cip["ucs_route_size"] = number(attrs["show"])
        elif where == "cipcm" and cip is not None:
            if name == "cip.cm.sc":
                # a Forward Open reply: only a successful one is decoded
                cm = {(0x52, 0, None): "ucs", (0x54, 0, None): "fo", (0x54, 1, 0): "fo", (0x4e, 0, None): "fo",
                      (0x4e, 1, 0): "fo"}.get(
                    (number(attrs["show"]), cip["rr"], genstat))
            elif cm in ("ucs", "fo") and name in THEIR_CM:
                cip[THEIR_CM[name]] = number(attrs["show"])
            elif cm == "ucs" and name in THEIR_UCS:
                cip[THEIR_UCS[name]] = number(attrs["show"])
            elif cm == "fo" and name in THEIR_FO:
                cip[THEIR_FO[name]] = number(attrs["show"])
            elif (cm == "ucs" and name in THEIR_HOPS) or (cm == "fo" and name in THEIR_FO_PARAMS):
                slot = THEIR_HOPS.get(name) or THEIR_FO_PARAMS[name]
                cip[slot] = (cip[slot] or ()) + (number(attrs["show"]),)
        elif where == "msp" and cip is not None:
            if name == "cip.sc":
                cip["msp_sc"] = (cip["msp_sc"] or ()) + (number(attrs["show"]),)
            elif name == "cip.path_segment":
                msp_segments += 1
                if msp_segments == 1:
                    msp_first_segment = number(attrs["show"])
            elif name == "cip.class" and msp_segments == 1 and msp_first_segment == 0x20:
                cip["msp_class"] = (cip["msp_class"] or ()) + (number(attrs["show"]),)
        elif where == "embedded" and cip is not None:
            slot = {"cip.sc": "ucs_service", "cip.rr": "ucs_rr", "cip.request_path_size": "ucs_pathsize"}.get(name)
            if slot is not None and cip[slot] is None:
                cip[slot] = number(attrs["show"])
    return out


def our_messages(packet):
    out, msg, cip = [], None, None
    prefix = "enipr.cpf.item.cip."
    for indent, kind, name, attrs in packet:
        if kind == "proto":
            if indent == 2:
                msg = new_message() if name == "enipr" else None
                if msg is not None:
                    out.append(msg)
            continue
        if msg is None or not name:
            continue
        if name == "enipr.cpf.item.cip":
            cip = new_cip()
            msg["cip"].append(cip)
        elif name.startswith(prefix):
            field = name[len(prefix):]
            if field in OUR_CIP:
                slot = OUR_CIP[field]
                cip[slot] = round(float(attrs["show"]) * 1e6) if slot in OUR_TIMES else number(attrs["show"])
            elif field in ("msp.offset", "msp_reply.offset"):
                cip["msp_offsets"] = (cip["msp_offsets"] or ()) + (number(attrs["show"]),)
            elif field in OUR_TUPLES:
                slot = OUR_TUPLES[field]
                cip[slot] = (cip[slot] or ()) + (number(attrs["show"]),)
            elif field in ("msp.request", "msp_reply.reply"):
                cip["msp_services"] = (cip["msp_services"] or ()) + (span(attrs),)
            elif field in ("msp.request.service", "msp_reply.reply.service"):
                cip["msp_sc"] = (cip["msp_sc"] or ()) + (number(attrs["show"]),)
            elif field == "msp.request.path.class":
                cip["msp_class"] = (cip["msp_class"] or ()) + (number(attrs["show"]),)
        elif name == "enipr.context":
            msg["context"] = attrs.get("value", "")
        elif name in OURS:
            key = OURS[name]
            value = attrs["show"] if key in TEXTS else number(attrs["show"])
            if key in SCALARS:
                msg[key] = value
            else:
                msg[key].append(value)
    return out


def cip_count(c):
    """Fields in one CIP record: each offset of a Multiple Service Packet counts."""
    return sum(len(v) if isinstance(v, tuple) else 1 for v in c.values() if v is not None)


def field_count(msg):
    n = sum(1 for k in SCALARS if msg[k] is not None)
    n += sum(len(msg[k]) for k in LISTS if k != "cip")
    return n + sum(cip_count(c) for c in msg["cip"])


def compare_messages(theirs, ours):
    """(fields compared, fields agreeing, differences as text)."""
    compared = agreeing = 0
    diffs = []
    for i, (t, o) in enumerate(zip(theirs, ours)):
        for k in SCALARS + LISTS:
            a, b = t[k], o[k]
            if k == "cip":
                n = max(sum(cip_count(c) for c in a), sum(cip_count(c) for c in b))
            elif k in LISTS:
                n = max(len(a), len(b))
            else:
                n = 0 if a is None and b is None else 1
            compared += n
            if a == b:
                agreeing += n
            else:
                diffs.append("message %d %s: wireshark %r, rules %r" % (i + 1, k, a, b))
    if len(theirs) != len(ours):
        extra = theirs[len(ours):] or ours[len(theirs):]
        compared += sum(field_count(m) for m in extra)
        diffs.append("wireshark decodes %d messages, the rules %d" % (len(theirs), len(ours)))
    return compared, agreeing, diffs


def count_embedded(s, theirs, ours):
    """Adds to s the embedded services' codes and classes Wireshark shows (msp_sc, msp_class)
    and how many of ours agree, position by position."""
    for t, o in zip(theirs, ours):
        for tc, oc in zip(t["cip"], o["cip"]):
            for slot in ("msp_sc", "msp_class"):
                a, b = tc[slot] or (), oc[slot] or ()
                s[slot] += len(a)
                s[slot + "_agree"] += sum(1 for x, y in zip(a, b) if x == y)


def differential(capture_path):
    """Per-frame comparison of one capture; returns a summary dict."""
    theirs = [wireshark_messages(p) for p in pdml_packets(BARE, capture_path)]
    ours, experts, pairing = [], 0, dict.fromkeys(PAIRING_EXPERTS, 0)
    for p in pdml_packets(ENV, capture_path):
        ours.append(our_messages(p))
        for _, kind, name, _ in p:
            if kind == "field" and name in pairing:
                pairing[name] += 1
            elif kind == "field" and name.startswith("enipr.expert."):
                experts += 1
    if len(theirs) != len(ours):
        raise AssertionError("%s: %d frames for Wireshark, %d with the rules" % (capture_path, len(theirs), len(ours)))
    s = {"frames": len(ours), "enip_frames": 0, "messages_ws": 0, "messages_ours": 0,
         "fields": 0, "agree": 0, "frames_differ": [], "experts": experts, "pairing": pairing,
         "msp_sc": 0, "msp_sc_agree": 0, "msp_class": 0, "msp_class_agree": 0}
    for number_, (t, o) in enumerate(zip(theirs, ours), 1):
        if not t and not o:
            continue
        s["enip_frames"] += 1
        s["messages_ws"] += len(t)
        s["messages_ours"] += len(o)
        compared, agreeing, diffs = compare_messages(t, o)
        count_embedded(s, t, o)
        s["fields"] += compared
        s["agree"] += agreeing
        if diffs:
            s["frames_differ"].append((number_, diffs))
    return s


# --- the tests ---------------------------------------------------------------------

def ethercat_frame():
    """One EtherCAT frame (BRD, 1 data byte) for the two-plugins check."""
    datagram = struct.pack("<BBHHHH", 7, 0x20, 0, 0, 1, 0) + b"\x11" + struct.pack("<H", 2)
    header = struct.pack("<H", len(datagram) | (1 << 12))
    return ethernet(header + datagram, ethertype=0x88A4)


class Loading(unittest.TestCase):
    @unittest.skipIf(SANITIZE, "tshark -G plugins cannot run with the sanitizer runtimes preloaded")
    def test_enip_and_ethercat_plugins_load_together(self):
        rows = ENV.assert_plugin_loaded("enipr")
        names = [r[0] for r in rows]
        self.assertIn("dissgen_enip.so", names)
        self.assertIn("dissgen_ethercat.so", names)
        protocols, _ = ENV.protocols()
        for p in ("enipr", "ecatr", "enip", "cip", "cipio"):
            self.assertIn(p, protocols)
        cap = capture("both.pcap", [TcpFlow(50000, 44818).segment(SEED), ethercat_frame()])
        rows = fields(ENV, cap, ["_ws.col.Protocol", "enipr.command", "ecatr.datagram.cmd"])
        self.assertEqual([r["_ws.col.Protocol"] for r in rows], ["ENIPR", "ECATR"])
        self.assertEqual(rows[0]["enipr.command"], "0x006f")
        self.assertEqual(rows[1]["ecatr.datagram.cmd"], "0x07")

    def test_wireshark_enip_stays_selectable(self):
        cap = capture("decode_as.pcap", [TcpFlow(50000, 44818).segment(SEED)])
        rows = fields(ENV, cap, ["_ws.col.Protocol", "enip.command", "cip.sc", "enipr.command"],
                      ["-d", "tcp.port==44818,enip"])
        self.assertEqual(rows[0]["enip.command"], "0x006f")
        self.assertEqual(rows[0]["enipr.command"], "")
        self.assertEqual(rows[0]["cip.sc"].split(",")[0], "0x54")


SEED_EXPECTED = {
    "_ws.col.Protocol": "ENIPR",
    "_ws.col.Info": "SendRRData, session 0x20020000, Forward Open (Connection Manager)",
    "enipr.command": "0x006f", "enipr.length": "62", "enipr.session": "0x20020000",
    "enipr.status": "0x00000000", "enipr.context": "00 00 00 00 00 00 00 00", "enipr.options": "0x00000000",
    "enipr.iface": "0x00000000", "enipr.timeout": "1024", "enipr.cpf.itemcount": "2",
    "enipr.cpf.item.typeid": "0x0000,0x00b2", "enipr.cpf.item.length": "0,46",
    "enipr.cpf.item.cip.service": "0x54", "enipr.cpf.item.cip.rr": "0x00",
    "enipr.cpf.item.cip.pathsize": "2", "enipr.cpf.item.cip.path.segment": "0x20",
    "enipr.cpf.item.cip.path.class": "0x06", "enipr.cpf.item.cip.path.more": "24 01",
    # The Forward Open's 40 bytes after the path (header 24, interface handle + timeout 6, item
    # count 2, two item headers 8, service + path size 2, path 4), field by field (forward_open_fields).
    "enipr.cpf.item.cip.data": "", "enipr.cpf.item.cip.genstat": "", "enipr.cpf.item.connid": "",
    "enipr.cpf.item.data": "",
}


def forward_open_fields(data):
    """The rules' Forward Open fields, as tshark prints them, computed from a request's bytes."""
    (tick, ticks, ot_connid, to_connid, serial, vendor, orig_serial, multiplier, ot_rpi, ot_params, to_rpi,
     to_params, transport, path_size) = struct.unpack("<BBIIHHIB3xIHIHBB", data[:36])
    p = "enipr.cpf.item.cip.fwd_open."
    out = {p + "tick_time": str(tick & 15), p + "priority": str(tick >> 4 & 1), p + "timeout_ticks": str(ticks),
           p + "ot_connid": "0x%08x" % ot_connid, p + "to_connid": "0x%08x" % to_connid,
           p + "conn_serial": "0x%04x" % serial, p + "vendor": "0x%04x" % vendor,
           p + "orig_serial": "0x%08x" % orig_serial, p + "timeout_multiplier": "0x%02x" % multiplier,
           p + "ot_rpi": "%d.%06d000" % divmod(ot_rpi, 10 ** 6), p + "to_rpi": "%d.%06d000" % divmod(to_rpi, 10 ** 6),
           p + "transport.class": str(transport & 15), p + "transport.trigger": "0x%02x" % (transport >> 4 & 7),
           p + "transport.direction": "0x%02x" % (transport >> 7), p + "path_size": str(path_size),
           p + "path": " ".join("%02x" % b for b in data[36:36 + 2 * path_size])}
    for d, v in (("ot_params.", ot_params), ("to_params.", to_params)):
        out.update({p + d + "size": str(v & 0x1FF), p + d + "variable": "0x%04x" % (v >> 9 & 1),
                    p + d + "priority": "0x%04x" % (v >> 10 & 3), p + d + "type": "0x%04x" % (v >> 13 & 3),
                    p + d + "owner": str(v >> 15)})
    return out


class Seed(unittest.TestCase):
    def test_seed_message_in_one_tcp_segment(self):
        self.assertEqual(len(SEED), 86)
        cap = capture("seed.pcap", [TcpFlow(50000, 44818).segment(SEED)])
        expected = dict(SEED_EXPECTED, **forward_open_fields(SEED[24 + 6 + 2 + 8 + 2 + 4:]))
        rows = fields(ENV, cap, list(expected))
        self.assertEqual(len(rows), 1)
        self.assertEqual(rows[0], expected)
        # The connection path ends the message: 46 - 2 - 4 - 36 bytes.
        self.assertEqual(len(rows[0]["enipr.cpf.item.cip.fwd_open.path"].split()), 4)

    def test_wireshark_agrees_on_the_seed(self):
        cap = capture("seed_ws.pcap", [TcpFlow(50000, 44818).segment(SEED)])
        s = differential(cap)
        self.assertEqual((s["messages_ws"], s["messages_ours"]), (1, 1))
        self.assertEqual(s["frames_differ"], [])
        self.assertEqual(s["fields"], s["agree"])
        self.assertGreaterEqual(s["fields"], 14)


class Tcp(unittest.TestCase):
    NAMES = ["enipr.command", "enipr.length", "enipr.session", "enipr.cpf.itemcount", "enipr.cpf.item.typeid",
             "enipr.cpf.item.length", "enipr.cpf.item.cip.service", "enipr.cpf.item.cip.rr",
             "enipr.cpf.item.cip.pathsize", "enipr.cpf.item.seqcount", "enipr.cpf.item.connid",
             "enipr.rs.version", "tcp.reassembled.length", "_ws.col.Protocol", "_ws.col.Info"]

    def test_one_message_split_over_three_segments(self):
        flow = TcpFlow(50001, 44818)
        # 3 bytes: not even the length field; 40: inside the CPF; 43: the rest.
        frames = [flow.segment(SEED[:3]), flow.segment(SEED[3:43]), flow.segment(SEED[43:])]
        rows = fields(ENV, capture("split3.pcap", frames), self.NAMES)
        self.assertEqual([r["enipr.command"] for r in rows], ["", "", "0x006f"])
        last = rows[2]
        self.assertEqual(last["tcp.reassembled.length"], "86")
        self.assertEqual(last["enipr.length"], "62")
        self.assertEqual(last["enipr.session"], "0x20020000")
        self.assertEqual(last["enipr.cpf.item.typeid"], "0x0000,0x00b2")
        self.assertEqual(last["enipr.cpf.item.length"], "0,46")
        self.assertEqual(last["enipr.cpf.item.cip.service"], "0x54")
        self.assertEqual(last["enipr.cpf.item.cip.pathsize"], "2")
        # Wireshark's enip reassembles the same way.
        self.assertEqual(differential(ENV.path("split3.pcap"))["frames_differ"], [])

    def test_three_messages_in_one_segment(self):
        flow = TcpFlow(50002, 44818)
        rows = fields(ENV, capture("three.pcap", [flow.segment(REGISTER + SEED + GET_ATTR)]), self.NAMES)
        self.assertEqual(len(rows), 1)
        r = rows[0]
        self.assertEqual(r["_ws.col.Protocol"], "ENIPR")
        self.assertEqual(r["_ws.col.Info"], "RegisterSession, session 0x00000000 | "
                                            "SendRRData, session 0x20020000, Forward Open (Connection Manager) | "
                                            "SendUnitData, session 0x11020100, Get Attribute Single")
        self.assertEqual(r["enipr.command"], "0x0065,0x006f,0x0070")
        self.assertEqual(r["enipr.length"], "4,62,%d" % (len(GET_ATTR) - 24))
        self.assertEqual(r["enipr.session"], "0x00000000,0x20020000,0x11020100")
        self.assertEqual(r["enipr.rs.version"], "1")
        self.assertEqual(r["enipr.cpf.itemcount"], "2,2")
        self.assertEqual(r["enipr.cpf.item.typeid"], "0x0000,0x00b2,0x00a1,0x00b1")
        self.assertEqual(r["enipr.cpf.item.length"], "0,46,4,%d" % (2 + 4 + 2))
        self.assertEqual(r["enipr.cpf.item.connid"], "0x80fe0028")
        self.assertEqual(r["enipr.cpf.item.seqcount"], "1929")
        self.assertEqual(r["enipr.cpf.item.cip.service"], "0x54,0x0e")
        self.assertEqual(r["enipr.cpf.item.cip.rr"], "0x00,0x01")
        self.assertEqual(r["enipr.cpf.item.cip.pathsize"], "2")     # responses have none
        self.assertEqual(differential(ENV.path("three.pcap"))["frames_differ"], [])

    def test_messages_straddling_segments(self):
        flow = TcpFlow(50003, 44818)
        stream = REGISTER + SEED + GET_ATTR + GET_ATTR_ERROR
        cuts = [0, 30, 30 + 86, len(stream) - 5, len(stream)]    # 1.25, 1, 1.9, 0.1 messages
        frames = [flow.segment(stream[a:b]) for a, b in zip(cuts, cuts[1:])]
        rows = fields(ENV, capture("straddle.pcap", frames),
                      ["enipr.command", "enipr.cpf.item.cip.genstat", "enipr.cpf.item.cip.addstatsize",
                       "enipr.cpf.item.cip.addstat"])
        self.assertEqual([r["enipr.command"] for r in rows], ["0x0065", "0x006f", "0x0070", "0x0070"])
        self.assertEqual(rows[3]["enipr.cpf.item.cip.genstat"], "0x1f")
        self.assertEqual(rows[3]["enipr.cpf.item.cip.addstatsize"], "1")
        self.assertEqual(rows[3]["enipr.cpf.item.cip.addstat"], "34 12")
        self.assertEqual(differential(ENV.path("straddle.pcap"))["frames_differ"], [])

    def test_a_corrupted_header_starts_no_reassembly(self):
        # an unknown command declaring 65520 bytes: not EtherNet/IP (valid="..."), so the
        # messages after it decode; the segment itself goes to Wireshark's enip, which enipr
        # displaced on the port (enip alone decodes none of the later ones: no comparison here)
        flow = TcpFlow(50004, 44818)
        frames = [flow.segment(REGISTER), flow.segment(encap(0x1234, bytes(16))[:2] + b"\xf0\xff" + bytes(36)),
                  flow.segment(GET_ATTR), flow.segment(SEED)]
        rows = fields(ENV, capture("corrupted.pcap", frames), ["enipr.command", "_ws.col.Protocol"])
        self.assertEqual([r["enipr.command"] for r in rows], ["0x0065", "", "0x0070", "0x006f"])
        self.assertEqual(rows[1]["_ws.col.Protocol"], "ENIP")


    def test_sockaddr_item_in_network_byte_order(self):
        p = "enipr.cpf.item.sockaddr."
        names = ["enipr.cpf.item.typeid", "enipr.cpf.item.length", "enipr.cpf.item.cip.service",
                 "enipr.cpf.item.cip.rr", "enipr.cpf.item.cip.genstat", p + "family", p + "port", p + "addr",
                 p + "zero"]
        # The request first: Wireshark's cip knows a reply's object from its request only.
        frames = [TcpFlow(50004, 44818).segment(SEED),
                  TcpFlow(44818, 50004, src=(10, 1, 1, 164), dst=(10, 1, 1, 167)).segment(FORWARD_OPEN_REPLY)]
        rows = fields(ENV, capture("sockaddr.pcap", frames), names + ["enipr.cpf.item.cip.fwd_open_reply.ot_api"])
        self.assertEqual([rows[1][n] for n in names],
                         ["0x0000,0x00b2,0x8001", "0,30,16", "0x54", "0x01", "0x00", "2", "2222", "239.192.1.2",
                          "00 00 00 00 00 00 00 00"])
        self.assertEqual(rows[1]["enipr.cpf.item.cip.fwd_open_reply.ot_api"], "0.000000000")
        s = differential(ENV.path("sockaddr.pcap"))
        self.assertEqual(s["frames_differ"], [])
        self.assertEqual(s["fields"], s["agree"])


class Udp(unittest.TestCase):
    def test_list_identity_over_udp_44818(self):
        frames = [udp(50010, 44818, LIST_IDENTITY_REQ, dst=(255, 255, 255, 255)),
                  udp(44818, 50010, LIST_IDENTITY_REPLY, src=(10, 1, 1, 164), dst=(10, 1, 1, 167))]
        p = "enipr.cpf.item.identity."
        names = ["enipr.command", "enipr.length", "enipr.context", "enipr.cpf.itemcount", "enipr.cpf.item.typeid",
                 "enipr.cpf.item.length", p + "version", p + "sockaddr.family", p + "sockaddr.port",
                 p + "sockaddr.addr", p + "sockaddr.zero", p + "vendor", p + "devtype", p + "prodcode",
                 p + "revision.major", p + "revision.minor", p + "status", p + "serial", p + "namelen",
                 p + "name", p + "state"]
        rows = fields(ENV, capture("listidentity.pcap", frames), names)
        self.assertEqual(rows[0]["enipr.command"], "0x0063")
        self.assertEqual(rows[0]["enipr.length"], "0")
        self.assertEqual(rows[0]["enipr.cpf.itemcount"], "")      # a request has no data
        r = rows[1]
        self.assertEqual(r["enipr.context"], "00 00 c1 de be d1 f0 0d")
        expected = ["1", "0x000c", str(len(IDENTITY_ITEM)), "1", "2", "44818", "10.1.1.164",
                    "00 00 00 00 00 00 00 00", "0x0001", "0x000c", "58", "4", "3", "0x0030", "0x00524d8e",
                    "11", "1756-ENBT/A", "0x03"]
        self.assertEqual([r[n] for n in names[3:]], expected)
        self.assertEqual(differential(ENV.path("listidentity.pcap"))["frames_differ"], [])

    def test_list_services_reply_over_tcp(self):
        p = "enipr.cpf.item.listservices."
        names = ["enipr.command", "enipr.cpf.item.typeid", p + "version", p + "tcp", p + "udp", p + "name"]
        rows = fields(ENV, capture("listservices.pcap", [TcpFlow(44818, 50011).segment(LIST_SERVICES_REPLY)]),
                      names)
        self.assertEqual([rows[0][n] for n in names],
                         ["0x0004", "0x0100", "1", "1", "1", "Communications"])

    def test_class1_io_over_udp_2222(self):
        frames = [udp(2222, 2222, IO_FRAME)]
        names = ["_ws.col.Protocol", "enipr.command", "enipr.io.cpf.itemcount", "enipr.io.cpf.item.typeid",
                 "enipr.io.cpf.item.length", "enipr.io.cpf.item.connid", "enipr.io.cpf.item.seqnum",
                 "enipr.io.cpf.item.data"]
        rows = fields(ENV, capture("io.pcap", frames), names)
        self.assertEqual([rows[0][n] for n in names],
                         ["ENIPR", "", "2", "0x8002,0x00b1", "8,6", "0x004b0603", "4166875", "a5 87 e8 0f 03 00"])
        self.assertEqual(differential(ENV.path("io.pcap"))["frames_differ"], [])


class Services(unittest.TestCase):
    """Unconnected Send and Multiple Service Packet, field by field against the bytes, and
    against Wireshark's cip/cipcm (the differential compares the same fields)."""
    P = "enipr.cpf.item.cip."

    def test_unconnected_send_with_odd_and_even_message(self):
        p = self.P + "ucs."
        names = [self.P + "service", self.P + "path.class", p + "tick_time", p + "priority", p + "timeout_ticks",
                 p + "msg_size", p + "odd", p + "message.service", p + "message.rr", p + "message.pathsize",
                 p + "message.path", p + "message.data", p + "pad", p + "route_size", p + "reserved",
                 p + "route.hop.port", p + "route.hop.extended", p + "route.hop.type", p + "route.hop.link",
                 self.P + "data", "_ws.expert"]
        flow = TcpFlow(50030, 44818)
        names_more = names + [self.P + "ucs.route.hop.more"]
        cap = capture("ucs.pcap", [flow.segment(UCS_ODD), flow.segment(UCS_EVEN), flow.segment(UCS_EXTENDED)])
        rows = fields(ENV, cap, names_more)
        self.assertEqual([rows[0][n] for n in names],
                         ["0x52", "0x06", "7", "0", "249", "9", "1", "0x10", "0x00", "3", "20 01 24 01 30 05",
                          "07", "0x00", "1", "0x00", "0x01", "0", "0x00", "0", "", ""])
        # tick byte 0x1a: tick time 10, priority 1; no pad after 6 bytes; two hops
        self.assertEqual([rows[1][n] for n in names],
                         ["0x52", "0x06", "10", "1", "10", "6", "0", "0x01", "0x00", "2", "20 01 24 01",
                          "", "", "2", "0x00", "0x01,0x02", "0,0", "0x00,0x00", "0,3", "", ""])
        r = rows[2]
        self.assertEqual([r[n] for n in names[-8:-2]], ["6", "0x00", "0x01,0x02", "0,1", "0x00,0x00", "0"])
        self.assertEqual(r[self.P + "ucs.route.hop.more"], "08 " + " ".join("%02x" % c for c in b"10.1.1.5"))
        s = differential(ENV.path("ucs.pcap"))
        self.assertEqual(s["frames_differ"], [])
        self.assertEqual(s["fields"], s["agree"])

    def test_service_0x52_to_another_class_is_not_unconnected_send(self):
        names = [self.P + "service", self.P + "path.segment", self.P + "path.class", self.P + "path.more",
                 self.P + "ucs", self.P + "ucs.msg_size", self.P + "data", "_ws.expert"]
        rows = fields(ENV, capture("readtagfrag.pcap", [TcpFlow(50031, 44818).segment(READ_TAG_FRAGMENTED)]), names)
        self.assertEqual([rows[0][n] for n in names],
                         ["0x52", "0x91", "", "04 54 41 47 31", "", "", "01 00 00 00 00 00", ""])
        self.assertEqual(differential(ENV.path("readtagfrag.pcap"))["frames_differ"], [])

    def test_forward_close_and_its_reply(self):
        p, r = self.P + "fwd_close.", self.P + "fwd_close_reply."
        names = [p + "tick_time", p + "priority", p + "timeout_ticks", p + "conn_serial", p + "vendor",
                 p + "orig_serial", p + "path_size", p + "reserved", p + "path", r + "conn_serial", r + "vendor",
                 r + "orig_serial", r + "app_reply_size", self.P + "data", "_ws.expert"]
        frames = [TcpFlow(50033, 44818).segment(FORWARD_CLOSE),
                  TcpFlow(44818, 50033, src=(10, 1, 1, 164), dst=(10, 1, 1, 167)).segment(FORWARD_CLOSE_REPLY)]
        rows = fields(ENV, capture("fwdclose.pcap", frames), names)
        self.assertEqual([rows[0][n] for n in names],
                         ["10", "0", "240", "0x0014", "0x004d", "0x32952bf3", "3", "0x00", "01 00 20 02 24 01",
                          "", "", "", "", "", ""])
        self.assertEqual([rows[1][n] for n in names],
                         ["", "", "", "", "", "", "", "", "", "0x0014", "0x004d", "0x32952bf3", "0", "", ""])
        s = differential(ENV.path("fwdclose.pcap"))
        self.assertEqual(s["frames_differ"], [])
        self.assertEqual(s["fields"], s["agree"])

    def test_multiple_service_packet_request_and_replies(self):
        flow = TcpFlow(50032, 44818)
        back = TcpFlow(44818, 50032, src=(10, 1, 1, 164), dst=(10, 1, 1, 167))
        cap = capture("msp.pcap", [flow.segment(MSP_REQUEST), back.segment(MSP_REPLY),
                                   back.segment(MSP_ERROR_REPLY)])
        names = [self.P + "service", self.P + "rr", self.P + "genstat", self.P + "msp.count", self.P + "msp.offset",
                 self.P + "msp.request.service", self.P + "msp.request.path.class", self.P + "msp.request.data",
                 self.P + "msp_reply.count", self.P + "msp_reply.offset", self.P + "msp_reply.reply.service",
                 self.P + "msp_reply.reply.genstat", self.P + "msp_reply.reply.data",
                 self.P + "msp_reply.reply.requested_attribute", self.P + "msp_reply.reply.id_attr.vendor",
                 self.P + "data", "_ws.expert"]
        rows = fields(ENV, cap, names)
        # each embedded request: its service, class and data (the second one's three words)
        self.assertEqual([rows[0][n] for n in names],
                         ["0x0a", "0x00", "", "2", "6,14", "0x0e,0x03", "0x01,0xf5", "02 00 03 00 05 00",
                          "", "", "", "", "", "", "", "", ""])
        # each embedded reply: its service and status; the first one decoded by the first embedded
        # request (Identity, attribute 1: the vendor), the second one (TCP/IP object) has no data
        self.assertEqual([rows[1][n] for n in names],
                         ["0x0a", "0x01", "0x1e", "", "", "", "", "", "2", "6,12", "0x0e,0x03", "0x00,0x05",
                          "", "1", "0x0001", "", ""])
        # An error reply carries no services: nothing to decode, nothing malformed to report; its
        # request (the same sender context) was answered by the first reply, so it says that it
        # cannot read what its request named.
        self.assertEqual([rows[2][n] for n in names], ["0x0a", "0x01", "0x08"] + [""] * 13 + [NO_REQUEST_NOTE])
        s = differential(ENV.path("msp.pcap"))
        self.assertEqual(s["frames_differ"], [])
        self.assertEqual(s["fields"], s["agree"])


NO_REQUEST_NOTE = ("Expert Info (Note/Sequence): The request of this response is not known (not captured or given "
                   "up as lost before it came): the values read from it are unknown")
# The pairing's expert infos (requests and replies across frames), apart from the malformed ones.
PAIRING_EXPERTS = ("enipr.expert.no_request_context", "enipr.expert.no_response", "enipr.expert.duplicate",
                   "enipr.expert.out_of_order")


class Malformed(unittest.TestCase):
    def test_truncated_and_corrupted_messages_never_break_tshark(self):
        """Every prefix of the seed, of a ListIdentity reply and of CIP service messages, and
        byte flips, over UDP 44818 and 2222: tshark exits 0, and truncations give expert
        infos, not exceptions."""
        payloads = [m[:n] for m in (SEED, LIST_IDENTITY_REPLY, GET_ATTR_ERROR) for n in range(1, len(m))]
        # Unconnected Send and Multiple Service Packet: cut inside the CIP message, and flipped
        more = [m[:n] for m in (UCS_ODD, MSP_REQUEST, MSP_REPLY, FORWARD_CLOSE) for n in range(40, len(m))]
        more += [m[:i] + bytes([m[i] ^ 0xFF]) + m[i + 1:] for m in (UCS_ODD, MSP_REPLY) for i in range(40, len(m))]
        for m in (SEED, LIST_IDENTITY_REPLY, IO_FRAME):
            for i in range(len(m)):
                payloads.append(m[:i] + bytes([m[i] ^ 0xFF]) + m[i + 1:])
        frames = [udp(50020, 44818, b) for b in payloads] + [udp(2222, 2222, b) for b in payloads[:200]]
        frames += [udp(50020, 44818, b) for b in more]
        cap = capture("malformed.pcap", frames)
        p = ENV.tshark(["-r", cap, "-T", "fields", "-e", "_ws.col.Protocol", "-e", "_ws.expert.message"],
                       check=False)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stderr.strip(), "")
        rows = [line.split("\t") for line in p.stdout.splitlines()]
        self.assertEqual(len(rows), len(frames))
        # on 44818 a message too short for the header's Command and Length, or with a command
        # Wireshark's enip does not know, is not EtherNet/IP (valid="..."): it goes to the
        # dissector enipr displaced on the port, Wireshark's enip, as if enipr were not there
        def ours(b):
            return len(b) >= 4 and struct.unpack("<HH", b[:4])[0] in ENIP_COMMANDS and struct.unpack("<HH", b[:4])[1] <= 65511
        alone = [line for line in ENV.tshark(["-r", cap, "--disable-protocol", "enipr", "-T", "fields", "-e",
                                              "_ws.col.Protocol"]).stdout.splitlines()]
        claimed = [ours(b) for b in payloads] + [True] * 200 + [ours(b) for b in more]
        expected = ["ENIPR" if mine else alone[i] for i, mine in enumerate(claimed)]
        self.assertGreater(claimed.count(False), 30)
        self.assertEqual([r[0] for r in rows], expected)
        verbose = ENV.tshark(["-r", cap, "-V"], check=False)
        self.assertEqual(verbose.returncode, 0, verbose.stderr)
        self.assertNotIn("[Malformed Packet: ENIPR", verbose.stdout, "a Wireshark exception escaped the rules")
        # A prefix cut inside the Unconnected Data item says so where it happens.
        self.assertRegex(rows[60][1], r"past the end|Truncated|should occur")
        # ... and the differential counts our expert infos (none on the corpus, see Corpus)
        self.assertGreater(differential(ENV.path("malformed.pcap"))["experts"], len(payloads) // 2)


class MspFaults(unittest.TestCase):
    """A corrupted offset in a real Multiple Service Packet gives our bad_offset expert on
    that frame alone; the clean copies give none, and nothing escapes as an exception."""

    def test_corrupted_offset_gives_bad_offset_on_that_frame_only(self):
        import pcaprewrite as pr
        path = os.path.join(corpus_dir(), "cip-multiple-2.pcap")
        if not os.path.isfile(path):
            self.skipTest("no %s" % path)
        cap = pr.Capture.read(path)
        clean = cap.packets[0]
        # the reply's count (11) and its first offsets (24, 36, 48), as the corpus has them
        at = bytes(clean.data).find(struct.pack("<HHHH", 11, 24, 36, 48))
        self.assertGreater(at, 0)
        past_end, decreasing = clean.copy(), clean.copy()
        pr.set_u16(past_end, at + 2 + 2 * 4, 0x7fff)          # service 5 starts past the end
        pr.set_u16(decreasing, at + 2 + 2 * 2, 30)           # service 3 before service 2 ends
        cap.packets = [clean, past_end, clean.copy(), decreasing, clean.copy()]
        out = os.path.join(ENV.home, "msp-faults.pcap")
        cap.write(out)
        os.chmod(out, 0o644)
        # the copies repeat one TCP segment: not retransmissions here, each is decoded
        no_seq = ["-o", "tcp.analyze_sequence_numbers:FALSE"]
        rows = fields(ENV, out, ["frame.number", "enipr.cpf.item.cip.msp_reply.reply.service", "_ws.expert.message"],
                      extra=no_seq)
        self.assertEqual(len(rows), 5)
        # every copy is a reply whose request is not in the capture: one note each, besides
        for r in rows:
            messages = r["_ws.expert.message"].split(",") if r["_ws.expert.message"] else []
            self.assertIn(NO_REQUEST_NOTE[len("Expert Info (Note/Sequence): "):], messages, r)
            r["_ws.expert.message"] = ",".join(m for m in messages if not m.startswith("The request of this"))
        expert = [n + 1 for n, r in enumerate(rows) if r["_ws.expert.message"]]
        self.assertEqual(expert, [2, 4], rows)
        flagged = ENV.tshark(["-r", out, "-Y", "enipr.expert.bad_offset", "-T", "fields", "-e", "frame.number"] +
                             no_seq)
        self.assertEqual(flagged.stdout.split(), ["2", "4"])
        self.assertRegex(rows[1]["_ws.expert.message"], r"'Embedded Reply' 5 of 11: offset 32767 \(byte \d+\) is past the end")
        self.assertRegex(rows[3]["_ws.expert.message"], r"'Embedded Reply' 3 of 11: offset 30 \(byte \d+\) is smaller than the one before")
        # the tree so far: the services before the bad offset
        self.assertEqual(rows[0]["enipr.cpf.item.cip.msp_reply.reply.service"], ",".join(["0x03"] * 11))
        self.assertEqual(rows[1]["enipr.cpf.item.cip.msp_reply.reply.service"], ",".join(["0x03"] * 3))
        self.assertEqual(rows[3]["enipr.cpf.item.cip.msp_reply.reply.service"], "0x03")
        verbose = ENV.tshark(["-r", out, "-V"] + no_seq, check=False)
        self.assertEqual(verbose.returncode, 0, verbose.stderr)
        self.assertNotIn("[Malformed Packet", verbose.stdout)


class Corpus(unittest.TestCase):
    """Wireshark's enip/cip (no dissgen plugin) against the rules (default), on real captures."""

    def test_real_captures_agree_with_wireshark(self):
        corpus, files = corpus_files(self)
        start = time.time()
        total = {"enip_frames": 0, "messages_ws": 0, "messages_ours": 0, "fields": 0, "agree": 0, "differ": 0,
                 "experts": 0, "msp_sc": 0, "msp_sc_agree": 0, "msp_class": 0, "msp_class_agree": 0}
        problems, pairing = [], dict.fromkeys(PAIRING_EXPERTS, 0)
        print("\n%-40s %7s %8s %9s %9s %9s" % ("capture", "frames", "msgs ws", "msgs ours", "fields",
                                                "agreeing"), file=sys.stderr)
        for f in files:
            # Read by both tshark users: a copy in ENV's HOME when the corpus is private.
            s = differential(ENV.readable(os.path.join(corpus, f)))
            for k in total:
                total[k] += len(s["frames_differ"]) if k == "differ" else s[k]
            print("%-40s %7d %8d %9d %9d %9d%s" % (f, s["enip_frames"], s["messages_ws"], s["messages_ours"],
                                                   s["fields"], s["agree"],
                                                   "  %d frames differ" % len(s["frames_differ"])
                                                   if s["frames_differ"] else ""), file=sys.stderr)
            for number_, diffs in s["frames_differ"]:
                problems.append("%s frame %d: %s" % (f, number_, "; ".join(diffs)))
            for k in pairing:
                pairing[k] += s["pairing"][k]
        print("%-40s %7d %8d %9d %9d %9d  (%.1f s)" % ("total", total["enip_frames"], total["messages_ws"],
                                                      total["messages_ours"], total["fields"], total["agree"],
                                                      time.time() - start), file=sys.stderr)
        print("embedded services of Multiple Service Packets: %d of %d service codes and %d of %d classes "
              "agree with Wireshark's cip" % (total["msp_sc_agree"], total["msp_sc"], total["msp_class_agree"],
                                              total["msp_class"]), file=sys.stderr)
        self.assertGreater(total["messages_ws"], 0)
        self.assertEqual(problems, [], "\n".join(problems[:40]))
        if "cip-multiple-2.pcap" in files:  # 11 replies in one Multiple Service Packet
            self.assertGreaterEqual(total["msp_sc"], 11)
        self.assertEqual((total["msp_sc_agree"], total["msp_class_agree"]), (total["msp_sc"], total["msp_class"]))
        # Real traffic is well-formed: none of our expert infos fires on it, apart from the
        # pairing's notes: replies whose request is not in the capture (it began before), and
        # replies that came back after a later request's (pipelined requests, and the requests of
        # concurrent sessions and connections: the pairing's order is capture-wide). No request
        # is given up and no message is a duplicate.
        print("pairing notes: %s" % ", ".join("%s %d" % (k.split(".")[-1], v) for k, v in pairing.items()),
              file=sys.stderr)
        self.assertEqual(total["experts"], 0)
        self.assertEqual((pairing["enipr.expert.no_response"], pairing["enipr.expert.duplicate"]), (0, 0))


# Identity object values of CIP replies: Wireshark's cip.id.* field and ours, in the replies
# to Get Attributes All, Get Attribute Single and Get Attribute List (decoded by the request's
# path: request{...} and the pairing).
IDENTITY_FIELDS = (("cip.id.vendor_id", "vendor"), ("cip.id.device_type", "devtype"),
                   ("cip.id.product_code", "prodcode"), ("cip.id.major_rev", "revision.major"),
                   ("cip.id.minor_rev", "revision.minor"), ("cip.id.status", "status"),
                   ("cip.id.serial_number", "serial"), ("cip.id.product_name", "name"))
OUR_IDENTITY = ("enipr.cpf.item.cip.id.", "enipr.cpf.item.cip.id_attr.", "enipr.cpf.item.cip.id_list.attr.value.",
                "enipr.cpf.item.cip.msp_reply.reply.id.", "enipr.cpf.item.cip.msp_reply.reply.id_attr.",
                "enipr.cpf.item.cip.msp_reply.reply.id_list.attr.value.")


def identity_values(capture_path):
    """Per capture and Identity field: Wireshark's values, ours equal to them, different,
    missing; ours in all; how many of Wireshark's are inside Multiple Service Packet replies
    (each decoded by the embedded request at its position: request{...} of a field in a
    repeated node); the differences."""
    theirs_names = [t for t, _ in IDENTITY_FIELDS]
    ours_names = [prefix + o for _, o in IDENTITY_FIELDS for prefix in OUR_IDENTITY]
    theirs = fields(BARE, capture_path, ["frame.number", "cip.service"] + theirs_names)
    ours = fields(ENV, capture_path, ["frame.number"] + ours_names, extra=["-2"])

    def norm(v):
        try:
            return int(v, 0)
        except ValueError:
            return v
    per_field = {t: dict(wireshark=0, equal=0, different=0, missing=0, ours=0, in_msp=0) for t in theirs_names}
    diffs = []
    for t, o in zip(theirs, ours):
        msp = "0x8a" in t["cip.service"].split(",")
        for their_name, our_name in IDENTITY_FIELDS:
            a = [norm(v) for v in t[their_name].split(",") if v]
            b = [norm(v) for prefix in OUR_IDENTITY for v in o[prefix + our_name].split(",") if v]
            c = per_field[their_name]
            c["ours"] += len(b)
            if msp:
                c["in_msp"] += len(a)
            c["wireshark"] += len(a)
            same = sum(1 for x, y in zip(a, b) if x == y)
            c["equal"] += same
            c["different"] += min(len(a), len(b)) - same
            c["missing"] += max(0, len(a) - len(b))
            if same != len(a) or len(a) != len(b):
                diffs.append("frame %s %s: %s, ours %s" % (t["frame.number"], their_name, a, b))
    total = {k: sum(c[k] for c in per_field.values()) for k in next(iter(per_field.values()))}
    return total, per_field, diffs


class IdentityReplies(TsharkTestCase, unittest.TestCase):
    """CIP replies carry no path: ours decode the Identity object's attributes by the
    request's class and attribute (request{...}), value for value as Wireshark's cip does."""

    def test_identity_values_agree_with_wireshark(self):
        corpus, files = corpus_files(self)
        grand = grand_msp = 0
        with self.checks() as check:
            for f in files:
                total, per_field, diffs = identity_values(ENV.readable(os.path.join(corpus, f)))
                grand += total["wireshark"]
                grand_msp += total["in_msp"]
                if not total["wireshark"] and not total["ours"] and not total["in_msp"]:
                    continue
                print("%s: Wireshark's cip.id values %d: ours equal %d, different %d, missing %d; %d of them in "
                      "Multiple Service Packet replies (%s)" % (
                          f, total["wireshark"], total["equal"], total["different"], total["missing"],
                          total["in_msp"], ", ".join("%s %d/%d%s" % (
                              n.split(".")[-1], c["equal"], c["wireshark"], " (%d in MSP)" % c["in_msp"] if c["in_msp"] else "")
                              for n, c in per_field.items() if c["wireshark"] or c["in_msp"])), file=sys.stderr)
                check(total["ours"] == total["equal"], "%s: ours decode no Identity value Wireshark does not" % f)
                check(not diffs, "%s: every Identity value as Wireshark's cip.id.* (%s)"
                      % (f, "; ".join(diffs[:5]) or "%d values" % total["wireshark"]))
            # EIP-RebootorRestart.pcap has Get Attributes All and Get Attribute List replies, and
            # Get Attribute List replies inside Multiple Service Packet replies (as enip_cip_example)
            if "EIP-RebootorRestart.pcap" in files:
                check(grand > 0, "the corpus has Identity values to compare")
                check(grand_msp > 0, "the corpus has Identity values inside Multiple Service Packet replies")


def connected(seq, cip, connection, session=0x11020100):
    """SendUnitData: a Connected Address item and a Connected Data item (sequence count, cip)."""
    return send_data(0x70, [(0x00A1, struct.pack("<I", connection)), (0x00B1, struct.pack("<H", seq) + cip)],
                     session=session)


IDENTITY = bytes.fromhex("20012401")
IDENTITY_ALL = struct.pack("<HHHBBHIB", 1, 0x0C, 58, 4, 3, 0x0030, 0x00524D8E, 11) + b"1756-ENBT/A"


class PipelinedReplies(TsharkTestCase, unittest.TestCase):
    """Connected requests of one session in flight at once, answered in another order: each reply
    finds its request by the session and the CIP sequence count (a key after the CPF headers) and
    is decoded by the class, instance and attribute that request named."""

    def test_replies_decoded_by_their_own_request(self):
        ot, to = 0x80FE0028, 0x00A1B2C3      # the connection's ids, one per direction
        requests = {100: cip_request(0x01, IDENTITY),                                     # Get Attributes All
                    101: cip_request(0x0E, IDENTITY + bytes.fromhex("3007")),             # product name
                    102: cip_request(0x03, IDENTITY, struct.pack("<HHH", 2, 1, 6)),       # vendor, serial
                    103: cip_request(0x01, bytes.fromhex("20022401"))}                    # Message Router
        replies = {101: cip_response(0x0E, data=b"\x0b1756-ENBT/A"),
                   103: cip_response(0x01, data=struct.pack("<HHH", 1, 0x0001, 2)),
                   100: cip_response(0x01, data=IDENTITY_ALL),
                   102: cip_response(0x03, data=struct.pack("<HHHHHHI", 2, 1, 0, 0x0001, 6, 0, 0x00524D8E))}
        out, back = TcpFlow(50040, 44818), TcpFlow(44818, 50040, src=(10, 1, 1, 164), dst=(10, 1, 1, 167))
        # a second apart (the pairing's timeout is 5 s): 100, 101 sent; 101 answered; 102 sent; 100
        # answered; 103 sent and answered; 102 answered
        order = [(out, 100, ot, requests), (out, 101, ot, requests), (back, 101, to, replies),
                 (out, 102, ot, requests), (back, 100, to, replies), (out, 103, ot, requests),
                 (back, 103, to, replies), (back, 102, to, replies)]
        frames = [flow.segment(connected(k, messages[k], conn)) for flow, k, conn, messages in order]
        # and a Get Attribute Single through an Unconnected Send (SendRRData: paired by sender context)
        frames.append(out.segment(unconnected(unconnected_send(cip_request(0x0E, IDENTITY + b"\x30\x03")),
                                              context=b"routed!!")))
        frames.append(back.segment(unconnected(cip_response(0x0E, data=struct.pack("<H", 58)), context=b"routed!!")))
        # a reply whose request is not in the capture: decoded as far as it goes, and said so
        frames.append(back.segment(connected(7, cip_response(0x01, data=IDENTITY_ALL), to)))
        cap = capture("pipelined.pcap", frames)
        c = "enipr.cpf.item.cip."
        names = ["enipr.request_in", c + "identity_request", c + "requested_attribute", c + "id.vendor",
                 c + "id.devtype", c + "id.prodcode", c + "id.revision.major", c + "id.revision.minor",
                 c + "id.status", c + "id.serial", c + "id.name", c + "id_attr.name", c + "id_attr.prodcode",
                 c + "id_list.attr.id", c + "id_list.attr.value.vendor", c + "id_list.attr.value.serial",
                 "enipr.expert.no_request_context"]
        all_ = ["0x0001", "0x000c", "58", "4", "3", "0x0030", "0x00524d8e", "1756-ENBT/A"]
        want = {3: ["2", "1", "7"] + [""] * 8 + ["1756-ENBT/A"] + [""] * 5,
                5: ["1", "1", ""] + all_ + [""] * 6,
                7: ["6", "0"] + [""] * 15,
                8: ["4", "1", ""] + [""] * 10 + ["1,6", "0x0001", "0x00524d8e", ""],
                10: ["9", "1", "3"] + [""] * 9 + ["58"] + [""] * 4,
                11: ["", "", ""] + [""] * 13 + ["1"]}
        with self.checks() as check:
            for two_pass in (False, True):
                rows = fields(ENV, cap, names, extra=["-2"] if two_pass else [])
                for frame, values in want.items():
                    got = [rows[frame - 1][n] for n in names]
                    check(got == values, "%s: frame %d as its request says: %s" % (
                        "-2" if two_pass else "one pass", frame,
                        "ok" if got == values else "%s, want %s" % (got, values)))
                # order="any": replies in another order than their requests are neither out of
                # order nor do they leave a request unanswered
                flagged = fields(ENV, cap, ["frame.number", "enipr.expert.out_of_order", "enipr.expert.no_response"],
                                 extra=["-2"] if two_pass else [])
                flagged = [r["frame.number"] for r in flagged
                           if r["enipr.expert.out_of_order"] or r["enipr.expert.no_response"]]
                check(not flagged, "%s: no reply out of order, no request unanswered (order=\"any\"): %s" % (
                    "-2" if two_pass else "one pass", flagged or "none"))


def corpus_dir():
    return ARGS.corpus or os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus", "enip")


def corpus_files(test):
    """The corpus folder and its captures; skips `test` when there are none."""
    corpus = corpus_dir()
    files = sorted(f for f in os.listdir(corpus) if f.endswith((".pcap", ".pcapng"))) \
        if os.path.isdir(corpus) else []
    if not files:
        test.skipTest("no EtherNet/IP corpus at %s" % corpus)
    return corpus, files


def setUpModule():
    global ENV, BARE
    ENV, BARE = TsharkEnv(prefix="dissgen-enip-"), TsharkEnv(prefix="dissgen-enip-ws-")
    # Wireshark's side loads no plugin at all (an empty WIRESHARK_PLUGIN_DIR; tshark runs as an
    # ordinary user), so not even a dissgen plugin in the global folder (the .deb installs
    # dissgen-packaged-enip.so there) can take TCP 44818 from Wireshark's enip. enip and cip are
    # built into libwireshark.
    empty = os.path.join(BARE.home, "no-plugins")
    os.makedirs(os.path.join(empty, BARE.abi, "epan"))
    subprocess.run(["chmod", "-R", "a+rX", empty], check=True)
    base_env = BARE.env
    BARE.env = lambda: dict(base_env(), WIRESHARK_PLUGIN_DIR=empty)
    try:
        for rules in ("enip.xml", "ethercat.xml"):
            ENV.install_plugin(ARGS.dissgen, os.path.join(ARGS.source_dir, "rules", rules))
    except BaseException:
        tearDownModule()
        raise


def tearDownModule():
    ENV.cleanup()
    BARE.cleanup()


def main():
    args, status = run_unittests(lambda parser: parser.add_argument(
        "--corpus", help="EtherNet/IP captures (default: <source-dir>/../shared/corpus/enip)"))
    if status == 0 and not os.path.isdir(corpus_dir()):
        print("SKIPPED: no EtherNet/IP corpus at %s; the differential on real captures did not run "
              "(every other test passed)" % corpus_dir())
        return SKIP_CODE
    return status


if __name__ == "__main__":
    sys.exit(main())

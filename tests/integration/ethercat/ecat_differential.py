#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Differential test: dissgen's EtherCAT plugin (ecatr) against Wireshark's own plugin
(ecatf/ecat) and against the bytes' ground truth.  Python 3 stdlib only.

  ecat_differential.py --dissgen build/bin/dissgen --source-dir . [--frames 3000] [--seed 1]
  ecat_differential.py --dissgen build/bin/dissgen --source-dir . --corpus /work/shared/corpus/ethercat

Generated mode writes N varied frames (pcapgen.py) in one capture; corpus mode reads every
*.pcap/*.pcapng of DIR in place (exit 77 with "SKIPPED: ..." when DIR is missing).  Each
capture is decoded by tshark twice, once per side, in a throw-away HOME holding our plugin:
  ours:      tshark -r CAP -T fields -E occurrence=a -E aggregator=, -e ecatr.* ...
  Wireshark: tshark -r CAP -T json -J "ecatf ecat" -d ethertype==0x88a4,ecatf -d udp.port==34980,ecatf
and every field is compared frame by frame, datagram by datagram, with:
  truth  the ecatr contract applied to the captured bytes (pcapgen.decode_ecat; for generated
         frames also checked against the values the generator wrote)
  model  what Wireshark's plugin is known to show for those bytes (ws_model below): it ignores
         the header's Length, so with M=1 on the last datagram it reads the padding as one more
         datagram; it drops a datagram that is cut short (no partial tree) and the whole tree
         when a datagram header or a lone datagram is cut; it shows no Data for zero-length
         datagrams and where it decodes ESC registers (register space, incl. reads with WKC 0
         where it shows nothing) or DC receive times, only the bytes after a mailbox header
         for mailbox datagrams, and nothing more of a frame once its mailbox sub-dissector throws.
A value where ours and Wireshark differ is "explained" only when ours equals the truth and
Wireshark equals the model; ours must equal the truth everywhere.  A frame fails on any
unexplained difference or any difference from the truth.  Last line: "N passed, M failed".
"""

import argparse
import glob
import io
import json
import os
import re
import struct
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from collections import OrderedDict, defaultdict

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
sys.dont_write_bytecode = True      # no __pycache__ in the source tree
import pcapgen  # noqa: E402
import ecat_deep  # noqa: E402
from pcapgen import Partial, is_logical  # noqa: E402
import tshark_env  # noqa: E402

SKIP_CODE = 77

# key, scope, ours field, Wireshark field, kind
FIELDS = [
    ("length", "header", "ecatr.header.length", "ecatf.length", "int"),
    ("reserved", "header", "ecatr.header.reserved", "ecatf.reserved", "int"),
    ("type", "header", "ecatr.header.type", "ecatf.type", "int"),
    ("cmd", "dg", "ecatr.datagram.cmd", "ecat.cmd", "int"),
    ("idx", "dg", "ecatr.datagram.idx", "ecat.idx", "int"),
    ("adp", "dg", "ecatr.datagram.adp", "ecat.adp", "int"),
    ("ado", "dg", "ecatr.datagram.ado", "ecat.ado", "int"),
    ("lad", "dg", "ecatr.datagram.lad", "ecat.lad", "int"),
    ("len", "dg", "ecatr.datagram.len", "ecat.subframe.length", "int"),
    ("reserved", "dg", "ecatr.datagram.reserved", "ecat.subframe.reserved", "int"),
    ("circulating", "dg", "ecatr.datagram.circulating", "ecat.subframe.circulating", "bool"),
    ("more", "dg", "ecatr.datagram.more", "ecat.subframe.more", "bool"),
    ("irq", "dg", "ecatr.datagram.irq", "ecat.int", "int"),
    ("data", "dg", "ecatr.datagram.data", "ecat.data", "bytes"),
    ("wkc", "dg", "ecatr.datagram.wkc", "ecat.cnt", "int"),
    # The data of a read no slave answered (WKC 0): Wireshark has no such field.
    ("unread", "dg", "ecatr.datagram.unread", None, "bytes"),
]
HEADER_KEYS = [f[0] for f in FIELDS if f[1] == "header"]
DG_KEYS = [f[0] for f in FIELDS if f[1] == "dg"]
KIND = {(f[1], f[0]): f[4] for f in FIELDS}
WS_DG_FIELD = {f[3]: f[0] for f in FIELDS if f[1] == "dg" and f[3]}
WS_HDR_FIELD = {f[3]: f[0] for f in FIELDS if f[1] == "header"}
# Fields that only exist for some commands (the others are one per datagram).
ONLY_FOR = {"adp": lambda c: not is_logical(c), "ado": lambda c: not is_logical(c),
            "lad": is_logical}

WS_DECODE_AS = ["-d", "ethertype==0x88a4,ecatf", "-d", "udp.port==34980,ecatf"]

# True when rules/ethercat.xml decodes the data (registers, mailboxes): set by prepare_env from
# `dissgen fields`; the datagram's Data field is then shown only where nothing decodes it.
DEEP = False
REG_VIEW_CMDS = (1, 2, 3, 4, 5, 6, 7, 8, 9, 13, 14)


def shown_fields():
    """FIELDS that our plugin has (ecatr.datagram.unread only in rules that decode the data)."""
    return [f for f in FIELDS if DEEP or f[0] != "unread"]


def ours_view(d):
    """Which alternative of the datagram's data rules/ethercat.xml decodes: "unread" (a read with
    WKC 0), "reg" (physical/broadcast below 0x1000), "mbx" (APRD..FPRW at 0x1000 and above, at
    least 6 bytes) or "data" (everything else)."""
    if not DEEP:
        return "data"
    cmd, n, ado, wkc = d.get("cmd"), d.get("len"), d.get("ado"), d.get("wkc")
    if not isinstance(n, int) or not isinstance(cmd, int):
        return "data"
    if cmd in (1, 4, 7) and n >= 1 and wkc == 0:
        return "unread"
    if isinstance(ado, int) and cmd in REG_VIEW_CMDS and ado < 0x1000 and n >= 1:
        return "reg"
    if isinstance(ado, int) and 1 <= cmd <= 6 and ado >= 0x1000 and n >= 6:
        return "mbx"
    return "data"


def _u16(b, o):
    return struct.unpack_from("<H", b, o)[0] if o + 2 <= len(b) else 0


def mailbox_fault(data):
    """True when rules/ethercat.xml meets a fault inside this mailbox (a length past the end of
    the datagram's data, or fixed fields that do not fit the mailbox length): by the project's
    Mailbox is malformed="skip": ours shows the mailbox's tree so far with an expert info, then
    the datagram's WKC and the later datagrams.  Mirrors the rules' alternatives, for any bytes."""
    n = len(data)
    mlen, typ = _u16(data, 0), data[5] & 0x0F
    if mlen > n - 6:
        return True                 # every content alternative has the mailbox Length
    c = data[6:6 + mlen]
    need = 0

    def fits(k):
        nonlocal need
        need += k
        return need <= mlen
    if typ == 0:
        return not fits(4)
    if typ == 2:
        if not fits(4):
            return True
        ft = c[0] & 0x0F
        if ft == 1:
            return not fits(4)
        if ft in (2, 7):
            return not fits(4 + 6 + 16 + 32)
        if ft in (4, 9):
            if not fits(2):
                return True
            w = _u16(c, 4)
            return not fits(6 * ((w >> 12) & 0x0F) + 6 * ((w >> 10) & 3))
        return False
    if typ == 3:
        if not fits(2):
            return True
        svc = _u16(c, 0) >> 12
        if svc == 1:
            return not fits(8)
        if svc in (2, 3):
            if not fits(1):
                return True
            cs = c[2] >> 5
            init = 1 if svc == 2 else 2
            if cs in ((1, 2, 4) if svc == 2 else (2, 3, 4)) and not fits(3):
                return True
            if cs == init or cs == 4:
                return not fits(4)
            return False
        if svc == 8:
            if not fits(4):
                return True
            op = c[2] & 0x7F
            if (op == 1 and not fits(2)) or (3 <= op <= 6 and not fits(2)):
                return True
            if op == 4:
                return not fits(4)
            if op in (5, 6):
                return not fits(2 + (6 if op == 6 else 0))
            if op == 7:
                return not fits(4)
        return False
    if typ == 4:
        if not fits(2):
            return True
        return c[0] in (1, 2, 3, 4, 5, 6) and not fits(4)
    if typ == 5:
        if not fits(4):
            return True
        return bool(c[0] & 0x10) and not fits(2)
    if typ == 15:
        return not fits(6)
    return False


STOP_WHY = ("ours-stops-in-mailbox: a length in this mailbox overruns its data; ours shows the mailbox's tree "
            "so far with an expert info (and goes on after it), Wireshark decodes on in its subset buffer")


def mailbox_faults(exp):
    """Indexes of the datagrams whose mailbox ours stops decoding inside (then skips)."""
    return [i for i, d in enumerate(exp["datagrams"])
            if isinstance(d.get("data"), bytes) and ours_view(d) == "mbx" and mailbox_fault(d["data"])]


VIEW_WHY = {
    "reg": "ours-registers: ours decodes these bytes as ESC registers (ecatr.datagram.reg), "
           "Wireshark shows them raw (no register of its table lies wholly inside, or it ends at 0x09FF)",
    "mbx": "ours-mailbox: ours decodes these bytes as a mailbox (ecatr.datagram.mbx); Wireshark "
           "shows raw data for mailbox types outside 1-5, lengths above 1500 or reads with WKC above 1",
    "unread": "ours-unread: ours shows the data of a read no slave answered as ecatr.datagram.unread",
}


class _Missing:
    def __repr__(self):
        return "-"


MISSING = _Missing()


# --------------------------------------------------------------------------- value parsing

class ReprError(ValueError):
    pass


_INT_RE = re.compile(r"0[xX][0-9a-fA-F]+|[0-9]+")
_HEX2 = re.compile(r"[0-9a-fA-F]{2}")
_BOOLS = {"1": True, "True": True, "true": True, "TRUE": True,
          "0": False, "False": False, "false": False, "FALSE": False}


def parse_value(kind, s):
    """tshark text -> Python value; representation differences are normalised here and only
    here ("0x0010" == "16", "1" == "True", "01:02" == "01 02" == "0102", "<MISSING>" == b"");
    anything else is an error."""
    s = s.strip()
    if kind == "int":
        if not _INT_RE.fullmatch(s):
            raise ReprError("not an integer: %r" % s)
        return int(s, 16) if s[:2] in ("0x", "0X") else int(s)
    if kind == "bool":
        try:
            return _BOOLS[s]
        except KeyError:
            raise ReprError("not a boolean: %r" % s) from None
    if kind == "bytes":
        if s == "<MISSING>":        # how tshark -T fields prints a zero-length FT_BYTES item
            return b""
        # hex pairs, either run together or all separated by one of ':' ' ' '-' '.'
        for sep in ":- .":
            if sep in s:
                parts = s.split(sep)
                break
        else:
            parts = [s[k:k + 2] for k in range(0, len(s), 2)]
        if s and not all(len(p) == 2 and _HEX2.fullmatch(p) for p in parts):
            raise ReprError("not bytes: %r" % (s if len(s) < 80 else s[:80] + "..."))
        return bytes.fromhex("".join(parts))
    raise AssertionError(kind)


def shown(v):
    if v is MISSING:
        return "(absent)"
    if isinstance(v, Partial):
        return "(absent, or the %d bytes present: %s)" % (len(v.value), short_hex(v.value))
    if isinstance(v, bytes):
        return short_hex(v)
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, int):
        return "%d (0x%x)" % (v, v)
    if isinstance(v, ReprError):
        return "unparsable %s" % v
    return repr(v)


def short_hex(b, limit=48):
    h = b.hex()
    if len(b) > limit:
        return "%s...(%d bytes)" % (h[:limit * 2], len(b))
    return h if h else "(empty)"


# --------------------------------------------------------------------------- our side

def ours_command(cap, fieldset):
    # quote=d: a field that is there is printed in quotes, one that is not as nothing (a
    # zero-length FT_BYTES item prints as <MISSING>).
    args = ["-r", cap, "-T", "fields", "-E", "header=n", "-E", "separator=/t", "-E", "quote=d",
            "-E", "occurrence=a", "-E", "aggregator=,", "-e", "frame.number"]
    for f in shown_fields():
        args += ["-e", f[2] if fieldset == "ecatr" else f[3]]
    return args


def parse_ours(text, expected_by_frame):
    """-T fields lines -> {frame: {"header": {k: v}, "datagrams": [ {k: v} ], "problems": [..]}}.
    Values of one field are given to the datagrams in order (adp/ado only to non-logical
    commands, lad only to logical ones); surplus values are a problem of the frame."""
    result = {}
    for line in text.splitlines():
        cols = line.split("\t")
        if len(cols) != len(shown_fields()) + 1:
            raise RuntimeError("unexpected -T fields line: %r" % line[:200])
        num = int(cols[0].strip('"'))
        cols = cols[1:]
        if not any(cols):
            continue
        exp = expected_by_frame.get(num)
        rec = {"header": {}, "datagrams": [], "problems": []}
        lists = {}
        for (key, scope, _, _, kind), col in zip(shown_fields(), cols):
            if col == "":
                raw = []
            elif len(col) >= 2 and col[0] == col[-1] == '"':
                raw = col[1:-1].split(",")
            else:
                raise RuntimeError("frame %d: unquoted -T fields value %r" % (num, col[:80]))
            vals = []
            for r in raw:
                try:
                    vals.append(parse_value(kind, r))
                except ReprError as e:
                    vals.append(e)
            lists[(scope, key)] = vals
        for key in HEADER_KEYS:
            v = lists[("header", key)]
            if len(v) > 1:
                rec["problems"].append("%d values of header %s" % (len(v), key))
            rec["header"][key] = v[0] if v else MISSING
        cmds = lists[("dg", "cmd")]
        rec["datagrams"] = [{"cmd": c} for c in cmds]
        for key in DG_KEYS:
            if key == "cmd":
                continue
            vals = lists.get(("dg", key), [])
            pred = ONLY_FOR.get(key, lambda c: True)
            idx = [i for i, d in enumerate(rec["datagrams"])
                   if not isinstance(d["cmd"], ReprError) and pred(d["cmd"])]
            targets = [rec["datagrams"][i] for i in idx]
            if key in ("data", "unread"):
                # The contract: a zero-length Data field adds no item (as in Wireshark's plugin),
                # so the values belong to the datagrams whose Length is not 0; with decoded data,
                # Data is shown only where nothing decodes it and Unread only for reads with WKC 0.
                edg = exp["datagrams"] if exp else []
                idx = [i for i in idx if rec["datagrams"][i].get("len") != 0 and
                       (ours_view(edg[i]) if i < len(edg) else "data") == key]
                targets = [rec["datagrams"][i] for i in idx]
            for d, v in zip(targets, vals):
                d[key] = v
            if len(vals) > len(targets):
                rec["problems"].append("%s: %d values for %d datagrams that can have it (%s)" %
                                       (FIELDS_BY_KEY[key][2], len(vals), len(targets),
                                        ",".join(shown(v) for v in vals[len(targets):])[:200]))
        result[num] = rec
    return result


FIELDS_BY_KEY = {f[0]: f for f in FIELDS if f[1] == "dg"}

# How tshark -T fields prints each ecatr field (used only by --simulate perfect).
_FMT = {("header", "length"): "%d", ("header", "reserved"): "%d", ("header", "type"): "%d",
        ("dg", "cmd"): "0x%02x", ("dg", "idx"): "0x%02x", ("dg", "adp"): "0x%04x", ("dg", "ado"): "0x%04x",
        ("dg", "lad"): "0x%08x", ("dg", "len"): "%d", ("dg", "reserved"): "%d", ("dg", "irq"): "0x%04x",
        ("dg", "wkc"): "%d"}


def perfect_fields_text(expected, nframes):
    """-T fields output of an ideal ecatr plugin (the truth; a cut data field left out)."""
    lines = []
    for num in range(1, nframes + 1):
        e = expected.get(num)
        cols = ['"%d"' % num]
        for key, scope, _, _, kind in shown_fields():
            if e is None or e["header"] is None:
                vals = []
            elif scope == "header":
                vals = [e["header"][key]]
            else:
                vals = [d[key] for d in e["datagrams"] if key in d and not isinstance(d[key], Partial)]
            out = []
            for v in vals:
                if kind == "bool":
                    out.append("1" if v else "0")
                elif kind == "bytes":
                    out.append(v.hex() if v else "<MISSING>")
                else:
                    out.append(_FMT[(scope, key)] % v)
            cols.append('"%s"' % ",".join(out) if out else "")
        lines.append("\t".join(cols))
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- Wireshark side

def ws_command(cap):
    # -x: every field's position and length ("_raw"), for the register and mailbox comparison
    return ["-r", cap, "-T", "json", "-x", "-J", "ecatf ecat ecat_mailbox"] + WS_DECODE_AS


def ours_deep_command(cap):
    return ["-r", cap, "-T", "json", "-x", "-J", "ecatr"]


class _Obj(list):
    """A JSON object as its (key, value) pairs: tshark repeats keys (two datagrams with the
    same summary text), which a dict would merge."""


def _pairs(v):
    return v if isinstance(v, _Obj) else None


def parse_ws_json(path):
    """tshark -T json -> [ {"header": {..}, "datagrams": [ {k: v} ], "malformed": bool} ] (one per
    packet, in order).  Only the datagram subtree itself, its Header and the Length subtree are
    read (no mailbox/EoE contents)."""
    pkts = json.loads(tshark_env.read_tshark_output(path), object_pairs_hook=_Obj)
    out = []
    for pk in pkts:
        src = dict(pk)["_source"]
        layers = dict(src)["layers"]
        rec = {"header": {}, "datagrams": [], "malformed": False, "has_ecat": False}
        ecatf = ecat = None
        for k, v in layers:
            if k == "ecatf" and ecatf is None:
                ecatf = v
            elif k == "ecat" and ecat is None:
                ecat = v
            elif k.startswith("_ws.malformed") or k.startswith("_ws.short"):
                rec["malformed"] = True
        if ecatf is not None:
            for k, v in ecatf:
                if k in WS_HDR_FIELD:
                    rec["header"][WS_HDR_FIELD[k]] = _parse_or_err("int", v)
        if ecat is not None:
            rec["has_ecat"] = True
            for k, v in ecat:
                if k.startswith("_ws.malformed") or k.startswith("_ws.short"):
                    rec["malformed"] = True
                sub = _pairs(v)
                if sub is None or not k.startswith("EtherCAT datagram"):
                    continue
                d = {}
                for k2, v2 in sub:
                    if k2 == "Header" and _pairs(v2) is not None:
                        for k3, v3 in v2:
                            if k3.startswith("Length") and _pairs(v3) is not None:
                                for k4, v4 in v3:
                                    if k4 in WS_DG_FIELD:
                                        key = WS_DG_FIELD[k4]
                                        d[key] = _parse_or_err(KIND[("dg", key)], v4)
                            elif k3 in WS_DG_FIELD:
                                key = WS_DG_FIELD[k3]
                                d[key] = _parse_or_err(KIND[("dg", key)], v3)
                    elif k2 in WS_DG_FIELD:
                        key = WS_DG_FIELD[k2]
                        d[key] = _parse_or_err(KIND[("dg", key)], v2)
                    elif k2.startswith("_ws.malformed"):
                        rec["malformed"] = True
                rec["datagrams"].append(d)
        out.append(rec)
    return out


def _parse_or_err(kind, v):
    if not isinstance(v, str):
        return ReprError("not a value: %r" % (v,))
    try:
        return parse_value(kind, v)
    except ReprError as e:
        return e


# --------------------------------------------------------------------------- Wireshark model

REGISTER_CMDS = (1, 2, 3, 4, 5, 6, 7, 8, 9, 13, 14)     # commands whose data Wireshark matches
READ_CMDS = (1, 4, 7)                                     # against its ESC register table
MAILBOX_TYPES = (1, 2, 3, 4, 5)                           # AoE, EoE, CoE, FoE, SoE
ESC_REGISTER_END = 0x0A00       # Wireshark's register table ends below this offset


class OneOf:
    """The model allows any of these (each with the reason it differs from the truth)."""
    def __init__(self, *options):
        self.options = options      # (value, reason) pairs

    def __repr__(self):
        return "OneOf%r" % (self.options,)


def ws_model(payload):
    """What Wireshark 4.0's ecatf/ecat plugin shows for an EtherCAT payload (as captured).
    Returns {"header": {..} or None, "datagrams": [ {key: value | MISSING | OneOf} ],
             "why": {(index, key): reason}, "note": [..], "dropped_why": reason, "mailboxes": [..]}."""
    res = {"header": None, "datagrams": [], "why": {}, "note": [], "dropped_why": None,
           "mailboxes": []}
    if len(payload) < 2:
        return res
    h = struct.unpack("<H", payload[:2])[0]
    res["header"] = {"length": h & 0x7FF, "reserved": (h >> 11) & 1, "type": h >> 12}
    if h >> 12 != 1:
        return res
    tvb = payload[2:]
    L = len(tvb)

    def hdr_at(off):
        if off + 10 > L:
            return None
        cmd, idx, addr, lw, irq = struct.unpack("<BBIHH", tvb[off:off + 10])
        return cmd, idx, addr, lw, irq

    # 1. Wireshark first walks the chain of datagram headers (M bit) over the whole buffer,
    #    padding included; a header cut short there throws before any tree is made.
    off = 0
    chain = []
    while True:
        hd = hdr_at(off)
        if hd is None:
            res["note"].append("ws: datagram header cut short while counting -> no ecat tree")
            res["dropped_why"] = ("ws-no-tree: a datagram header in the M chain (Length ignored, padding "
                                  "included) is cut short, Wireshark shows no datagram at all")
            return res
        chain.append(off)
        off += 12 + (hd[3] & 0x7FF)
        if not (off < L and hd[3] & 0x8000):
            break
    # 2. A single datagram: its working counter is read for the Info column.
    if len(chain) == 1:
        hd = hdr_at(0)
        if 12 + (hd[3] & 0x7FF) > L:
            res["note"].append("ws: lone datagram cut short -> no ecat tree")
            res["dropped_why"] = "ws-no-tree: the only datagram is cut short, Wireshark shows no datagram at all"
            return res
    # 3. Each datagram's working counter is read before anything of it is shown: a datagram
    #    cut short is not shown at all and ends the dissection.
    for i, off in enumerate(chain):
        cmd, idx, addr, lw, irq = hdr_at(off)
        n = lw & 0x7FF
        if off + 12 + n > L:
            res["note"].append("ws: datagram %d cut short -> not shown (no partial tree)" % (i + 1))
            res["dropped_why"] = "ws-truncated: datagram cut short, Wireshark shows no partial tree"
            break
        data = tvb[off + 10:off + 10 + n]
        wkc = struct.unpack("<H", tvb[off + 10 + n:off + 12 + n])[0]
        d = {"cmd": cmd, "idx": idx}
        if is_logical(cmd):
            d["lad"] = addr
        else:
            d["adp"] = addr & 0xFFFF
            d["ado"] = addr >> 16
        d.update({"len": n, "reserved": (lw >> 11) & 7, "circulating": bool(lw & 0x4000),
                  "more": bool(lw & 0x8000), "irq": irq, "wkc": wkc})
        ado = addr >> 16
        if cmd in (1, 4) and ado == 0x0900 and lw >= 16 and wkc > 0:
            d["data"] = MISSING
            res["why"][(i, "data")] = "ws-dc-view: APRD/FPRD of DC receive times (0x900) shows a 'Dc' subtree, no Data"
            if off + 10 + 16 > L:      # it reads 16 bytes of receive times whatever the length
                res["note"].append("ws: DC receive times read past the end -> datagram header only")
                del d["wkc"]
                res["datagrams"].append(d)
                res["dropped_why"] = "ws-dc-view: reading 16 bytes of DC receive times ran past the end"
                res["why"][(i, "wkc")] = res["dropped_why"]
                break
        elif n == 0:
            d["data"] = MISSING
            res["why"][(i, "data")] = "ws-no-empty-data: Wireshark adds no Data item for a zero-length datagram"
        elif cmd in REGISTER_CMDS and ado < ESC_REGISTER_END:
            if cmd in READ_CMDS and wkc == 0:
                why = "ws-register-read-wkc0: register read with WKC 0, Wireshark drops the data"
            else:
                why = "ws-register-view: ESC register fields shown instead of Data"
            d["data"] = OneOf((data, None), (MISSING, why))
        else:
            d["data"] = data
            if n >= 6 and ado >= 0x1000 and (cmd in (2, 3, 5, 6) or (cmd in (1, 4) and wkc == 1)):
                mlen = struct.unpack("<H", data[:2])[0]
                mtype = data[5] & 0x0F
                if mtype in MAILBOX_TYPES and mlen <= 1500:
                    rest = data[min(mlen + 6, n):]
                    d["data"] = rest if rest else MISSING
                    res["why"][(i, "data")] = ("ws-mailbox: mailbox header (type %d, length %d) decoded as a "
                                               "mailbox, Data is only the %d bytes after it" % (mtype, mlen, len(rest)))
                    res["mailboxes"].append(i)
        res["datagrams"].append(d)
    return res


def model_after_mailbox_exception(model, ws):
    """Wireshark's mailbox sub-dissector throws on some mailbox contents (too short for the
    service it names); the exception ends the whole EtherCAT dissection: that datagram loses
    Data and WKC, the following datagrams are not shown, and the packet is marked malformed.
    The model cannot foresee the sub-dissector, so when Wireshark marks the packet malformed
    and stops right at a mailbox datagram, the model is cut there."""
    if not ws.get("malformed"):
        return model
    for k in model["mailboxes"]:
        if k < len(ws["datagrams"]) and "wkc" not in ws["datagrams"][k] and len(ws["datagrams"]) == k + 1:
            why = ("ws-mailbox-exception: Wireshark's mailbox sub-dissector threw on datagram %d's mailbox, "
                   "the rest of the frame is not shown" % (k + 1))
            m = dict(model)
            m["datagrams"] = [dict(d) for d in model["datagrams"][:k + 1]]
            m["why"] = dict(model["why"])
            for key in ("data", "wkc"):
                m["datagrams"][k][key] = MISSING
                m["why"][(k, key)] = why
            m["dropped_why"] = why
            m["note"] = model["note"] + ["ws: mailbox sub-dissector exception"]
            return m
    return model


def model_matches(pred, val):
    """(ok, reason) for a Wireshark value against the model's prediction."""
    if isinstance(pred, OneOf):
        for v, why in pred.options:
            if v == val:
                return True, why
        return False, None
    return pred == val, None


# --------------------------------------------------------------------------- ours: items, Info, experts

OUR_EXPERTS = ("truncated", "past_end", "more_no_data", "count_short", "bad_length", "unused")
DG_FIXED = [("Command", 1), ("Index", 1)]


def ours_shows(payload, on_wire=None):
    """What the bytes imply ecatr shows besides the field values, by rules/ethercat.xml and
    the runtime's rules (docs/manual.md): the number of ecatr.datagram items, the Info column, and
    the expert infos as (filter name, offset in the EtherCAT payload, message) in tree order,
    and the regions (start, end, container, ours stops inside) of datagram data where ours reports what the rules
    inside find (registers, mailboxes: the Wireshark comparison checks those; container None:
    a faulty mailbox, where ours stops with an expert info of its own), and the ecatr.padding
    value (hex; "" when none): zeros after the datagrams, up to the header's Length.
    on_wire: the payload's length on the wire, when the capture kept less (a snapshot length):
    what runs out at the kept end but was on the wire is no expert info (docs/manual.md,
    "Malformed packets"); decoding stops there."""
    experts, summaries, regions = [], [], []
    size = len(payload)

    def cut(data_end, needed_end):
        """The data ran out only because the capture kept less than the wire had."""
        return on_wire is not None and data_end >= size and size < on_wire and needed_end <= on_wire

    told_end = 0  # the header's Length, once reported past the end of the bytes

    def told(data_end, needed_end):
        """Not reported: the capture's cut, or bytes the header's Length already said are missing."""
        return cut(data_end, needed_end) or (data_end >= size and needed_end <= told_end)

    if size < 2:
        if not cut(size, 2):
            experts.append(("truncated", 0, "Truncated: 'Length' needs 2 bytes, only %d left" % size))
        return 0, "EtherCAT", experts, regions, ""
    h = struct.unpack("<H", payload[:2])[0]
    length, ftype = h & 0x7FF, h >> 12
    name = "Datagrams" if ftype == 1 else "Payload"
    past_end = length > size - 2
    if past_end and not cut(size, 2 + length):
        experts.append(("past_end", 2, "'%s' has length %d, past the end of its data (%d bytes left)"
                        % (name, length, size - 2)))
    if past_end:
        told_end = 2 + length
    if ftype != 1:
        return 0, "EtherCAT", experts, regions, ""
    end = size if past_end else 2 + length
    off, items, stopped = 2, 0, False

    def leaf(what, n):
        nonlocal off, stopped
        if n > end - off:
            if not told(end, off + n):
                experts.append(("truncated", off, "Truncated: '%s' needs %d bytes, only %d left" % (what, n, end - off)))
            stopped = True
            return None
        v = payload[off:off + n]
        off += n
        return v

    while True:
        items += 1
        shown = {"cmd": "-", "address": "", "len": "-"}
        more = False
        v = leaf("Command", 1)
        if v is not None:
            cmd, ado = v[0], None
            shown["cmd"] = pcapgen.CMD_NAMES.get(cmd, "Unknown (0x%02x)" % cmd)
            parts = [("Index", 1)] + ([("Logical address", 4)] if is_logical(cmd) else
                                      [("Slave address (ADP)", 2), ("Offset address (ADO)", 2)])
            parts += [("Length", 2), ("Interrupt", 2)]
            for what, n in parts:
                if what == "Slave address (ADP)":
                    shown["address"] = " -:-"      # the Address container is entered: "-" for what is missing
                v = leaf(what, n)
                if v is None:
                    break
                if what == "Logical address":
                    shown["address"] = " 0x%08x" % struct.unpack("<I", v)[0]
                elif what == "Slave address (ADP)":
                    shown["address"] = " 0x%04x:-" % struct.unpack("<H", v)[0]
                elif what == "Offset address (ADO)":
                    ado = struct.unpack("<H", v)[0]
                    shown["address"] = shown["address"][:-1] + "0x%04x" % ado
                elif what == "Length":
                    w = struct.unpack("<H", v)[0]
                    dlen, more = w & 0x7FF, bool(w & 0x8000)
                    shown["len"] = "%d" % dlen
            if not stopped:
                wkc = struct.unpack_from("<H", payload, off + dlen)[0] if dlen + 2 <= end - off else None
                view = ours_view({"cmd": cmd, "len": dlen, "ado": ado, "wkc": wkc})
                if cmd in (1, 4, 7) and 1 <= dlen <= 2047 and wkc is None and cut(end, off + dlen + 2):
                    # the rules' look-ahead at the working counter (a read answered or not) reads
                    # bytes the capture did not keep: no alternative is taken, decoding stops
                    stopped = True
                elif dlen > end - off:
                    if not told(end, off + dlen):
                        experts.append(("past_end", off, "'%s' has length %d, past the end of its data (%d bytes left)"
                                        % (DATA_CONTAINERS[view], dlen, end - off)))
                    regions.append((off, end, DATA_CONTAINERS[view], True))
                    stopped = True
                else:
                    if view == "mbx" and mailbox_fault(payload[off:off + dlen]):
                        regions.append((off, off + dlen, None, True))    # malformed="skip"
                    elif view != "data":
                        regions.append((off, off + dlen, DATA_CONTAINERS[view], False))
                    off += dlen
                    leaf("Working counter", 2)
        summaries.append("%s%s len %s" % (shown["cmd"], shown["address"], shown["len"]))
        if stopped or not more:
            break
        if off >= end:
            if not told(end, end + 1):
                experts.append(("more_no_data", off, "'Datagram': the repeat flag 'More' says another follows, "
                                "but no data is left"))
            break
    padding = ""
    if not stopped and not past_end and off < end:
        if any(payload[off:end]):
            experts.append(("unused", off, "'Datagrams' is %d bytes, but its fields end after %d: %d bytes are not "
                            "decoded" % (length, off - 2, end - off)))
        else:       # zeros up to the header's Length: padding, no expert info
            padding = payload[off:end].hex()
    if len(summaries) > 1:
        info = "Datagram \u00d7%d: %s" % (len(summaries), ", ".join(summaries))
    else:
        info = summaries[0]
    return items, info, experts, regions, padding


# The container rules/ethercat.xml decodes a datagram's data as, by ours_view().
DATA_CONTAINERS = {"unread": "Not read (working counter 0)", "reg": "Registers", "mbx": "Mailbox", "data": "Data"}


def inside_data(experts, regions):
    """(our expert infos outside the data regions, problems): the data container's own "has
    length ... past the end" stays; those inside are the rules' (checked against Wireshark's
    values), but a faulty mailbox must have at least one."""
    kept, problems = [], []
    for s, t, container, stops in regions:
        # Where ours stops (a faulty mailbox, data past the end), its expert may sit at the end
        # (not the working counter's, which follows a skipped mailbox).
        inside = [e for e in experts if (s <= e[1] < t or stops and e[1] == t and "'Working counter'" not in e[2]) and
                  not (container and e[1] == s and e[2].startswith("'%s' has length" % container))]
        if container is None and not inside:
            problems.append("ours: no expert info inside the faulty mailbox at %d..%d" % (s, t))
        experts = [e for e in experts if e not in inside]
    return experts, problems


def extras_command(cap):
    return ["-r", cap, "-T", "fields", "-E", "header=n", "-E", "separator=/t", "-E", "quote=d",
            "-E", "occurrence=a", "-E", "aggregator=,", "-e", "frame.number", "-e", "ecatr.datagram",
            "-e", "_ws.col.Info", "-e", "ecatr.padding"]


def experts_command(cap):
    """PDML of the frames with an expert info of ours: the only output that gives its position."""
    return ["-r", cap, "-T", "pdml", "-Y", " || ".join("ecatr.expert." + e for e in OUR_EXPERTS)]


def parse_extras(text, pdml_path):
    """-> {frame: {"items": n, "info": text, "padding": hex, "experts": [(name, offset, message)]}}"""
    out = {}
    for line in text.splitlines():
        num, dgs, info, padding = [c[1:-1] if len(c) >= 2 and c[0] == c[-1] == '"' else c for c in line.split("\t")]
        out[int(num)] = {"items": len(dgs.split(",")) if dgs else 0, "info": info, "padding": padding, "experts": []}
    # Only our expert items are read here, so mending the labels does not matter.
    pdml = tshark_env.read_tshark_output(pdml_path, xml=True)
    for _, packet in ET.iterparse(io.BytesIO(pdml.encode("utf-8"))):
        if packet.tag != "packet":
            continue
        num = int(packet.find("proto[@name='geninfo']/field[@name='num']").get("show"))
        ecat = packet.find(".//proto[@name='ecatr']")
        base = int(ecat.get("pos")) if ecat is not None else 0
        for item in packet.iter("field"):
            if item.get("name") != "_ws.expert":
                continue
            for child in item.findall("field"):
                # Only the per-frame experts: the pairing's cross-frame ones
                # (ecatr.expert.changed, ...) are test_pairing's to check.
                name = child.get("name", "")
                if name.startswith("ecatr.expert.") and name[len("ecatr.expert."):] in OUR_EXPERTS:
                    out.setdefault(num, {"items": 0, "info": "", "padding": "", "experts": []})["experts"].append(
                        (child.get("name")[len("ecatr.expert."):], int(item.get("pos")) - base, child.get("showname")))
        packet.clear()
    return out


def info_agrees(got, implied):
    """ours_shows() implies each datagram's text up to its length; what the datagram's data
    holds (AL states, mailbox contents) may follow after a space (test_info_column.py checks
    those texts against the bytes of real captures)."""
    if got is None or implied is None:
        return got == implied
    def entries(info):
        m = re.match("Datagram \u00d7(\\d+): ", info)
        return (int(m.group(1)), info[m.end():]) if m else (1, info)
    (n_got, rest), (n_implied, wanted) = entries(got), entries(implied)
    if n_got != n_implied:
        return False
    for prefix in wanted.split(", ") if n_implied > 1 else [wanted]:
        if rest == prefix:
            rest = ""
        elif rest.startswith(prefix + ", "):
            rest = rest[len(prefix) + 2:]
        elif rest.startswith(prefix + " "):
            cut = rest.find(", ", len(prefix))
            rest = rest[cut + 2:] if cut >= 0 else ""
        else:
            return False
    return rest == ""


def compare_extras(num, payload, got, on_wire=None):
    """Problems of one frame: ecatr.datagram items, Info, padding, expert infos against ours_shows()."""
    items, info, experts, regions, padding = ours_shows(payload, on_wire)
    got = got or {"items": 0, "info": None, "padding": "", "experts": []}
    got_experts, problems = inside_data(got["experts"], regions)
    got = dict(got, experts=got_experts)
    if got["items"] != items:
        problems.append("ours: %d ecatr.datagram items, the bytes imply %d" % (got["items"], items))
    if not info_agrees(got["info"], info):
        problems.append("ours: Info %r, the bytes imply %r" % (got["info"], info))
    if got["padding"] != padding:
        problems.append("ours: padding %r, the bytes imply %r" % (got["padding"], padding))
    if got["experts"] != experts:
        problems.append("ours: expert infos %s, the bytes imply %s" % (got["experts"], experts))
    return [{"frame": num, "what": p} for p in problems]


# --------------------------------------------------------------------------- comparison

class Stats:
    def __init__(self):
        self.cols = ("values", "agree", "explained", "mismatch", "ours!=truth", "ws!=model")
        self.rows = OrderedDict()
        for f in FIELDS:
            self.rows[f[2]] = dict.fromkeys(self.cols, 0)
        self.explained = defaultdict(int)
        self.frames_pass = 0
        self.frames_fail = 0
        self.failures = []
        self.frames_with_explanations = defaultdict(int)
        self.notes = defaultdict(int)
        self.extras_frames = 0      # frames whose ecatr.datagram items, Info, padding and experts were checked
        self.extras_experts = 0
        self.deep = ecat_deep.DeepStats()

    def table(self):
        w = max(len(k) for k in self.rows)
        lines = ["%-*s %s" % (w, "field (ours)", " ".join("%11s" % c for c in self.cols))]
        for k, r in self.rows.items():
            lines.append("%-*s %s" % (w, k, " ".join("%11d" % r[c] for c in self.cols)))
        return "\n".join(lines)


def _eq(a, b):
    """Same value and same type (True is not 1); MISSING equals only MISSING."""
    if a is MISSING or b is MISSING:
        return a is b
    if isinstance(a, (ReprError, Partial, OneOf)) or isinstance(b, (ReprError, Partial, OneOf)):
        return False
    return type(a) is type(b) and a == b


def truth_ok(exp, val):
    if isinstance(exp, bytes) and exp == b"":
        return val is MISSING, None     # zero-length Data: no item (the contract)
    if isinstance(exp, Partial):
        return val is MISSING or (isinstance(val, bytes) and val == exp.value), \
            ("partial shown" if val is not MISSING else "partial absent")
    return _eq(exp, val), None


def compare_frame(num, exp, model, ours, ws, stats, context):
    """Compare one frame; return list of problem dicts (empty when the frame passes)."""
    problems = []
    ours = ours or {"header": {}, "datagrams": [], "problems": []}
    ws = ws or {"header": {}, "datagrams": [], "malformed": False}
    model = model_after_mailbox_exception(model, ws)
    for p in ours.get("problems", []):
        problems.append({"frame": num, "what": "ours: " + p})

    def one(scope, key, i, e, o, w, m, why_model):
        fname = FIELDS_BY_SCOPE[(scope, key)]
        row = stats.rows[fname]
        if e is MISSING and o is MISSING and w is MISSING and m is MISSING:
            return
        row["values"] += 1
        t_ok, t_note = truth_ok(e, o)
        if t_note:
            stats.notes["a cut Data field (absent or the bytes present are both accepted): ours: " + t_note] += 1
        m_ok, m_why = model_matches(m, w)
        why = m_why or why_model
        if not t_ok:
            row["ours!=truth"] += 1
        if not m_ok:
            row["ws!=model"] += 1
        if _eq(o, w):
            row["agree"] += 1
            if t_ok:
                return
        elif t_ok and m_ok and why:
            row["explained"] += 1
            stats.explained[why.split(":")[0]] += 1
            context["explained"].add(why.split(":")[0])
            return
        else:
            row["mismatch"] += 1
        where = "header" if scope == "header" else "datagram %d" % (i + 1)
        problems.append({"frame": num, "field": fname, "where": where, "ours": o, "wireshark": w,
                         "truth": e, "model": m, "why": why,
                         "verdict": ("ours differs from the truth" if not t_ok else
                                     "Wireshark differs from ours and the model does not explain it")})

    for note in model["note"]:
        stats.notes[re.sub(r"datagram \d+", "datagram N", note)] += 1
    eh = exp["header"] or {}
    mh = model["header"] or {}
    for key in HEADER_KEYS:
        one("header", key, 0, eh.get(key, MISSING), ours["header"].get(key, MISSING),
            ws["header"].get(key, MISSING), mh.get(key, MISSING), None)
    edg, mdg = exp["datagrams"], model["datagrams"]
    odg, wdg = ours["datagrams"], ws["datagrams"]
    n = max(len(edg), len(mdg), len(odg), len(wdg))
    for i in range(n):
        e_d = edg[i] if i < len(edg) else None
        m_d = mdg[i] if i < len(mdg) else None
        for key in DG_KEYS:
            e = e_d.get(key, MISSING) if e_d else MISSING
            m = m_d.get(key, MISSING) if m_d else MISSING
            o = odg[i].get(key, MISSING) if i < len(odg) else MISSING
            w = wdg[i].get(key, MISSING) if i < len(wdg) else MISSING
            why = model["why"].get((i, key))
            if key in ("data", "unread") and e_d is not None:
                view = ours_view(e_d)
                if view != key:
                    e = MISSING
                elif key == "unread":
                    e = e_d.get("data", MISSING)     # the bytes of Data, under another name
                    why = VIEW_WHY["unread"]
                if key == "data" and view != "data" and why is None:
                    why = VIEW_WHY[view]
            if why is None and not _eq(e, m) and not isinstance(m, OneOf):
                if e_d is None and m_d is not None:
                    why = ("ws-invented-datagram: M=1 on the last datagram, Wireshark reads the bytes after "
                           "the header's Length (padding) as another datagram")
                elif m_d is None and e_d is not None:
                    why = model["dropped_why"]
                elif isinstance(e, Partial) and m is MISSING:
                    why = "ws-truncated: datagram cut short, Wireshark shows no partial tree"
            if why is None and not _eq(e, m):
                why = context.get("header_length_why")
            one("dg", key, i, e, o, w, m, why)
    return problems


FIELDS_BY_SCOPE = {(f[1], f[0]): f[2] for f in FIELDS}


# --------------------------------------------------------------------------- running

def run_sides(env, cap, fieldset, tag):
    """Run both tshark sides at once; return (ours -T fields text or None, ws json path,
    ours items/Info/experts (parse_extras) or None, seconds). fieldset None (--simulate
    perfect) runs only the Wireshark side; only the real plugin (ecatr) has the extras."""
    t0 = time.time()
    ws_out = env.path(tag + ".ws.json")
    ours_out = env.path(tag + ".ours.tsv")
    extras_out, pdml_out = env.path(tag + ".extras.tsv"), env.path(tag + ".experts.pdml")
    runs = [("Wireshark", ws_command(cap), ws_out)]
    if fieldset is not None:
        runs.append(("ours", ours_command(cap, fieldset), ours_out))
    if fieldset == "ecatr":
        runs += [("ours", extras_command(cap), extras_out), ("ours", experts_command(cap), pdml_out)]
    deep_out = env.path(tag + ".ours.json")
    if fieldset == "ecatr" and DEEP:
        runs.append(("ours, registers and mailboxes", ours_deep_command(cap), deep_out))
    procs = []
    for side, args, out in runs:
        fh = open(out, "w")
        procs.append((side, fh, subprocess.Popen(env.command(args), env=env.env(), cwd=env.home,
                                                 stdout=fh, stderr=subprocess.PIPE, text=True)))
    for side, fh, p in procs:
        err = p.communicate()[1]
        fh.close()
        if p.returncode != 0:
            raise tshark_env.TsharkError("tshark (%s side) exited %d on %s:\n%s" % (side, p.returncode, cap, err))
        if err.strip():
            print("note: tshark (%s side) stderr on %s:\n%s" % (side, os.path.basename(cap), err.strip()))
    ours_text, extras = None, None
    if fieldset is not None:
        with open(ours_out) as fh:
            ours_text = fh.read()
    run_sides.deep_json = deep_out if fieldset == "ecatr" and DEEP else None
    if fieldset == "ecatr":
        with open(extras_out) as fh:
            extras = parse_extras(fh.read(), pdml_out)
    return ours_text, ws_out, extras, time.time() - t0


def compare_capture(packets, ours_text, ws_json, stats, label, truths=None, extras=None):
    """packets: [(linktype, bytes, orig_len)] in capture order; extras: parse_extras() of ours."""
    expected = {}
    models = {}
    payloads = {}
    for num, (lt, pkt, orig) in enumerate(packets, 1):
        payload, encap = pcapgen.ecat_payload_of(pkt, lt)
        if payload is None:
            continue
        expected[num] = pcapgen.decode_ecat(payload)
        models[num] = ws_model(payload)
        payloads[num] = (payload, pkt, orig, encap)
    if truths is not None:
        check_truth(expected, truths, payloads)
    if ours_text is None:
        ours_text = perfect_fields_text(expected, len(packets))
    ours = parse_ours(ours_text, expected)
    ws = parse_ws_json(ws_json)
    if len(ws) != len(packets):
        raise RuntimeError("%s: Wireshark JSON has %d packets, capture has %d" % (label, len(ws), len(packets)))
    decoded = len(set(ours) & set(expected))
    if expected and not decoded:
        print("note: %s: our plugin decoded none of the %d EtherCAT frames (is ecatr registered on "
              "ethertype 0x88A4 / udp.port 34980, and does it win over Wireshark's ecatf?)" % (label, len(expected)))
    for num in sorted(set(ours) - set(expected)):
        stats.frames_fail += 1
        stats.failures.append(([{"frame": num, "what": "ours decoded a frame that is not EtherCAT by "
                                 "ethertype 0x88A4 / UDP port 34980"}], label, None, None))
    deep_ws = deep_ours = None
    if getattr(run_sides, "deep_json", None):
        deep_ws = ecat_deep.items_per_packet(ws_json, ("ecat.", "ecat_mailbox.", "ecat.reg"))
        deep_ours = ecat_deep.items_per_packet(run_sides.deep_json, ("ecatr.",))
    for num in sorted(expected):
        context = {"explained": set(), "header_length_why": header_length_why(payloads[num][0], expected[num])}
        probs = compare_frame(num, expected[num], models[num], ours.get(num), ws[num - 1], stats, context)
        if extras is not None:
            payload, pkt, orig, _encap = payloads[num]
            probs += compare_extras(num, payload, extras.get(num), len(payload) + orig - len(pkt))
            stats.extras_frames += 1
            stats.extras_experts += len((extras.get(num) or {"experts": []})["experts"])
        if deep_ws is not None:
            stops = []
            hl_why = context["header_length_why"]
            if hl_why:      # Wireshark decodes on after the Datagrams the header's Length allows
                payload, pkt = payloads[num][0], payloads[num][1]
                base = len(pkt) - len(payload)
                cut = base + 2 + (struct.unpack("<H", payload[:2])[0] & 0x7FF)
                off = base + 2
                for d in expected[num]["datagrams"]:     # the datagram the cut falls in: ours shows
                    if isinstance(d.get("len"), int):    # only whole register blocks of its data
                        if off + 12 + d["len"] > cut:
                            cut = min(cut, off + 10)
                            break
                        off += 12 + d["len"]
                stops.append((cut, None, hl_why))
            faults = mailbox_faults(expected[num])
            if faults:     # where ours stops: inside the faulty mailboxes (then goes on after them)
                payload, pkt = payloads[num][0], payloads[num][1]
                off = len(pkt) - len(payload) + 2
                for i, d in enumerate(expected[num]["datagrams"]):
                    if not isinstance(d.get("len"), int):
                        break       # a datagram cut short: nothing decoded after it
                    if i in faults:
                        stops.append((off + 10, off + 10 + d["len"], STOP_WHY))
                    off += 12 + d["len"]
            for what in ecat_deep.compare_packet(num, deep_ws[num - 1], deep_ours[num - 1], stats.deep, stops):
                probs.append({"frame": num, "what": "registers/mailboxes: " + what})
        for e in context["explained"]:
            stats.frames_with_explanations[e] += 1
        if probs:
            stats.frames_fail += 1
            t = truths[num - 1] if truths else None
            stats.failures.append((probs, label, payloads[num], t))
        else:
            stats.frames_pass += 1
    return len(expected)


def header_length_why(payload, exp):
    """Wireshark's plugin ignores the header's Length. When the datagrams decoded within it
    are not those decoded to the end of the payload, that explains a difference."""
    if exp["header"] is None or exp["header"]["type"] != 1:
        return None
    h = struct.unpack("<H", payload[:2])[0] | 0x7FF
    if pcapgen.decode_ecat(struct.pack("<H", h) + payload[2:])["datagrams"] == exp["datagrams"]:
        return None
    return ("ws-ignores-header-length: the header's Length disagrees with the datagrams, Wireshark "
            "decodes them to the end of the payload")


def check_truth(expected, truths, payloads):
    """The reference decode of each generated frame equals what the generator wrote."""
    for num, t in enumerate(truths, 1):
        e = expected.get(num)
        assert e is not None, "generated frame %d is not EtherCAT?" % num
        assert e["header"] == t["header"] or "truncate_to" in t, (num, e["header"], t["header"])
        if "truncate_to" in t or "odd_lengths" in t or t["header"]["type"] != 1:
            continue
        want = pcapgen.expected_from_truth(t)
        if e["datagrams"] != want:
            raise AssertionError("frame %d: reference decode %r != generator truth %r" % (num, e["datagrams"], want))


def print_failures(stats, limit):
    shown_n = 0
    for probs, label, pl, t in stats.failures:
        if shown_n >= limit:
            break
        shown_n += 1
        num = probs[0]["frame"]
        print("--- %s frame %d%s" % (label, num, (" [%s]" % t["note"]) if t and t.get("note") else ""))
        if pl:
            payload, pkt, orig, encap = pl
            ref = pcapgen.decode_ecat(payload)
            print("    encapsulation %s, %d bytes captured of %d; datagrams: %s" %
                  (encap, len(pkt), orig, ", ".join(
                      "%s len %s" % (pcapgen.CMD_NAMES.get(d["cmd"], "0x%02x" % d["cmd"]), d.get("len", "?"))
                      for d in ref["datagrams"]) or "none"))
            print("    EtherCAT payload (%d bytes, from the frame header):" % len(payload))
            h = payload.hex()
            for k in range(0, min(len(h), 256), 64):
                print("      " + h[k:k + 64])
            if len(h) > 256:
                print("      ... (%d more bytes)" % ((len(h) - 256) // 2))
        for p in probs[:8]:
            if "what" in p:
                print("    " + p["what"])
                continue
            print("    %s %s: %s" % (p["where"], p["field"], p["verdict"]))
            print("        ours:      %s" % shown(p["ours"]))
            print("        Wireshark: %s" % shown(p["wireshark"]))
            print("        truth:     %s" % shown(p["truth"]))
            if p["why"]:
                print("        (model: %s)" % p["why"])
            elif not isinstance(p["model"], _Missing) or p["wireshark"] is not MISSING:
                print("        model:     %s" % (shown(p["model"]) if not isinstance(p["model"], OneOf)
                                                  else " or ".join(shown(v) for v, _ in p["model"].options)))
        if len(probs) > 8:
            print("    ... %d more differences in this frame" % (len(probs) - 8))


def mismatch_class(p):
    if "what" in p:
        return re.sub(r"\d+(, \d+)*", "N", p["what"])
    o, w, t = p["ours"], p["wireshark"], p["truth"]

    def kind(v):
        if v is MISSING:
            return "absent"
        if isinstance(v, ReprError):
            return "unparsable"
        if v == b"":
            return "empty"
        return "a value"
    if p["verdict"].startswith("ours"):
        if kind(o) == kind(t) == "a value":
            return "%s: ours differs from the truth" % p["field"]
        return "%s: ours %s, truth %s" % (p["field"], kind(o), kind(t))
    return "%s: Wireshark %s, ours %s (= truth), not explained by the model" % (p["field"], kind(w), kind(o))


def report(stats, args, extra=""):
    print()
    print("Per-field agreement (values: field occurrences compared; explained: known Wireshark "
          "behaviour, ours checked against the truth instead):")
    print(stats.table())
    if stats.explained:
        print()
        print("Explained differences (values / frames):")
        for k in sorted(stats.explained):
            print("  %-28s %6d / %d" % (k, stats.explained[k], stats.frames_with_explanations[k]))
    if stats.notes:
        print()
        print("Notes:")
        for k in sorted(stats.notes):
            print("  %6d x %s" % (stats.notes[k], k))
    if stats.failures:
        classes = defaultdict(lambda: [0, 0])
        for probs, _, _, _ in stats.failures:
            seen = set()
            for p in probs:
                c = mismatch_class(p)
                classes[c][0] += 1
                if c not in seen:
                    classes[c][1] += 1
                    seen.add(c)
        print()
        print("Mismatch classes (values / frames):")
        for c, (nv, nf) in sorted(classes.items(), key=lambda kv: -kv[1][0]):
            print("  %6d / %-6d %s" % (nv, nf, c))
        print()
        print("First mismatches:")
        print_failures(stats, args.show)
    if stats.extras_frames:
        print()
        print("ecatr.datagram items, Info column, padding and expert infos (name, position, message) checked "
              "against the bytes on %d frames (%d expert infos)" % (stats.extras_frames, stats.extras_experts))
    if DEEP:
        print()
        print(stats.deep.report())
    if extra:
        print(extra)
    print()
    print("%d passed, %d failed" % (stats.frames_pass, stats.frames_fail))


def prepare_env(args):
    env = tshark_env.TsharkEnv(keep=args.keep)
    if args.simulate == "wireshark":
        print("SIMULATION: 'ours' is Wireshark's own plugin read through -T fields (no dissgen)")
        return env, "ecat"
    if args.simulate == "perfect":
        print("SIMULATION: 'ours' is an ideal plugin (the truth printed as -T fields; no dissgen)")
        return env, None
    rules = os.path.join(args.source_dir, "rules", "ethercat.xml")
    t0 = time.time()
    files = env.install_plugin(args.dissgen, rules)
    env.assert_plugin_loaded("ecatr")
    global DEEP
    names = subprocess.run([args.dissgen, "fields", rules], capture_output=True, text=True).stdout
    DEEP = "\necatr.datagram.reg\t" in names
    print("registers and mailboxes: %s" % ("compared value by value" if DEEP else
                                           "not in these rules (Data compared as raw bytes)"))
    print("installed %s into %s in %.1fs (tshark runs as %s)" %
          (", ".join(os.path.basename(f) for f in files), env.plugin_dir, time.time() - t0,
           "uid 65534" if env.as_nobody else "the current user"))
    return env, "ecatr"


def generated(args):
    t0 = time.time()
    n = args.frames
    specials = max(1, n // 300) if args.malformed is None else args.malformed
    frames = pcapgen.random_frames(args.seed, n, args.max_datagrams, m_on_last=specials,
                                   truncated=specials, other_types=min(specials, 3),
                                   odd_lengths=specials)
    blob = pcapgen.pcap_bytes(frames)
    truths = [pcapgen.truth(f, i + 1) for i, f in enumerate(frames)]
    packets = []
    for f in frames:
        pkt, orig = pcapgen.encode_frame(f)
        packets.append((1, pkt, orig))
    t_gen = time.time() - t0
    env, fieldset = prepare_env(args)
    try:
        cap = env.add_file("generated.pcap", blob)
        if args.keep:
            with open(env.path("generated.truth.json"), "w") as fh:
                json.dump(truths, fh)
        print("generated %d frames (seed %d, up to %d datagrams, %d each of M=1-on-last, truncated, header "
              "reserved bit, header Length and datagram Length disagreeing with the bytes) in %.2fs: %s"
              % (n, args.seed, args.max_datagrams, specials, t_gen, cap))
        ours_text, ws_json, extras, t_run = run_sides(env, cap, fieldset, "generated")
        t1 = time.time()
        stats = Stats()
        compare_capture(packets, ours_text, ws_json, stats, "generated", truths, extras)
        t_cmp = time.time() - t1
        report(stats, args, "timing: generate %.2fs, tshark (both sides, in parallel) %.2fs, compare %.2fs"
               % (t_gen, t_run, t_cmp))
    finally:
        env.cleanup()
    return 0 if stats.frames_fail == 0 else 1


def corpus(args):
    d = args.corpus
    files = sorted(glob.glob(os.path.join(d, "*.pcapng")) + glob.glob(os.path.join(d, "*.pcap")))
    if not os.path.isdir(d) or not files:
        print("SKIPPED: no corpus at %s (no *.pcap/*.pcapng)" % d)
        return SKIP_CODE
    env, fieldset = prepare_env(args)
    stats = Stats()
    try:
        t0 = time.time()
        total = 0
        for path in files:
            cap = env.readable(path)     # a copy in the temporary HOME if need be
            packets = list(pcapgen.read_capture(path))
            ours_text, ws_json, extras, _ = run_sides(env, cap, fieldset, "corpus")
            before = (stats.frames_pass, stats.frames_fail)
            n = compare_capture(packets, ours_text, ws_json, stats, os.path.basename(path), extras=extras)
            total += n
            print("%-40s %6d packets, %6d EtherCAT frames: %d passed, %d failed" %
                  (os.path.basename(path), len(packets), n, stats.frames_pass - before[0],
                   stats.frames_fail - before[1]))
        report(stats, args, "timing: %d files, %d EtherCAT frames in %.2fs" % (len(files), total, time.time() - t0))
    finally:
        env.cleanup()
    return 0 if stats.frames_fail == 0 else 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", help="dissgen binary (default SOURCE_DIR/build/bin/dissgen)")
    ap.add_argument("--source-dir", default=os.path.normpath(os.path.join(HERE, "..", "..", "..")),
                    help="repository root (rules/ethercat.xml)")
    ap.add_argument("--frames", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-datagrams", type=int, default=12, choices=range(1, 21), metavar="1..20")
    ap.add_argument("--malformed", type=int, default=None,
                    help="frames of each malformed kind (M=1 on last, truncated); default frames/300, at least 1")
    ap.add_argument("--corpus", metavar="DIR", help="compare over the captures in DIR instead of generated frames")
    ap.add_argument("--show", type=int, default=5, help="mismatching frames to print in detail")
    ap.add_argument("--keep", action="store_true", help="keep the temporary HOME (captures, tshark outputs)")
    ap.add_argument("--simulate", choices=("wireshark", "perfect"),
                    help="no dissgen, to check this tool: 'ours' is Wireshark's own plugin read through "
                         "-T fields (expect failures at its known defects), or an ideal plugin (expect none)")
    args = ap.parse_args(argv)
    if not args.simulate:
        args.dissgen = args.dissgen or os.path.join(args.source_dir, "build", "bin", "dissgen")
        if not os.path.isfile(os.path.join(args.source_dir, "rules", "ethercat.xml")):
            ap.error("no rules/ethercat.xml under --source-dir %s" % args.source_dir)
    try:
        if args.corpus:
            return corpus(args)
        return generated(args)
    except tshark_env.TsharkError as e:
        print("ERROR: %s" % e)
        print("0 passed, %d failed" % (args.frames if not args.corpus else 1))
        return 2


if __name__ == "__main__":
    sys.exit(main())

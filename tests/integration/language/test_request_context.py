#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""request{Name}: a response's values read from its paired request (tests/rules/request_context.xml,
Modbus/TCP's read functions over UDP port 47502, keys: transaction and unit).

  test_request_context.py --dissgen build/bin/dissgen --source-dir .

Generated captures of read transactions, several in flight at once (different keys, answered
out of order). Function 3: each register's number is the request's reference plus its index;
function 1 (one byte per coil): as many coils as the request's quantity, numbered the same way;
both show the request's reference as the first register, right after the keys, also in a response
that ends there (and none when it ends inside them).
Checked against the bytes in one pass and with -2, also over TCP with up to three messages in a
segment. The same capture without its requests:
every response decodes what it can (register values, no numbers, no coils), says so with
rqc.expert.no_request_context once, and raises no malformed expert. And a field of a repeated
node read by position (tests/rules/request_by_position.xml): each answer of a batch decoded by
the request's operation at its position. Needs no corpus.
"""

import os
import re
import random
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402
import pcapgen  # noqa: E402
from test_enip import udp  # noqa: E402

ARGS = None
PORT = 47502
CLIENT, SERVER = b"\x0a\x00\x00\x01", b"\x0a\x00\x00\x02"
FIELDS = ["frame.number", "rqc.transaction", "rqc.first_register", "rqc.registers.values.register.value",
          "rqc.registers.values.register.number", "rqc.coils.coil.state", "rqc.coils.coil.number",
          "rqc.coils.coil_count", "rqc.request_in", "rqc.expert.no_request_context", "rqc.expert.bad_length",
          "_ws.expert.severity"]


def transactions(seed, n):
    """n read transactions: (transaction, unit, function, reference, quantity, values)."""
    rng = random.Random(seed)
    out = []
    for i in range(n):
        function = rng.choice([1, 3])
        quantity = rng.choice([1, 2, 5, rng.randrange(1, 40)])
        reference = rng.choice([0, 1, 65535 - quantity, rng.randrange(65536 - quantity)])
        values = [rng.randrange(65536 if function == 3 else 2) for _ in range(quantity)]
        out.append((1 + (i * 7919) % 65535, rng.choice([1, 2]), function, reference, quantity, values))
    return out


def schedule(txns, seed):
    """Messages in capture order: up to three transactions in flight, answered in any order."""
    rng = random.Random(seed)
    order, waiting, pending = [], [], list(range(len(txns)))
    while pending or waiting:
        if pending and (len(waiting) < 3 and (not waiting or rng.random() < 0.6)):
            k = pending.pop(0)
            order.append(("request", k))
            waiting.append(k)
        else:
            order.append(("response", waiting.pop(rng.randrange(len(waiting)))))
    return order


def payload(direction, txn, client=None):
    """The message; with `client`, behind its length-prefixed name (request_context_decoded_keys.xml)."""
    head = b"" if client is None else bytes([len(client)]) + client
    return head + modbus(direction, txn)


def modbus(direction, txn):
    transaction, unit, function, reference, quantity, values = txn
    if direction == "request":
        pdu = struct.pack(">BHH", function, reference, quantity)
    elif function == 3:
        pdu = struct.pack(">BB", function, 2 * quantity) + b"".join(struct.pack(">H", v) for v in values)
    else:
        pdu = struct.pack(">BB", function, quantity) + bytes(values)
    return struct.pack(">HHHB", transaction, 0, 1 + len(pdu), unit) + pdu


def frame(direction, data, client_port=40000):
    sport, dport = (client_port, PORT) if direction == "request" else (PORT, client_port)
    src, dst = (CLIENT, SERVER) if direction == "request" else (SERVER, CLIENT)
    u = struct.pack("!HHHH", sport, dport, 8 + len(data), 0) + data
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0, src, dst)
    ip = ip[:10] + struct.pack("!H", pcapgen.ip_checksum(ip)) + ip[12:]
    return b"\x02\x00\x00\x00\x00\x02\x02\x00\x00\x00\x00\x01\x08\x00" + ip + u


def expected(txn, with_request):
    """What a response shows, as tshark -T fields prints it."""
    _, _, function, reference, quantity, values = txn
    numbers = ",".join(str(reference + i) for i in range(quantity)) if with_request else ""
    first = {"rqc.first_register": str(reference) if with_request else ""}
    if function == 3:
        return {**first, "rqc.registers.values.register.value": ",".join("0x%04x" % v for v in values),
                "rqc.registers.values.register.number": numbers,
                "rqc.coils.coil.state": "", "rqc.coils.coil.number": "", "rqc.coils.coil_count": ""}
    return {**first, "rqc.registers.values.register.value": "", "rqc.registers.values.register.number": "",
            "rqc.coils.coil.state": ",".join("0x%02x" % v for v in values) if with_request else "",
            "rqc.coils.coil.number": numbers, "rqc.coils.coil_count": str(quantity) if with_request else ""}


def client_name(k):
    """A client name of 0-12 bytes, different from one transaction to the next."""
    return b"station-%d" % k if k % 3 else b"plc%d" % (k % 7) if k % 2 else b""


class TestRequestContext(TsharkTestCase, unittest.TestCase):
    RULES = "request_context.xml"
    CLIENT = None  # the name in front of each message: None, or k -> bytes

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", cls.RULES), "rqc")
        cls.txns = transactions(47502, 120)
        cls.order = schedule(cls.txns, 1)
        name = (lambda k: None) if cls.CLIENT is None else cls.CLIENT
        cls.full = cls.env.add_file("full.pcap", pcapgen.raw_pcap_bytes(
            [frame(d, payload(d, cls.txns[k], name(k))) for d, k in cls.order]))
        cls.orphans = [k for d, k in cls.order if d == "response"]
        cls.orphan_path = cls.env.add_file("orphans.pcap", pcapgen.raw_pcap_bytes(
            [frame("response", payload("response", cls.txns[k], name(k))) for k in cls.orphans]))

    def rows(self, path, two_pass):
        return {n: {f: ",".join(v) for f, v in r.items()}
                for n, r in self.env.field_rows(path, FIELDS, two_pass).items()}

    def test_numbers_and_counts_come_from_the_request(self):
        in_flight = max(sum(1 for d, k in self.order[:i] if d == "request") -
                        sum(1 for d, k in self.order[:i] if d == "response") for i in range(len(self.order)))
        out_of_order = sum(1 for i, (d, k) in enumerate(self.order) if d == "response" and
                           any(d2 == "request" and k2 > k for d2, k2 in self.order[:i]) and
                           any(d2 == "response" and k2 > k for d2, k2 in self.order[:i]))
        with self.checks() as check:
            check(in_flight == 3 and out_of_order > 0, "the capture has 3 transactions in flight at once and "
                  "%d responses after a later one's" % out_of_order)
            for two_pass in (False, True):
                mode = "-2" if two_pass else "one pass"
                rows = self.rows(self.full, two_pass)
                requests = {k: n for n, (d, k) in enumerate(self.order, 1) if d == "request"}
                wrong, registers, coils = [], 0, 0
                for n, (d, k) in enumerate(self.order, 1):
                    r = rows[n]
                    if d == "request":
                        if r["rqc.expert.no_request_context"] or r["rqc.registers.values.register.number"]:
                            wrong.append((n, "request", r))
                        continue
                    want = expected(self.txns[k], True)
                    got = {f: r[f] for f in want}
                    if got != want or r["rqc.request_in"] != str(requests[k]) or r["rqc.expert.no_request_context"]:
                        wrong.append((n, got, want))
                    registers += len(want["rqc.registers.values.register.number"].split(",")) if self.txns[k][2] == 3 else 0
                    coils += self.txns[k][4] if self.txns[k][2] == 1 else 0
                check(not wrong, "%s: %d register numbers and %d coils (count and numbers) of %d responses as "
                      "their requests say, no expert%s" % (mode, registers, coils, len(self.orphans),
                                                           "" if not wrong else " (wrong: %s)" % wrong[:2]))

    def test_connections_are_ordered_apart(self):
        """A server answers each connection in order, not the capture's connections among
        themselves: a request from one client port answered after 30 transactions of another
        is paired, neither lost nor out of order."""
        slow, quick = self.txns[0], self.txns[1:31]
        frames = [frame("request", payload("request", slow), 40001)]
        for t in quick:
            frames += [frame("request", payload("request", t)), frame("response", payload("response", t))]
        frames.append(frame("response", payload("response", slow), 40001))
        path = self.env.add_file("two-connections.pcap", pcapgen.raw_pcap_bytes(frames))
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number", "rqc.request_in", "rqc.expert.no_response",
                                                  "rqc.expert.out_of_order"], two_pass)
                last = rows[len(frames)]
                check(last["rqc.request_in"] == ["1"], "%s: the slow connection's response pairs with frame 1 (%s)"
                      % ("-2" if two_pass else "one pass", last["rqc.request_in"]))
                flagged = [n for n, r in rows.items() if r["rqc.expert.no_response"] or r["rqc.expert.out_of_order"]]
                check(not flagged, "%s: nothing lost or out of order (%s)" % ("-2" if two_pass else "one pass", flagged))

    def test_several_messages_in_one_tcp_segment(self):
        """Over TCP a segment carries one to three messages (pdulength): each response finds
        its own request, and a second pass reads what the first found for each of them, not
        only for a segment's first message."""
        rng = random.Random(5)
        segments, seq = [], {"request": 1000, "response": 50000}
        i = 0
        while i < len(self.order):
            d = self.order[i][0]
            run = 1
            while run < 3 and i + run < len(self.order) and self.order[i + run][0] == d and rng.random() < 0.7:
                run += 1
            segments.append((d, [k for _d, k in self.order[i:i + run]]))
            i += run
        frames = []
        for d, ks in segments:
            data = b"".join(modbus(d, self.txns[k]) for k in ks)
            sport, dport = (40000, PORT) if d == "request" else (PORT, 40000)
            src, dst = (CLIENT, SERVER) if d == "request" else (SERVER, CLIENT)
            frames.append(pcapgen.tcp_ethernet_frame(data, sport, dport, seq[d], src, dst))
            seq[d] += len(data)
        path = self.env.add_file("tcp.pcap", pcapgen.raw_pcap_bytes(frames))
        shared = sum(1 for d, ks in segments if d == "response" and len(ks) > 1)
        with self.checks() as check:
            check(shared > 10, "%d segments carry two or three responses" % shared)
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number", "rqc.first_register",
                                                  "rqc.registers.values.register.number", "rqc.coils.coil.number",
                                                  "rqc.expert.no_request_context"], two_pass)
                wrong = []
                for n, (d, ks) in enumerate(segments, 1):
                    if d != "response":
                        continue
                    r = rows[n]
                    want_first = [str(self.txns[k][3]) for k in ks]
                    want_numbers = [str(self.txns[k][3] + j) for k in ks for j in range(self.txns[k][4])]
                    got_numbers = r["rqc.registers.values.register.number"] + r["rqc.coils.coil.number"]
                    want_sorted = sorted(want_numbers, key=int)
                    if r["rqc.first_register"] != want_first or sorted(got_numbers, key=int) != want_sorted \
                            or r["rqc.expert.no_request_context"]:
                        wrong.append((n, r["rqc.first_register"], want_first))
                check(not wrong, "%s: every response of a segment of several shows its own request's first "
                      "register and numbers%s" % ("-2" if two_pass else "one pass",
                                                  "" if not wrong else " (wrong: %s)" % wrong[:3]))

    def test_responses_without_their_requests(self):
        with self.checks() as check:
            for two_pass in (False, True):
                mode = "-2" if two_pass else "one pass"
                rows = self.rows(self.orphan_path, two_pass)
                wrong = []
                for n, k in enumerate(self.orphans, 1):
                    r = rows[n]
                    want = expected(self.txns[k], False)
                    got = {f: r[f] for f in want}
                    if got != want or r["rqc.expert.no_request_context"] != "1" or r["rqc.expert.bad_length"] \
                            or r["_ws.expert.severity"] not in ("4194304",):
                        wrong.append((n, got, want, r["rqc.expert.no_request_context"], r["_ws.expert.severity"]))
                check(not wrong, "%s: %d responses without their requests: register values kept, no numbers, "
                      "no coils, one note each and nothing malformed%s" % (
                          mode, len(self.orphans), "" if not wrong else " (wrong: %s)" % wrong[:2]))

    def test_response_cut_after_its_keys(self):
        """A response that ends right after its keys (the unit) still finds its request: the first
        register shows; one byte shorter, it has no keys to look with and shows none."""
        name = (lambda k: None) if self.CLIENT is None else self.CLIENT
        frames, cuts = [], []
        for k, cut in ((3, 0), (4, 1)):
            txn = self.txns[k]
            head = len(payload("response", txn, name(k))) - len(modbus("response", txn))
            frames += [frame("request", payload("request", txn, name(k))),
                       frame("response", payload("response", txn, name(k))[:head + 7 - cut])]
            cuts.append(str(txn[3]) if cut == 0 else "")
        path = self.env.add_file("cut.pcap", pcapgen.raw_pcap_bytes(frames))
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.rows(path, two_pass)
                got = [rows[n]["rqc.first_register"] for n in (2, 4)]
                check(got == cuts and rows[2]["rqc.request_in"] == "1" and not rows[2]["rqc.expert.no_request_context"],
                      "%s: the response cut after its unit shows its request's first register, the one cut inside "
                      "it none (%s, want %s)" % ("-2" if two_pass else "one pass", got, cuts))

    def test_expert_text(self):
        out = self.env.tshark(["-r", self.orphan_path, "-V", "-c", "1"]).stdout
        with self.checks() as check:
            check("The request of this response is not known (not captured or given up as lost before it came)" in out,
                  "the expert info says why the values are missing")
            # Where it sits: at the start of the message, covering no byte (the whole
            # message, not one of its fields, lacks its request).
            pdml = self.env.tshark(["-r", self.orphan_path, "-T", "pdml", "-c", "3"]).stdout
            starts = re.findall(r'<proto name="rqc"[^>]*\bpos="(\d+)"', pdml)
            experts = re.findall(r'<field name="_ws\.expert" showname="[^"]*The request of this response is not '
                                 r'known[^>]*>', pdml)
            places = [(re.search(r'\bpos="(\d+)"', e).group(1), re.search(r'\bsize="(\d+)"', e).group(1))
                      for e in experts]
            check(len(starts) == 3 and places == [(p, "0") for p in starts],
                  "the expert info is at the message's start (%s), 0 bytes long: %s" % (starts, places))


class TestRequestContextDecodedKeys(TestRequestContext):
    """The same transactions behind a client name of any length (request_context_decoded_keys.xml):
    the keys are not at fixed offsets, and a response finds its request with the key values it
    decoded before its first request{...}."""
    RULES = "request_context_decoded_keys.xml"
    CLIENT = staticmethod(client_name)
    # Shown by the plain rule file alone: they do not depend on where the keys are.
    test_connections_are_ordered_apart = None
    test_several_messages_in_one_tcp_segment = None


class TestRequestByPath(TsharkTestCase, unittest.TestCase):
    """request{Container/Name} (tests/rules/request_path.xml): both read functions have their
    own request layout with a Reference and a Quantity, and each response reads its own
    function's by path; the registers' numbers of function 3 come from Read registers'
    Reference although Read coils' comes first in the file."""

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "request_path.xml"), "rqp")
        cls.txns = transactions(47507, 60)
        cls.order = schedule(cls.txns, 2)
        cls.path = cls.env.add_file("paths.pcap", pcapgen.raw_pcap_bytes(
            [frame(d, modbus(d, cls.txns[k])) for d, k in cls.order]))

    def test_each_response_reads_its_own_layouts_field(self):
        fields = [f.replace("rqc.", "rqp.") for f in FIELDS if f != "rqc.first_register"]
        functions = {f for _, _, f, _, _, _ in self.txns}
        with self.checks() as check:
            check(functions == {1, 3}, "both read functions are in the capture")
            for two_pass in (False, True):
                rows = self.env.field_rows(self.path, fields, two_pass)
                wrong = []
                for n, (d, k) in enumerate(self.order, 1):
                    if d != "response":
                        continue
                    want = {f.replace("rqc.", "rqp."): v for f, v in expected(self.txns[k], True).items()
                            if f != "rqc.first_register"}
                    got = {f: ",".join(rows[n][f]) for f in want}
                    if got != want:
                        wrong.append((n, got, want))
                check(not wrong, "%s: every response's register and coil numbers (and coil count) from its own "
                      "function's request layout%s" % ("-2" if two_pass else "one pass",
                                                       "" if not wrong else " (wrong: %s)" % wrong[:2]))


class TestRequestDefined(TsharkTestCase, unittest.TestCase):
    """defined(request{Quantity}) (tests/rules/request_defined.xml): a coil response whose request
    was captured says so and has its coils counted and numbered from it; one whose request was
    not says so too and shows its bytes as raw states, with no coils and no malformed expert."""

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "request_defined.xml"), "rqk")
        cls.txns = [t for t in transactions(47508, 80) if t[2] == 1]
        cls.order = schedule(cls.txns, 3)
        frames = [frame(d, modbus(d, cls.txns[k])) for d, k in cls.order]
        cls.orphans = [k for d, k in cls.order if d == "response"][:10]
        frames += [frame("response", modbus("response", cls.txns[k])) for k in cls.orphans]
        cls.path = cls.env.add_file("defined.pcap", pcapgen.raw_pcap_bytes(frames))

    def test_responses_say_whether_their_request_is_known(self):
        fields = ["frame.number", "rqk.coils.request_known", "rqk.coils.raw_states", "rqk.coils.coil.state",
                  "rqk.coils.coil.number", "rqk.expert.no_request_context", "_ws.malformed", "_ws.expert.severity"]
        with self.checks() as check:
            for two_pass in (False, True):
                mode = "-2" if two_pass else "one pass"
                rows = {n: {f: ",".join(v) for f, v in r.items()}
                        for n, r in self.env.field_rows(self.path, fields, two_pass).items()}
                expect = [(n, k, True) for n, (d, k) in enumerate(self.order, 1) if d == "response"]
                expect += [(len(self.order) + 1 + i, k, False) for i, k in enumerate(self.orphans)]
                wrong = []
                for n, k, known in expect:
                    _, _, _, reference, quantity, values = self.txns[k]
                    want = {"rqk.coils.request_known": "1" if known else "0",
                            "rqk.coils.raw_states": "" if known else " ".join("%02x" % v for v in values),
                            "rqk.coils.coil.state": ",".join("0x%02x" % v for v in values) if known else "",
                            "rqk.coils.coil.number": ",".join(str(reference + i) for i in range(quantity))
                            if known else "",
                            "rqk.expert.no_request_context": "" if known else "1", "_ws.malformed": ""}
                    got = {f: rows[n][f] for f in want}
                    if got != want:
                        wrong.append((n, got, want))
                check(not wrong, "%s: %d responses with their request (coils from it), %d without (raw states), "
                      "each saying which%s" % (mode, len(expect) - len(self.orphans), len(self.orphans),
                                               "" if not wrong else " (wrong: %s)" % wrong[:2]))


# --- request{Name} by position (tests/rules/request_by_position.xml, UDP 47505) -------------

BATCH_PORT = 47505
BATCH_FIELDS = ["frame.number", "batch.answer.word", "batch.answer.text", "batch.answer.asked",
                "batch.expert.no_request_context", "_ws.expert.severity"]


def batches(seed, n):
    """n batches: (transaction, [(kind, address, answer)]): kind 1 a word, kind 2 a text."""
    rng = random.Random(seed)
    out = []
    for t in range(n):
        ops = []
        for _ in range(rng.choice([0, 1, 2, 3, 5, 8])):
            kind = rng.choice([1, 2])
            answer = rng.randrange(0x10000) if kind == 1 else bytes(rng.choice(b"abcxyz") for _ in range(rng.randrange(1, 6)))
            ops.append((kind, rng.randrange(0x10000), answer))
        out.append((0x100 + t, ops))
    return out


def batch_message(direction, batch):
    transaction, ops = batch
    head = struct.pack(">HB", transaction, len(ops))
    if direction == "request":
        return head + b"".join(struct.pack(">BH", kind, address) for kind, address, _ in ops)
    return head + b"".join(struct.pack(">H", a) if kind == 1 else bytes([len(a)]) + a for kind, _, a in ops)


def batch_frame(direction, data):
    sport, dport = (40001, BATCH_PORT) if direction == "request" else (BATCH_PORT, 40001)
    src, dst = (CLIENT, SERVER) if direction == "request" else (SERVER, CLIENT)
    u = struct.pack("!HHHH", sport, dport, 8 + len(data), 0) + data
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0, src, dst)
    ip = ip[:10] + struct.pack("!H", pcapgen.ip_checksum(ip)) + ip[12:]
    return b"\x02\x00\x00\x00\x00\x02\x02\x00\x00\x00\x00\x01\x08\x00" + ip + u


def batch_frames(seed=47505, n=40):
    """The batches' requests and responses, several in flight and answered out of order, then
    five responses again without their requests (transactions never sent)."""
    bs = batches(seed, n)
    order = schedule(bs, seed)
    frames = [batch_frame(d, batch_message(d, bs[k])) for d, k in order]
    orphans = [(0x7000 + k, ops) for k, (_, ops) in enumerate(bs) if ops][:5]
    return bs, order, orphans, frames + [batch_frame("response", batch_message("response", b)) for b in orphans]


def overlong_frames(bs, first=0x7100):
    """Batches answered with more answers than their requests asked: each request sends its
    first operations only, the response answers them all. [(transaction, ops, asked)], frames."""
    longer = [(first + k, ops, len(ops) // 2) for k, (_, ops) in enumerate(bs) if len(ops) >= 2][:5]
    frames = []
    for transaction, ops, asked in longer:
        frames.append(batch_frame("request", batch_message("request", (transaction, ops[:asked]))))
        frames.append(batch_frame("response", batch_message("response", (transaction, ops))))
    return longer, frames


class TestRequestByPosition(TsharkTestCase, unittest.TestCase):
    """A field of a repeated node read by position: each answer of a batch is a word or a text
    as the operation at its position in the request says (request{Kind} in the answer's
    repeat, the request keeping every operation's Kind). Requests in flight together, answered
    out of order; responses without their requests show no word and no text, and say so."""

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "request_by_position.xml"), "batch")
        cls.batches, cls.order, cls.orphans, frames = batch_frames()
        cls.overlong, more = overlong_frames(cls.batches)
        cls.first_overlong = len(frames) + 1
        cls.path = cls.env.add_file("batches.pcap", pcapgen.raw_pcap_bytes(frames + more))

    def test_positions_the_request_lacks_are_undefined(self):
        """Answers past the request's operations read request{Kind} of an instance the request
        did not have: Asked is undefined (left out), not 0, and decodes neither a word nor a text."""
        with self.checks() as check:
            check(len(self.overlong) >= 3, "%d responses longer than their requests" % len(self.overlong))
            for two_pass in (False, True):
                rows = self.env.field_rows(self.path, BATCH_FIELDS, two_pass)
                wrong = []
                for i, (_, ops, asked) in enumerate(self.overlong):
                    r = rows[self.first_overlong + 2 * i + 1]
                    want = {"batch.answer.asked": [str(kind) for kind, _, _ in ops[:asked]],
                            "batch.answer.word": ["0x%04x" % a for kind, _, a in ops[:asked] if kind == 1],
                            "batch.answer.text": [a.decode() for kind, _, a in ops[:asked] if kind == 2]}
                    got = {f: r.get(f, []) for f in want}
                    if got != want:
                        wrong.append((self.first_overlong + 2 * i + 1, got, want))
                check(not wrong, "%s: answers past the request's %s operations have no Asked, word or text%s"
                      % ("-2" if two_pass else "one pass", [a for _, _, a in self.overlong],
                         "" if not wrong else " (wrong: %s)" % wrong[:2]))

    def test_answers_decoded_by_the_operation_at_their_position(self):
        in_flight = max(sum(1 for d, k in self.order[:i] if d == "request") -
                        sum(1 for d, k in self.order[:i] if d == "response") for i in range(len(self.order)))
        with self.checks() as check:
            check(in_flight > 1, "batches in flight together (%d at most)" % in_flight)
            for two_pass in (False, True):
                mode = "-2" if two_pass else "one pass"
                rows = {n: {f: ",".join(v) for f, v in r.items()}
                        for n, r in self.env.field_rows(self.path, BATCH_FIELDS, two_pass).items()}
                wrong = []
                for n, (d, k) in enumerate(self.order, 1):
                    if d != "response":
                        continue
                    ops = self.batches[k][1]
                    want = {"batch.answer.word": ",".join("0x%04x" % a for kind, _, a in ops if kind == 1),
                            "batch.answer.text": ",".join(a.decode() for kind, _, a in ops if kind == 2),
                            "batch.expert.no_request_context": ""}
                    got = {f: rows[n][f] for f in want}
                    if got != want:
                        wrong.append((n, got, want))
                check(not wrong, "%s: %d responses, each answer a word or a text as its request's operation at "
                      "the same position says%s" % (mode, sum(1 for d, _ in self.order if d == "response"),
                                                    "" if not wrong else " (wrong: %s)" % wrong[:2]))
                first = len(self.order) + 1
                orphan_rows = [rows[first + i] for i in range(len(self.orphans))]
                check(all(r["batch.answer.word"] == "" and r["batch.answer.text"] == "" and
                          r["batch.expert.no_request_context"] == "1" for r in orphan_rows),
                      "%s: responses without their requests: no word, no text, one note each (%s)"
                      % (mode, [(r["batch.answer.word"], r["batch.expert.no_request_context"]) for r in orphan_rows]))


class TestComputedKey(TsharkTestCase, unittest.TestCase):
    """A computed value as a pairing key ({Node A} + {Node B}: the same for a request and
    its response, whose nodes are swapped): it has no bytes at a fixed offset, so a response
    finds its request with the value its walk computed, and request{Quantity} reads it. A
    response captured twice is a duplicate, not paired, and its copy reads the same request."""

    RULES = """<root name="Computed key test" abbreviation="CKEY" byteorder="big">
  <hook table="udp.port" value="47600"/>
  <pairing>
    <key field="node[@name='Transaction']"/>
    <key field="node[@name='Node pair']"/>
    <request field="node[@name='Is response']" in="0"/>
  </pairing>
  <node name="Transaction" length="1byte" displaytype="numberhex"/>
  <node name="Is response" length="1byte" displaytype="numberdec"/>
  <node name="Node A" length="1byte" displaytype="numberdec"/>
  <node name="Node B" length="1byte" displaytype="numberdec"/>
  <node name="Node pair" value="{Node A} + {Node B}"/>
  <node name="Quantity" length="1byte" displaytype="numberdec">
    <when field="../node[@name='Is response']" in="0"/>
  </node>
  <node name="Asked" value="request{Quantity}">
    <when field="../node[@name='Is response']" in="1"/>
  </node>
</root>
"""

    @classmethod
    def prepare(cls):
        cls.install_text("computed_key.xml", cls.RULES, "ckey")

    def test_a_response_reads_its_request_by_a_computed_key(self):
        # (transaction, is response, node A, node B, quantity): requests of two node pairs with
        # the same transaction, answered in the other order; a response of a third pair: no request
        messages = [(7, 0, 1, 10, 5), (7, 0, 2, 30, 9), (7, 1, 30, 2, None), (7, 1, 10, 1, None),
                    (7, 1, 4, 4, None)]
        frames = []
        for t, is_response, a, b, quantity in messages:
            payload = bytes([t, is_response, a, b] + ([] if quantity is None else [quantity]))
            client, server = (40000, (10, 0, 0, 10)), (47600, (10, 0, 0, 1))
            (sport, src), (dport, dst) = (server, client) if is_response else (client, server)
            frames.append(udp(sport, dport, payload, src, dst))
        frames.append(frames[3])  # 6: frame 4 captured twice: a duplicate, not paired, decoded as frame 4
        path = self.env.add_file("computed_key.pcap", pcapgen.raw_pcap_bytes(frames))
        with self.checks() as check:
            for two_pass in (False, True):
                rows = self.env.field_rows(path, ["frame.number", "ckey.request_in", "ckey.asked",
                                                  "ckey.expert.no_request_context"], two_pass=two_pass)
                got = {n: (r["ckey.request_in"], r["ckey.asked"], bool(r["ckey.expert.no_request_context"]))
                       for n, r in rows.items() if n >= 3}
                want = {3: (["2"], ["9"], False), 4: (["1"], ["5"], False), 5: ([], [], True),
                        6: ([], ["5"], False)}
                check(got == want, "%s: %s, expected %s" % ("-2" if two_pass else "one pass", got, want))



class TestRequestsReadNoRequest(TsharkTestCase, unittest.TestCase):
    """A layout shared by requests and responses, its request{...} value without an `if`: a
    request (by the <request> field decoded before the value, or by the port it goes to)
    answers none, so it shows no value and no no_request_context note, even when its key
    repeats a request still waiting (a retransmission), and a count from that value ends its
    decoding quietly (not malformed); a response reads its request, and one whose request was
    not captured gets the note."""

    RULES = """<root name="Shared layout {how}" abbreviation="{abbreviation}" byteorder="big">
  <hook table="udp.port" value="{port}"/>
  <pairing>
    <key field="node[@name='Sequence']"/>
    {request}
  </pairing>
  <node name="Type" length="1byte" displaytype="numberdec"/>
  <node name="Sequence" length="2byte" displaytype="numberdec"/>
  <node name="Command" length="1byte" displaytype="numberdec"/>
  <node name="Asked" value="request{{Command}}"/>
  <node name="Items" count="../node[@name='Asked']">
    <node name="Item" length="1byte" displaytype="numberdec"/>
  </node>
</root>
"""
    KINDS = (("by field", "SHRF", 47610, '<request field="node[@name=\'Type\']" in="0"/>'),
             ("by port", "SHRP", 47611, ""))

    @classmethod
    def prepare(cls):
        for how, abbreviation, port, request in cls.KINDS:
            cls.install_text(abbreviation.lower() + ".xml", cls.RULES.format(
                how=how, abbreviation=abbreviation, port=port, request=request), abbreviation.lower())

    def test_requests_are_quiet_and_responses_read_theirs(self):
        # (type, sequence, command): a request, sent again; its response; a response whose
        # request was not captured
        messages = [(0, 5, 3), (0, 5, 3), (1, 5, 3), (1, 9, 1)]
        with self.checks() as check:
            for how, abbreviation, port, _ in self.KINDS:
                frames = []
                for kind, sequence, command in messages:
                    client, server = (40000, (10, 0, 0, 10)), (port, (10, 0, 0, 1))
                    (sport, src), (dport, dst) = (server, client) if kind else (client, server)
                    items = bytes(range(command)) if kind and sequence == 5 else b""  # the answer's items
                    frames.append(udp(sport, dport, struct.pack("!BHB", kind, sequence, command) + items, src, dst))
                path = self.env.add_file("shared_layout_%d.pcap" % port, pcapgen.raw_pcap_bytes(frames))
                p = abbreviation.lower()
                for two_pass in (False, True):
                    rows = self.env.field_rows(path, ["frame.number", p + ".asked", p + ".items.item",
                                                      p + ".expert.no_request_context", "_ws.expert.severity"],
                                               two_pass=two_pass)
                    got = {n: (r[p + ".asked"], r[p + ".items.item"], bool(r[p + ".expert.no_request_context"]),
                               r["_ws.expert.severity"]) for n, r in rows.items()}
                    note = ["4194304"]  # PI_NOTE, and nothing more serious (2: the pairing's duplicate)
                    want = {1: ([], [], False, []), 2: ([], [], False, note), 3: (["3"], ["0", "1", "2"], False, []),
                            4: ([], [], True, note)}
                    check(got == want, "%s, %s: %s, expected %s" % (how, "-2" if two_pass else "one pass", got, want))


class TestRoleDecodedAfterReader(TsharkTestCase, unittest.TestCase):
    """The <unanswered> or <request> field decoded after the first request{...} (dissgen check
    warns): a message it makes one that expects no response, or a request (here sent from the
    service's port, whose direction says response), gets no no_request_context note, though the
    value read before it missed; a response whose request was not captured still does."""

    RULES = """<root name="Late role {how}" abbreviation="{abbreviation}" byteorder="big">
  <hook table="udp.port" value="{port}"/>
  <pairing>
    <key field="node[@name='Sequence']"/>
    {role}
  </pairing>
  <node name="Sequence" length="2byte" displaytype="numberdec"/>
  <node name="Command" length="1byte" displaytype="numberdec"/>
  <node name="Asked" value="request{{Command}}"/>
  <node name="Type" length="1byte" displaytype="numberdec"/>
</root>
"""
    KINDS = (("unanswered", "LRU", 47612, '<unanswered field="node[@name=\'Type\']" in="2"/>', 2),
             ("request", "LRR", 47613, '<request field="node[@name=\'Type\']" in="0"/>', 0))

    @classmethod
    def prepare(cls):
        for how, abbreviation, port, role, _type in cls.KINDS:
            cls.install_text(abbreviation.lower() + ".xml", cls.RULES.format(
                how=how, abbreviation=abbreviation, port=port, role=role), abbreviation.lower())

    def test_only_responses_miss_their_request(self):
        with self.checks() as check:
            for how, abbreviation, port, _role, quiet_type in self.KINDS:
                # from the service's port: the quiet message, then a response whose request is not here
                frames = [udp(port, 40000, struct.pack("!HBB", sequence, 4, kind), (10, 0, 0, 1), (10, 0, 0, 10))
                          for sequence, kind in ((7, quiet_type), (9, 1))]
                path = self.env.add_file("late_role_%d.pcap" % port, pcapgen.raw_pcap_bytes(frames))
                p = abbreviation.lower()
                for two_pass in (False, True):
                    rows = self.env.field_rows(path, ["frame.number", p + ".expert.no_request_context"],
                                               two_pass=two_pass)
                    noted = [n for n, r in sorted(rows.items()) if r[p + ".expert.no_request_context"]]
                    check(noted == [2], "%s, %s: the note on %s, expected on frame 2 only" %
                          (how, "-2" if two_pass else "one pass", noted))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The generic pairing knows direction: a message to the hooked port is a request, one from it
a response (tests/rules/transactions.xml, UDP port 47480, keys: transaction and unit).

  test_transactions.py --dissgen build/bin/dissgen --source-dir .

A response never opens a transaction and a request never answers one: a response whose request
was not captured is linked to nothing, and the request that follows with the same key waits
for its own response. A request sent again with the same key gives up the first one, which is
reported lost (with -2 on itself, in one pass on the request that proved it), and so is one the
capture goes on for longer than the timeout after; one the capture ends exactly the timeout after
is still in flight. A protocol whose only key is a computed value (its walk reads no byte)
still tells a message sent again with other bytes from a duplicate by the message's bytes.
A request overtaken by the answers to 16 later requests still waits, by 17 it is lost; only
requests on its own connection count. Over TCP the connection is the client: requests a server
sends from its own port on two connections, with the same key, are paired apart. Over UDP a
response sent to a group address answers the latest request with its key sent to a group. A
request sent to a group (over UDP or right over Ethernet) takes every station's answer.
Needs no corpus.
"""

import os
import struct
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkTestCase, run_unittests  # noqa: E402
import pcapgen  # noqa: E402
from test_enip import TcpFlow  # noqa: E402

ARGS = None
PORT = 47480
CLIENT, SERVER = b"\x0a\x00\x00\x01", b"\x0a\x00\x00\x02"

# (ms, direction, transaction, unit): the capture, frame by frame.
MESSAGES = [
    (0, "response", 1, 1),    # 1: its request was not captured: an orphan
    (10, "request", 1, 1),    # 2: a new request, not an answer to 1
    (11, "response", 1, 1),   # 3: answers 2
    (20, "request", 2, 1),    # 4: lost: sent again as 5
    (30, "request", 2, 1),    # 5
    (31, "response", 2, 1),   # 6: answers 5
    (50, "request", 4, 1),    # 7
    (51, "request", 4, 2),    # 8: another unit, another key
    (52, "response", 4, 2),   # 9: answers 8
    (53, "response", 4, 1),   # 10: answers 7
    (60, "response", 5, 1),   # 11: an orphan
    (70, "response", 5, 1),   # 12: another orphan (a response never answers a response)
    (80, "request", 5, 1),    # 13
    (81, "response", 5, 1),   # 14: answers 13
    (100, "request", 7, 1),   # 15: lost: 17 comes more than the timeout (1 s) after it
    (101, "request", 6, 1),   # 16: in flight: 17 comes exactly the timeout after it
    (1101, "response", 8, 1), # 17: an orphan, the capture's last message
]
PAIRS = {3: 2, 6: 5, 9: 8, 10: 7, 14: 13}
LOST = {4: 5, 15: 17}  # lost request: the frame that proves it


def udp_frame(src, dst, sport, dport, payload):
    """An Ethernet frame of an IPv4 UDP datagram (the MAC addresses are not read)."""
    u = struct.pack("!HHHH", sport, dport, 8 + len(payload), 0) + payload
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(u), 0, 0x4000, 64, 17, 0, src, dst)
    ip = ip[:10] + struct.pack("!H", pcapgen.ip_checksum(ip)) + ip[12:]
    return b"\x02\x00\x00\x00\x00\x02\x02\x00\x00\x00\x00\x01\x08\x00" + ip + u


def frame(direction, transaction, unit, n, client_port=40000, client=CLIENT):
    payload = struct.pack(">HBBI", transaction, unit, 3, n)
    if direction == "request":
        return udp_frame(client, SERVER, client_port, PORT, payload)
    return udp_frame(SERVER, client, PORT, client_port, payload)


def write_frames(path, frames):
    """A pcap file of (ms, bytes), readable by the unprivileged tshark."""
    out = [struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)]
    for ms, data in frames:
        out.append(struct.pack("<IIII", 1_700_000_000 + ms // 1000, ms % 1000 * 1000, len(data), len(data)) + data)
    with open(path, "wb") as fh:
        fh.write(b"".join(out))
    os.chmod(path, 0o644)


def write(path, messages=MESSAGES):
    """messages: (ms, direction, transaction, unit[, the client's port[, its address]])."""
    write_frames(path, [(m[0], frame(m[1], m[2], m[3], n + 1, *m[4:])) for n, m in enumerate(messages)])


def decode(env, path, two_pass, more=()):
    """{frame number: {field: its values, comma-separated}}."""
    fields = ["frame.number", "txnp.request_in", "txnp.response_in", "txnp.expert.no_response",
              "txnp.no_response_to", "txnp.time"] + list(more)
    return {n: {f: ",".join(v) for f, v in r.items()} for n, r in env.field_rows(path, fields, two_pass).items()}


class TestTransactions(TsharkTestCase, unittest.TestCase):
    KEY_TEXT = "0x%04x"  # the transaction in the no-response note, as its field shows it

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "transactions.xml"), "txnp")

    def test_no_response_note_names_the_key_as_its_field_shows_it(self):
        path = self.env.path("notes.pcap")
        write(path)
        rows = self.env.field_rows(path, ["frame.number", "_ws.expert.message"], False, aggregator="|")
        notes = {n: [m for m in r["_ws.expert.message"] if m.startswith("No response to")] for n, r in rows.items()}
        want = {proof: ["No response to frame %d (Transaction %s), sent %.3f ms before" % (
                    lost, self.KEY_TEXT % MESSAGES[lost - 1][2], MESSAGES[proof - 1][0] - MESSAGES[lost - 1][0])]
                for lost, proof in LOST.items()}
        self.assertEqual({n: m for n, m in notes.items() if m}, want)

    def test_requests_and_responses_paired_by_direction(self):
        env = self.env
        path = env.path("transactions.pcap")
        write(path)
        with self.checks() as check:
            for two_pass in (True, False):
                mode = "-2" if two_pass else "one pass"
                rows = decode(env, path, two_pass)
                got = {n: int(r["txnp.request_in"]) for n, r in rows.items() if r["txnp.request_in"]}
                check(got == PAIRS, "%s: each response answers its own request, orphans answer nothing "
                      "(%s)" % (mode, got))
                if two_pass:
                    back = {int(r["txnp.response_in"]): n for n, r in rows.items() if r["txnp.response_in"]}
                    check(back == PAIRS, "%s: each answered request links its response (%s)" % (mode, back))
                    flagged = {n for n, r in rows.items() if r["txnp.expert.no_response"]}
                    check(flagged == set(LOST), "%s: no_response exactly on the lost requests %s (%s)" % (
                        mode, sorted(LOST), sorted(flagged)))
                else:
                    flagged = {n: r["txnp.no_response_to"] for n, r in rows.items() if r["txnp.expert.no_response"]}
                    want = {proof: str(lost) for lost, proof in LOST.items()}
                    check(flagged == want, "%s: no_response on the frame that proves the loss, naming it "
                          "(%s, want %s)" % (mode, flagged, want))
                times = {n: r["txnp.time"] for n, r in rows.items() if r["txnp.time"]}
                want = {n: "%.9f" % ((MESSAGES[n - 1][0] - MESSAGES[m - 1][0]) / 1000) for n, m in PAIRS.items()}
                check(times == want, "%s: round trips are the timestamps' differences (%s)" % (mode, times))


class TestTwoClients(TsharkTestCase, unittest.TestCase):
    """Two clients using the same key values are paired apart: a response answers the
    request of the client it is sent to (as Wireshark's Modbus/TCP pairs by conversation)."""
    OTHER = b"\x0a\x00\x00\x03"

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "transactions.xml"), "txnp")

    def test_each_response_answers_its_own_client(self):
        a, b = (40000, CLIENT), (40000, self.OTHER)
        messages = [(0, "request", 1, 1) + a, (1, "request", 1, 1) + b,    # 1, 2: the same key
                    (2, "response", 1, 1) + b, (3, "response", 1, 1) + a,  # 3 answers 2, 4 answers 1
                    (10, "request", 2, 1) + b, (11, "response", 2, 1) + a, # 6: an orphan (A asked nothing)
                    (12, "response", 2, 1) + b]                            # 7 answers 5
        path = self.env.path("two-clients.pcap")
        write(path, messages)
        with self.checks() as check:
            for two_pass in (True, False):
                rows = decode(self.env, path, two_pass)
                got = {n: int(r["txnp.request_in"]) for n, r in rows.items() if r["txnp.request_in"]}
                check(got == {3: 2, 4: 1, 7: 5}, "%s: each response answers its client's request (%s)" % (
                    "-2" if two_pass else "one pass", got))


class TestTransactionsDecimalKey(TestTransactions):
    """The same protocol with its transaction shown in decimal: so is it in the note."""
    KEY_TEXT = "%d"

    @classmethod
    def prepare(cls):
        with open(os.path.join(cls.args.source_dir, "tests", "rules", "transactions.xml"), encoding="utf-8") as f:
            text = f.read()
        decimal = text.replace('name="Transaction" length="2byte" displaytype="numberhex"',
                               'name="Transaction" length="2byte" displaytype="numberdec"')
        assert decimal != text
        path = cls.env.path("transactions_decimal.xml")
        with open(path, "w", encoding="utf-8") as f:
            f.write(decimal)
        cls.install(path, "txnp")


class TestOvertaken(TsharkTestCase, unittest.TestCase):
    """A request waits for its response while the responses to at most 16 later requests come
    first (a reordering): the response after 16 answers it; after 17 the request was given up
    (lost) and the late response answers nothing."""

    @classmethod
    def prepare(cls):
        cls.install(os.path.join("tests", "rules", "transactions.xml"), "txnp")

    @staticmethod
    def overtaken_by(later):
        """Request 0x100, `later` requests each answered at once, then 0x100's response."""
        messages = [(0, "request", 0x100, 1)]
        for k in range(later):
            messages += [(1 + 2 * k, "request", k + 1, 1), (2 + 2 * k, "response", k + 1, 1)]
        return messages + [(2 * later + 1, "response", 0x100, 1)]

    def test_sixteen_later_answers_wait_seventeen_give_up(self):
        with self.checks() as check:
            for later in (16, 17):
                messages = self.overtaken_by(later)
                path = self.env.path("overtaken_%d.pcap" % later)
                write(path, messages)
                last = len(messages)
                for two_pass in (True, False):
                    rows = decode(self.env, path, two_pass)
                    mode = "-2" if two_pass else "one pass"
                    answered = rows[last]["txnp.request_in"]
                    lost = {n for n, r in rows.items() if r["txnp.expert.no_response"]}
                    if later == 16:
                        check(answered == "1" and not lost, "%s: overtaken by 16, frame %d answers frame 1, "
                              "nothing lost (request_in %r, lost %s)" % (mode, last, answered, sorted(lost)))
                    else:
                        proof = last if not two_pass else 1
                        check(answered == "" and lost == {proof}, "%s: overtaken by 17, frame 1 lost (noted on "
                              "frame %d), frame %d an orphan (request_in %r, lost %s)" % (
                                  mode, proof, last, answered, sorted(lost)))

    def test_other_connections_overtake_nothing(self):
        """Order is per connection: 20 exchanges on another client port, then one answered
        on the request's own, overtake it once, not 21 times: its late response answers it
        (out of order), and nothing is lost."""
        messages = [(0, "request", 0x100, 1, 40001)]
        for k in range(20):
            messages += [(1 + 2 * k, "request", k + 1, 1, 40002), (2 + 2 * k, "response", k + 1, 1, 40002)]
        messages += [(50, "request", 0x200, 1, 40001), (51, "response", 0x200, 1, 40001),
                     (60, "response", 0x100, 1, 40001)]
        path = self.env.path("other_connections.pcap")
        write(path, messages)
        last = len(messages)
        with self.checks() as check:
            for two_pass in (True, False):
                rows = decode(self.env, path, two_pass)
                lost = {n for n, r in rows.items() if r["txnp.expert.no_response"]}
                check(rows[last]["txnp.request_in"] == "1" and not lost,
                      "%s: frame %d answers frame 1, nothing lost (request_in %r, lost %s)" % (
                          "-2" if two_pass else "one pass", last, rows[last]["txnp.request_in"], sorted(lost)))


class TestComputedKey(TsharkTestCase, unittest.TestCase):
    """Keyed by a computed value alone, the walk decodes no byte of the message: whether a
    message from the same sender soon after is the same again (a duplicate) or a new request
    is still told by all of its bytes, not by the none the walk read. A copy exactly a
    hundredth of the timeout later is a duplicate, to the nanosecond (0.7 s / 100 is not 7 ms
    in floating point)."""

    RULES = """<root name="Transactions Protocol" abbreviation="TXNP" byteorder="big">
  <hook table="udp.port" value="%d"/>
  <pairing timeout="0.7"><key field="node[@name='Channel']"/></pairing>
  <node name="Channel" value="7" displaytype="numberdec"/>
</root>
""" % PORT
    # (ms, direction, n): n is the payload's last field, so equal n means equal bytes
    CAPTURE = [(0, "request", 1),   # 1: given up: 2 is a new request with other bytes
               (1, "request", 2),   # 2
               (2, "response", 3),  # 3: answers 2
               (100, "request", 4), # 4
               (101, "request", 4), # 5: the same bytes again at once: a duplicate of 4
               (102, "response", 5),  # 6: answers 4
               (200, "request", 6),   # 7
               (207, "request", 6),   # 8: a hundredth of the timeout (7 ms) later, exactly: a duplicate of 7
               (212, "response", 7),  # 9: answers 7
               (300, "request", 8),   # 10: given up: 11 is the sender's next request
               (308, "request", 8),   # 11: 8 ms later: the same bytes, a new request
               (312, "response", 9)]  # 12: answers 11

    @classmethod
    def prepare(cls):
        cls.install_text("computed_key.xml", cls.RULES, "txnp")

    def test_other_bytes_are_a_new_request_the_same_bytes_a_duplicate(self):
        path = self.env.path("computed_key.pcap")
        write_frames(path, [(ms, frame(direction, 1, 1, n)) for ms, direction, n in self.CAPTURE])
        with self.checks() as check:
            for two_pass in (True, False):
                rows = self.env.field_rows(path, ["frame.number", "txnp.request_in", "txnp.expert.duplicate"],
                                           two_pass)
                pairs = {n: int(r["txnp.request_in"][0]) for n, r in rows.items() if r["txnp.request_in"]}
                duplicates = {n for n, r in rows.items() if r["txnp.expert.duplicate"]}
                mode = "-2" if two_pass else "one pass"
                check(pairs == {3: 2, 6: 4, 9: 7, 12: 11}, "%s: responses answer 2, 4, 7 and 11 (%s)" % (mode, pairs))
                check(duplicates == {5, 8}, "%s: only frames 5 and 8 are duplicates (%s)" % (mode, sorted(duplicates)))


class TestRequestRole(TsharkTestCase, unittest.TestCase):
    """<request field="Kind" in="1"/>: the message says whether it is a request, whichever
    side sends it. A request from the server's port (a station asking its master) is
    answered by the message to that port; two peers that both use the port pair by Kind; a
    message without Kind goes by the port as before."""

    RULES = """<root name="Transactions Protocol" abbreviation="TXNP" byteorder="big">
  <hook table="udp.port" value="%d"/>
  <pairing timeout="1">
    <key field="node[@name='Transaction']"/>
    <request field="node[@name='Kind']" in="1"/>
  </pairing>
  <node name="Transaction" length="2byte" displaytype="numberhex"/>
  <node name="Has kind" length="1byte" displaytype="numberdec"/>
  <node name="Kind" length="1byte" displaytype="numberdec" if="../node[@name='Has kind']" in="1"/>
  <node name="Number" length="4byte" displaytype="numberdec"/>
  <node name="Answer" if="../node[@name='Kind']" in="2">
    <node name="Asked" value="request{Number}" displaytype="numberdec"/>
  </node>
</root>
""" % PORT
    # (ms, sent by the server, source port, destination port, transaction, kind: None when the
    # message has none)
    CAPTURE = [(0, False, 40000, PORT, 1, 1),      # 1: a request to the server
               (1, True, PORT, 40000, 1, 2),       # 2: answers 1
               (10, True, PORT, 40000, 2, 1),      # 3: a request from the server's port
               (11, False, 40000, PORT, 2, 2),     # 4: answers 3, though sent to the port
               (20, True, PORT, PORT, 3, 1),       # 5: peers on the same port: a request
               (21, False, PORT, PORT, 3, 2),      # 6: answers 5
               (30, False, 40000, PORT, 4, None),  # 7: no Kind: to the port, a request
               (31, True, PORT, 40000, 4, None),   # 8: from the port, answers 7
               (40, True, PORT, 40000, 5, 1),      # 9: a request from the port, never answered
               (1100, False, 40000, PORT, 6, 1),   # 10
               (1101, True, PORT, 40000, 6, 2)]    # 11: answers 10, proves 9 lost (older than the timeout)
    PAIRS = {2: 1, 4: 3, 6: 5, 8: 7, 11: 10}
    LOST = {9: 11}

    @classmethod
    def prepare(cls):
        cls.install_text("request_role.xml", cls.RULES, "txnp")

    @staticmethod
    def message(from_server, sport, dport, transaction, kind, n):
        head = struct.pack(">HB", transaction, 0) if kind is None else struct.pack(">HBB", transaction, 1, kind)
        src, dst = (SERVER, CLIENT) if from_server else (CLIENT, SERVER)
        return udp_frame(src, dst, sport, dport, head + struct.pack(">I", n))

    def test_the_message_says_which_it_is(self):
        path = self.env.path("request_role.pcap")
        write_frames(path, [(ms, self.message(*m, n)) for n, (ms, *m) in enumerate(self.CAPTURE, 1)])
        with self.checks() as check:
            for two_pass in (True, False):
                mode = "-2" if two_pass else "one pass"
                rows = decode(self.env, path, two_pass, ["txnp.answer.asked", "txnp.expert.no_request_context"])
                pairs = {n: int(r["txnp.request_in"]) for n, r in rows.items() if r["txnp.request_in"]}
                check(pairs == self.PAIRS, "%s: each response answers its request (%s)" % (mode, pairs))
                flagged = {n for n, r in rows.items() if r["txnp.expert.no_response"]}
                want = set(self.LOST) if two_pass else set(self.LOST.values())
                check(flagged == want, "%s: no_response on %s only (%s)" % (mode, sorted(want), sorted(flagged)))
                # request{Number} in each response with Kind: its request's number, whichever port it went to
                asked = {n: r["txnp.answer.asked"] for n, r in rows.items() if r["txnp.answer.asked"]}
                want = {n: str(m) for n, m in self.PAIRS.items() if self.CAPTURE[n - 1][-1] == 2}
                check(asked == want, "%s: request{Number} %s, expected %s" % (mode, asked, want))
                missed = sorted(n for n, r in rows.items() if r["txnp.expert.no_request_context"])
                check(not missed, "%s: no 'request not known' note (%s)" % (mode, missed))


class TestGroupAddressed(TsharkTestCase, unittest.TestCase):
    """A response sent to a group address (an IPv4 multicast or the limited broadcast) names
    no client: it answers the latest request with its key values sent to a group, whoever
    sent it, as PTP's Delay_Resp (to 224.0.1.129) answers a slave's Delay_Req. Two clients
    asking in turn are each answered; request{Number} reads the request it answers."""

    A, B, MASTER = CLIENT, b"\x0a\x00\x00\x03", SERVER
    GROUP, BROADCAST = b"\xe0\x00\x01\x81", b"\xff\xff\xff\xff"
    # (ms, source, destination, transaction, kind): every message on the hooked port both ways
    CAPTURE = [(0, A, GROUP, 1, 1),          # 1: A asks the group
               (1, MASTER, GROUP, 1, 2),     # 2: answers 1
               (10, B, GROUP, 2, 1),         # 3: B asks
               (11, A, GROUP, 3, 1),         # 4: A asks
               (12, MASTER, GROUP, 3, 2),    # 5: answers 4
               (13, MASTER, GROUP, 2, 2),    # 6: answers 3, B's
               (20, MASTER, GROUP, 9, 2),    # 7: nobody asked: an orphan
               (30, B, BROADCAST, 5, 1),     # 8: B asks every station
               (31, MASTER, BROADCAST, 5, 2),  # 9: answers 8, to every station
               (40, A, GROUP, 6, 1),         # 10: A asks the group
               (41, MASTER, A, 6, 2)]        # 11: answers 10, to A itself
    PAIRS = {2: 1, 5: 4, 6: 3, 9: 8, 11: 10}

    # A's request is forgotten (10 timeouts old) after B asked with the same key: B's
    # client stays the one a group-addressed answer goes to.
    FORGOTTEN = [(100, A, GROUP, 7, 1),          # 1: A asks; never answered: lost
                 (10000, B, GROUP, 7, 1),        # 2: B asks with the same key
                 (10200, A, MASTER, 8, 1),       # 3
                 (10300, MASTER, A, 8, 2),       # 4: answers 3; A's key (1) is forgotten here
                 (10400, MASTER, GROUP, 7, 2)]   # 5: answers 2, B's
    FORGOTTEN_PAIRS = {4: 3, 5: 2}

    @classmethod
    def prepare(cls):
        cls.install_text("request_role.xml", TestRequestRole.RULES, "txnp")

    @staticmethod
    def message(src, dst, transaction, kind, n):
        return udp_frame(src, dst, PORT, PORT, struct.pack(">HBBI", transaction, 1, kind, n))

    def test_a_response_to_a_group_answers_its_requests_sender(self):
        path = self.env.path("group.pcap")
        write_frames(path, [(ms, self.message(*m, n)) for n, (ms, *m) in enumerate(self.CAPTURE, 1)])
        with self.checks() as check:
            for two_pass in (True, False):
                mode = "-2" if two_pass else "one pass"
                rows = decode(self.env, path, two_pass, ["txnp.answer.asked"])
                pairs = {n: int(r["txnp.request_in"]) for n, r in rows.items() if r["txnp.request_in"]}
                check(pairs == self.PAIRS, "%s: each response answers its request (%s)" % (mode, pairs))
                asked = {n: r["txnp.answer.asked"] for n, r in rows.items() if r["txnp.answer.asked"]}
                want = {n: str(m) for n, m in self.PAIRS.items()}
                check(asked == want, "%s: request{Number} %s, expected %s" % (mode, asked, want))
                lost = sorted(n for n, r in rows.items() if r["txnp.expert.no_response"])
                check(not lost, "%s: no request lost (%s)" % (mode, lost))

    def test_a_forgotten_request_leaves_a_later_clients_answer_alone(self):
        path = self.env.path("group-forgotten.pcap")
        write_frames(path, [(ms, self.message(*m, n)) for n, (ms, *m) in enumerate(self.FORGOTTEN, 1)])
        with self.checks() as check:
            for two_pass in (True, False):
                rows = decode(self.env, path, two_pass)
                pairs = {n: int(r["txnp.request_in"]) for n, r in rows.items() if r["txnp.request_in"]}
                check(pairs == self.FORGOTTEN_PAIRS, "%s: each response answers its request (%s)" % (
                    "-2" if two_pass else "one pass", pairs))


class TestGroupRequestManyAnswers(TsharkTestCase, unittest.TestCase):
    """A request sent to a group (a broadcast or multicast address, over UDP or right over
    Ethernet) is answered by every station that answers it with its key within the timeout,
    as PROFINET DCP's Identify All or EtherNet/IP's ListIdentity are: each answer links to it
    and reads its values, the request (with -2) links to each, and, answered, it is not lost
    when its sender asks again or its timeout passes. A group request nobody answers is lost as
    before; a unicast request still takes one answer."""

    A, D1, D2, D3 = CLIENT, SERVER, b"\x0a\x00\x00\x03", b"\x0a\x00\x00\x04"
    B = b"\x0a\x00\x00\x05"  # another station that asks
    GROUP, BROADCAST = b"\xe0\x00\x01\x81", b"\xff\xff\xff\xff"
    SUBNET = b"\x0a\x00\x00\xff"  # 10.0.0.255: a broadcast only its Ethernet address tells
    # (ms, source, destination, transaction, kind): 1 a request, 2 a response
    CAPTURE = [(0, A, BROADCAST, 1, 1),   # 1: A asks every station
               (1, D1, A, 1, 2),          # 2: answers 1
               (2, D2, A, 1, 2),          # 3: answers 1 too
               (3, D3, A, 1, 2),          # 4: and so does a third station
               (10, A, D1, 2, 1),         # 5: a unicast request
               (11, D1, A, 2, 2),         # 6: answers 5
               (12, D2, A, 2, 2),         # 7: 5 was answered, and to D1 alone: an orphan
               (20, A, GROUP, 3, 1),      # 8: nobody answers: lost
               (1500, A, BROADCAST, 4, 1),  # 9: past 8's timeout, after a quiet spell
               (1501, D1, A, 4, 2),       # 10: answers 9, and proves 8 lost (the second message after it)
               (1502, A, BROADCAST, 4, 1),  # 11: A asks again: 9, answered, is not lost
               (1503, D2, A, 4, 2),       # 12: answers 11
               (3000, D3, A, 4, 2)]       # 13: past 11's timeout: an orphan; 11 is not lost
    PAIRS = {2: 1, 3: 1, 4: 1, 6: 5, 10: 9, 12: 11}
    RESPONSES_IN = {1: "2,3,4", 5: "6", 9: "10", 11: "12"}
    ORPHANS = {7, 13}
    LOST = {8: 10}

    ETHERTYPE = 0x88B6
    ETHER_RULES = TestRequestRole.RULES.replace('<hook table="udp.port" value="%d"/>' % PORT,
                                                '<hook table="ethertype" value="0x%04x"/>' % ETHERTYPE)
    MAC = {A: b"\x02\x00\x00\x00\x00\x01", D1: b"\x02\x00\x00\x00\x00\x02",
           D2: b"\x02\x00\x00\x00\x00\x03", D3: b"\x02\x00\x00\x00\x00\x04", B: b"\x02\x00\x00\x00\x00\x05",
           GROUP: b"\x01\x0e\xcf\x00\x00\x00", BROADCAST: b"\xff\xff\xff\xff\xff\xff"}

    @classmethod
    def prepare(cls):
        assert cls.ETHER_RULES != TestRequestRole.RULES
        cls.install_text("request_role.xml", TestRequestRole.RULES, "txnp")
        cls.install_text("request_role_ether.xml", cls.ETHER_RULES.replace(
            'name="Transactions Protocol" abbreviation="TXNP"', 'name="Transactions over Ethernet" abbreviation="TXNE"'),
            "txne")

    def udp_message(self, src, dst, transaction, kind, n):
        frame = udp_frame(src, dst, PORT if kind == 2 else 40000, 40000 if kind == 2 else PORT,
                          struct.pack(">HBBI", transaction, 1, kind, n))
        return self.MAC[self.BROADCAST] + frame[6:] if dst == self.SUBNET else frame

    def ether_message(self, src, dst, transaction, kind, n):
        return self.MAC[dst] + self.MAC[src] + struct.pack(">HHBBI", self.ETHERTYPE, transaction, 1, kind, n)

    def check_capture(self, name, message, proto, capture=CAPTURE):
        path = self.env.path(name)
        write_frames(path, [(ms, message(*m, n)) for n, (ms, *m) in enumerate(capture, 1)])
        with self.checks() as check:
            for two_pass in (True, False):
                mode = "%s %s" % (name, "-2" if two_pass else "one pass")
                fields = ["frame.number"] + [proto + f for f in (
                    ".request_in", ".response_in", ".expert.no_response", ".no_response_to", ".no_request",
                    ".answer.asked", ".expert.out_of_order", ".expert.duplicate")]
                rows = {n: {f[len(proto) + 1:]: ",".join(v) for f, v in r.items()}
                        for n, r in self.env.field_rows(path, fields, two_pass).items()}
                check(len(rows) == len(self.CAPTURE), "%s: every frame decoded (%d)" % (mode, len(rows)))
                pairs = {n: int(r["request_in"]) for n, r in rows.items() if r["request_in"]}
                check(pairs == self.PAIRS, "%s: each answer links to its request (%s)" % (mode, pairs))
                asked = {n: r["answer.asked"] for n, r in rows.items() if r["answer.asked"]}
                check(asked == {n: str(m) for n, m in self.PAIRS.items()},
                      "%s: each answer reads its request's Number (%s)" % (mode, asked))
                linked = {n: r["response_in"] for n, r in rows.items() if r["response_in"]}
                check(linked == (self.RESPONSES_IN if two_pass else {}),
                      "%s: the requests link to their answers (%s)" % (mode, linked))
                orphans = {n for n, r in rows.items() if r["no_request"]}
                check(orphans == self.ORPHANS, "%s: orphans %s" % (mode, sorted(orphans)))
                flagged = {n for n, r in rows.items() if r["expert.no_response"]}
                want = set(self.LOST) if two_pass else set(self.LOST.values())
                check(flagged == want, "%s: no_response on %s only (%s)" % (mode, sorted(want), sorted(flagged)))
                proofs = {n: r["no_response_to"] for n, r in rows.items() if r["no_response_to"]}
                check(proofs == {p: str(q) for q, p in self.LOST.items()}, "%s: losses proved %s" % (mode, proofs))
                noise = sorted(n for n, r in rows.items() if r["expert.out_of_order"] or r["expert.duplicate"])
                check(not noise, "%s: no out-of-order or duplicate note (%s)" % (mode, noise))

    def test_over_udp_every_station_answers(self):
        self.check_capture("group_many.pcap", self.udp_message, "txnp")

    def test_to_a_subnet_broadcast_every_station_answers(self):
        capture = [(ms, src, self.SUBNET if dst == self.BROADCAST else dst, *rest)
                   for ms, src, dst, *rest in self.CAPTURE]
        self.check_capture("group_many_subnet.pcap", self.udp_message, "txnp", capture)

    def test_over_ethernet_every_station_answers(self):
        self.check_capture("group_many_ether.pcap", self.ether_message, "txne")

    def test_other_requests_of_the_key_come_first(self):
        """Right over Ethernet the key names no client: a request waiting for its first answer
        takes an answer before a group request answered already, and any message of the key
        other than a response ends the group request's wait (where the order decides, one
        response answers a request)."""
        A, B, D1, D2, D3, GROUP = self.A, self.B, self.D1, self.D2, self.D3, self.GROUP
        capture = [(0, A, GROUP, 9, 1),     # 1: a group request
                   (1, D1, A, 9, 2),        # 2: answers 1
                   (2, B, D3, 9, 1),        # 3: another station's request with the key: 1 waits no more
                   (3, D2, A, 9, 2),        # 4: answers 3
                   (10, A, GROUP, 10, 1),   # 5: a group request
                   (11, D1, A, 10, 2),      # 6: answers 5
                   (12, D2, A, 10, None),   # 7: no Kind: the order decides, a new request
                   (13, A, D2, 10, None),   # 8: answers 7
                   (20, A, GROUP, 11, 1),   # 9: a group request
                   (21, B, D3, 11, 1),      # 10: a request with the key before any answer
                   (22, D1, A, 11, 2),      # 11: answers 9, the oldest
                   (23, D3, B, 11, 2),      # 12: answers 10, which waits for its first answer
                   (24, D2, A, 11, 2)]      # 13: answers 9 again
        pairs_wanted = {2: 1, 4: 3, 6: 5, 8: 7, 11: 9, 12: 10, 13: 9}

        def message(src, dst, transaction, kind, n):
            if kind is None:
                return self.MAC[dst] + self.MAC[src] + struct.pack(">HHBI", self.ETHERTYPE, transaction, 0, n)
            return self.ether_message(src, dst, transaction, kind, n)
        path = self.env.path("group_first_answers.pcap")
        write_frames(path, [(ms, message(*m, n)) for n, (ms, *m) in enumerate(capture, 1)])
        with self.checks() as check:
            for two_pass in (True, False):
                mode = "-2" if two_pass else "one pass"
                rows = self.env.field_rows(path, ["frame.number", "txne.request_in", "txne.expert.no_response",
                                                  "txne.no_request", "txne.answer.asked"], two_pass)
                pairs = {n: int(r["txne.request_in"][0]) for n, r in rows.items() if r["txne.request_in"]}
                check(pairs == pairs_wanted, "%s: pairs %s" % (mode, pairs))
                asked = {n: r["txne.answer.asked"] for n, r in rows.items() if r["txne.answer.asked"]}
                check(asked == {n: [str(m)] for n, m in pairs_wanted.items() if capture[n - 1][4] == 2},
                      "%s: each answer reads its own request's Number (%s)" % (mode, asked))
                noise = sorted(n for n, r in rows.items() if r["txne.expert.no_response"] or r["txne.no_request"])
                check(not noise, "%s: nothing lost, no orphan (%s)" % (mode, noise))


class TestKeyFieldNotDecoded(TsharkTestCase, unittest.TestCase):
    """A key field a message does not have is left out of its key: messages without it pair
    with each other, and never with messages that have it (docs/manual.md, <key>)."""

    RULES = """<root name="Transactions Protocol" abbreviation="TXNP" byteorder="big">
  <hook table="udp.port" value="%d"/>
  <pairing timeout="1">
    <key field="node[@name='Transaction']"/>
    <key field="node[@name='Unit']"/>
  </pairing>
  <node name="Transaction" length="2byte" displaytype="numberhex"/>
  <node name="Has unit" length="1byte" displaytype="numberdec"/>
  <node name="Unit" length="1byte" displaytype="numberdec" if="../node[@name='Has unit']" in="1"/>
  <node name="Number" length="4byte" displaytype="numberdec"/>
</root>
""" % PORT
    # (ms, direction, transaction, unit: None when the message has none)
    CAPTURE = [(0, "request", 1, None),   # 1
               (1, "request", 1, 7),      # 2: another key: (1, 7)
               (2, "response", 1, 7),     # 3: answers 2
               (3, "response", 1, None),  # 4: answers 1
               (10, "request", 2, None),  # 5
               (11, "response", 2, 2)]    # 6: (2, 2) is not (2): an orphan; 5 waits
    PAIRS = {3: 2, 4: 1}

    @classmethod
    def prepare(cls):
        cls.install_text("key_not_decoded.xml", cls.RULES, "txnp")

    def test_messages_without_the_field_pair_apart(self):
        def message(direction, transaction, unit, n):
            head = struct.pack(">HB", transaction, 0) if unit is None else struct.pack(">HBB", transaction, 1, unit)
            payload = head + struct.pack(">I", n)
            if direction == "request":
                return udp_frame(CLIENT, SERVER, 40000, PORT, payload)
            return udp_frame(SERVER, CLIENT, PORT, 40000, payload)
        path = self.env.path("key_not_decoded.pcap")
        write_frames(path, [(ms, message(*m, n)) for n, (ms, *m) in enumerate(self.CAPTURE, 1)])
        with self.checks() as check:
            for two_pass in (True, False):
                mode = "-2" if two_pass else "one pass"
                rows = decode(self.env, path, two_pass, ["txnp.no_request"])
                pairs = {n: int(r["txnp.request_in"]) for n, r in rows.items() if r["txnp.request_in"]}
                check(pairs == self.PAIRS, "%s: pairs %s" % (mode, pairs))
                orphans = sorted(n for n, r in rows.items() if r["txnp.no_request"])
                check(orphans == [6], "%s: orphans %s" % (mode, orphans))


class TestServerRequestsOnTwoConnections(TsharkTestCase, unittest.TestCase):
    """Over TCP the key holds the connection (both ends), not just the request's sender: a
    server asking both its clients from its own port with the same transaction (as an ADS
    device sends notifications) pairs each answer with the request on its connection, and
    neither request gives the other up."""

    RULES = TestRequestRole.RULES.replace('table="udp.port"', 'table="tcp.port"')
    SERVER_IP, CLIENT_IP = (10, 0, 0, 2), (10, 0, 0, 1)

    @classmethod
    def prepare(cls):
        assert cls.RULES != TestRequestRole.RULES
        cls.install_text("request_role_tcp.xml", cls.RULES, "txnp")

    def test_each_connection_pairs_apart(self):
        flows = {}
        for client_port in (40000, 40001):
            flows[client_port] = (TcpFlow(PORT, client_port, self.SERVER_IP, self.CLIENT_IP, seq=1000),
                                  TcpFlow(client_port, PORT, self.CLIENT_IP, self.SERVER_IP, seq=5000))

        def message(client_port, from_server, transaction, kind, n):
            flow = flows[client_port][0 if from_server else 1]
            return flow.segment(struct.pack(">HBBI", transaction, 1, kind, n))

        capture = [message(40000, True, 7, 1, 1),    # 1: a request on connection A
                   message(40001, True, 7, 1, 2),    # 2: the same key on connection B
                   message(40001, False, 7, 2, 3),   # 3: answers 2
                   message(40000, False, 7, 2, 4)]   # 4: answers 1
        path = self.env.path("server_requests_tcp.pcap")
        write_frames(path, [(ms, f) for ms, f in enumerate(capture)])
        with self.checks() as check:
            for two_pass in (True, False):
                mode = "-2" if two_pass else "one pass"
                rows = decode(self.env, path, two_pass)
                pairs = {n: int(r["txnp.request_in"]) for n, r in rows.items() if r["txnp.request_in"]}
                check(pairs == {3: 2, 4: 1}, "%s: each answer pairs on its connection (%s)" % (mode, pairs))
                lost = sorted(n for n, r in rows.items() if r["txnp.expert.no_response"])
                check(not lost, "%s: no request given up (%s)" % (mode, lost))


class TestUnanswered(TsharkTestCase, unittest.TestCase):
    """<unanswered field="Function" in="8"/>: a message that expects no response (a
    notification) takes no part in pairing: never lost, never giving up an earlier request
    with its key, never answered; the other requests pair and are lost as before."""

    RULES = """<root name="Transactions Protocol" abbreviation="TXNP" byteorder="big">
  <hook table="udp.port" value="%d"/>
  <pairing timeout="1">
    <key field="node[@name='Transaction']"/>
    <unanswered field="node[@name='Function']" in="8"/>
  </pairing>
  <node name="Transaction" length="2byte" displaytype="numberhex"/>
  <node name="Unit" length="1byte" displaytype="numberdec"/>
  <node name="Function" length="1byte" displaytype="numberdec"/>
  <node name="Data" length="4byte" displaytype="numberhex"/>
  <node name="Answer" direction="response">
    <node name="Asked" value="request{Data}" displaytype="numberdec"/>
  </node>
</root>
""" % PORT
    # (ms, direction, transaction, function)
    CAPTURE = [(0, "request", 1, 3),      # 1
               (1, "response", 1, 3),     # 2: answers 1
               (10, "request", 2, 8),     # 3: a notification
               (20, "request", 2, 8),     # 4: another with the same key: 3 is not given up
               (30, "request", 3, 3),     # 5: lost: the capture goes on past its timeout
               (40, "response", 2, 8),    # 6: a notification the other way: answers nothing
               (1500, "request", 4, 3),   # 7
               (1501, "response", 4, 3),  # 8: answers 7, and (in one pass) tells that 5 is lost
               (1600, "request", 9, 3),   # 9
               (1601, "response", 9, 8),  # 10: a notification with 9's key: answers nothing, reads no request
               (1602, "response", 9, 3)]  # 11: answers 9
    PAIRS, LOST = {2: 1, 8: 7, 11: 9}, {5: 8}

    @classmethod
    def prepare(cls):
        cls.install_text("unanswered.xml", cls.RULES, "txnp")

    def test_notifications_take_no_part_in_pairing(self):
        def message(direction, transaction, function, n):
            data = frame(direction, transaction, 1, n)
            return data[:-5] + bytes([function]) + data[-4:]  # Function sits before the 4-byte Data
        path = self.env.path("unanswered.pcap")
        write_frames(path, [(ms, message(d, t, fn, n)) for n, (ms, d, t, fn) in enumerate(self.CAPTURE, 1)])
        with self.checks() as check:
            for two_pass in (True, False):
                mode = "-2" if two_pass else "one pass"
                rows = decode(self.env, path, two_pass, ["txnp.function", "txnp.answer.asked",
                                                         "txnp.expert.no_request_context"])
                functions = [rows[n]["txnp.function"] for n in sorted(rows)]
                check(functions == [str(m[3]) for m in self.CAPTURE], "%s: functions %s" % (mode, functions))
                pairs = {n: int(r["txnp.request_in"]) for n, r in rows.items() if r["txnp.request_in"]}
                check(pairs == self.PAIRS, "%s: pairs %s" % (mode, pairs))
                flagged = {n for n, r in rows.items() if r["txnp.expert.no_response"]}
                want = set(self.LOST) if two_pass else set(self.LOST.values())
                check(flagged == want, "%s: no_response on %s only (%s)" % (mode, sorted(want), sorted(flagged)))
                asked = {n: r["txnp.answer.asked"] for n, r in rows.items() if r["txnp.answer.asked"]}
                check(asked == {n: str(m) for n, m in self.PAIRS.items()},
                      "%s: each response reads its request's Data, the notifications none (%s)" % (mode, asked))
                noted = sorted(n for n, r in rows.items() if r["txnp.expert.no_request_context"])
                check(not noted, "%s: no 'request not known' note, on the notifications either (%s)" % (mode, noted))


if __name__ == "__main__":
    sys.exit(run_unittests()[1])

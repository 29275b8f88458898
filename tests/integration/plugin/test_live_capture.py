#!/usr/bin/env python3
"""Live capture: real EtherCAT captures replayed on a veth pair, decoded live.

  test_live_capture.py --dissgen build/bin/dissgen --source-dir . [--corpus DIR]

The test makes its own network namespace (`ip netns add`) holding a veth pair va <-> vb,
replays the EtherCAT frames of real captures from ../shared/corpus/ethercat onto va with a
raw socket of its own (this script with --send, keeping the captures' spacing, stretched
twice), and captures on vb with `tshark -i vb` and the installed plugin, once for `-c N`
frames and once for `-a duration:T`. tshark runs as an ordinary user (as root it would
ignore the per-user plugin) with the capture capabilities only (CAP_NET_RAW,
CAP_NET_ADMIN, as the `wireshark` group gives dumpcap). The live decode must equal the
decode of the same frames read from the file, the pairing included (ecatr.request_in,
what the segment did, the expert infos), but for the round-trip times.

Only traffic inside the namespace the test made. Skipped (exit 77, "SKIPPED: ...") when not
root or when network namespaces, veth or capabilities are not available.
"""

import argparse
import os
import select
import socket
import subprocess
import sys
import unittest
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import NOBODY, TsharkTestCase, run_unittests  # noqa: E402
import pcaprewrite as pr  # noqa: E402

CAPTURES = ["soem-sdinfo-ek1100-el1004.pcapng", "replay-sdo-error.pcapng"]
STRETCH = 2.0
FIELDS = ["frame.number", "ecatr.header.length", "ecatr.datagram.cmd", "ecatr.datagram.idx",
          "ecatr.datagram.adp", "ecatr.datagram.ado", "ecatr.datagram.lad", "ecatr.datagram.len",
          "ecatr.datagram.data", "ecatr.datagram.wkc", "ecatr.request_in", "ecatr.esc.wkc_added",
          "ecatr.esc.slaves_passed", "ecatr.esc.data_changed", "ecatr.expert.duplicate",
          "ecatr.expert.out_of_order", "ecatr.expert.changed", "ecatr.expert.frame_length",
          "ecatr.expert.write_changed", "ecatr.expert.wkc_down", "ecatr.expert.forwarding",
          "ecatr.expert.no_response", "ecatr.no_response_to"]
LOST_RETURNS = 5   # returns removed from a copy of the first capture: a live capture reports them
ARGS = None


def ethercat_frames(path):
    cap = pr.Capture.read(path)
    return cap, [k for k, p in enumerate(cap.packets) if pr.ecat_offset(p) == 14]


# ----------------------------------------------------------------------------- sender

def send(path, iface):
    """Replay the capture's EtherCAT frames on iface, keeping their spacing (stretched)."""
    cap, frames = ethercat_frames(path)
    s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW)
    s.bind((iface, 0))
    t0 = cap.seconds(cap.packets[frames[0]])
    start = time.monotonic()
    for k in frames:
        due = start + (cap.seconds(cap.packets[k]) - t0) * STRETCH
        while True:
            left = due - time.monotonic()
            if left <= 0:
                break
            time.sleep(min(left, 0.0005))
        s.send(bytes(cap.packets[k].data))
    s.close()
    return 0


# ----------------------------------------------------------------------------- namespace

def run(cmd, check_rc=True):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if check_rc and p.returncode != 0:
        raise RuntimeError("%s: exit %d: %s" % (" ".join(cmd), p.returncode, p.stderr.strip()))
    return p


class Namespace:
    def __init__(self):
        self.name = "dissgen-live-%d" % os.getpid()

    def __enter__(self):
        run(["ip", "netns", "add", self.name])
        try:
            self.exec(["sysctl", "-qw", "net.ipv6.conf.all.disable_ipv6=1",
                       "net.ipv6.conf.default.disable_ipv6=1"], check_rc=False)
            self.exec(["ip", "link", "add", "va", "type", "veth", "peer", "name", "vb"])
            self.exec(["ip", "link", "set", "va", "up"])
            self.exec(["ip", "link", "set", "vb", "up"])
        except Exception:
            self.__exit__()
            raise
        return self

    def exec(self, cmd, check_rc=True):
        return run(["ip", "netns", "exec", self.name] + cmd, check_rc)

    def prefix(self):
        return ["ip", "netns", "exec", self.name]

    def __exit__(self, *exc):
        run(["ip", "netns", "del", self.name], check_rc=False)


def capture_command(env, ns, stop):
    """tshark in the namespace, as nobody with the capture capabilities only."""
    cmd = ns.prefix() + ["setpriv", "--reuid=%d" % NOBODY, "--regid=%d" % NOBODY, "--clear-groups",
                         "--inh-caps=+net_raw,+net_admin", "--ambient-caps=+net_raw,+net_admin",
                         env.tshark_bin, "-i", "vb", "-f", "ether proto 0x88a4", "-l", "-T", "fields",
                         "-E", "occurrence=a", "-E", "aggregator=,"] + stop
    for f in FIELDS:
        cmd += ["-e", f]
    return cmd


def file_decode(env, path):
    """The rows of tshark -T fields as tshark -i prints them: a list of columns per frame."""
    rows = env.field_rows(path, FIELDS, display_filter="eth.type == 0x88a4")
    return [[str(n)] + [",".join(r[f]) for f in FIELDS[1:]] for n, r in rows.items()]


def normalise(rows, numbers):
    """Frame numbers (own and ecatr.request_in) as positions among the EtherCAT frames."""
    pos = {n: k for k, n in enumerate(numbers)}
    out = []
    links = [FIELDS.index("ecatr.request_in"), FIELDS.index("ecatr.no_response_to")]
    for r in rows:
        r = r + [""] * (len(FIELDS) - len(r))
        r = list(r)
        r[0] = str(pos.get(int(r[0]), "?"))
        for k in links:
            if r[k]:
                r[k] = ",".join(str(pos.get(int(x), "?")) for x in r[k].split(","))
        out.append(r)
    return out


def without_returns(src, dst, count):
    """A copy of the capture with `count` returned frames removed (spread over it, none near
    its end); the positions, among the copy's EtherCAT frames, of the requests they answered."""
    cap, frames = ethercat_frames(src)
    master = {bytes(cap.packets[k].data[6:12]) for k in frames if not cap.packets[k].data[6] & 0x02}
    waiting, pairs = {}, []
    for k in frames:
        p = cap.packets[k]
        key = tuple(d["idx"] for d in pr.ecat_datagrams(p))
        src_mac = bytes(p.data[6:12])
        if src_mac in master:
            waiting[key] = k
        elif key in waiting:
            pairs.append((waiting.pop(key), k))
    chosen = [pairs[(2 * n + 1) * (len(pairs) - 20) // (2 * count)] for n in range(count)]
    removed = {back for _sent, back in chosen}
    cap.packets = [p for k, p in enumerate(cap.packets) if k not in removed]
    cap.write(dst)
    os.chmod(dst, 0o644)
    _cap, kept = ethercat_frames(dst)
    tags = [cap.packets[k].tag for k in kept]
    return {tags.index(sent) for sent, _back in chosen}


def live(check, env, ns, path, stop, expect_frames):
    cmd = capture_command(env, ns, stop)
    p = subprocess.Popen(cmd, env=env.env(), cwd=env.home, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # Wait until dumpcap listens ("Capturing on 'vb'") before sending.
    seen, deadline = "", time.monotonic() + 30
    while "Capturing on" not in seen and time.monotonic() < deadline and p.poll() is None:
        ready, _, _ = select.select([p.stderr], [], [], 1.0)
        if ready:
            seen += os.read(p.stderr.fileno(), 4096).decode(errors="replace")
    if "Capturing on" not in seen:
        p.kill()
        out, err = p.communicate()
        raise RuntimeError("tshark did not start capturing: %s%s" % (seen, err))
    time.sleep(0.3)
    ns.exec([sys.executable, os.path.abspath(__file__), "--send", path, "--iface", "va"])
    try:
        out, err = p.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
    rows = [line.split("\t") for line in out.splitlines()]
    check(len(rows) == expect_frames, "%s %s: tshark -i saw %d frames of %d" % (
        os.path.basename(path), " ".join(stop), len(rows), expect_frames))
    return rows


class TestLiveCapture(TsharkTestCase, unittest.TestCase):
    """cls.ns: the namespace with the veth pair; skipped as a whole when it cannot be made."""

    @classmethod
    def prepare(cls):
        corpus_dir = ARGS.corpus or os.path.join(os.path.abspath(ARGS.source_dir), "..", "shared", "corpus",
                                                 "ethercat")
        cls.files = [f for f in CAPTURES if os.path.isfile(os.path.join(corpus_dir, f))]
        if not cls.files:
            raise unittest.SkipTest("no corpus captures at %s" % corpus_dir)
        if os.geteuid() != 0:
            raise unittest.SkipTest("making a network namespace and a veth pair needs root")
        try:
            cls.ns = Namespace().__enter__()
        except (OSError, RuntimeError) as e:
            raise unittest.SkipTest("network namespaces or veth pairs are not allowed here (%s)" % e)
        try:
            cls.install(os.path.join("rules", "ethercat.xml"), "ecatr")
            probe = subprocess.run(capture_command(cls.env, cls.ns, ["-c", "1", "-a", "duration:1"]),
                                   env=cls.env.env(), cwd=cls.env.home, capture_output=True, text=True)
            if "permission" in probe.stderr.lower() or "capabilit" in probe.stderr.lower():
                raise unittest.SkipTest("an ordinary user with CAP_NET_RAW cannot capture here: %s"
                                        % probe.stderr.strip())
            cls.paths = {}
            for name in cls.files:
                with open(os.path.join(corpus_dir, name), "rb") as fh:
                    cls.paths[name] = cls.env.add_file(name, fh.read())
        except BaseException:
            cls.ns.__exit__()     # tearDownClass does not run when setUpClass fails
            raise

    @classmethod
    def tearDownClass(cls):
        cls.ns.__exit__()
        super().tearDownClass()

    def replay(self, check, name, path, lost):
        """Replays the capture live twice (-c N, -a duration); the live decode must be the file's."""
        cap, frames = ethercat_frames(path)
        numbers = [k + 1 for k in frames]
        want = normalise(file_decode(self.env, path), numbers)
        check(len(want) == len(frames), "%s: the file holds %d EtherCAT frames" % (name, len(frames)))
        duration = (cap.seconds(cap.packets[frames[-1]]) - cap.seconds(cap.packets[frames[0]])) * STRETCH
        for stop in (["-c", str(len(frames))], ["-a", "duration:%d" % (int(duration) + 4)]):
            got = live(check, self.env, self.ns, path, stop, len(frames))
            got = normalise(got, list(range(1, len(got) + 1)))
            diff = [k for k, (a, b) in enumerate(zip(got, want)) if a != b]
            paired = sum(1 for r in got if r[FIELDS.index("ecatr.request_in")])
            check(not diff and len(got) == len(want),
                  "%s %s: the live decode equals the file's, pairing included (%d frames, %d paired)%s" % (
                      name, " ".join(stop), len(got), paired,
                      "; first difference at EtherCAT frame %d:\n  live %s\n  file %s" % (
                          diff[0], got[diff[0]], want[diff[0]]) if diff else ""))
            if lost is not None:
                k_expert, k_link = FIELDS.index("ecatr.expert.no_response"), FIELDS.index("ecatr.no_response_to")
                named = {int(x) for r in got if r[k_expert] for x in r[k_link].split(",") if x}
                check(named == lost, "%s %s: live, each lost frame is reported by a later frame "
                      "naming it (%s, removed returns of %s)" % (name, " ".join(stop), sorted(named),
                                                                sorted(lost)))

    def test_live_decode_equals_the_files(self):
        with self.checks() as check:
            for name in self.files:
                self.replay(check, name, self.paths[name], None)

    def test_live_losses_named_by_a_later_frame(self):
        lossy = "lossy-" + self.files[0]
        lost = without_returns(self.paths[self.files[0]], self.env.path(lossy), LOST_RETURNS)
        with self.checks() as check:
            self.replay(check, lossy, self.env.path(lossy), lost)


def add_arguments(parser):
    parser.add_argument("--corpus", help="the EtherCAT captures (default ../shared/corpus/ethercat)")


if __name__ == "__main__":
    if "--send" in sys.argv:    # this script run by the test inside the namespace: the sender
        ap = argparse.ArgumentParser()
        ap.add_argument("--send", required=True)
        ap.add_argument("--iface", required=True)
        args = ap.parse_args()
        sys.exit(send(args.send, args.iface))
    sys.exit(run_unittests(add_arguments)[1])

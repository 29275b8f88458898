#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The README's commands work as shown (Python 3 stdlib only).

1. The demo, the README's first command (`bash scripts/demo.sh`), run the way a reader runs
   it: in a fresh clone of HEAD inside a private (mode 700) mktemp folder, as .ci/run does,
   with the packages already installed. It must exit 0 and print every section: the headings
   of its `section` calls and the key lines of each (DEMO_LINES).
2. Every other command of README.md's ```sh blocks, in README order, in that clone; and the
   `dissgen` command lines of its text and command table, their metavariables (FILE.xml,
   DIR, ...) replaced by files of the repository (METAVARIABLES). Each must exit 0 and show
   what EXPECT says it shows. Commands that cannot run here are listed in SKIP with the
   reason, so a new README command is either run or skipped on purpose; the run ends with
   the list of README commands that no longer work.

The reader's HOME is a throw-away folder (a TsharkEnv), so `dissgen install` never touches
the real user's plugins. `dissgen` is the clone's build/bin/dissgen. `tshark` is a wrapper
(this script with --as-tshark) that runs tshark as the reader would see it: as root, as
uid 65534 with that HOME, the files it is given copied where that user can read them
(root's Wireshark ignores per-user plugins; tshark_env.py). Files the README names as
placeholders for the reader's own (capture.pcapng, Beckhoff_EK11xx.xml, ...) are put into
the clone under those names (STAND_INS), so that their commands run as written.

Exit status: 0 all worked, 1 something failed, 77 skipped (no git, no tshark, not a git
checkout, or packages missing that the demo would install).
"""
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import testpaths  # noqa: E402,F401  (every folder of tests/integration: tests share captures)
from tshark_env import TsharkEnv, TsharkTestCase, _make_readable, run_unittests  # noqa: E402

ARGS = None
DEMO = r"^bash scripts/demo\.sh\b"

# README commands not run here, each with the reason. Everything else in a ```sh block,
# and every `dissgen ...` command line of the text, is run.
SKIP = [
    (DEMO, "run first, from the fresh clone, and checked section by section (part 1)"),
    (r"^bash scripts/test\.sh\b", "runs the whole test suite, this test included"),
    # The package is built (the line before it runs); installing it is the package test's
    # job (ctest package_deb, in CI as root). The .deb it names is checked to exist.
    (r"^sudo |\bapt-get\b", "installs the .deb system-wide"),
    (r"^man dissgen\b", "needs the package installed (help_matches_man checks dissgen.1)"),
    (r"--system\b", "installs into Wireshark's global plugin folder, for every user"),
]

# What each run command must show: (pattern on the command, pattern its stdout must match,
# files it must have made). {home}: the reader's HOME, {plugins}: its per-user plugin
# folder, {out}: the stand-in for DIR.
EXPECT = [
    (r"^dissgen install query\.xml\b", r"^installed .*/dissgen_query\.so ", ["{plugins}/dissgen_query.so"]),
    (r"dissgen install rules/ethercat\.xml$", r"^installed .*/dissgen_ethercat\.so ",
     ["{plugins}/dissgen_ethercat.so"]),
    (r"dissgen install rules/enip\.xml$", r"^installed .*/dissgen_enip\.so ", ["{plugins}/dissgen_enip.so"]),
    (r"dissgen install rules/ethercat\.xml .*--dir ", r"^installed ", ["{out}/dissgen_ethercat.so"]),
    (r"dissgen install rules/ethercat\.xml --esi .*--network ", r"^installed ", []),
    (r"^tshark -r capture\.pcapng -V\b", r"^EtherCAT$\n^    Header$", []),
    (r"^tshark -r capture\.pcapng -Y 'ecatr\.datagram\.cmd == 0x0c' .*-e ecatr\.datagram\.lad",
     r"^0x00010000$", []),
    (r"^tshark -r capture\.pcap -Y 'enipr\.cpf\.item\.cip\.service == 0x54' .*-e enipr\.session",
     r"^0x20020000$", []),
    (r"^tshark -r capture\.pcapng -d ethertype==0x88a4,ecatf", r" ECAT \d+ 'BRD'", []),
    (r"^tshark -G fields \| grep ecatr\.pdo\.el1004", r"\tecatr\.pdo\.el1004\.channel_1\.input\t", []),
    (r"^dissgen esi ", r"^0x00000002 0x044c2c52 0x00120000 ", []),
    (r"^dissgen generate ", None, ["{out}/dissgen_ethercat.cpp"]),
    (r"^dissgen fields rules/ethercat\.xml$", r"^ecatr\.datagram\.cmd\tFT_UINT8\tCommand\trules$", []),
    (r"^dissgen fields .*--esi .*--network ", r"^ecatr\.pdo\.el1004\.channel_1\.input\t", []),
    (r"^dissgen --version$", r"^dissgen \d+\.\d+", []),
    (r"^dissgen --help$", r"^ +dissgen esi PATH\.\.\.$", []),
]

# Files the README's commands name for the reader's own, put into the clone under those
# names: (name, where its content comes from).
STAND_INS = [
    # A user's EtherCAT capture: the shipped generated one (LRW at 0x00010000).
    ("capture.pcapng", "samples/ethercat-demo.pcap"),
    # A user's EtherNet/IP capture: the paper's SendRRData with a Forward Open (session
    # 0x20020000) on TCP 44818, as test_enip.py builds it.
    ("capture.pcap", "enip-forward-open"),
    # Vendors' ESI files: small_io.xml describes the EK1100, EL1004 and EL2004.
    ("Beckhoff_EK11xx.xml", "tests/esi_ok/small_io.xml"),
    ("Beckhoff_EL1xxx.xml", "tests/esi_ok/bom_no_declaration.xml"),
]

# The metavariables of the command table's synopses, replaced by repository files ({out}: a
# throw-away folder). `[A | B]` becomes A; a row starting with `...` (options for check,
# generate, fields and install) is run as `dissgen fields FILE.xml ...`.
METAVARIABLES = {
    "FILE.xml": "rules/ethercat.xml",
    "DIR": "{out}",
    "PATH...": "tests/esi_ok",
    "PATH": "tests/esi_ok",
    "FILE": "tests/network/small_design.xml",
}

# The demo's key lines (regular expressions, multi-line mode), each with what it shows.
DEMO_LINES = [
    ("the real capture's frame count", r"^== samples/replay-sdo-error\.pcapng, a real capture: 556 frames, "),
    ("its first frames decoded as ECATR", r"^ +1 .* ECATR \d+ BRD 0x0000:0x0000 len 1$"),
    ("the bus scan's APWR of the station address", r"^ +20  0x0001  0x0010  1 +APWR 0x0001:0x0010 len 2$"),
    ("frame 544's SDO abort in the mailbox exchange",
     r"^ +544  0x1100  0x06020000  FPRD 0x1000:0x1100 len 256 CoE .*Abort transfer 0x1001:0x00$"),
    ("frame 544's tree with the abort code",
     r"^ +Abort code: Object does not exist in the object dictionary \(0x06020000\)$"),
    ("the returned DC frames counted", r"^== repeated frames: .*, 100 returned$"),
    ("the first DC frame", r"^ +106  0\.044131 s  0x0910  0 +FRMW 0x1000:0x0910 len 8$"),
    ("the real capture's timing report written", r"^wrote .*/demo-report\.html: 556 frames, 0 cycles$"),
]
LRW_ROW = r"^ +\d+  0x00010000 +[\d,]+ +[\d,]+ +[0-9a-f]{2}( [0-9a-f]{2})*$"
LRW_ROWS = 5


# --- the tshark wrapper --------------------------------------------------------------

def as_tshark(home, real_tshark, args):
    """tshark as the README's reader runs it, with HOME as that reader's (see the docstring)."""
    env = TsharkEnv(home=home, tshark=real_tshark)
    if env.as_nobody:
        _make_readable(home)      # what dissgen install, run as root, put there
        args = [env.readable(os.path.abspath(a)) if os.path.isfile(a) else a for a in args]
    else:
        args = [os.path.abspath(a) if os.path.isfile(a) else a for a in args]
    return subprocess.run(env.command(args), env=env.env(), cwd=env.home).returncode


# --- README.md -----------------------------------------------------------------------

def shown(cmd):
    """A command's first line without its trailing comment: how reports name it."""
    return re.sub(r"\s+#.*$", "", cmd.splitlines()[0]).strip()


def sh_block_commands(text):
    """[(line, command)] of the shell code blocks: one command a line; a line ending in a
    backslash goes on with the next, a here-document takes its body; comments are left out."""
    lines = text.splitlines()
    commands, fence, i = [], None, 0
    while i < len(lines):
        line = lines[i]
        i += 1
        if line.startswith("```"):
            fence = line[3:].strip() if fence is None else None
            continue
        if fence not in ("sh", "bash", "shell") or not line.strip() or line.lstrip().startswith("#"):
            continue
        start, cmd = i, line
        while cmd.endswith("\\") and i < len(lines):
            cmd += "\n" + lines[i]
            i += 1
        m = re.search(r"<<(-?)\s*(['\"]?)(\w+)\2", cmd)
        if m:
            while i < len(lines):
                cmd += "\n" + lines[i]
                i += 1
                if (lines[i - 1].lstrip("\t") if m.group(1) else lines[i - 1]) == m.group(3):
                    break
        commands.append((start, cmd))
    return commands


def text_commands(text):
    """[(line, command)] of the `dissgen ...` command lines in the text and tables (one per
    distinct command): a dissgen command with an argument, or a `... --option` table row.
    A command merely named (`dissgen install`) is not a command line."""
    text = re.sub(r"^```.*?^```", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S | re.M)
    seen, commands = set(), []
    for m in re.finditer(r"`((?:build/bin/)?dissgen (?:check|generate|fields|install|esi|--[a-z]+)\b[^`]*"
                         r"|\.\.\. --[^`]*)`", text):
        span = m.group(1).strip()
        words = span.split()
        if (len(words) < 3 and not words[1].startswith("--")) or span in seen:
            continue
        seen.add(span)
        commands.append((text.count("\n", 0, m.start()) + 1, span))
    return commands


def expand_synopsis(synopsis, out):
    """The command a synopsis stands for (METAVARIABLES), or raise ValueError."""
    s = synopsis.replace("\\|", "|")
    if s.startswith("... "):
        s = "dissgen fields FILE.xml " + s[4:]
    s = re.sub(r"\[([^\]]*)\]", lambda m: m.group(1).split("|")[0].strip(), s)
    words = [shlex.quote(METAVARIABLES[w].format(out=out)) if w in METAVARIABLES else w for w in s.split()]
    unknown = [w for w in words if re.fullmatch(r"[A-Z][A-Z0-9_]*(\.xml|\.\.\.)?", w)]
    if unknown:
        raise ValueError("no stand-in for %s (add it to METAVARIABLES)" % ", ".join(unknown))
    return " ".join(words)


# --- running -------------------------------------------------------------------------

def run(cmd, cwd, env, timeout):
    """Run cmd with bash (pipefail: a failing tshark before a grep counts); return (status,
    stdout, stderr, seconds). A command that outlives timeout is killed with its children."""
    t0 = time.monotonic()
    p = subprocess.Popen(["bash", "-o", "pipefail", "-c", cmd], cwd=cwd, env=env, text=True,
                         stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         start_new_session=True)
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, err = p.communicate()
        err += "\n(killed after %d s)" % timeout
        return -1, out, err, time.monotonic() - t0
    return p.returncode, out, err, time.monotonic() - t0


def tail(text, n=30):
    lines = text.rstrip("\n").splitlines()
    return "\n".join(("      " + l) for l in lines[-n:])


def git(*args, **kw):
    # The checkout may belong to another user than the one running the test.
    return subprocess.run(["git", "-c", "safe.directory=*"] + list(args), check=True, text=True,
                          capture_output=True, **kw).stdout.strip()


def missing_packages(source_dir):
    """The packages scripts/install-deps.sh would install (the demo would run apt-get)."""
    with open(os.path.join(source_dir, "scripts", "install-deps.sh")) as fh:
        m = re.search(r"^packages=\(([^)]*)\)", fh.read(), re.M)
    missing = []
    for p in m.group(1).split() if m else []:
        q = subprocess.run(["dpkg-query", "-W", "-f=${Status}", p], capture_output=True, text=True)
        if "install ok installed" not in q.stdout:
            missing.append(p)
    return missing


def skip_reason(source_dir):
    for tool in ("git", "tshark", "dpkg-query") + (("setpriv",) if os.geteuid() == 0 else ()):
        if shutil.which(tool) is None:
            return "%s is not installed" % tool
    try:
        git("-C", source_dir, "rev-parse", "HEAD")
    except subprocess.CalledProcessError:
        return "%s is not a git checkout (the demo runs from a clone of HEAD)" % source_dir
    missing = missing_packages(source_dir)
    if missing:
        return "packages missing, which the demo would install first: %s" % " ".join(missing)
    return None


def stage_stand_ins(clone):
    for name, source in STAND_INS:
        target = os.path.join(clone, name)
        if source == "enip-forward-open":
            from test_enip import SEED, TcpFlow, pcap
            with open(target, "wb") as fh:
                fh.write(pcap([TcpFlow(50000, 44818).segment(SEED)]))
        else:
            shutil.copyfile(os.path.join(clone, source), target)


def check_demo(check, status, output, demo_script):
    """Part 1: the demo's exit status, its section headings and key lines."""
    check(status == 0, "bash scripts/demo.sh exits 0 (it exited %d)" % status)
    with open(demo_script) as fh:
        headings = re.findall(r'^section "([^"]*)"', fh.read(), re.M)
    printed = [l[3:] for l in output.splitlines() if l.startswith("== ")]
    check(len(printed) == len(headings) and len(headings) > 0,
          "the demo prints all %d section headings of scripts/demo.sh (printed %d)" % (len(headings), len(printed)))
    for h in headings:
        fixed = h.split("$")[0]       # up to the first value the demo fills in
        check(any(p.startswith(fixed) for p in printed), "the demo prints the heading '== %s'" % h)
    for what, pattern in DEMO_LINES:
        check(re.search(pattern, output, re.M), "the demo shows %s" % what)
    sections = output.split("\n== ")
    lrw = next((s for s in sections if s.startswith("cyclic process data (LRW")), "")
    rows = re.findall(LRW_ROW, lrw, re.M)
    check(len(rows) == LRW_ROWS, "the demo's LRW section shows %d LRW rows (found %d)" % (LRW_ROWS, len(rows)))
    report = re.search(r"^report: (/\S+\.html) ", sections[-1], re.M)
    page = ""
    if report and os.path.isfile(report.group(1)):
        with open(report.group(1), encoding="utf-8") as fh:
            page = fh.read()
    check(sections[-1].startswith("the timing report of samples/replay-sdo-error.pcapng") and
          '<table id="slaves">' in page and 'id="round-trip"' in page,
          "the demo's last section writes the real capture's timing report (its slave, its round trips) "
          "and says where")


def keep_option(parser):
    parser.add_argument("--keep", action="store_true", help="keep the clone and the reader's HOME")


class TestReadmeCommands(TsharkTestCase, unittest.TestCase):
    """The demo in a fresh clone, then every README command as its reader would type it
    (self.env is the reader's HOME, tshark run as the unprivileged user)."""

    def test_the_demo_and_every_readme_command_work_as_shown(self):
        source_dir = os.path.abspath(ARGS.source_dir)
        reason = skip_reason(source_dir)
        if reason:
            self.skipTest(reason)
        reader = self.env
        reader.keep = ARGS.keep
        broken = []               # (line, README command, why)
        tmp = tempfile.mkdtemp(prefix="dissgen-readme-")     # mode 700, as .ci/run's mktemp -d
        os.chmod(tmp, 0o700)
        started = time.monotonic()
        try:
            with self.checks() as check:
                self.demo_and_commands(check, broken, source_dir, tmp, reader)
        finally:
            if ARGS.keep:
                print("(kept %s)" % tmp)
            else:
                shutil.rmtree(tmp, ignore_errors=True)
            print("\n%.0f s in all" % (time.monotonic() - started))
            if broken:
                print("README commands that do not work as shown:")
                for line, name, why in broken:
                    print("  README.md:%s: %s: %s" % (line or "-", name, why))

    def demo_and_commands(self, check, broken, source_dir, tmp, reader):
        # --- part 1: the demo in a fresh clone -------------------------------------
        head = git("-C", source_dir, "rev-parse", "HEAD")
        if git("-C", source_dir, "status", "--porcelain", "--untracked-files=no"):
            print("note: %s has uncommitted changes; this test runs HEAD (%s)" % (source_dir, head))
        clone = os.path.join(tmp, "dissgen")
        git("init", "-q", clone)
        git("-C", clone, "fetch", "-q", source_dir, "HEAD")
        git("-C", clone, "checkout", "-q", "--detach", "FETCH_HEAD")
        print("clone of %s in %s (folder mode %o); reader's HOME %s" %
              (head[:12], clone, os.stat(tmp).st_mode & 0o777, reader.home))

        demo_env = dict(os.environ, HOME=reader.home)
        status, out, err, secs = run("bash scripts/demo.sh", clone, demo_env, timeout=1800)
        print("bash scripts/demo.sh: exit %d, %.0f s" % (status, secs))
        output = out + err
        n = len(check.failed)
        check_demo(check, status, out, os.path.join(clone, "scripts", "demo.sh"))
        if len(check.failed) > n:
            print("    demo output (last lines):\n" + tail(output, 60))
            broken.append((0, "bash scripts/demo.sh", "; ".join(check.failed[n:])))

        # --- part 2: every README command ------------------------------------------
        bindir = os.path.join(tmp, "bin")
        os.mkdir(bindir)
        os.symlink(os.path.join(clone, "build", "bin", "dissgen"), os.path.join(bindir, "dissgen"))
        wrapper = os.path.join(bindir, "tshark")
        with open(wrapper, "w") as fh:
            fh.write("#!/bin/sh\n# tshark as the README's reader sees it (readme_commands.py)\nexec %s \"$@\"\n" %
                     " ".join(shlex.quote(a) for a in (sys.executable, os.path.abspath(__file__), "--as-tshark",
                                                       reader.home, reader.tshark_bin)))
        os.chmod(wrapper, 0o755)
        reader_env = dict(os.environ, HOME=reader.home, PATH=bindir + os.pathsep + os.environ.get("PATH", ""),
                          XDG_CONFIG_HOME=os.path.join(reader.home, ".config"))
        stage_stand_ins(clone)
        out_dir = os.path.join(tmp, "out")
        fill = {"home": reader.home, "plugins": reader.plugin_dir, "out": out_dir}

        with open(os.path.join(clone, "README.md"), encoding="utf-8") as fh:
            readme = fh.read()
        commands = [(line, cmd, cmd) for line, cmd in sh_block_commands(readme)]
        for line, span in text_commands(readme):
            try:
                commands.append((line, span, expand_synopsis(span, out_dir)))
            except ValueError as e:
                check(False, "README.md:%d: `%s`: %s" % (line, span, e))
                broken.append((line, span, str(e)))
        check(len(commands) > 10, "README.md shows its commands (%d found)" % len(commands))

        for line, readme_text, cmd in commands:
            name = shown(readme_text)
            skipped = next((why for pattern, why in SKIP if re.search(pattern, shown(cmd))), None)
            if skipped:
                print("skip README.md:%d: %s  -- %s" % (line, name, skipped))
                deb = re.search(r"apt-get install (\./build/\S+\.deb)", name)
                if deb and not check(os.path.isfile(os.path.join(clone, deb.group(1))),
                                     "README.md:%d: the package it installs, %s, is what the build makes"
                                     % (line, deb.group(1))):
                    broken.append((line, name, "no %s after the package build (%s)" % (
                        deb.group(1), ", ".join(f for f in os.listdir(os.path.join(clone, "build"))
                                                if f.endswith(".deb")) or "no .deb")))
                continue
            status, out, err, secs = run(cmd, clone, reader_env, timeout=900)
            problems = [] if status == 0 else ["exit %d" % status]
            for pattern, stdout_re, files in EXPECT:
                if not re.search(pattern, shown(cmd)):
                    continue
                if stdout_re and not re.search(stdout_re, out, re.M):
                    problems.append("its output lacks /%s/" % stdout_re)
                problems += ["made no %s" % f.format(**fill) for f in files
                             if not os.path.exists(f.format(**fill))]
            label = name if cmd == readme_text else "%s  (run as: %s)" % (name, cmd)
            if not check(not problems, "README.md:%d: %s  [%.1f s]" % (line, label, secs)):
                print("    %s\n    stdout:\n%s\n    stderr:\n%s" % ("; ".join(problems), tail(out), tail(err)))
                broken.append((line, name, "; ".join(problems)))


def main():
    if len(sys.argv) > 3 and sys.argv[1] == "--as-tshark":
        return as_tshark(sys.argv[2], sys.argv[3], sys.argv[4:])
    return run_unittests(keep_option)[1]


if __name__ == "__main__":
    sys.exit(main())

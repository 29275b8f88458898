#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""A throw-away HOME for running tshark with a per-user dissgen plugin (Python 3 stdlib only).

As root, Wireshark ignores per-user plugins, so tshark is run as uid/gid 65534 (setpriv) when
this process is root, and everything it reads (HOME, plugin folder, captures) is made readable
by that user.  Otherwise tshark simply runs with HOME set.

    with TsharkEnv() as env:
        env.install_plugin("build/bin/dissgen", "rules/ethercat.xml")
        env.assert_plugin_loaded("ecatr")
        cap = env.add_file("gen.pcap", blob)
        out = env.tshark(["-r", cap, "-T", "fields", "-e", "ecatr.datagram.cmd"]).stdout

CLI (for a quick look):  tshark_env.py --dissgen PATH --rules FILE [--protocol ecatr] [-- tshark args]
"""

import argparse
import contextlib
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile

NOBODY = 65534

# What Wireshark's plugin loader says when it skips a plugin (stderr, exit status 0).
LOADER_PATTERNS = re.compile(r"plugin|symbol|compiled for|\.so\b|couldn't load|undefined", re.I)

# DISSGEN_SANITIZE=1: plugins are built with AddressSanitizer and UndefinedBehaviorSanitizer.
SANITIZE = os.environ.get("DISSGEN_SANITIZE") == "1"
SANITIZER_FLAGS = "-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined -g"
SANITIZER_PRELOAD = "libasan.so.8 libubsan.so.1"


class TsharkError(RuntimeError):
    pass


class Checks:
    """Prints one "ok"/"FAIL" line per check; `failed` lists the failed ones, `count` all.
    A test collects its fine-grained checks in one (TsharkTestCase.checks) and fails at
    its end, listing them.

        with self.checks() as check:
            check(a == b, "what a == b means")
    """

    def __init__(self):
        self.failed = []
        self.count = 0

    def __call__(self, cond, what):
        self.count += 1
        print(("ok   " if cond else "FAIL ") + what, flush=True)
        if not cond:
            self.failed.append(what)
        return cond


def corpus_captures(folder):
    """The names of the *.pcap and *.pcapng files in folder, sorted ([] when it is absent)."""
    return sorted(f for f in os.listdir(folder) if f.endswith((".pcap", ".pcapng"))) if os.path.isdir(folder) else []


def relative_time_ns(text):
    """A relative time as tshark prints it, in seconds ("-0.000012345"), as whole ns (-12345)."""
    negative = text.startswith("-")
    seconds, _, fraction = text.lstrip("-").partition(".")
    ns = int(seconds) * 10**9 + int((fraction + "000000000")[:9])
    return -ns if negative else ns


def read_tshark_output(path, xml=False):
    """The text tshark wrote to path (JSON or PDML), made parseable: tshark cuts a long label
    at a byte count, which may fall inside a UTF-8 character (a long string from random
    bytes), and its PDML may hold control characters, which XML does not allow."""
    with open(path, "rb") as fh:
        text = fh.read().decode("utf-8", "replace")
    return re.sub("[\x00-\x08\x0b\x0c\x0e-\x1f]", "?", text) if xml else text


def wireshark_abi():
    """Major.minor of the installed Wireshark, e.g. "4.0" (the per-user plugin folder name)."""
    try:
        v = subprocess.run(["pkg-config", "--modversion", "wireshark"], check=True,
                           capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        out = subprocess.run(["tshark", "--version"], capture_output=True, text=True).stdout
        m = re.search(r"TShark \(Wireshark\) (\d+\.\d+)", out)
        if not m:
            raise TsharkError("cannot tell the Wireshark version (no pkg-config wireshark, no tshark)")
        return m.group(1)
    m = re.match(r"(\d+)\.(\d+)", v)
    if not m:
        raise TsharkError("pkg-config --modversion wireshark gave %r" % v)
    return "%s.%s" % m.groups()


def readable_by_others(path):
    """Whether any user can read path: the file is world-readable and every folder above it
    world-searchable (a checkout in a mode-700 folder is not, whoever owns it)."""
    path = os.path.abspath(path)
    if os.path.isfile(path) and not os.stat(path).st_mode & stat.S_IROTH:
        return False
    while True:
        if os.path.isdir(path) and not os.stat(path).st_mode & stat.S_IXOTH:
            return False
        parent = os.path.dirname(path)
        if parent == path:
            return True
        path = parent


def _make_readable(path):
    """chmod a+rX on path and everything below it."""
    for root, dirs, files in os.walk(path):
        os.chmod(root, os.stat(root).st_mode | 0o555)
        for f in files:
            p = os.path.join(root, f)
            mode = os.stat(p).st_mode
            os.chmod(p, mode | 0o444 | (0o111 if mode & 0o100 else 0))


class TsharkEnv:
    def __init__(self, keep=False, prefix="dissgen-tshark-", tshark="tshark", home=None):
        """home: an existing HOME to use (another process's TsharkEnv), left in place."""
        self.as_nobody = os.geteuid() == 0
        if home:
            self.home = home
            keep = True
        else:
            base = tempfile.gettempdir()
            if self.as_nobody and not readable_by_others(base):
                base = "/tmp"
            self.home = tempfile.mkdtemp(prefix=prefix, dir=base)
            os.chmod(self.home, 0o755)
        self.keep = keep
        self.tshark_bin = shutil.which(tshark) or tshark
        self.abi = wireshark_abi()
        self.plugin_dir = os.path.join(self.home, ".local", "lib", "wireshark", "plugins",
                                       self.abi, "epan")
        # TMPDIR for what runs as the tshark user (dissgen report builds there): a machine's
        # /tmp is not always writable by everyone
        self.tmp = os.path.join(self.home, "tmp")
        os.makedirs(self.tmp, exist_ok=True)
        os.chmod(self.tmp, 0o1777)
        self.installed = []

    # -- files ---------------------------------------------------------------
    def path(self, name):
        return os.path.join(self.home, name)

    def add_file(self, name, blob):
        """Write blob (bytes) as HOME/name, readable by the tshark user; return its path."""
        p = self.path(name)
        with open(p, "wb") as fh:
            fh.write(blob)
        os.chmod(p, 0o644)
        return p

    def readable(self, path):
        """A path to the file at path that the tshark user can read: path itself when it
        can, else a copy in HOME (the checkout or the corpus may sit in a private folder)."""
        if not self.as_nobody or readable_by_others(path):
            return path
        staged = os.path.join(self.home, "staged")
        os.makedirs(staged, mode=0o755, exist_ok=True)
        copy = os.path.join(staged, os.path.basename(path))
        if not os.path.exists(copy):
            shutil.copyfile(path, copy)
            os.chmod(copy, 0o644)
        return copy

    # -- plugin --------------------------------------------------------------
    def install_plugin(self, dissgen, rules, extra_args=()):
        """Run `dissgen install RULES --dir <per-user plugin folder>`; return the new files."""
        if not os.path.isfile(dissgen) or not os.access(dissgen, os.X_OK):
            raise TsharkError("%s: no such executable (build dissgen first)" % dissgen)
        os.makedirs(self.plugin_dir, exist_ok=True)
        before = set(os.listdir(self.plugin_dir))
        cmd = [dissgen, "install", rules, "--dir", self.plugin_dir] + list(extra_args)
        build_env = dict(os.environ)
        if SANITIZE:
            build_env["DISSGEN_CXXFLAGS"] = SANITIZER_FLAGS
        p = subprocess.run(cmd, capture_output=True, text=True, env=build_env)
        if p.returncode != 0:
            raise TsharkError("%s failed (exit %d):\n%s%s" % (" ".join(cmd), p.returncode, p.stdout, p.stderr))
        _make_readable(self.home)
        new = sorted(set(os.listdir(self.plugin_dir)) - before)
        self.installed = [os.path.join(self.plugin_dir, f) for f in new] or \
            [os.path.join(self.plugin_dir, f) for f in sorted(os.listdir(self.plugin_dir))]
        if not self.installed:
            raise TsharkError("%s succeeded but put nothing in %s" % (" ".join(cmd), self.plugin_dir))
        return self.installed

    # -- running -------------------------------------------------------------
    def env(self):
        e = {"HOME": self.home, "PATH": os.environ.get("PATH", "/usr/bin:/bin"),
             "LANG": "C.UTF-8", "LC_ALL": "C.UTF-8", "TZ": "UTC",
             "XDG_CONFIG_HOME": os.path.join(self.home, ".config"), "TMPDIR": self.tmp}
        if SANITIZE:
            # The plugin is built with ASan+UBSan; tshark is not, so the runtimes are
            # preloaded. Any report aborts tshark (non-zero exit, report on stderr).
            e["LD_PRELOAD"] = SANITIZER_PRELOAD
            e["ASAN_OPTIONS"] = "detect_leaks=0:abort_on_error=1:halt_on_error=1"
            e["UBSAN_OPTIONS"] = "print_stacktrace=1:halt_on_error=1"
        return e

    def command(self, args):
        cmd = [self.tshark_bin] + list(args)
        if self.as_nobody:
            cmd = ["setpriv", "--reuid=%d" % NOBODY, "--regid=%d" % NOBODY, "--clear-groups"] + cmd
        return cmd

    def field_rows(self, path, fields, two_pass=False, display_filter=None, aggregator=",", with_stderr=False,
                   extra_args=()):
        """{frame number: {field: [values]}} of `tshark -T fields` for fields[1:] (fields[0]
        is frame.number), every occurrence of each field; with display_filter, of the frames
        it keeps.  aggregator: what tshark puts between occurrences (one no value holds).
        with_stderr: (rows, what tshark wrote to stderr). extra_args: more tshark options
        (--disable-protocol P, ...)."""
        args = ["-r", path, "-T", "fields", "-E", "occurrence=a", "-E", "aggregator=" + aggregator]
        args += ["-2"] if two_pass else []
        args += list(extra_args)
        if display_filter:
            args += ["-Y", display_filter]
        for f in fields:
            args += ["-e", f]
        p = self.tshark(args)
        rows = {}
        for line in p.stdout.splitlines():
            cols = (line.split("\t") + [""] * len(fields))[:len(fields)]
            rows[int(cols[0])] = {f: (v.split(aggregator) if v else []) for f, v in zip(fields[1:], cols[1:])}
        return (rows, p.stderr) if with_stderr else rows

    def field_rows_each_pass(self, path, fields, **kwargs):
        """("one pass", rows), then ("-2", rows): field_rows() in one pass and in two, for
        checks that must hold in both (kwargs as for field_rows)."""
        for two_pass in (False, True):
            yield ("-2" if two_pass else "one pass"), self.field_rows(path, fields, two_pass=two_pass, **kwargs)

    def tshark(self, args, check=True, stdout=None, timeout=1800, extra_env=None):
        """Run tshark; return CompletedProcess (text stdout/stderr unless stdout is a file).
        extra_env: variables set for this run only (DISSGEN_TABLE_WALK, ...)."""
        cmd = self.command(args)
        p = subprocess.run(cmd, env=dict(self.env(), **(extra_env or {})), cwd=self.home, timeout=timeout, text=True,
                           stdout=stdout if stdout is not None else subprocess.PIPE,
                           stderr=subprocess.PIPE)
        if check and p.returncode != 0:
            raise TsharkError("tshark exited %d: %s\n%s" % (p.returncode, " ".join(args), p.stderr))
        return p

    # -- checks --------------------------------------------------------------
    def plugins(self):
        """[(name, version, type, path)] from `tshark -G plugins`, and its stderr."""
        p = self.tshark(["-G", "plugins"])
        rows = []
        for line in p.stdout.splitlines():
            parts = [s.strip() for s in line.split("\t")]
            if len(parts) >= 4:
                rows.append(tuple(parts[:4]))
        return rows, p.stderr

    def protocols(self):
        p = self.tshark(["-G", "protocols"])
        return {line.split("\t")[2] for line in p.stdout.splitlines() if line.count("\t") >= 2}, p.stderr

    def assert_plugin_loaded(self, protocol=None):
        """The installed plugin file(s) are listed by `tshark -G plugins`, tshark printed no
        loader warning, and (if given) the protocol's filter name is registered."""
        if SANITIZE:
            # `tshark -G plugins` hangs with the sanitizer runtimes preloaded; the
            # protocol check below still proves the instrumented plugin loaded.
            rows, err = [], ""
            protocol = protocol or "ecatr"
        else:
            rows, err = self.plugins()
        problems = []
        if err.strip():
            problems.append("tshark -G plugins wrote to stderr (loader warning?):\n" + err.strip())
        listed = {os.path.realpath(r[3]) for r in rows}
        for f in ([] if SANITIZE else self.installed or []):
            if f.endswith(".so") and os.path.realpath(f) not in listed:
                problems.append("%s is not listed by tshark -G plugins" % f)
        if not SANITIZE and not any(f.endswith(".so") for f in self.installed or []):
            ours = [r for r in rows if os.path.realpath(r[3]).startswith(os.path.realpath(self.plugin_dir))]
            if not ours:
                problems.append("no plugin from %s is listed by tshark -G plugins" % self.plugin_dir)
        if protocol:
            protos, perr = self.protocols()
            if perr.strip():
                problems.append("tshark -G protocols wrote to stderr:\n" + perr.strip())
            if protocol not in protos:
                problems.append("protocol %r is not registered" % protocol)
        if problems:
            raise TsharkError("plugin not loaded cleanly:\n- " + "\n- ".join(problems))
        return rows

    @staticmethod
    def loader_warnings(stderr):
        """The lines of a tshark stderr that look like plugin-loader complaints."""
        return [l for l in stderr.splitlines() if LOADER_PATTERNS.search(l)]

    # -- lifetime ------------------------------------------------------------
    def cleanup(self):
        if not self.keep:
            shutil.rmtree(self.home, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.cleanup()
        return False


class TsharkTestCase:
    """Mixin for a unittest.TestCase class whose tests share one TsharkEnv (cls.env),
    set up by the class's own `prepare()` classmethod, if it has one (`cls.install(rules,
    protocol)` puts a plugin in it); cls.args: the options run_unittests parsed.

    A test that makes many fine-grained checks collects them with `self.checks()`: each
    prints an ok/FAIL line, and the test fails at the end of the block, listing the
    failed ones (and when the block made no check at all).  A test that cannot run here
    (no corpus, no privileges) calls `self.skipTest("why")`."""

    @classmethod
    def setUpClass(cls):
        cls.env = TsharkEnv()
        try:
            if hasattr(cls, "prepare"):
                cls.prepare()
        except BaseException:
            cls.env.cleanup()     # tearDownClass does not run when setUpClass fails
            raise

    @classmethod
    def tearDownClass(cls):
        cls.env.cleanup()

    @classmethod
    def install(cls, rules, protocol, extra_args=()):
        """Install the plugin of rules (a path in the source tree) into cls.env, check it loads."""
        cls.env.install_plugin(cls.args.dissgen, os.path.join(cls.args.source_dir, rules), extra_args)
        cls.env.assert_plugin_loaded(protocol)

    @classmethod
    def install_text(cls, name, rules, protocol):
        """Write a rule file's text into cls.env as `name`, install its plugin, check it loads."""
        path = cls.env.path(name)
        with open(path, "w", encoding="utf-8") as f:
            f.write(rules)
        cls.install(path, protocol)

    @contextlib.contextmanager
    def checks(self):
        print(flush=True)     # the checks' lines start on their own, after unittest's "test_x ... "
        check = Checks()
        yield check
        if check.failed:
            self.fail("%d of %d checks failed:\n- %s" % (len(check.failed), check.count,
                                                        "\n- ".join(check.failed)))
        if not check.count:
            self.fail("no check was made")

    def check_every_pass(self, check, decoded, want, what):
        """Checks that what earlier frames taught reads the same however tshark shows it:
        decoded(two_pass, display_filter) -> {frame: value} gives `want` in one pass and with
        -2 (the same frames, no more), and with -2 -Y 'frame.number % 3 == 0' the same values
        on the frames that filter keeps. `what`: the property, for the checks' lines."""
        def differing(got, wanted):
            wrong = dict(list({n: (got.get(n), w) for n, w in wanted.items() if got.get(n) != w}.items())[:3])
            extra = sorted(set(got) - set(wanted))[:5]
            return ("; frame: (got, want) %s" % wrong if wrong else "") + \
                ("; frames not expected: %s" % extra if extra else "")
        for two_pass in (False, True):
            got = decoded(two_pass, None)
            check(got == want, "%s: %s (%d frames%s)" % ("-2" if two_pass else "one pass", what, len(want),
                                                        differing(got, want)))
        kept = {n: w for n, w in want.items() if n % 3 == 0}
        got = decoded(True, "frame.number % 3 == 0")
        check(got == kept, "-2 -Y 'frame.number %% 3 == 0': the same on the %d frames kept%s" % (
            len(kept), differing(got, kept)))


def run_unittests(add_arguments=None):
    """The entry point of every tests/integration/*/test_*.py: parses --dissgen and
    --source-dir (plus what `add_arguments(parser)` adds), runs the module's unittest
    cases (or those named: `TestX.test_y`, `-k pattern`), and returns (args, exit status
    for ctest): 0 when every test run passed or skipped, 77 when every one skipped
    ("SKIPPED: <reasons>"), 1 when one failed or when none was run (a selection that
    matches nothing)."""
    import unittest
    parser = argparse.ArgumentParser()
    parser.add_argument("--dissgen", required=True)
    parser.add_argument("--source-dir", required=True)
    if add_arguments:
        add_arguments(parser)
    args, rest = parser.parse_known_args()
    if shutil.which("tshark") is None:
        print("SKIPPED: tshark is not installed")
        return args, 77
    main_module = sys.modules["__main__"]
    main_module.ARGS = TsharkTestCase.args = args
    result = unittest.main(module=main_module, argv=[sys.argv[0]] + rest, exit=False, verbosity=2).result
    skipped = [(test, why) for test, why in result.skipped]
    ran = result.testsRun - sum(1 for test, _why in skipped if isinstance(test, unittest.TestCase))
    reasons = sorted({why for _test, why in skipped})
    sys.stdout.flush()
    if not result.wasSuccessful():
        return args, 1
    if ran == 0 and skipped:
        print("SKIPPED: " + "; ".join(reasons))
        return args, 77
    if ran == 0:
        print("FAIL: no test was run (does the selection name a test?)")
        return args, 1
    if skipped:
        print("(skipped here: %s)" % "; ".join("%s: %s" % (t.id().split(".", 1)[-1], why) for t, why in skipped))
    return args, 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", help="dissgen binary (omit to run tshark without our plugin)")
    ap.add_argument("--rules", help="rule file to install")
    ap.add_argument("--protocol", help="filter name the plugin must register (e.g. ecatr)")
    ap.add_argument("--keep", action="store_true", help="keep the temporary HOME")
    ap.add_argument("tshark_args", nargs="*", help="arguments for one tshark run (after --)")
    a = ap.parse_args(argv)
    try:
        return _run(a)
    except TsharkError as e:
        print("ERROR: %s" % e, file=sys.stderr)
        return 1


def _run(a):
    with TsharkEnv(keep=a.keep) as env:
        print("HOME=%s (plugin folder %s, tshark as %s)" %
              (env.home, env.plugin_dir, "uid 65534" if env.as_nobody else "this user"), file=sys.stderr)
        if a.dissgen:
            files = env.install_plugin(a.dissgen, a.rules)
            print("installed: %s" % ", ".join(files), file=sys.stderr)
            env.assert_plugin_loaded(a.protocol)
            print("plugin loaded cleanly", file=sys.stderr)
        if a.tshark_args:
            args = []
            for x in a.tshark_args:     # captures given by path are copied into HOME
                if os.path.isfile(x) and not x.startswith(env.home):
                    with open(x, "rb") as fh:
                        x = env.add_file(os.path.basename(x), fh.read())
                args.append(x)
            p = env.tshark(args, check=False)
            sys.stdout.write(p.stdout)
            sys.stderr.write(p.stderr)
            return p.returncode
    return 0


if __name__ == "__main__":
    sys.exit(main())

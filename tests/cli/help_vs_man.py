#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""`dissgen --help` and the man page name the same commands and options (Python 3 stdlib only).

    help_vs_man.py --dissgen build/bin/dissgen --man packaging/dissgen.1

From --help: the commands of the usage lines ("dissgen CMD ...") and of the "commands:"
list, the options of the usage lines and of the "options:" list (each must be in both).
From the man page: the items (.TP) of COMMANDS and of OPTIONS, and what SYNOPSIS names.
Every command and option of one must be in the other; the binary knows each command
(it does not answer "unknown command"); --version says the man page header's version, and
no command at all prints the usage and exits 2.  Prints "N passed, N failed".
"""

import argparse
import re
import subprocess
import sys

OPTION = re.compile(r"(?<![\w-])(--?[A-Za-z][\w-]*)")


def help_text(dissgen):
    p = subprocess.run([dissgen, "--help"], capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit("%s --help exited %d: %s" % (dissgen, p.returncode, p.stderr))
    return p.stdout


def sections(text, heads):
    """{head: [lines]} for the blocks that start with a line 'head:' and end at a blank line."""
    out, current = {}, None
    for line in text.splitlines():
        if line.rstrip(":") in heads and line.endswith(":"):
            current = out.setdefault(line[:-1], [])
        elif not line.strip():
            current = None
        elif current is not None:
            current.append(line)
    return out


def from_help(text):
    usage = [l for l in text.splitlines() if re.match(r"\s*(usage:\s*)?dissgen\b", l)]
    usage_commands = set()
    usage_options = set()
    for line in usage:
        words = line.split("dissgen", 1)[1].split()
        if words and not words[0].startswith("-"):
            usage_commands.add(words[0])
        usage_options |= set(OPTION.findall(line))
    blocks = sections(text, ("commands", "options"))
    listed_commands = {l.split()[0] for l in blocks.get("commands", []) if l.startswith("  ") and
                       not l.startswith("   ")}
    listed_options = set()
    for l in blocks.get("options", []):
        if l.startswith("  ") and l.strip().startswith("-"):
            # "  -h, --help  text": the option names before the two-space gap.
            head = re.split(r"\s{2,}", l.strip(), maxsplit=1)[0]
            listed_options |= set(OPTION.findall(head))
    return usage_commands, usage_options, listed_commands, listed_options


def roff_plain(line):
    """A roff line without its macro and font escapes: .BI \\-o " DIR" -> -o DIR."""
    line = re.sub(r"^\.[A-Z]{1,2}\s*", "", line)
    line = line.replace("\\-", "-").replace('"', " ")
    return re.sub(r"\\f[BIRP]", "", line)


def from_man(path):
    with open(path, encoding="utf-8") as fh:
        lines = fh.read().splitlines()
    section, items, synopsis = None, {"COMMANDS": [], "OPTIONS": []}, []
    for i, line in enumerate(lines):
        if line.startswith(".SH"):
            section = line[3:].strip().strip('"')
            continue
        if section == "SYNOPSIS":
            synopsis.append(roff_plain(line))
        elif section in items and line.startswith(".TP") and i + 1 < len(lines):
            items[section].append(roff_plain(lines[i + 1]))
    commands = {t.split()[0] for t in items["COMMANDS"] if t.split()}
    options = set()
    for t in items["OPTIONS"]:
        options |= set(OPTION.findall(t))
    # SYNOPSIS: "dissgen CMD" is split over .B lines: "dissgen check", "FILE.xml", ...
    syn_commands, syn_options = set(), set()
    for t in synopsis:
        m = re.match(r"dissgen\s+([a-z][\w-]*)", t)
        if m:
            syn_commands.add(m.group(1))
        syn_options |= set(OPTION.findall(t))
    return commands, options, syn_commands, syn_options


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dissgen", required=True)
    ap.add_argument("--man", required=True)
    args = ap.parse_args(argv)

    usage_cmds, usage_opts, help_cmds, help_opts = from_help(help_text(args.dissgen))
    man_cmds, man_opts, syn_cmds, syn_opts = from_man(args.man)
    all_cmds, all_opts = usage_cmds | help_cmds, usage_opts | help_opts
    passed = failed = 0

    def check(what, missing):
        nonlocal passed, failed
        if missing:
            failed += 1
            print("FAILED: %s: %s" % (what, " ".join(sorted(missing))))
        else:
            passed += 1
            print("ok: %s" % what)

    check("--help lists some commands and options", set() if help_cmds and help_opts else {"(none found)"})
    check("every command of the usage lines is in --help's command list", usage_cmds - help_cmds)
    check("every option of the usage lines is in --help's option list", usage_opts - help_opts)
    check("every command of --help has an item in the man page's COMMANDS", all_cmds - man_cmds)
    check("every COMMANDS item of the man page is in --help", man_cmds - all_cmds)
    check("every option of --help has an item in the man page's OPTIONS", all_opts - man_opts)
    check("every OPTIONS item of the man page is in --help", man_opts - all_opts)
    check("the man page's SYNOPSIS names every command", all_cmds - syn_cmds)
    check("the man page's SYNOPSIS names only commands and options of --help",
          (syn_cmds - all_cmds) | (syn_opts - all_opts))
    unknown = set()
    for cmd in sorted(all_cmds):
        p = subprocess.run([args.dissgen, cmd, "/nonexistent/rules.xml"], capture_output=True, text=True)
        if "unknown command" in p.stderr:
            unknown.add(cmd)
    check("dissgen knows every command --help lists (%s)" % ", ".join(sorted(all_cmds)), unknown)
    # --version says the version the man page's header names; no argument prints the usage and fails.
    with open(args.man, encoding="utf-8") as fh:
        header = re.search(r'^\.TH .*"(dissgen [^"]+)"', fh.read(), re.M)
    p = subprocess.run([args.dissgen, "--version"], capture_output=True, text=True)
    check("dissgen --version prints %r and exits 0 (it printed %r, exit %d)" % (
        header.group(1) if header else "?", p.stdout.strip(), p.returncode),
        set() if header and p.returncode == 0 and p.stdout.strip() == header.group(1) else {"--version"})
    p = subprocess.run([args.dissgen], capture_output=True, text=True)
    check("dissgen without a command prints the usage and exits 2 (exit %d)" % p.returncode,
          set() if p.returncode == 2 and p.stdout.startswith("usage:") else {"(no command)"})
    print("commands: %s; options: %s" % (" ".join(sorted(all_cmds)), " ".join(sorted(all_opts))))
    print("%d passed, %d failed" % (passed, failed))
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())

// SPDX-License-Identifier: GPL-2.0-or-later
// dissgen: rule file (XML) -> Wireshark dissector plugin.
//
//   dissgen check FILE.xml                 validate only
//   dissgen generate FILE.xml -o DIR       write the generated C++ into DIR
//   dissgen fields FILE.xml                list the display-filter fields
//   dissgen install FILE.xml [--dir DIR | --system]
//                                          generate, build and install the plugin
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "build_plugin.h"
#include "emit_cpp.h"
#include "parser.h"
#include "validator.h"
#include "wireshark_env.h"

namespace fs = std::filesystem;
using namespace dissgen;

namespace {

// Every command and option, each described once: tests/cli/help_vs_man.py
// checks that packaging/dissgen.1 documents the same ones (and only those).
const char kUsage[] =
    "usage: dissgen check FILE.xml\n"
    "       dissgen generate FILE.xml -o DIR\n"
    "       dissgen fields FILE.xml\n"
    "       dissgen install FILE.xml [--dir DIR | --system]\n"
    "       dissgen --help | --version\n"
    "\n"
    "commands:\n"
    "  check     validate the rule file; diagnostics as FILE:LINE: error: MESSAGE\n"
    "  generate  write the plugin's C++ source (dissgen_STEM.cpp) into DIR\n"
    "  fields    one line per field: display-filter name, Wireshark type, name\n"
    "  install   generate, compile against the installed Wireshark and install the\n"
    "            plugin (dissgen_STEM.so), per user by default\n"
    "\n"
    "options:\n"
    "  -o DIR      generate: the folder to write into\n"
    "  --dir DIR   install: into DIR instead of the per-user plugin folder\n"
    "  --system    install: into Wireshark's global plugin folder (needed when\n"
    "              Wireshark runs as root: it ignores per-user plugins)\n"
    "  -h, --help  print this help and exit\n"
    "  --version   print dissgen's version and exit\n";

struct Loaded {
    std::unique_ptr<Protocol> proto;
    bool ok = false;
};

// parse -> validate, printing diagnostics to stderr.
Loaded load(const std::string& path, Diagnostics& diags) {
    Loaded l;
    l.proto = parse_rule_file(path, diags);
    if (l.proto && !diags.has_errors()) validate(*l.proto, diags);
    l.ok = l.proto && !diags.has_errors();
    return l;
}

void print(const Diagnostics& diags, const std::string& path) { std::cerr << diags.format(path); }

// A protocol name already in the installed Wireshark makes the plugin refuse
// to load there. Only a warning for check: the rules may target another Wireshark.
void check_names_against_wireshark(const Protocol& p, Diagnostics& diags, bool as_error) {
    for (const InstalledProtocol& w : installed_protocols()) {
        if (w.name == p.name && w.short_name == p.abbreviation && w.filter == p.filter)
            continue;  // this very protocol, from a plugin installed earlier
        std::string clash;
        if (w.filter == p.filter) clash = "filter name '" + p.filter + "'";
        else if (w.short_name == p.abbreviation) clash = "abbreviation '" + p.abbreviation + "'";
        else if (w.name == p.name) clash = "name '" + p.name + "'";
        if (clash.empty()) continue;
        std::string msg = "the protocol " + clash + " is already used by Wireshark's '" + w.name + "' (" +
                          w.filter + "); the plugin will not load beside it: change it on <root>" +
                          (p.filter_given || clash.rfind("filter", 0) != 0 ? "" : " (e.g. filter=\"" + p.filter + "_rules\")");
        if (as_error) diags.error(p.line, msg);
        else diags.warning(p.line, msg);
        return;
    }
}

// The dissgen package installs a plugin per shipped rule file into Wireshark's
// global folder as dissgen-packaged-STEM.so, built from share/dissgen/rules/STEM.xml.
// Returns the one whose protocol shares a name with `p`, and that protocol's filter name.
struct Packaged {
    std::string plugin, filter;
};
Packaged packaged_plugin_for(const Protocol& p, const std::string& system_dir, const std::string& argv0) {
    const std::string prefix = "dissgen-packaged-", suffix = ".so";
    std::error_code ec;
    fs::path rules_dir = fs::path(share_dir(argv0)) / "rules";
    for (fs::directory_iterator it(system_dir, ec), end; !ec && it != end; it.increment(ec)) {
        std::string f = it->path().filename().string();
        if (f.size() <= prefix.size() + suffix.size() || f.rfind(prefix, 0) != 0 ||
            f.compare(f.size() - suffix.size(), suffix.size(), suffix) != 0)
            continue;
        fs::path rules = rules_dir / (f.substr(prefix.size(), f.size() - prefix.size() - suffix.size()) + ".xml");
        Diagnostics ignored;
        auto other = fs::exists(rules, ec) ? parse_rule_file(rules.string(), ignored) : nullptr;
        if (other && (other->filter == p.filter || other->abbreviation == p.abbreviation || other->name == p.name))
            return {it->path().string(), other->filter};
    }
    return {};
}

int cmd_check(const std::string& path) {
    Diagnostics diags;
    Loaded l = load(path, diags);
    if (l.ok) check_names_against_wireshark(*l.proto, diags, false);
    print(diags, path);
    return l.ok ? 0 : 1;
}

int cmd_fields(const std::string& path) {
    Diagnostics diags;
    Loaded l = load(path, diags);
    print(diags, path);
    if (!l.ok) return 1;
    std::cout << list_fields(*l.proto);
    return 0;
}

int cmd_generate(const std::string& path, const std::string& out_dir) {
    Diagnostics diags;
    Loaded l = load(path, diags);
    print(diags, path);
    if (!l.ok) return 1;
    std::string code = emit_cpp(*l.proto, fs::path(path).filename().string());
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    fs::path target = fs::path(out_dir) / (plugin_basename(path) + ".cpp");
    // Rewrite only on change, so builds that depend on the file stay up to date.
    std::ifstream old(target, std::ios::binary);
    std::string previous((std::istreambuf_iterator<char>(old)), std::istreambuf_iterator<char>());
    if (previous == code) return 0;
    std::ofstream out(target, std::ios::binary);
    out << code;
    if (!out) {
        std::cerr << "dissgen: cannot write " << target.string() << "\n";
        return 1;
    }
    return 0;
}

int cmd_install(const std::string& path, const std::string& dir, bool system, const std::string& argv0) {
    Diagnostics diags;
    Loaded l = load(path, diags);
    if (l.ok) check_names_against_wireshark(*l.proto, diags, system);
    print(diags, path);
    if (!l.ok || diags.has_errors()) return 1;

    auto headers = headers_version();
    if (!headers) {
        std::cerr << "dissgen: Wireshark's development files are missing (pkg-config wireshark): install libwireshark-dev\n";
        return 1;
    }
    auto running = tshark_version();
    if (running && *running != *headers) {
        std::cerr << "dissgen: the Wireshark headers are version " << *headers << " but tshark is " << *running
                  << "; Wireshark would reject the plugin. Install the libwireshark-dev that matches tshark.\n";
        return 1;
    }
    std::string target_dir = dir;
    if (system) {
        auto sys = system_plugin_dir();
        if (!sys) {
            std::cerr << "dissgen: cannot find Wireshark's plugin folder (pkg-config --variable=plugindir wireshark)\n";
            return 1;
        }
        target_dir = *sys;
    } else if (target_dir.empty()) {
        target_dir = user_plugin_dir(*headers);
        if (geteuid() == 0)
            std::cerr << "dissgen: note: you are root, and Wireshark run as root ignores per-user plugins; "
                         "installing into " << target_dir << " anyway. Use --system for root's Wireshark.\n";
    }
    // A packaged plugin for the same protocol: Wireshark registers per-user plugins
    // before global ones, so a per-user build takes over and the packaged one steps
    // aside; two global ones would register in directory order, i.e. unpredictably.
    if (auto sys = system_plugin_dir()) {
        std::error_code ec;
        bool into_system = system || fs::equivalent(target_dir, *sys, ec);
        auto [packaged, packaged_filter] = packaged_plugin_for(*l.proto, *sys, argv0);
        if (!packaged.empty() && into_system) {
            std::cerr << "dissgen: the dissgen package's " << packaged << " already provides protocol '"
                      << packaged_filter << "' in Wireshark's global plugin folder, and Wireshark would load "
                      << "the two in no fixed order. Install per user instead (without --system; Wireshark run "
                      << "as root ignores per-user plugins), or first set the packaged plugin aside:\n"
                      << "  dpkg-divert --local --rename --divert " << packaged << ".disabled --add " << packaged
                      << "\n";
            return 1;
        }
        if (!packaged.empty())
            std::cerr << "dissgen: note: the dissgen package's " << packaged << " provides protocol '"
                      << packaged_filter << "' too. Wireshark registers per-user plugins first, so this one "
                      << "replaces it for you and the packaged one steps aside. Wireshark run as root keeps the "
                      << "packaged one.\n";
    }
    std::string runtime = find_runtime_dir(argv0);
    if (runtime.empty()) {
        std::cerr << "dissgen: cannot find the plugin runtime (dissgen_runtime.cpp); set DISSGEN_RUNTIME_DIR\n";
        return 1;
    }
    BuildRequest req{emit_cpp(*l.proto, fs::path(path).filename().string()), plugin_basename(path), target_dir,
                     runtime};
    std::string installed;
    std::string error = build_and_install(req, installed);
    if (!error.empty()) {
        std::cerr << "dissgen: " << error << "\n";
        return 1;
    }
    std::cout << "installed " << installed << " (protocol " << l.proto->filter << ", Wireshark " << *headers
              << "); restart Wireshark to load it\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty() || args[0] == "-h" || args[0] == "--help" || args[0] == "help") {
        std::cout << kUsage;
        return args.empty() ? 2 : 0;
    }
    if (args[0] == "--version") {
        std::cout << "dissgen " DISSGEN_VERSION "\n";
        return 0;
    }
    const std::string command = args[0];
    std::string file, out_dir, dir;
    bool system = false;
    for (size_t i = 1; i < args.size(); ++i) {
        const std::string& a = args[i];
        if ((a == "-o" || a == "--dir") && i + 1 < args.size()) {
            (a == "-o" ? out_dir : dir) = args[++i];
        } else if (a == "--system") {
            system = true;
        } else if (!a.empty() && a[0] == '-') {
            std::cerr << "dissgen: unknown option '" << a << "'\n" << kUsage;
            return 2;
        } else if (file.empty()) {
            file = a;
        } else {
            std::cerr << "dissgen: one rule file at a time ('" << a << "' is extra)\n";
            return 2;
        }
    }
    if (file.empty()) {
        std::cerr << "dissgen: " << command << " needs a rule file\n" << kUsage;
        return 2;
    }
    if (command == "check") return cmd_check(file);
    if (command == "fields") return cmd_fields(file);
    if (command == "generate") {
        if (out_dir.empty()) {
            std::cerr << "dissgen: generate needs -o DIR\n";
            return 2;
        }
        return cmd_generate(file, out_dir);
    }
    if (command == "install") {
        if (system && !dir.empty()) {
            std::cerr << "dissgen: use either --dir or --system\n";
            return 2;
        }
        return cmd_install(file, dir, system, argv[0]);
    }
    std::cerr << "dissgen: unknown command '" << command << "'\n" << kUsage;
    return 2;
}

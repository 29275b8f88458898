// SPDX-License-Identifier: GPL-2.0-or-later
// dissgen: rule file (XML) -> Wireshark dissector plugin.
//
//   dissgen check FILE.xml                 validate only
//   dissgen generate FILE.xml -o DIR       write the generated C++ into DIR
//   dissgen fields FILE.xml                list the display-filter fields
//   dissgen install FILE.xml [--dir DIR | --system]
//                                          generate, build and install the plugin
//   dissgen esi PATH...                    list the device catalogue of ESI files
//   dissgen report CAPTURE... -o FILE.html timing report of an EtherCAT capture, or of
//                                          any protocol whose rules declare cycles or pairing
//   dissgen sources [FILE.xml]             the runtime files and compile options of a plugin
// check, generate, fields and install take --esi PATH (repeatable),
// --network FILE and --compact: the catalogue and the designed network are
// embedded into the plugin.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "analyses.h"
#include "build_plugin.h"
#include "ethercat/emit_catalogue.h"
#include "emit_cpp.h"
#include "ethercat/esi_reader.h"
#include "ethercat/network_reader.h"
#include "packaged_plugins.h"
#include "parser.h"
#include "report/any/cycles_model.h"
#include "report/any/cycles_page.h"
#include "report/capture_stream.h"
#include "report/ethercat/report_page.h"
#include "report/ethercat/timing_model.h"
#include "runtime_list.h"
#include "runtime_names.h"
#include "validator.h"
#include "wireshark_env.h"
#include "xml_input.h"

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
    "       dissgen esi PATH...\n"
    "       dissgen report CAPTURE... -o FILE.html [--rules FILE.xml] [--protocol FILTER]\n"
    "       dissgen sources [FILE.xml]\n"
    "       dissgen --help | --version\n"
    "  check, generate, fields, install and report also take [--esi PATH]... [--network FILE] [--compact]\n"
    "\n"
    "commands:\n"
    "  check     validate the rule file; diagnostics as FILE:LINE: error: MESSAGE\n"
    "  generate  write the plugin's C++ source (dissgen_STEM.cpp) into DIR\n"
    "  fields    one line per field: display-filter name, Wireshark type, name, and\n"
    "            where it comes from (rules, runtime, reassembly, pairing, the analysis, esi)\n"
    "  install   generate, compile against the installed Wireshark and install the\n"
    "            plugin (dissgen_STEM.so), per user by default\n"
    "  esi       list the devices of ESI files (a file or a folder of *.xml), one line\n"
    "            per revision: 0xVENDOR 0xPRODUCT 0xREVISION NAME, sorted\n"
    "  report    decode a capture with the installed plugin (with --esi or --network:\n"
    "            with a plugin built from the rules and those for this run) and write one\n"
    "            self-contained HTML page. EtherCAT: cycles, periods, jitter, round trips,\n"
    "            lost frames, working-counter errors, the slaves' AL states, the network\n"
    "            check; any other protocol whose rules declare <cycles> or <pairing>: its\n"
    "            cycles' periods and jitter, losses, round trips. Several captures (a\n"
    "            ring-buffer file set of dumpcap, in order) report as one\n"
    "  sources   what a plugin of the rule file (without one: of any rule file) is built\n"
    "            from: a line 'flags OPTION...', then 'source PATH' and 'header PATH' lines,\n"
    "            paths relative to the runtime folder (share/dissgen/runtime)\n"
    "\n"
    "options:\n"
    "  -o DIR          generate: the folder to write into; report: the HTML file\n"
    "  --dir DIR       install: into DIR instead of the per-user plugin folder\n"
    "  --system        install: into Wireshark's global plugin folder (needed when\n"
    "                  Wireshark runs as root: it ignores per-user plugins)\n"
    "  --esi PATH      embed the device catalogue of these ESI files (repeatable)\n"
    "  --network FILE  embed the designed network: a design (<network><slave type=\"EK1100\"/>..)\n"
    "                  or an ENI file; registers a field per PDO entry of its slaves\n"
    "  --compact       embed only the device models the network uses\n"
    "  --rules FILE    report: the rules of the plugin built for --esi/--network\n"
    "                  (default: the shipped ethercat.xml)\n"
    "  --protocol FILTER  report: the protocol to report on, by filter name, when\n"
    "                  several installed plugins have cycles or pairing\n"
    "  -h, --help      print this help and exit\n"
    "  --version       print dissgen's version and exit\n";

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

// The ESI catalogue and network design to embed (--esi, --network, --compact).
struct BusInput {
    std::vector<std::string> esi;
    std::string network_file;
    bool compact = false;

    Catalogue catalogue;
    Network network;
    bool given() const { return !esi.empty() || !network_file.empty(); }
    BusOptions options() const { return {network_file.empty() ? nullptr : &network, compact}; }
};

// Reads the ESI files and the network; diagnostics on stderr. False on any error.
bool load_bus(BusInput& bus) {
    if (bus.compact && bus.network_file.empty()) {
        std::cerr << "dissgen: --compact keeps the models a network uses: give --network FILE too\n";
        return false;
    }
    if (!bus.esi.empty() && !load_catalogue(bus.esi, bus.catalogue, std::cerr)) return false;
    if (bus.network_file.empty()) return true;
    Diagnostics diags;
    std::string text, why;
    if (!read_whole_file(bus.network_file, text, why)) diags.error(0, "cannot read the network file: " + why);
    else read_network(text, bus.network_file, bus.catalogue, bus.network, diags);
    print(diags, bus.network_file);
    return !diags.has_errors();
}

// The generated source, with the bus tables when --esi or --network was given.
std::string generate_source(const Protocol& proto, const std::string& path, const BusInput& bus) {
    if (!bus.given()) return emit_cpp(proto, fs::path(path).filename().string());
    EmbeddedTables tables = emit_bus(bus.catalogue, bus.options(), proto.filter);
    return emit_cpp(proto, fs::path(path).filename().string(), &tables);
}

int cmd_esi(const std::vector<std::string>& paths) {
    Catalogue cat;
    if (!load_catalogue(paths, cat, std::cerr)) return 1;
    std::cout << list_catalogue(cat);
    return 0;
}

// A protocol name already in the installed Wireshark makes the plugin refuse
// to load there. Only a warning for check: the rules may target another Wireshark.
void check_names_against_wireshark(const Protocol& p, Diagnostics& diags, bool as_error) {
    for (const InstalledProtocol& w : installed_protocols()) {
        const bool same = w.name == p.name && w.short_name == p.abbreviation && w.filter == p.filter;
        if (same && installed_by_dissgen(w.filter)) continue;  // this very protocol, from a plugin installed earlier
        std::string msg;
        if (same) {
            msg = "the protocol's name, abbreviation and filter name are those of Wireshark's own '" + w.name +
                  "' (" + w.filter + "); the plugin will not load beside it: change all three on <root>";
        } else {
            std::string clash;
            if (w.filter == p.filter) clash = "filter name '" + p.filter + "'";
            else if (w.short_name == p.abbreviation) clash = "abbreviation '" + p.abbreviation + "'";
            else if (w.name == p.name) clash = "name '" + p.name + "'";
            if (clash.empty()) continue;
            msg = "the protocol " + clash + " is already used by Wireshark's '" + w.name + "' (" + w.filter +
                  "); the plugin will not load beside it: change it on <root>" +
                  (p.filter_given || clash.rfind("filter", 0) != 0 ? "" : " (e.g. filter=\"" + p.filter + "_rules\")");
        }
        if (as_error) diags.error(p.line, msg);
        else diags.warning(p.line, msg);
        return;
    }
}

int cmd_check(const std::string& path, BusInput& bus) {
    Diagnostics diags;
    Loaded l = load(path, diags);
    if (l.ok) check_names_against_wireshark(*l.proto, diags, false);
    print(diags, path);
    bool bus_ok = load_bus(bus);
    return l.ok && bus_ok ? 0 : 1;
}

int cmd_fields(const std::string& path, BusInput& bus) {
    Diagnostics diags;
    Loaded l = load(path, diags);
    print(diags, path);
    if (!l.ok || !load_bus(bus)) return 1;
    std::cout << list_fields(*l.proto);
    if (bus.given()) std::cout << list_bus_fields(bus.catalogue, bus.options(), l.proto->filter);
    return 0;
}

int cmd_generate(const std::string& path, const std::string& out_dir, BusInput& bus) {
    Diagnostics diags;
    Loaded l = load(path, diags);
    print(diags, path);
    if (!l.ok || !load_bus(bus)) return 1;
    std::string code = generate_source(*l.proto, path, bus);
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

int cmd_install(const std::string& path, const std::string& dir, bool system, const std::string& argv0,
                BusInput& bus) {
    Diagnostics diags;
    Loaded l = load(path, diags);
    if (l.ok) check_names_against_wireshark(*l.proto, diags, system);
    print(diags, path);
    if (!l.ok || diags.has_errors() || !load_bus(bus)) return 1;

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
        auto [packaged, packaged_filter] =
            packaged_plugin_for(*l.proto, *sys, (fs::path(share_dir(argv0)) / "rules").string());
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
        std::cerr << "dissgen: cannot find the plugin runtime (dissgen_runtime.h and its sources); set DISSGEN_RUNTIME_DIR\n";
        return 1;
    }
    BuildRequest req{generate_source(*l.proto, path, bus), plugin_basename(path), target_dir, runtime,
                     analysis_runtime_sources(*l.proto)};
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

// A plugin of `rules` with the catalogue/network of `bus`, built into a new
// folder that tshark then uses as its HOME: the plugin sits in that HOME's
// per-user plugin folder, where it takes over from a packaged one as usual,
// and no plugin the user installed gets in its way. "" on failure.
std::string build_report_plugin(const std::string& rules, BusInput& bus, const std::string& argv0) {
    Diagnostics diags;
    Loaded l = load(rules, diags);
    print(diags, rules);
    if (!l.ok || !load_bus(bus)) return "";
    auto headers = headers_version();
    std::string runtime = find_runtime_dir(argv0);
    if (!headers || runtime.empty()) {
        std::cerr << "dissgen: report: building a plugin for --esi/--network needs libwireshark-dev and the runtime\n";
        return "";
    }
    std::string tried;
    const std::string root = make_temp_folder("dissgen-report", tried);
    if (root.empty()) {
        std::cerr << "dissgen: report: cannot create a temporary folder in " << tried << "\n";
        return "";
    }
    BuildRequest req{generate_source(*l.proto, rules, bus), plugin_basename(rules), user_plugin_dir(*headers, root), runtime,
                     analysis_runtime_sources(*l.proto)};
    std::string installed, error = build_and_install(req, installed);
    if (!error.empty()) {
        std::cerr << "dissgen: report: " << error << "\n";
        std::error_code ec;
        fs::remove_all(root, ec);
        return "";
    }
    return root;
}

// "" when `path` is open for writing, else a message for the user.
std::string open_report(const std::string& path, std::ofstream& out) {
    out.open(path, std::ios::binary);
    return out ? "" : "cannot write " + path + ": " + std::strerror(errno);
}

// Why the report could not be written at `path`, found before the capture is
// read (a missing folder, one that cannot be written); "" when it can be.
std::string report_path_problem(const std::string& path) {
    fs::path folder = fs::path(path).parent_path();
    if (folder.empty()) folder = ".";
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) return "cannot write " + path + ": no folder " + folder.string();
    if (access(folder.c_str(), W_OK) != 0) return "cannot write " + path + ": " + std::strerror(errno);
    return "";
}

// The runtime files and compile options of a plugin of `path` ("" for every
// analysis): plugin_runtime/runtime.list, as dissgen compiles it.
int cmd_sources(const std::string& path) {
    std::vector<const Analysis*> wanted;
    if (path.empty()) {
        for (const Analysis& a : analyses()) wanted.push_back(&a);
    } else {
        Diagnostics diags;
        Loaded l = load(path, diags);
        print(diags, path);
        if (!l.ok) return 1;
        if (const Analysis* a = analysis_of(*l.proto)) wanted.push_back(a);
    }
    std::cout << runtime_files_text(runtime_list(), wanted);
    return 0;
}

// Reads the capture into a Model with its Builder (the EtherCAT one, or any
// protocol's with <cycles>/<pairing>) and writes its page with `write`.
template <class Model, class Builder>
int write_report(CaptureStream& stream, const std::vector<std::string>& known, const std::string& protocol,
                 const std::vector<std::string>& captures, const std::string& out_path,
                 std::string (*write)(const Model&, const std::string&, std::ostream&)) {
    stream.fields = Builder::fields(protocol, known);
    stream.extra_args = Builder::statistics_args(protocol, known);
    Model model;
    model.captures = captures;
    Builder builder(protocol, stream.fields, model);
    stream.on_other_line = [&](std::string_view line) { builder.add_statistics_line(line); };
    std::string error = read_capture(stream, captures, [&](const FieldRow& row) { builder.add(row); });
    std::ofstream out;
    if (error.empty()) error = open_report(out_path, out);
    if (error.empty()) error = write(model, DISSGEN_VERSION, out);
    if (!error.empty()) {
        std::cerr << "dissgen: report: " << error << "\n";
        return 1;
    }
    std::cout << "wrote " << out_path << ": " << model.frames << " frames, " << model.cycles.size() << " cycles\n";
    return 0;
}

// Which protocol to report on: `wanted` (--protocol), else the EtherCAT one,
// else the only one with cycles or pairing. "" after a message when none or
// several fit; `ethercat` says which report it gets.
std::string choose_protocol(const std::vector<std::string>& known, const std::string& wanted,
                            const std::string& tshark, bool& ethercat) {
    const std::string ecat = ethercat_protocol(known);
    const std::vector<std::string> others = cycles_protocols(known, ecat);
    ethercat = !ecat.empty() && (wanted.empty() || wanted == ecat);
    if (ethercat) return ecat;
    if (!wanted.empty()) {
        if (std::find(others.begin(), others.end(), wanted) != others.end()) return wanted;
        std::cerr << "dissgen: report: " << tshark << " has no protocol '" << wanted
                  << "' of dissgen with cycles or pairing\n";
        return "";
    }
    if (others.size() == 1) return others[0];
    if (others.empty()) {
        std::cerr << "dissgen: report: " << tshark << " has no EtherCAT plugin of dissgen (no protocol with "
                     "the " DG_ANALYSIS_ETHERCAT_ESC " analysis's fields) and no plugin whose rules declare "
                     "<cycles> or <pairing>: install one first, e.g. dissgen install rules/ethercat.xml\n";
        if (geteuid() == 0)
            std::cerr << "dissgen: report: (run as root, tshark reads no per-user plugin folder: a plugin that "
                         "`dissgen install` put in your home is not seen; run the report as that user, or install "
                         "it with --system)\n";
        return "";
    }
    std::cerr << "dissgen: report: several protocols have cycles or pairing (";
    for (size_t i = 0; i < others.size(); ++i) std::cerr << (i ? ", " : "") << others[i];
    std::cerr << "): choose one with --protocol\n";
    return "";
}

int cmd_report(const std::vector<std::string>& captures, const std::string& out_path, std::string rules,
               const std::string& wanted, BusInput& bus, const std::string& argv0) {
    if (std::string problem = report_path_problem(out_path); !problem.empty()) {
        std::cerr << "dissgen: report: " << problem << "\n";
        return 1;
    }
    CaptureStream stream;
    if (const char* t = std::getenv("DISSGEN_TSHARK"); t && *t) stream.tshark = t;
    std::string plugin_root;
    if (bus.given()) {
        // Wireshark run as root reads no plugin folder but its own.
        if (geteuid() == 0) {
            std::cerr << "dissgen: report: --esi/--network build a plugin for this run, into a per-user plugin "
                         "folder, which Wireshark run as root does not read: run the report as a normal user, or "
                         "install the plugin with them (dissgen install --system ...) and run the report without\n";
            return 1;
        }
        if (rules.empty()) rules = (fs::path(share_dir(argv0)) / "rules" / "ethercat.xml").string();
        plugin_root = build_report_plugin(rules, bus, argv0);
        if (plugin_root.empty()) return 1;
        stream.environment.push_back({"HOME", plugin_root});
    }
    struct Cleanup {
        std::string d;
        ~Cleanup() {
            std::error_code ec;
            if (!d.empty()) fs::remove_all(d, ec);
        }
    } cleanup{plugin_root};

    std::vector<std::string> known = known_fields(stream);
    bool ethercat = false;
    std::string protocol = choose_protocol(known, wanted, stream.tshark, ethercat);
    if (protocol.empty()) return 1;
    if (ethercat)
        return write_report<TimingModel, TimingModelBuilder>(stream, known, protocol, captures, out_path,
                                                             write_report_html);
    return write_report<CyclesModel, CyclesModelBuilder>(stream, known, protocol, captures, out_path,
                                                         write_cycles_report_html);
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty() || args[0] == "help") {
        std::cout << kUsage;
        return args.empty() ? 2 : 0;
    }
    // -h/--help anywhere (`dissgen install --help`): the help, not a usage error
    for (const std::string& a : args)
        if (a == "-h" || a == "--help") {
            std::cout << kUsage;
            return 0;
        }
    if (args[0] == "--version") {
        std::cout << "dissgen " DISSGEN_VERSION "\n";
        return 0;
    }
    const std::string command = args[0];
    std::string out_dir, dir, rules, protocol;
    std::vector<std::string> files;
    bool system = false;
    BusInput bus;
    for (size_t i = 1; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "-o" || a == "--dir" || a == "--esi" || a == "--network" || a == "--rules" ||
            a == "--protocol") {
            if (i + 1 >= args.size()) {
                std::cerr << "dissgen: " << a << " needs a value\n";
                return 2;
            }
            const std::string& v = args.at(++i);
            if (a == "-o") out_dir = v;
            else if (a == "--rules") rules = v;
            else if (a == "--protocol") protocol = v;
            else if (a == "--dir") dir = v;
            else if (a == "--esi") bus.esi.push_back(v);
            else if (!bus.network_file.empty()) {
                std::cerr << "dissgen: one --network at a time\n";
                return 2;
            } else bus.network_file = v;
        } else if (a == "--system") {
            system = true;
        } else if (a == "--compact") {
            bus.compact = true;
        } else if (!a.empty() && a[0] == '-') {
            std::cerr << "dissgen: unknown option '" << a << "'\n" << kUsage;
            return 2;
        } else {
            files.push_back(a);
        }
    }
    if (command == "esi") {
        if (files.empty() || bus.given() || bus.compact) {
            std::cerr << "dissgen: esi takes ESI files or folders only\n" << kUsage;
            return 2;
        }
        return cmd_esi(files);
    }
    if (command == "report") {
        if (files.empty() || out_dir.empty()) {
            std::cerr << "dissgen: report takes captures (one, or a ring-buffer set in order) and -o FILE.html\n"
                      << kUsage;
            return 2;
        }
        return cmd_report(files, out_dir, rules, protocol, bus, argv[0]);
    }
    if (command == "sources") {
        if (files.size() > 1 || bus.given() || bus.compact || !out_dir.empty() || !dir.empty() || system ||
            !rules.empty() || !protocol.empty()) {
            std::cerr << "dissgen: sources takes at most one rule file\n" << kUsage;
            return 2;
        }
        return cmd_sources(files.empty() ? "" : files[0]);
    }
    if (!rules.empty() || !protocol.empty()) {
        std::cerr << "dissgen: " << (rules.empty() ? "--protocol" : "--rules") << " is an option of report\n";
        return 2;
    }
    if (files.size() > 1) {
        std::cerr << "dissgen: one rule file at a time ('" << files[1] << "' is extra)\n";
        return 2;
    }
    const std::string file = files.empty() ? "" : files[0];
    if (file.empty()) {
        std::cerr << "dissgen: " << command << " needs a rule file\n" << kUsage;
        return 2;
    }
    if (command == "check") return cmd_check(file, bus);
    if (command == "fields") return cmd_fields(file, bus);
    if (command == "generate") {
        if (out_dir.empty()) {
            std::cerr << "dissgen: generate needs -o DIR\n";
            return 2;
        }
        return cmd_generate(file, out_dir, bus);
    }
    if (command == "install") {
        if (system && !dir.empty()) {
            std::cerr << "dissgen: use either --dir or --system\n";
            return 2;
        }
        return cmd_install(file, dir, system, argv[0], bus);
    }
    std::cerr << "dissgen: unknown command '" << command << "'\n" << kUsage;
    return 2;
}

// SPDX-License-Identifier: GPL-2.0-or-later
// Helpers shared by the unit tests: run the generator's front end on a rule
// file or on text, and read files of the source tree.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "analyses.h"
#include "diagnostics.h"
#include "model.h"
#include "parser.h"
#include "validator.h"

namespace dissgen::testing {

inline std::string source_path(const std::string& relative) { return std::string(DISSGEN_SOURCE_DIR) + "/" + relative; }

inline std::string read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct Front {
    std::unique_ptr<Protocol> proto;
    Diagnostics diags;
    bool ok() const { return proto && !diags.has_errors(); }
    std::string messages() const { return diags.format("rules.xml"); }
};

// parse + validate, as `dissgen check` does (without asking tshark).
inline Front front_end(const std::string& xml) {
    Front f;
    f.proto = parse_rules(xml, f.diags);
    if (f.proto && !f.diags.has_errors()) validate(*f.proto, f.diags);
    return f;
}

// A rule file with one root around `body`.
inline std::string rules(const std::string& body, const std::string& root_attrs = "ethertype=\"0x88b5\"") {
    return "<root name=\"Test\" abbreviation=\"TST\" " + root_attrs + ">\n" + body + "</root>\n";
}

// The first node named `name`, in document order.
inline const Node* find(const Protocol& proto, const std::string& name) {
    const Node* found = nullptr;
    for_each_node(proto.nodes, [&](const Node& n) {
        if (!found && n.name == name) found = &n;
    });
    return found;
}

// A fresh folder under /tmp, removed with all it holds when it goes out of scope;
// an empty path when it could not be made.
class TempDir {
public:
    explicit TempDir(const std::string& prefix) {
        std::string tmpl = "/tmp/" + prefix + "-XXXXXX";
        if (mkdtemp(tmpl.data())) path_ = tmpl;
    }
    ~TempDir() {
        std::error_code ec;
        if (!path_.empty()) std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

inline bool contains(const std::string& haystack, const std::string& needle) {
    return haystack.find(needle) != std::string::npos;
}

// How many times `needle` occurs in `haystack`.
inline size_t count_of(const std::string& haystack, const std::string& needle) {
    size_t n = 0;
    for (size_t at = haystack.find(needle); at != std::string::npos; at = haystack.find(needle, at + 1)) ++n;
    return n;
}

// What <pairing analysis="NAME"> needs in a small test file: the <input>
// lines inside <pairing>, and the nodes they name (from <root>): a leaf per
// input of the message, and, in a repeated node, one per input of each
// instance. One line each.
struct AnalysisScaffold {
    std::vector<std::string> inputs, nodes;
};

inline AnalysisScaffold analysis_scaffold(const std::string& name) {
    AnalysisScaffold s;
    const Analysis* a = find_analysis(name);
    if (!a) return s;
    std::vector<std::string> own, repeated, registers;
    for (size_t i = 0; i < a->inputs.size(); ++i) {
        const std::string leaf = "Input " + std::to_string(i);
        const std::string path = a->inputs[i].per_instance ? "node[@name='Inputs']/node[@name='" + leaf + "']"
                                 : a->inputs[i].address    ? "node[@name='Registers']/node[@name='" + leaf + "']"
                                                           : "node[@name='" + leaf + "']";
        s.inputs.push_back("    <input name=\"" + a->inputs[i].name + "\" field=\"" + path + "\"/>");
        const std::string at = a->inputs[i].address ? " at=\"" + std::to_string(0x100 + 2 * i) + "\"" : "";
        (a->inputs[i].per_instance ? repeated : a->inputs[i].address ? registers : own)
            .push_back("<node name=\"" + leaf + "\" length=\"1byte\" displaytype=\"numberdec\"" + at + "/>");
    }
    s.nodes.push_back("  <node name=\"Input count\" length=\"1byte\" displaytype=\"numberdec\"/>");
    for (const std::string& n : own) s.nodes.push_back("  " + n);
    s.nodes.push_back("  <node name=\"Inputs\" count=\"../node[@name='Input count']\">");
    for (const std::string& n : repeated) s.nodes.push_back("    " + n);
    s.nodes.push_back("  </node>");
    if (!registers.empty()) {
        // a register map on the input count: each register input names one of its registers
        s.nodes.push_back("  <node name=\"Registers\" base=\"../node[@name='Input count']\" length=\"rest\">");
        for (const std::string& n : registers) s.nodes.push_back("    " + n);
        s.nodes.push_back("  </node>");
    }
    return s;
}

// The lines joined, each ended by a newline.
inline std::string lines_of(const std::vector<std::string>& lines) {
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
}

}  // namespace dissgen::testing

// SPDX-License-Identifier: GPL-2.0-or-later
// The runtime's names (plugin_runtime/dissgen_names.h, read through
// generator/runtime_names.h): every one of them, generic, the pairing's and
// each analysis', is refused as a rule field's filter name where the runtime
// registers it, and only there. The rule files are written from the list, so
// a name added to it is tested here without another line.
#include <gtest/gtest.h>

#include <set>
#include <sstream>
#include <vector>

#include "runtime_names.h"
#include "analyses.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

using Kind = RuntimeName::Kind;
using When = NameGroup::When;

// The part of a filter name after "tst." that a rule field takes to clash
// with `n`: the name itself, or one under the prefix.
std::string clashing_name(const RuntimeName& n) {
    return n.kind == Kind::Prefix ? std::string(n.name) + "x" : std::string(n.name);
}

// Nodes whose last one is named tst.NAME: a container per dotted segment,
// then the leaf. One line each, closing tags after the leaf.
std::vector<std::string> nodes_named(const std::string& name) {
    std::vector<std::string> segments;
    std::istringstream in(name);
    for (std::string s; std::getline(in, s, '.');) segments.push_back(s);
    std::vector<std::string> lines;
    for (size_t i = 0; i + 1 < segments.size(); ++i)
        lines.push_back("  <node name=\"C" + std::to_string(i) + "\" filter=\"" + segments[i] + "\">");
    lines.push_back("  <node name=\"Leaf\" filter=\"" + segments.back() +
                    "\" length=\"1byte\" displaytype=\"numberdec\"/>");
    for (size_t i = 0; i + 1 < segments.size(); ++i) lines.push_back("  </node>");
    return lines;
}

// What a rule file needs around its own nodes for the runtime to register a
// group's names: before them, and after them.
struct Scaffold {
    std::vector<std::string> before, after;
};

Scaffold scaffold_for(const NameGroup& g) {
    const std::string key = "  <key field=\"node[@name='Id']\"/>";
    const std::string id = "  <node name=\"Id\" length=\"2byte\" displaytype=\"numberdec\"/>";
    switch (g.when) {
        case When::Always: return {};
        case When::Reassembly:
            return {{id, "  <node name=\"Seq\" length=\"1byte\" displaytype=\"numberdec\"/>"},
                    {"  <node name=\"Data\" length=\"rest\" reassemble-id=\"../node[@name='Id']\" "
                     "reassemble-seq=\"../node[@name='Seq']\" reassemble-more=\"../node[@name='Seq']\"/>"}};
        case When::Pairing: return {{"  <pairing>", key, "  </pairing>", id}, {}};
        case When::RequestContext:
            return {{"  <pairing>", key, "  </pairing>", id}, {"  <node name=\"Again\" value=\"request{Id}\"/>"}};
        case When::Cycles:
            return {{"  <cycles>", "  <signature field=\"node[@name='Id']\"/>", "  </cycles>", id}, {}};
        case When::Analysis: {
            const AnalysisScaffold inputs = analysis_scaffold(g.analysis);
            Scaffold s{{"  <pairing analysis=\"" + std::string(g.analysis) + "\">", key}, inputs.nodes};
            s.before.insert(s.before.end(), inputs.inputs.begin(), inputs.inputs.end());
            s.before.push_back("  </pairing>");
            s.before.push_back(id);
            return s;
        }
    }
    return {};
}

// A rule file of `scaffold` around the nodes named tst.NAME; *leaf_line is
// the line of the field named so.
std::string rule_file(const Scaffold& scaffold, const std::string& name, int* leaf_line) {
    std::vector<std::string> lines = {"<root name=\"Test\" abbreviation=\"TST\" ethertype=\"0x88b5\">"};
    lines.insert(lines.end(), scaffold.before.begin(), scaffold.before.end());
    std::vector<std::string> own = nodes_named(name);
    *leaf_line = static_cast<int>(lines.size() + (own.size() + 1) / 2);
    lines.insert(lines.end(), own.begin(), own.end());
    lines.insert(lines.end(), scaffold.after.begin(), scaffold.after.end());
    lines.push_back("</root>");
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
}

TEST(RuntimeNames, EveryNameIsRefusedWhereTheRuntimeRegistersIt) {
    size_t tested = 0;
    for (const NameGroup& g : runtime_name_groups()) {
        for (const RuntimeName& n : g.names) {
            int line = 0;
            const std::string name = clashing_name(n);
            const std::string xml = rule_file(scaffold_for(g), name, &line);
            Front f = front_end(xml);
            const std::string expected = "rules.xml:" + std::to_string(line) + ": error: filter name 'tst." + name +
                                         "' is reserved for " + g.owner;
            EXPECT_FALSE(f.ok()) << "tst." << name << " (" << g.source << ") was accepted:\n" << xml;
            EXPECT_TRUE(contains(f.messages(), expected))
                << "expected " << expected << "...\ngot:\n" << f.messages() << "for:\n" << xml;
            ++tested;
        }
    }
    EXPECT_GE(tested, 54u);  // as many as the list held when this test was written
}

// The names of the reassembly, the pairing and an analysis are free for a
// protocol without them (enip.xml, say, may well have a "slave" field).
TEST(RuntimeNames, OtherNamesAreFreeWithoutThePartThatRegistersThem) {
    std::set<std::string> everywhere;
    for (const RuntimeName& n : name_group(When::Always).names) everywhere.insert(n.name);
    for (const NameGroup& g : runtime_name_groups()) {
        if (g.when == When::Always) continue;
        for (const RuntimeName& n : g.names) {
            if (everywhere.count(n.name)) continue;
            int line = 0;
            const std::string xml = rule_file({}, clashing_name(n), &line);
            Front f = front_end(xml);
            EXPECT_TRUE(f.ok()) << "tst." << clashing_name(n) << " (" << g.source << "):\n" << f.messages();
        }
    }
}

// A prefix reserves the names under it, not the name itself.
TEST(RuntimeNames, APrefixLeavesItsOwnNameFree) {
    for (const NameGroup& g : runtime_name_groups()) {
        for (const RuntimeName& n : g.names) {
            if (n.kind != Kind::Prefix) continue;
            std::string own(n.name);
            own.pop_back();  // the '.'
            int line = 0;
            Front f = front_end(rule_file(scaffold_for(g), own, &line));
            EXPECT_TRUE(f.ok()) << "tst." << own << ":\n" << f.messages();
        }
    }
}

TEST(RuntimeNames, EveryAnalysisHasItsNames) {
    for (const Analysis& analysis : analyses()) {
        bool found = false;
        for (const NameGroup& g : runtime_name_groups())
            found = found || (g.when == When::Analysis && g.analysis == analysis.name);
        EXPECT_TRUE(found) << analysis.name;
    }
}

TEST(RuntimeNames, NamesAreUniqueInTheirGroupAndPrefixesEndWithADot) {
    for (const NameGroup& g : runtime_name_groups()) {
        std::set<std::string> seen;
        for (const RuntimeName& n : g.names) {
            EXPECT_TRUE(seen.insert(n.name).second) << g.source << ": " << n.name;
            if (n.kind == Kind::Prefix) EXPECT_EQ(std::string(n.name).back(), '.') << n.name;
        }
    }
}

// The bus model's names: the clash that made `tshark -Y 'P.slave == 3'` fail
// ("P.slave (type=Label) cannot participate in == comparison").
TEST(RuntimeNames, BusModelNamesAreReservedForTheEthercatAnalysis) {
    std::set<std::string> names;
    for (const NameGroup& g : runtime_name_groups())
        if (g.when == When::Analysis && std::string(g.analysis) == "ethercat-esc")
            for (const RuntimeName& n : g.names) names.insert(n.name);
    for (const char* name : {"slave", "slave.position", "slave.name", "process_data", "wkc.expected", "pdo.entry",
                             "pdo.", "expert.network.count", "expert.wkc", "esc", "expert.forwarding"})
        EXPECT_TRUE(names.count(name)) << name;
}

}  // namespace
}  // namespace dissgen::testing

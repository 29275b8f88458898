// SPDX-License-Identifier: GPL-2.0-or-later
#include "runtime_names.h"

#include "../plugin_runtime/dissgen_names.h"
#include "analyses.h"

namespace dissgen {

namespace {

using Kind = RuntimeName::Kind;
using When = NameGroup::When;

// The rows of dissgen_names.h as the generator sees them: types, bases and
// severities as the text of their Wireshark constants.
#define DISSGEN_FIELD(id, name, type, display, strings, label, blurb) \
    {Kind::Field, #id, name, #type, #display, label, "", ""},
#define DISSGEN_EXPERT(id, name, group, severity, summary) \
    {Kind::Expert, #id, name, "FT_NONE", "BASE_NONE", summary, #group, #severity},
#define DISSGEN_PREFIX(prefix) {Kind::Prefix, "", prefix, "", "", "", "", ""},

std::vector<NameGroup> make_groups() {
    return {
        {When::Always, "", "the runtime of every protocol", "runtime",
         {DG_RUNTIME_FIELDS(DISSGEN_FIELD) DG_RUNTIME_EXPERTS(DISSGEN_EXPERT)}},
        {When::Reassembly, "", "the reassembly", "reassembly", {DG_FRAGMENT_FIELDS(DISSGEN_FIELD)}},
        {When::Pairing, "", "the request/response pairing", "pairing",
         {DG_PAIRING_FIELDS(DISSGEN_FIELD) DG_PAIRING_EXPERTS(DISSGEN_EXPERT)}},
        {When::RequestContext, "", "values read from the paired request", "request context",
         {DG_REQUEST_CONTEXT_EXPERTS(DISSGEN_EXPERT)}},
        {When::Cycles, "", "the cycles of <cycles>", "cycles",
         {DG_CYCLES_FIELDS(DISSGEN_FIELD) DG_CYCLES_EXPERTS(DISSGEN_EXPERT)}},
        {When::Analysis, DG_ANALYSIS_ETHERCAT_ESC, "the " DG_ANALYSIS_ETHERCAT_ESC " analysis",
         DG_ANALYSIS_ETHERCAT_ESC,
         {DG_ESC_FIELDS(DISSGEN_FIELD) DG_BUS_FIELDS(DISSGEN_FIELD) DG_CYCLE_FIELDS(DISSGEN_FIELD) DG_DC_FIELDS(DISSGEN_FIELD) DG_ESC_EXPERTS(DISSGEN_EXPERT)
              DG_BUS_EXPERTS(DISSGEN_EXPERT) DG_BUS_PREFIXES(DISSGEN_PREFIX)}},
    };
}

#undef DISSGEN_FIELD
#undef DISSGEN_EXPERT
#undef DISSGEN_PREFIX

bool reassembles(const Protocol& proto) {
    bool any = false;
    for_each_node(proto.nodes, [&](const Node& n) { any = any || n.reassembles(); });
    return any;
}

bool applies(const NameGroup& g, const Protocol& proto) {
    switch (g.when) {
        case When::Always: return true;
        case When::Reassembly: return reassembles(proto);
        case When::Pairing: return proto.pairing != nullptr;
        case When::RequestContext: return proto.pairing && !proto.request_fields.empty();
        case When::Cycles: return proto.cycles != nullptr && !analysis_times_cycles(proto);
        case When::Analysis: return proto.pairing && proto.pairing->analysis == g.analysis;
    }
    return false;
}

bool clashes(const RuntimeName& n, const std::string& rest) {
    if (n.kind == Kind::Prefix) return rest.compare(0, std::string(n.name).size(), n.name) == 0;
    return rest == n.name;
}

}  // namespace

const std::vector<NameGroup>& runtime_name_groups() {
    static const std::vector<NameGroup> groups = make_groups();
    return groups;
}

const NameGroup& name_group(NameGroup::When when) {
    for (const NameGroup& g : runtime_name_groups())
        if (g.when == when) return g;
    return runtime_name_groups().front();
}

std::vector<const NameGroup*> name_groups_of(const Protocol& proto) {
    std::vector<const NameGroup*> out;
    for (const NameGroup& g : runtime_name_groups())
        if (applies(g, proto)) out.push_back(&g);
    return out;
}

std::optional<NameClash> runtime_name_clash(const std::vector<const NameGroup*>& groups,
                                            const std::string& protocol_filter, const std::string& filter_name) {
    const std::string head = protocol_filter + ".";
    if (filter_name.compare(0, head.size(), head) != 0) return std::nullopt;
    const std::string rest = filter_name.substr(head.size());
    for (const NameGroup* g : groups)
        for (const RuntimeName& n : g->names)
            if (clashes(n, rest)) return NameClash{g, &n};
    return std::nullopt;
}

std::string NameClash::description(const std::string& protocol_filter) const {
    std::string what = group->owner;
    switch (name->kind) {
        case Kind::Field: return what + " (its field '" + name->label + "')";
        case Kind::Expert: return what + " (its expert info '" + name->label + "')";
        case Kind::Prefix: return what + " (its fields under '" + protocol_filter + "." + name->name + "')";
    }
    return what;
}

std::string runtime_filter_name(const std::string& protocol_filter, const char* name) {
    return protocol_filter + "." + name;
}

std::string runtime_expert_summary(const char* name) {
    for (const NameGroup& g : runtime_name_groups())
        for (const RuntimeName& n : g.names)
            if (n.kind == RuntimeName::Kind::Expert && std::string(n.name) == name) return n.label;
    return name;
}

}  // namespace dissgen

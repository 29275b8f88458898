// SPDX-License-Identifier: GPL-2.0-or-later
// The names the runtime, the request/response pairing and each analysis
// register under a protocol's filter name P, read from the runtime's own list
// (plugin_runtime/dissgen_names.h): the validator reserves them, the emitter
// registers the generic ones, `dissgen fields` lists them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "model.h"
#include "../plugin_runtime/dissgen_names.h"

namespace dissgen {

struct RuntimeName {
    enum class Kind { Field, Expert, Prefix };
    Kind kind;
    const char* id;        // the row's C identifier (hf_ID, ei_ID, frag_hf_ID, a dg_experts member)
    const char* name;      // after "P."; a Prefix ends with '.'
    const char* type;      // "FT_UINT16"; an expert info is an FT_NONE field to Wireshark
    const char* display;   // "BASE_HEX" (fields)
    const char* label;     // display name; an expert info's summary
    const char* group;     // "PI_MALFORMED" (expert infos)
    const char* severity;  // "PI_ERROR" (expert infos)
};

// The names one part of the runtime registers, and for which protocols.
struct NameGroup {
    enum class When { Always, Reassembly, Pairing, RequestContext, Cycles, Analysis };
    When when;
    const char* analysis;  // When::Analysis: the <pairing analysis="..."> it belongs to
    const char* owner;     // in diagnostics: "is reserved for OWNER"
    const char* source;    // in `dissgen fields`: where the field comes from
    std::vector<RuntimeName> names;
};

// Every group, in the order `dissgen fields` lists them.
const std::vector<NameGroup>& runtime_name_groups();

// The group of the runtime's names for every protocol, for reassembly or for
// the pairing (not for an analysis: there may be several).
const NameGroup& name_group(NameGroup::When when);

// The groups whose names a protocol gets.
std::vector<const NameGroup*> name_groups_of(const Protocol& proto);

// A rule field's filter name that is one of the runtime's, or under one of its prefixes.
struct NameClash {
    const NameGroup* group;
    const RuntimeName* name;
    std::string description(const std::string& protocol_filter) const;  // "the ... analysis (its field 'Slave')"
};
std::optional<NameClash> runtime_name_clash(const std::vector<const NameGroup*>& groups,
                                            const std::string& protocol_filter, const std::string& filter_name);

// Each runtime name as a constant named by its row's identifier
// (runtime_field::period is "cycle.period"): code that reads a plugin's fields
// (dissgen report) names them through the one list, so that a rename reaches
// it and a removed row no longer compiles, instead of silently emptying it.
#define DISSGEN_NAME_CONSTANT(id, name, ...) inline constexpr const char id[] = name;
namespace runtime_field {
DG_RUNTIME_FIELDS(DISSGEN_NAME_CONSTANT)
DG_FRAGMENT_FIELDS(DISSGEN_NAME_CONSTANT)
DG_PAIRING_FIELDS(DISSGEN_NAME_CONSTANT)
DG_CYCLES_FIELDS(DISSGEN_NAME_CONSTANT)
DG_ESC_FIELDS(DISSGEN_NAME_CONSTANT)
DG_BUS_FIELDS(DISSGEN_NAME_CONSTANT)
DG_CYCLE_FIELDS(DISSGEN_NAME_CONSTANT)
DG_DC_FIELDS(DISSGEN_NAME_CONSTANT)
}  // namespace runtime_field
namespace runtime_expert {
DG_RUNTIME_EXPERTS(DISSGEN_NAME_CONSTANT)
DG_PAIRING_EXPERTS(DISSGEN_NAME_CONSTANT)
DG_REQUEST_CONTEXT_EXPERTS(DISSGEN_NAME_CONSTANT)
DG_CYCLES_EXPERTS(DISSGEN_NAME_CONSTANT)
DG_ESC_EXPERTS(DISSGEN_NAME_CONSTANT)
DG_BUS_EXPERTS(DISSGEN_NAME_CONSTANT)
}  // namespace runtime_expert
#undef DISSGEN_NAME_CONSTANT

// "P.NAME": a runtime name under a protocol's filter name.
std::string runtime_filter_name(const std::string& protocol_filter, const char* name);

// The expert info's summary, as the plugin labels it (its row in the list).
std::string runtime_expert_summary(const char* name);

}  // namespace dissgen

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
    enum class When { Always, Reassembly, Pairing, RequestContext, Analysis };
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

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Stage 3: validated model -> C++ source of a Wireshark plugin that plugs
// into plugin_runtime/. The output is deterministic: no timestamps, no
// absolute paths, so golden files can diff it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "model.h"

namespace dissgen {

// How a field is registered with Wireshark (hf_register_info).
struct FieldType {
    std::string type;     // "FT_UINT16", "FT_BYTES", "FT_NONE", ...
    std::string display;  // "BASE_HEX", "16", "SEP_COLON", ...
    uint64_t mask = 0;
};

FieldType field_type(const Node& n);

// The fragment fields a reassembling protocol registers (Wireshark's
// fragment_items): C identifier stem, name, filter name, type, display.
struct FragmentField {
    std::string ident, name, filter, type, display;
};
std::vector<FragmentField> fragment_fields(const Protocol& proto);

// A C string literal of `s` (UTF-8 kept, control characters escaped).
std::string c_string(const std::string& s);

// `DECLARATION[] = { ... };` with one row a line; C++ has no empty arrays, so
// a table without rows holds one empty row ({}).
std::string c_array(const std::string& declaration, const std::vector<std::string>& rows);

// A row of the runtime's tables (plugin_runtime/dissgen_rows.h): `start`, the
// row's constructor, and its setters "name(value)", wrapped to fit a line.
std::string named_row(const std::string& start, const std::vector<std::string>& setters);

// Extra tables and fields from other inputs than the rule file (the ESI
// catalogue and network design, emit_catalogue.h), placed by emit_cpp.
struct EmbeddedTables {
    std::string includes;                 // after the runtime's include
    std::string declarations;             // hf variables
    std::string tables;                   // constant data, before the protocol
    std::vector<std::string> hf_entries;  // hf_register_info initializers
    std::string analysis_data;            // defined in `tables`, for the pairing's analysis (dg_protocol)
};

// `source_name` is the rule file's base name, quoted in the header comment.
std::string emit_cpp(const Protocol& proto, const std::string& source_name, const EmbeddedTables* extra = nullptr);

// One line per field: filter name, Wireshark type, display name and where it
// comes from: kRulesSource for the rule file's fields (first, in document
// order), then what the runtime registers for the protocol, each with its
// NameGroup's source ("runtime", "reassembly", "pairing", an analysis).
// Expert infos are listed too: Wireshark registers each as an FT_NONE field.
constexpr const char* kRulesSource = "rules";
std::string list_fields(const Protocol& proto);

}  // namespace dissgen

// Stage 3b: the ESI catalogue and the network design -> the plugin's static
// bus tables (plugin_runtime/ethercat/ethercat_design.h) and a registered field for every
// PDO entry of the designed slaves. emit_cpp() places the pieces.
#pragma once

#include <string>

#include "emit_cpp.h"
#include "esi_model.h"

namespace dissgen {

struct BusOptions {
    const Network* network = nullptr;  // nullptr: catalogue only
    bool compact = false;              // embed only the models the network uses
};

// `filter` is the protocol's filter name: fields are FILTER.pdo.OWNER.PDO.ENTRY.
EmbeddedTables emit_bus(const Catalogue& cat, const BusOptions& options, const std::string& filter);

// The field type of a PDO entry of ESI DataType `data_type` and `bits` bits
// (BITn: the smallest unsigned type that holds n bits; unknown types: bytes).
FieldType pdo_field_type(const std::string& data_type, unsigned bits);

// One line per PDO field, as list_fields() prints the rule fields, from kEsiSource.
constexpr const char* kEsiSource = "esi";
std::string list_bus_fields(const Catalogue& cat, const BusOptions& options, const std::string& filter);

}  // namespace dissgen

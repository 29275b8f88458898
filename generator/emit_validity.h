// SPDX-License-Identifier: GPL-2.0-or-later
// The generated part of valid="LIST" fields and <heuristic>: the dg_validity
// of plugin_runtime/dissgen_validity.h and the heuristic entry point. A
// protocol with neither gets none of it, and its generated code is as before.
#pragma once

#include <string>

#include "model.h"

namespace dissgen {

// Any valid field or heuristic.
bool has_validity(const Protocol& proto);

// The tables and the heuristic entry: after the dg_protocol, before the
// dissector entries that call dg_valid_dissect(&FILTER_validity, ...).
std::string emit_validity(const Protocol& proto);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Stage 2: check a parsed protocol against the rule language and derive what
// the emitter needs: effective byte orders and display types, bit groups and
// masks, display-filter names, and the value slots that lengths, counts,
// repeat flags, conditions and summaries read at run time.
#pragma once

#include "diagnostics.h"
#include "model.h"

namespace dissgen {

// Returns true when the protocol has no errors (warnings allowed).
bool validate(Protocol& proto, Diagnostics& diags);

// The filter-name segment a node gets from its name alone ("" when the name
// has no ASCII letters or digits).
std::string segment_from_name(const std::string& name);

bool is_valid_filter_segment(const std::string& s);

// A node's name without its "{i}" (instance number) markers, for
// the filter name of a block repeated at a stride.
std::string name_without_index(const std::string& name);

}  // namespace dissgen

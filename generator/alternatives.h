// SPDX-License-Identifier: GPL-2.0-or-later
// Alternatives: nodes of which at most one is decoded in one pass through
// their closest common container (members of one chain, or siblings whose
// conditions on one field cannot both hold), and the fields such nodes may
// share under one filter name.
#pragma once

#include "model.h"

#include <string>

namespace dissgen {

// Whether a and b can never both be decoded in one pass through their
// closest common container.
bool are_alternatives(const Protocol& proto, const Node& a, const Node& b);

// Whether the own conditions of x and y (if/in and <when> on one field,
// hooks, directions) can never hold together, whatever comes between them.
bool conditions_exclude(const Node& x, const Node& y);

// Why a and b cannot be one Wireshark field ("" when they can): their
// types, display bases, bit masks, value names or unit labels differ.
std::string shared_field_mismatch(const Node& a, const Node& b);

}  // namespace dissgen

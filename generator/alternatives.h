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

// Why a and b cannot be one Wireshark field ("" when they can): their
// types, display bases, bit masks, value names or unit labels differ.
std::string shared_field_mismatch(const Node& a, const Node& b);

}  // namespace dissgen

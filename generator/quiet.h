// SPDX-License-Identifier: GPL-2.0-or-later
// Which nodes a packet walk may step over when nobody sees them (no tree,
// no tap listener).
#pragma once

#include "model.h"

#include <cstdint>
#include <functional>
#include <map>

namespace dissgen {

// For each node that may be stepped over, the bytes it takes. With no tree
// and no tap listener (tshark's summary lines), a node is only worth decoding
// for what others see of it: a value a later node, a summary or the pairing
// reads, a hand-off (another dissector's side effects), or a malformed spot
// that would stop the walk. A node with none of these, whose size is fixed
// and whose fields cannot be malformed within that size, is stepped over.
// is_key tells which leaves the pairing reads: its keys and its analysis' inputs.
std::map<const Node*, uint64_t> quiet_sizes(const Protocol& proto,
                                           const std::function<bool(const Node&)>& is_key);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Which nodes a packet walk may step over when nobody sees them (no tree,
// no tap listener).
#include "quiet.h"

#include <optional>

namespace dissgen {
namespace {

// Whether decoding n matters to anything but its own (unseen) items.
bool feeds_others(const Node& n, const std::function<bool(const Node&)>& is_key) {
    if (n.slot >= 0 || !n.summary_pieces.empty() || n.dissector || n.reassembles() || is_key(n)) return true;
    if (!n.findings.empty()) return true;  // raises its expert infos
    if (!n.learns.empty()) return true;    // learns values for later messages
    for (const auto& c : n.children)
        if (feeds_others(*c, is_key)) return true;
    return false;
}

// The bytes n takes, when they are fixed and decoding n inside that many
// bytes can raise no expert info (no truncation, no length past its
// container, no unused bytes); nullopt otherwise.
std::optional<uint64_t> infallible_size(const Node& n) {
    // (Hand-offs never get here: they feed another dissector, see feeds_others.)
    // An overlay takes no bytes of the walk: stepping over its size would move it.
    if (n.is_repeated() || n.is_window() || n.is_overlay()) return std::nullopt;
    if (n.is_computed()) return 0;  // reads fields, raises nothing
    if (n.is_leaf()) {
        if (n.in_bit_group || !n.has_fixed_length() || n.fixed_bits % 8) return std::nullopt;
        return n.fixed_bits / 8;
    }
    uint64_t sum = 0;
    for (const auto& c : n.children) {
        // Every child always decoded: the size does not depend on values.
        if (c->is_conditional() || c->at) return std::nullopt;
        if (c->in_bit_group) {
            if (c->group_first) sum += c->group_bytes;
            continue;
        }
        std::optional<uint64_t> size = infallible_size(*c);
        if (!size) return std::nullopt;
        sum += *size;
    }
    if (n.length_kind == LengthKind::Children) return sum;
    // A fixed length the fields fill exactly (fewer would be "unused bytes").
    if (n.has_fixed_length() && n.fixed_bits % 8 == 0 && n.fixed_bits / 8 == sum) return sum;
    return std::nullopt;
}

}  // namespace

std::map<const Node*, uint64_t> quiet_sizes(const Protocol& proto,
                                           const std::function<bool(const Node&)>& is_key) {
    std::map<const Node*, uint64_t> sizes;
    for_each_node(proto.nodes, [&](const Node& n) {
        if (feeds_others(n, is_key)) return;
        std::optional<uint64_t> size = infallible_size(n);
        if (size && *size > 0 && *size <= UINT32_MAX) sizes[&n] = *size;
    });
    return sizes;
}

}  // namespace dissgen

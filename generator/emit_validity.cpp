// SPDX-License-Identifier: GPL-2.0-or-later
#include "emit_validity.h"

#include "emit_cpp.h"
#include "text_util.h"

#include <algorithm>
#include <sstream>
#include <vector>

namespace dissgen {

namespace {

std::vector<const Node*> valid_fields(const Protocol& proto) {
    std::vector<const Node*> out;
    for_each_node(proto.nodes, [&](const Node& n) {
        if (n.has_valid) out.push_back(&n);
    });
    return out;
}

// The values in both lists.
std::vector<ValueRange> intersect(const std::vector<ValueRange>& a, const std::vector<ValueRange>& b) {
    std::vector<ValueRange> out;
    for (const ValueRange& x : a)
        for (const ValueRange& y : b)
            if (std::max(x.low, y.low) <= std::min(x.high, y.high))
                out.push_back({std::max(x.low, y.low), std::min(x.high, y.high), {}});
    return out;
}

std::string upper(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::toupper(c); });
    return s;
}

}  // namespace

bool has_validity(const Protocol& proto) { return !proto.heuristics.empty() || !valid_fields(proto).empty(); }

std::string emit_validity(const Protocol& proto) {
    const std::string& f = proto.filter;
    std::ostringstream o;
    std::vector<ValueRange> ranges;
    std::vector<std::string> rows;
    uint32_t header = 0;
    for (const Node* n : valid_fields(proto)) {
        const unsigned bytes = n->in_bit_group ? n->group_bytes : static_cast<unsigned>(n->bits / 8);
        header = std::max(header, static_cast<uint32_t>(n->valid_offset + bytes));
        const size_t in_first = ranges.size();
        ranges.insert(ranges.end(), n->valid_list.begin(), n->valid_list.end());
        // the 'ifhook' lists of the field and its containers: tested only where all of them hold
        bool hooked = false;
        std::vector<ValueRange> hooks;
        for (const Node* a = n; a; a = a->parent)
            if (a->has_hook) {
                hooks = hooked ? intersect(hooks, a->hook_list) : a->hook_list;
                hooked = true;
            }
        if (hooked && hooks.empty()) hooks.push_back({1, 0, {}});  // no hook value: never tested
        const size_t hook_first = ranges.size();
        ranges.insert(ranges.end(), hooks.begin(), hooks.end());
        std::ostringstream row;
        row << "/* " << n->name << ", line " << n->line << " */ { " << n->valid_offset << ", " << bytes << ", " << (n->byteorder == ByteOrder::Little ? 1 : 0) << ", "
            << (n->in_bit_group ? n->shift : 0) << ", " << (n->in_bit_group ? n->bits : 0) << ", " << in_first << ", "
            << n->valid_list.size() << ", " << (hooked ? hook_first : 0) << ", " << hooks.size() << " }";
        rows.push_back(row.str());
    }
    if (proto.pdulength && proto.pdulength->target) header = std::max(header, proto.pdu_fixed_len);

    o << "/* Valid fields (valid=\"LIST\"): offset, bytes, little-endian, shift, bits, valid values (first, count),\n"
      << " * hook values it is tested for (first, count; 0: every message). */\n";
    if (!ranges.empty()) {
        o << "static const dg_range " << f << "_valid_ranges[] = {";
        for (size_t i = 0; i < ranges.size(); ++i)
            o << (i ? ", " : " ") << "{ " << hex(ranges[i].low) << ", " << hex(ranges[i].high) << " }";
        o << " };\n";
    }
    if (!rows.empty()) {
        o << "static const dg_valid_field " << f << "_valid_fields[] = {";
        for (size_t i = 0; i < rows.size(); ++i) o << (i ? ",\n    " : "\n    ") << rows[i];
        o << "\n};\n";
    }
    if (!proto.heuristics.empty()) {
        o << "/* <heuristic>: list, short name, display name, enabled by default. */\n"
          << "static const dg_heuristic " << f << "_heuristics[] = {";
        for (size_t i = 0; i < proto.heuristics.size(); ++i) {
            const Heuristic& h = proto.heuristics[i];
            o << (i ? ",\n    " : "\n    ") << "{ " << c_string(h.table) << ", " << c_string(f + "_" + h.table) << ", "
              << c_string(proto.name + " over " + upper(h.table)) << ", " << (h.enabled ? "TRUE" : "FALSE") << " }";
        }
        o << "\n};\n"
          << "static dg_heur_result heur_" << f << "(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data);\n";
    }
    o << "static const dg_validity " << f << "_validity = {\n"
      << "    &" << f << "_protocol, " << (rows.empty() ? "NULL" : f + "_valid_fields") << ", " << rows.size() << ", "
      << (ranges.empty() ? "NULL" : f + "_valid_ranges") << ", " << header << ",\n"
      << "    " << (proto.heuristics.empty() ? "NULL" : f + "_heuristics") << ", " << proto.heuristics.size() << ", "
      << (proto.heuristics.empty() ? "NULL" : "heur_" + f) << "\n};\n\n";
    if (!proto.heuristics.empty())
        o << "static dg_heur_result heur_" << f << "(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data _U_)\n{\n"
          << "    return dg_valid_heuristic(&" << f << "_validity, tvb, pinfo, tree) != 0;\n}\n\n";
    return o.str();
}

}  // namespace dissgen

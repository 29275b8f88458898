#include "emit_cpp.h"

#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <vector>

namespace dissgen {

namespace {

std::string c_string(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += static_cast<char>(c);
        } else if (c < 0x20 || c == 0x7f) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\%03o", c);
            out += buf;
        } else {
            out += static_cast<char>(c);  // UTF-8 passes through
        }
    }
    return out + "\"";
}

std::string hex(uint64_t v, int digits = 0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%0*llx", digits, static_cast<unsigned long long>(v));
    return buf;
}

unsigned value_bytes(const Node& n) { return n.in_bit_group ? n.group_bytes : n.bits / 8; }

// Everything the emitter names or numbers, worked out once.
struct Layout {
    std::vector<const Node*> nodes;                  // document order; index = doc_index - 1
    std::map<const Node*, std::string> ident;        // C identifier stem, unique
    std::vector<std::vector<int>> child_lists;       // [0] = top level
    std::map<const Node*, int> first_child;          // into the flat children array
    std::vector<int> children_flat;
    std::vector<ValueRange> ranges;
    std::map<const Node*, int> range_first;
    std::map<const Node*, int> hook_range_first;     // ifhook lists, after every 'in' list
    std::vector<std::pair<std::string, int>> pieces;  // (text, slot)
    std::map<const Node*, int> piece_first;
};

std::string ident_for(const Protocol& proto, const Node& n) {
    std::string base = n.filter_name.empty() ? proto.filter + "_" + (n.segment.empty() ? n.name : n.segment)
                                             : n.filter_name;
    std::string out;
    for (char c : base) out += (std::isalnum(static_cast<unsigned char>(c)) && static_cast<unsigned char>(c) < 0x80) ? c : '_';
    return out;
}

Layout make_layout(const Protocol& proto) {
    Layout l;
    std::set<std::string> used;
    for_each_node(proto.nodes, [&](const Node& n) {
        l.nodes.push_back(&n);
        // Filter names are unique, but "a.b_c" and "a_b.c" make the same identifier:
        // add the node's position, and a counter should even that be taken.
        std::string base = ident_for(proto, n);
        std::string id = base;
        for (int k = 0; !used.insert(id).second; ++k)
            id = base + "_" + std::to_string(n.doc_index) + (k ? "_" + std::to_string(k) : "");
        l.ident[&n] = id;
    });
    auto add_list = [&](const std::vector<std::unique_ptr<Node>>& kids, const Node* owner) {
        if (owner) l.first_child[owner] = static_cast<int>(l.children_flat.size());
        for (const auto& k : kids) l.children_flat.push_back(k->doc_index - 1);
    };
    add_list(proto.nodes, nullptr);
    for (const Node* n : l.nodes)
        if (n->is_container()) add_list(n->children, n);
    for (const Node* n : l.nodes) {
        if (n->if_field) {
            l.range_first[n] = static_cast<int>(l.ranges.size());
            l.ranges.insert(l.ranges.end(), n->in_list.begin(), n->in_list.end());
        }
    }
    for (const Node* n : l.nodes) {
        if (n->has_hook) {
            l.hook_range_first[n] = static_cast<int>(l.ranges.size());
            l.ranges.insert(l.ranges.end(), n->hook_list.begin(), n->hook_list.end());
        }
    }
    for (const Node* n : l.nodes) {
        if (!n->summary_pieces.empty()) {
            l.piece_first[n] = static_cast<int>(l.pieces.size());
            for (const SummaryPiece& p : n->summary_pieces)
                l.pieces.push_back({p.text, p.leaf ? p.leaf->slot : -1});
        }
    }
    return l;
}

const char* show_of(const Node& n) {
    if (n.is_container()) return "DG_SHOW_HIDDEN";
    switch (n.display) {
        case Display::NumberHex: return "DG_SHOW_HEX";
        case Display::NumberDec: return "DG_SHOW_DEC";
        case Display::Bool: return "DG_SHOW_BOOL";
        case Display::Enum: return "DG_SHOW_ENUM";
        case Display::Address: return "DG_SHOW_ADDRESS";
        case Display::Origin: return "DG_SHOW_BYTES";
        case Display::NonDisplay: return "DG_SHOW_HIDDEN";
    }
    return "DG_SHOW_HIDDEN";
}

std::string flags_of(const Node& n, bool pairing_key) {
    std::vector<std::string> f;
    if (n.byteorder == ByteOrder::Little) f.push_back("DG_LITTLE");
    if (n.is_numeric()) f.push_back("DG_NUMERIC");
    if (n.is_leaf() && n.display == Display::NonDisplay) f.push_back("DG_HIDDEN");
    if (n.in_bit_group) f.push_back("DG_GROUP");
    if (n.group_first) f.push_back("DG_GROUP_FIRST");
    if (n.group_last) f.push_back("DG_GROUP_LAST");
    if (pairing_key) f.push_back("DG_KEY");  // issue 11
    if (f.empty()) return "0";
    std::string out;
    for (size_t i = 0; i < f.size(); ++i) out += (i ? "|" : "") + f[i];
    return out;
}

const char* length_kind_of(const Node& n) {
    if (n.in_bit_group) return "DG_LEN_FIXED";
    switch (n.length_kind) {
        case LengthKind::Bits:
        case LengthKind::Bytes: return "DG_LEN_FIXED";
        case LengthKind::Field: return "DG_LEN_FIELD";
        case LengthKind::Rest: return "DG_LEN_REST";
        case LengthKind::Children: return "DG_LEN_CHILDREN";
    }
    return "DG_LEN_CHILDREN";
}

std::string ref_of(const FieldRef* r) {
    if (!r || !r->target) return "{-1, 0, 0}";
    std::string op = r->op ? std::string("'") + r->op + "'" : "0";
    return "{" + std::to_string(r->target->slot) + ", " + op + ", " + std::to_string(r->operand) + "}";
}

// Slots of a subtree are consecutive because they are numbered in document order.
std::pair<int, int> slot_span(const Node& n) {
    int first = -1, count = 0;
    auto visit = [&](const Node& d) {
        if (d.slot < 0) return;
        if (first < 0) first = d.slot;
        ++count;
    };
    visit(n);
    for_each_node(n.children, visit);
    return {first < 0 ? 0 : first, count};
}

class Emitter {
public:
    Emitter(const Protocol& p, const std::string& source) : p_(p), source_(source), l_(make_layout(p)) {}
    std::string run();

private:
    void header();
    void declarations();
    void value_strings();
    void tables();
    void node_table();
    void protocol_struct();
    void register_functions();
    std::string hf(const Node& n) const { return "hf_" + l_.ident.at(&n); }
    std::string ett(const Node& n) const { return "ett_" + l_.ident.at(&n); }
    std::string vals(const Node& n) const { return l_.ident.at(&n) + "_vals"; }
    bool has_hf(const Node& n) const { return !n.filter_name.empty(); }
    bool uses_val64(const Node& n) const { return value_bytes(n) > 4; }
    bool is_pairing_key(const Node& n) const {  // issue 11
        if (!p_.pairing) return false;
        for (const PairingKey& k : p_.pairing->keys)
            if (k.field.target == &n) return true;
        return false;
    }

    const Protocol& p_;
    std::string source_;
    Layout l_;
    std::ostringstream o_;
};

std::string Emitter::run() {
    header();
    declarations();
    value_strings();
    tables();
    node_table();
    protocol_struct();
    register_functions();
    return o_.str();
}

void Emitter::header() {
    o_ << "/* Generated by dissgen from " << source_ << "; do not edit.\n"
       << " * Edit the rule file and regenerate: dissgen install " << source_ << "\n"
       << " *\n"
       << " * Protocol " << p_.name << " (" << p_.abbreviation << "), display filter \"" << p_.filter << "\".\n"
       << " */\n"
       << "#include \"dissgen_runtime.h\"\n\n";
}

void Emitter::declarations() {
    o_ << "static int proto_" << p_.filter << " = -1;\n\n";
    for (const Node* n : l_.nodes)
        if (has_hf(*n)) o_ << "static int " << hf(*n) << " = -1;\n";
    o_ << "\nstatic gint ett_" << p_.filter << " = -1;\n";
    for (const Node* n : l_.nodes)
        if (n->is_container()) o_ << "static gint " << ett(*n) << " = -1;\n";
    o_ << "\nstatic dg_experts ei_" << p_.filter << ";\n\n";
}

void Emitter::value_strings() {
    for (const Node* n : l_.nodes) {
        if (n->is_container() || n->display != Display::Enum) continue;
        bool wide = uses_val64(*n);
        o_ << "static const " << (wide ? "val64_string " : "value_string ") << vals(*n) << "[] = {\n";
        std::set<uint64_t> seen;
        int digits = static_cast<int>((n->bits + 3) / 4);
        for (const EnumItem& e : n->enums)
            if (seen.insert(e.value).second)
                o_ << "    { " << hex(e.value, digits) << ", " << c_string(e.name) << " },\n";
        o_ << "    { 0, NULL }\n};\n\n";
    }
}

void Emitter::tables() {
    o_ << "static const guint16 " << p_.filter << "_children[] = {";
    for (size_t i = 0; i < l_.children_flat.size(); ++i) o_ << (i ? ", " : " ") << l_.children_flat[i];
    o_ << " };\n\n";
    o_ << "static const dg_range " << p_.filter << "_ranges[] = {";
    if (l_.ranges.empty()) o_ << " { 0, 0 }";
    for (size_t i = 0; i < l_.ranges.size(); ++i)
        o_ << (i ? ", " : " ") << "{ " << hex(l_.ranges[i].low) << ", " << hex(l_.ranges[i].high) << " }";
    o_ << " };\n\n";
    o_ << "static const dg_summary_piece " << p_.filter << "_summary[] = {";
    if (l_.pieces.empty()) o_ << " { NULL, -1 }";
    for (size_t i = 0; i < l_.pieces.size(); ++i) {
        const auto& [text, slot] = l_.pieces[i];
        o_ << (i ? ",\n    " : "\n    ") << "{ " << (slot < 0 ? c_string(text) : "NULL") << ", " << slot << " }";
    }
    o_ << (l_.pieces.empty() ? " };\n\n" : "\n};\n\n");
    o_ << "static const dg_hook " << p_.filter << "_hooks[] = {";
    bool first = true;
    if (p_.ethertype) {
        o_ << "\n    { \"ethertype\", " << hex(*p_.ethertype, 4) << " }";
        first = false;
    }
    for (const Hook& h : p_.hooks) {
        o_ << (first ? "\n" : ",\n") << "    { " << c_string(h.table) << ", " << h.value << " }";
        first = false;
    }
    o_ << "\n};\n\n";
}

void Emitter::node_table() {
    o_ << "/* One entry per <node>, in document order. Columns: name, hf, ett, kind, length kind, show, flags,\n"
       << " * length, shift, bits, slot, length ref, count ref, repeat slot, if slot, in ranges (first, count),\n"
       << " * children (first, count), slots inside (first, count), summary pieces (first, count). */\n";
    o_ << "static const dg_node " << p_.filter << "_nodes[] = {\n";
    for (const Node* np : l_.nodes) {
        const Node& n = *np;
        unsigned length = n.in_bit_group ? n.group_bytes : static_cast<unsigned>(n.fixed_bits / 8);
        if (!n.has_fixed_length() && !n.in_bit_group) length = 0;
        auto [slot_first, slot_count] = slot_span(n);
        o_ << "    /* " << n.doc_index - 1 << ": line " << n.line << " */\n"
           << "    { " << c_string(n.name) << ", " << (has_hf(n) ? "&" + hf(n) : "NULL") << ", "
           << (n.is_container() ? "&" + ett(n) : "NULL") << ", " << (n.is_container() ? "DG_CONTAINER" : "DG_LEAF")
           << ", " << length_kind_of(n) << ", " << show_of(n) << ", " << flags_of(n, is_pairing_key(n)) << ",\n      " << length << ", "
           << n.shift << ", " << n.bits << ", " << n.slot << ", "
           << ref_of(n.length_kind == LengthKind::Field ? &n.length_ref : nullptr) << ", "
           << ref_of(n.count ? &*n.count : nullptr) << ", "
           << (n.repeat && n.repeat->target ? n.repeat->target->slot : -1) << ", "
           << (n.if_field && n.if_field->target ? n.if_field->target->slot : -1) << ", "
           << (n.if_field ? l_.range_first.at(&n) : 0) << ", " << (n.if_field ? n.in_list.size() : 0) << ", "
           << (n.is_container() ? l_.first_child.at(&n) : 0) << ", " << n.children.size() << ", " << slot_first
           << ", " << slot_count << ", " << (l_.piece_first.count(&n) ? l_.piece_first.at(&n) : 0) << ", "
           << n.summary_pieces.size();
        // ifhook ranges (first, count): only where given, the struct defaults them to none.
        if (n.has_hook) o_ << ", " << l_.hook_range_first.at(&n) << ", " << n.hook_list.size();
        o_ << " },\n";
    }
    if (l_.nodes.empty()) o_ << "    { NULL, NULL, NULL, 0, 0, 0, 0, 0, 0, 0, -1, {-1, 0, 0}, {-1, 0, 0}, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0 }\n";
    o_ << "};\n\n";
}

void Emitter::protocol_struct() {
    const std::string& f = p_.filter;
    const Node* pdu = p_.pdulength ? p_.pdulength->target : nullptr;
    o_ << "static int dissect_" << f << "(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data);\n";
    if (pdu) o_ << "static int dissect_" << f << "_stream(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data);\n";
    size_t hook_count = p_.hooks.size() + (p_.ethertype ? 1 : 0);
    if (p_.pairing) {  // issue 11
        char timeout[32];
        std::snprintf(timeout, sizeof timeout, "%.9g", p_.pairing->timeout);
        o_ << "\n/* Request/response pairing (<pairing>, line " << p_.pairing->line
           << "): timeout in seconds, analysis. */\n"
           << "static const dg_pairing " << f << "_pairing = { " << timeout << ", "
           << (p_.pairing->analysis.empty() ? "NULL" : c_string(p_.pairing->analysis)) << " };\n";
    }
    o_ << "\nstatic dg_protocol " << f << "_protocol = {\n"
       << "    " << c_string(p_.name) << ", " << c_string(p_.abbreviation) << ", " << c_string(f) << ",\n"
       << "    &proto_" << f << ", &ett_" << f << ", dissect_" << f << ", "
       << (pdu ? "dissect_" + f + "_stream" : "NULL") << ",\n"
       << "    " << f << "_nodes, " << l_.nodes.size() << ", " << f << "_children, 0, " << p_.nodes.size() << ",\n"
       << "    " << f << "_ranges, " << f << "_summary, " << p_.slot_count << ", &ei_" << f << ",\n"
       << "    " << f << "_hooks, " << hook_count << ",\n"
       << "    " << (pdu ? pdu->doc_index - 1 : -1) << ", "
       << (pdu ? p_.pdu_fixed_len - value_bytes(*pdu) : 0) << ", " << p_.pdulengthadd;
    if (p_.pairing) o_ << ",\n    &" << f << "_pairing";  // issue 11
    o_ << "\n};\n\n";
    o_ << "static int dissect_" << f << "(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data _U_)\n{\n"
       << "    return dg_dissect(&" << f << "_protocol, tvb, pinfo, tree);\n}\n\n";
    if (pdu)
        o_ << "static int dissect_" << f << "_stream(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data _U_)\n{\n"
           << "    return dg_dissect_stream(&" << f << "_protocol, tvb, pinfo, tree);\n}\n\n";
}

void Emitter::register_functions() {
    const std::string& f = p_.filter;
    o_ << "void proto_register_" << f << "(void)\n{\n    static hf_register_info hf[] = {\n";
    bool first = true;
    for (const Node* n : l_.nodes) {
        if (!has_hf(*n)) continue;
        FieldType t = field_type(*n);
        std::string strings = "NULL";
        if (n->is_leaf() && n->display == Display::Enum)
            strings = uses_val64(*n) ? "VALS64(" + vals(*n) + ")" : "VALS(" + vals(*n) + ")";
        o_ << (first ? "" : ",\n") << "        { &" << hf(*n) << ",\n          { " << c_string(n->name) << ", "
           << c_string(n->filter_name) << ", " << t.type << ", " << t.display << ", " << strings << ", "
           << hex(t.mask) << ",\n            " << (n->description.empty() ? "NULL" : c_string(n->description))
           << ", HFILL } }";
        first = false;
    }
    if (first) o_ << "        { NULL, { NULL, NULL, FT_NONE, BASE_NONE, NULL, 0x0, NULL, HFILL } }";
    o_ << "\n    };\n\n    static gint *ett[] = {\n        &ett_" << f;
    for (const Node* n : l_.nodes)
        if (n->is_container()) o_ << ",\n        &" << ett(*n);
    o_ << "\n    };\n\n    static ei_register_info ei[] = {\n";
    const char* experts[][4] = {
        {"truncated", "PI_MALFORMED", "PI_ERROR", "The packet ends inside a field"},
        {"past_end", "PI_MALFORMED", "PI_ERROR", "A length field points past the end of its data"},
        {"more_no_data", "PI_MALFORMED", "PI_WARN", "The repeat flag says more follow, but no data is left"},
        {"count_short", "PI_MALFORMED", "PI_WARN", "Fewer instances than the count field says"},
        {"bad_length", "PI_MALFORMED", "PI_ERROR", "A length or count is missing or negative"},
        {"unused", "PI_PROTOCOL", "PI_WARN", "A length says more bytes than its fields hold"},
    };
    const size_t expert_count = sizeof experts / sizeof experts[0];
    for (size_t i = 0; i < expert_count; ++i)
        o_ << "        { &ei_" << f << "." << experts[i][0] << ", { \"" << f << ".expert." << experts[i][0] << "\", "
           << experts[i][1] << ", " << experts[i][2] << ", \"" << experts[i][3] << "\", EXPFILL } }"
           << (i + 1 < expert_count ? ",\n" : "\n");
    o_ << "    };\n\n"
       << "    if (!dg_protocol_names_free(&" << f << "_protocol))\n        return;\n"
       << "    dg_register(&" << f << "_protocol, hf, " << (first ? "0" : "(int)G_N_ELEMENTS(hf)")
       << ", ett, (int)G_N_ELEMENTS(ett), ei, (int)G_N_ELEMENTS(ei));\n}\n\n"
       << "void proto_reg_handoff_" << f << "(void)\n{\n    dg_handoff(&" << f << "_protocol);\n}\n\n"
       << "DG_DECLARE_PLUGIN(proto_register_" << f << ", proto_reg_handoff_" << f << ")\n";
}

}  // namespace

FieldType field_type(const Node& n) {
    if (n.is_container()) return {"FT_NONE", "BASE_NONE", 0};
    if (!n.is_numeric()) {
        const char* sep = n.display == Display::Address ? "SEP_COLON"
                          : n.display == Display::Origin ? "SEP_SPACE"
                                                         : "BASE_NONE";
        return {"FT_BYTES", sep, 0};
    }
    unsigned bytes = value_bytes(n);
    uint64_t mask = 0;
    if (n.in_bit_group) mask = (n.bits >= 64 ? ~0ull : ((1ull << n.bits) - 1)) << n.shift;
    if (n.display == Display::Bool)
        return {"FT_BOOLEAN", n.in_bit_group ? std::to_string(bytes * 8) : "BASE_NONE", mask};
    std::string type = "FT_UINT" + std::to_string(bytes * 8);
    std::string base = "BASE_DEC";
    if (n.display == Display::NumberHex) base = "BASE_HEX";
    if (n.display == Display::Enum) base = bytes > 4 ? "BASE_HEX|BASE_VAL64_STRING" : "BASE_HEX";
    return {type, base, mask};
}

std::string emit_cpp(const Protocol& proto, const std::string& source_name) {
    return Emitter(proto, source_name).run();
}

std::string list_fields(const Protocol& proto) {
    std::ostringstream out;
    out << proto.filter << "\tFT_PROTOCOL\t" << proto.name << "\n";
    for_each_node(proto.nodes, [&](const Node& n) {
        if (n.filter_name.empty()) return;
        out << n.filter_name << "\t" << field_type(n).type << "\t" << n.name << "\n";
    });
    return out.str();
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "emit_cpp.h"

#include "analyses.h"
#include "emit_validity.h"
#include "findings.h"
#include "quiet.h"
#include "runtime_names.h"
#include "text_util.h"

#include "validator.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

namespace dissgen {

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

namespace {

// Text inside a /* */ comment: a "*/" in it would end the comment.
std::string comment_text(std::string text) {
    for (size_t at = text.find("*/"); at != std::string::npos; at = text.find("*/", at)) text.replace(at, 2, "* /");
    return text;
}

}  // namespace

std::string c_array(const std::string& declaration, const std::vector<std::string>& rows) {
    std::string out = declaration + "[] = {\n";
    for (const std::string& row : rows) out += "    " + row + ",\n";
    if (rows.empty()) out += "    {}\n";
    return out + "};\n\n";
}

std::string named_row(const std::string& start, const std::vector<std::string>& setters) {
    std::string out = start;
    size_t column = 4 + out.size();
    for (const std::string& s : setters) {
        if (column + 1 + s.size() > 116) {
            out += "\n       ";
            column = 7;
        }
        out += "." + s;
        column += 1 + s.size();
    }
    return out;
}

namespace {

// The bytes a numeric leaf's item is read from: its bit group's, a packed bit field's one byte.
unsigned value_bytes(const Node& n) { return n.in_bit_group ? n.group_bytes : n.packed_bits ? 1 : n.bits / 8; }

// A bit field's mask inside its group (0 for a whole-byte field).
uint64_t group_mask(const Node& n) {
    if (!n.in_bit_group) return 0;
    return (n.bits >= 64 ? ~0ull : ((1ull << n.bits) - 1)) << n.shift;
}

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
    struct Piece {
        std::string text;
        int slot = -1;
        size_t group = 0;  // an optional part of the next `group` pieces
        int node = -1;     // a container whose summary is inserted
        const Node* leaf = nullptr;  // the field a placeholder shows
    };
    std::vector<Piece> pieces;
    std::map<const Node*, int> piece_first;
    // table rows for <when>, peeks, windows and their places
    std::map<const Node*, int> when_first;
    std::map<const Node*, int> window_index;
    std::vector<std::string> whens, peeks, peek_lengths, windows, places;
    // computed values: each one's operations, in postfix order
    std::map<const Node*, std::pair<int, int>> expr_span;  // first, count
    std::vector<ExprRow> exprs;
    // <finding>s in document order: their rows, and each node's first; the
    // expert infos, one per name (a <group> used twice raises one from each use)
    std::vector<std::string> findings;
    std::map<const Node*, int> finding_first;
    std::vector<const Finding*> finding_experts;
    // <learn>s in document order (Learn::index): their rows, their keys' rows, each node's first
    std::vector<std::string> learns, learn_keys;
    std::map<const Node*, int> learn_first;
    bool uses_layout_tables() const { return !whens.empty() || !windows.empty(); }
    bool node_uses_layout_columns(const Node& n) const { return when_first.count(&n) || window_index.count(&n) || n.otherwise; }
};

void layout_conditions_and_windows(Layout& l, const std::map<const Node*, uint64_t>& quiet);
void layout_findings(Layout& l, const std::string& filter);
void layout_learns(Layout& l, const Protocol& proto);

std::string ident_for(const Protocol& proto, const Node& n) {
    std::string base = n.filter_name.empty() ? proto.filter + "_" + (n.segment.empty() ? n.name : n.segment)
                                             : n.filter_name;
    std::string out;
    for (char c : base) out += (std::isalnum(static_cast<unsigned char>(c)) && static_cast<unsigned char>(c) < 0x80) ? c : '_';
    return out;
}

// The slot a summary of container x reads a leaf's value from: its copy kept
// across the repeat between them, which a later instance without it does not
// clear; else its own.
int shown_slot(const Node& x, const Node& leaf) {
    const Node* repeat = repeat_between(x, leaf);
    if (!repeat) return leaf.slot;
    auto kept = leaf.kept_slots.find(repeat);
    return kept != leaf.kept_slots.end() ? kept->second : leaf.slot;
}

// quiet: the nodes a walk nobody sees steps over, and their sizes (quiet.h).
Layout make_layout(const Protocol& proto, const std::map<const Node*, uint64_t>& quiet) {
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
            for (const SummaryPiece& p : n->summary_pieces) {
                const int slot = p.leaf ? shown_slot(*n, *p.leaf) : -1;
                // a container's kept copy holds its text, shown as a value; its own slot, its summary made again
                const bool made_again = p.leaf && p.leaf->is_container() && slot == p.leaf->slot;
                l.pieces.push_back({p.text, slot, p.group, made_again ? p.leaf->doc_index - 1 : -1, p.leaf});
            }
        }
    }
    layout_conditions_and_windows(l, quiet);
    for (const Node* n : l.nodes) {
        if (!n->is_computed()) continue;
        std::vector<ExprRow> rows = compile_expression(*n->value, n->display == Display::Float);
        l.expr_span[n] = {static_cast<int>(l.exprs.size()), static_cast<int>(rows.size())};
        l.exprs.insert(l.exprs.end(), rows.begin(), rows.end());
    }
    layout_findings(l, proto.filter);
    layout_learns(l, proto);
    return l;
}

// The dg_learn_ends of a <learn>: whose value it is besides its keys'.
std::string learn_ends(const Learn& learn) {
    return learn.conversation ? "DG_LEARN_ENDS_CONVERSATION"
           : learn.sender     ? "DG_LEARN_ENDS_SENDER"
                              : "DG_LEARN_ENDS_NONE";
}

// Each <learn>: its value, condition and keys' operations (after the
// findings'), the transport's ends it is kept by; each key its value and lookup.
void layout_learns(Layout& l, const Protocol& proto) {
    auto add = [&](const Expr* e) -> std::string {
        if (!e) return "0, 0";
        std::vector<ExprRow> rows = compile_expression(*e, false);
        const size_t first = l.exprs.size();
        l.exprs.insert(l.exprs.end(), rows.begin(), rows.end());
        return std::to_string(first) + ", " + std::to_string(rows.size());
    };
    for (const Node* n : l.nodes) {
        if (n->learns.empty()) continue;
        l.learn_first[n] = static_cast<int>(l.learns.size());
        for (const Learn& learn : n->learns) {
            const size_t key_first = l.learn_keys.size();
            for (const LearnKey& k : learn.keys)
                l.learn_keys.push_back("{ " + add(&k.value) + ", " + add(k.lookup ? &*k.lookup : nullptr) + ", " +
                                       add(k.span ? &*k.span : nullptr) + ", " + add(k.id ? &*k.id : nullptr) + " }");
            const std::string value = add(&learn.value);
            const std::string condition = add(learn.condition ? &*learn.condition : nullptr);
            l.learns.push_back("/* " + learn.name + ", line " + std::to_string(learn.line) + " */ { " + value + ", " +
                               condition + ", " + std::to_string(key_first) + ", " +
                               std::to_string(learn.keys.size()) + ", " + learn_ends(learn) + " }");
        }
    }
    // readers with keys of their own: what they read is their learn's
    for (const auto& read : proto.learned_read_keys) {
        const Learn& learn = *read->learn;
        const size_t key_first = l.learn_keys.size();
        for (size_t i = 0; i < learn.keys.size(); ++i) {
            const Expr* lookup = read->lookups[i] ? &*read->lookups[i] : nullptr;
            // which key has a span, and its id, the runtime takes from the learner's keys
            l.learn_keys.push_back("{ " + add(&learn.keys[i].value) + ", " + add(lookup) + ", 0, 0, 0, 0 }");
        }
        l.learns.push_back("/* learned{" + learn.name + "} at line " + std::to_string(read->line) + " */ { 0, 0, 0, 0, " +
                           std::to_string(key_first) + ", " + std::to_string(learn.keys.size()) + ", " +
                           learn_ends(learn) + ", " + std::to_string(learn.index + 1) + " }");
    }
}

// Each <finding>: its expert field, condition (after every computed value's
// operations) and text (after every summary's pieces).
void layout_findings(Layout& l, const std::string& filter) {
    std::map<std::string, size_t> expert_of;  // filter name -> index in finding_experts
    for (const Node* n : l.nodes) {
        if (n->findings.empty()) continue;
        l.finding_first[n] = static_cast<int>(l.findings.size());
        for (const Finding& f : n->findings) {
            auto [expert, added] = expert_of.emplace(f.filter_name, l.finding_experts.size());
            if (added) l.finding_experts.push_back(&f);
            std::vector<ExprRow> rows = compile_expression(f.condition, false);
            const size_t expr_first = l.exprs.size(), text_first = l.pieces.size();
            l.exprs.insert(l.exprs.end(), rows.begin(), rows.end());
            for (const SummaryPiece& p : f.text_pieces)
                l.pieces.push_back({p.text, p.leaf ? p.leaf->slot : -1, 0, -1, p.leaf});
            l.findings.push_back("/* " + f.name + ", line " + std::to_string(f.line) + " */ { &" + filter +
                                 "_finding_ei[" + std::to_string(expert->second) + "], " +
                                 std::to_string(expr_first) + ", " + std::to_string(rows.size()) + ", " +
                                 std::to_string(text_first) + ", " + std::to_string(f.text_pieces.size()) + " }");
        }
    }
}

// A computed value's operation: its code, then what that code reads.
std::string expr_row(const ExprRow& r) {
    std::string row = "dg_op(" + r.code + ")";
    if (r.code == "DG_OP_INT") row = "dg_op_int(" + std::to_string(r.integer) + ")";
    if (r.code == "DG_OP_FLOAT") {
        char buf[40];
        std::snprintf(buf, sizeof buf, "%.17g", r.real);
        row = "dg_op_real(" + std::string(buf) + ")";
    }
    if (r.code.rfind("DG_OP_FIELD", 0) == 0 || r.code.rfind("DG_OP_REQUEST_FIELD", 0) == 0)
        row = "dg_op_field(" + r.code + ", " + std::to_string(r.slot) + ", " + std::to_string(r.bits) + ")";
    if (r.code == "DG_OP_LEARNED") row = "dg_op_learned(" + std::to_string(r.slot) + ")";
    return row;
}

std::string ref_of(const FieldRef* r);

// <when> rows (their 'in' lists after every other list), peeks,
// windows and their places sorted by address.
void layout_conditions_and_windows(Layout& l, const std::map<const Node*, uint64_t>& quiet) {
    for (const Node* n : l.nodes) {
        if (n->whens.empty()) continue;
        l.when_first[n] = static_cast<int>(l.whens.size());
        for (const When& w : n->whens) {
            int in_first = static_cast<int>(l.ranges.size());
            l.ranges.insert(l.ranges.end(), w.in_list.begin(), w.in_list.end());
            std::string ranges = std::to_string(in_first) + ", " + std::to_string(w.in_list.size());
            if (!w.peek) {
                l.whens.push_back("dg_when_field(" + std::to_string(w.ref.target ? w.ref.target->slot : -1) + ", " + ranges + ")");
                continue;
            }
            l.whens.push_back("dg_when_peek(" + std::to_string(l.peeks.size()) + ", " + ranges + ")");
            l.peeks.push_back("{ " + std::to_string(w.ref.target->doc_index - 1) + ", " + std::to_string(w.offset) + ", " +
                              std::to_string(l.peek_lengths.size()) + ", " + std::to_string(w.lengths.size()) + ", " +
                              std::to_string(w.up) + ", " + std::to_string(w.target_up) + " }");
            for (const FieldRef* r : w.lengths) l.peek_lengths.push_back(ref_of(r));
        }
    }
    for (const Node* n : l.nodes) {
        if (!n->is_window()) continue;
        std::vector<const Node*> kids;
        for (const auto& c : n->children) kids.push_back(c.get());
        std::stable_sort(kids.begin(), kids.end(), [](const Node* a, const Node* b) { return *a->at < *b->at; });
        bool document_order = true;
        uint64_t max_span = 0;
        for (size_t k = 0; k < kids.size(); ++k) {
            const Node& c = *kids[k];
            uint64_t instances = c.instances.value_or(1), stride = c.stride.value_or(0);
            max_span = std::max(max_span, stride * (instances - 1) + c.place_bytes);
            if (k && kids[k - 1]->doc_index > c.doc_index) document_order = false;
        }
        l.window_index[n] = static_cast<int>(l.windows.size());
        l.windows.push_back("{ " + ref_of(&*n->base) + ", " + std::to_string(l.places.size()) + ", " +
                            std::to_string(kids.size()) + ", " + std::to_string(max_span) + ", " +
                            (document_order ? "TRUE" : "FALSE") + " }");
        for (const Node* c : kids) {
            // quiet within its size: each instance is, and the window steps over the place unread
            auto q = quiet.find(c);
            bool quiet_place = q != quiet.end() && q->second <= c->place_bytes;
            l.places.push_back("{ " + std::to_string(c->doc_index - 1) + ", " + (quiet_place ? "TRUE" : "FALSE") + ", " +
                               hex(*c->at) + ", " + std::to_string(c->place_bytes) + ", " +
                               std::to_string(c->stride.value_or(0)) + ", " + std::to_string(c->instances.value_or(1)) +
                               " }");
        }
    }
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
        case Display::String: return "DG_SHOW_STRING";
        case Display::StringZ: return "DG_SHOW_STRINGZ";
        case Display::IPv4: return "DG_SHOW_IPV4";
        case Display::Int: return "DG_SHOW_INT";
        case Display::Float: return "DG_SHOW_FLOAT";
        case Display::Time: return "DG_SHOW_TIME";
        case Display::DateTime: return "DG_SHOW_DATETIME";
        case Display::Guid: return "DG_SHOW_GUID";
        case Display::IPv6: return "DG_SHOW_IPV6";
        case Display::Mac: return "DG_SHOW_MAC";
        case Display::Eui64: return "DG_SHOW_EUI64";
        case Display::Oid: return "DG_SHOW_OID";
        case Display::Varint: return "DG_SHOW_VARINT";
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
    if (pairing_key) f.push_back("DG_KEY");
    if (n.skip_malformed) f.push_back("DG_SKIP_MALFORMED");
    if (f.empty()) return "0";
    std::string out;
    for (size_t i = 0; i < f.size(); ++i) out += (i ? "|" : "") + f[i];
    return out;
}

const char* length_kind_of(const Node& n) {
    if (n.in_bit_group) return "DG_LEN_FIXED";
    if (n.packed_bits) return "DG_LEN_PACKED";
    if (n.is_computed()) return "DG_LEN_COMPUTED";
    switch (n.length_kind) {
        case LengthKind::Bits:
        case LengthKind::Bytes: return "DG_LEN_FIXED";
        case LengthKind::Field: return "DG_LEN_FIELD";
        case LengthKind::Rest: return "DG_LEN_REST";
        case LengthKind::Children: return "DG_LEN_CHILDREN";
    }
    return "DG_LEN_CHILDREN";
}

// A reference to a field's value: its slot, the arithmetic on it, and whether
// the slot holds a signed value (an int, or a computed value: -3 is a
// negative length, not 2^64 - 3).
std::string ref_of(const FieldRef* r) {
    if (!r || !r->target) return "{-1, 0, 0, 0}";
    std::string op = r->op ? std::string("'") + r->op + "'" : "0";
    const bool is_signed = r->target->is_computed() || r->target->display == Display::Int;
    return "{" + std::to_string(r->target->slot) + ", " + op + ", " + (is_signed ? "1" : "0") + ", " +
           std::to_string(r->operand) + "}";
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
    for_each_node(n.children, [&](const Node& d) {
        visit(d);
        count += static_cast<int>(d.kept_after.size());  // kept copies of leaves inside d: after d's own slots
    });
    return {first < 0 ? 0 : first, count};
}

class Emitter {
public:
    Emitter(const Protocol& p, const std::string& source, const EmbeddedTables* extra)
        : p_(p), source_(source), extra_(extra),
          quiet_(quiet_sizes(p, [this](const Node& n) {
              return is_pairing_key(n) || n.analysis_input >= 0 || n.cycle_role != 0;
          })), l_(make_layout(p, quiet_)) {}
    std::string run();

private:
    void header();
    void declarations();
    void value_strings();
    void tables();
    void node_table();
    std::string node_row(const Node& n) const;
    // compiled walks: a function per list of siblings (dg_list_walk)
    bool has_walk(const Node& n) const { return n.is_container() && !n.children.empty() && !l_.window_index.count(&n); }
    std::string walk_name(const Node* owner) const;
    std::string walk_signature(const Node* owner) const {
        return "static void " + walk_name(owner) +
               "(dg_rt::dg_state *st, proto_tree *tree, gint *offset, gint end, gboolean in_summary)";
    }
    void walk_declarations();
    void walk_definitions();
    // compiled summaries: a function per summarised container (dg_summary_text)
    std::string summary_name(int node) const { return p_.filter + "_summary_" + std::to_string(node); }
    std::string summary_signature(const Node& n) const {
        return "static gboolean " + summary_name(n.doc_index - 1) + "(const dg_rt::dg_state *st, dg_rt::dg_text *out)";
    }
    void summary_definitions();
    void summary_pieces(size_t first, size_t count, const std::string& complete, int depth);
    std::vector<std::string> summary_rows() const;
    std::string protocol_row() const;
    void request_context();
    void cycles_tables();
    void request_role(const CycleField& r, const std::string& name, const std::string& says);
    std::string extra_row(const Node& n) const;
    void condition_and_window_tables();
    void learn_tables();
    void protocol_struct();
    size_t input_places();
    void register_functions();
    void expert_entries();
    void finding_entries();
    // typed values, hand-off and reassembly (dg_extra)
    bool uses_reassembly() const;
    void extra_table();
    void fragment_declarations();
    void range_strings(const Node& n);
    std::string rvals(const Node& n) const { return l_.ident.at(&n) + "_rvals"; }
    std::map<const Node*, int> extra_index_;
    std::map<const Node*, int> kept_first_;  // a leaf's first row in P_kept_slots
    // alternatives sharing a filter name share the first one's field
    std::string hf(const Node& n) const { return "hf_" + l_.ident.at(n.shares_field ? n.shares_field : &n); }
    bool registers_hf(const Node& n) const { return has_hf(n) && !n.shares_field; }
    std::string ett(const Node& n) const { return "ett_" + l_.ident.at(&n); }
    std::string vals(const Node& n) const { return l_.ident.at(&n) + "_vals"; }
    bool has_hf(const Node& n) const { return !n.filter_name.empty(); }
    bool uses_val64(const Node& n) const { return value_bytes(n) > 4; }
    bool is_pairing_key(const Node& n) const {
        if (!p_.pairing) return false;
        for (const PairingKey& k : p_.pairing->keys)
            if (k.field.target == &n) return true;
        return false;
    }

    const Protocol& p_;
    std::string source_;
    const EmbeddedTables* extra_;
    std::map<const Node*, uint64_t> quiet_;  // nodes stepped over when unseen, and their sizes; declared before l_, whose layout reads it
    Layout l_;
    std::ostringstream o_;
};

std::string Emitter::run() {
    header();
    declarations();
    fragment_declarations();
    value_strings();
    tables();
    extra_table();
    walk_declarations();
    node_table();
    walk_definitions();
    summary_definitions();
    protocol_struct();
    register_functions();
    return o_.str();
}

void Emitter::header() {
    o_ << "/* Generated by dissgen from " << source_ << "; do not edit.\n"
       << " * Edit the rule file and regenerate: dissgen install " << source_ << "\n"
       << " *\n"
       << " * Protocol " << p_.name << " (" << p_.abbreviation << "), display filter \"" << p_.filter << "\".\n"
       << " *\n"
       << " * It is built with the dissgen runtime and libwireshark, both under the\n"
       << " * GNU General Public License, version 2 or later: so is the plugin.\n"
       << " * SPDX-License-Identifier: GPL-2.0-or-later\n"
       << " */\n"
       << "#include \"dissgen_rows.h\"\n#include \"dissgen_state.h\"\n" << (has_validity(p_) ? "#include \"dissgen_validity.h\"\n" : "")
       << (extra_ ? extra_->includes : "") << "\n";
}

void Emitter::declarations() {
    o_ << "static int proto_" << p_.filter << " = -1;\n\n";
    for (const Node* n : l_.nodes)
        if (registers_hf(*n)) o_ << "static int " << hf(*n) << " = -1;\n";
    o_ << "\nstatic gint ett_" << p_.filter << " = -1;\n";
    for (const Node* n : l_.nodes)
        if (n->is_container()) o_ << "static gint " << ett(*n) << " = -1;\n";
    if (extra_ && !extra_->declarations.empty()) o_ << "\n" << extra_->declarations;
    o_ << "\nstatic dg_experts ei_" << p_.filter << ";\n\n";
}

void Emitter::value_strings() {
    for (const Node* n : l_.nodes)  // Wireshark writes the label right after the value (char *: Wireshark 4.0)
        if (n->has_unit_label() && n->display != Display::Float)
            o_ << "static const unit_name_string " << l_.ident.at(n) << "_unit = { (char *)" << c_string(" " + n->unit)
               << ", NULL };\n\n";
    for (const Node* n : l_.nodes) {
        if (n->is_container() || n->display != Display::Enum) continue;
        if (n->has_enum_ranges()) {
            range_strings(*n);
            continue;
        }
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
    if (l_.ranges.empty()) o_ << " {}";  // C++ has no empty arrays
    for (size_t i = 0; i < l_.ranges.size(); ++i)
        o_ << (i ? ", " : " ") << "{ " << hex(l_.ranges[i].low) << ", " << hex(l_.ranges[i].high) << " }";
    o_ << " };\n\n";
    o_ << c_array("static const dg_summary_piece " + p_.filter + "_summary", summary_rows());
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
    condition_and_window_tables();
    learn_tables();
    if (extra_) o_ << extra_->tables;
}

// Summary pieces: text, a leaf's value, an optional part {?...}, a container's summary.
std::vector<std::string> Emitter::summary_rows() const {
    std::vector<std::string> rows;
    for (const Layout::Piece& p : l_.pieces) {
        if (p.group) rows.push_back("dg_optional(" + std::to_string(p.group) + ")");
        else if (p.node >= 0) rows.push_back("dg_summary_of(" + std::to_string(p.slot) + ", " + std::to_string(p.node) + ")");
        else if (p.slot >= 0) rows.push_back("dg_value(" + std::to_string(p.slot) + ")");
        else rows.push_back("dg_text(" + c_string(p.text) + ")");
    }
    return rows;
}

// The tables of <when> conditions, peeks and windows, where used.
void Emitter::condition_and_window_tables() {
    auto table = [&](const char* type, const char* name, const std::vector<std::string>& rows, const char* comment) {
        if (rows.empty()) return;
        o_ << "/* " << comment << " */\n" << c_array("static const " + std::string(type) + " " + p_.filter + "_" + name, rows);
    };
    table("dg_when", "whens", l_.whens, "<when> conditions: on a field's value or a peek, in ranges (first, count)");
    o_ << "/* What conditions read; compiled walks pass it as a constant (dissgen_state.h, selected). */\n"
       << "static const dg_conditions " << p_.filter << "_conditions = { " << p_.filter << "_ranges, "
       << (l_.whens.empty() ? std::string("NULL") : p_.filter + "_whens") << " };\n\n";
    table("dg_peek", "peeks", l_.peeks, "Look-ahead: target node, offset, field lengths (first, count), from the node (0) or its Nth container");
    table("dg_ref", "peek_lengths", l_.peek_lengths, "Field lengths between a node and the field it peeks at");
    table("dg_window", "windows", l_.windows, "Windows: base address, places (first, count), largest span, document order");
    table("dg_place", "places", l_.places, "Window children by address: node, quiet within its size, address, size, stride, instances");
    std::vector<std::string> exprs;
    for (const ExprRow& r : l_.exprs) exprs.push_back(expr_row(r));
    table("dg_expr_op", "exprs", exprs, "Computed values: their operations in postfix order");
    if (l_.findings.empty()) return;
    o_ << "/* <finding>s: expert info, condition (first, count in exprs), text (first, count in summary). */\n"
       << "static expert_field " << p_.filter << "_finding_ei[" << l_.finding_experts.size() << "];\n";
    o_ << c_array("static const dg_finding " + p_.filter + "_findings", l_.findings);
}

void Emitter::learn_tables() {
    if (l_.learns.empty()) return;
    o_ << "/* <learn>s: value, if (first, count in exprs; 0, 0: none), keys (first, count), the ends it is kept by. */\n";
    o_ << c_array("static const dg_learn " + p_.filter + "_learns", l_.learns);
    if (l_.learn_keys.empty()) return;
    o_ << "/* Their keys: value, lookup, span, id (first, count in exprs; lookup 0, 0: as the value; span, id 0, 0: none, or a reader's: its learn's). */\n";
    o_ << c_array("static const dg_learn_key " + p_.filter + "_learn_keys", l_.learn_keys);
}

void Emitter::node_table() {
    std::vector<std::string> rows;
    for (const Node* n : l_.nodes) rows.push_back("/* " + std::to_string(n->doc_index - 1) + ": line " + std::to_string(n->line) + " */\n    " + node_row(*n));
    o_ << "/* One entry per <node>, in document order. */\n"
       << c_array("static const dg_node " + p_.filter + "_nodes", rows);
}

// A node's row: its kind, name and ids, then every value that is not "none".
std::string Emitter::node_row(const Node& n) const {
    std::string name = c_string(n.name), hf_ref = has_hf(n) ? "&" + hf(n) : "NULL";
    std::string start = n.is_container() ? "dg_container(" + name + ", " + hf_ref + ", &" + ett(n) + ")"
                                         : "dg_leaf(" + name + ", " + hf_ref + ")";
    std::vector<std::string> set;
    auto add = [&](const char* setter, const std::string& args) { set.push_back(setter + ("(" + args + ")")); };
    auto pair = [](size_t first, size_t count) { return std::to_string(first) + ", " + std::to_string(count); };
    if (n.is_leaf()) add("show", show_of(n));
    if (std::string flags = flags_of(n, is_pairing_key(n)); flags != "0") add("flags", flags);
    std::string length_kind = length_kind_of(n);
    if (length_kind == "DG_LEN_FIELD") add("length_field", ref_of(&n.length_ref));
    if (length_kind == "DG_LEN_REST") add("length_rest", "");
    if (length_kind == "DG_LEN_CHILDREN") add("length_children", "");
    if (length_kind == "DG_LEN_COMPUTED") add("length_computed", "");
    if (length_kind == "DG_LEN_PACKED") add("length_packed", "");
    unsigned length = n.in_bit_group ? n.group_bytes : static_cast<unsigned>(n.fixed_bits / 8);
    if (length && (n.has_fixed_length() || n.in_bit_group)) add("length", std::to_string(length));
    if (length_kind == "DG_LEN_REST" && n.rest_keep) add("length", std::to_string(n.rest_keep));
    if (n.shift) add("shift", std::to_string(n.shift));
    if (n.bits) add("bits", std::to_string(n.bits));
    if (n.slot >= 0) add("slot", std::to_string(n.slot));
    if (n.count) add("count", ref_of(&*n.count));
    if (n.repeat && n.repeat->target) add("repeat", std::to_string(n.repeat->target->slot));
    if (n.if_field)
        add("if_in", std::to_string(n.if_field->target ? n.if_field->target->slot : -1) + ", " +
                         pair(l_.range_first.at(&n), n.in_list.size()));
    if (n.is_container()) add("children", pair(l_.first_child.at(&n), n.children.size()));
    if (auto [first, count] = slot_span(n); count) add("slots", pair(first, count));
    if (!n.summary_pieces.empty()) add("summary", pair(l_.piece_first.at(&n), n.summary_pieces.size()));
    if (n.has_hook) add("hooks", pair(l_.hook_range_first.at(&n), n.hook_list.size()));
    if (extra_index_.count(&n)) add("extra", "&" + p_.filter + "_extra[" + std::to_string(extra_index_.at(&n)) + "]");
    if (!n.whens.empty()) add("whens", pair(l_.when_first.at(&n), n.whens.size()));
    if (n.otherwise) add("alt", "DG_ALT_OTHERWISE");
    if (l_.window_index.count(&n)) add("window", std::to_string(l_.window_index.at(&n)));
    if (quiet_.count(&n)) add("quiet_size", std::to_string(quiet_.at(&n)) + "u");
    if (has_walk(n)) add("walk", walk_name(&n));
    if (!n.summary_pieces.empty()) add("summarize", summary_name(n.doc_index - 1));
    return named_row(start, set);
}

// The walk of a container's children (owner NULL: the top-level nodes).
std::string Emitter::walk_name(const Node* owner) const {
    return p_.filter + "_walk_" + (owner ? std::to_string(owner->doc_index - 1) : std::string("top"));
}

void Emitter::walk_declarations() {
    o_ << "/* The lists of siblings, compiled: each member decoded in turn, its node a\n"
       << " * constant (dissgen_state.h, dissect_child). */\n";
    o_ << walk_signature(nullptr) << ";\n";
    for (const Node* n : l_.nodes)
        if (has_walk(*n)) o_ << walk_signature(n) << ";\n";
    o_ << "\n/* The summaries, compiled: the pieces in turn (dissgen_text.cpp, append_pieces). */\n";
    for (const Node* n : l_.nodes)
        if (!n->summary_pieces.empty()) o_ << summary_signature(*n) << ";\n";
    o_ << "\n";
}

// The statements of pieces [first, first + count) at nesting `depth`;
// `complete` is the flag a value that shows nothing clears.
void Emitter::summary_pieces(size_t first, size_t count, const std::string& complete, int depth) {
    const std::string in(4 * static_cast<size_t>(depth), ' ');
    for (size_t i = first; i < first + count; ++i) {
        const Layout::Piece& p = l_.pieces[i];
        if (p.group) {
            // left out unless every value it shows itself (not those of parts inside it) was decoded
            std::string decoded;
            for (size_t j = i + 1; j < i + 1 + p.group; ++j) {
                const Layout::Piece& q = l_.pieces[j];
                if (q.group) j += q.group;
                else if (q.slot >= 0) decoded += (decoded.empty() ? "" : " && ") + std::string("st->present[") + std::to_string(q.slot) + "]";
            }
            std::string part = "part" + std::to_string(depth + 1), mark = "mark" + std::to_string(depth + 1);
            o_ << in << "if (" << (decoded.empty() ? "TRUE" : decoded) << ") { /* {?...} */\n"
               << in << "    gsize " << mark << " = out->len;\n" << in << "    gboolean " << part << " = TRUE;\n";
            summary_pieces(i + 1, p.group, part, depth + 1);
            o_ << in << "    if (!" << part << ") dg_rt::text_truncate(out, " << mark << ");\n" << in << "}\n";
            i += p.group;
        } else if (p.slot < 0) {
            o_ << in << "dg_rt::text_append(out, " << c_string(p.text) << ", " << p.text.size() << ");\n";
        } else {
            std::string slot = "st->slots[" + std::to_string(p.slot) + "]";
            std::string value = "dg_rt::append_shown_value(st, out, &" + slot + ")";
            // A plain hex or decimal number shows its value as such (dissgen_text.cpp, append_bare_value).
            const Node* f = p.leaf;
            bool plain = f && f->is_leaf() && f->is_numeric() && !f->is_computed() && !f->unit_given;
            if (p.node >= 0) value = summary_name(p.node) + "(st, out)";
            else if (plain && f->display == Display::NumberHex && !f->is_number_sized_by_field())  // fixed width
                value = "dg_rt::append_hex(out, " + slot + ".value, " + std::to_string((f->bits + 3) / 4) + ")";
            else if (plain && f->display == Display::NumberDec)
                value = "dg_rt::append_dec(out, " + slot + ".value)";
            o_ << in << "if (!st->present[" << p.slot << "]) {\n"
               << in << "    dg_rt::text_append(out, \"-\", 1);\n" << in << "    " << complete << " = FALSE;\n"
               << in << "} else {\n"
               << in << "    gsize before = out->len;\n" << in << "    " << value << ";\n"
               << in << "    if (out->len == before) " << complete << " = FALSE;\n" << in << "}\n";
        }
    }
}

void Emitter::summary_definitions() {
    for (const Node* n : l_.nodes) {
        if (n->summary_pieces.empty()) continue;
        o_ << summary_signature(*n) << "\n{\n    /* line " << n->line << " */\n"
           << "    gboolean complete = TRUE;\n";
        summary_pieces(static_cast<size_t>(l_.piece_first.at(n)), n->summary_pieces.size(), "complete", 1);
        o_ << "    return complete;\n}\n\n";
    }
}

void Emitter::walk_definitions() {
    auto define = [&](const Node* owner, size_t first, size_t count) {
        o_ << walk_signature(owner) << "\n{\n";
        if (owner) o_ << "    /* " << comment_text(owner->name) << " (line " << owner->line << ") */\n";
        o_ << "    gboolean chain_taken = FALSE;\n    dg_rt::list_begin(st, *offset, end);\n";
        for (size_t i = first; i < first + count; ++i) {
            int k = l_.children_flat[i];
            o_ << "    if (!st->stopped) dg_rt::dissect_child(st, &" << p_.filter << "_conditions, &" << p_.filter << "_nodes[" << k
               << "], tree, offset, end, in_summary, &chain_taken); /* " << comment_text(l_.nodes[k]->name) << " */\n";
        }
        o_ << "    dg_rt::list_end(st);\n}\n\n";
    };
    define(nullptr, 0, p_.nodes.size());
    for (const Node* n : l_.nodes)
        if (has_walk(*n)) define(n, l_.first_child.at(n), n->children.size());
}

// The registers the pairing's analysis reads (<input> of a window child):
// where each sits, handed to it once. Returns how many.
size_t Emitter::input_places() {
    const Analysis* analysis = find_analysis(p_.pairing->analysis);
    std::vector<const AnalysisInput*> bound;
    for (const AnalysisInput& input : p_.pairing->inputs)
        if (analysis && input.index >= 0 && analysis->inputs[input.index].address) bound.push_back(&input);
    if (bound.empty()) return 0;
    o_ << "/* Where the registers the analysis reads sit in their register map: input, address, size,\n"
       << "   stride and instances (from at=, stride=, instances=). */\n"
       << "static const dg_input_place " << p_.filter << "_input_places[] = {\n";
    for (const AnalysisInput* input : bound) {
        const Node& t = *input->field.target;
        o_ << "    { " << input->index << ", " << hex(*t.at, 4) << ", " << t.place_bytes << ", " << t.stride.value_or(0)
           << ", " << t.instances.value_or(1) << " }, /* " << comment_text(input->name) << ": "
           << comment_text(t.name) << ", line " << t.line << " */\n";
    }
    o_ << "};\n";
    return bound.size();
}

void Emitter::protocol_struct() {
    const std::string& f = p_.filter;
    const Node* pdu = p_.pdulength ? p_.pdulength->target : nullptr;
    o_ << "static int dissect_" << f << "(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data);\n";
    if (pdu) o_ << "static int dissect_" << f << "_stream(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data);\n";
    if (p_.pairing) {
        char timeout[32];
        std::snprintf(timeout, sizeof timeout, "%.9g", p_.pairing->timeout);
        const Analysis* analysis = find_analysis(p_.pairing->analysis);
        o_ << "\n/* Request/response pairing (<pairing>, line " << p_.pairing->line
           << "): timeout in seconds, analysis, responses in the order of their requests, the registers the "
              "analysis reads, what says a message is a request (<request>; NULL: its direction). */\n";
        if (analysis)
            o_ << "/* The " << c_string(analysis->name) << " analysis, compiled in from the runtime. */\n"
               << "extern \"C\" const struct dg_analysis " << analysis->symbol << ";\n";
        const size_t places = input_places();
        const std::optional<CycleField>& request = p_.pairing->request;
        const std::optional<CycleField>& unanswered = p_.pairing->unanswered;
        if (request) request_role(*request, "request_role", "is a request, any other value a response");
        if (unanswered) request_role(*unanswered, "unanswered", "expects no response: it takes no part in pairing");
        o_ << "static const dg_pairing " << f << "_pairing = { " << timeout << ", "
           << (analysis ? "&" + analysis->symbol : std::string("NULL")) << ", " << (p_.pairing->ordered ? 1 : 0)
           << ", " << (places ? f + "_input_places" : std::string("NULL")) << ", " << places
           << ", " << (request ? "&" + f + "_request_role" : std::string("NULL"))
           << ", " << (unanswered ? "&" + f + "_unanswered" : std::string("NULL")) << " };\n";
        if (!p_.request_fields.empty()) request_context();
    }
    if (p_.cycles) cycles_tables();
    o_ << "\nstatic dg_protocol " << f << "_protocol =\n    " << protocol_row() << ";\n\n";
    // valid fields: the entries test them first (dg_valid_*)
    const bool valid = has_validity(p_);
    const std::string entry = valid ? "dg_valid_" : "dg_", of = valid ? "_validity" : "_protocol";
    if (valid) o_ << emit_validity(p_);
    // a message the valid fields refuse goes on, with the dissector's data, to the one our hook displaced
    const std::string data = valid ? "void *data" : "void *data _U_", pass = valid ? ", data" : "";
    o_ << "static int dissect_" << f << "(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, " << data << ")\n{\n"
       << "    return " << entry << "dissect(&" << f << of << ", tvb, pinfo, tree" << pass << ");\n}\n\n";
    if (pdu)
        o_ << "static int dissect_" << f << "_stream(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, " << data
           << ")\n{\n"
           << "    return " << entry << "dissect_stream(&" << f << of << ", tvb, pinfo, tree" << pass << ");\n}\n\n";
}

// The protocol's row: its names, entry points and tables; the tables it does not use stay NULL.
std::string Emitter::protocol_row() const {
    const std::string& f = p_.filter;
    const Node* pdu = p_.pdulength ? p_.pdulength->target : nullptr;
    size_t hook_count = p_.hooks.size() + (p_.ethertype ? 1 : 0);
    std::vector<std::string> set = {
        "ids(&proto_" + f + ", &ett_" + f + ")",
        "dissect(dissect_" + f + ", " + (pdu ? "dissect_" + f + "_stream" : "NULL") + ")",
        "nodes(" + f + "_nodes, " + std::to_string(l_.nodes.size()) + ")",
        "children(" + f + "_children, 0, " + std::to_string(p_.nodes.size()) + ")",
        "conditions(&" + f + "_conditions)",
        "pieces(" + f + "_summary)",
        "slot_count(" + std::to_string(p_.slot_count) + ")",
        "experts(&ei_" + f + ")",
        "hooks(" + f + "_hooks, " + std::to_string(hook_count) + ")",
        "top_walk(" + walk_name(nullptr) + ")"};
    if (pdu)
        set.push_back("pdu_length(" + std::to_string(pdu->doc_index - 1) + ", " +
                      std::to_string(p_.pdu_offset) + ", " + std::to_string(p_.pdulengthadd) + ")");
    if (uses_reassembly()) set.push_back("reassembly(&" + f + "_reassembly, &" + f + "_fragment_items)");
    auto table = [&](const char* name, const std::vector<std::string>& rows) {
        if (!rows.empty()) set.push_back(std::string(name) + "(" + f + "_" + name + ")");
    };
    table("peeks", l_.peeks);
    table("peek_lengths", l_.peek_lengths);
    table("windows", l_.windows);
    table("places", l_.places);
    if (!l_.exprs.empty()) set.push_back("exprs(" + f + "_exprs)");
    if (p_.no_padding) set.push_back("no_padding()");
    if (!l_.findings.empty()) set.push_back("findings(" + f + "_findings)");
    if (!l_.learns.empty())
        set.push_back("learns(" + f + "_learns, " + (l_.learn_keys.empty() ? std::string("NULL") : f + "_learn_keys") +
                      ", " + std::to_string(l_.learns.size()) + ")");
    if (p_.pairing) set.push_back("pairing(&" + f + "_pairing)");
    if (p_.pairing && !p_.request_fields.empty()) set.push_back("request_context(&" + f + "_request_context)");
    if (p_.cycles) set.push_back("cycles(&" + f + "_cycles)");
    if (extra_ && !extra_->analysis_data.empty()) set.push_back("analysis_data(&" + extra_->analysis_data + ")");
    return named_row("dg_protocol_of(" + c_string(p_.name) + ", " + c_string(p_.abbreviation) + ", " + c_string(f) + ")", set);
}

// <cycles>: the window, the sequence count's width, whether the sender is
// part of the signature, and the values each <only>/<never> test holds for
// (a test without 'in': any value but 0).
// The dg_range rows of a field's test: its 'in' list, or any value but 0.
void append_test_ranges(const CycleField& t, std::vector<std::string>& ranges) {
    if (t.in_list.empty()) ranges.push_back("{ " + hex(1) + ", " + hex(UINT64_MAX) + " }");
    for (const ValueRange& r : t.in_list) ranges.push_back("{ " + hex(r.low) + ", " + hex(r.high) + " }");
}

void Emitter::cycles_tables() {
    const std::string& f = p_.filter;
    const Cycles& c = *p_.cycles;
    std::vector<std::string> tests, ranges;
    auto add_tests = [&](const std::vector<CycleField>& fields, const char* element) {
        for (const CycleField& t : fields) {
            const size_t first = ranges.size();
            append_test_ranges(t, ranges);
            tests.push_back("/* <" + std::string(element) + ">, line " + std::to_string(t.line) + " */ { " +
                            std::to_string(first) + ", " + std::to_string(ranges.size() - first) + " }");
        }
    };
    add_tests(c.only, "only");
    add_tests(c.never, "never");
    o_ << "\n/* Periodic traffic (<cycles>, line " << c.line
       << "): each <only>/<never> test's ranges; window, sequence bits, sender in the signature, "
          "<only> tests, sequence step (0: learned), losses told by the period, the count's wrap (0: at 2^bits), "
          "requests only, the most lost in one gap (0: the default). */\n";
    if (!tests.empty())
        o_ << c_array("static const dg_cycle_test " + f + "_cycle_tests", tests)
           << c_array("static const dg_range " + f + "_cycle_ranges", ranges);
    o_ << "static const dg_cycles " << f << "_cycles = { " << c.window << ", " << c.sequence_bits << ", "
       << (c.by_connection ? "DG_STREAM_ENDS_CONNECTION" : c.by_sender ? "DG_STREAM_ENDS_SENDER" : "DG_STREAM_ENDS_NONE")
       << ", " << c.only.size() << ", "
       << (tests.empty() ? std::string("NULL") : f + "_cycle_tests") << ", "
       << (tests.empty() ? std::string("NULL") : f + "_cycle_ranges") << ", " << c.sequence_step << "u, "
       << (c.lost_by_period ? 1 : 0) << ", " << c.sequence_wrap << "u, " << (c.requests_only ? 1 : 0) << ", " << c.max_lost << "u };\n";
}

// <request> (<unanswered>): the field's slot and the values that make a
// message a request (one that expects no response); `name` is the table's.
void Emitter::request_role(const CycleField& r, const std::string& name, const std::string& says) {
    const std::string& f = p_.filter;
    const std::string element = name == "request_role" ? "request" : name;
    std::vector<std::string> ranges;
    append_test_ranges(r, ranges);
    o_ << "/* <" << element << ">, line " << r.line << ": a message whose " << c_string(r.field.target->name)
       << " is one of these " << says << ". */\n"
       << c_array("static const dg_range " + f + "_" + element + "_ranges", ranges) << "static const dg_request_role "
       << f << "_" << name << " = { " << r.field.target->slot << ", " << ranges.size() << ", " << f << "_" << element
       << "_ranges };\n";
}

// request{...}: the key fields where a response reads them before it is
// decoded (in the walk's order: the document's), and the slots of the fields
// a request keeps for its responses.
void Emitter::request_context() {
    const std::string& f = p_.filter;
    std::vector<const PairingKey*> keys;  // none: the keys the walk decoded, read when needed
    for (const PairingKey& k : p_.pairing->keys)
        if (k.field.target && !p_.pairing->keys_decoded) keys.push_back(&k);
    std::sort(keys.begin(), keys.end(), [](const PairingKey* a, const PairingKey* b) {
        return a->field.target->doc_index < b->field.target->doc_index;
    });
    std::vector<std::string> key_rows, slot_rows;
    for (const PairingKey* k : keys) {
        const Node& n = *k->field.target;
        key_rows.push_back("/* " + n.name + ", line " + std::to_string(n.line) + " */ { " + std::to_string(k->offset) +
                           ", " + std::to_string(value_bytes(n)) + ", " +
                           (n.byteorder == ByteOrder::Little ? "1" : "0") + ", " +
                           std::to_string(n.in_bit_group ? n.shift : 0) + ", " +
                           std::to_string(n.in_bit_group ? n.bits : 0) + " }");
    }
    std::vector<std::string> instance_rows;  // per kept field: 1 when kept per instance (read by position)
    bool by_position = false;
    for (const Node* n : p_.request_fields) {
        slot_rows.push_back("/* " + n->name + ", line " + std::to_string(n->line) + " */ " + std::to_string(n->slot));
        instance_rows.push_back(n->keeps_instances ? "1" : "0");
        by_position = by_position || n->keeps_instances;
    }
    o_ << (p_.pairing->keys_decoded
               ? "/* request{...}: no key fields at fixed offsets (a response looks its request up with the key\n"
                 " * values decoded before its first request{...}), and the slots of the fields a request keeps\n"
                 " * for its responses. */\n"
               : "/* request{...}: the key fields at fixed offsets (offset, bytes, little-endian, shift, bits), and the\n"
                 " * slots of the fields a request keeps for its responses. */\n")
       << c_array("static const dg_fixed_field " + f + "_request_keys", key_rows)
       << c_array("static const gint16 " + f + "_request_slots", slot_rows);
    if (by_position)  // fields in a repeated node: every instance is kept
        o_ << c_array("static const guint8 " + f + "_request_by_position", instance_rows);
    o_ << "static const dg_request_context " << f << "_request_context = { " << f << "_request_keys, "
       << key_rows.size() << ", " << f << "_request_slots, " << slot_rows.size() << ", "
       << (by_position ? f + "_request_by_position" : std::string("NULL")) << " };\n";
}

void Emitter::register_functions() {
    const std::string& f = p_.filter;
    o_ << "void proto_register_" << f << "(void)\n{\n    static hf_register_info hf[] = {\n";
    bool first = true;
    for (const Node* n : l_.nodes) {
        if (!registers_hf(*n)) continue;
        FieldType t = field_type(*n);
        std::string strings = "NULL";
        if (n->is_leaf() && n->display == Display::Enum)
            strings = uses_val64(*n) ? "VALS64(" + vals(*n) + ")" : "VALS(" + vals(*n) + ")";
        if (n->is_leaf() && n->display == Display::Enum && n->has_enum_ranges()) strings = "RVALS(" + rvals(*n) + ")";
        if (n->has_unit_label() && n->display != Display::Float) {  // floats: the runtime writes it
            t.display += "|BASE_UNIT_STRING";
            strings = "(const void *)&" + l_.ident.at(n) + "_unit";
        }
        o_ << (first ? "" : ",\n") << "        { &" << hf(*n) << ",\n          { " << c_string(n->name) << ", "
           << c_string(n->filter_name) << ", " << t.type << ", " << t.display << ", " << strings << ", "
           << hex(t.mask) << ",\n            " << (n->description.empty() ? "NULL" : c_string(n->description))
           << ", HFILL } }";
        first = false;
    }
    if (uses_reassembly()) {  // the fragment fields of Wireshark's reassembly API
        for (const auto& fr : fragment_fields(p_)) {
            o_ << (first ? "" : ",\n") << "        { &frag_hf_" << fr.ident << ",\n          { " << c_string(fr.name)
               << ", " << c_string(fr.filter) << ", " << fr.type << ", " << fr.display << ", NULL, 0x0, NULL, HFILL } }";
            first = false;
        }
    }
    for (const std::string& entry : extra_ ? extra_->hf_entries : std::vector<std::string>{}) {
        o_ << (first ? "" : ",\n") << "        " << entry;
        first = false;
    }
    if (first) o_ << "        { NULL, { NULL, NULL, FT_NONE, BASE_NONE, NULL, 0x0, NULL, HFILL } }";
    o_ << "\n    };\n\n    static gint *ett[] = {\n        &ett_" << f;
    for (const Node* n : l_.nodes)
        if (n->is_container()) o_ << ",\n        &" << ett(*n);
    if (uses_reassembly()) o_ << ",\n        &frag_ett_fragment,\n        &frag_ett_fragments";
    o_ << "\n    };\n\n    static ei_register_info ei[] = {\n";
    expert_entries();
    o_ << "    };\n\n"
       << "    if (!dg_protocol_names_free(&" << f << "_protocol))\n        return;\n"
       << "    dg_register(&" << f << "_protocol, hf, " << (first ? "0" : "(int)G_N_ELEMENTS(hf)")
       << ", ett, (int)G_N_ELEMENTS(ett), ei, (int)G_N_ELEMENTS(ei));\n}\n\n"
       << "void proto_reg_handoff_" << f << "(void)\n{\n    dg_handoff(&" << f << "_protocol);\n"
       << (p_.heuristics.empty() ? "" : "    dg_validity_handoff(&" + f + "_validity);\n") << "}\n\n"
       << "DG_DECLARE_PLUGIN(proto_register_" << f << ", proto_reg_handoff_" << f << ")\n";
}

// The expert infos every protocol registers (dg_experts), from the runtime's list.
void Emitter::expert_entries() {
    const std::string& f = p_.filter;
    std::vector<const RuntimeName*> experts;
    for (const RuntimeName& n : name_group(NameGroup::When::Always).names)
        if (n.kind == RuntimeName::Kind::Expert) experts.push_back(&n);
    for (size_t i = 0; i < experts.size(); ++i) {
        const RuntimeName& e = *experts[i];
        o_ << "        { &ei_" << f << "." << e.id << ", { " << c_string(f + "." + e.name) << ", " << e.group << ", "
           << e.severity << ", " << c_string(e.label) << ", EXPFILL } }"
           << (i + 1 < experts.size() || !l_.findings.empty() ? ",\n" : "\n");
    }
    finding_entries();
}

// The rule file's <finding>s, after the runtime's expert infos; the summary
// is the text as written.
void Emitter::finding_entries() {
    const std::vector<const Finding*>& all = l_.finding_experts;
    for (size_t i = 0; i < all.size(); ++i) {
        const Finding& f = *all[i];
        o_ << "        { &" << p_.filter << "_finding_ei[" << i << "], { " << c_string(f.filter_name) << ", "
           << group_constant(f.group) << ", " << severity_constant(f.severity) << ", " << c_string(f.text)
           << ", EXPFILL } }" << (i + 1 < all.size() ? ",\n" : "\n");
    }
}

// --- typed values, hand-off and reassembly ------------------------------------

bool Emitter::uses_reassembly() const {
    for (const Node* n : l_.nodes)
        if (n->reassembles()) return true;
    return false;
}

void Emitter::fragment_declarations() {
    if (!uses_reassembly()) return;
    o_ << "/* Reassembly across frames (Wireshark's reassembly API). */\n";
    for (const auto& fr : fragment_fields(p_)) o_ << "static int frag_hf_" << fr.ident << " = -1;\n";
    const std::string& f = p_.filter;
    o_ << "static gint frag_ett_fragment = -1;\nstatic gint frag_ett_fragments = -1;\n"
       << "static reassembly_table " << f << "_reassembly;\n\n"
       << "static const fragment_items " << f << "_fragment_items = {\n"
       << "    &frag_ett_fragment, &frag_ett_fragments,\n"
       << "    &frag_hf_fragments, &frag_hf_fragment, &frag_hf_fragment_overlap, &frag_hf_fragment_overlap_conflicts,\n"
       << "    &frag_hf_fragment_multiple_tails, &frag_hf_fragment_too_long_fragment, &frag_hf_fragment_error,\n"
       << "    &frag_hf_fragment_count, &frag_hf_reassembled_in, &frag_hf_reassembled_length,\n"
       << "    &frag_hf_reassembled_data, \"Fragments\"\n};\n\n";
}

void Emitter::range_strings(const Node& n) {
    o_ << "static const range_string " << rvals(n) << "[] = {\n";
    int digits = static_cast<int>((n.bits + 3) / 4);
    for (const EnumItem& e : n.enums)
        o_ << "    { " << hex(e.value, digits) << ", " << hex(e.high, digits) << ", " << c_string(e.name) << " },\n";
    o_ << "    { 0, 0, NULL }\n};\n\n";
}

// A datetime's ENC_TIME_* encoding (s+ns, ENC_TIME_SECS_NSECS, is the runtime's default).
std::string datetime_encoding(const Node& n) {
    const std::string unit = n.datetime_unit();
    if (unit == "ns") return "ENC_TIME_NSECS";
    if (unit == "us") return "ENC_TIME_USECS";
    if (unit == "ms") return "ENC_TIME_MSECS";
    if (unit == "s") return "ENC_TIME_SECS";
    if (unit == "filetime") return "DG_TIME_FILETIME";  // no ENC_TIME_ of Wireshark's: the runtime converts it
    return "ENC_TIME_SECS_NSECS";
}

bool needs_extra(const Node& n) {
    return (n.is_leaf() && (n.display == Display::String || n.display == Display::StringZ ||
                            n.display == Display::Time)) ||
           (n.is_leaf() && n.display == Display::DateTime && n.datetime_unit() != "s+ns") ||
           n.repeat_rest || n.direction != Direction::Any || n.dissector || n.reassembles() || n.is_located() ||
           n.keeps_values || n.keeps_instances || !n.kept_slots.empty() || n.is_computed() || n.has_unit_label() || n.is_overlay() ||
           !n.findings.empty() || !n.learns.empty() || n.analysis_input >= 0 || n.cycle_role != 0 ||
           n.is_counted_list_of_no_bytes();
}

void Emitter::extra_table() {
    std::vector<std::string> kept;
    for (const Node* n : l_.nodes)
        if (!n->kept_slots.empty()) {
            kept_first_[n] = static_cast<int>(kept.size());
            for (const auto& [repeat, slot] : n->kept_slots)
                kept.push_back("/* " + n->name + " across " + repeat->name + " */ " + std::to_string(slot));
        }
    if (!kept.empty()) {
        o_ << "/* Slots where a leaf a summary names across a repeat keeps its last value. */\n"
           << c_array("static const gint16 " + p_.filter + "_kept_slots", kept);
    }
    std::vector<std::string> rows;
    for (const Node* n : l_.nodes)
        if (needs_extra(*n)) {
            extra_index_[n] = static_cast<int>(rows.size());
            rows.push_back("/* " + std::to_string(n->doc_index - 1) + ": " + n->name + " */\n    " + extra_row(*n));
        }
    if (rows.empty()) return;
    o_ << "/* What few nodes need beyond dg_node. */\n" << c_array("static const dg_extra " + p_.filter + "_extra", rows);
}

// A node's dg_extra: every value that is not the default (UTF-8, nanoseconds, no reassembly).
std::string Emitter::extra_row(const Node& n) const {
    std::vector<std::string> set;
    auto add = [&](const char* setter, const std::string& args) { set.push_back(setter + ("(" + args + ")")); };
    auto slot = [](const std::optional<FieldRef>& r) { return r && r->target ? r->target->slot : -1; };
    if (n.encoding == "ascii") add("encoding", "ENC_ASCII");
    if (n.encoding == "iso-8859-1") add("encoding", "ENC_ISO_8859_1");
    // A time, or a computed datetime (a count of its unit, not bytes), in a unit coarser than ns.
    const bool counts_units = n.display == Display::Time || (n.display == Display::DateTime && n.is_computed());
    if (counts_units && (n.unit == "s" || n.unit == "ms" || n.unit == "us"))
        add("units_per_second", n.unit == "s" ? "1" : n.unit == "ms" ? "1000" : "1000000");
    if (n.display == Display::DateTime && !n.is_computed() && n.datetime_unit() != "s+ns")
        add("time_encoding", datetime_encoding(n));
    if (n.repeat_rest) add("repeat_rest", "");
    if (n.is_counted_list_of_no_bytes()) add("no_bytes", "");
    if (n.direction != Direction::Any)
        add("direction", n.direction == Direction::Request ? "DG_DIR_REQUEST" : "DG_DIR_RESPONSE");
    if (n.dissector) add("dissector", c_string(*n.dissector));
    if (slot(n.reassemble_id) >= 0) add("reassemble_id", std::to_string(slot(n.reassemble_id)));
    if (n.reassemble_offset && n.reassemble_offset->target) add("reassemble_offset", ref_of(&*n.reassemble_offset));
    if (slot(n.reassemble_seq) >= 0) add("reassemble_seq", std::to_string(slot(n.reassemble_seq)));
    if (slot(n.reassemble_last) >= 0) add("reassemble_last", std::to_string(slot(n.reassemble_last)));
    if (slot(n.reassemble_more) >= 0) add("reassemble_more", std::to_string(slot(n.reassemble_more)));
    // offset tables
    if (slot(n.offsets) >= 0) add("offsets_slot", std::to_string(slot(n.offsets)));
    if (!n.from_up && slot(n.from) >= 0) add("from_slot", std::to_string(slot(n.from)));
    if (n.from_up) add("from_up", std::to_string(n.from_up));
    if (n.keeps_values) add("keep_values", "");
    if (n.keeps_instances) add("keep_instances", "");
    if (!n.kept_slots.empty())
        add("kept", p_.filter + "_kept_slots + " + std::to_string(kept_first_.at(&n)) + ", " +
                        std::to_string(n.kept_slots.size()));
    if (n.has_unit_label()) add("unit", c_string(" " + n.unit));
    if (slot(n.overlay) >= 0) add("overlay", std::to_string(slot(n.overlay)));
    if (n.is_computed())
        add("value", std::to_string(l_.expr_span.at(&n).first) + ", " + std::to_string(l_.expr_span.at(&n).second));
    if (slot(n.covers) >= 0) add("covers", std::to_string(slot(n.covers)));
    if (!n.findings.empty()) add("findings", std::to_string(l_.finding_first.at(&n)) + ", " + std::to_string(n.findings.size()));
    if (!n.learns.empty()) add("learns", std::to_string(l_.learn_first.at(&n)) + ", " + std::to_string(n.learns.size()));
    if (n.analysis_input >= 0) add("input", std::to_string(n.analysis_input));
    if (n.cycle_role) add("cycle_role", std::to_string(n.cycle_role) + ", " + std::to_string(n.cycle_test));
    return named_row("dg_node_extra()", set);
}

}  // namespace

std::vector<FragmentField> fragment_fields(const Protocol& proto) {
    std::vector<FragmentField> out;
    for (const RuntimeName& n : name_group(NameGroup::When::Reassembly).names)
        out.push_back({n.id, n.label, proto.filter + "." + n.name, n.type, n.display});
    return out;
}

// The Wireshark type of string, stringz, int, float, time, datetime, guid and address leaves.
std::optional<FieldType> typed_field_type(const Node& n) {
    unsigned bytes = value_bytes(n);
    switch (n.display) {
        case Display::String: return FieldType{"FT_STRING", "BASE_NONE", 0};
        case Display::StringZ: return FieldType{"FT_STRINGZ", "BASE_NONE", 0};
        case Display::IPv4: return FieldType{"FT_IPv4", "BASE_NONE", 0};
        case Display::Float: return FieldType{n.fixed_bits == 64 ? "FT_DOUBLE" : "FT_FLOAT", "BASE_NONE", 0};
        case Display::Time: return FieldType{"FT_RELATIVE_TIME", "BASE_NONE", 0};
        case Display::DateTime: return FieldType{"FT_ABSOLUTE_TIME", "ABSOLUTE_TIME_UTC", 0};
        case Display::Guid: return FieldType{"FT_GUID", "BASE_NONE", 0};
        case Display::IPv6: return FieldType{"FT_IPv6", "BASE_NONE", 0};
        case Display::Mac: return FieldType{"FT_ETHER", "BASE_NONE", 0};
        case Display::Eui64: return FieldType{"FT_EUI64", "BASE_NONE", 0};
        case Display::Oid: return FieldType{"FT_OID", "BASE_NONE", 0};
        case Display::Varint: return FieldType{"FT_UINT64", "BASE_DEC", 0};
        case Display::Int: {
            return FieldType{"FT_INT" + std::to_string(bytes * 8), "BASE_DEC", group_mask(n)};
        }
        default: return std::nullopt;
    }
}

// A computed value: 64 bits (a hex one as wide as its mask), signed unless
// shown in hex or as a name.
FieldType computed_field_type(const Node& n) {
    switch (n.display) {
        case Display::Float: return {"FT_DOUBLE", "BASE_NONE", 0};
        case Display::Bool: return {"FT_BOOLEAN", "BASE_NONE", 0};
        case Display::Time: return {"FT_RELATIVE_TIME", "BASE_NONE", 0};
        case Display::DateTime: return {"FT_ABSOLUTE_TIME", "ABSOLUTE_TIME_UTC", 0};
        case Display::NumberHex: return {"FT_UINT" + std::to_string(n.bits), "BASE_HEX", 0};
        case Display::Enum:  // masked to 32 bits or fewer: as wide as its mask (check_computed)
            if (n.bits <= 32)
                return {"FT_UINT" + std::to_string(n.bits), n.has_enum_ranges() ? "BASE_HEX|BASE_RANGE_STRING" : "BASE_HEX", 0};
            return {"FT_UINT64", "BASE_HEX|BASE_VAL64_STRING", 0};
        default: return {"FT_INT64", "BASE_DEC", 0};
    }
}

FieldType field_type(const Node& n) {
    if (n.is_container()) return {"FT_NONE", "BASE_NONE", 0};
    if (n.is_computed()) return computed_field_type(n);
    if (auto typed = typed_field_type(n)) return *typed;
    if (!n.is_numeric()) {
        const char* sep = n.display == Display::Address ? "SEP_COLON"
                          : n.display == Display::Origin ? "SEP_SPACE"
                                                         : "BASE_NONE";
        return {"FT_BYTES", sep, 0};
    }
    unsigned bytes = value_bytes(n);
    uint64_t mask = group_mask(n);
    if (n.display == Display::Bool)
        return {"FT_BOOLEAN", n.in_bit_group ? std::to_string(bytes * 8) : "BASE_NONE", mask};
    std::string type = "FT_UINT" + std::to_string(bytes * 8);
    std::string base = "BASE_DEC";
    if (n.display == Display::NumberHex) base = "BASE_HEX";
    if (n.display == Display::Enum) base = bytes > 4 ? "BASE_HEX|BASE_VAL64_STRING" : "BASE_HEX";
    if (n.display == Display::Enum && n.has_enum_ranges()) base = "BASE_HEX|BASE_RANGE_STRING";
    return {type, base, mask};
}

std::string emit_cpp(const Protocol& proto, const std::string& source_name, const EmbeddedTables* extra) {
    return Emitter(proto, source_name, extra).run();
}

std::string list_fields(const Protocol& proto) {
    std::ostringstream out;
    out << proto.filter << "\tFT_PROTOCOL\t" << proto.name << "\t" << kRulesSource << "\n";
    for_each_node(proto.nodes, [&](const Node& n) {
        if (n.filter_name.empty() || n.shares_field) return;  // a shared field is listed once
        out << n.filter_name << "\t" << field_type(n).type << "\t" << n.name << "\t" << kRulesSource << "\n";
    });
    std::set<std::string> findings;  // a <group> used twice raises one from each use
    for_each_node(proto.nodes, [&](const Node& n) {  // <finding>s: expert infos, named by their text
        for (const Finding& f : n.findings)
            if (findings.insert(f.filter_name).second)
                out << f.filter_name << "\tFT_NONE\t" << f.text << "\t" << kRulesSource << "\n";
    });
    for (const NameGroup* g : name_groups_of(proto))
        for (const RuntimeName& n : g->names)
            if (n.kind == RuntimeName::Kind::Field || n.kind == RuntimeName::Kind::Expert)
                out << proto.filter << "." << n.name << "\t" << n.type << "\t" << n.label << "\t" << g->source << "\n";
    return out.str();
}

}  // namespace dissgen

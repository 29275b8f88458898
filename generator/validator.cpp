// SPDX-License-Identifier: GPL-2.0-or-later
#include "validator.h"

#include "alternatives.h"
#include "analysis_inputs.h"
#include "expression.h"
#include "findings.h"

#include "runtime_names.h"
#include "text_util.h"

#include <algorithm>
#include <cctype>
#include <functional>
#include <tuple>
#include <unordered_map>
#include <map>
#include <optional>

namespace dissgen {

namespace {

std::string quote(const Node& n) { return "'" + n.name + "'"; }

std::string at_line(const Node& n) {
    return " (line " + std::to_string(n.line) + (n.group_use.empty() ? "" : ", " + n.group_use) + ")";
}

// The one size of an address display (Wireshark's item of that type takes no other).
unsigned fixed_display_bytes(Display d) {
    switch (d) {
        case Display::IPv4: return 4;
        case Display::Mac: return 6;
        case Display::Eui64: return 8;
        default: return 16;  // guid, ipv6
    }
}

// Displays that show whole bytes and never join a bit group.
bool is_byte_display(Display d) {
    return d == Display::Origin || d == Display::Address || d == Display::String || d == Display::StringZ ||
           d == Display::IPv4 || d == Display::Float || d == Display::Time || d == Display::DateTime ||
           d == Display::Guid || d == Display::IPv6 || d == Display::Mac || d == Display::Eui64 || d == Display::Oid;
}

// The repeated node around t (t itself included) that does not hold
// `reader`, or nullptr: then the reader sees one value of t.
const Node* repeat_outside(const Node* t, const Node& reader) {
    for (const Node* r = t; r; r = r->parent)
        if (r->is_repeated() && !is_ancestor_or_self(r, &reader)) return r;
    return nullptr;
}

// The closest container around `a` that holds `b` too (nullptr: the message).
const Node* common_container(const Node* a, const Node& b) {
    for (const Node* c = a->parent; c; c = c->parent)
        if (is_ancestor_or_self(c, &b)) return c;
    return nullptr;
}

// Whether n or a node around it is repeated: `index` has an instance to count.
bool inside_repeat(const Node& n) {
    for (const Node* r = &n; r; r = r->parent)
        if (r->is_repeated()) return true;
    return false;
}

// A Wireshark dissector table or heuristic list name: [a-z0-9._]+
bool is_table_name(const std::string& table) {
    bool ok = !table.empty();
    for (char c : table)
        ok = ok && (std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) ||
                    c == '.' || c == '_');
    return ok;
}

class Validator {
public:
    Validator(Protocol& proto, Diagnostics& diags) : proto_(proto), diags_(diags) {}
    void run();

private:
    void check_root();
    void inherit_and_check_node(Node& n, ByteOrder inherited);
    void check_leaf_display(Node& n);
    void unaligned_group(const Node& first, unsigned bits, const std::string& next);
    void layout_children(std::vector<std::unique_ptr<Node>>& children);
    void close_group(std::vector<Node*>& group, unsigned bits);
    void join_groups_of_word(std::vector<std::unique_ptr<Node>>& children);
    void layout_packed_bits(Node& n);
    void mean_same_bits(Node& n, std::vector<const Node*>& alternatives);
    std::optional<uint64_t> fixed_bytes(const Node& n) const;
    std::optional<uint64_t> children_fixed_bytes(const Node& n) const;
    void check_fixed_container(const Node& n);
    void check_reference(Node& n, const FieldRef& ref, const std::string& what);
    void check_pdulength();
    void check_computed(Node& n);
    bool widen_masked_values(Node& n, const Node& owner, const std::vector<const Node*>& holders);
    // Where an expression is read: the node it belongs to, the fields it may
    // read (doc_index below reach), the line and words of its messages.
    struct ExprSite {
        int reach;
        int line;
        std::string in;
        // a key's lookup: computed where learned{...} reads it, so the
        // instance its fields and `index` belong to is the reader's
        // (check_lookups_at_readers)
        bool at_reader = false;
        // a computed value's own: it has a place in the message (`offset`)
        bool at_computed = false;
    };
    bool check_expr(Node& n, Expr& e);
    bool check_expr(Node& n, Expr& e, const ExprSite& at);
    const Node* find_before(int reach, const std::string& name);
    const Node* find_readable_before(int reach, const std::string& name, const Node& reader);
    void warn_if_alternative(const Node& field, const Node& reader, int line, const std::string& what);
    void warn_if_default_beside_a_rival(const Node& n);
    std::vector<std::string> names_before(int reach) const;
    // Every node of each name, in document order: names are looked up once
    // per expression operand, and a <group> used many times makes the tree
    // large, so a lookup must not walk it.
    std::unordered_map<std::string, std::vector<const Node*>> nodes_by_name_;
    std::map<std::pair<int, std::string>, std::string> name_suggestions_;  // (line, misspelt name) -> nearest
    int past_last_node_ = 1;  // a reach past every node: all of them are before it
    // <finding>s: their words, names, condition and text (findings.h)
    void check_findings(Node& n);
    void parse_finding_text(Node& n, Finding& f, const ExprSite& at);
    void name_findings();
    // <learn>s and learned{Name}: values from earlier messages
    void collect_learns();
    void check_learns(Node& n);
    bool check_learned(Node& n, Expr& e, const ExprSite& at);
    void check_lookups_at_readers();
    struct LearnedRead {
        const Node* reader;
        const Learn* learn;
        int line;
        std::string in;
        Expr* expr;  // the learned{...} operand
        int reach;   // what the reader's own fields may read
    };
    void resolve_lookups_at_reader(LearnedRead& read);
    std::vector<LearnedRead> learned_reads_;
    std::map<std::string, size_t> read_rows_;  // a reader row's targets -> its row (resolve_lookups_at_reader)
    bool check_integer_expr(Node& n, Expr& e, const ExprSite& at, const std::string& what);
    bool check_request_field(Node& n, Expr& e);
    const Node* request_field_target(const Node& n, const std::string& text, const std::string& what);
    struct RequestTarget {
        const Node* target;
        std::string problem;  // why there is none, after the words naming the read
    };
    RequestTarget resolve_request_field(const std::string& text) const;
    std::map<std::string, RequestTarget> request_targets_;  // request_field_target, by text
    bool check_defined(const Node& n, Expr& e);
    void check_request_keys();
    const Node* reader_before(const Node& t) const;
    const Node* fixed_offset_blocker(const Node& n, uint64_t& offset) const;
    void check_validity();  // valid="LIST" fields and <heuristic>
    void check_pairing();
    void check_request_role(const CycleField& f, const std::string& element);
    void check_cycles();
    void check_cycles_of_ethercat(const Cycles& c);
    bool check_cycle_field(const CycleField& f, const char* element, int role, int test,
                           std::map<const Node*, int>& seen);
    void check_hook_list(const Node& n);
    void check_list_fits(int line, const std::vector<ValueRange>& list, const FieldRef& ref,
                         const char* attribute = "in");
    void offset_of(const Node* t, uint64_t& offset, const Node*& blocker) const;
    struct Place {
        uint64_t offset;        // from the start of the message
        const Node* blocker;    // what keeps it from being fixed, or nullptr
    };
    void place(const std::vector<std::unique_ptr<Node>>& nodes, uint64_t offset, const Node* blocker) const;
    mutable std::unordered_map<const Node*, Place> places_;  // offset_of, made on first use
    void parse_summary(Node& n);
    void assign_filter_names(std::vector<std::unique_ptr<Node>>& nodes, const std::string& prefix);
    void share_filter_name(Node& n, const Node& owner);
    void mark_slot(Node* n) { if (n) needs_slot_[n] = true; }
    void keep_values_across_repeats();
    void assign_slots();
    void check_table_sizes();
    // display types, range enums, repeat="rest", direction, hand-off, reassembly
    void check_display_direction_handoff(Node& n);
    void check_unit(const Node& n);
    void check_string_display(Node& n);
    void check_varint(Node& n);
    void check_datetime_length(const Node& n);
    void check_enum_ranges(const Node& n);
    void check_handoff(const Node& n);
    void check_reassembly(Node& n);
    void check_runtime_name(const Node& n);
    // <when>, otherwise, windows
    void check_layout(Node& n);
    void check_peek(Node& n, When& w);
    void check_offsets(Node& n);  // offsets="XPATH" from="XPATH"
    void check_rest_reach(const Node& n);  // a rest leaf that leaves nothing for what follows
    void check_overlay(Node& n);  // overlay="XPATH"
    void check_covers(Node& n);   // covers="XPATH" on a computed value
    bool known_before(const Node* t, const Node& n) const;

    Protocol& proto_;
    Diagnostics& diags_;
    std::map<const Node*, bool> needs_slot_;
    std::map<std::string, const Node*> filter_owner_;
    std::map<std::string, std::vector<const Node*>> filter_sharers_;  // every node of a shared filter name
    std::vector<const NameGroup*> runtime_names_;  // the names the runtime registers for this protocol
};

void Validator::run() {
    for_each_node(proto_.nodes, [&](Node& n) {
        nodes_by_name_[n.name].push_back(&n);
        past_last_node_ = std::max(past_last_node_, n.doc_index + 1);
    });
    check_root();
    collect_learns();
    for (auto& n : proto_.nodes) inherit_and_check_node(*n, proto_.byteorder);
    layout_children(proto_.nodes);
    for_each_node(proto_.nodes, [&](Node& n) {
        if (n.is_container() && !n.is_window()) check_fixed_container(n);
        if (n.length_kind == LengthKind::Field) check_reference(n, n.length_ref, "length");
        if (n.count) check_reference(n, *n.count, "count");
        if (n.repeat) check_reference(n, *n.repeat, "repeat");
        if (n.if_field) check_reference(n, *n.if_field, "if");
        if (n.if_field) check_list_fits(n.line, n.in_list, *n.if_field);
        for (const When& w : n.whens) check_list_fits(w.line, w.in_list, w.ref);
        if (n.has_hook) check_hook_list(n);
        if (n.summary) parse_summary(n);
        check_display_direction_handoff(n);
        check_layout(n);
        check_offsets(n);
        check_rest_reach(n);
        if (n.is_overlay()) check_overlay(n);
        if (n.covers) check_covers(n);
        if (n.is_computed()) check_computed(n);
        if (n.unit_given) check_unit(n);  // after check_computed, which settles a computed value's display
        if (!n.findings.empty()) check_findings(n);
        if (!n.learns.empty()) check_learns(n);
    });
    check_lookups_at_readers();
    check_pdulength();
    check_validity();
    check_pairing();
    check_cycles();
    check_request_keys();
    runtime_names_ = name_groups_of(proto_);
    assign_filter_names(proto_.nodes, proto_.filter);
    name_findings();
    assign_slots();
    if (!diags_.has_errors()) check_table_sizes();  // expressions compile only once every name resolved
}

// The plugin's tables index their rows with 16 bits (plugin_runtime's
// dg_node, dg_extra, dg_when): a rule file whose tables outgrow them would be
// miscompiled, so it is refused, on the line of the node that goes past.
void Validator::check_table_sizes() {
    const size_t max_rows = 65535;
    size_t nodes = 0, ranges = 0, operations = 0;
    bool reported = false;
    auto over = [&](const Node& n, size_t count, size_t limit, const std::string& what) {
        if (reported || count <= limit) return;
        reported = true;
        diags_.error(n.line, "the rule file is too large for the plugin's tables: more than " +
                                 std::to_string(limit) + " " + what + " in all");
    };
    for_each_node(proto_.nodes, [&](Node& n) {
        over(n, ++nodes, max_rows, "nodes");
        ranges += n.in_list.size() + n.hook_list.size() + n.valid_list.size();
        for (const When& w : n.whens) ranges += w.in_list.size();
        over(n, ranges, max_rows, "values in 'in', 'ifhook', 'valid' and <when> lists");
        if (n.is_computed()) operations += compile_expression(*n.value, n.display == Display::Float).size();
        for (const Finding& f : n.findings) operations += compile_expression(f.condition, false).size();
        for (const Learn& l : n.learns) {
            operations += compile_expression(l.value, false).size();
            if (l.condition) operations += compile_expression(*l.condition, false).size();
            for (const LearnKey& k : l.keys)
                operations += compile_expression(k.value, false).size() +
                              (k.lookup ? compile_expression(*k.lookup, false).size() : 0) +
                              (k.span ? compile_expression(*k.span, false).size() : 0) +
                              (k.id ? compile_expression(*k.id, false).size() : 0);
        }
        over(n, operations, max_rows, "operations in computed values");
        if (n.slot >= 0) over(n, static_cast<size_t>(n.slot) + 1, 32767, "fields whose values are read");
    });
    // readers with keys of their own: rows of learns (read by a 16-bit signed
    // slot), of keys, and operations
    size_t key_rows = 0;
    for (const Learn* l : proto_.learns) key_rows += l->keys.size();
    for (size_t k = 0; k < proto_.learned_read_keys.size() && !reported; ++k) {
        const LearnedReadKeys& row = *proto_.learned_read_keys[k];
        key_rows += row.lookups.size();
        for (size_t i = 0; i < row.lookups.size(); ++i)
            operations += compile_expression(row.learn->keys[i].value, false).size() +
                          (row.lookups[i] ? compile_expression(*row.lookups[i], false).size() : 0);
        const size_t rows = proto_.learns.size() + k + 1;
        for (auto [count, limit, what] : {std::make_tuple(rows, size_t{32767}, "learned{...} readers and <learn>s"),
                                          std::make_tuple(key_rows, max_rows, "keys of learned{...} readers"),
                                          std::make_tuple(operations, max_rows, "operations in computed values")}) {
            if (reported || count <= limit) continue;
            reported = true;
            diags_.error(row.line, "the rule file is too large for the plugin's tables: more than " +
                                       std::to_string(limit) + " " + what + " in all");
        }
    }
}

void Validator::check_root() {
    if (!proto_.ethertype && proto_.hooks.empty() && proto_.heuristics.empty())
        diags_.error(proto_.line, "<root> needs an 'ethertype' or at least one <hook> (or <heuristic>); "
                                  "otherwise nothing is decoded with these rules");
    if (!is_valid_filter_segment(proto_.filter))
        diags_.error(proto_.line,
                     "protocol filter name '" + proto_.filter + "'" +
                         (proto_.filter_given ? "" : " (the abbreviation lowercased)") +
                         " is not valid: it must match [a-z][a-z0-9_]*" +
                         (proto_.filter_given ? "" : "; set a 'filter' attribute on <root>"));
    std::map<std::pair<std::string, uint64_t>, int> hooked;  // table and value -> the line that hooks it first
    if (proto_.ethertype) hooked[{"ethertype", *proto_.ethertype}] = proto_.line;
    for (const Hook& h : proto_.hooks) {
        if (!is_table_name(h.table) && !h.table.empty())
            diags_.error(h.line, "bad hook table '" + h.table + "': expected a Wireshark dissector table such as udp.port");
        auto [first, added] = hooked.emplace(std::make_pair(h.table, h.value), h.line);
        if (!added)
            diags_.warning(h.line, "<hook table=\"" + h.table + "\" value=\"" + std::to_string(h.value) +
                                       "\"> repeats line " + std::to_string(first->second) + ": one hook is enough");
    }
    for (const Heuristic& h : proto_.heuristics) {
        const bool port = h.table.size() > 5 && h.table.compare(h.table.size() - 5, 5, ".port") == 0;
        if (!h.table.empty() && (!is_table_name(h.table) || port))
            diags_.error(h.line, "bad heuristic table '" + h.table + "': expected a Wireshark heuristic list such as "
                                 "udp, tcp or eth" + (port ? " ('" + h.table + "' is a dissector table: use <hook>)" : ""));
    }
    if (proto_.nodes.empty()) diags_.warning(proto_.line, "<root> has no <node>: the protocol decodes nothing");
}

void Validator::inherit_and_check_node(Node& n, ByteOrder inherited) {
    n.byteorder = n.byteorder_given.value_or(inherited);
    if (n.is_container()) {
        if (!n.display_given) n.display = Display::NonDisplay;
        else if (n.display != Display::NonDisplay)
            diags_.warning(n.line, "displaytype '" + std::string(display_name(n.display)) + "' has no effect on container " +
                                       quote(n) + ": a container shows its name and its children");
        if (n.length_kind == LengthKind::Bits && n.fixed_bits % 8 != 0)
            diags_.error(n.line, "container " + quote(n) + " has length " + std::to_string(n.fixed_bits) +
                                     "bit: a container's length must be whole bytes");
        if (!n.enums.empty()) diags_.warning(n.line, "enum items on container " + quote(n) + " are ignored");
    } else {
        check_leaf_display(n);
        if (n.summary) diags_.warning(n.line, "summary on leaf " + quote(n) + " is ignored: it applies to containers");
    }
    if (n.repeat && n.count)
        diags_.error(n.line, "node " + quote(n) + " has both 'repeat' and 'count'; use one of them");
    if (n.filter && !n.filter->empty() && !is_valid_filter_segment(*n.filter))
        diags_.error(n.line, "bad filter '" + *n.filter + "': it must match [a-z][a-z0-9_]*");
    if (n.filter && n.filter->empty() && n.is_leaf())
        diags_.error(n.line, "filter=\"\" only applies to containers; leaf " + quote(n) + " needs a filter name");
    for (auto& c : n.children) inherit_and_check_node(*c, n.byteorder);
}

void Validator::check_leaf_display(Node& n) {
    if (n.is_computed()) return;  // check_computed
    if (n.display == Display::Varint) {
        check_varint(n);
        return;
    }
    if (n.length_kind == LengthKind::Children && n.display != Display::StringZ)
        diags_.warning(n.line, "leaf " + quote(n) + " has no length and no children: it takes no bytes");
    if (!n.display_given) n.display = Display::Origin;
    bool numeric = is_numeric_display(n.display);
    if (n.is_number_sized_by_field()) {
        n.bits = 64;
    } else if (numeric) {
        if (!n.has_fixed_length())
            diags_.error(n.line, std::string(display_name(n.display)) + " display needs a fixed length of 1-64 bits" +
                                     (n.display == Display::Time ? "" : " or a length from a field") + "; " +
                                     quote(n) + " has a variable length");
        else if (n.fixed_bits > 64)
            diags_.error(n.line, std::string(display_name(n.display)) + " display on more than 64 bits: " + quote(n) +
                                     " is " + std::to_string(n.fixed_bits) + " bits");
    }
    if (n.has_fixed_length() && n.fixed_bits <= 64) n.bits = static_cast<unsigned>(n.fixed_bits);
    if (n.display == Display::Enum) {
        for (const EnumItem& e : n.enums) {
            if (n.bits > 0 && n.bits < 64 && e.value >> n.bits)
                diags_.error(e.line, "enum value " + std::to_string(e.value) + " does not fit the " +
                                         std::to_string(n.bits) + "-bit field " + quote(n));
        }
        std::map<uint64_t, int> seen;
        for (const EnumItem& e : n.enums)
            if (!seen.emplace(e.value, e.line).second)
                diags_.warning(e.line, "enum value " + std::to_string(e.value) + " of " + quote(n) +
                                           " is listed twice; the first item is used");
    } else if (!n.enums.empty()) {
        diags_.warning(n.line, "enum items of " + quote(n) + " are ignored: its displaytype is not 'enum'");
    }
}

// A varint's bytes say where it ends: it has no length, holds up to 64 bits
// and names no enum items (shown in decimal).
void Validator::check_varint(Node& n) {
    if (n.length_kind != LengthKind::Children)
        diags_.error(n.line, "varint display takes no length: its bytes say where it ends (bit 7 set while "
                             "another byte follows); remove length= from " + quote(n));
    n.bits = 64;
    if (!n.enums.empty())
        diags_.warning(n.line, "enum items of " + quote(n) + " are ignored: a varint is shown in decimal");
}

namespace {

// "Nbyte" counts as 8N bits: a whole-byte leaf inside a group joins it, unless it
// shows bytes (origin, address), which a group cannot hold.
bool is_bit_leaf(const Node& n) {
    return n.is_leaf() && (n.length_kind == LengthKind::Bits ||
                           (n.length_kind == LengthKind::Bytes && !is_byte_display(n.display)));
}

bool lists_meet(const std::vector<ValueRange>& a, const std::vector<ValueRange>& b) {
    for (const ValueRange& x : a)
        for (const ValueRange& y : b)
            if (x.low <= y.high && y.low <= x.high) return true;
    return false;
}

// Whether n, right after the members that mean the latest bits of a bit group,
// is one more meaning of them: it is never decoded with any of them. That is so
// when n is an `otherwise` in the chain of alternatives of each (docs/manual.md,
// "Alternatives with a default"), or when n and each have an `if` on the same
// field with lists that share no value.
bool means_same_bits(const Node& n, const std::vector<const Node*>& alternatives) {
    if (!n.if_field && !n.otherwise) return false;
    for (size_t i = 0; i < alternatives.size(); ++i) {
        const Node& a = *alternatives[i];
        bool in_chain = n.otherwise && (a.if_field || a.otherwise);
        for (size_t j = i + 1; in_chain && j < alternatives.size(); ++j) in_chain = alternatives[j]->otherwise;
        bool disjoint = a.if_field && n.if_field && a.if_field->target && a.if_field->target == n.if_field->target &&
                        !lists_meet(a.in_list, n.in_list);
        if (!in_chain && !disjoint) return false;
    }
    return !alternatives.empty();
}

}  // namespace

// "bit group starting at X ends after N bits, not on a byte boundary" and,
// when a node ends the group, what it is.
void Validator::unaligned_group(const Node& first, unsigned bits, const std::string& next) {
    diags_.error(first.line, "bit group starting at " + quote(first) + " ends after " + std::to_string(bits) +
                                 " bits, not on a byte boundary" + (next.empty() ? "" : " (next is " + next + ")"));
}

// Groups consecutive bit fields into whole-byte integers (docs/manual.md,
// "Lengths, bit fields, repetition, conditions"); recurses into containers.
void Validator::layout_children(std::vector<std::unique_ptr<Node>>& children) {
    std::vector<Node*> group;
    std::vector<const Node*> alternatives;  // the members that mean the latest bits, in order
    unsigned group_bits = 0;
    for (auto& child : children) {
        Node& n = *child;
        bool bit_leaf = is_bit_leaf(n);
        bool whole_bytes = bit_leaf && n.fixed_bits % 8 == 0;
        if (group.empty() && (!bit_leaf || whole_bytes)) {
            if (n.is_container()) layout_children(n.children);
            continue;
        }
        if (bit_leaf && !whole_bytes && n.count && !n.repeat && !n.repeat_rest && !n.offsets) {
            // count="..." on a bit field: a packed list, which starts and ends on a byte
            // boundary of its own.
            if (!group.empty()) {
                unaligned_group(*group.front(), group_bits,
                                quote(n) + at_line(n) + ", a packed list of bit fields, which starts a byte");
                group.clear();
                group_bits = 0;
            }
            layout_packed_bits(n);
            continue;
        }
        if (!bit_leaf) {
            unaligned_group(*group.front(), group_bits, quote(n) + at_line(n));
            group.clear();
            group_bits = 0;
            if (n.is_container()) layout_children(n.children);
            continue;
        }
        if (n.is_repeated())
            diags_.error(n.line, "bit field " + quote(n) + " cannot have 'repeat': it shares bytes with its "
                                 "neighbours in a bit group (with 'count' alone, a packed list)");
        else if (n.has_hook)
            diags_.error(n.line, "bit field " + quote(n) + " cannot have 'ifhook': it shares bytes with its "
                                 "neighbours in a bit group");
        else if (n.direction != Direction::Any)
            diags_.error(n.line, "bit field " + quote(n) + " cannot have 'direction': it shares bytes with its "
                                 "neighbours in a bit group");
        // A bit field written without a displaytype shows its value in hex: the
        // nearest thing to origin's "raw bytes in hex" for a part of a byte.
        if (n.display == Display::Origin && !n.display_given) n.display = Display::NumberHex;
        if (is_byte_display(n.display))
            diags_.error(n.line, std::string(display_name(n.display)) + " display needs whole bytes; bit field " +
                                     quote(n) + " is part of a bit group (use numberhex, numberdec, bool, enum or int)");
        if (!group.empty() && n.byteorder != group.front()->byteorder)
            diags_.error(n.line, "bit field " + quote(n) + " has another byte order than its bit group starting at " +
                                     quote(*group.front()));
        if (!group.empty() && means_same_bits(n, alternatives)) {
            mean_same_bits(n, alternatives);  // the same bits again, with another meaning
        } else {
            alternatives.assign(1, &n);
            group_bits += static_cast<unsigned>(std::min<uint64_t>(n.fixed_bits, 1u << 20));
        }
        group.push_back(&n);
        // The group ends on a byte boundary, unless the next sibling means these bits too.
        const Node* next = &child != &children.back() ? (&child + 1)->get() : nullptr;
        if (group_bits % 8 == 0 &&
            !(next && is_bit_leaf(*next) && !next->count && means_same_bits(*next, alternatives))) {
            close_group(group, group_bits);
            group.clear();
            group_bits = 0;
        }
    }
    if (!group.empty()) unaligned_group(*group.front(), group_bits, "");
    join_groups_of_word(children);
}

// A container of 2 to 8 bytes made of bit fields alone is one word (a 16-bit
// flag word, IEC 104's 15-bit sequence number beside its format bit): its
// groups, closed at each byte boundary above, become one group of its length,
// so that each field's mask is on the word, as Wireshark's bitmasks are. A
// whole-byte number among them (a spare octet) joins the word too. The values
// are the same either way; only the masks and the fields' width change.
void Validator::join_groups_of_word(std::vector<std::unique_ptr<Node>>& children) {
    const Node* word = children.empty() ? nullptr : children.front()->parent;
    if (!word || !word->has_fixed_length() || word->fixed_bits < 16 || word->fixed_bits > 64 || word->fixed_bits % 8)
        return;
    auto whole_byte_member = [](const Node& n) {
        return !n.in_bit_group && is_bit_leaf(n) && n.fixed_bits % 8 == 0 && !is_byte_display(n.display) &&
               !n.is_repeated() && !n.packed_bits && !n.has_hook && n.direction == Direction::Any;
    };
    unsigned bytes = 0;
    bool grouped = false;
    for (const auto& c : children) {
        if (c->byteorder != children.front()->byteorder) return;
        if (c->in_bit_group) {
            grouped = true;
            if (c->group_last) bytes += c->group_bytes;
        } else if (whole_byte_member(*c)) {
            bytes += static_cast<unsigned>(c->fixed_bits / 8);
        } else {
            return;
        }
    }
    if (!grouped || bytes * 8 != word->fixed_bits || children.front()->group_bytes == bytes) return;
    unsigned before = 0;  // bytes of the word before the current group
    for (auto& c : children) {
        Node& n = *c;
        if (!n.in_bit_group) {  // a whole-byte number: a group of its own first
            n.in_bit_group = n.group_last = true;
            n.group_bytes = static_cast<unsigned>(n.fixed_bits / 8);
            n.bits = static_cast<unsigned>(n.fixed_bits);
            n.shift = 0;
        }
        const unsigned own = n.group_bytes;
        const unsigned after = bytes - before - own;
        n.shift += 8 * (n.byteorder == ByteOrder::Little ? before : after);
        n.group_bytes = bytes;
        n.group_first = &c == &children.front();
        if (n.group_last) before += own;
        n.group_last = &c == &children.back();
    }
}

// A bit field with count="...": its values are packed into whole bytes, N per byte
// (docs/manual.md, "Bit fields"); one straddling two bytes would need a bit order
// across bytes that no protocol we know uses.
void Validator::layout_packed_bits(Node& n) {
    if (n.fixed_bits != 1 && n.fixed_bits != 2 && n.fixed_bits != 4)
        diags_.error(n.line, "bit field " + quote(n) + " with 'count' is " + std::to_string(n.fixed_bits) +
                                 " bits; a packed list of bit fields takes 1, 2 or 4 bits a value");
    if (n.display == Display::Origin && !n.display_given) n.display = Display::NumberHex;
    if (is_byte_display(n.display))
        diags_.error(n.line, std::string(display_name(n.display)) + " display needs whole bytes; bit field " +
                                 quote(n) + " is a packed list (use numberhex, numberdec, bool, enum or int)");
    n.packed_bits = true;
}

// n means the bits of the members in `alternatives` (means_same_bits): it takes
// none of its own, and must have their width.
void Validator::mean_same_bits(Node& n, std::vector<const Node*>& alternatives) {
    const Node& first = *alternatives.front();
    if (n.fixed_bits != first.fixed_bits)
        diags_.error(n.line, "bit field " + quote(n) + " is another meaning of the bits of " + quote(first) +
                                 at_line(first) + ", which has " + std::to_string(first.fixed_bits) + " bits, not " +
                                 std::to_string(n.fixed_bits) + "; alternatives of the same bits have the same width");
    n.bit_alternative = true;
    alternatives.push_back(&n);
}

void Validator::close_group(std::vector<Node*>& group, unsigned bits) {
    if (bits > 64) {
        diags_.error(group.front()->line, "bit group starting at " + quote(*group.front()) + " is " +
                                              std::to_string(bits) + " bits; a bit group spans 1 to 8 bytes");
        return;
    }
    unsigned used = 0;
    const Node* meant = nullptr;  // the member whose bits an alternative means
    for (Node* n : group) {
        n->in_bit_group = true;
        n->group_bytes = bits / 8;
        if (n->bit_alternative && meant) {
            n->shift = meant->shift;
            continue;
        }
        n->shift = n->byteorder == ByteOrder::Little ? used : bits - used - n->bits;
        used += n->bits;
        meant = n;
    }
    group.front()->group_first = true;
    group.back()->group_last = true;
}

std::optional<uint64_t> Validator::fixed_bytes(const Node& n) const {
    if (n.is_overlay()) return 0;  // decodes bytes already decoded: the next sibling starts where it would
    if (n.is_repeated() || n.is_conditional()) return std::nullopt;
    if (n.is_computed()) return 0;
    if (n.has_fixed_length()) return n.fixed_bits / 8;
    if (n.length_kind != LengthKind::Children || n.is_leaf()) return std::nullopt;
    return children_fixed_bytes(n);
}

// The bytes n's children take when all of them have a fixed size (bit groups
// count by their whole bytes); nullopt when one of them is variable.
std::optional<uint64_t> Validator::children_fixed_bytes(const Node& n) const {
    uint64_t sum = 0;
    for (const auto& c : n.children) {
        if (c->in_bit_group) {
            if (c->group_first) sum += c->group_bytes;
            continue;
        }
        auto b = fixed_bytes(*c);
        if (!b) return std::nullopt;
        sum += *b;
    }
    return sum;
}

void Validator::check_fixed_container(const Node& n) {
    if (!n.has_fixed_length()) return;
    auto sum = children_fixed_bytes(n);
    if (!sum) return;  // variable children: checked at run time
    if (*sum != n.fixed_bits / 8)
        diags_.error(n.line, "children of " + quote(n) + " add up to " + std::to_string(*sum) + " bytes, but its length is " +
                                 std::to_string(n.fixed_bits / 8) + " bytes");
}

// length, count and if read an earlier numeric field of the same repeat
// instance; repeat reads a flag inside the repeated node.
void Validator::check_reference(Node& n, const FieldRef& ref, const std::string& what) {
    const Node* t = ref.target;
    if (!t) return;  // the parser already reported the XPath
    const std::string field = what + " field " + quote(*t) + at_line(*t);
    if (!t->is_numeric()) {
        diags_.error(n.line, field + " is not numeric: it must be a leaf of 1-64 bits shown as numberhex, "
                                     "numberdec, int, time, bool, enum, varint or nondisplay, or an integer computed value");
        return;
    }
    if (what == "repeat") {
        if (!is_ancestor_or_self(&n, t))
            diags_.error(n.line, "repeat flag " + quote(*t) + at_line(*t) + " is outside the repeated node " + quote(n) +
                                     "; it must be one of its fields");
        mark_slot(const_cast<Node*>(t));
        return;
    }
    if (t->doc_index >= n.doc_index) {
        diags_.error(n.line, field + " is not decoded before " + quote(n) + "; it must come earlier in the file");
        return;
    }
    if (const Node* r = repeat_outside(t, n)) {
        diags_.error(n.line, field + " is inside repeated node " + quote(*r) + at_line(*r) +
                                 ", which does not contain " + quote(n) +
                                 "; use a field of the same instance or one outside every repeat");
        return;
    }
    warn_if_alternative(*t, n, n.line, what + " field");
    mark_slot(const_cast<Node*>(t));
}

// Finds the byte offset of `t` (of its bit group, for a bit field) from the
// start of the message. `blocker` is set to the first node that keeps the
// offset from being fixed: a container of `t` (or `t`) that is repeated or
// has an `if` or `otherwise`, or a field before it without a fixed size.
// Read after the layout checks, so every node is placed once, in one walk.
void Validator::offset_of(const Node* t, uint64_t& offset, const Node*& blocker) const {
    if (places_.empty()) place(proto_.nodes, 0, nullptr);
    auto it = places_.find(t);
    if (it == places_.end()) return;
    offset += it->second.offset;
    if (!blocker) blocker = it->second.blocker;
}

void Validator::place(const std::vector<std::unique_ptr<Node>>& nodes, uint64_t offset, const Node* blocker) const {
    for (const auto& c : nodes) {
        const Node* inside = blocker;
        if (!inside && (c->is_repeated() || c->if_field || c->otherwise || c->is_overlay())) inside = c.get();
        places_[c.get()] = {offset, inside};
        place(c->children, offset, inside);
        if (c->in_bit_group) {
            if (c->group_last) offset += c->group_bytes;
            continue;
        }
        auto b = fixed_bytes(*c);
        if (b) offset += *b;
        else if (!blocker) blocker = c.get();
    }
}

// Why a node keeps the pdulength field from a fixed place in every message.
std::string pdulength_blocker(const Node& blocker, const Node& t) {
    const std::string where = quote(blocker) + at_line(blocker);
    const bool encloses = is_ancestor_or_self(&blocker, &t);
    const std::string self = &blocker == &t ? "it" : "it is inside " + where + ", which";
    if (blocker.is_repeated())
        return encloses ? self + " is repeated" : where + " before it is repeated";
    if (encloses && blocker.is_overlay()) return self + " is an overlay: its bytes are another node's";
    if (encloses && !blocker.if_field)
        return self + " is an 'otherwise' alternative: a message without it would have no length";
    if (encloses) return self + " has an 'if': a message without it would have no length";
    if (blocker.is_conditional()) return where + " before it is decoded only under a condition";
    return where + " before it has no fixed length";
}

void Validator::check_pdulength() {
    if (!proto_.pdulength || !proto_.pdulength->target) return;
    const Node* t = proto_.pdulength->target;
    if (!t->is_numeric()) {
        diags_.error(proto_.line, "pdulength field " + quote(*t) + at_line(*t) + " is not numeric");
        return;
    }
    if (t->is_computed()) {
        diags_.error(proto_.line, "pdulength field " + quote(*t) + at_line(*t) +
                                      " is a computed value: a message's length is read from its bytes before it is "
                                      "decoded; name the length field itself (pdulengthadd adds a constant)");
        return;
    }
    uint64_t offset = 0;
    const Node* blocker = nullptr;
    offset_of(t, offset, blocker);
    if (blocker) {
        diags_.error(proto_.line, "pdulength field " + quote(*t) + " must be at a fixed offset from the start of the "
                                                                     "message, in every message: " +
                                      pdulength_blocker(*blocker, *t));
        return;
    }
    // a varint has one byte at least; its others come with the message (dissgen_handoff.cpp)
    const unsigned field_bytes = t->display == Display::Varint ? 1 : t->in_bit_group ? t->group_bytes : t->bits / 8;
    proto_.pdu_fixed_len = static_cast<unsigned>(offset) + field_bytes;
    proto_.pdu_offset = static_cast<unsigned>(offset);
    mark_slot(const_cast<Node*>(t));
}

// Why a valid field is not decoded at one place in every message.
std::string valid_blocker(const Node& blocker, const Node& t) {
    const std::string where = quote(blocker) + at_line(blocker);
    const std::string self = &blocker == &t ? "it" : "it is inside " + where + ", which";
    if (!is_ancestor_or_self(&blocker, &t) || blocker.is_repeated() || blocker.is_overlay())
        return pdulength_blocker(blocker, t);
    if (blocker.is_window() || blocker.at) return self + " is placed by address in a window";
    if (blocker.length_kind == LengthKind::Field)
        return self + " takes its length from a field: a message may end it before";
    if (blocker.length_kind == LengthKind::Rest && blocker.rest_keep)
        return self + " is 'rest - " + std::to_string(blocker.rest_keep) +
               "': a message with fewer bytes left does not decode it";
    return self + " is decoded only under a condition ('if', <when>, direction or otherwise)";
}

// What keeps n from being at a fixed offset from the start of every message
// (n computed, so in no bytes; a field before it of no fixed length; n or a
// container of it repeated, conditional, placed in a window or cut short by
// a length field), or nullptr with `offset` set.
const Node* Validator::fixed_offset_blocker(const Node& n, uint64_t& offset) const {
    if (n.is_computed()) return &n;
    const Node* blocker = nullptr;
    offset_of(&n, offset, blocker);
    for (const Node* a = &n; a; a = a->parent) {
        const bool conditional = a->if_field || !a->whens.empty() || a->otherwise || a->direction != Direction::Any;
        // (a container of `rest - N` is not decoded at all with fewer than N bytes left)
        const bool cut = a != &n && (a->length_kind == LengthKind::Field ||
                                     (a->length_kind == LengthKind::Rest && a->rest_keep));
        const bool placed = a->is_window() || a->at || cut;
        if (!blocker && (conditional || placed)) blocker = a;
    }
    return blocker;
}

// valid="LIST": tested before anything is added to the tree, so each such
// field sits at a fixed offset and is decoded in every message; an 'ifhook'
// on it or a container only limits the messages it is tested in.
void Validator::check_validity() {
    bool unhooked = false;  // a valid field tested in every message, whatever the hook
    for_each_node(proto_.nodes, [&](Node& n) {
        if (!n.has_valid) return;
        if (n.is_computed()) {
            diags_.error(n.line, "'valid' on computed value " + quote(n) + ": the test reads bytes before anything "
                                 "is decoded; put 'valid' on the fields it is computed from");
            return;
        }
        if (!n.is_numeric()) {
            diags_.error(n.line, "'valid' field " + quote(n) + " is not numeric: it must be a leaf of 1-64 bits shown as "
                                 "numberhex, numberdec, int, time, bool, enum, varint or nondisplay");
            return;
        }
        if (n.display == Display::Varint) {
            diags_.error(n.line, "'valid' field " + quote(n) + " is a varint: the test reads fields of fixed length "
                                 "before anything is decoded");
            return;
        }
        uint64_t offset = 0;
        const Node* blocker = fixed_offset_blocker(n, offset);
        // (an overlay around it says more than a field of no fixed length before it)
        for (const Node* a = n.parent; blocker && a; a = a->parent)
            if (a->is_overlay()) blocker = a;
        bool hooked = false;
        for (const Node* a = &n; a; a = a->parent) hooked = hooked || a->has_hook;
        if (blocker) {
            diags_.error(n.line, "'valid' field " + quote(n) + " must be at a fixed offset from the start of the message, "
                                 "in every message: " + valid_blocker(*blocker, n));
            return;
        }
        n.valid_offset = offset;
        unhooked = unhooked || !hooked;
        FieldRef self;
        self.target = &n;
        check_list_fits(n.line, n.valid_list, self, "valid");
    });
    if (!proto_.heuristics.empty() && !unhooked)
        diags_.error(proto_.heuristics.front().line,
                     "<heuristic> needs a field with 'valid' (outside every 'ifhook' container): the values that "
                     "tell this protocol's messages from others");
}

// ifhook values are those of the root's ethertype and hooks (or a Decode As
// choice); a list that matches none of them is most likely a mistake.
void Validator::check_hook_list(const Node& n) {
    std::vector<uint64_t> values;
    if (proto_.ethertype) values.push_back(*proto_.ethertype);
    for (const Hook& h : proto_.hooks) values.push_back(h.value);
    for (uint64_t v : values)
        for (const ValueRange& r : n.hook_list)
            if (v >= r.low && v <= r.high) return;
    if (!n.hook_list.empty())
        diags_.warning(n.line, quote(n) + " has an 'ifhook' list that matches none of the root's ethertype and hook "
                               "values: it is decoded only through Decode As on such a value");
}

// An 'in' value the field cannot hold never matches: most likely the list
// was written for a wider field (in="0x100-0x1ff" on a byte).
void Validator::check_list_fits(int line, const std::vector<ValueRange>& list, const FieldRef& ref,
                                const char* attribute) {
    const Node* t = ref.target;
    // a computed value is a 64-bit integer, whatever its (zero) width in the message
    if (!t || !t->is_numeric() || t->value_bits() >= 64) return;
    const uint64_t max = (uint64_t{1} << t->fixed_bits) - 1;
    for (const ValueRange& r : list) {
        if (r.high <= max) continue;
        // echoed as written, the field's maximum in the same base: valid="0-300" is not "0x0-0x12c"
        const bool written_hex = r.text.find("0x") != std::string::npos || r.text.find("0X") != std::string::npos;
        const std::string values = !r.text.empty() ? r.text : r.low == r.high ? hex(r.low) : hex(r.low) + "-" + hex(r.high);
        const std::string highest = written_hex ? hex(max) : std::to_string(max);
        diags_.warning(line, "'" + std::string(attribute) + "' value " + values + " does not fit the " + std::to_string(t->fixed_bits) +
                                 "-bit field " + quote(*t) + at_line(*t) + ": " +
                                 (r.low > max ? "it never matches" : "values above " + highest + " never match"));
    }
}

// A summary template: literal text, {X} (the first node named X inside the
// container, in document order, that is a leaf or has a summary: its shown
// value or its summary) and {?...} (an optional part: left out when a
// placeholder inside it has nothing to show). Parsed into pieces; an optional
// part is a piece that owns the pieces after it.
void Validator::parse_summary(Node& n) {
    if (!n.is_container()) return;
    const std::string& s = *n.summary;
    std::vector<size_t> open_parts;  // pieces of the optional parts not closed yet
    size_t i = 0;
    while (i < s.size()) {
        size_t stop = s.find_first_of(open_parts.empty() ? "{" : "{}", i);
        if (stop == std::string::npos) {
            n.summary_pieces.push_back({s.substr(i), nullptr});
            break;
        }
        if (stop > i) n.summary_pieces.push_back({s.substr(i, stop - i), nullptr});
        if (s[stop] == '}') {  // closes the innermost optional part
            SummaryPiece& part = n.summary_pieces[open_parts.back()];
            part.group = n.summary_pieces.size() - open_parts.back() - 1;
            open_parts.pop_back();
            i = stop + 1;
            continue;
        }
        size_t close = s.find('}', stop);
        if (close == std::string::npos) {
            diags_.error(n.line, "summary of " + quote(n) + " has '{' without '}'");
            return;
        }
        std::string name = s.substr(stop + 1, close - stop - 1);
        // {?NAME} with no '{' inside is a reference to a leaf named "?NAME" as
        // before optional parts existed; with one it opens an optional part.
        if (name.size() > 1 && name[0] == '?' && name.find('{') != std::string::npos) {
            open_parts.push_back(n.summary_pieces.size());
            n.summary_pieces.push_back({"", nullptr});
            i = stop + 2;
            continue;
        }
        // The first node named so, in document order, that shows a value or
        // has a summary; a container without one only explains a failure.
        Node* found = nullptr;
        Node* container = nullptr;
        const Node* passed_over = nullptr;  // a later one, decoded only when the first is not
        for_each_node(n.children, [&](Node& d) {
            if (d.name != name) return;
            if (found && !passed_over && (d.is_leaf() || d.summary) && are_alternatives(proto_, *found, d))
                passed_over = &d;
            if (!found && (d.is_leaf() || d.summary)) found = &d;
            if (!container && d.is_container() && !d.summary) container = &d;
        });
        if (passed_over)
            diags_.warning(n.line, "summary of " + quote(n) + " shows {" + name + "} from " + quote(*found) +
                                       at_line(*found) + " only; " + quote(*passed_over) + at_line(*passed_over) +
                                       ", an alternative to it, never shows there: rename it and show it in an "
                                       "optional part of its own ({?...}), or give each alternative a summary");
        if (!found && container) {
            diags_.error(n.line, "summary of " + quote(n) + " refers to {" + name + "}, a container without a summary: "
                                     "give " + quote(*container) + " a summary or name a leaf");
            return;
        }
        if (!found && !name.empty() && name[0] == '?') {
            diags_.error(n.line, "summary of " + quote(n) + " has an optional part {" + name +
                                     "} with no {X} inside: it would never show anything");
            return;
        }
        if (!found) {
            diags_.error(n.line, "summary of " + quote(n) + " refers to {" + name + "}, but no leaf named '" + name +
                                     "' is inside it");
            return;
        }
        n.summary_pieces.push_back({"", found});
        mark_slot(found);
        i = close + 1;
    }
    if (!open_parts.empty()) {
        n.summary_pieces.clear();
        diags_.error(n.line, "summary of " + quote(n) + " has an optional part '{?' without its closing '}'");
    }
}

void Validator::assign_filter_names(std::vector<std::unique_ptr<Node>>& nodes, const std::string& prefix) {
    for (auto& child : nodes) {
        Node& n = *child;
        if (n.filter) {
            n.segment = *n.filter;
        } else {
            n.segment = segment_from_name(name_without_index(n.name));
            if (n.segment.empty()) {
                n.segment = "f" + std::to_string(n.doc_index);
                diags_.warning(n.line, "name " + quote(n) + " gives no filter name; using '" + n.segment +
                                           "': add filter=\"...\" for a readable one");
            }
        }
        std::string own = n.segment.empty() ? "" : prefix + "." + n.segment;
        n.filter_name = own;
        if (!own.empty()) {
            check_runtime_name(n);
            auto [it, inserted] = filter_owner_.emplace(own, &n);
            if (!inserted) share_filter_name(n, *it->second);
        }
        assign_filter_names(n.children, own.empty() ? prefix : own);
    }
}

// Computed hex values as wide as their mask (check_computed) that share one
// field with values of another width are 64 bits, as every other computed
// value: two masks, or a mask beside an 8-byte field, then agree. Whether one
// was widened.
bool Validator::widen_masked_values(Node& n, const Node& owner, const std::vector<const Node*>& holders) {
    bool widened = false;
    auto widen = [&](const Node& c) {
        // (an enum with ranges stays as masked: Wireshark has no 64-bit range_string)
        const bool widens = c.display == Display::NumberHex || (c.display == Display::Enum && !c.has_enum_ranges());
        if (!c.is_computed() || !widens || c.bits == 64) return;
        const_cast<Node&>(c).bits = 64;  // the validator owns the model it checks
        widened = true;
    };
    widen(n);
    widen(owner);
    for (const Node* h : holders) widen(*h);
    return widened;
}

// A filter name already taken by `owner`: one field for both when they are
// alternatives (at most one is decoded) of the same Wireshark type, as
// Wireshark's pn_dcp.option is filled by every option's layout; otherwise an error.
void Validator::share_filter_name(Node& n, const Node& owner) {
    const std::string& name = n.filter_name;
    std::vector<const Node*>& holders = filter_sharers_[name];
    if (holders.empty()) holders.push_back(&owner);
    for (const Node* other : holders)
        if (!are_alternatives(proto_, *other, n)) {
            diags_.error(n.line, "duplicate filter name '" + name + "'" +
                                     (n.group_use.empty() ? "" : " of the copy " + n.group_use) + " (also used by " +
                                     quote(*other) + at_line(*other) + "); give one of them a 'filter' attribute");
            return;
        }
    std::string mismatch = shared_field_mismatch(owner, n);
    const Node* differs = &n;
    if (!mismatch.empty() && widen_masked_values(n, owner, holders)) {
        mismatch = shared_field_mismatch(owner, n);
        // a holder that is no masked value keeps its width, no longer the widened field's
        for (const Node* h : holders)
            if (mismatch.empty() && h != &owner && !(mismatch = shared_field_mismatch(owner, *h)).empty()) differs = h;
    }
    if (!mismatch.empty()) {
        diags_.error(n.line, "alternatives " + quote(owner) + at_line(owner) + " and " + quote(*differs) + at_line(*differs) +
                                 " share the filter name '" + name + "' but not its field type (" + mismatch +
                                 "); give one of them a 'filter' attribute");
        return;
    }
    n.shares_field = &owner;
    holders.push_back(&n);
    if (n.name != owner.name)
        diags_.warning(n.line, quote(n) + " shares the filter name '" + name + "' with " + quote(owner) +
                                   at_line(owner) + " and is shown with its name " + quote(owner));
}

// <pairing> key fields are numeric leaves, each named once.
void Validator::check_pairing() {
    if (!proto_.pairing) return;
    std::map<const Node*, int> seen;
    for (const PairingKey& key : proto_.pairing->keys) {
        const Node* t = key.field.target;
        if (!t) continue;  // the parser reported the XPath
        if (!t->is_numeric()) {
            diags_.error(key.line, "key field " + quote(*t) + at_line(*t) +
                                       " is not numeric: a key is a leaf of 1-64 bits shown as a number, bool, "
                                       "enum or nondisplay");
            continue;
        }
        auto [it, inserted] = seen.emplace(t, key.line);
        if (!inserted)
            diags_.error(key.line, "key field " + quote(*t) + " is already a key (line " + std::to_string(it->second) +
                                       ")");
    }
    check_analysis_inputs(proto_, diags_);
    if (proto_.pairing->request) check_request_role(*proto_.pairing->request, "request");
    if (proto_.pairing->unanswered) check_request_role(*proto_.pairing->unanswered, "unanswered");
}

// <request> and <unanswered>: one numeric value per message, read once the
// message is decoded (from its slot).
void Validator::check_request_role(const CycleField& f, const std::string& element) {
    Node* t = f.field.target;
    if (!t) return;  // the parser reported the XPath
    if (!t->is_numeric()) {
        diags_.error(f.line, element + " field " + quote(*t) + at_line(*t) + " is not numeric: <" + element +
                                 "> reads a leaf of 1-64 bits shown as a number, bool, enum or nondisplay, or an "
                                 "integer computed value");
        return;
    }
    check_list_fits(f.line, f.in_list, f.field);
    const std::string says = element == "request" ? "whether it is a request" : "whether it expects a response";
    for (const Node* r = t; r; r = r->parent)
        if (r->is_repeated()) {
            diags_.error(f.line, element + " field " + quote(*t) + at_line(*t) + " is inside repeated node " +
                                     quote(*r) + at_line(*r) + ": a message says once " + says +
                                     "; use a field outside every repeat");
            return;
        }
    mark_slot(t);
    // The message's role is known once the field is decoded; a request{...}
    // read before that takes it for what its direction says, and may read a
    // request that is not its own (a notification, a request of the same key).
    if (const Node* reader = reader_before(*t))
        diags_.warning(f.line, element + " field " + quote(*t) + at_line(*t) + " is decoded after " + quote(*reader) +
                                   at_line(*reader) + ", which reads request{...}: until it is decoded, a message is "
                                   "taken " + (element == "request" ? "for what its direction says" : "to expect a response") +
                                   ", so " + quote(*reader) + " may read a request that is not its own; move " +
                                   quote(*t) + " before " + quote(*reader));
}

// <cycles>: numeric fields, each read for one thing, the sequence count no
// wider than its field; with the EtherCAT analysis, which times frames by
// their returns, nothing it does not do.
void Validator::check_cycles() {
    if (!proto_.cycles) return;
    Cycles& c = *proto_.cycles;
    if (proto_.pairing && proto_.pairing->analysis == DG_ANALYSIS_ETHERCAT_ESC) check_cycles_of_ethercat(c);
    if (c.requests_only && !proto_.pairing)
        diags_.error(c.line, "requests=\"yes\" times the requests of a <pairing>, and this protocol has none: "
                             "add <pairing> with the key fields that tie a response to its request");
    if (c.lost_by_period && c.sequence)
        diags_.error(c.line, "lost=\"period\" and the <sequence> count (line " + std::to_string(c.sequence->line) +
                                 ") would both tell the messages lost: a stream with a count is judged by its count; "
                                 "keep one");
    if (c.max_lost && !c.sequence && !c.lost_by_period)
        diags_.error(c.line, "maxlost=\"" + std::to_string(c.max_lost) +
                                 "\" limits the messages counted lost, and nothing counts them here: add a "
                                 "<sequence field=\"XPATH\"/> or lost=\"period\", or remove it");
    if (c.lost_line && !c.sequence)
        diags_.error(c.lost_line, "lost=\"sequence\" needs a <sequence field=\"XPATH\"/> in <cycles> (or "
                                  "lost=\"period\": losses told by the period)");
    std::map<const Node*, int> seen;
    for (const CycleField& f : c.signature) check_cycle_field(f, "signature", 1, 0, seen);
    int test = 0;
    for (const CycleField& f : c.only) check_cycle_field(f, "only", 3, test++, seen);
    for (const CycleField& f : c.never) check_cycle_field(f, "never", 4, test++, seen);
    if (!c.sequence || !check_cycle_field(*c.sequence, "sequence", 2, 0, seen)) return;
    const Node& t = *c.sequence->field.target;  // decoded more than once in a message: the last value counts
    const unsigned width = t.value_bits();
    if (c.sequence_bits == 0)
        c.sequence_bits = width;
    else if (c.sequence_bits > width)
        diags_.error(c.sequence->line, "bits=\"" + std::to_string(c.sequence_bits) + "\" is wider than sequence field " +
                                           quote(t) + at_line(t) + " (" + std::to_string(width) + " bits)");
    if (c.sequence_wrap && width < 64 && c.sequence_wrap - 1 > (uint64_t{1} << width) - 1)
        diags_.error(c.sequence->line, "wrap=\"" + std::to_string(c.sequence_wrap) + "\" is more values than sequence field " +
                                           quote(t) + at_line(t) + " holds (" + std::to_string(width) + " bits)");
    // a step of more than half the count's range would make every advance look like a count going back
    const uint64_t top = c.sequence_wrap        ? c.sequence_wrap - 1
                         : c.sequence_bits < 64 ? (uint64_t{1} << c.sequence_bits) - 1
                                                : ~uint64_t{0};
    const std::string range = c.sequence_wrap ? "count wrapping at " + std::to_string(c.sequence_wrap)
                                              : std::to_string(c.sequence_bits) + "-bit sequence count";
    const uint64_t half = (top >> 1) + (top & 1);  // the largest advance taken as forward
    if (c.sequence_step > half)
        diags_.error(c.sequence->line, "step=\"" + std::to_string(c.sequence_step) +
                                           "\" is more than half the range of a " + range + " (" +
                                           std::to_string(half) + ")");
}

// The ethercat-esc analysis times each frame as sent, with its return and its
// working counters: EtherCAT frames carry no count, and come from the master.
void Validator::check_cycles_of_ethercat(const Cycles& c) {
    const std::string with = " does not apply with <pairing analysis=\"" DG_ANALYSIS_ETHERCAT_ESC
                             "\">, which times each frame as sent with its return: ";
    if (c.sequence)
        diags_.error(c.sequence->line, "<sequence>" + with + "EtherCAT frames carry no count (remove it)");
    if (c.lost_by_period || c.lost_line)
        diags_.error(c.line, std::string("lost=\"") + (c.lost_by_period ? "period" : "sequence") + "\"" + with +
                                 "a frame not returned is counted lost by the analysis (remove it)");
    if (c.by_sender)
        diags_.error(c.line, std::string("sender=\"") + (c.by_connection ? "connection" : "yes") + "\"" + with +
                                 "every frame is the master's (remove it)");
    if (c.requests_only)
        diags_.error(c.line, "requests=\"yes\"" + with + "only frames as sent are timed already (remove it)");
}

bool Validator::check_cycle_field(const CycleField& f, const char* element, int role, int test,
                                  std::map<const Node*, int>& seen) {
    Node* t = f.field.target;
    if (!t) return false;  // the parser reported the XPath
    const bool signature = role == 1;
    if (signature && !t->is_numeric() && !t->is_compared_by_bytes()) {
        diags_.error(f.line, "signature field " + quote(*t) + at_line(*t) +
                                 " cannot tell streams apart: a signature field is a number, an integer computed "
                                 "value, or a leaf of text, an address, a GUID or bytes (compared byte for byte)");
        return false;
    }
    if (!signature && !t->is_numeric()) {
        diags_.error(f.line, std::string(element) + " field " + quote(*t) + at_line(*t) +
                                 " is not numeric: <cycles> reads leaves of 1-64 bits shown as a number, bool, "
                                 "enum or nondisplay, or integer computed values");
        return false;
    }
    auto [it, inserted] = seen.emplace(t, f.line);
    if (!inserted) {
        diags_.error(f.line, "field " + quote(*t) + " is already read by <cycles> (line " + std::to_string(it->second) +
                                 "): each field has one part in it");
        return false;
    }
    check_list_fits(f.line, f.in_list, f.field);  // <only>/<never>: a value the field cannot hold never matches
    t->cycle_role = role;
    t->cycle_test = test;
    return true;
}

// A summary shows the last value of a leaf (or the last text of a summarised
// container) its container decoded, though a repeat between them began an
// instance without it since (a TLV list: each instance one member): such
// nodes keep a copy for each repeat a summary names them across, which that
// repeat's instances leave and the summarised container's own next instance
// clears.
void Validator::keep_values_across_repeats() {
    for_each_node(proto_.nodes, [&](Node& x) {
        for (const SummaryPiece& p : x.summary_pieces) {
            if (!p.leaf) continue;  // a container's copy is its summary text (dissgen_walk.cpp, container_decoded)
            const Node* r = repeat_between(x, *p.leaf);
            if (r && p.leaf->kept_slots.emplace(r, -1).second) const_cast<Node*>(r)->kept_after.push_back(p.leaf);
        }
    });
}

// Slots in document order; a leaf's kept copy right after the slots of the
// repeat it is kept across, so that every subtree's slots stay contiguous.
void Validator::assign_slots() {
    keep_values_across_repeats();
    int next = 0;
    std::function<void(std::vector<std::unique_ptr<Node>>&)> place = [&](std::vector<std::unique_ptr<Node>>& nodes) {
        for (auto& child : nodes) {
            Node& n = *child;
            if (needs_slot_.count(&n) || !n.kept_slots.empty()) n.slot = next++;
            place(n.children);
            for (Node* kept : n.kept_after) kept->kept_slots[&n] = next++;
        }
    };
    place(proto_.nodes);
    proto_.slot_count = next;
}

// --- computed values ---------------------------------------------------------

// The node named `name` last in document order among the first reach - 1, or nullptr.
const Node* Validator::find_before(int reach, const std::string& name) {
    auto it = nodes_by_name_.find(name);
    if (it == nodes_by_name_.end()) return nullptr;
    const std::vector<const Node*>& named = it->second;
    auto past = std::lower_bound(named.begin(), named.end(), reach,
                                 [](const Node* c, int r) { return c->doc_index < r; });
    return past == named.begin() ? nullptr : *(past - 1);
}

// The closest node named `name` before `reach` that `reader` sees one value
// of (a Tag outside a repeat, not the one inside a repeat decoded since; not
// one in an alternative to the reader, never decoded with it); when none, the
// closest of any kind, for the error or warning to name.
const Node* Validator::find_readable_before(int reach, const std::string& name, const Node& reader) {
    const Node* closest = find_before(reach, name);
    auto readable = [&](const Node* c) { return !repeat_outside(c, reader) && !are_alternatives(proto_, *c, reader); };
    if (!closest || readable(closest)) return closest;
    // A node passed over as an alternative stands for the reader's own copy of
    // the field: an earlier one must be inside the container holding both (a
    // header before the chain), not in another copy of a <group> or another
    // container that has the same chain.
    bool scoped = false;
    const Node* scope = nullptr;  // nullptr: the whole message
    const std::vector<const Node*>& named = nodes_by_name_.find(name)->second;
    for (auto it = std::find(named.rbegin(), named.rend(), closest); it != named.rend(); ++it) {
        if (!scoped && are_alternatives(proto_, **it, reader)) {
            scoped = true;
            scope = common_container(*it, reader);
        }
        if (readable(*it) && (!scope || is_ancestor_or_self(scope, *it))) return *it;
    }
    return closest;
}

// A reference whose field is in an alternative to its reader (an earlier
// member of the reader's chain, or a sibling whose condition excludes the
// reader's) reads a value that is never there.
void Validator::warn_if_alternative(const Node& field, const Node& reader, int line, const std::string& what) {
    if (!are_alternatives(proto_, field, reader)) return;
    diags_.warning(line, what + " is " + quote(field) + at_line(field) + ", an alternative to " + quote(reader) +
                             ": never decoded together with it, so its value is never there");
}

// The names of the nodes among the first reach - 1, each once, in document
// order (of two as close, a misspelt name is offered the first).
std::vector<std::string> Validator::names_before(int reach) const {
    std::vector<std::pair<int, std::string>> firsts;
    for (const auto& [name, named] : nodes_by_name_)
        if (named.front()->doc_index < reach) firsts.emplace_back(named.front()->doc_index, name);
    std::sort(firsts.begin(), firsts.end());
    std::vector<std::string> names;
    for (auto& f : firsts) names.push_back(std::move(f.second));
    return names;
}

void Validator::check_computed(Node& n) {
    const std::string what = "computed value " + quote(n);
    if (n.is_container()) diags_.error(n.line, what + " cannot have children: it is one value");
    if (n.length_kind != LengthKind::Children)
        diags_.error(n.line, what + " takes no bytes: drop its 'length'");
    if (n.is_repeated() || n.in_bit_group)
        diags_.error(n.line, what + " cannot repeat: put it inside the repeated node instead");
    if (n.dissector || n.reassembles())
        diags_.error(n.line, what + " has no bytes to hand to a dissector or to reassemble");
    if (!check_expr(n, *n.value)) return;
    if (!n.display_given) n.display = n.value->is_float ? Display::Float : Display::NumberDec;
    switch (n.display) {
    case Display::NumberDec: case Display::NumberHex: case Display::Int: case Display::Bool:
    case Display::Enum: case Display::Float: case Display::NonDisplay:
        break;
    case Display::Time: case Display::DateTime:
        // a count of the unit (since 1970 for a datetime): seconds and nanoseconds are one number here
        if (n.value->is_float)
            diags_.error(n.line, what + " is shown as " + display_name(n.display) + ", a count of " +
                                     (n.unit_given ? "'" + n.unit + "'" : "nanoseconds") +
                                     ", but its value has a fraction: compute a whole count, such as "
                                     "{Seconds} * 1000000000 + {Fraction} * 1000000000 / 16777216");
        if (n.display == Display::DateTime && n.unit_given && (n.unit == "s+ns" || n.unit == "filetime"))
            diags_.error(n.line, what + " is a datetime with unit '" + n.unit + "'" +
                                     (n.unit == "s+ns" ? ", two numbers" : ", a field's encoding") +
                                     "; a computed datetime is one count since 1970: unit 'ns' (the default), 'us', "
                                     "'ms' or 's'");
        break;
    default:
        diags_.error(n.line, what + " is shown as " + display_name(n.display) +
                                 "; a computed value is shown as numberdec, numberhex, int, bool, enum, float, time, "
                                 "datetime or nondisplay");
    }
    // A hex value or enum masked to 16 bits is a 16-bit field: 0x6000, not 0x0000000000006000.
    n.bits = n.display == Display::NumberHex || n.display == Display::Enum ? expr_value_bits(*n.value) : 64;
    const uint64_t mask = expr_mask(*n.value);
    if (n.display == Display::Enum && n.bits < 64)
        for (const EnumItem& e : n.enums)
            if ((e.is_range ? e.high : e.value) > mask)
                diags_.error(e.line, "enum value " + std::to_string(e.is_range ? e.high : e.value) +
                                         " is above the mask of computed value " + quote(n) + " (" + hex(mask) +
                                         ", its last '&'): it is never computed");
}

// Resolves the fields of an expression, checks that index has a repeat to
// count, and types it: an operand that is a decimal or a float field makes
// its operator work in double (comparisons and logic give 0 or 1).
bool Validator::check_expr(Node& n, Expr& e) {
    return check_expr(n, e, ExprSite{n.doc_index, n.line, " in the value of " + quote(n), false, true});
}

bool Validator::check_expr(Node& n, Expr& e, const ExprSite& at) {
    bool ok = true;
    for (Expr& a : e.args) ok = check_expr(n, a, at) && ok;
    if (!ok) return false;
    const std::string& in = at.in;
    switch (e.op) {
    case ExprOp::Int: return true;
    case ExprOp::Float: e.is_float = true; return true;
    case ExprOp::Index:
        if (at.at_reader || inside_repeat(n)) return true;
        diags_.error(at.line, "'index'" + in + ": it is not inside a repeated node, so there is no instance to count");
        return false;
    case ExprOp::Offset:
        if (at.at_computed) return true;
        diags_.error(at.line, "'offset'" + in +
                                  ": only a computed value has a place in the message; compute it there "
                                  "(<node name=\"Here\" value=\"offset\"/>) and read {Here}");
        return false;
    case ExprOp::RequestField: return check_request_field(n, e);
    case ExprOp::Learned: return check_learned(n, e, at);
    case ExprOp::Defined: return check_defined(n, e);
    case ExprOp::Field: {
        const Node* t = at.at_reader ? find_before(at.reach, e.name) : find_readable_before(at.reach, e.name, n);
        if (!t) {
            auto named = nodes_by_name_.find(e.name);
            if (named != nodes_by_name_.end()) {
                const Node* later = named->second.front();
                diags_.error(at.line, "{" + e.name + "}" + in + " is " + quote(*later) + at_line(*later) +
                                         ", which comes after it; a value reads fields decoded before it");
                return false;
            }
            // copies of a <group> share the line, and the message once told
            auto [near_it, first] = name_suggestions_.try_emplace({at.line, e.name});
            if (first) near_it->second = closest_match(e.name, names_before(at.reach));
            const std::string& near = near_it->second;
            diags_.error(at.line, "{" + e.name + "}" + in + ": no node of that name comes before it" +
                                     (near.empty() ? "" : " (did you mean {" + near + "}?)"));
            return false;
        }
        if (!t->is_numeric() && !(t->is_computed() && t->display == Display::Float)) {
            diags_.error(at.line, "{" + e.name + "}" + in + " is " + quote(*t) + at_line(*t) +
                                     ", which is not numeric: it must be a leaf of 1-64 bits shown as a number, "
                                     "or a computed value");
            return false;
        }
        if (const Node* r = at.at_reader ? nullptr : repeat_outside(t, n)) {
            diags_.error(at.line, "{" + e.name + "}" + in + " is inside repeated node " + quote(*r) + at_line(*r) +
                                     ", which does not contain " + quote(n) +
                                     "; use a field of the same instance or one outside every repeat");
            return false;
        }
        if (!at.at_reader) warn_if_alternative(*t, n, at.line, "{" + e.name + "}" + in);
        e.target = const_cast<Node*>(t);
        e.is_float = t->display == Display::Float;
        mark_slot(e.target);
        return true;
    }
    case ExprOp::Conditional:  // a double when either value is; the condition may be either
        e.is_float = e.args[1].is_float || e.args[2].is_float;
        return true;
    default:
        break;
    }
    bool any_float = false;
    for (const Expr& a : e.args) any_float = any_float || a.is_float;
    if (any_float && expr_op_needs_integers(e.op)) {
        diags_.error(at.line, std::string("operator '") + expr_op_text(e.op) + "'" + in +
                                 " needs integers; an operand is a decimal or a float field");
        return false;
    }
    const bool gives_truth = e.op == ExprOp::Not || e.op == ExprOp::And || e.op == ExprOp::Or ||
                             (e.op >= ExprOp::Lt && e.op <= ExprOp::Ne);
    e.is_float = any_float && !gives_truth;
    return true;
}

namespace {

bool decoded_only_in(const Node& c, Direction d) {
    for (const Node* a = &c; a; a = a->parent)
        if (a->direction == d) return true;
    return false;
}

// "Read registers/Reference": a node's name preceded by those of its nearest
// containers, as many as segments given.
bool matches_path(const Node& c, const std::vector<std::string>& segments) {
    const Node* a = &c;
    for (auto s = segments.rbegin(); s != segments.rend(); ++s, a = a->parent)
        if (!a || a->name != *s) return false;
    return true;
}

std::vector<std::string> path_segments(const std::string& path) {
    std::vector<std::string> out;
    size_t start = 0;
    for (size_t slash; (slash = path.find('/', start)) != std::string::npos; start = slash + 1)
        out.push_back(path.substr(start, slash - start));
    out.push_back(path.substr(start));
    return out;
}

// The shortest path (name, then its containers') that tells c from the
// other candidates, for a message that lists them.
std::string telling_path(const Node& c, const std::vector<const Node*>& candidates) {
    std::vector<std::string> segments;
    for (const Node* a = &c; a; a = a->parent) {
        segments.insert(segments.begin(), a->name);
        int alike = 0;
        for (const Node* o : candidates) alike += matches_path(*o, segments);
        if (alike == 1) break;
    }
    std::string path;
    for (const std::string& s : segments) path += (path.empty() ? "" : "/") + s;
    return path;
}

}  // namespace

// The node request{TEXT} reads: TEXT is a node's name, or a path "A/B/Name"
// of names (Name inside B inside A) when no node has TEXT as its name. Of the
// nodes it fits that a request decodes, those decoded only in requests (it
// or a container of it has direction="request") if any: exactly one, since
// reading the first of several would silently pick a layout. NULL after an
// error; a node decoded only in responses when no other fits.
const Node* Validator::request_field_target(const Node& n, const std::string& text, const std::string& what) {
    auto [known, added] = request_targets_.try_emplace(text);
    if (added) known->second = resolve_request_field(text);
    const RequestTarget& r = known->second;
    if (!r.target) diags_.error(n.line, what + r.problem);
    return r.target;
}

// request_field_target's answer for TEXT, the same wherever it is read.
Validator::RequestTarget Validator::resolve_request_field(const std::string& text) const {
    static const std::vector<const Node*> none;
    auto nodes_named = [&](const std::string& name) -> const std::vector<const Node*>& {
        auto it = nodes_by_name_.find(name);
        return it == nodes_by_name_.end() ? none : it->second;
    };
    const bool whole_name = nodes_by_name_.count(text) > 0;
    const std::vector<std::string> segments = whole_name ? std::vector<std::string>{text} : path_segments(text);
    const std::vector<const Node*>& named = nodes_named(segments.back());
    std::vector<const Node*> fits, requests, responses;
    for (const Node* c : named) {
        if (!matches_path(*c, segments)) continue;
        (decoded_only_in(*c, Direction::Response) ? responses : fits).push_back(c);
        if (decoded_only_in(*c, Direction::Request)) requests.push_back(c);
    }
    if (!requests.empty()) fits = requests;
    if (fits.size() > 1) {
        std::string list;
        for (const Node* c : fits) list += std::string(list.empty() ? "" : ", ") + "'" + telling_path(*c, fits) + "'" + at_line(*c);
        return {nullptr, " is ambiguous: " + std::to_string(fits.size()) + " fields a request decodes fit it: " + list +
                             "; name one by its path, e.g. request{" + telling_path(*fits.front(), fits) + "}"};
    }
    if (!fits.empty()) return {fits.front(), ""};
    if (!responses.empty()) return {responses.front(), ""};
    // a path that is wrong above a right name: suggest the right path
    const std::string near = named.empty() ? closest_match(segments.back(), names_before(past_last_node_))
                                           : telling_path(*named[0], named);
    return {nullptr, std::string(segments.size() > 1 ? ": no node has that path" : ": no node has that name") +
                         (near.empty() ? "" : " (did you mean request{" + near + "}?)")};
}

// request{Name}: a field of the paired request (request_field_target).
// Numeric, inside one repeat at the most (read by position), and in a
// protocol whose messages are paired.
bool Validator::check_request_field(Node& n, Expr& e) {
    const std::string what = "request{" + e.name + "} in the value of " + quote(n);
    if (!proto_.pairing) {
        diags_.error(n.line, what + ": the protocol has no <pairing>, so no message has a request to read; add a "
                                    "<pairing> with the key fields a response repeats from its request");
        return false;
    }
    const Node* t = request_field_target(n, e.name, what);
    if (!t) return false;
    if (!t->is_numeric() && !t->is_computed()) {
        diags_.error(n.line, what + " is " + quote(*t) + at_line(*t) +
                                 ", which is not numeric: it must be a leaf of 1-64 bits shown as a number, "
                                 "or a computed value");
        return false;
    }
    // In a repeated node: the request keeps the value of each instance, and
    // the reader takes the one of its own instance (its innermost repeat's
    // index): the reply to a request's third item reads the third item.
    const Node* repeat = nullptr;
    for (const Node* r = t; r; r = r->parent) {
        if (!r->is_repeated()) continue;
        if (repeat) {
            diags_.error(n.line, what + " is inside repeated nodes " + quote(*repeat) + at_line(*repeat) + " and " +
                                     quote(*r) + at_line(*r) +
                                     ": a request keeps the values of one repeat level; use a field inside one "
                                     "repeated node at the most");
            return false;
        }
        repeat = r;
    }
    if (repeat) {
        bool reader_repeated = false;
        for (const Node* r = &n; r && !reader_repeated; r = r->parent) reader_repeated = r->is_repeated();
        if (!reader_repeated) {
            diags_.error(n.line, what + " is inside repeated node " + quote(*repeat) + at_line(*repeat) +
                                     ": a request keeps its value per instance, read by position, and " + quote(n) +
                                     " is not inside a repeated node whose instance number would choose one; use "
                                     "a field outside every repeat, or read it from inside a repeat");
            return false;
        }
    }
    if (decoded_only_in(*t, Direction::Response)) {
        diags_.error(n.line, what + " is " + quote(*t) + at_line(*t) +
                                 ", which is decoded only in responses (direction=\"response\"): a request never "
                                 "has it");
        return false;
    }
    e.target = const_cast<Node*>(t);
    e.is_float = t->display == Display::Float;
    auto& readers = proto_.request_readers;
    auto at = std::lower_bound(readers.begin(), readers.end(), &n,
                               [](const Node* a, const Node* b) { return a->doc_index < b->doc_index; });
    if (at == readers.end() || *at != &n) readers.insert(at, &n);
    auto& kept = proto_.request_fields;
    auto it = std::find(kept.begin(), kept.end(), t);
    e.request_index = static_cast<int>(it - kept.begin());
    if (it == kept.end()) kept.push_back(t);
    mark_slot(e.target);
    if (repeat) e.target->keeps_instances = true;
    return true;
}

// defined(X) asks about one value that may be missing: a field ({Name}, not
// decoded under a condition) or a field of the request (request{Name}, the
// request not captured). A number or index is always defined, and an
// expression is undefined exactly when a field in it is: ask about that.
bool Validator::check_defined(const Node& n, Expr& e) {
    const Expr& x = e.args[0];
    if (x.op != ExprOp::Field && x.op != ExprOp::RequestField && x.op != ExprOp::Learned) {
        diags_.error(n.line, "defined(...) in the value of " + quote(n) +
                                 " asks about one field, {Name}, request{Name} or learned{Name}: " +
                                 (x.op == ExprOp::Int || x.op == ExprOp::Float || x.op == ExprOp::Index || x.op == ExprOp::Offset
                                      ? "a number, index or offset is always defined"
                                      : "an expression is undefined when a field it reads is (but for a value ?: "
                                        "does not choose); ask about that field"));
        return false;
    }
    e.is_float = false;
    return true;
}

// The first node before t in document order whose value reads request{...}
// and that a message may decode with t (not an alternative to it), or nullptr.
// Alternatives inside a repeated node (a list of TLVs) are still decoded in
// one message, by different instances.
const Node* Validator::reader_before(const Node& t) const {
    auto in_one_repeat = [](const Node& a, const Node& b) {
        for (const Node* x = a.parent; x; x = x->parent)
            if (x->is_repeated() && is_ancestor_or_self(x, &b)) return true;
        return false;
    };
    for (const Node* r : proto_.request_readers) {
        if (r->doc_index >= t.doc_index) break;
        if (in_one_repeat(t, *r) || !are_alternatives(proto_, t, *r)) return r;
    }
    return nullptr;
}

// With request{...}, a response looks its request up by its key values.
// When every key field is at a fixed offset from the start of every message,
// it reads them before it is decoded. Otherwise it takes the values the walk
// decoded when a value first reads the request: every key field must then
// come before the first node whose value reads request{...}.
void Validator::check_request_keys() {
    if (!proto_.pairing || proto_.request_fields.empty()) return;
    Pairing& pairing = *proto_.pairing;
    for (PairingKey& key : pairing.keys) {
        const Node* t = key.field.target;
        if (!t || !t->is_numeric()) continue;  // reported
        uint64_t offset = 0;
        // a varint is read by the walk, never from its bytes ahead of it
        if (fixed_offset_blocker(*t, offset) || t->display == Display::Varint) pairing.keys_decoded = true;
        key.offset = offset;
    }
    if (!pairing.keys_decoded) return;
    const Node* moving = nullptr;  // the first key field not at a fixed offset
    for (const PairingKey& key : pairing.keys) {
        uint64_t offset = 0;
        const Node* t = key.field.target;
        if (!moving && t && t->is_numeric() && (fixed_offset_blocker(*t, offset) || t->display == Display::Varint))
            moving = t;
    }
    for (const PairingKey& key : pairing.keys) {
        const Node* t = key.field.target;
        const Node* reader = t && t->is_numeric() ? reader_before(*t) : nullptr;
        if (!reader) continue;
        diags_.error(key.line, "key field " + quote(*t) + at_line(*t) + " is decoded after " + quote(*reader) +
                                   at_line(*reader) + ", which reads request{...}: key field " + quote(*moving) +
                                   " is not at a fixed offset, so a response looks its request up with the key "
                                   "values decoded before its first request{...}; move every key field before " +
                                   quote(*reader));
    }
}

// --- display types, range enums, repeat="rest", direction, hand-off, reassembly ---

// unit="...": a time's unit (ns, us, ms, s), a datetime's encoding (s+ns or a
// count of ns, us, ms or s since 1970), or the label a number is shown with
// ("°C", "rpm"): numbers in decimal (numberdec, int) or float.
void Validator::check_unit(const Node& n) {
    if (n.display == Display::Time) {
        if (n.unit != "ns" && n.unit != "us" && n.unit != "ms" && n.unit != "s")
            diags_.error(n.line, "bad unit '" + n.unit + "': expected 'ns', 'us', 'ms' or 's'");
        return;
    }
    if (n.display == Display::DateTime) {
        if (n.unit != "s+ns" && n.unit != "ns" && n.unit != "us" && n.unit != "ms" && n.unit != "s" &&
            n.unit != "filetime")
            diags_.error(n.line, "bad unit '" + n.unit + "' for a datetime: expected 's+ns' (seconds and nanoseconds, "
                                 "the default), a count since 1970 of 'ns', 'us', 'ms' or 's', or 'filetime' (100 ns "
                                 "since 1601, Windows FILETIME and OPC UA's DateTime)");
        return;
    }
    if (n.is_container() || (n.display != Display::NumberDec && n.display != Display::Int && n.display != Display::Float)) {
        diags_.error(n.line, "'unit' applies to time and datetime leaves and to numbers shown as numberdec, int or float; " +
                                 quote(n) + " is shown as " + display_name(n.display));
        return;
    }
    bool printable = !n.unit.empty() && n.unit.size() <= 32;
    for (unsigned char c : n.unit) printable = printable && c >= 0x20 && c != 0x7f;
    if (!printable)
        diags_.error(n.line, "bad unit '" + n.unit + "': a unit label is 1 to 32 printable characters, such as \"rpm\"");
}

void Validator::check_display_direction_handoff(Node& n) {
    if (n.repeat_rest && n.count)
        diags_.error(n.line, "node " + quote(n) + " has both repeat=\"rest\" and 'count'; use one of them");
    if (n.encoding_given && n.display != Display::String && n.display != Display::StringZ)
        diags_.error(n.line, "'encoding' applies to string and stringz leaves; " + quote(n) + " is shown as " +
                                 display_name(n.display));
    if (n.direction != Direction::Any) {
        bool port_hook = false;
        for (const Hook& h : proto_.hooks)
            if (h.table.size() > 5 && h.table.compare(h.table.size() - 5, 5, ".port") == 0) port_hook = true;
        if (!port_hook)
            diags_.warning(n.line, quote(n) + " has a 'direction', but <root> has no <hook> on a port table "
                                   "(such as udp.port): it is decoded only through Decode As on a port");
    }
    if (n.is_leaf()) {
        check_string_display(n);
        if (!n.enums.empty() && n.display == Display::Enum) check_enum_ranges(n);
    }
    if (n.dissector) check_handoff(n);
    if (n.reassembles()) check_reassembly(n);
}

void Validator::check_string_display(Node& n) {
    if (n.is_computed()) return;  // check_computed
    const std::string shown = display_name(n.display);
    switch (n.display) {
        case Display::String:
            if (n.length_kind == LengthKind::Children)
                diags_.error(n.line, "string display needs a length (Nbyte, a length field or 'rest'); " + quote(n) +
                                         " has none (use stringz for text that ends with a NUL)");
            [[fallthrough]];
        case Display::StringZ:
            if (n.length_kind == LengthKind::Bits && n.fixed_bits % 8 != 0 && !n.in_bit_group && !n.packed_bits)
                diags_.error(n.line, shown + " display needs whole bytes; " + quote(n) + " is " +
                                         std::to_string(n.fixed_bits) + " bits");
            break;
        case Display::IPv4: case Display::Guid: case Display::IPv6: case Display::Mac: case Display::Eui64: {
            const unsigned bytes = fixed_display_bytes(n.display);
            if (!n.has_fixed_length() || n.fixed_bits != bytes * 8)
                diags_.error(n.line, shown + " display needs a length of " + std::to_string(bytes) + "byte; " +
                                         quote(n) + " has another length");
            break;
        }
        case Display::Float:
            if (!n.has_fixed_length() || (n.fixed_bits != 32 && n.fixed_bits != 64))
                diags_.error(n.line, "float display needs a length of 4byte or 8byte (IEEE 754 single or double); " +
                                         quote(n) + " has another length");
            break;
        case Display::Time:
            if (n.has_fixed_length() && n.fixed_bits <= 64 && n.fixed_bits % 8 != 0 && !n.in_bit_group && !n.packed_bits)
                diags_.error(n.line, "time display needs 1 to 8 whole bytes; " + quote(n) + " is " +
                                         std::to_string(n.fixed_bits) + " bits");
            break;
        case Display::DateTime: check_datetime_length(n); break;
        case Display::Oid:
            if (n.length_kind == LengthKind::Children)
                diags_.error(n.line, "oid display needs a length (Nbyte, a length field or 'rest'); " + quote(n) +
                                         " has none");
            break;
        default: break;
    }
}

// The lengths Wireshark reads an absolute time of each encoding from: 8
// bytes, or 4 for seconds (a 32-bit count, as time_t was).
void Validator::check_datetime_length(const Node& n) {
    const std::string unit = n.datetime_unit();
    const bool seconds = unit == "s";
    if (unit != "s+ns" && unit != "ns" && unit != "us" && unit != "ms" && unit != "filetime" && !seconds)
        return;  // check_unit
    if (n.has_fixed_length() && (n.fixed_bits == 64 || (seconds && n.fixed_bits == 32))) return;
    diags_.error(n.line, "datetime display with unit '" + unit + "' needs a length of " +
                             (seconds ? "4byte or 8byte" : "8byte") + "; " + quote(n) + " has another length");
}

// Range items become a range_string: at most 32 bits, no two items overlapping.
void Validator::check_enum_ranges(const Node& n) {
    if (!n.has_enum_ranges()) return;
    // A computed value is a 64-bit field unless masked (check_computed sets its
    // width later): Wireshark has no 64-bit range_string field (registered as
    // one, its names were read as a val64_string and crashed).
    const unsigned bits = n.is_computed() ? expr_value_bits(*n.value) : n.bits;
    if (n.is_computed() && bits > 32) {
        diags_.error(n.line, "enum ranges need a field of at most 32 bits; computed value " + quote(n) +
                                 " is 64 bits: mask it ({X} & 0xFF), list single values, or give the ranges to a "
                                 "field (an overlay over the bytes)");
        return;
    }
    if (bits > 32) {
        diags_.error(n.line, "enum ranges need a field of at most 32 bits; " + quote(n) + " is " +
                                 std::to_string(n.bits) + " bits");
        return;
    }
    for (size_t i = 0; i < n.enums.size(); ++i) {
        const EnumItem& e = n.enums[i];
        if (e.is_range && n.bits > 0 && n.bits < 64 && e.high >> n.bits)
            diags_.error(e.line, "enum range up to " + std::to_string(e.high) + " does not fit the " +
                                     std::to_string(n.bits) + "-bit field " + quote(n));
        for (size_t j = 0; j < i; ++j) {
            const EnumItem& f = n.enums[j];
            if (e.value <= f.high && f.value <= e.high) {
                diags_.error(e.line, "enum item '" + e.name + "' overlaps item '" + f.name + "' (line " +
                                         std::to_string(f.line) + ") of " + quote(n) +
                                         "; with ranges every value must have one name");
                break;
            }
        }
    }
}

// dissector= and reassemble-* work on a leaf of bytes with a length.
bool handoff_leaf_ok(const Node& n) {
    return n.is_leaf() && n.length_kind != LengthKind::Children && !n.in_bit_group &&
           (n.display == Display::Origin || n.display == Display::Address || n.display == Display::String ||
            n.display == Display::StringZ);
}

void Validator::check_handoff(const Node& n) {
    if (!handoff_leaf_ok(n))
        diags_.error(n.line, "dissector=\"" + *n.dissector + "\" needs a leaf of bytes with a length "
                             "(displaytype origin, address, string or stringz; Nbyte, a length field or 'rest'); " +
                             quote(n) + (n.is_container() ? " is a container" : " is not one"));
}

void Validator::check_reassembly(Node& n) {
    if (!handoff_leaf_ok(n)) {
        diags_.error(n.line, "reassembly needs a leaf of bytes with a length (displaytype origin, address, string "
                             "or stringz; Nbyte, a length field or 'rest'); " +
                                 quote(n) + (n.is_container() ? " is a container" : " is not one"));
        return;
    }
    if (!n.reassemble_id)
        diags_.error(n.line, "reassembly of " + quote(n) + " needs 'reassemble-id' (the field that tells "
                                                            "the reassembled messages apart)");
    if (!n.reassemble_offset == !n.reassemble_seq)
        diags_.error(n.line, "reassembly of " + quote(n) + " needs exactly one of 'reassemble-offset' (byte offset "
                                                            "of the fragment) and 'reassemble-seq' (fragment number)");
    if (!n.reassemble_last == !n.reassemble_more)
        diags_.error(n.line, "reassembly of " + quote(n) + " needs exactly one of 'reassemble-last' (non-zero on "
                                                            "the last fragment) and 'reassemble-more' (non-zero when "
                                                            "more follow)");
    struct { const char* what; std::optional<FieldRef>* ref; } refs[] = {
        {"reassemble-id", &n.reassemble_id},     {"reassemble-offset", &n.reassemble_offset},
        {"reassemble-seq", &n.reassemble_seq},   {"reassemble-last", &n.reassemble_last},
        {"reassemble-more", &n.reassemble_more},
    };
    for (auto& r : refs)
        if (*r.ref) check_reference(n, **r.ref, r.what);
}

// A field may not take a name the runtime registers for the protocol: two
// fields of one name and different types make Wireshark refuse filters on it.
void Validator::check_runtime_name(const Node& n) {
    auto clash = runtime_name_clash(runtime_names_, proto_.filter, n.filter_name);
    if (clash)
        diags_.error(n.line, "filter name '" + n.filter_name + "' is reserved for " +
                                 clash->description(proto_.filter) + "; give " + quote(n) +
                                 " or its container another 'filter'");
}

// --- <when>, otherwise, windows ------------------------------------------

std::string lines_of(const Node& n) { return quote(n) + at_line(n); }

const std::vector<std::unique_ptr<Node>>& siblings_of(const Protocol& proto, const Node& n) {
    return n.parent ? n.parent->children : proto.nodes;
}

const Node* previous_sibling(const Protocol& proto, const Node& n) {
    const Node* prev = nullptr;
    for (const auto& s : siblings_of(proto, n)) {
        if (s.get() == &n) return prev;
        prev = s.get();
    }
    return nullptr;
}

// A chain's default (otherwise="true" without conditions of its own) is the
// alternative of its chain's members only. When the chain opens right after a
// sibling whose condition excludes the opener's (A if Kind 0, B if Kind 1,
// Other otherwise), the default decodes beside that sibling too: most likely
// the author meant one chain, with otherwise="true" on the opener.
void Validator::warn_if_default_beside_a_rival(const Node& n) {
    auto is_default = [](const Node& m) { return m.otherwise && !m.has_own_condition(); };
    if (!is_default(n)) return;
    const Node* opener = previous_sibling(proto_, n);
    for (; opener && opener->otherwise; opener = previous_sibling(proto_, *opener))
        if (is_default(*opener)) return;  // (a second default is never decoded at all)
    if (!opener) return;
    const Node* rival = previous_sibling(proto_, *opener);
    // (a computed value beside a chain lays nothing out: no rival)
    if (!rival || rival->is_computed() || !conditions_exclude(*rival, *opener)) return;
    diags_.warning(n.line, "otherwise=\"true\" on " + quote(n) + " is the default of the chain that " +
                               lines_of(*opener) + " opens, so it is decoded also when " + lines_of(*rival) +
                               " is; to make " + quote(*rival) + " a member of that chain, give " + quote(*opener) +
                               " otherwise=\"true\"");
}

void Validator::check_layout(Node& n) {
    for (When& w : n.whens) {
        if (w.peek)
            check_peek(n, w);
        else
            check_reference(n, w.ref, "when");
    }
    bool bit_field = n.is_leaf() && (n.in_bit_group || (n.length_kind == LengthKind::Bits && n.fixed_bits % 8 != 0 &&
                                                         !n.packed_bits));
    if (bit_field && !n.whens.empty())
        diags_.error(n.line, "bit field " + quote(n) + " cannot have <when>: it shares bytes with its neighbours in a "
                             "bit group (an 'if' keeps its bits in the group)");
    else if (bit_field && n.otherwise && !n.bit_alternative)
        diags_.error(n.line, "bit field " + quote(n) + " has 'otherwise' but means no bits of a conditional bit field "
                             "before it: in a bit group, 'otherwise' follows bit fields with an 'if'");
    if (n.otherwise) {
        const Node* prev = previous_sibling(proto_, n);
        if (!prev)
            diags_.error(n.line, "otherwise=\"true\" on " + quote(n) + " needs a previous sibling with a condition "
                                 "(if, <when>, ifhook, direction) to be the alternative of; it is the first of its "
                                 "siblings");
        else if (!prev->is_conditional())
            diags_.error(n.line, "otherwise=\"true\" on " + quote(n) + " needs a previous sibling with a condition "
                                 "(if, <when>, ifhook, direction) or otherwise; " + lines_of(*prev) +
                                 " is always decoded");
        else if (!bit_field || n.bit_alternative)  // (a bit field's misplaced otherwise is an error above)
            warn_if_default_beside_a_rival(n);
    }
    if (n.skip_malformed) {
        if (n.is_leaf())
            diags_.error(n.line, "malformed=\"skip\" on leaf " + quote(n) + ": only a container can be skipped, "
                                 "with what is left of it after the malformed spot");
        else if (n.length_kind != LengthKind::Field && !n.has_fixed_length())
            diags_.error(n.line, "malformed=\"skip\" on " + quote(n) + " needs a fixed length or one from a field: "
                                 "decoding goes on where that length says the container ends");
    }
    if (n.base) {
        if (n.is_leaf())
            diags_.error(n.line, "'base' on leaf " + quote(n) + ": a window is a container whose children have 'at' addresses");
        else if (n.length_kind == LengthKind::Children)
            diags_.error(n.line, "window " + quote(n) + " needs a length (fixed, from a field or 'rest'): the bytes "
                                 "whose addresses start at 'base'");
        check_reference(n, *n.base, "base");
    }
    const Node* window = n.parent && n.parent->is_window() ? n.parent : nullptr;
    if (n.stride.has_value() != n.instances.has_value())
        diags_.error(n.line, n.stride ? "'stride' on " + quote(n) + " needs 'instances' (how many blocks)"
                                      : "'instances' on " + quote(n) + " needs 'stride' (the distance between blocks)");
    if (!window) {
        if (n.at)
            diags_.error(n.line, "'at' on " + quote(n) + ", which is not a child of a window (a container with 'base')");
        else if (n.stride || n.instances)
            diags_.error(n.line, "'stride' and 'instances' on " + quote(n) + " need an 'at' address in a window");
        return;
    }
    if (!n.at) {
        diags_.error(n.line, quote(n) + " is a child of window " + lines_of(*window) +
                                 " and needs an 'at' address");
        return;
    }
    if (n.is_repeated())
        diags_.error(n.line, "window child " + quote(n) + " cannot have 'repeat' or 'count'; use 'stride' and 'instances'");
    if (n.otherwise)
        diags_.error(n.line, "window child " + quote(n) + " cannot have 'otherwise': window children are placed by "
                             "address, not one after another");
    std::optional<uint64_t> size;
    if (n.has_fixed_length() && n.fixed_bits % 8 == 0) size = n.fixed_bits / 8;
    else if (n.length_kind == LengthKind::Children && n.is_container()) size = children_fixed_bytes(n);
    if (!size || *size == 0)
        diags_.error(n.line, "window child " + quote(n) + " needs a fixed length in whole bytes (its own 'Nbyte', or "
                             "children that all have one)");
    else
        n.place_bytes = *size;
}

// offsets="XPATH" from="XPATH". The offsets are the values of every
// instance of an earlier repeated numeric leaf; from is an earlier field or
// container (its first byte) or a container around n (the start of its
// content). Each instance runs to the next offset, the last to the end of its
// container, so n's own length is "rest".
void Validator::check_offsets(Node& n) {
    if (!n.offsets && !n.from) return;
    if (!n.offsets || !n.from) {
        diags_.error(n.line, n.offsets ? "'offsets' on " + quote(n) + " needs 'from': the field or container the "
                                         "offsets are counted from"
                                       : "'from' on " + quote(n) + " needs 'offsets': the repeated field whose "
                                         "values place the instances");
        return;
    }
    if (n.repeat || n.count || n.repeat_rest)
        diags_.error(n.line, "node " + quote(n) + " has 'offsets' and 'repeat' or 'count'; the offset table already "
                             "says how many instances there are: use one of them");
    if (n.length_kind != LengthKind::Rest || n.rest_keep)
        diags_.error(n.line, "node " + quote(n) + " with 'offsets' needs length=\"rest\": each instance runs to "
                             "where the next offset points, the last one to the end of its container");
    if (const Node* t = n.offsets->target) {
        const std::string field = "offsets field " + quote(*t) + at_line(*t);
        const Node* outside = repeat_outside(t->parent, n);  // a repeated container around t but not around n
        if (!t->is_numeric())
            diags_.error(n.line, field + " is not numeric: it must be a leaf of 1-64 bits shown as numberhex, "
                                         "numberdec, int, time, bool, enum, varint or nondisplay, or an integer computed value");
        else if (!t->count && !t->repeat && !t->repeat_rest)
            diags_.error(n.line, field + " is not repeated: it must have 'count' (or 'repeat'), one offset per "
                                         "instance of " + quote(n));
        else if (t->packed_bits)
            diags_.error(n.line, field + " is a packed list of bit fields: an offset table is a repeated field "
                                         "of whole bytes");
        else if (t->doc_index >= n.doc_index)
            diags_.error(n.line, field + " is not decoded before " + quote(n) + "; it must come earlier in the file");
        else if (outside)
            diags_.error(n.line, field + " is inside repeated node " + lines_of(*outside) + ", which does not contain " +
                                     quote(n) + "; use a table of the same instance or one outside every repeat");
        else {
            mark_slot(const_cast<Node*>(t));
            const_cast<Node*>(t)->keeps_values = true;
        }
    }
    if (const Node* f = n.from->target) {
        const std::string field = "from " + quote(*f) + at_line(*f);
        if (f == &n) {
            diags_.error(n.line, field + " is the node itself; use the container around it or an earlier field");
        } else if (is_ancestor_or_self(f, &n)) {
            n.from_up = 0;
            for (const Node* a = &n; a != f; a = a->parent) n.from_up++;
        } else if (!known_before(f, n)) {
            diags_.error(n.line, field + " is not decoded before " + quote(n) + " in the same instance; it must be an "
                                         "earlier field or container, or a container around " + quote(n));
        } else {
            mark_slot(const_cast<Node*>(f));
        }
    }
}

// A `rest` leaf takes the bytes up to the end of the closest container
// around it that has a length (or of the message): a node after a container
// without one, inside that end, then finds no bytes and is reported
// truncated in every message that reaches it. A group nested deeper than its
// depth stands in as such a leaf.
void Validator::check_rest_reach(const Node& n) {
    if (!n.is_leaf() || n.length_kind != LengthKind::Rest || n.rest_keep || n.is_repeated()) return;
    for (const Node* c = &n;; c = c->parent) {
        const auto& siblings = c->parent ? c->parent->children : proto_.nodes;
        if (c != &n) {
            auto at = std::find_if(siblings.begin(), siblings.end(), [&](const auto& s) { return s.get() == c; });
            for (auto s = at == siblings.end() ? at : at + 1; s != siblings.end(); ++s) {
                const Node& after = **s;
                if (after.is_computed() || after.takes_no_bytes() || after.is_overlay() ||
                    are_alternatives(proto_, *c, after))
                    continue;
                const bool stand_in = n.filter && n.filter->rfind("deeper", 0) == 0;
                diags_.warning(n.line, "leaf " + quote(n) + " takes the rest of the message (no container around it "
                                       "has a length), so " + quote(after) + at_line(after) + " finds no bytes after it" +
                                       (stand_in ? ": raise the group's depth to what the messages hold"
                                                 : ": give a container around it a length, or leave the bytes after "
                                                   "it with length=\"rest - N\""));
                return;
            }
        }
        const Node* p = c->parent;
        if (!p || p->length_kind != LengthKind::Children || p->is_repeated() || p->is_window() || p->is_overlay() ||
            p->at)
            return;
    }
}

// overlay="XPATH": a container decoding the bytes of an earlier leaf or
// container of the same instance (or outside every repeat), from its first
// byte. The walk does not move, so the overlay is not placed (window, offset
// table), repeated or computed.
void Validator::check_overlay(Node& n) {
    const std::string what = "'overlay' on " + quote(n);
    if (n.is_leaf()) {
        diags_.error(n.line, what + ": an overlay is a container whose children decode the bytes of another node; "
                                    "put the fields inside it");
        return;
    }
    const char* clash = n.base ? "base" : n.at ? "at" : n.stride ? "stride" : n.instances ? "instances"
                      : n.offsets ? "offsets" : n.from ? "from" : n.repeat ? "repeat" : n.count ? "count"
                      : n.repeat_rest ? "repeat" : n.value ? "value" : n.dissector ? "dissector" : nullptr;
    if (clash) {
        diags_.error(n.line, what + " cannot have '" + clash + "': an overlay is decoded once, over the bytes of "
                                    "its target, and does not move the position of the nodes after it");
        return;
    }
    const Node* t = n.overlay->target;
    if (!t) return;  // the parser already reported the XPath
    const std::string target = "overlay target " + lines_of(*t);
    if (t == &n) {
        diags_.error(n.line, target + " is the overlay itself; select an earlier leaf or container");
    } else if (is_ancestor_or_self(t, &n)) {
        diags_.error(n.line, target + " contains " + quote(n) + "; an overlay decodes the bytes of a node decoded "
                                      "before it, not of its own container");
    } else if (t->doc_index >= n.doc_index) {
        diags_.error(n.line, target + " is not decoded before " + quote(n) + "; it must come earlier in the file");
    } else if (t->is_computed()) {
        diags_.error(n.line, target + " is a computed value: it has no bytes to decode again");
    } else {
        if (const Node* r = repeat_outside(t, n)) {
            diags_.error(n.line, target + (r == t ? " is repeated" : " is inside repeated node " + lines_of(*r)) +
                                     ", which does not contain " + quote(n) +
                                     "; use a node of the same instance or one outside every repeat");
            return;
        }
        mark_slot(const_cast<Node*>(t));
    }
}

// covers="XPATH": the bytes of a node decoded before the computed value, in
// its instance or outside every repeat; the runtime reads where they are
// from the node's slot.
void Validator::check_covers(Node& n) {
    if (!n.is_computed()) {
        diags_.error(n.line, "'covers' on " + quote(n) + ": only a computed value (value=\"...\") is shown on the "
                                 "bytes of another node; a field has bytes of its own");
        return;
    }
    const Node* t = n.covers->target;
    if (!t) return;  // the parser already reported the XPath
    const std::string what = "'covers' of " + quote(n) + " selects " + quote(*t) + at_line(*t);
    if (t->doc_index >= n.doc_index || is_ancestor_or_self(t, &n)) {
        diags_.error(n.line, what + ", which is not decoded before it; select an earlier field");
        return;
    }
    if (t->is_computed()) {
        diags_.error(n.line, what + ", a computed value: it has no bytes to show the value on");
        return;
    }
    if (const Node* r = repeat_outside(t, n)) {
        diags_.error(n.line, what + ", inside repeated node " + quote(*r) + at_line(*r) + ", which does not contain " +
                                 quote(n) + "; select a node of the same instance or one outside every repeat");
        return;
    }
    mark_slot(const_cast<Node*>(t));
}

// Whether the value of t is known when n starts: decoded earlier, in the same
// repeat instance or outside every repeat.
bool Validator::known_before(const Node* t, const Node& n) const {
    return t && t->doc_index < n.doc_index && !repeat_outside(t, n);
}

// peek: the target is a later sibling of n or of an ancestor, and every node
// from n up to it has a length known when n starts.
void Validator::check_peek(Node& n, When& w) {
    const Node* t = w.ref.target;
    if (!t) return;
    const std::string field = "'peek' field " + lines_of(*t);
    if (!t->is_numeric()) {
        diags_.error(w.line, field + " is not numeric: it must be a leaf of 1-64 bits shown as numberhex, numberdec, "
                                     "bool, enum or nondisplay");
        return;
    }
    if (t->display == Display::Varint) {
        diags_.error(w.line, field + " is a varint: peek reads a field of fixed length before the walk reaches it");
        return;
    }
    if (t->doc_index <= n.doc_index) {
        diags_.error(w.line, field + " is not after " + quote(n) + "; peek looks ahead, use <when field=...> for an "
                                     "earlier field");
        return;
    }
    const std::string unknown = field + " position is not known before " + quote(n) + " starts: ";
    if (t->is_conditional() || t->is_repeated()) {
        diags_.error(w.line, unknown + "it is conditional or repeated");
        return;
    }
    uint64_t offset = 0;
    std::vector<const FieldRef*> lengths;
    // Why the offset is not known (first reason), until counting restarts at
    // a container that ends where its own length says.
    std::string why;
    // Adds the bytes of s (n itself when self) to the offset.
    auto add = [&](const Node& s, bool self) {
        std::string not_known;
        if (s.is_overlay()) return;  // the walk's position does not move
        if ((!self && s.is_conditional()) || s.is_repeated())
            not_known = lines_of(s) + " is " + (s.is_repeated() ? "repeated" : "conditional");
        else if (s.has_fixed_length())
            offset += s.fixed_bits / 8;
        else if (s.is_computed() || (s.is_leaf() && s.length_kind == LengthKind::Children &&
                                     s.display != Display::StringZ && s.display != Display::Varint))
            ;  // takes no bytes
        else if (s.length_kind == LengthKind::Field && known_before(s.length_ref.target, n))
            lengths.push_back(&s.length_ref);
        else if (auto sum = s.length_kind == LengthKind::Children && !s.is_leaf() ? children_fixed_bytes(s)
                                                                                    : std::nullopt)
            offset += *sum;
        else
            not_known = lines_of(s) + " has a length not known before then";
        if (why.empty()) why = not_known;
    };
    add(n, true);
    unsigned up = 0, anchor = 0;  // containers climbed; the one whose start the offset counts from
    for (const Node* level = &n;; level = level->parent) {
        if (level->parent && level->parent->is_window()) {
            diags_.error(w.line, unknown + lines_of(*level) + " is placed by address in a window");
            return;
        }
        const auto& siblings = siblings_of(proto_, *level);
        size_t k = 0;
        while (siblings[k].get() != level) ++k;
        bool chain = true;  // later members of level's chain are skipped when level is decoded
        for (++k; k < siblings.size(); ++k) {
            const Node& s = *siblings[k];
            if (chain && s.otherwise) continue;
            chain = false;
            if (&s == t) {
                if (!why.empty()) {
                    diags_.error(w.line, unknown + why);
                    return;
                }
                w.offset = offset;
                w.lengths = lengths;
                w.up = anchor;
                w.target_up = up;
                for (const FieldRef* r : lengths) mark_slot(r->target);
                return;
            }
            if (is_ancestor_or_self(&s, t)) {
                diags_.error(w.line, unknown + "it is inside " + lines_of(s) + "; it must be a later sibling of " +
                                         quote(n) + " or of one of its containers");
                return;
            }
            if (s.in_bit_group) {
                if (s.group_last) offset += s.group_bytes;
            } else {
                add(s, false);
            }
        }
        const Node* p = level->parent;
        if (!p) {
            diags_.error(w.line, unknown + "it is not a later sibling of " + quote(n) + " or of one of its containers");
            return;
        }
        ++up;
        if (p->is_repeated() || p->is_window() || p->is_overlay()) {
            diags_.error(w.line, unknown + "container " + lines_of(*p) +
                                     (p->is_repeated() ? " is repeated"
                                      : p->is_window() ? " is a window"
                                                       : " is an overlay of another node's bytes"));
            return;
        }
        if (p->length_kind == LengthKind::Children) continue;  // it ends where its children do
        // It ends `length` bytes after its own start: count from there.
        offset = 0;
        lengths.clear();
        why.clear();
        if (p->has_fixed_length()) {
            offset = p->fixed_bits / 8;
        } else if (p->length_kind == LengthKind::Field && known_before(p->length_ref.target, n)) {
            lengths.push_back(&p->length_ref);
        } else {
            diags_.error(w.line, unknown + "container " + lines_of(*p) + " has a length not known before then");
            return;
        }
        anchor = up;
    }
}

}  // namespace

std::string name_without_index(const std::string& name) {
    std::string out = name;
    for (size_t at; (at = out.find("{i}")) != std::string::npos;) out.erase(at, 3);
    return out;
}

std::string segment_from_name(const std::string& name) {
    std::string out;
    bool pending_sep = false;
    for (unsigned char c : name) {
        char lower = static_cast<char>(std::tolower(c < 0x80 ? c : 0));
        bool keep = c < 0x80 && (std::islower(static_cast<unsigned char>(lower)) || std::isdigit(c));
        if (!keep) {
            pending_sep = true;
            continue;
        }
        if (pending_sep && !out.empty()) out += '_';
        pending_sep = false;
        out += lower;
    }
    if (!out.empty() && std::isdigit(static_cast<unsigned char>(out[0]))) out = "f" + out;
    return out;
}

bool is_valid_filter_segment(const std::string& s) {
    if (s.empty() || !std::islower(static_cast<unsigned char>(s[0]))) return false;
    for (unsigned char c : s)
        if (!(std::islower(c) || std::isdigit(c) || c == '_') || c >= 0x80) return false;
    return true;
}

bool validate(Protocol& proto, Diagnostics& diags) {
    Validator(proto, diags).run();
    return !diags.has_errors();
}

// --- findings from the rules -------------------------------------------------

namespace {

// What is checked once n is decoded (a finding, a learn) reads n, what is
// inside it and what comes before it: the doc_index reach past its last node.
int reach_after(const Node& n) {
    int reach = n.doc_index + 1;
    for_each_node(n.children, [&](Node& c) { reach = std::max(reach, c.doc_index + 1); });
    return reach;
}

}  // namespace

// A finding is checked once its node is decoded: its condition and text read
// the node itself, what is inside it and what comes before it.
void Validator::check_findings(Node& n) {
    const int reach = reach_after(n);
    for (Finding& f : n.findings) {
        const std::string what = "finding '" + f.name + "'";
        if (severity_constant(f.severity).empty()) {
            const std::string near = closest_match(f.severity, severity_names());
            diags_.error(f.line, "unknown severity '" + f.severity + "' of " + what + "; use chat, note, warning or error" +
                                     (near.empty() ? "" : " (did you mean '" + near + "'?)"));
        }
        if (group_constant(f.group).empty()) {
            std::string all;
            for (const std::string& g : group_names()) all += (all.empty() ? "" : ", ") + g;
            const std::string near = closest_match(f.group, group_names());
            diags_.error(f.line, "unknown group '" + f.group + "' of " + what + "; use one of " + all +
                                     (near.empty() ? "" : " (did you mean '" + near + "'?)"));
        }
        const ExprSite at{reach, f.line, " in the condition of " + what};
        if (check_expr(n, f.condition, at) && f.condition.is_float)
            diags_.error(f.line, "the condition of " + what + " is a real number; compare it (" + f.condition_text +
                                     " != 0) to say when the finding holds");
        parse_finding_text(n, f, ExprSite{reach, f.line, " in the text of " + what});
    }
}

// The text: literal pieces and {Name}, the shown value of the field Name as
// a value reads it (the last one of that name the finding can see).
void Validator::parse_finding_text(Node& n, Finding& f, const ExprSite& at) {
    const std::string& s = f.text;
    for (size_t i = 0; i < s.size();) {
        size_t open = s.find('{', i);
        if (open == std::string::npos) {
            f.text_pieces.push_back({s.substr(i), nullptr});
            return;
        }
        if (open > i) f.text_pieces.push_back({s.substr(i, open - i), nullptr});
        size_t close = s.find('}', open);
        if (close == std::string::npos) {
            diags_.error(at.line, "'{' without '}'" + at.in);
            return;
        }
        const std::string name = s.substr(open + 1, close - open - 1);
        for (const char* source : {"request", "learned"}) {
            const std::string prefix = source;
            if (open < prefix.size() || s.compare(open - prefix.size(), prefix.size(), prefix) != 0) continue;
            diags_.error(at.line, prefix + "{" + name + "}" + at.in + ": the text shows fields of the message; put " +
                                      prefix + "{" + name + "} in a computed value (value=\"" + prefix + "{" + name +
                                      "}\", nondisplay if it need not be shown) and name that");
            return;
        }
        const Node* t = find_readable_before(at.reach, name, n);
        if (!t || t->is_container()) {
            diags_.error(at.line, "{" + name + "}" + at.in + ": no field of that name is decoded before it");
            return;
        }
        if (const Node* r = repeat_outside(t, n)) {
            diags_.error(at.line, "{" + name + "}" + at.in + " is inside repeated node " + quote(*r) + at_line(*r) +
                                      ", which does not contain " + quote(n));
            return;
        }
        f.text_pieces.push_back({"", const_cast<Node*>(t)});
        mark_slot(const_cast<Node*>(t));
        i = close + 1;
    }
}

// Where the first of two same names is: another line, or this one again
// when a <group> holding it is used more than once.
namespace {

std::string also_at(int first, int line) {
    if (first != line) return " (also line " + std::to_string(first) + ")";
    return " on this line again: when a <group> holding it is used more than once, each use copies the name "
           "(give it its name outside the group)";
}

}  // namespace

// Filter names P.finding.NAME: a lowercase segment, each once, and no field's.
void Validator::name_findings() {
    std::map<std::string, int> seen;
    for_each_node(proto_.nodes, [&](Node& n) {
        for (Finding& f : n.findings) {
            if (f.name.empty() || !std::islower(static_cast<unsigned char>(f.name[0])) ||
                f.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos) {
                diags_.error(f.line, "bad finding name '" + f.name + "': it is a filter-name segment, [a-z][a-z0-9_]*");
                continue;
            }
            f.filter_name = proto_.filter + ".finding." + f.name;
            auto [it, inserted] = seen.emplace(f.name, f.line);
            if (!inserted && it->second == f.line) continue;  // a <group> used again: one expert info, raised by each use
            if (!inserted)
                diags_.error(f.line, "duplicate finding name '" + f.name + "'" + also_at(it->second, f.line));
            else if (auto owner = filter_owner_.find(f.filter_name); owner != filter_owner_.end())
                diags_.error(f.line, "finding '" + f.name + "' is filtered as '" + f.filter_name + "', the name of " +
                                         quote(*owner->second) + at_line(*owner->second) + "; rename one of them");
        }
    });
}

// --- values learned from earlier messages ------------------------------------

// The most keys a <learn> has (the runtime's DG_MAX_LEARN_KEYS).
constexpr size_t kMaxLearnKeys = 16;

// Every <learn>, numbered in document order, before any expression reads
// learned{Name} (a reader may come before its <learn>: it reads earlier
// messages). Names are what learned{...} says between its braces: each once.
void Validator::collect_learns() {
    std::map<std::string, int> seen;
    for_each_node(proto_.nodes, [&](Node& n) {
        for (Learn& l : n.learns) {
            if (l.name.empty() || l.name.find_first_of("{}") != std::string::npos) {
                diags_.error(l.line, "bad learn name '" + l.name + "': learned{Name} reads it, so it is not empty and "
                                     "has no brace");
                continue;
            }
            auto [it, inserted] = seen.emplace(l.name, l.line);
            if (!inserted) {
                diags_.error(l.line, "duplicate learn name '" + l.name + "'" + also_at(it->second, l.line));
                continue;
            }
            l.index = static_cast<int>(proto_.learns.size());
            proto_.learns.push_back(&l);
        }
    });
}

// An expression that must give an integer (a learned value, a key, a
// condition): checked as any, then its type.
bool Validator::check_integer_expr(Node& n, Expr& e, const ExprSite& at, const std::string& what) {
    if (!check_expr(n, e, at)) return false;
    if (!e.is_float) return true;
    diags_.error(at.line, what + " is a real number; a learned value, its keys and its condition are integers");
    return false;
}

// A <learn> is evaluated once an instance of its node is decoded: its value,
// condition and keys read the node itself, what is inside it and what comes
// before it. A key's lookup is how a reader computes the key: it may read any
// field (a reader that has not decoded it finds nothing). Keys never read
// learned{...}: looking a value up would need another lookup first.
void Validator::check_learns(Node& n) {
    const int reach = reach_after(n);
    const int everywhere = std::max(reach, past_last_node_);
    auto reads_learned = [](const Expr& e) {
        std::function<bool(const Expr&)> any = [&](const Expr& x) {
            if (x.op == ExprOp::Learned) return true;
            for (const Expr& a : x.args)
                if (any(a)) return true;
            return false;
        };
        return any(e);
    };
    for (Learn& l : n.learns) {
        const std::string what = "learn '" + l.name + "'";
        if (l.keys.size() > kMaxLearnKeys)
            diags_.error(l.keys[kMaxLearnKeys].line, what + " has more than " + std::to_string(kMaxLearnKeys) +
                                                         " keys; combine some into one value");
        check_integer_expr(n, l.value, ExprSite{reach, l.line, " in the value of " + what}, "the value of " + what);
        if (l.condition)
            check_integer_expr(n, *l.condition, ExprSite{reach, l.line, " in the if of " + what}, "the if of " + what);
        auto check_key = [&](Expr& e, int line, const std::string& word, int key_reach, bool at_reader) {
            const std::string where = " in the " + word + " of " + what;
            if (reads_learned(e)) {
                diags_.error(line, "learned{...}" + where +
                                       ": a key is computed before anything learned is looked up, so it reads "
                                       "fields only");
                return;
            }
            check_integer_expr(n, e, ExprSite{key_reach, line, where, at_reader}, "the " + word + " of " + what);
        };
        const LearnKey* spanned = nullptr;
        for (LearnKey& k : l.keys) {
            check_key(k.value, k.line, "key", reach, false);
            if (k.lookup) check_key(*k.lookup, k.line, "lookup", everywhere, true);
            if (k.id && !k.span)
                diags_.error(k.line, what + ": an id names a window, and this key has no span: add span=\"...\" "
                                            "(how many keys from this one the window holds)");
            if (k.id) check_key(*k.id, k.line, "id", reach, false);
            if (!k.span) continue;
            check_key(*k.span, k.line, "span", reach, false);
            if (spanned)
                diags_.error(k.line, what + ": a second key with a span (the key on line " +
                                         std::to_string(spanned->line) +
                                         " has one): a reader's key finds one range, so one key may have a span");
            else
                spanned = &k;
        }
    }
}

// learned{Name}: the value the <learn> Name learned, under the keys this
// message gives, in an earlier message. Its reader is evaluated on every
// pass, a computed value too (its slot makes the walk compute it without a
// tree), so that each pass reads it alike.
bool Validator::check_learned(Node& n, Expr& e, const ExprSite& at) {
    const Learn* found = nullptr;
    std::vector<std::string> names;
    for (const Learn* l : proto_.learns) {
        if (l->name == e.name) found = l;
        names.push_back(l->name);
    }
    if (!found) {
        const std::string near = closest_match(e.name, names);
        diags_.error(at.line, "learned{" + e.name + "}" + at.in + ": no <learn> has that name" +
                                 (near.empty() ? "" : " (did you mean learned{" + near + "}?)"));
        return false;
    }
    e.learn_index = found->index;
    e.is_float = false;
    learned_reads_.push_back({&n, found, at.line, at.in, &e, at.reach});
    if (n.is_computed()) mark_slot(&n);
    return true;
}

// A lookup is computed where learned{...} reads it: a field of a repeated
// node it reads must be of the reader's own instance, decoded before it, and
// `index` counts the reader's instances, so the reader is inside a repeat.
void Validator::check_lookups_at_readers() {
    for (LearnedRead& read : learned_reads_) {
        resolve_lookups_at_reader(read);
        const Node& reader = *read.reader;
        const std::string head = "learned{" + read.learn->name + "}" + read.in + ": the lookup of its key on line ";
        std::function<void(const Expr&, int)> visit = [&](const Expr& e, int key_line) {
            for (const Expr& a : e.args) visit(a, key_line);
            if (e.op == ExprOp::Index && !inside_repeat(reader))
                diags_.error(read.line, head + std::to_string(key_line) + " reads 'index', and " + quote(reader) +
                                            " is not inside a repeated node, so there is no instance to count");
            if (e.op != ExprOp::Field || !e.target) return;
            const Node* t = e.target;
            const Node* r = t;
            while (r && !r->is_repeated()) r = r->parent;
            if (!r) {
                if (t->doc_index >= read.reach)
                    diags_.error(read.line, head + std::to_string(key_line) + " reads {" + e.name + "}" + at_line(*t) +
                                                ", and no node of that name is decoded before " + quote(reader) +
                                                ": a lookup reads what the reader's message decoded before it");
            } else if (!is_ancestor_or_self(r, &reader)) {
                diags_.error(read.line, head + std::to_string(key_line) + " reads {" + e.name + "}, inside " +
                                            "repeated node " + quote(*r) + at_line(*r) + ", which does not contain " +
                                            quote(reader) + "; use a field of the reader's instance or one "
                                            "outside every repeat");
            } else if (t->doc_index >= reader.doc_index) {
                diags_.error(read.line, head + std::to_string(key_line) + " reads {" + e.name + "}" + at_line(*t) +
                                            " of the reader's instance, decoded after " + quote(reader) +
                                            "; it must come earlier in the file");
            }
        };
        const LearnedReadKeys* own = read.expr->learn_index >= static_cast<int>(proto_.learns.size())
                                         ? proto_.learned_read_keys[read.expr->learn_index - proto_.learns.size()].get()
                                         : nullptr;
        for (size_t i = 0; i < read.learn->keys.size(); ++i) {
            const LearnKey& k = read.learn->keys[i];
            if (own && own->lookups[i]) visit(*own->lookups[i], k.line);
            else if (k.lookup) visit(*k.lookup, k.line);
        }
    }
}

// `{X}` in a key's lookup is the closest X before the reader (the <learn>
// resolved it where the learn is, the last X in the file): where that is
// another node, as in each copy of a <group>, the reader gets keys of its
// own. A name with no node before the reader keeps the learn's, for the
// checks above to explain.
void Validator::resolve_lookups_at_reader(LearnedRead& read) {
    auto row = std::make_unique<LearnedReadKeys>();
    row->learn = read.learn;
    row->line = read.line;
    bool differs = false;
    std::string signature = std::to_string(read.learn->index);  // the row's targets, to share equal rows
    std::function<void(Expr&, int)> retarget = [&](Expr& e, int key_line) {
        for (Expr& a : e.args) retarget(a, key_line);
        if (e.op != ExprOp::Field || !e.target) return;
        const Node* near = find_before(read.reach, e.name);
        if (near && near != e.target && !near->is_numeric()) {
            diags_.error(read.line, "learned{" + read.learn->name + "}" + read.in + ": the lookup of its key on line " +
                                        std::to_string(key_line) + " reads {" + e.name + "}, which before it is " +
                                        quote(*near) + at_line(*near) + ", not numeric: it must be a leaf shown as "
                                        "a number, or a computed value");
            e.target = nullptr;  // told once: the checks at readers skip it
            differs = true;
            return;
        }
        if (near && near != e.target) {
            e.target = const_cast<Node*>(near);
            mark_slot(e.target);
            differs = true;
        }
        signature += " " + std::to_string(e.target->doc_index);
    };
    for (const LearnKey& k : read.learn->keys) {
        row->lookups.emplace_back();
        signature += ";";
        if (!k.lookup) continue;
        Expr copy = *k.lookup;
        retarget(copy, k.line);
        row->lookups.back() = std::move(copy);
    }
    if (!differs) return;
    auto [shared, added] = read_rows_.emplace(signature, proto_.learns.size() + proto_.learned_read_keys.size());
    read.expr->learn_index = static_cast<int>(shared->second);
    if (added) proto_.learned_read_keys.push_back(std::move(row));
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "alternatives.h"

#include "emit_cpp.h"

#include <cstdio>
#include <vector>

namespace dissgen {

namespace {

const std::vector<std::unique_ptr<Node>>& siblings(const Protocol& proto, const Node& n) {
    return n.parent ? n.parent->children : proto.nodes;
}

size_t position(const Protocol& proto, const Node& n) {
    const auto& list = siblings(proto, n);
    for (size_t i = 0; i < list.size(); ++i)
        if (list[i].get() == &n) return i;
    return list.size();
}

bool disjoint(const std::vector<ValueRange>& a, const std::vector<ValueRange>& b) {
    for (const ValueRange& x : a)
        for (const ValueRange& y : b)
            if (x.low <= y.high && y.low <= x.high) return false;
    return true;
}

// A condition on the value of an earlier field: if/in or <when field>.
struct Test {
    const Node* field;
    const std::vector<ValueRange>* list;
};

std::vector<Test> tests_of(const Node& n) {
    std::vector<Test> out;
    if (n.if_field && n.if_field->target && !n.if_field->op) out.push_back({n.if_field->target, &n.in_list});
    for (const When& w : n.whens)
        if (!w.peek && w.ref.target && !w.ref.op) out.push_back({w.ref.target, &w.in_list});
    return out;
}

// x before y among the same siblings: one chain when y and every sibling
// between them are otherwise="true" (only the first member that holds is decoded).
bool same_chain(const Protocol& proto, const Node& x, const Node& y) {
    const auto& list = siblings(proto, x);
    for (size_t k = position(proto, x) + 1; k <= position(proto, y) && k < list.size(); ++k)
        if (!list[k]->otherwise) return false;
    return true;
}

std::string type_text(const FieldType& t) {
    char mask[32];  // " mask 0x" and up to 16 digits
    std::snprintf(mask, sizeof mask, " mask 0x%llx", static_cast<unsigned long long>(t.mask));
    return t.type + " " + t.display + (t.mask ? mask : "");
}

bool same_enums(const Node& a, const Node& b) {
    if (a.enums.size() != b.enums.size()) return false;
    for (size_t i = 0; i < a.enums.size(); ++i) {
        const EnumItem &x = a.enums[i], &y = b.enums[i];
        if (x.value != y.value || x.name != y.name || x.is_range != y.is_range || x.high != y.high) return false;
    }
    return true;
}

}  // namespace

// Siblings whose own conditions cannot both hold: one field (decoded once,
// before both) tested against disjoint lists, disjoint hook lists, or
// opposite directions.
bool conditions_exclude(const Node& x, const Node& y) {
    for (const Test& a : tests_of(x))
        for (const Test& b : tests_of(y))
            if (a.field == b.field && disjoint(*a.list, *b.list)) return true;
    if (x.has_hook && y.has_hook && disjoint(x.hook_list, y.hook_list)) return true;
    return x.direction != Direction::Any && y.direction != Direction::Any && x.direction != y.direction;
}

bool are_alternatives(const Protocol& proto, const Node& a, const Node& b) {
    // The ancestors (or selves) of a and b that are siblings: their common container's children.
    for (const Node* x = &a; x; x = x->parent)
        for (const Node* y = &b; y; y = y->parent) {
            if (x->parent != y->parent) continue;
            if (x == y) return false;  // one inside the other
            bool x_first = position(proto, *x) < position(proto, *y);
            const Node& first = x_first ? *x : *y;
            const Node& second = x_first ? *y : *x;
            return same_chain(proto, first, second) || conditions_exclude(first, second);
        }
    return false;
}

std::string shared_field_mismatch(const Node& a, const Node& b) {
    FieldType ta = field_type(a), tb = field_type(b);
    if (ta.type != tb.type || ta.display != tb.display || ta.mask != tb.mask)
        return type_text(ta) + " and " + type_text(tb);
    // (either side: a hex field owning the name would show an enum's values bare)
    if ((a.display == Display::Enum || b.display == Display::Enum) && !same_enums(a, b))
        return "different <enum> items";
    if (a.has_unit_label() != b.has_unit_label() || (a.has_unit_label() && a.unit != b.unit))
        return "different unit labels";
    return "";
}

}  // namespace dissgen

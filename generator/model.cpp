// SPDX-License-Identifier: GPL-2.0-or-later
#include "model.h"

namespace dissgen {

const char* display_name(Display d) {
    switch (d) {
        case Display::Address: return "address";
        case Display::NumberHex: return "numberhex";
        case Display::NumberDec: return "numberdec";
        case Display::Bool: return "bool";
        case Display::Origin: return "origin";
        case Display::Enum: return "enum";
        case Display::NonDisplay: return "nondisplay";
        case Display::String: return "string";
        case Display::StringZ: return "stringz";
        case Display::IPv4: return "ipv4";
        case Display::Int: return "int";
        case Display::Float: return "float";
        case Display::Time: return "time";
        case Display::DateTime: return "datetime";
        case Display::Guid: return "guid";
        case Display::IPv6: return "ipv6";
        case Display::Mac: return "mac";
        case Display::Eui64: return "eui64";
        case Display::Oid: return "oid";
        case Display::Varint: return "varint";
    }
    return "?";
}

bool is_numeric_display(Display d) {
    return d == Display::NumberHex || d == Display::NumberDec || d == Display::Bool ||
           d == Display::Enum || d == Display::Int || d == Display::Time;
}

bool Node::is_number_sized_by_field() const {
    return is_leaf() && !is_computed() && length_kind == LengthKind::Field && display != Display::Time &&
           is_numeric_display(display);
}

bool Node::takes_no_bytes() const {
    if (is_computed()) return true;
    if (is_overlay() || is_leaf() || length_kind != LengthKind::Children) return false;
    for (const auto& c : children)
        if (!c->is_overlay() && !(c->takes_no_bytes() && !c->is_repeated())) return false;
    return true;
}

bool Node::is_numeric() const {
    if (is_computed()) return display != Display::Float;
    if (display == Display::Varint) return is_leaf() && length_kind == LengthKind::Children;
    if (is_number_sized_by_field()) return true;
    if (!is_leaf() || !has_fixed_length()) return false;
    if (fixed_bits < 1 || fixed_bits > 64) return false;
    return is_numeric_display(display) || display == Display::NonDisplay;
}

bool Node::is_compared_by_bytes() const {
    if (!is_leaf() || is_computed() || is_numeric()) return false;
    switch (display) {
        case Display::String: case Display::StringZ: case Display::Origin: case Display::Address:
        case Display::IPv4: case Display::Guid: case Display::IPv6: case Display::Mac: case Display::Eui64:
        case Display::Oid: case Display::NonDisplay: return true;
        default: return false;
    }
}

}  // namespace dissgen

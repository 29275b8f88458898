// The rule model: plain data describing one protocol as a tree of fields.
// The parser fills in what the file says; the validator checks it and adds
// what follows from it (bit groups, filter names, value slots).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace dissgen {

enum class ByteOrder { Big, Little };

enum class Display { Address, NumberHex, NumberDec, Bool, Origin, Enum, NonDisplay };

enum class LengthKind {
    Children,  // absent or empty: sum of the children
    Bits,      // "Nbit"
    Bytes,     // "Nbyte"
    Field,     // XPath to an earlier numeric field, with optional arithmetic
    Rest,      // to the end of the enclosing known-length container or packet
};

struct Node;

// A reference to another field, written as an XPath in the rule file
// (length, count, repeat, if, pdulength), possibly followed by one
// arithmetic operator and an integer ("XPATH * 2").
struct FieldRef {
    std::string xpath;      // as written, without the arithmetic tail
    char op = 0;            // 0, '+', '-' or '*'
    int64_t operand = 0;
    Node* target = nullptr; // resolved by the parser
};

struct EnumItem {
    uint64_t value = 0;
    std::string name;
    int line = 0;
};

struct ValueRange {
    uint64_t low = 0, high = 0;
};

// One piece of a summary template: literal text, or the shown value of a leaf.
struct SummaryPiece {
    std::string text;       // literal when leaf == nullptr
    Node* leaf = nullptr;
};

struct Node {
    // --- as written ---
    std::string name;
    int line = 0;
    int doc_index = 0;      // 1-based position among all <node> elements
    LengthKind length_kind = LengthKind::Children;
    uint64_t fixed_bits = 0;        // for Bits and Bytes
    FieldRef length_ref;            // for Field
    Display display = Display::Origin;
    bool display_given = false;
    std::optional<FieldRef> repeat, count, if_field;
    std::vector<ValueRange> in_list;
    bool has_in = false;
    // ifhook: decoded only when the packet came through a hook (dissector
    // table entry, Decode As included) whose value is in this list.
    std::vector<ValueRange> hook_list;
    bool has_hook = false;
    std::optional<std::string> filter;  // empty string: leave container out of names
    std::string description;
    std::optional<std::string> summary;
    std::optional<ByteOrder> byteorder_given;
    std::vector<EnumItem> enums;
    std::vector<std::unique_ptr<Node>> children;
    Node* parent = nullptr;         // nullptr for top-level nodes

    // --- derived by the validator ---
    ByteOrder byteorder = ByteOrder::Big;  // effective
    std::string segment;                   // this node's filter-name segment
    std::string filter_name;               // full display-filter name ("" if none)
    // bit group membership: a group is a run of sibling leaves read as one
    // integer of group_bytes bytes; shift/bits place this leaf inside it.
    bool in_bit_group = false;
    bool group_first = false;
    bool group_last = false;
    unsigned group_bytes = 0;
    unsigned shift = 0;
    unsigned bits = 0;                     // width of a numeric leaf (fixed length)
    int slot = -1;                         // value slot, -1 when nobody refers to it
    std::vector<SummaryPiece> summary_pieces;

    bool is_container() const { return !children.empty(); }
    bool is_leaf() const { return children.empty(); }
    bool is_repeated() const { return repeat.has_value() || count.has_value(); }
    // Decoded only under a condition (if/in or ifhook): may take no bytes.
    bool is_conditional() const { return if_field.has_value() || has_hook; }
    bool has_fixed_length() const {
        return length_kind == LengthKind::Bits || length_kind == LengthKind::Bytes;
    }
    // A leaf of 1-64 bits whose value other fields may refer to.
    bool is_numeric() const;
};

struct Hook {
    std::string table;
    uint64_t value = 0;
    int line = 0;
};

// --- issue 11: request/response pairing (<pairing> in <root>) ---
// A message is a request until a later one with the same key values answers
// it. Key fields are numeric leaves; in a repeated node every instance's
// value is part of the key, in order.
struct PairingKey {
    FieldRef field;
    int line = 0;
};

struct Pairing {
    int line = 0;
    std::vector<PairingKey> keys;
    double timeout = 1.0;   // seconds a request waits for its response
    std::string analysis;   // "" or a protocol analysis of the runtime ("ethercat-esc")
};

// Analyses the runtime knows (plugin_runtime/dissgen_pairing.cpp).
constexpr const char* kPairingAnalyses[] = {"ethercat-esc"};

struct Protocol {
    std::string name;
    std::string abbreviation;
    std::string filter;              // display-filter name of the protocol
    bool filter_given = false;
    std::optional<uint64_t> ethertype;
    ByteOrder byteorder = ByteOrder::Big;
    std::vector<Hook> hooks;
    std::optional<FieldRef> pdulength;
    int64_t pdulengthadd = 0;
    int line = 0;
    std::vector<std::unique_ptr<Node>> nodes;
    // issue 11: request/response pairing, when the file declares it
    std::unique_ptr<Pairing> pairing;

    // --- derived by the validator ---
    int slot_count = 0;
    unsigned pdu_fixed_len = 0;      // bytes needed to read the pdulength field
};

// Calls fn(node) for every node in document order.
template <typename Fn>
void for_each_node(const std::vector<std::unique_ptr<Node>>& nodes, Fn&& fn) {
    for (const auto& n : nodes) {
        fn(*n);
        for_each_node(n->children, fn);
    }
}

const char* display_name(Display d);
bool is_numeric_display(Display d);

}  // namespace dissgen

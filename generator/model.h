// SPDX-License-Identifier: GPL-2.0-or-later
// The rule model: plain data describing one protocol as a tree of fields.
// The parser fills in what the file says; the validator checks it and adds
// what follows from it (bit groups, filter names, value slots).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "expression.h"

namespace dissgen {

enum class ByteOrder { Big, Little };

enum class Display {
    Address, NumberHex, NumberDec, Bool, Origin, Enum, NonDisplay,
    // values shown as text, addresses, signed and floating-point numbers, times
    String, StringZ, IPv4, Int, Float, Time,
    // absolute dates and times (Wireshark's FT_ABSOLUTE_TIME), GUIDs (FT_GUID)
    DateTime, Guid,
    // IPv6 addresses (FT_IPv6), MAC addresses (FT_ETHER: the vendor's name shown), EUI-64s (FT_EUI64)
    IPv6, Mac, Eui64,
    // object identifiers, BER-encoded without tag and length (FT_OID: shown dotted, 1.3.6.1...)
    Oid,
    // unsigned base-128 numbers of 1 to 10 bytes, lowest 7 bits first, bit 7 set while more follow
    // (MQTT's remaining length, protobuf's varint): a leaf without a length, its bytes say where it ends
    Varint
};

// direction="request|response" (Any: no such attribute)
enum class Direction { Any, Request, Response };

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
    // value="LOW-HIGH" (a range; value is LOW)
    uint64_t high = 0;
    bool is_range = false;
};

struct ValueRange {
    uint64_t low = 0, high = 0;
    std::string text;  // as written ("0-300", "0x10"), for messages that echo it
};

// One piece of a summary template: literal text, the shown value of a leaf,
// the summary of a container, or an optional part {?...} made of the `group`
// pieces after it.
struct SummaryPiece {
    std::string text;       // literal when leaf == nullptr and group == 0
    Node* leaf = nullptr;   // a leaf, or a container with a summary
    size_t group = 0;       // > 0: an optional part of the next `group` pieces
};

// One <when> condition of a node: an earlier field (`field`) or
// a later one whose position is known when the node starts (`peek`).
struct When {
    FieldRef ref;
    bool peek = false;
    std::vector<ValueRange> in_list;
    int line = 0;
    // peek, derived by the validator: the target sits `offset` bytes plus the
    // values of `lengths` after the start of the node.
    uint64_t offset = 0;
    std::vector<const FieldRef*> lengths;
    unsigned up = 0;  // 0: from the node's start; k: from the start of its k-th container
    unsigned target_up = 0;  // the target is a child of the node's k-th container (0: a sibling)
};

// <finding name="..." severity="..." group="..." condition="EXPR" text="..."/>
// inside a node: an expert info raised on the node's bytes, once an instance
// of it is decoded, when the condition holds (defined and not zero).
struct Finding {
    std::string name;        // segment of its filter name, P.finding.NAME
    std::string severity;    // chat, note, warning, error (as written)
    std::string group;       // protocol, malformed, sequence, ... (as written; default protocol)
    Expr condition;
    std::string condition_text;
    std::string text;        // {Name}: the shown value of a field decoded before
    int line = 0;
    // derived by the validator
    std::vector<SummaryPiece> text_pieces;
    std::string filter_name;
};

// <learn name="..." value="EXPR" [if="EXPR"] [sender="yes"|conversation="yes"]>
// <key value="EXPR" [lookup="EXPR"] [span="EXPR"]/>... </learn> inside a node:
// once an instance of the node is decoded (first pass), the value is learned
// under the keys' values (and the sender's address, or the conversation's); learned{NAME} in a later
// message reads the latest value learned under its own keys (lookup, else
// value) in an earlier one. A key with a span learns a window: the values
// value .. value + span - 1, any of which finds it; with an id, the window is
// what the id names, and its next teaching moves it.
struct LearnKey {
    Expr value;
    std::optional<Expr> lookup;  // how a reader computes the key, when not as the learner does
    std::optional<Expr> span;    // how many key values from this one the value is learned under
    std::optional<Expr> id;      // which window it is (with a span)
    std::string value_text, lookup_text, span_text, id_text;
    int line = 0;
};

struct Learn {
    std::string name;
    Expr value;
    std::string value_text;
    std::optional<Expr> condition;  // if="EXPR": learned only when it holds
    std::string condition_text;
    bool sender = false;            // sender="yes": the source address is a key too
    bool conversation = false;      // conversation="yes": both ends are, either way round
    std::vector<LearnKey> keys;
    int line = 0;
    // derived by the validator
    int index = -1;                 // its row in the plugin's table of learns
};

// The keys of learned{Name} as one reader computes them, when its lookups
// name other fields than the <learn>'s do: `{X}` in a lookup is the closest
// X before the reader, so each copy of a <group> reads its own fields. Rows
// of the plugin's learns table after the learns themselves.
struct LearnedReadKeys {
    const Learn* learn = nullptr;
    std::vector<std::optional<Expr>> lookups;  // per key, as resolved at the reader (none: as the learner)
    int line = 0;                              // the reader's
};

struct Node;
// Orders nodes as the document does, so that what is kept per node is
// emitted in the same order on every run (not by address).
struct InDocumentOrder {
    bool operator()(const Node* a, const Node* b) const;
};

struct Node {
    // --- as written ---
    std::string name;
    int line = 0;
    // a node of a group's copy: "in group 'G' used on line N" (outermost use
    // last), which tells the copies apart where `line` cannot; else empty
    std::string group_use;
    int doc_index = 0;      // 1-based position among all <node> elements
    LengthKind length_kind = LengthKind::Children;
    uint64_t fixed_bits = 0;        // for Bits and Bytes
    uint32_t rest_keep = 0;         // for Rest: "rest - N" leaves the last N bytes to a trailer
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
    // valid="LIST": a message is this protocol's only when this field's value is in the list.
    std::vector<ValueRange> valid_list;
    bool has_valid = false;
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
    // an alternative of an earlier node with the same filter name and field
    // type: registered once, as that node's field (nullptr: its own field)
    const Node* shares_field = nullptr;
    // bit group membership: a group is a run of sibling leaves read as one
    // integer of group_bytes bytes; shift/bits place this leaf inside it.
    bool in_bit_group = false;
    // a packed list of bit fields: a leaf of 1, 2 or 4 bits with `count`, its
    // values filling whole bytes of their own (no bit group)
    bool packed_bits = false;
    // a conditional member of a bit group that means the previous member's bits
    // otherwise (same width, conditions that never hold together): takes no bits of its own
    bool bit_alternative = false;
    bool group_first = false;
    bool group_last = false;
    unsigned group_bytes = 0;
    unsigned shift = 0;
    unsigned bits = 0;                     // width of a numeric leaf (fixed length)
    int slot = -1;                         // value slot, -1 when nobody refers to it
    std::vector<SummaryPiece> summary_pieces;
    // A leaf a summary names across a repeat also keeps its last value in a
    // slot of that repeat's (kept_slots: repeat -> slot), placed after the
    // repeat's slots so that its new instances do not clear it; the repeat
    // lists those leaves in kept_after.
    std::map<const Node*, int, InDocumentOrder> kept_slots;
    std::vector<Node*> kept_after;

    // --- display attributes, repeat="rest", direction, hand-off, reassembly ---
    std::string encoding = "utf-8";        // string, stringz: "ascii" or "utf-8"
    bool encoding_given = false;
    std::string unit = "ns";               // time: "ns", "us", "ms" or "s"; datetime: also "s+ns"
    bool unit_given = false;
    // unit="°C" on a number: the label its item is shown with (not a time's or datetime's unit)
    bool has_unit_label() const { return unit_given && display != Display::Time && display != Display::DateTime; }
    // a datetime's encoding: its unit, or seconds and nanoseconds as two 32-bit values by default
    // (a computed datetime: a count of nanoseconds since 1970)
    std::string datetime_unit() const { return unit_given ? unit : value ? "ns" : "s+ns"; }
    bool repeat_rest = false;              // repeat="rest": until the enclosing container ends
    Direction direction = Direction::Any;  // direction="request|response"
    std::optional<std::string> dissector;  // dissector="NAME": hand the bytes to that dissector
    std::optional<FieldRef> reassemble_id, reassemble_offset, reassemble_seq, reassemble_last,
        reassemble_more;
    bool reassembles() const { return reassemble_id || reassemble_offset || reassemble_seq ||
                                      reassemble_last || reassemble_more; }
    bool has_enum_ranges() const {
        for (const EnumItem& e : enums)
            if (e.is_range) return true;
        return false;
    }
    // --- alternatives, multi-field conditions, look-ahead, register maps ---
    std::vector<When> whens;                // <when field|peek="XPATH" in="LIST"/> children, ANDed
    std::vector<Finding> findings;          // <finding> children: expert infos the rules raise
    std::vector<Learn> learns;              // <learn> children: values later messages read (learned{Name})
    bool otherwise = false;                 // otherwise="true": member of the previous sibling's chain
    bool skip_malformed = false;            // malformed="skip": a malformed spot inside spoils only this container
    std::optional<FieldRef> base;           // base="XPATH [+-* N]": this container is a window
    std::optional<uint64_t> at;             // at="ADDRESS": placed in the parent window
    std::optional<uint64_t> stride;         // stride="N" instances="M": repeated block at a stride
    std::optional<uint64_t> instances;
    // derived by the validator
    uint64_t place_bytes = 0;               // a window child's fixed size
    bool is_window() const { return base.has_value(); }
    // --- offset tables ---
    // offsets="XPATH" from="XPATH": instance i starts offset[i] bytes after the
    // start of `from` and ends where instance i+1 starts (the last one: at the
    // end of the enclosing container). offsets selects a repeated numeric leaf.
    std::optional<FieldRef> offsets, from;
    // value="EXPR": a computed leaf, shown as a generated item; takes no bytes
    std::optional<Expr> value;
    std::string value_text;                 // as written, for messages
    std::optional<FieldRef> covers;         // covers="XPATH": a computed value shown on that node's bytes
    // derived by the validator
    bool keeps_values = false;              // an offsets table: every instance's value is kept
    bool keeps_instances = false;           // request{...} reads it by position: each instance's value is kept
    unsigned from_up = 0;                   // from an enclosing container: k levels up (0: an earlier field)
    bool is_located() const { return offsets.has_value(); }
    // overlay="XPATH": a container decoded over the bytes of an earlier node
    // (from its first byte); the walk's position does not move.
    std::optional<FieldRef> overlay;
    bool is_overlay() const { return overlay.has_value(); }
    // derived by the validator: a valid field's byte offset (its bit group's) from the message start
    uint64_t valid_offset = 0;
    // derived by the validator: the pairing analysis reads this leaf as its
    // input number analysis_input (-1: none), per instance of its repeated node or not
    int analysis_input = -1;
    bool analysis_input_per_instance = false;
    // derived by the validator: what <cycles> reads from this leaf (0 none,
    // else a dg_cycle_role: 1 signature, 2 sequence, 3 only, 4 never) and,
    // for only/never, its test's number
    int cycle_role = 0;
    int cycle_test = 0;

    bool is_computed() const { return value.has_value(); }
    bool is_container() const { return !children.empty(); }
    bool is_leaf() const { return children.empty(); }
    bool is_repeated() const { return repeat.has_value() || count.has_value() || repeat_rest || offsets.has_value(); }
    // Decoded more than once, each instance afresh: repeated, or a window's
    // child laid out at a stride.
    bool has_instances() const { return is_repeated() || stride.has_value(); }
    // A number whose length comes from a field: 1-8 bytes read at run time as 64 bits
    // (a PDO entry laid out by a learned mapping). A time needs a fixed length.
    bool is_number_sized_by_field() const;
    // An instance takes no bytes: computed values, overlays and containers of them
    // only (a list of entries laid out by learned values over bytes decoded before).
    bool takes_no_bytes() const;
    // A counted list of such instances: the walk repeats it `count` times without
    // moving (dg_extra.no_bytes).
    bool is_counted_list_of_no_bytes() const { return count.has_value() && !repeat && !repeat_rest && takes_no_bytes(); }
    // A condition of its own: if/in, <when>, ifhook or direction (not otherwise).
    bool has_own_condition() const {
        return if_field.has_value() || has_hook || direction != Direction::Any || !whens.empty();
    }
    // Decoded only under a condition (its own, or otherwise): may take no bytes.
    bool is_conditional() const { return has_own_condition() || otherwise; }
    bool has_fixed_length() const {
        return length_kind == LengthKind::Bits || length_kind == LengthKind::Bytes;
    }
    // A leaf of 1-64 bits whose value other fields may refer to.
    bool is_numeric() const;
    // A leaf read from bytes that are not a number (text, an address, a GUID,
    // raw bytes): what <cycles> compares byte for byte in a signature.
    bool is_compared_by_bytes() const;
    // How wide a numeric leaf's value is: its bits, or 64 for a computed
    // value and a number whose length comes from a field (read as 64-bit).
    unsigned value_bits() const { return has_fixed_length() ? static_cast<unsigned>(fixed_bits) : 64; }
};

// <heuristic table="udp" enabled="true|false"/>: found by its valid fields on a heuristic list.
struct Heuristic {
    std::string table;
    bool enabled = true;
    int line = 0;
};

struct Hook {
    std::string table;
    uint64_t value = 0;
    int line = 0;
};

// --- request/response pairing (<pairing> in <root>) ---
// A message is a request until a later one with the same key values answers
// it. Key fields are numeric leaves; in a repeated node every instance's
// value is part of the key, in order.
struct PairingKey {
    FieldRef field;
    int line = 0;
    // derived by the validator when a value reads request{...}: the key
    // field's byte offset (its bit group's) from the message start, when
    // every key field has one (Pairing::keys_decoded false)
    uint64_t offset = 0;
};

// <input name="..." field="XPATH"/> in <pairing>: a field the pairing's
// analysis reads from each message (generator/analysis_inputs.h).
struct AnalysisInput {
    std::string name;
    FieldRef field;
    int line = 0;
    // set by check_analysis_inputs: the analysis' input number (-1: not
    // bound); whether it is read by address says the analysis' spec of it
    int index = -1;
};

// A field <cycles> reads (<signature>, <sequence>, <only> or <never>), or
// <pairing>'s <request>: a field, and the values that hold.
struct CycleField {
    FieldRef field;
    std::vector<ValueRange> in_list;  // <only>/<never>: the values that hold (none given: not 0)
    int line = 0;
};

struct Pairing {
    int line = 0;
    std::vector<PairingKey> keys;
    std::vector<AnalysisInput> inputs;
    double timeout = 1.0;   // seconds a request waits for its response
    // order="request" (true): responses come back in the order of their
    // requests (per connection); order="any": in any order, so none is out
    // of order and later answers do not give a request up
    bool ordered = true;
    // derived by the validator when a value reads request{...}: some key
    // field is not at a fixed offset, so a response looks its request up
    // with the key values the walk decoded before its first request{...}
    bool keys_decoded = false;
    std::string analysis;   // "" or the name of a protocol analysis (analyses.h)
    // <request field="XPATH" in="LIST"/>: the message says which it is (its
    // value in the list: a request; decoded and not in it: a response)
    std::optional<CycleField> request;
    // <unanswered field="XPATH" in="LIST"/>: a message whose value is in the
    // list expects no response (a notification): it takes no part in pairing
    std::optional<CycleField> unanswered;
};

// --- periodic traffic (<cycles> in <root>) ---

// The runtime counts a gap's lost messages in 32 bits, the top value meaning
// "the count went back": the largest maxlost="N".
constexpr uint64_t kMostLostInAGap = 0xfffffffeu;

// Messages with the same signature values (and sender) are a stream; a
// stream whose messages come at a regular period is a cycle.
struct Cycles {
    int line = 0;
    unsigned window = 8;                   // regular periods in a row that make a cycle
    bool by_sender = false;                // sender="yes": the sender is part of the signature
    bool by_connection = false;            // sender="connection": its receiver too (a stream per connection side)
    std::vector<CycleField> signature;     // one or more
    std::optional<CycleField> sequence;    // the sequence count, if any
    unsigned sequence_bits = 0;            // its width (bits="..."; default: the field's)
    uint64_t sequence_step = 1;            // how much it advances per message (step="..."); 0: learned
    uint64_t sequence_wrap = 0;            // wrap="N": it runs 0 .. N - 1 (0: to 2^bits - 1)
    std::vector<CycleField> only, never;   // conditions
    bool lost_by_period = false;           // lost="period": a cycle's gap of n periods is n - 1 lost
    int lost_line = 0;                     // the line of lost="sequence" (0: not given)
    bool requests_only = false;            // requests="yes": only the pairing's requests, with round trips
    uint64_t max_lost = 0;                 // maxlost="N": a gap of more lost is a restart (0: not given)
};

struct Protocol {
    std::string name;
    std::string abbreviation;
    std::string filter;              // display-filter name of the protocol
    bool filter_given = false;
    std::optional<uint64_t> ethertype;
    ByteOrder byteorder = ByteOrder::Big;
    std::vector<Hook> hooks;
    std::vector<Heuristic> heuristics;
    std::optional<FieldRef> pdulength;
    int64_t pdulengthadd = 0;
    bool no_padding = false;  // padding="none": zero bytes a length leaves over raise P.expert.unused too
    int line = 0;
    std::vector<std::unique_ptr<Node>> nodes;
    // request/response pairing, when the file declares it
    std::unique_ptr<Pairing> pairing;
    // periodic traffic, when the file declares it
    std::unique_ptr<Cycles> cycles;

    // --- derived by the validator ---
    int slot_count = 0;
    unsigned pdu_fixed_len = 0;      // bytes needed to read the pdulength field (a varint's first)
    unsigned pdu_offset = 0;         // where the pdulength field starts in every message
    // the fields of a request that responses read (request{Name}), each once;
    // a request keeps their values in this order
    std::vector<const Node*> request_fields;
    // every node whose value reads request{...}, in document order
    std::vector<const Node*> request_readers;
    // every <learn>, in document order (Learn::index)
    std::vector<Learn*> learns;
    // readers whose lookups resolve to other fields (rows learns.size() + k)
    std::vector<std::unique_ptr<LearnedReadKeys>> learned_read_keys;
};

inline bool InDocumentOrder::operator()(const Node* a, const Node* b) const { return a->doc_index < b->doc_index; }

// Whether `ancestor` is n or a node around it.
inline bool is_ancestor_or_self(const Node* ancestor, const Node* n) {
    for (; n; n = n->parent)
        if (n == ancestor) return true;
    return false;
}

// The outermost node with instances strictly between container `x` and its
// leaf `leaf`: whose new instances clear what an earlier one decoded.
inline const Node* repeat_between(const Node& x, const Node& leaf) {
    const Node* outermost = nullptr;
    for (const Node* r = leaf.parent; r && r != &x; r = r->parent)
        if (r->has_instances()) outermost = r;
    return outermost;
}

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

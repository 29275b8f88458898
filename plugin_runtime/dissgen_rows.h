// SPDX-License-Identifier: GPL-2.0-or-later
/* Named rows for the tables of generated code.
 *
 * A row starts from what its kind needs, and names each value it sets;
 * everything it does not name keeps its "none" value:
 *
 *     dg_leaf("Length", &hf_x_length).show(DG_SHOW_DEC).flags(DG_NUMERIC).length(2).bits(16).slot(0)
 *
 * (C++17 has no designated initializers; plugins are built as C++17 because
 * Wireshark's own TRY macro is deprecated C++20.) Everything is constexpr, so
 * the tables stay constant data, initialized before any code runs.
 */
#pragma once

#include "dissgen_runtime.h"

/* A dg_node under construction: dg_leaf() or dg_container(), then the setters. */
struct dg_node_row {
    dg_node n;
    constexpr operator dg_node() const { return n; }
    constexpr dg_node_row &show(guint8 v) { n.show = v; return *this; }
    constexpr dg_node_row &flags(guint8 v) { n.flags = v; return *this; }
    /* length kind: fixed (the default, `length` bytes), from a field, to the end, or the children's sum */
    constexpr dg_node_row &length(guint32 bytes) { n.length = bytes; return *this; }
    constexpr dg_node_row &length_field(dg_ref ref) { n.length_kind = DG_LEN_FIELD; n.length_ref = ref; return *this; }
    constexpr dg_node_row &length_rest() { n.length_kind = DG_LEN_REST; return *this; }
    constexpr dg_node_row &length_children() { n.length_kind = DG_LEN_CHILDREN; return *this; }
    constexpr dg_node_row &length_packed() { n.length_kind = DG_LEN_PACKED; return *this; }
    constexpr dg_node_row &length_computed() { n.length_kind = DG_LEN_COMPUTED; return *this; }
    constexpr dg_node_row &shift(guint8 v) { n.shift = v; return *this; }
    constexpr dg_node_row &bits(guint8 v) { n.bits = v; return *this; }
    constexpr dg_node_row &slot(gint16 v) { n.slot = v; return *this; }
    constexpr dg_node_row &count(dg_ref ref) { n.count = ref; return *this; }
    constexpr dg_node_row &repeat(gint16 flag_slot) { n.repeat_slot = flag_slot; return *this; }
    /* decoded only when the value in `value_slot` is in ranges[first .. first + count) */
    constexpr dg_node_row &if_in(gint16 value_slot, guint16 first, guint16 count) {
        n.if_slot = value_slot; n.in_first = first; n.in_count = count; return *this;
    }
    constexpr dg_node_row &children(guint16 first, guint16 count) { n.first_child = first; n.child_count = count; return *this; }
    constexpr dg_node_row &slots(guint16 first, guint16 count) { n.slot_first = first; n.slot_count = count; return *this; }
    constexpr dg_node_row &summary(guint16 first, guint16 count) { n.summary_first = first; n.summary_count = count; return *this; }
    constexpr dg_node_row &hooks(guint16 first, guint16 count) { n.hook_first = first; n.hook_count = count; return *this; }
    constexpr dg_node_row &extra(const dg_extra *v) { n.extra = v; return *this; }
    constexpr dg_node_row &whens(guint16 first, guint16 count) { n.when_first = first; n.when_count = count; return *this; }
    constexpr dg_node_row &alt(guint8 v) { n.alt = v; return *this; }
    constexpr dg_node_row &window(gint16 v) { n.window = v; return *this; }
    constexpr dg_node_row &quiet_size(guint32 bytes) { n.quiet_size = bytes; return *this; }
    constexpr dg_node_row &walk(dg_list_walk fn) { n.walk = fn; return *this; }
    constexpr dg_node_row &summarize(dg_summary_text fn) { n.summarize = fn; return *this; }
};

constexpr dg_node_row dg_node_of(guint8 kind, const char *name, int *hf, int *ett) {
    dg_node_row r{};
    r.n.kind = kind;
    r.n.name = name;
    r.n.hf = hf;
    r.n.ett = ett;
    r.n.slot = r.n.repeat_slot = r.n.if_slot = -1;
    r.n.length_ref = r.n.count = dg_ref{-1, 0, 0, 0};
    return r;
}

/* hf NULL: a node left out of filter names. */
constexpr dg_node_row dg_leaf(const char *name, int *hf) { return dg_node_of(DG_LEAF, name, hf, NULL); }
constexpr dg_node_row dg_container(const char *name, int *hf, int *ett) {
    return dg_node_of(DG_CONTAINER, name, hf, ett).show(DG_SHOW_HIDDEN);
}

/* A dg_extra under construction: dg_node_extra(), then the setters. */
struct dg_extra_row {
    dg_extra e;
    constexpr operator dg_extra() const { return e; }
    constexpr dg_extra_row &encoding(guint32 v) { e.encoding = v; return *this; }
    constexpr dg_extra_row &units_per_second(guint32 v) { e.units_per_second = v; return *this; }
    constexpr dg_extra_row &repeat_rest() { e.repeat_rest = 1; return *this; }
    constexpr dg_extra_row &no_bytes() { e.no_bytes = 1; return *this; }
    constexpr dg_extra_row &direction(guint8 v) { e.direction = v; return *this; }
    constexpr dg_extra_row &dissector(const char *v) { e.dissector = v; return *this; }
    constexpr dg_extra_row &reassemble_id(gint16 slot) { e.reassemble_id = slot; return *this; }
    constexpr dg_extra_row &reassemble_offset(dg_ref ref) { e.reassemble_offset = ref; return *this; }
    constexpr dg_extra_row &reassemble_seq(gint16 slot) { e.reassemble_seq = slot; return *this; }
    constexpr dg_extra_row &reassemble_last(gint16 slot) { e.reassemble_last = slot; return *this; }
    constexpr dg_extra_row &reassemble_more(gint16 slot) { e.reassemble_more = slot; return *this; }
    constexpr dg_extra_row &offsets_slot(gint16 slot) { e.offsets_slot = slot; return *this; }
    constexpr dg_extra_row &from_slot(gint16 slot) { e.from_slot = slot; return *this; }
    constexpr dg_extra_row &from_up(guint8 levels) { e.from_up = levels; return *this; }
    constexpr dg_extra_row &keep_values() { e.keep_values = 1; return *this; }
    constexpr dg_extra_row &keep_instances() { e.keep_instances = 1; return *this; }
    constexpr dg_extra_row &kept(const gint16 *slots, guint8 count) { e.kept_slots = slots; e.kept_count = count; return *this; }
    constexpr dg_extra_row &unit(const char *label) { e.unit = label; return *this; }
    constexpr dg_extra_row &overlay(gint16 target_slot) { e.overlay_slot = target_slot; return *this; }
    constexpr dg_extra_row &value(guint16 first, guint16 count) { e.expr_first = first; e.expr_count = count; return *this; }
    constexpr dg_extra_row &covers(gint16 slot) { e.covers_slot = slot; return *this; }
    constexpr dg_extra_row &findings(guint16 first, guint16 count) {
        e.finding_first = first; e.finding_count = count; return *this;
    }
    constexpr dg_extra_row &learns(guint16 first, guint16 count) {
        e.learn_first = first; e.learn_count = count; return *this;
    }
    constexpr dg_extra_row &input(gint8 number) { e.input = number; return *this; }
    constexpr dg_extra_row &cycle_role(guint8 role, guint8 test) { e.cycle_role = role; e.cycle_test = test; return *this; }
    constexpr dg_extra_row &time_encoding(guint32 v) { e.time_encoding = v; return *this; }
};

/* UTF-8 strings, times in nanoseconds, no reassembly. */
constexpr dg_extra_row dg_node_extra() {
    dg_extra_row r{};
    r.e.encoding = ENC_UTF_8;
    r.e.units_per_second = 1000000000;
    r.e.reassemble_id = r.e.reassemble_seq = r.e.reassemble_last = r.e.reassemble_more = -1;
    r.e.reassemble_offset = dg_ref{-1, 0, 0, 0};
    return r;
}

/* Summary pieces: literal text, a leaf's shown value (its slot), an optional
 * part {?...} of the next `pieces` pieces, or the summary of the container
 * `node` (an index into the node table), shown when `decoded_slot` is present. */
constexpr dg_summary_piece dg_text(const char *text) { return dg_summary_piece{text, -1, 0, 0}; }
constexpr dg_summary_piece dg_value(gint16 slot) { return dg_summary_piece{NULL, slot, 0, 0}; }
constexpr dg_summary_piece dg_optional(guint16 pieces) { return dg_summary_piece{NULL, -1, pieces, 0}; }
constexpr dg_summary_piece dg_summary_of(gint16 decoded_slot, guint16 node) {
    return dg_summary_piece{NULL, decoded_slot, 0, static_cast<guint16>(node + 1)};
}

/* <when> conditions: an earlier field's value, or a later one read ahead
 * (peeks[peek]), in ranges[first .. first + count). */
constexpr dg_when dg_when_field(gint16 slot, guint16 first, guint16 count) { return dg_when{slot, -1, first, count}; }
constexpr dg_when dg_when_peek(gint16 peek, guint16 first, guint16 count) { return dg_when{-1, peek, first, count}; }

/* A dg_protocol under construction: dg_protocol_of(), then the setters. */
struct dg_protocol_row {
    dg_protocol p;
    constexpr operator dg_protocol() const { return p; }
    constexpr dg_protocol_row &ids(int *proto, int *ett) { p.proto = proto; p.ett = ett; return *this; }
    constexpr dg_protocol_row &dissect(dissector_t message, dissector_t stream) {
        p.dissect = message; p.dissect_stream = stream; return *this;
    }
    constexpr dg_protocol_row &nodes(const dg_node *v, guint16 count) { p.nodes = v; p.node_count = count; return *this; }
    constexpr dg_protocol_row &children(const guint16 *v, guint16 top_first, guint16 top_count) {
        p.children = v; p.top_first = top_first; p.top_count = top_count; return *this;
    }
    constexpr dg_protocol_row &conditions(const dg_conditions *v) { p.conditions = v; return *this; }
    constexpr dg_protocol_row &pieces(const dg_summary_piece *v) { p.pieces = v; return *this; }
    constexpr dg_protocol_row &slot_count(guint16 v) { p.slot_count = v; return *this; }
    constexpr dg_protocol_row &experts(dg_experts *v) { p.ei = v; return *this; }
    constexpr dg_protocol_row &hooks(const dg_hook *v, guint16 count) { p.hooks = v; p.hook_count = count; return *this; }
    /* message length = value of nodes[node], `offset` bytes into the message, plus `add` */
    constexpr dg_protocol_row &pdu_length(gint16 node, guint32 offset, gint64 add) {
        p.pdu_node = node; p.pdu_offset = offset; p.pdu_add = add; return *this;
    }
    constexpr dg_protocol_row &reassembly(reassembly_table *table, const fragment_items *items) {
        p.reassembly = table; p.fragments = items; return *this;
    }
    constexpr dg_protocol_row &peeks(const dg_peek *v) { p.peeks = v; return *this; }
    constexpr dg_protocol_row &peek_lengths(const dg_ref *v) { p.peek_lengths = v; return *this; }
    constexpr dg_protocol_row &windows(const dg_window *v) { p.windows = v; return *this; }
    constexpr dg_protocol_row &places(const dg_place *v) { p.places = v; return *this; }
    constexpr dg_protocol_row &pairing(const dg_pairing *v) { p.pairing = v; return *this; }
    constexpr dg_protocol_row &analysis_data(const void *v) { p.analysis_data = v; return *this; }
    constexpr dg_protocol_row &exprs(const dg_expr_op *v) { p.exprs = v; return *this; }
    constexpr dg_protocol_row &request_context(const dg_request_context *v) { p.request_context = v; return *this; }
    constexpr dg_protocol_row &findings(const dg_finding *v) { p.findings = v; return *this; }
    constexpr dg_protocol_row &learns(const dg_learn *v, const dg_learn_key *keys, guint16 count) {
        p.learns = v; p.learn_keys = keys; p.learn_count = count; return *this;
    }
    constexpr dg_protocol_row &top_walk(dg_list_walk fn) { p.top_walk = fn; return *this; }
    constexpr dg_protocol_row &no_padding() { p.no_padding = 1; return *this; }
    constexpr dg_protocol_row &cycles(const dg_cycles *v) { p.cycles = v; return *this; }
};

/* Operations of computed values: dg_op(CODE) for operators and index, and
 * the operands that carry a number or read a field. */
constexpr dg_expr_op dg_op(guint8 code) { return dg_expr_op{code, 0, -1, 0, 0}; }
constexpr dg_expr_op dg_op_int(gint64 v) { return dg_expr_op{DG_OP_INT, 0, -1, v, 0}; }
constexpr dg_expr_op dg_op_real(gdouble v) { return dg_expr_op{DG_OP_FLOAT, 0, -1, 0, v}; }
constexpr dg_expr_op dg_op_field(guint8 code, gint16 slot, guint8 bits) { return dg_expr_op{code, bits, slot, 0, 0}; }
constexpr dg_expr_op dg_op_learned(gint16 learn) { return dg_expr_op{DG_OP_LEARNED, 0, learn, 0, 0}; }

constexpr dg_protocol_row dg_protocol_of(const char *name, const char *short_name, const char *filter) {
    dg_protocol_row r{};
    r.p.name = name;
    r.p.short_name = short_name;
    r.p.filter = filter;
    r.p.pdu_node = -1;
    return r;
}

// SPDX-License-Identifier: GPL-2.0-or-later
/* The runtime that dissgen-generated dissectors plug into.
 *
 * Generated code describes a protocol as static tables (hf_register_info,
 * ett ids, and one dg_node per rule-file node in document order); the
 * runtime walks those tables over the packet with tvb_/proto_ calls. All
 * bounds are checked before each call, so a malformed packet yields expert
 * infos and the tree decoded so far, never a Wireshark exception.
 */
#pragma once

#include "dissgen_expr.h"
#include "dissgen_compat.h"
#include "dissgen_names.h"

/* Node kinds and length forms (docs/manual.md, "Lengths, bit fields, repetition, conditions"). */
enum dg_kind { DG_LEAF = 0, DG_CONTAINER = 1 };
enum dg_length_kind {
    DG_LEN_FIXED = 0,    /* bytes in dg_node.length */
    DG_LEN_FIELD = 1,    /* value of an earlier field, dg_node.length_ref */
    DG_LEN_REST = 2,     /* to the end of the enclosing known-length container */
    DG_LEN_CHILDREN = 3, /* sum of the children */
    DG_LEN_COMPUTED = 4, /* none: a computed value (dg_extra.expr_first/count) */
    DG_LEN_PACKED = 5    /* a list of bit fields: dg_node.count values of dg_node.bits bits, packed into bytes */
};
/* How a leaf's value is shown; used for summaries and the Info column. */
enum dg_show {
    DG_SHOW_HEX = 0, DG_SHOW_DEC, DG_SHOW_BOOL, DG_SHOW_ENUM, DG_SHOW_ADDRESS, DG_SHOW_BYTES, DG_SHOW_HIDDEN,
    /* values shown as text, addresses, signed and floating-point numbers, times */
    DG_SHOW_STRING, DG_SHOW_STRINGZ, DG_SHOW_IPV4, DG_SHOW_INT, DG_SHOW_FLOAT, DG_SHOW_TIME,
    DG_SHOW_DATETIME, DG_SHOW_GUID,
    /* addresses of one size: IPv6, MAC (FT_ETHER), EUI-64 */
    DG_SHOW_IPV6, DG_SHOW_MAC, DG_SHOW_EUI64, DG_SHOW_OID,
    /* an unsigned base-128 number whose bytes say where it ends (decimal) */
    DG_SHOW_VARINT
};
enum dg_flags {
    DG_LITTLE = 1 << 0,      /* little-endian value */
    DG_NUMERIC = 1 << 1,     /* leaf read as an unsigned integer */
    DG_HIDDEN = 1 << 2,      /* nondisplay leaf: hidden but filterable */
    DG_GROUP = 1 << 3,       /* member of a bit group */
    DG_GROUP_FIRST = 1 << 4, /* first member: reads the group's bytes */
    DG_GROUP_LAST = 1 << 5,  /* last member: moves past the group's bytes */
    DG_KEY = 1 << 6,         /* a <pairing> key field (dissgen_pairing.h) */
    DG_SKIP_MALFORMED = 1 << 7 /* malformed="skip": a malformed spot inside spoils only this container */
};

/* A run-time value taken from an earlier field, with optional arithmetic. */
typedef struct dg_ref {
    gint16 slot;       /* -1: none */
    char op;           /* 0, '+', '-' or '*' */
    guint8 is_signed;  /* the field keeps a signed value (an int, a computed value): -3 is -3 */
    gint32 operand;    /* the generator accepts at most 999999999 */
} dg_ref;

typedef struct dg_range {
    guint64 low, high;
} dg_range;

/* Literal text (slot < 0), the shown value of the leaf in `slot`, or (node >
 * 0) the summary of container nodes[node - 1], decoded when `slot` is
 * present. group > 0: an optional part {?...} made of the next `group`
 * pieces, left out when one of their placeholders shows nothing. */
typedef struct dg_summary_piece {
    const char *text;
    gint16 slot;
    guint16 group = 0;
    guint16 node = 0;
} dg_summary_piece;

/* A datetime counting 100 ns since 1601 (Windows FILETIME, OPC UA's
 * DateTime): Wireshark has no ENC_TIME_ for it, the runtime converts it
 * (filetime_to_nstime). Outside every ENC_TIME_ value. */
#define DG_TIME_FILETIME 0x7f000000u

/* What few nodes need (direction, repeat="rest", strings, times,
 * hand-off, reassembly), kept out of dg_node so that it costs the others one
 * pointer. */
enum dg_direction { DG_DIR_ANY = 0, DG_DIR_REQUEST = 1, DG_DIR_RESPONSE = 2 };

typedef struct dg_extra {
    guint32 encoding;         /* string, stringz: ENC_ASCII, ENC_UTF_8 or ENC_ISO_8859_1 */
    guint32 units_per_second; /* time: 1000000000 (ns), 1000000 (us), 1000 (ms) or 1 (s) */
    guint8 repeat_rest;       /* repeat="rest": instances until the enclosing container ends */
    guint8 no_bytes;          /* count: instances that take no bytes (computed values, overlays) */
    guint8 direction;         /* dg_direction */
    const char *dissector;    /* dissector="NAME": hand the bytes to it; NULL: none */
    gint16 reassemble_id;     /* slot of reassemble-id; -1: no reassembly */
    dg_ref reassemble_offset; /* byte offset of the fragment (slot -1: numbered instead) */
    gint16 reassemble_seq;    /* slot of the fragment number, or -1 */
    gint16 reassemble_last;   /* slot of the "last fragment" flag, or -1 */
    gint16 reassemble_more;   /* slot of the "more fragments" flag, or -1 */
    /* offsets="XPATH" from="XPATH". Instance i of the node starts
     * offset[i] bytes after the base and ends where instance i+1 starts (the
     * last: at the end of its container). The base is the first byte of the
     * field in from_slot, or (from_slot -1) the start of the from_up-th
     * enclosing container's content. Generated code gives them only for the
     * nodes that use them. */
    gint16 offsets_slot = -1; /* slot of the repeated offset leaf; -1: not placed by a table */
    gint16 from_slot = -1;
    guint8 from_up = 0;
    guint8 keep_values = 0;   /* an offset leaf: the value of every instance is kept (up to DG_MAX_TABLE) */
    guint8 keep_instances = 0; /* request{...} reads it by position: each instance's value is kept, at its
                                * instance number (up to DG_MAX_TABLE) */
    /* A summary names this leaf across repeats: its last value is also kept
     * in these slots, one per repeat, which its new instances do not clear. */
    const gint16 *kept_slots = nullptr;
    guint8 kept_count = 0;
    const char *unit = nullptr; /* unit="°C" on a number: " °C", written after its value in summaries */
    /* overlay="XPATH": this container decodes the bytes of the node in
     * overlay_slot (a leaf or container decoded before it: its slot keeps
     * where they are), from their first byte; the walk's position does not
     * move. -1: not an overlay. */
    gint16 overlay_slot = -1;
    /* value="EXPR": the operations dg_protocol.exprs[expr_first ..] */
    guint16 expr_first = 0, expr_count = 0;
    /* covers="XPATH": the computed value's item is shown on the bytes of the
     * node in covers_slot (decoded before it); -1: on none (a zero-length item) */
    gint16 covers_slot = -1;
    /* <finding> children: dg_protocol.findings[finding_first ..], checked
     * once each instance of the node is decoded */
    guint16 finding_first = 0, finding_count = 0;
    /* <learn> children: dg_protocol.learns[learn_first ..], evaluated once
     * each instance of the node is decoded, on the first pass */
    guint16 learn_first = 0, learn_count = 0;
    /* <pairing><input>: the number of the pairing analysis' input this leaf
     * is (its value goes to the message's dg_view); -1: none */
    gint8 input = -1;
    /* <cycles>: what the cycle analysis reads from this leaf (dg_cycle_role),
     * and for DG_CYCLE_ONLY / DG_CYCLE_NEVER its test (dg_cycles.tests); 0: none */
    guint8 cycle_role = 0;
    guint8 cycle_test = 0;
    /* datetime: its ENC_TIME_* encoding (ENC_TIME_SECS_NSECS, 0, when the node has no dg_extra) */
    guint32 time_encoding = ENC_TIME_SECS_NSECS; /* or DG_TIME_FILETIME */
} dg_extra;

/* A <finding>: the expert info `ei` is raised on the node's bytes when the
 * condition dg_protocol.exprs[expr_first ..] is defined and not zero; its
 * text is the summary pieces dg_protocol.pieces[text_first ..]. */
typedef struct dg_finding {
    expert_field *ei;
    guint16 expr_first, expr_count;
    guint16 text_first, text_count;
} dg_finding;

/* dg_learn.ends: the transport's ends that are a key of a learned value too:
 * none, the sender's address and port, or both ends either way round (one
 * value per conversation, taught by either side, read by both). */
enum dg_learn_ends { DG_LEARN_ENDS_NONE = 0, DG_LEARN_ENDS_SENDER = 1, DG_LEARN_ENDS_CONVERSATION = 2 };

/* A <learn>: once an instance of its node is decoded on the first pass, when
 * its condition (exprs[if_first ..], none when if_count is 0) holds, the
 * value exprs[value_first ..] is learned under its keys
 * (dg_protocol.learn_keys[key_first ..]) and the transport's ends that
 * `ends` names (dissgen_learned.cpp). */
typedef struct dg_learn {
    guint16 value_first, value_count;
    guint16 if_first, if_count;
    guint16 key_first, key_count;
    guint8 ends; /* dg_learn_ends: whose value it is besides the keys' */
    /* 0: a <learn>; n: the keys one reader of learned{...} computes for the
     * <learn> in row n - 1 (its lookups read the fields closest to it) */
    guint16 keys_of = 0;
} dg_learn;

/* The most keys a <learn> has (the generator refuses more). */
#define DG_MAX_LEARN_KEYS 16

/* A key of a <learn>: its value as the learner computes it, and as a reader
 * of learned{...} does (lookup; lookup_count 0: as the learner). With a span
 * (span_count > 0; one key of a learn at most) the learner's value starts a
 * window of span keys and a reader's key finds the window that holds it; with
 * an id (id_count > 0) the window is what the id names, moved by its next
 * teaching. */
typedef struct dg_learn_key {
    guint16 value_first, value_count;
    guint16 lookup_first, lookup_count;
    guint16 span_first, span_count;
    guint16 id_first, id_count;
} dg_learn_key;

/* The most entries an offset table may have; longer ones are malformed. */
#define DG_MAX_TABLE 1024
/* <when> conditions, otherwise, windows (register maps). */
enum dg_alt_flags {
    DG_ALT_OTHERWISE = 1 << 0  /* otherwise="true": only when no earlier member of its chain was decoded */
};

/* One <when>: an earlier field's value (slot), or a later one read ahead (peek). */
typedef struct dg_when {
    gint16 slot;    /* field: the value's slot; -1 for a peek */
    gint16 peek;    /* peek: index into dg_protocol.peeks; -1 for a field */
    guint16 in_first, in_count;
} dg_when;

/* What the tests of a node's conditions read (if/in, ifhook, <when>): the
 * value ranges and the <when> rows (NULL when none). A compiled walk passes
 * its protocol's as a constant, so each test folds to its comparisons. */
typedef struct dg_conditions {
    const dg_range *ranges;
    const dg_when *whens;
} dg_conditions;

/* Where a peeked leaf sits: `offset` bytes plus the values of the length
 * references peek_lengths[length_first ..] after the start of the node
 * (up == 0) or of its up-th enclosing container. */
typedef struct dg_peek {
    guint16 target;                     /* the numeric leaf (node index) */
    guint32 offset;
    guint16 length_first, length_count;
    guint8 up;
    guint8 target_up; /* the target's list: the node's own (0) or its k-th container's */
} dg_peek;

/* A child of a window, at an absolute address; stride > 0: `instances`
 * blocks of `size` bytes, `stride` bytes apart. */
typedef struct dg_place {
    guint16 node;
    /* the node is quiet (dg_node.quiet_size) within `size` bytes: a walk
     * nobody sees steps over each instance without reading the node */
    gboolean quiet;
    guint64 at;
    guint32 size;
    guint32 stride;
    guint32 instances;
} dg_place;

/* A container whose first byte has the address `base`; its places are sorted
 * by address, and none spans more than max_span bytes. */
typedef struct dg_window {
    dg_ref base;
    guint16 place_first, place_count;
    guint64 max_span;
    gboolean address_order_is_document_order;
} dg_window;

/* A list of siblings decoded by code the generator compiled for it (the
 * generated source's *_walk_* functions: dissgen_state.h dissect_child() for
 * each member, its node a constant), instead of the table walk's loop over
 * dg_protocol.children. Both decode the same. */
namespace dg_rt __attribute__((visibility("hidden"))) {
struct dg_state;
struct dg_text;
}
typedef void (*dg_list_walk)(dg_rt::dg_state *st, proto_tree *tree, gint *offset, gint end, gboolean in_summary);
/* A container's summary compiled the same way (the generated *_summary_*
 * functions): appends it to out; FALSE when a value in it showed nothing,
 * as dissgen_text.cpp append_pieces() says of the pieces' table. */
typedef gboolean (*dg_summary_text)(const dg_rt::dg_state *st, dg_rt::dg_text *out);

/* Two cache lines, the first of them what the walk reads of every node it
 * meets (kind, lengths, slots, conditions, quiet size, extra, count, hf):
 * out of line, the walk reads nodes from a table no cache keeps between
 * frames, so that a visit costs one line of it. */
typedef struct alignas(64) dg_node {
    guint8 kind;        /* dg_kind */
    guint8 length_kind; /* dg_length_kind */
    guint8 show;        /* dg_show */
    guint8 flags;       /* dg_flags */
    guint32 length;     /* fixed length in bytes; a bit field's group length */
    guint8 shift, bits; /* bit field: position and width inside its group */
    gint16 slot;        /* where this leaf's value is kept, -1 if nobody reads it */
    gint16 repeat_slot; /* >= 0: decoded again while that flag is non-zero */
    gint16 if_slot;     /* >= 0: decoded only when that value is in the ranges */
    guint16 in_first, in_count;
    /* ifhook: decoded only when the value the dissector table matched
     * (pinfo->match_uint: the port, the ethertype) is in these ranges.
     * Generated code gives them only for nodes that have the attribute. */
    guint16 hook_first = 0, hook_count = 0;
    /* <when> conditions (dg_conditions.whens), DG_ALT_* flags, and
     * the window (dg_protocol.windows) of a container with 'base'. Generated
     * code gives them only for nodes that use them. */
    guint16 when_first = 0, when_count = 0;
    guint8 alt = 0;
    gint16 window = -1;
    /* quiet_size: > 0 when nothing but the node's own items depends on it
     * (no value others read, no summary, key or hand-off) and it cannot be
     * malformed within these many bytes: a walk with no tree and no tap
     * listener steps over it when they are there. */
    guint32 quiet_size = 0;
    /* NULL for nodes without string/time/int/float/ipv4 attributes,
     * repeat="rest", direction, dissector or reassembly. */
    const dg_extra *extra = NULL;
    dg_ref count;       /* slot >= 0: decoded exactly that many times */
    int *hf;            /* NULL for a container left out of filter names */
    /* the second line: what containers and their summaries read */
    int *ett;           /* containers only */
    dg_ref length_ref;  /* DG_LEN_FIELD */
    guint16 first_child, child_count;
    guint16 slot_first, slot_count; /* slots inside this subtree */
    guint16 summary_first, summary_count;
    const char *name;
    /* a container's children, compiled (NULL: the table walk) */
    dg_list_walk walk = NULL;
    /* its summary, compiled (NULL: the pieces' table) */
    dg_summary_text summarize = NULL;
} dg_node;
static_assert(sizeof(void *) != 8 || sizeof(dg_node) == 128, "dg_node: two cache lines");

/* The expert infos of every protocol, one member per row of
 * DG_RUNTIME_EXPERTS (dissgen_names.h), which the generated code registers. */
#define DG_EXPERT_MEMBER(id, name, group, severity, summary) expert_field id;
typedef struct dg_experts {
    DG_RUNTIME_EXPERTS(DG_EXPERT_MEMBER)
} dg_experts;

typedef struct dg_hook {
    const char *table;
    guint32 value;
} dg_hook;

/* Request/response pairing declared by <pairing> in the rule file
 * (dissgen_pairing.cpp). Key fields carry DG_KEY. */
struct dg_analysis; /* dissgen_pairing.h; each analysis defines its own in its folder */

/* Periodic traffic declared by <cycles> in the rule file (dissgen_cycles.cpp).
 * A leaf the analysis reads carries its role in dg_extra.cycle_role. */
enum dg_cycle_role {
    DG_CYCLE_SIGNATURE = 1, /* part of the stream's signature (every instance, in order) */
    DG_CYCLE_SEQUENCE = 2,  /* the stream's sequence count */
    DG_CYCLE_ONLY = 3,      /* the message may be cyclic only when this holds */
    DG_CYCLE_NEVER = 4      /* the message is never cyclic when this holds (any instance) */
};

/* <only>/<never>: the leaf's value holds when it lies in one of the ranges
 * dg_cycles.ranges[range_first .. range_first + range_count). */
typedef struct dg_cycle_test {
    guint16 range_first, range_count;
} dg_cycle_test;

/* dg_cycles.by_sender: the transport's ends that are part of a stream's signature. */
enum dg_stream_ends { DG_STREAM_ENDS_NONE = 0, DG_STREAM_ENDS_SENDER = 1, DG_STREAM_ENDS_CONNECTION = 2 };

typedef struct dg_cycles {
    guint8 window;         /* regular periods in a row that make a stream a cycle */
    guint8 sequence_bits;  /* the sequence count's width; 0: none */
    guint8 by_sender;      /* what of the transport is part of the signature: dg_stream_ends */
    guint8 only_count;     /* the <only> tests, numbered 0 .. only_count - 1, before the <never> ones */
    const dg_cycle_test *tests;
    const dg_range *ranges;
    guint64 sequence_step; /* how much the count advances per message; 0: learned from the stream */
    guint8 lost_by_period; /* lost="period": a cycle's period of n nominal ones means n - 1 lost */
    guint64 sequence_wrap; /* wrap="N": the count runs 0 .. N - 1, then 0 again; 0: at 2^sequence_bits */
    guint8 requests_only;  /* requests="yes": only the pairing's requests are timed, with their round trips */
    guint32 max_lost;      /* maxlost="N": a gap of more messages lost is a restart; 0: half the count's
                              range (a sequence), 15 (lost="period") */
} dg_cycles;

/* A register the pairing's analysis reads, where the rule file's register map
 * puts it (<input> bound to a child of a window): its address in the window,
 * its size, and with stride > 0 `instances` blocks `stride` bytes apart. */
typedef struct dg_input_place {
    guint8 input;            /* the analysis' input number */
    guint64 at;
    guint32 size, stride, instances;
} dg_input_place;

/* <request field="XPATH" in="LIST"/>: the message says whether it is a
 * request. Once it is decoded, the field's value (in its slot) in one of the
 * ranges: a request; decoded and in none: a response; not decoded: the
 * transport's direction, as without it. */
typedef struct dg_request_role {
    gint16 slot;
    guint16 range_count;
    const dg_range *ranges;
} dg_request_role;

typedef struct dg_pairing {
    double timeout;          /* seconds a request waits for its response */
    const struct dg_analysis *analysis; /* NULL, or the protocol analysis the rule file names */
    guint8 ordered;          /* order="request": responses come in their requests' order (per connection) */
    const dg_input_place *places; /* the registers the analysis reads (NULL: none bound) */
    guint16 place_count;
    const dg_request_role *request; /* NULL: the transport's direction (or the order) decides */
    const dg_request_role *unanswered; /* <unanswered>: a message in its ranges takes no part in pairing */
} dg_pairing;

/* request{Name} in computed values: a response reads fields of its paired
 * request (dissgen_request.cpp). When the key fields sit at fixed offsets
 * (`keys`), a response finds its request before it is decoded; otherwise
 * (`key_count` 0) it finds it with the key values the walk has decoded when
 * a value first reads the request. A request keeps the values of the fields
 * in `slots`, in that order, for its responses. */
typedef struct dg_fixed_field {
    guint32 offset;     /* bytes from the message start (a bit field: its group's) */
    guint8 length;      /* bytes read */
    guint8 little;
    guint8 shift, bits; /* bits > 0: a bit field, `bits` wide, `shift` bits up */
} dg_fixed_field;

typedef struct dg_request_context {
    const dg_fixed_field *keys; /* the key fields, in the order the walk decodes them; */
    guint16 key_count;          /* 0: the keys the walk decoded (DG_KEY), read when needed */
    const gint16 *slots;        /* the slots of the fields a request keeps */
    guint16 kept_count;
    /* per kept field, 1: it is in a repeated node, the request keeps each
     * instance's value (the slot's table) and a response reads the one of its
     * own instance number; NULL: no such field */
    const guint8 *by_position;
} dg_request_context;

typedef struct dg_protocol {
    const char *name;        /* long name, e.g. "EtherCAT" */
    const char *short_name;  /* Protocol column, e.g. "ECATR" */
    const char *filter;      /* display-filter name, e.g. "ecatr" */
    int *proto;
    int *ett;                /* the protocol's own subtree */
    dissector_t dissect;     /* generated entry points, calling dg_dissect / dg_dissect_stream */
    dissector_t dissect_stream;
    const dg_node *nodes;
    guint16 node_count;
    const guint16 *children; /* child index lists, addressed by first_child/child_count */
    guint16 top_first, top_count; /* the top-level nodes' list in `children` */
    const dg_conditions *conditions;
    const dg_summary_piece *pieces;
    guint16 slot_count;
    dg_experts *ei;
    const dg_hook *hooks;    /* ethertype first when present */
    guint16 hook_count;
    /* Stream transports (pdulength): message length = value of node pdu_node,
     * found pdu_offset bytes into the message, plus pdu_add. */
    gint16 pdu_node;         /* -1 when the protocol has no pdulength */
    guint32 pdu_offset;
    gint64 pdu_add;
    /* reassembly across frames (NULL when no node reassembles). */
    reassembly_table *reassembly = NULL;
    const fragment_items *fragments = NULL;
    /* tables of peeks and windows (NULL when unused). */
    const dg_peek *peeks = NULL;
    const dg_ref *peek_lengths = NULL;
    const dg_window *windows = NULL;
    const dg_place *places = NULL;
    /* request/response pairing, NULL when the rule file has none.
     * Generated code gives it only for protocols that have one. */
    const dg_pairing *pairing = nullptr;
    /* Data for the pairing's analysis, built from other inputs than the rule
     * file (for the EtherCAT analysis: the ESI catalogue and network design
     * of --esi / --network); only the analysis knows its type. NULL when none;
     * generated code gives it only when there is some. */
    const void *analysis_data = nullptr;
    const dg_expr_op *exprs = nullptr; /* computed values' operations, NULL when none */
    /* request{...}: NULL when no value reads the paired request. Generated
     * code gives it only for protocols that use it. */
    const dg_request_context *request_context = nullptr;
    /* <finding>s, addressed by dg_extra.finding_first/count; NULL when none */
    const dg_finding *findings = nullptr;
    /* <learn>s, addressed by dg_extra.learn_first/count and by learned{...}
     * (DG_OP_LEARNED); NULL when none */
    const dg_learn *learns = nullptr;
    const dg_learn_key *learn_keys = nullptr;
    guint16 learn_count = 0;
    dg_list_walk top_walk = nullptr; /* the top-level nodes, compiled (NULL: the table walk) */
    /* padding="none": zero bytes a length leaves over are not padding but
     * P.expert.unused, like any others. Generated code gives it only when set. */
    guint8 no_padding = 0;
    /* <cycles>: periodic streams, NULL when the rule file declares none.
     * Generated code gives it only for protocols that have one. */
    const dg_cycles *cycles = nullptr;
} dg_protocol;

/* The entry points generated code calls. C linkage: plain symbol
 * names in every plugin (tests/integration/plugin/test_plugin_contents.py reads
 * them), whatever the compiler's name mangling. */
extern "C" {

/* True when no protocol of the running Wireshark uses this protocol's name,
 * short name or filter name; otherwise reports the clash (report_failure)
 * so the caller can skip registering, and Wireshark keeps running. */
gboolean dg_protocol_names_free(const dg_protocol *p);

/* Registers the protocol's hf/ett/expert arrays. */
void dg_register(dg_protocol *p, hf_register_info *hf, int hf_count, gint **ett, int ett_count,
                 ei_register_info *ei, int ei_count);

/* Sets the abbrev of each of `count` fields (or the name of each expert
 * info) to "FILTER.NAME", names[i] being the NAME of the i-th row of a list
 * of dissgen_names.h. The strings live until Wireshark exits. */
void dg_name_fields(hf_register_info *hf, const char *const *names, guint count, const char *filter);
void dg_name_experts(ei_register_info *ei, const char *const *names, guint count, const char *filter);

/* Handoff: adds the protocol to its ethertype/hook tables and makes sure it,
 * not another plugin that registered the same values, is the default. */
void dg_handoff(const dg_protocol *p);

/* Dissects one message; returns the number of bytes decoded. */
int dg_dissect(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree);

/* Dissects a TCP segment holding whole or partial messages (pdulength). */
int dg_dissect_stream(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree);

/* The length of the message at `offset` from its pdulength field (a
 * tcp_dissect_pdus get_pdu_len; data: the dg_protocol). */
guint dg_message_length(packet_info *pinfo, tvbuff_t *tvb, int offset, void *data);

}

// SPDX-License-Identifier: GPL-2.0-or-later
/* Inside the runtime: the state of the message being decoded, the helpers
 * every part of the walk calls for every field (inline here, so that each
 * source inlines them), and what the runtime's sources call of each other.
 *
 *   dissgen_walk.cpp        the table walk: leaves, containers, repeats, located instances
 *   dissgen_conditions.cpp  references, offset tables, conditions, windows
 *   dissgen_text.cpp        shown values, summaries, the Info column
 *   dissgen_handoff.cpp     hand-off to other dissectors, reassembly, stream transports
 *   dissgen_register.cpp    registration, hand-off tables, statistics
 *
 * Wireshark's exceptions are longjmps that skip C++ destructors, so nothing
 * here owns a non-trivial C++ object; memory comes from pinfo->pool. Names
 * here are hidden: each plugin links its own copy of the runtime.
 */
#pragma once

#include "dissgen_cycles.h"
#include "dissgen_pairing.h"
#include "dissgen_runtime.h"
#include "dissgen_text.h"
#include "dissgen_values.h"

namespace dg_rt __attribute__((visibility("hidden"))) {

/* A slot's value is valid only while dg_state.present[slot] is set: the
 * flags are cleared per message and per repeated instance, the slots not
 * (fewer bytes to clear). */
struct dg_slot {
    guint64 value;
    gint offset;
    gint length;
    const dg_node *node;
};

/* One counted thing for the stats tree: an enum leaf's value, or how many
 * instances a repeated node had in this message. */
struct dg_tap_record {
    guint16 node;
    guint64 value;
};

struct dg_tap_data {
    dg_tap_record *records;
    guint count, capacity;
    const dg_frame_pairing *pairing; /* what the pairing found, or NULL */
};

/* Every value of an offset leaf (extra->keep_values) in this
 * message, in instance order; reset when its repetition starts. */
struct dg_table {
    guint64 *values;
    guint count, capacity;
    gboolean overflow; /* more than DG_MAX_TABLE instances */
    guint8 *present;   /* keep_instances: per instance, decoded (values[i] holds it); count: the last one + 1 */
};

/* Summaries of one repeated node's instances, gathered for the Info column
 * (in `buf` on the caller's stack until they outgrow it). */
struct dg_summaries {
    dg_text text;
    char buf[256];
    guint count;
};

#define DG_END_KNOWN (-1) /* dg_state.cut_end of a container the capture kept whole */

#define DG_MAX_LISTS 80 /* nesting is at most 64 levels (parser.h kMaxNesting) */

struct dg_state {
    const dg_protocol *p;
    tvbuff_t *tvb;
    packet_info *pinfo;
    dg_slot *slots;
    guint8 *present;      /* per slot: decoded in this message (instance) */
    dg_table *tables;     /* offset tables: per slot, allocated at the first offset leaf */
    gint packet_end;      /* captured bytes */
    gint cut_end;         /* where the innermost container ends on the wire when the capture cut it short;
                           * DG_END_KNOWN: in one that ends where its end says; 0: at the top level */
    gboolean stopped;     /* a malformed spot was reported: decode nothing more */
    gboolean faulted;     /* a malformed spot was reported in this message, even if decoding went on */
    gboolean cut_shown;   /* the capture kept less than the frame had: shown once (capture_cut) */
    gboolean header_only; /* a stream message whose length field says less than its header: only the
                           * header is walked, and what it lacks is that one fault, told once */
    gint64 told_end;      /* where a length reported past the end of its data says its container ends
                           * (0: none), and where that data ran out: data missing there, needed up to
                           * no further than told_end, is that fault, not told again */
    gint told_short_at;
    gboolean peek_cut;    /* a <when peek> read past the kept bytes: which alternative holds is not known */
    gboolean want_text;   /* summaries are shown: a visible tree, or columns */
    gboolean want_info;   /* the Info column is shown (pinfo->cinfo) */
    gboolean quiet;       /* no tree, no tap listener: step over quiet nodes (dg_node.quiet_size) */
    dg_text *info;  /* the Info column being built (want_info) */
    dg_text *text;  /* scratch for one container's summary (want_text) */
    guint64 group_value;  /* the bit group being decoded */
    guint32 hook_value;   /* pinfo->match_uint on entry: the hook (or Decode As) value, for ifhook */
    dg_tap_data *tap;     /* what the stats tree counts; NULL when nobody listens */
    guint8 direction;     /* DG_DIR_REQUEST/RESPONSE when a port hook matched, else DG_DIR_ANY */
    guint32 instance;     /* the instance number of the innermost repeat (computed values' index) */
    gint here;            /* where the computed value being evaluated sits (its `offset`) */
    guint lists;          /* lists of siblings open: list_starts[0 .. lists) */
    /* the values of the <pairing> key fields (DG_KEY), in decoding order */
    guint64 *keys;
    guint key_count, key_capacity;
    /* what the pairing analysis reads (dg_view): the values of the input
     * leaves (dg_extra.input), first pass only; views NULL otherwise */
    dg_view_value *views;
    guint view_count, view_capacity;
    gboolean wants_view;
    /* <cycles>, first pass only: what the leaves with a dg_extra.cycle_role
     * decoded (dg_cycle_input) */
    gboolean wants_cycles;
    dg_cycle_input cycle;
    guint cycle_capacity;
    gboolean cycle_on_stack;     /* cycle's arrays are dg_message_buffers' (not to be realloc'ed) */
    /* request{...}: what the paired request kept, NULL when it is not known */
    mutable const dg_request_values *request;
    mutable gboolean request_missed; /* a value read the request, and it is not known */
    mutable gboolean request_none;   /* a value read the request of a request: there is none (no note) */
    /* keys from the walk (dg_request_context.key_count 0), first pass: the
     * request is looked up when a value first reads it, with the keys decoded so far */
    mutable gboolean request_pending;
    guint message;                   /* the message's number within the frame */
    /* Last, not cleared per message (an entry is written when its list
     * opens, before anything reads it): where each list of siblings being
     * decoded started (the message, then each open container), for peeks and
     * offsets counted from a container, and where each ends (a peek reads
     * nothing beyond). */
    gint list_starts[DG_MAX_LISTS];
    gint list_ends[DG_MAX_LISTS];
};

/* --- dissgen_walk.cpp ---------------------------------------------------- */

/* How computed values, findings and learns read fields, the request and
 * what was learned (dissgen_expr.h). */
extern const dg_expr_readers message_readers;

/* Reports a malformed spot at `offset` (clamped into the packet) and stops decoding. */
void report(dg_state *st, proto_tree *tree, expert_field *ei, gint offset, gint length, const char *format, ...)
    G_GNUC_PRINTF(6, 7);

/* pdulength: the length of the stream message at offset that its length
 * field gives (with pdulengthadd; a varint's counts from its own end), and in
 * *header the bytes up to the end of that field. DG_STREAM_LENGTH_MORE when a
 * varint length is not all there yet, DG_STREAM_LENGTH_BAD when it never ends
 * (its 10 bytes all say another follows). */
enum { DG_STREAM_LENGTH_MORE = -1, DG_STREAM_LENGTH_BAD = -2 };
gint64 stream_message_length(const dg_protocol *p, tvbuff_t *tvb, int offset, guint *header);
/* The fewest bytes up to the end of the length field: a varint has 1 at least. */
static inline guint stream_header_length(const dg_protocol *p)
{
    const dg_node *n = &p->nodes[p->pdu_node];
    return p->pdu_offset + (n->show == DG_SHOW_VARINT ? 1 : n->length);
}

/* Whether bytes needed up to needed_end are missing only because the capture
 * kept less of the frame than was on the wire (a snapshot length): the data
 * ran out at the captured end (data_end), and the frame's length on the wire
 * reaches needed_end. Such a frame is not malformed. */
static inline gboolean cut_by_capture(const dg_state *st, gint64 data_end, gint64 needed_end)
{
    const gint64 on_wire = (gint64)tvb_reported_length(st->tvb);
    return data_end >= st->packet_end && st->packet_end < on_wire && needed_end <= on_wire;
}

/* Stops decoding where the captured bytes end, as Wireshark shows a frame cut
 * by the snapshot length ("[Packet size limited during capture]", once per
 * message): no expert info, the frame is not malformed. */
void capture_cut(dg_state *st, proto_tree *tree);

/* Data that ran out at data_end where a node needed it up to needed_end: the
 * capture's cut (cut_by_capture), the fault of an enclosing length already
 * reported (st->told_end: decoding stops, nothing more is told), or a
 * malformed spot reported as report() does. */
void report_missing(dg_state *st, proto_tree *tree, expert_field *ei, gint64 data_end, gint64 needed_end, gint offset,
                    gint length, const char *format, ...) G_GNUC_PRINTF(8, 9);

/* One instance of n (a leaf or a container) at *offset, before end; sink
 * gathers the Info column text of a repeated node's instances, or NULL. */
void dissect_instance(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end,
                      gboolean in_summary, dg_summaries *sink);

/* A selected member of a list that dissect_child() does not decode inline:
 * an overlay, the instances of a repeated or located node, or one instance. */
void dissect_node(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary);

/* DISSGEN_TABLE_WALK set when the plugin registered: containers walk their
 * children and build their summaries from the tables even when the generator
 * compiled them (to compare the two; tests/integration/language/test_compiled_walk.py). */
extern gboolean table_walk_only;

/* P.padding (dissgen_names.h): registered with the protocol, added by containers. */
extern int hf_padding;

/* --- dissgen_conditions.cpp ---------------------------------------------- */

/* The value of a length or count reference, or FALSE (reported) when it is
 * missing or negative. */
gboolean ref_value(dg_state *st, const dg_ref *ref, const dg_node *n, const char *what, proto_tree *tree,
                   gint offset, gint64 *out);

/* The table of the offset leaf in `slot`, allocated on first use. */
dg_table *table_of(dg_state *st, gint16 slot);
void table_append(dg_state *st, const dg_node *n, guint64 value);
/* keep_instances: the value of the current instance (st->instance). */
void table_put(dg_state *st, const dg_node *n, guint64 value);
/* An offset leaf's repetition starts a new, empty table. */
void table_reset(dg_state *st, const dg_node *n, gint offset);

/* The value of the leaf a <when peek> reads ahead from node_start, when its
 * bytes are there. */
enum { DG_PEEK_ABSENT = 0, DG_PEEK_VALUE = 1, DG_PEEK_CUT = -1 /* past the bytes the capture kept */ };
gint peek_value(const dg_state *st, const dg_peek *pk, gint node_start, guint64 *out);

/* A window's children, at addresses: dg_node.window. */
void dissect_window(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary);

/* --- dissgen_text.cpp ---------------------------------------------------- */

/* A datetime leaf's time from its `length` bytes at offset, by its unit. */
nstime_t datetime_at(const dg_state *st, const dg_node *n, gint offset, gint length);
/* The name an enum's value_string, val64_string or range_string gives the value, or NULL. */
const char *enum_name(const header_field_info *hfi, guint64 value);
/* The hex digits a number of n is shown with: as many as its bits need; a
 * 64-bit field whose values vary in width (a length from a field, a
 * computed value) shows the digits the value needs, in whole bytes, rather
 * than sixteen for every value. */
static inline guint hex_digits(const dg_node *n, guint64 value)
{
    if (n->bits < 64 || (n->length_kind != DG_LEN_FIELD && n->length_kind != DG_LEN_COMPUTED)) return (n->bits + 3) / 4;
    guint digits = 2;
    while (digits < 16 && (value >> (4 * digits)) != 0) digits += 2;
    return digits;
}
/* A hex or enum item of such a field, with that many digits. */
proto_item *add_variable_hex(const dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint length,
                             guint64 value);
/* A number as its field's tree item shows it, without an enum name or a unit
 * label: decimal, signed decimal, or hex with as many digits as its bits need
 * (dissgen_text.cpp). */
void append_number(dg_text *out, const dg_node *n, guint64 value);

/* The summary of container n, in st->text (valid until the next summary). */
const char *summary_text(const dg_state *st, const dg_node *n);

/* Appends a leaf's value as its tree item shows it, with its unit label (a
 * compiled summary's value). */
void append_shown_value(const dg_state *st, dg_text *out, const dg_slot *s);
/* Appends the summary pieces [first, first + count): a <finding>'s text. */
void append_text_pieces(const dg_state *st, dg_text *out, guint first, guint count);

void info_append(dg_state *st, const char *text, gsize len);

/* Info column text of a repeated node's summarised instances: gathered in
 * *s while they are decoded (when summaries_begin says so), then added. */
gboolean summaries_begin(const dg_state *st, const dg_node *n, gboolean in_summary, dg_summaries *s);
void summaries_end(dg_state *st, const dg_node *n, const dg_summaries *s);

/* --- dissgen_handoff.cpp ------------------------------------------------- */

/* A leaf with dissector= or reassemble-*: its bytes (or, once reassembled,
 * the whole message) go to the named dissector, or are shown raw. */
void dissect_handoff(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint len);

/* The most bytes a varint has: 10 hold 70 bits, enough for 64. */
#define DG_VARINT_MOST_BYTES 10

/* The varint in the `len` captured bytes at offset (Wireshark's
 * tvb_get_varint): FALSE when it does not end in them or holds more than 64
 * bits (a 10th byte above 1), which tvb_get_varint would silently drop. */
static inline gboolean dg_read_varint(tvbuff_t *tvb, gint offset, gint len, guint64 *value)
{
    if (tvb_get_varint(tvb, (guint)offset, (guint)len, value, ENC_VARINT_PROTOBUF) != (guint)len) return FALSE;
    return len < DG_VARINT_MOST_BYTES || dg_tvb_get_uint8(tvb, offset + len - 1) <= 1;
}

/* After every plugin's handoff: the dissectors that dissector= names, the
 * reassembled sources' names. */
void find_handoff_dissectors(const dg_protocol *p);

/* --- dissgen_learned.cpp ------------------------------------------------- */

/* The evaluator's reader of learned{...} values (dissgen_expr.h). */
gboolean read_learned(const void *context, gint16 index, guint64 *value);
/* n's <learn>s, once an instance of it is decoded (first pass). */
void learn_values(dg_state *st, const dg_node *n);
/* At registration, for a protocol with <learn>s. */
void learned_register(const dg_protocol *p);

/* --- dissgen_request.cpp ------------------------------------------------- */

/* Before the walk: the request this message answers, or none (st->request);
 * with keys from the walk, on the first pass, it is looked up later. */
void request_begin(dg_state *st);
/* After the walk, before the pairing (first pass, keys from the walk): a
 * message that read no request value looks its request up now, so that later
 * passes, which may decode more of it, read the same. */
void request_walked(dg_state *st);
/* After the walk and the pairing: a request keeps its values (first pass);
 * a message that read an unknown request says so. */
void request_end(dg_state *st, const dg_frame_pairing *fp, proto_tree *tree);
/* The evaluator's reader of request{...} values (dissgen_expr.h). */
gboolean read_request(const void *context, gint16 index, guint64 *value);

/* --- dissgen_register.cpp ------------------------------------------------ */

extern int stats_tap; /* the protocol's tap, -1 before registration */

/* --- inline: run for every field ----------------------------------------- */

static inline void key_append(dg_state *st, guint64 value)
{
    if (st->key_count == st->key_capacity) {
        st->key_capacity = st->key_capacity ? 2 * st->key_capacity : 16;
        st->keys = (guint64 *)wmem_realloc(st->pinfo->pool, st->keys, st->key_capacity * sizeof(guint64));
    }
    st->keys[st->key_count++] = value;
}

/* An input of the pairing analysis: where the walk found it and its value. */
static inline void view_append(dg_state *st, const dg_node *n, guint64 value, gint offset, gint length)
{
    if (st->view_count == st->view_capacity) {
        st->view_capacity = st->view_capacity ? 2 * st->view_capacity : 32;
        st->views = (dg_view_value *)wmem_realloc(st->pinfo->pool, st->views,
                                                  st->view_capacity * sizeof(dg_view_value));
    }
    dg_view_value *v = &st->views[st->view_count++];
    v->value = value;
    v->offset = offset;
    v->length = (guint16)length;
    v->input = (guint8)n->extra->input;
    v->instance = st->instance;
}

/* A signature field shown as text, an address or bytes: its bytes, in the
 * packet's pool, and their hash for its value. NULL when the capture cut
 * them short (the message then has no value for it). */
static inline const guint8 *signature_bytes(dg_state *st, gint offset, gint length, guint64 *hash)
{
    if (length < 0 || !tvb_bytes_exist(st->tvb, offset, length)) return NULL;
    const guint8 *b = length ? (const guint8 *)tvb_memdup(st->pinfo->pool, st->tvb, offset, length)
                             : (const guint8 *)"";
    *hash = fnv1a64(14695981039346656037ull ^ (guint64)length, b, (gsize)length);
    return b;
}

/* Room for twice as many signature values: the arrays start on the stack
 * (dg_message_buffers), and move to pinfo->pool when a message has more. */
static inline void grow_cycle_input(dg_state *st)
{
    dg_cycle_input *in = &st->cycle;
    const guint old = st->cycle_capacity, c = 2 * old; /* begin_message gave the first */
    wmem_allocator_t *pool = st->pinfo->pool;
    if (st->cycle_on_stack) {
        in->values = (guint64 *)wmem_memdup(pool, in->values, old * sizeof(guint64));
        in->nodes = (guint16 *)wmem_memdup(pool, in->nodes, old * sizeof(guint16));
        in->bytes = (const guint8 **)wmem_memdup(pool, in->bytes, old * sizeof(const guint8 *));
        in->lengths = (guint32 *)wmem_memdup(pool, in->lengths, old * sizeof(guint32));
        st->cycle_on_stack = FALSE;
    }
    in->values = (guint64 *)wmem_realloc(pool, in->values, c * sizeof(guint64));
    in->nodes = (guint16 *)wmem_realloc(pool, in->nodes, c * sizeof(guint16));
    in->bytes = (const guint8 **)wmem_realloc(pool, in->bytes, c * sizeof(const guint8 *));
    in->lengths = (guint32 *)wmem_realloc(pool, in->lengths, c * sizeof(guint32));
    st->cycle_capacity = c;
}

/* A leaf the cycle analysis reads (dg_extra.cycle_role), first pass. */
static inline void cycle_record(dg_state *st, const dg_node *n, guint64 value, gint offset, gint length)
{
    const dg_extra *x = n->extra;
    dg_cycle_input *in = &st->cycle;
    if (x->cycle_role == DG_CYCLE_SIGNATURE) {
        const guint8 *bytes = NULL;
        if (!(n->flags & DG_NUMERIC) && !(bytes = signature_bytes(st, offset, length, &value))) return;
        if (in->count == st->cycle_capacity) grow_cycle_input(st);
        in->values[in->count] = value;
        in->bytes[in->count] = bytes;
        in->lengths[in->count] = bytes ? (guint32)length : 0;
        in->nodes[in->count++] = (guint16)(n - st->p->nodes);
        return;
    }
    if (x->cycle_role == DG_CYCLE_SEQUENCE) {
        in->sequence = value;
        in->has_sequence = TRUE;
        return;
    }
    const dg_cycles *c = st->p->cycles;
    const dg_cycle_test *t = &c->tests[x->cycle_test];
    if (!in_ranges(c->ranges, t->range_first, t->range_count, value)) return;
    if (x->cycle_role == DG_CYCLE_ONLY)
        in->only_held |= (guint32)1 << x->cycle_test;
    else
        in->never = TRUE;
}

/* Whether the cycle analysis reads this leaf, in this pass. */
static inline __attribute__((always_inline)) gboolean is_cycle_input(const dg_state *st, const dg_node *n)
{
    return st->wants_cycles && n->extra && n->extra->cycle_role;
}

/* Whether the pairing analysis reads this leaf, in this pass. */
static inline __attribute__((always_inline)) gboolean is_view_input(const dg_state *st, const dg_node *n)
{
    return st->wants_view && n->extra && n->extra->input >= 0;
}

static inline void tap_record(dg_state *st, const dg_node *n, guint64 value)
{
    dg_tap_data *t = st->tap;
    if (t->count == t->capacity) {
        t->capacity = t->capacity ? 2 * t->capacity : 16;
        t->records = (dg_tap_record *)wmem_realloc(st->pinfo->pool, t->records, t->capacity * sizeof(dg_tap_record));
    }
    t->records[t->count].node = (guint16)(n - st->p->nodes);
    t->records[t->count].value = value;
    t->count++;
}

/* Whether the message decoded the field of r (<request>, <unanswered>) with
 * a value in its ranges. */
static inline gboolean role_holds(const dg_state *st, const dg_request_role *r)
{
    return in_ranges(r->ranges, 0, r->range_count, st->slots[r->slot].value);
}

/* <unanswered>: a message that expects no response (a notification) asks
 * nothing, answers nothing and reads no request. */
static inline gboolean takes_part_in_pairing(const dg_state *st, const dg_request_role *unanswered)
{
    return !unanswered || !st->present[unanswered->slot] || !role_holds(st, unanswered);
}

/* Keeps a decoded leaf's value where later nodes, the stats tree and the
 * pairing find it. */
static inline __attribute__((always_inline)) void store(dg_state *st, const dg_node *n, guint64 value, gint offset,
                                                        gint length)
{
    /* a repeated enum leaf is counted per message, by its instances (dissect_repeated) */
    if (st->tap && n->show == DG_SHOW_ENUM && !is_repeated(n)) tap_record(st, n, value);
    if (n->flags & DG_KEY) key_append(st, value);
    if (is_view_input(st, n)) view_append(st, n, value, offset, length);
    if (is_cycle_input(st, n)) cycle_record(st, n, value, offset, length);
    if (n->slot < 0) return;
    if (n->extra && n->extra->keep_values) table_append(st, n, value);
    if (n->extra && n->extra->keep_instances) table_put(st, n, value);
    dg_slot *s = &st->slots[n->slot];
    s->value = value;
    s->offset = offset;
    s->length = length;
    s->node = n;
    st->present[n->slot] = TRUE;
    if (n->extra && n->extra->kept_count)
        for (guint8 i = 0; i < n->extra->kept_count; i++) {
            st->slots[n->extra->kept_slots[i]] = *s;
            st->present[n->extra->kept_slots[i]] = TRUE;
        }
}

/* Whether store() uses a leaf's value: a later node reads it (slot) or the
 * stats tree counts it. Otherwise the walk need not read it from the tvb. */
static inline __attribute__((always_inline)) gboolean value_wanted(const dg_state *st, const dg_node *n)
{
    return n->slot >= 0 || (st->tap && n->show == DG_SHOW_ENUM) || (n->flags & DG_KEY) || is_view_input(st, n) ||
           is_cycle_input(st, n);
}

/* A new instance: the values of the previous one's subtree are gone. */
static inline void clear_slots(dg_state *st, const dg_node *n)
{
    if (n->slot_count) memset(&st->present[n->slot_first], 0, n->slot_count);
}

/* Whether the value of n's if="..." field was decoded and is in its ranges. */
static inline __attribute__((always_inline)) gboolean condition_holds(const dg_state *st, const dg_conditions *c,
                                                                      const dg_node *n)
{
    return st->present[n->if_slot] && in_ranges(c->ranges, n->in_first, n->in_count, st->slots[n->if_slot].value);
}

/* Whether every <when> of n holds; node_start is where n would begin. */
static inline __attribute__((always_inline)) gboolean whens_hold(dg_state *st, const dg_conditions *c,
                                                                 const dg_node *n, gint node_start)
{
    /* unrolled: with a constant node, each <when> folds to its comparisons */
#pragma GCC unroll 8
    for (guint i = 0; i < n->when_count; i++) {
        const dg_when *w = &c->whens[n->when_first + i];
        guint64 value;
        if (w->peek >= 0) {
            gint peeked = peek_value(st, &st->p->peeks[w->peek], node_start, &value);
            if (G_UNLIKELY(peeked == DG_PEEK_CUT)) st->peek_cut = TRUE; /* undecidable: nothing after is known */
            if (peeked != DG_PEEK_VALUE) return FALSE;
        } else {
            const dg_slot *s = &st->slots[w->slot];
            if (!st->present[w->slot]) return FALSE;
            value = s->value;
        }
        if (!in_ranges(c->ranges, w->in_first, w->in_count, value)) return FALSE;
    }
    return TRUE;
}

/* Whether n is decoded at `offset`. *chain_taken says whether a member of the
 * current chain of alternatives (a conditional node and the otherwise nodes
 * after it) was decoded; an otherwise node is skipped when one was. With a
 * constant node and constant conditions, as in compiled walks, only the tests
 * the node has are left, each its comparisons with constants. */
static inline __attribute__((always_inline)) gboolean selected(dg_state *st, const dg_conditions *c,
                                                               const dg_node *n, gint offset, gboolean *chain_taken)
{
    const guint8 direction = n->extra ? n->extra->direction : (guint8)DG_DIR_ANY;
    const gboolean otherwise = (n->alt & DG_ALT_OTHERWISE) != 0;
    if (!otherwise && !n->hook_count && n->if_slot < 0 && !n->when_count && !direction) {
        *chain_taken = FALSE; /* unconditional: ends any chain */
        return TRUE;
    }
    if (otherwise && *chain_taken) return FALSE;
    /* a member of a chain: decoded when its conditions hold */
    gboolean holds = (!n->hook_count || in_ranges(c->ranges, n->hook_first, n->hook_count, st->hook_value)) &&
                     (n->if_slot < 0 || condition_holds(st, c, n)) && (!direction || direction == st->direction) &&
                     whens_hold(st, c, n, offset);
    *chain_taken = holds;
    return holds;
}

/* --- inline: one member of a list of siblings ---------------------------- */

/* A numeric leaf's item from its bytes already read (a bit group's
 * whole value: Wireshark masks and shifts it by the field's bitmask), which
 * costs Wireshark about a third less than proto_tree_add_item() reading them
 * again. Unsigned and boolean displays only; the others are added from the
 * bytes. */
static inline proto_item *add_numeric_item(const dg_state *st, const dg_node *n, proto_tree *tree, gint offset,
                                           gint length, guint64 raw)
{
    switch (n->show) {
    case DG_SHOW_HEX: case DG_SHOW_DEC: case DG_SHOW_ENUM:
        return length <= 4 ? proto_tree_add_uint(tree, *n->hf, st->tvb, offset, length, (guint32)raw)
                           : proto_tree_add_uint64(tree, *n->hf, st->tvb, offset, length, raw);
    case DG_SHOW_BOOL: /* Wireshark's boolean API takes 32 bits */
        if (length <= 4) return proto_tree_add_boolean(tree, *n->hf, st->tvb, offset, length, (guint32)raw);
        return proto_tree_add_item(tree, *n->hf, st->tvb, offset, length, encoding_of(n));
    default:
        return proto_tree_add_item(tree, *n->hf, st->tvb, offset, length, encoding_of(n));
    }
}

/* The first member of a bit group reads the group's bytes; FALSE when they are not all there. */
static inline __attribute__((always_inline)) gboolean group_read(dg_state *st, const dg_node *n, proto_tree *tree,
                                                                 gint offset, gint end)
{
    if (!(n->flags & DG_GROUP_FIRST)) return TRUE;
    if ((gint)n->length > end - offset) {
        report_missing(st, tree, &st->p->ei->truncated, end, (gint64)offset + n->length, offset, -1,
                       "Truncated: '%s' needs %u bytes, only %d left", n->name, n->length, end - offset);
        return FALSE;
    }
    st->group_value = read_uint(st->tvb, offset, n->length, encoding_of(n));
    return TRUE;
}

/* A member of a bit group: the first reads the group's bytes, each adds
 * its item and keeps its bits, the last moves past the bytes. */
static inline __attribute__((always_inline)) void dissect_bit_field(dg_state *st, const dg_node *n, proto_tree *tree,
                                                                    gint *offset, gint end)
{
    if (!group_read(st, n, tree, *offset, end)) return;
    /* No tree (e.g. tshark's summary lines): only values later nodes read are
     * wanted. proto_tree_add_item() would check the length and return NULL. */
    if (tree) {
        proto_item *item = add_numeric_item(st, n, tree, *offset, (gint)n->length, st->group_value);
        if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
    }
    if (value_wanted(st, n)) store(st, n, bit_field(st->group_value, n->shift, n->bits), *offset, n->length);
    if (n->flags & DG_GROUP_LAST) *offset += n->length;
}

/* A member of a bit group whose condition does not hold: no item and no
 * value, but the group's bytes are read and passed as if it were there. */
static inline __attribute__((always_inline)) void pass_bit_field(dg_state *st, const dg_node *n, proto_tree *tree,
                                                                 gint *offset, gint end)
{
    if (group_read(st, n, tree, *offset, end) && (n->flags & DG_GROUP_LAST)) *offset += n->length;
}

/* The value and item of a numeric leaf (not a time or an address) whose
 * `len` bytes at offset are all there. */
static inline __attribute__((always_inline)) void decode_number(dg_state *st, const dg_node *n, proto_tree *tree,
                                                                gint offset, gint len)
{
    guint64 value = 0;
    if (tree || value_wanted(st, n)) value = read_uint(st->tvb, offset, (guint)len, encoding_of(n));
    if (tree) {
        proto_item *item = add_numeric_item(st, n, tree, offset, len, value);
        if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
    }
    store(st, n, value, offset, len);
}

/* A leaf decoded once, with nothing but its bytes: decoded inline. */
static inline __attribute__((always_inline)) gboolean is_plain_leaf(const dg_node *n)
{
    return n->kind == DG_LEAF && !n->extra && n->count.slot < 0 && n->repeat_slot < 0;
}

static inline __attribute__((always_inline)) gboolean is_plain_number(const dg_node *n)
{
    return is_plain_leaf(n) && !(n->flags & DG_GROUP) && (n->flags & DG_NUMERIC) && n->length_kind == DG_LEN_FIXED &&
           n->show != DG_SHOW_TIME && n->show != DG_SHOW_IPV4;
}

/* Whether a walk nobody sees (no tree, no tap listener) may step over n in
 * the `bytes` it has: n feeds nothing (dg_node.quiet_size) and cannot be
 * malformed within them. */
static inline __attribute__((always_inline)) gboolean quiet_within(const dg_state *st, const dg_node *n, gint64 bytes)
{
    return st->quiet && n->quiet_size && (gint64)n->quiet_size <= bytes;
}

/* One member of a list of siblings at *offset, before end, when it is
 * selected (*chain_taken: see selected()). Bit fields and fixed numbers
 * inline, the rest out of line. Generated code calls it with each member
 * of a list (a constant node and conditions: the tests fold away), the table
 * walk in a loop. */
static inline __attribute__((always_inline)) void dissect_child(dg_state *st, const dg_conditions *c, const dg_node *n,
                                                                proto_tree *tree, gint *offset, gint end,
                                                                gboolean in_summary, gboolean *chain_taken)
{
    if (!selected(st, c, n, *offset, chain_taken)) {
        if (G_UNLIKELY(st->peek_cut)) { /* which alternative holds is in bytes the capture did not keep */
            capture_cut(st, tree);
            return;
        }
        if (n->flags & DG_GROUP) pass_bit_field(st, n, tree, offset, end); /* its bits stay in the group */
        return;
    }
    if (quiet_within(st, n, end - *offset)) {
        *offset += (gint)n->quiet_size; /* nobody would see it, and it cannot be malformed */
        return;
    }
    if (is_plain_leaf(n) && (n->flags & DG_GROUP)) {
        dissect_bit_field(st, n, tree, offset, end);
    } else if (is_plain_number(n) && (gint)n->length <= end - *offset) {
        decode_number(st, n, tree, *offset, (gint)n->length);
        *offset += (gint)n->length;
    } else {
        dissect_node(st, n, tree, offset, end, in_summary);
    }
}

/* A list of siblings starts at offset and ends at end (for peeks and
 * offsets counted from a container), and ends. */
static inline __attribute__((always_inline)) void list_begin(dg_state *st, gint offset, gint end)
{
    if (st->lists < DG_MAX_LISTS) {
        st->list_starts[st->lists] = offset;
        st->list_ends[st->lists] = end;
    }
    st->lists++;
}

static inline __attribute__((always_inline)) void list_end(dg_state *st) { st->lists--; }

/* The encoding a non-numeric leaf's item is added with. */
static inline guint item_encoding(const dg_node *n)
{
    switch (n->show) {
    case DG_SHOW_STRING: case DG_SHOW_STRINGZ: return n->extra ? n->extra->encoding : ENC_UTF_8;
    case DG_SHOW_IPV4: case DG_SHOW_FLOAT: case DG_SHOW_GUID: case DG_SHOW_EUI64: return encoding_of(n);
    case DG_SHOW_DATETIME: return encoding_of(n) | (n->extra ? n->extra->time_encoding : ENC_TIME_SECS_NSECS);
    default: return ENC_NA;
    }
}

} // namespace dg_rt

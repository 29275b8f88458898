// SPDX-License-Identifier: GPL-2.0-or-later
/* The table walk behind every dissgen-generated dissector.
 *
 * Wireshark's exceptions are longjmps that skip C++ destructors, so nothing
 * here owns a non-trivial C++ object; memory comes from pinfo->pool. Every
 * read is checked against the bytes left first, so no tvb_ or proto_ call
 * can throw: malformed packets end in an expert info instead.
 */
#include "dissgen_runtime.h"

#include "dissgen_pairing.h"

#include <epan/proto_data.h>
#include <epan/stats_tree.h>
#include <epan/tap.h>

#include <float.h>
#include <stdlib.h>
#include <string.h>

namespace {

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

/* Each plugin links its own copy of the runtime and holds one protocol, so
 * the stats tree callbacks (which get no user pointer) find it here. */
const dg_protocol *stats_protocol;
int stats_tap = -1;

/* Every value of an offset leaf (extra->keep_values) in this
 * message, in instance order; reset when its repetition starts. */
struct dg_table {
    guint64 *values;
    guint count, capacity;
    gboolean overflow; /* more than DG_MAX_TABLE instances */
};

/* Text being built (summaries, the Info column): a buffer of the caller's
 * (on its stack) or in the packet pool, moved to the pool when it outgrows
 * it, with inline appends. wmem_strbuf_new() and its appends cost several
 * times more, and summary lines run this on every frame. */
struct dg_text {
    wmem_allocator_t *pool;
    char *data;   /* NUL-terminated */
    gsize len, cap;
};

/* A text in `buf` (the caller's, usually on its stack) until it outgrows it. */
void text_init(dg_text *t, wmem_allocator_t *pool, char *buf, gsize cap)
{
    t->pool = pool;
    t->data = buf;
    t->data[0] = '\0';
    t->len = 0;
    t->cap = cap;
}

/* One allocation: the struct and a first buffer that most texts never outgrow. */
dg_text *text_new(wmem_allocator_t *pool)
{
    const gsize first = 120;
    dg_text *t = (dg_text *)wmem_alloc(pool, sizeof(dg_text) + first);
    text_init(t, pool, (char *)(t + 1), first);
    return t;
}

void text_grow(dg_text *t, gsize n)
{
    gsize cap = MAX(2 * t->cap, t->len + n + 1);
    char *bigger = (char *)wmem_alloc(t->pool, cap);
    memcpy(bigger, t->data, t->len + 1);
    t->data = bigger; /* the old buffer goes with the pool */
    t->cap = cap;
}

/* Inlined: it runs for every piece of every summary. */
inline __attribute__((always_inline)) void text_append(dg_text *t, const char *s, gsize n)
{
    if (G_UNLIKELY(t->len + n >= t->cap)) text_grow(t, n);
    memcpy(t->data + t->len, s, n);
    t->len += n;
    t->data[t->len] = '\0';
}

void text_truncate(dg_text *t, gsize len)
{
    if (len < t->len) {
        t->len = len;
        t->data[len] = '\0';
    }
}

/* Summaries of one repeated node's instances, gathered for the Info column
 * (in `buf` on the caller's stack until they outgrow it). */
struct dg_summaries {
    dg_text text;
    char buf[256];
    guint count;
};

#define DG_MAX_LISTS 80 /* nesting is at most 64 levels (parser.h kMaxNesting) */

struct dg_state {
    const dg_protocol *p;
    tvbuff_t *tvb;
    packet_info *pinfo;
    dg_slot *slots;
    guint8 *present;      /* per slot: decoded in this message (instance) */
    dg_table *tables;     /* offset tables: per slot, allocated at the first offset leaf */
    gint packet_end;      /* captured bytes */
    gboolean stopped;     /* a malformed spot was reported: decode nothing more */
    gboolean want_text;   /* summaries are shown: a visible tree, or columns */
    gboolean want_info;   /* the Info column is shown (pinfo->cinfo) */
    gboolean quiet;       /* no tree, no tap listener: step over quiet nodes (dg_node.quiet_size) */
    dg_text *info;  /* the Info column being built (want_info) */
    dg_text *text;  /* scratch for one container's summary (want_text) */
    guint64 group_value;  /* the bit group being decoded */
    guint32 hook_value;   /* pinfo->match_uint on entry: the hook (or Decode As) value, for ifhook */
    dg_tap_data *tap;     /* what the stats tree counts; NULL when nobody listens */
    guint8 direction;     /* DG_DIR_REQUEST/RESPONSE when a port hook matched, else DG_DIR_ANY */
    /* where each list of siblings being decoded started (the
     * message, then each open container), for peeks counted from a container */
    gint list_starts[DG_MAX_LISTS];
    gint list_ends[DG_MAX_LISTS]; /* and where each ends: a peek reads nothing beyond */
    guint lists;
    /* the values of the <pairing> key fields (DG_KEY), in decoding order */
    guint64 *keys;
    guint key_count, key_capacity;
};

void key_append(dg_state *st, guint64 value)
{
    if (st->key_count == st->key_capacity) {
        st->key_capacity = st->key_capacity ? 2 * st->key_capacity : 16;
        st->keys = (guint64 *)wmem_realloc(st->pinfo->pool, st->keys, st->key_capacity * sizeof(guint64));
    }
    st->keys[st->key_count++] = value;
}

void tap_record(dg_state *st, const dg_node *n, guint64 value)
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

guint encoding_of(const dg_node *n) { return (n->flags & DG_LITTLE) ? ENC_LITTLE_ENDIAN : ENC_BIG_ENDIAN; }

guint64 read_uint(tvbuff_t *tvb, gint offset, guint length, guint encoding)
{
    switch (length) {
    case 1: return dg_tvb_get_uint8(tvb, offset);
    case 2: return dg_tvb_get_uint16(tvb, offset, encoding);
    case 3: return dg_tvb_get_uint24(tvb, offset, encoding);
    case 4: return dg_tvb_get_uint32(tvb, offset, encoding);
    case 5: return dg_tvb_get_uint40(tvb, offset, encoding);
    case 6: return dg_tvb_get_uint48(tvb, offset, encoding);
    case 7: return dg_tvb_get_uint56(tvb, offset, encoding);
    default: return dg_tvb_get_uint64(tvb, offset, encoding);
    }
}

guint64 bit_mask(guint bits) { return bits >= 64 ? G_MAXUINT64 : ((G_GUINT64_CONSTANT(1) << bits) - 1); }

/* Reports a malformed spot at `offset` (clamped into the packet) and stops decoding. */
void report(dg_state *st, proto_tree *tree, expert_field *ei, gint offset, gint length, const char *format, ...)
    G_GNUC_PRINTF(6, 7);

void report(dg_state *st, proto_tree *tree, expert_field *ei, gint offset, gint length, const char *format, ...)
{
    if (offset > st->packet_end) offset = st->packet_end;
    if (length < 0 || offset + length > st->packet_end) length = st->packet_end - offset;
    st->stopped = TRUE;
    if (st->quiet) {
        /* No tree and no tap listener: nobody reads the text, but the
         * severity still goes to the Expert column and the capture's highest
         * severity, as Wireshark does for every expert info. */
        proto_tree_add_expert(tree, st->pinfo, ei, st->tvb, offset, length);
        return;
    }
    va_list ap;
    va_start(ap, format);
    char *text = wmem_strdup_vprintf(st->pinfo->pool, format, ap);
    va_end(ap);
    proto_tree_add_expert_format(tree, st->pinfo, ei, st->tvb, offset, length, "%s", text);
}

/* A reference's value with its arithmetic applied. Values beyond 2^31 are
 * past any packet's end anyway; clamping there keeps even "* 999999999" (the
 * largest operand the generator accepts) in range. */
gint64 ref_arith(const dg_slot *s, const dg_ref *ref)
{
    gint64 v = s->value > (G_GUINT64_CONSTANT(1) << 31) ? (G_GINT64_CONSTANT(1) << 31) : (gint64)s->value;
    switch (ref->op) {
    case '+': v += ref->operand; break;
    case '-': v -= ref->operand; break;
    case '*': v *= ref->operand; break;
    default: break;
    }
    return v;
}

/* The value of a length or count reference, or FALSE (reported) when it is
 * missing or negative. */
gboolean ref_value(dg_state *st, const dg_ref *ref, const dg_node *n, const char *what, proto_tree *tree,
                   gint offset, gint64 *out)
{
    const dg_slot *s = &st->slots[ref->slot];
    if (!st->present[ref->slot]) {
        report(st, tree, &st->p->ei->bad_length, offset, 0, "The %s of '%s' comes from a field that is not in this packet",
               what, n->name);
        return FALSE;
    }
    gint64 v = ref_arith(s, ref);
    if (v < 0) {
        report(st, tree, &st->p->ei->bad_length, offset, 0, "The %s of '%s' is negative (%" G_GINT64_MODIFIER "d)",
               what, n->name, v);
        return FALSE;
    }
    *out = v;
    return TRUE;
}

/* The table of the offset leaf in `slot`, allocated on first use. */
dg_table *table_of(dg_state *st, gint16 slot)
{
    if (!st->tables) st->tables = wmem_alloc0_array(st->pinfo->pool, dg_table, st->p->slot_count);
    return &st->tables[slot];
}

void table_append(dg_state *st, const dg_node *n, guint64 value)
{
    dg_table *t = table_of(st, n->slot);
    if (t->count == DG_MAX_TABLE) {
        t->overflow = TRUE;
        return;
    }
    if (t->count == t->capacity) {
        t->capacity = t->capacity ? MIN(2 * t->capacity, (guint)DG_MAX_TABLE) : 16;
        t->values = (guint64 *)wmem_realloc(st->pinfo->pool, t->values, t->capacity * sizeof(guint64));
    }
    t->values[t->count++] = value;
}

/* An offset leaf's repetition starts a new, empty table; the slot
 * says it is there, even when no instance follows (a count of 0). */
void table_reset(dg_state *st, const dg_node *n, gint offset)
{
    dg_table *t = table_of(st, n->slot);
    t->count = 0;
    t->overflow = FALSE;
    dg_slot *s = &st->slots[n->slot];
    s->value = 0;
    s->offset = offset;
    s->length = 0;
    s->node = n;
    st->present[n->slot] = TRUE;
}

inline __attribute__((always_inline)) void store(dg_state *st, const dg_node *n, guint64 value, gint offset,
                                                 gint length)
{
    if (st->tap && n->show == DG_SHOW_ENUM) tap_record(st, n, value);
    if (n->flags & DG_KEY) key_append(st, value);
    if (n->slot < 0) return;
    if (n->extra && n->extra->keep_values) table_append(st, n, value);
    dg_slot *s = &st->slots[n->slot];
    s->value = value;
    s->offset = offset;
    s->length = length;
    s->node = n;
    st->present[n->slot] = TRUE;
}

/* Whether store() uses a leaf's value: a later node reads it (slot) or the
 * stats tree counts it. Otherwise the walk need not read it from the tvb. */
gboolean value_wanted(const dg_state *st, const dg_node *n)
{
    return n->slot >= 0 || (st->tap && n->show == DG_SHOW_ENUM) || (n->flags & DG_KEY);
}

/* Whether value lies in one of the `count` ranges from ranges[first] on. */
gboolean in_ranges(const dg_protocol *p, guint16 first, guint16 count, guint64 value)
{
    for (guint i = 0; i < count; i++) {
        const dg_range *r = &p->ranges[first + i];
        if (value >= r->low && value <= r->high) return TRUE;
    }
    return FALSE;
}

gboolean condition_holds(const dg_state *st, const dg_node *n)
{
    const dg_slot *s = &st->slots[n->if_slot];
    return st->present[n->if_slot] && in_ranges(st->p, n->in_first, n->in_count, s->value);
}

/* Summary text is built with memcpy appends and hand-made numbers instead of
 * printf: it runs for every instance of a summarised container. */
void append_str(dg_text *out, const char *text) { text_append(out, text, strlen(text)); }

/* Same text as "%" G_GINT64_MODIFIER "u". */
void append_dec(dg_text *out, guint64 v)
{
    char buf[24];
    gsize i = sizeof buf;
    do {
        buf[--i] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    text_append(out, buf + i, sizeof buf - i);
}

/* Same text as "0x%0*" G_GINT64_MODIFIER "x" with width `digits` (at most 16 used). */
void append_hex(dg_text *out, guint64 v, guint digits)
{
    static const char hex[] = "0123456789abcdef";
    char buf[2 + 16];
    gsize i = sizeof buf;
    guint n = 0;
    do {
        buf[--i] = hex[v & 0xf];
        v >>= 4;
        n++;
    } while (v);
    for (; n < digits && n < 16; n++) buf[--i] = '0';
    buf[--i] = 'x';
    buf[--i] = '0';
    text_append(out, buf + i, sizeof buf - i);
}

/* The name an enum's value_string, val64_string or range_string gives the value, or NULL. */
const char *enum_name(const header_field_info *hfi, guint64 value)
{
    if (hfi->display & BASE_RANGE_STRING) return try_rval_to_str((guint32)value, (const range_string *)hfi->strings);
    if (hfi->display & BASE_VAL64_STRING) return try_val64_to_str(value, (const val64_string *)hfi->strings);
    return try_val_to_str((guint32)value, (const value_string *)hfi->strings);
}

/* A time leaf's count of units as an nstime. */
nstime_t time_of(const dg_node *n, guint64 value)
{
    guint64 per_second = n->extra && n->extra->units_per_second ? n->extra->units_per_second : 1000000000u;
    nstime_t t;
    t.secs = (time_t)(value / per_second);
    t.nsecs = (int)((value % per_second) * (1000000000u / per_second));
    return t;
}

/* The values of string, stringz, ipv4, int, float and time leaves,
 * for summaries and the Info column (as the tree item shows them). */
void append_typed_value(const dg_state *st, dg_text *out, const dg_slot *s)
{
    const dg_node *n = s->node;
    char buf[64];
    switch (n->show) {
    case DG_SHOW_STRING:
    case DG_SHOW_STRINGZ:
        if (s->length > 0)
            append_str(out, (const char *)tvb_get_string_enc(st->pinfo->pool, st->tvb, s->offset, s->length,
                                                             n->extra ? n->extra->encoding : ENC_UTF_8));
        return;
    case DG_SHOW_IPV4: {
        guint32 a = (guint32)s->value;
        g_snprintf(buf, sizeof buf, "%u.%u.%u.%u", a >> 24, (a >> 16) & 0xff, (a >> 8) & 0xff, a & 0xff);
        break;
    }
    case DG_SHOW_INT: {
        guint64 v = s->value;
        if (n->bits > 0 && n->bits < 64 && (v >> (n->bits - 1)) & 1) v |= ~bit_mask(n->bits);
        g_snprintf(buf, sizeof buf, "%" G_GINT64_MODIFIER "d", (gint64)v);
        break;
    }
    case DG_SHOW_FLOAT:
        if (s->length == 4)
            g_snprintf(buf, sizeof buf, "%.*g", FLT_DIG, tvb_get_ieee_float(st->tvb, s->offset, encoding_of(n)));
        else
            g_snprintf(buf, sizeof buf, "%.*g", DBL_DIG, tvb_get_ieee_double(st->tvb, s->offset, encoding_of(n)));
        break;
    case DG_SHOW_TIME: {
        nstime_t t = time_of(n, s->value);
        g_snprintf(buf, sizeof buf, "%" G_GINT64_MODIFIER "d.%09d seconds", (gint64)t.secs, t.nsecs);
        break;
    }
    default: return;
    }
    append_str(out, buf);
}

/* Appends a leaf's value as its tree item shows it, for summaries. */
void append_shown_value(const dg_state *st, dg_text *out, const dg_slot *s)
{
    wmem_allocator_t *pool = st->pinfo->pool;
    const dg_node *n = s->node;
    switch (n->show) {
    case DG_SHOW_HEX:
        append_hex(out, s->value, (n->bits + 3) / 4);
        return;
    case DG_SHOW_BOOL:
        append_str(out, s->value ? "True" : "False");
        return;
    case DG_SHOW_ENUM: {
        const char *name = enum_name(proto_registrar_get_nth(*n->hf), s->value);
        if (name) {
            append_str(out, name);
        } else {
            /* As the tree shows it: as many hex digits as the field's bits need. */
            text_append(out, "Unknown (", 9);
            append_hex(out, s->value, (n->bits + 3) / 4);
            text_append(out, ")", 1);
        }
        return;
    }
    /* An empty byte field (length 0 from a field, or 'rest' with nothing left)
     * shows nothing: tvb_bytes_to_str_punct() asserts len > 0. */
    case DG_SHOW_ADDRESS:
        if (s->length > 0) append_str(out, tvb_bytes_to_str_punct(pool, st->tvb, s->offset, s->length, ':'));
        return;
    case DG_SHOW_BYTES:
        if (s->length > 0) append_str(out, tvb_bytes_to_str_punct(pool, st->tvb, s->offset, s->length, ' '));
        return;
    case DG_SHOW_STRING: case DG_SHOW_STRINGZ: case DG_SHOW_IPV4: case DG_SHOW_INT: case DG_SHOW_FLOAT:
    case DG_SHOW_TIME:
        append_typed_value(st, out, s);
        return;
    default:
        if (n->flags & DG_NUMERIC)
            append_dec(out, s->value);
        else if (s->length > 0)
            append_str(out, tvb_bytes_to_str_punct(pool, st->tvb, s->offset, s->length, ' '));
        return;
    }
}

/* Whether every value an optional part shows itself (not those of the parts
 * inside it) was decoded: a part that is left out then costs no text. */
gboolean part_decoded(const dg_state *st, guint first, guint count)
{
    for (guint i = first; i < first + count; i++) {
        const dg_summary_piece *piece = &st->p->pieces[i];
        if (piece->group)
            i += piece->group;
        else if (piece->slot >= 0 && !st->present[piece->slot])
            return FALSE;
    }
    return TRUE;
}

/* Appends the `count` summary pieces from pieces[first] on; FALSE when a
 * placeholder among them showed nothing (not decoded, or empty), which drops
 * the optional part {?...} around it. Outside optional parts a value that was
 * not decoded shows as "-". */
gboolean append_pieces(const dg_state *st, dg_text *out, guint first, guint count)
{
    gboolean complete = TRUE;
    for (guint i = first; i < first + count; i++) {
        const dg_summary_piece *piece = &st->p->pieces[i];
        if (piece->group) {
            gsize mark = out->len;
            if (part_decoded(st, i + 1, piece->group) && !append_pieces(st, out, i + 1, piece->group))
                text_truncate(out, mark); /* a value with empty text */
            i += piece->group;
        } else if (piece->slot < 0) {
            append_str(out, piece->text);
        } else {
            const dg_slot *s = &st->slots[piece->slot];
            gsize before = out->len;
            if (!st->present[piece->slot]) {
                text_append(out, "-", 1);
                complete = FALSE;
                continue;
            }
            if (piece->node) {
                const dg_node *c = &st->p->nodes[piece->node - 1];
                append_pieces(st, out, c->summary_first, c->summary_count);
            } else {
                append_shown_value(st, out, s);
            }
            if (out->len == before) complete = FALSE;
        }
    }
    return complete;
}

/* The summary of container n, in st->text (valid until the next summary). */
const char *summary_text(const dg_state *st, const dg_node *n)
{
    dg_text *out = st->text;
    text_truncate(out, 0);
    append_pieces(st, out, n->summary_first, n->summary_count);
    return out->data;
}

/* The separator before the next item of the Info column, when there is one before it. */
void info_separate(dg_state *st)
{
    if (st->info->len > 0) text_append(st->info, ", ", 2);
}

void info_append(dg_state *st, const char *text, gsize len)
{
    info_separate(st);
    text_append(st->info, text, len);
}

void dissect_list(dg_state *st, guint16 first, guint16 count, proto_tree *tree, gint *offset, gint end,
                  gboolean in_summary);
void dissect_window(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary);

/* A numeric leaf's item from its bytes already read (a bit group's
 * whole value: Wireshark masks and shifts it by the field's bitmask), which
 * costs Wireshark about a third less than proto_tree_add_item() reading them
 * again. Unsigned displays only; the others are added from the bytes. */
proto_item *add_numeric_item(const dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint length,
                             guint64 raw)
{
    switch (n->show) {
    case DG_SHOW_HEX: case DG_SHOW_DEC: case DG_SHOW_ENUM:
        return length <= 4 ? proto_tree_add_uint(tree, *n->hf, st->tvb, offset, length, (guint32)raw)
                           : proto_tree_add_uint64(tree, *n->hf, st->tvb, offset, length, raw);
    default:
        return proto_tree_add_item(tree, *n->hf, st->tvb, offset, length, encoding_of(n));
    }
}

void dissect_bit_field(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end)
{
    if (n->flags & DG_GROUP_FIRST) {
        if ((gint)n->length > end - *offset) {
            report(st, tree, &st->p->ei->truncated, *offset, -1, "Truncated: '%s' needs %u bytes, only %d left",
                   n->name, n->length, end - *offset);
            return;
        }
        st->group_value = read_uint(st->tvb, *offset, n->length, encoding_of(n));
    }
    /* No tree (e.g. tshark's summary lines): only values later nodes read are
     * wanted. proto_tree_add_item() would check the length and return NULL. */
    if (tree) {
        proto_item *item = add_numeric_item(st, n, tree, *offset, (gint)n->length, st->group_value);
        if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
    }
    if (value_wanted(st, n)) store(st, n, (st->group_value >> n->shift) & bit_mask(n->bits), *offset, n->length);
    if (n->flags & DG_GROUP_LAST) *offset += n->length;
}

/* --- strings, hand-off to other dissectors, reassembly ------------------ */

/* The encoding a non-numeric leaf's item is added with. */
guint item_encoding(const dg_node *n)
{
    switch (n->show) {
    case DG_SHOW_STRING: case DG_SHOW_STRINGZ: return n->extra ? n->extra->encoding : ENC_UTF_8;
    case DG_SHOW_IPV4: case DG_SHOW_FLOAT: return encoding_of(n);
    default: return ENC_NA;
    }
}

/* Bytes from offset to the first NUL before end, NUL included; one more than
 * is left when there is none. */
gint64 stringz_length(const dg_state *st, gint offset, gint end)
{
    if (offset >= end) return 1;
    gint nul = dg_tvb_find_uint8(st->tvb, offset, end - offset, 0);
    return nul < 0 ? (gint64)(end - offset) + 1 : (gint64)(nul - offset) + 1;
}

/* Per node: the handle its dissector= names (NULL: absent from this Wireshark,
 * the bytes are shown raw), and the name of its reassembled data source.
 * Filled at handoff; one protocol per plugin, like stats_protocol. */
dissector_handle_t *handoff_handles;
char **reassembled_names;

/* Gives tvb to the leaf's dissector. Its exceptions end its own tree, not our
 * walk (show_exception, as Wireshark's dissectors do), and it may not
 * rewrite our Protocol and Info columns. */
void call_handoff(dg_state *st, dissector_handle_t handle, tvbuff_t *tvb, proto_tree *tree)
{
    packet_info *pinfo = st->pinfo;
    gboolean writable = col_get_writable(pinfo->cinfo, COL_INFO);
    col_set_writable(pinfo->cinfo, -1, FALSE);
    TRY {
        call_dissector(handle, tvb, pinfo, tree);
    }
    CATCH_NONFATAL_ERRORS {
        show_exception(tvb, pinfo, tree, EXCEPT_CODE, GET_MESSAGE);
    }
    ENDTRY;
    col_set_writable(pinfo->cinfo, -1, writable);
}

/* A slot's value, or FALSE (an expert info, decoding goes on) when the field
 * is not in this packet. */
gboolean reassembly_value(dg_state *st, const dg_node *n, gint16 slot, proto_tree *tree, gint offset, guint64 *out)
{
    const dg_slot *s = &st->slots[slot];
    if (!st->present[slot]) {
        proto_tree_add_expert_format(tree, st->pinfo, &st->p->ei->bad_length, st->tvb, offset, 0,
                                     "'%s' cannot be reassembled: a field it needs is not in this packet", n->name);
        return FALSE;
    }
    *out = s->value;
    return TRUE;
}

/* Adds the fragment in tvb[offset, offset+len) to its message; returns the
 * whole message in the frame that completes it, NULL otherwise. */
tvbuff_t *add_fragment(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint len)
{
    const dg_extra *x = n->extra;
    const dg_protocol *p = st->p;
    guint64 id = 0, number = 0, flag = 0;
    gint64 frag_offset = 0;
    if (!reassembly_value(st, n, x->reassemble_id, tree, offset, &id)) return NULL;
    if (x->reassemble_seq >= 0 && !reassembly_value(st, n, x->reassemble_seq, tree, offset, &number)) return NULL;
    if (x->reassemble_offset.slot >= 0 &&
        !ref_value(st, &x->reassemble_offset, n, "fragment offset", tree, offset, &frag_offset))
        return NULL;
    gint16 flag_slot = x->reassemble_last >= 0 ? x->reassemble_last : x->reassemble_more;
    if (!reassembly_value(st, n, flag_slot, tree, offset, &flag)) return NULL;
    gboolean more = x->reassemble_last >= 0 ? flag == 0 : flag != 0;
    if (frag_offset > G_MAXINT32 || number > G_MAXUINT16) {
        proto_tree_add_expert_format(tree, st->pinfo, &p->ei->bad_length, st->tvb, offset, len,
                                     "'%s': fragment offset or number out of range", n->name);
        return NULL;
    }
    packet_info *pinfo = st->pinfo;
    gboolean save_fragmented = pinfo->fragmented;
    pinfo->fragmented = TRUE;
    fragment_head *head = x->reassemble_seq >= 0
        ? fragment_add_seq_check(p->reassembly, st->tvb, offset, pinfo, (guint32)id, NULL, (guint32)number,
                                 (guint32)len, more)
        : fragment_add_check(p->reassembly, st->tvb, offset, pinfo, (guint32)id, NULL, (guint32)frag_offset,
                             (guint32)len, more);
    tvbuff_t *whole = process_reassembled_data(st->tvb, offset, pinfo, reassembled_names[n - p->nodes], head,
                                               p->fragments, NULL, tree);
    pinfo->fragmented = save_fragmented;
    return whole;
}

/* A leaf with dissector= or reassemble-*: its bytes (or, once reassembled,
 * the whole message) go to the named dissector, or are shown raw. */
void dissect_handoff(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint len)
{
    dissector_handle_t handle = handoff_handles ? handoff_handles[n - st->p->nodes] : NULL;
    tvbuff_t *payload;
    if (n->extra->reassemble_id >= 0 && st->p->reassembly) {
        if (tree) { /* the fragment itself */
            proto_item *item = proto_tree_add_item(tree, *n->hf, st->tvb, offset, len, item_encoding(n));
            if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
        }
        payload = add_fragment(st, n, tree, offset, len);
        if (!payload) return;
        if (!handle) {
            proto_tree_add_item(tree, *n->hf, payload, 0, -1, item_encoding(n));
            return;
        }
    } else {
        proto_item *item = tree ? proto_tree_add_item(tree, *n->hf, st->tvb, offset, len, item_encoding(n)) : NULL;
        /* Shown by the other dissector: our field stays filterable, hidden. */
        if (item && (handle || (n->flags & DG_HIDDEN))) proto_item_set_hidden(item);
        if (!handle) return;
        payload = tvb_new_subset_length(st->tvb, offset, len);
    }
    call_handoff(st, handle, payload, tree);
}

void dissect_leaf(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end)
{
    if (n->flags & DG_GROUP) {
        dissect_bit_field(st, n, tree, offset, end);
        return;
    }
    gint64 length = 0;
    switch (n->length_kind) {
    case DG_LEN_FIXED: length = n->length; break;
    case DG_LEN_FIELD:
        if (!ref_value(st, &n->length_ref, n, "length", tree, *offset, &length)) return;
        break;
    case DG_LEN_REST: length = end - *offset; break;
    default:
        /* a stringz without a length runs to its NUL, included. */
        length = n->show == DG_SHOW_STRINGZ ? stringz_length(st, *offset, end) : 0;
        break;
    }
    gint left = end - *offset;
    if (length > left) {
        /* Show the bytes that are there, then say what is missing. An IPv4
         * address or a float has one size only: Wireshark throws on fewer bytes. */
        gboolean fixed_size = n->show == DG_SHOW_IPV4 || n->show == DG_SHOW_FLOAT;
        if (!(n->flags & DG_NUMERIC) && !fixed_size && left > 0 && tree) {
            proto_item *item = proto_tree_add_item(tree, *n->hf, st->tvb, *offset, left, item_encoding(n));
            if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
        }
        if (n->show == DG_SHOW_STRINGZ && n->length_kind == DG_LEN_CHILDREN)
            report(st, tree, &st->p->ei->truncated, *offset, left,
                   "Truncated: '%s' has no NUL before the end of its data (%d bytes left)", n->name, left);
        else if (n->length_kind == DG_LEN_FIELD)
            report(st, tree, &st->p->ei->past_end, *offset, left,
                   "'%s' has length %" G_GINT64_MODIFIER "d, past the end of its data (%d bytes left)", n->name,
                   length, left);
        else
            report(st, tree, &st->p->ei->truncated, *offset, left,
                   "Truncated: '%s' needs %" G_GINT64_MODIFIER "d bytes, only %d left", n->name, length, left);
        return;
    }
    gint len = (gint)length;
    guint64 value = 0;
    proto_item *item = NULL;
    if (n->extra && (n->extra->dissector || n->extra->reassemble_id >= 0) && len > 0) {
        dissect_handoff(st, n, tree, *offset, len);
        store(st, n, 0, *offset, len);
        *offset += len;
        return;
    }
    /* The value is read only when store() uses it, the item added only when
     * there is a tree. */
    if (n->show == DG_SHOW_TIME) {
        /* a count of units; the item shows it as seconds. */
        value = read_uint(st->tvb, *offset, (guint)len, encoding_of(n));
        if (tree) {
            nstime_t t = time_of(n, value);
            item = proto_tree_add_time(tree, *n->hf, st->tvb, *offset, len, &t);
        }
    } else if (n->show == DG_SHOW_IPV4) {
        if (value_wanted(st, n)) value = read_uint(st->tvb, *offset, 4, encoding_of(n));
        if (tree) item = proto_tree_add_item(tree, *n->hf, st->tvb, *offset, len, encoding_of(n));
    } else if (n->flags & DG_NUMERIC) {
        if (tree || value_wanted(st, n)) value = read_uint(st->tvb, *offset, (guint)len, encoding_of(n));
        if (tree) item = add_numeric_item(st, n, tree, *offset, len, value);
    } else if (len > 0 && tree) {
        item = proto_tree_add_item(tree, *n->hf, st->tvb, *offset, len, item_encoding(n));
    }
    if (item && (n->flags & DG_HIDDEN)) proto_item_set_hidden(item);
    store(st, n, value, *offset, len);
    *offset += len;
}

/* P.padding: the zero bytes between the end of a known-length container's
 * fields and the end of its length. One protocol per plugin, like stats_protocol. */
int hf_padding = -1;

/* Whether the `length` bytes at offset are captured and all zero. Bytes the
 * capture did not keep are not known to be zero. */
gboolean all_zero(const dg_state *st, gint offset, gint length)
{
    static const guint8 zeros[64] = {0};
    if (offset < 0 || length > st->packet_end - offset) return FALSE;
    while (length > 0) {
        gint n = MIN(length, (gint)sizeof zeros);
        if (tvb_memeql(st->tvb, offset, zeros, (size_t)n) != 0) return FALSE;
        offset += n;
        length -= n;
    }
    return TRUE;
}

void dissect_container(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end,
                       gboolean in_summary, dg_summaries *sink)
{
    gint start = *offset;
    gint64 length = -1;
    switch (n->length_kind) {
    case DG_LEN_FIXED: length = n->length; break;
    case DG_LEN_FIELD:
        if (!ref_value(st, &n->length_ref, n, "length", tree, start, &length)) return;
        break;
    case DG_LEN_REST: length = end - start; break;
    default: break;
    }
    gboolean past_end = length > end - start;
    gint inner_end = (length >= 0 && !past_end) ? start + (gint)length : end;

    proto_item *item = NULL;
    proto_tree *subtree = NULL;
    /* Length 0 now, the real length once the children are decoded: a length
     * of -1 would throw when the container starts at the end of the packet. */
    if (!tree) {
        /* nothing to add to */
    } else if (n->hf) {
        item = proto_tree_add_item(tree, *n->hf, st->tvb, start, 0, ENC_NA);
        subtree = proto_item_add_subtree(item, *n->ett);
    } else {
        subtree = proto_tree_add_subtree(tree, st->tvb, start, 0, *n->ett, &item, n->name);
    }
    if (past_end)
        report(st, subtree, n->length_kind == DG_LEN_FIELD ? &st->p->ei->past_end : &st->p->ei->truncated, start,
               end - start, "'%s' has length %" G_GINT64_MODIFIER "d, past the end of its data (%d bytes left)",
               n->name, length, end - start);
    /* Decode what is there even when the length overruns. */
    gboolean was_stopped = st->stopped;
    st->stopped = FALSE;
    if (n->window >= 0) /* a window: children at addresses, not one after another */
        dissect_window(st, n, subtree, offset, inner_end, in_summary || n->summary_count > 0);
    else
        dissect_list(st, n->first_child, n->child_count, subtree, offset, inner_end,
                     in_summary || n->summary_count > 0);
    st->stopped = st->stopped || was_stopped;
    if (!st->stopped && length >= 0 && *offset < inner_end &&
        (n->length_kind == DG_LEN_FIXED || n->length_kind == DG_LEN_FIELD)) {
        if (all_zero(st, *offset, inner_end - *offset)) {
            /* Zero bytes up to the length: padding, which senders may add (to
             * a minimum length, or a length rounded up). Nothing is wrong. */
            if (subtree) proto_tree_add_item(subtree, hf_padding, st->tvb, *offset, inner_end - *offset, ENC_NA);
        } else {
            /* The length says more than the fields hold: say so, then skip to the end. */
            proto_tree_add_expert_format(subtree, st->pinfo, &st->p->ei->unused, st->tvb, *offset,
                                         inner_end - *offset,
                                         "'%s' is %" G_GINT64_MODIFIER "d bytes, but its fields end after %d: "
                                         "%d bytes are not decoded",
                                         n->name, length, *offset - start, inner_end - *offset);
        }
    }
    if (!st->stopped && length >= 0) *offset = inner_end;
    if (st->stopped && !was_stopped && (n->flags & DG_SKIP_MALFORMED) && length >= 0) {
        /* malformed="skip": the spot is marked by its expert info; the rest of
         * this container is left undecoded and decoding goes on after it, as
         * for a PDU in a tvb of its own. */
        st->stopped = FALSE;
        *offset = inner_end;
    }
    proto_item_set_len(item, *offset - start);

    /* A container that a summary refers to: decoded in this instance. */
    if (n->slot >= 0) {
        dg_slot *s = &st->slots[n->slot];
        s->offset = start;
        s->length = *offset - start;
        s->node = n;
        st->present[n->slot] = TRUE;
    }
    /* The text only when something shows it: the item, or the Info column
     * (a summarised container inside another one only has its item). */
    if (n->summary_count > 0 && st->want_text && (item || (!in_summary && st->want_info))) {
        const char *text = summary_text(st, n);
        gsize text_len = st->text->len;
        if (item) proto_item_append_text(item, ": %s", text);
        if (!in_summary && st->want_info) {
            if (sink) {
                if (sink->count++) text_append(&sink->text, ", ", 2);
                text_append(&sink->text, text, text_len);
            } else {
                info_append(st, text, text_len);
            }
        }
    }
}

void clear_slots(dg_state *st, const dg_node *n)
{
    if (n->slot_count) memset(&st->present[n->slot_first], 0, n->slot_count);
}

void dissect_instance(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end,
                      gboolean in_summary, dg_summaries *sink)
{
    if (n->kind == DG_LEAF)
        dissect_leaf(st, n, tree, offset, end);
    else
        dissect_container(st, n, tree, offset, end, in_summary, sink);
}

/* Info column text of a repeated node's summarised instances: gathered in
 * *s while they are decoded (when summaries_begin says so), then added. */
gboolean summaries_begin(const dg_state *st, const dg_node *n, gboolean in_summary, dg_summaries *s)
{
    s->count = 0;
    if (in_summary || n->summary_count == 0 || !st->want_info) return FALSE;
    text_init(&s->text, st->pinfo->pool, s->buf, sizeof s->buf);
    return TRUE;
}

void summaries_end(dg_state *st, const dg_node *n, const dg_summaries *s)
{
    if (s->count > 1) {
        /* "NAME ×COUNT: SUMMARY, SUMMARY, ..." */
        info_separate(st);
        append_str(st->info, n->name);
        text_append(st->info, " \xc3\x97", 3);
        append_dec(st->info, s->count);
        text_append(st->info, ": ", 2);
        text_append(st->info, s->text.data, s->text.len);
    } else if (s->count == 1) {
        info_append(st, s->text.data, s->text.len);
    }
}

/* repeat: another instance while the flag is set; count: exactly N. Every
 * instance must consume bytes, which bounds the loop by the packet size. */
void dissect_repeated(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary)
{
    gint64 wanted = -1;
    if (n->count.slot >= 0 && !ref_value(st, &n->count, n, "count", tree, *offset, &wanted)) return;
    if (n->extra && n->extra->keep_values) table_reset(st, n, *offset); /* a new table for this repetition */
    dg_summaries summaries;
    gboolean collect = summaries_begin(st, n, in_summary, &summaries);

    guint instances = 0;
    for (gint64 done = 0; wanted < 0 || done < wanted; done++) {
        if (wanted >= 0 && *offset >= end) {
            report(st, tree, &st->p->ei->count_short, *offset, 0,
                   "'%s' should occur %" G_GINT64_MODIFIER "d times, but the data ends after %" G_GINT64_MODIFIER "d",
                   n->name, wanted, done);
            st->stopped = FALSE; /* the data simply ended: siblings may still be empty-length */
            break;
        }
        if (n->extra && n->extra->repeat_rest && *offset >= end) break; /* repeat="rest": stop where the data ends */
        clear_slots(st, n);
        gint before = *offset;
        dissect_instance(st, n, tree, offset, end, in_summary, collect ? &summaries : NULL);
        instances++;
        if (st->stopped || *offset == before) break;
        if (n->repeat_slot >= 0) {
            const dg_slot *flag = &st->slots[n->repeat_slot];
            if (!st->present[n->repeat_slot] || flag->value == 0) break;
            if (*offset >= end) {
                report(st, tree, &st->p->ei->more_no_data, *offset, 0,
                       "'%s': the repeat flag '%s' says another follows, but no data is left", n->name,
                       flag->node->name);
                st->stopped = FALSE;
                break;
            }
        }
    }
    if (st->tap) tap_record(st, n, instances);
    if (collect) summaries_end(st, n, &summaries);
}

/* Whether entry k of offset table t, placed at base, lies in
 * [low, end]; otherwise reports it (bad_offset), which ends the node. */
gboolean entry_ok(dg_state *st, const dg_node *n, proto_tree *tree, const dg_table *t, guint k, gint64 base,
                  gint64 low, gint end, gint first)
{
    gint64 at = base + (gint64)MIN(t->values[k], (guint64)G_MAXINT32);
    if (at >= low && at <= end) return TRUE;
    report(st, tree, &st->p->ei->bad_offset, first, 0,
           "'%s' %u of %u: offset %" G_GINT64_MODIFIER "u (byte %" G_GINT64_MODIFIER "d) is %s; "
           "the instances lie in bytes %d to %d",
           n->name, k + 1, t->count, t->values[k], at,
           at > end ? "past the end" : k == 0 ? "before the bytes left" : "smaller than the one before it", first, end);
    return FALSE;
}

/* offsets="XPATH" from="XPATH". Instance i covers [base +
 * offset[i], base + offset[i+1]), the last one [base + offset[last], end).
 * An offset before the bytes not yet decoded, past the end, or smaller than
 * the one before is reported (bad_offset) and ends the node; the instances
 * before it are decoded. */
void dissect_located(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary)
{
    const dg_extra *x = n->extra;
    const dg_slot *ts = &st->slots[x->offsets_slot];
    if (!st->present[x->offsets_slot]) {
        report(st, tree, &st->p->ei->bad_length, *offset, 0,
               "The offsets of '%s' come from a field that is not in this packet", n->name);
        return;
    }
    const dg_table *t = table_of(st, x->offsets_slot);
    gint64 base;
    if (x->from_slot >= 0) {
        const dg_slot *fs = &st->slots[x->from_slot];
        if (!st->present[x->from_slot]) {
            report(st, tree, &st->p->ei->bad_length, *offset, 0,
                   "The offsets of '%s' count from a field that is not in this packet", n->name);
            return;
        }
        base = fs->offset;
    } else if (x->from_up <= st->lists && st->lists - x->from_up < DG_MAX_LISTS) {
        base = st->list_starts[st->lists - x->from_up];
    } else {
        base = 0; /* nested deeper than the lists kept: from the message */
    }
    if (t->overflow) {
        report(st, tree, &st->p->ei->bad_offset, ts->offset, ts->length,
               "The offset table '%s' has more than %u entries; '%s' is not decoded", ts->node->name,
               (guint)DG_MAX_TABLE, n->name);
        return;
    }
    dg_summaries summaries;
    gboolean collect = summaries_begin(st, n, in_summary, &summaries);
    guint instances = 0;
    gint first = *offset;
    for (guint i = 0; i < t->count && !st->stopped; i++) {
        if (i == 0 && !entry_ok(st, n, tree, t, 0, base, first, end, first)) break;
        gint64 from = base + (gint64)t->values[i]; /* checked: inside [first, end] */
        gint to = end;
        if (i + 1 < t->count) {
            if (!entry_ok(st, n, tree, t, i + 1, base, from, end, first)) break;
            to = (gint)(base + (gint64)t->values[i + 1]);
        }
        gint at = (gint)from;
        clear_slots(st, n);
        dissect_instance(st, n, tree, &at, to, in_summary, collect ? &summaries : NULL);
        instances++;
        if (!st->stopped) *offset = to;
    }
    if (st->tap) tap_record(st, n, instances);
    if (collect) summaries_end(st, n, &summaries);
}

gboolean is_repeated(const dg_node *n)
{
    return n->count.slot >= 0 || n->repeat_slot >= 0 ||
           (n->extra && (n->extra->repeat_rest || n->extra->offsets_slot >= 0));
}

gboolean hook_holds(const dg_state *st, const dg_node *n)
{
    return in_ranges(st->p, n->hook_first, n->hook_count, st->hook_value);
}

/* --- <when>, otherwise, windows ----------------------------------------- */

/* The value of the leaf a peek reads ahead, when its bytes are there. */
gboolean peek_value(const dg_state *st, const dg_peek *pk, gint node_start, guint64 *out)
{
    if (pk->up > st->lists || st->lists - pk->up >= DG_MAX_LISTS) return FALSE;
    gint64 at = (gint64)(pk->up ? st->list_starts[st->lists - pk->up] : node_start) + pk->offset;
    /* The leaf must lie inside the list it belongs to: bytes after a container's
     * end (padding, the next message) are not its value. */
    guint list = st->lists - 1 - pk->target_up;
    gint64 limit = (pk->target_up < st->lists && list < DG_MAX_LISTS) ? MIN(st->list_ends[list], st->packet_end)
                                                                       : st->packet_end;
    for (guint i = 0; i < pk->length_count; i++) {
        const dg_ref *ref = &st->p->peek_lengths[pk->length_first + i];
        const dg_slot *s = &st->slots[ref->slot];
        if (!st->present[ref->slot]) return FALSE;
        gint64 v = ref_arith(s, ref);
        if (v < 0) return FALSE;
        at += v;
        if (at > limit) return FALSE;
    }
    const dg_node *t = &st->p->nodes[pk->target];
    if (at + t->length > limit) return FALSE;
    guint64 v = read_uint(st->tvb, (gint)at, t->length, encoding_of(t));
    *out = (t->flags & DG_GROUP) ? (v >> t->shift) & bit_mask(t->bits) : v;
    return TRUE;
}

/* Whether every <when> of n holds; node_start is where n would begin. */
gboolean whens_hold(const dg_state *st, const dg_node *n, gint node_start)
{
    for (guint i = 0; i < n->when_count; i++) {
        const dg_when *w = &st->p->whens[n->when_first + i];
        guint64 value;
        if (w->peek >= 0) {
            if (!peek_value(st, &st->p->peeks[w->peek], node_start, &value)) return FALSE;
        } else {
            const dg_slot *s = &st->slots[w->slot];
            if (!st->present[w->slot]) return FALSE;
            value = s->value;
        }
        if (!in_ranges(st->p, w->in_first, w->in_count, value)) return FALSE;
    }
    return TRUE;
}

/* Whether n is decoded at `offset`. *chain_taken says whether a member of the
 * current chain of alternatives (a conditional node and the otherwise nodes
 * after it) was decoded; an otherwise node is skipped when one was. */
gboolean selected_conditional(const dg_state *st, const dg_node *n, gint offset, gboolean *chain_taken);

inline gboolean selected(const dg_state *st, const dg_node *n, gint offset, gboolean *chain_taken)
{
    if (!n->alt && !n->hook_count && n->if_slot < 0 && !n->when_count && !n->extra) {
        *chain_taken = FALSE; /* unconditional: ends any chain */
        return TRUE;
    }
    return selected_conditional(st, n, offset, chain_taken);
}

/* selected() for a node with a condition, an otherwise or a direction: out of
 * line, so that the unconditional test above is inlined into the walk. */
gboolean selected_conditional(const dg_state *st, const dg_node *n, gint offset, gboolean *chain_taken)
{
    gboolean otherwise = (n->alt & DG_ALT_OTHERWISE) != 0;
    if (otherwise && *chain_taken) return FALSE;
    guint8 direction = n->extra ? n->extra->direction : (guint8)DG_DIR_ANY;
    gboolean conditional = otherwise || n->hook_count || n->if_slot >= 0 || n->when_count || direction;
    gboolean holds = (!n->hook_count || hook_holds(st, n)) && (n->if_slot < 0 || condition_holds(st, n)) &&
                     (!direction || direction == st->direction) && whens_hold(st, n, offset);
    *chain_taken = conditional && holds;
    return holds;
}

/* The name of instance i of a block at a stride: "{i}" replaced by i, or " i" appended. */
const char *instance_name(const dg_state *st, const dg_node *n, guint i)
{
    dg_text *out = text_new(st->pinfo->pool);
    const char *name = n->name, *mark;
    gboolean marked = FALSE;
    while ((mark = strstr(name, "{i}")) != NULL) {
        text_append(out, name, (gsize)(mark - name));
        append_dec(out, i);
        name = mark + 3;
        marked = TRUE;
    }
    append_str(out, name);
    if (!marked) {
        text_append(out, " ", 1);
        append_dec(out, i);
    }
    return out->data;
}

/* Renames the item a block instance added after `before` in tree: its label
 * (name, value, summary) with the name replaced by the instance's name. */
void label_instance(const dg_state *st, const dg_node *n, proto_tree *tree, proto_node *before, guint i)
{
    if (!tree || !PTREE_DATA(tree)->visible) return;
    proto_node *item = before ? before->next : tree->first_child;
    if (!item || !item->finfo) return;
    char label[ITEM_LABEL_LENGTH];
    const char *now = label;
    if (item->finfo->rep)
        now = item->finfo->rep->representation;
    else
        dg_fill_label(item->finfo, label);
    gsize name_len = strlen(n->name);
    if (strncmp(now, n->name, name_len) != 0) return;
    proto_item_set_text(item, "%s%s", instance_name(st, n, i), now + name_len);
}

/* Decodes the instances of one window child that lie wholly inside the
 * window's addresses [base, last); `start` is the window's first byte. */
void dissect_place(dg_state *st, const dg_place *pl, proto_tree *tree, gint start, guint64 base, guint64 last,
                   gboolean in_summary)
{
    const dg_node *c = &st->p->nodes[pl->node];
    if (st->quiet && c->quiet_size && c->quiet_size <= pl->size) return; /* unseen, cannot be malformed */
    gboolean no_chain = FALSE;
    if (!selected(st, c, start, &no_chain)) return;
    guint32 i = 0;
    if (pl->stride && base > pl->at) i = (guint32)MIN((base - pl->at + pl->stride - 1) / pl->stride, (guint64)pl->instances);
    for (; i < pl->instances && !st->stopped; i++) {
        guint64 a = pl->at + (guint64)pl->stride * i;
        if (a < base) continue;
        if (a + pl->size > last) break;
        gint offset = start + (gint)(a - base);
        proto_node *before = tree ? tree->last_child : NULL;
        clear_slots(st, c);
        dissect_instance(st, c, tree, &offset, offset + (gint)pl->size, in_summary, NULL);
        if (pl->stride) label_instance(st, c, tree, before, i);
    }
}

/* The first index in [l, h) whose place starts at or after addr. */
guint first_at_or_after(const dg_place *places, guint l, guint h, guint64 addr)
{
    while (l < h) {
        guint m = l + (h - l) / 2;
        if (places[m].at < addr)
            l = m + 1;
        else
            h = m;
    }
    return l;
}

int compare_node_index(const void *a, const void *b)
{
    return (int)((const dg_place *const *)a)[0]->node - (int)((const dg_place *const *)b)[0]->node;
}

/* A window's children: each place (each instance of a block) wholly inside
 * [base, base + window length), in document order. Places are sorted by
 * address, so a binary search finds the few that may be inside. */
void dissect_window(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary)
{
    const dg_window *w = &st->p->windows[n->window];
    const dg_slot *s = &st->slots[w->base.slot];
    if (!st->present[w->base.slot]) {
        report(st, tree, &st->p->ei->bad_length, *offset, 0,
               "The base address of '%s' comes from a field that is not in this packet", n->name);
        return;
    }
    guint64 base = s->value;
    gboolean bad = FALSE;
    switch (w->base.op) {
    case '+': bad = __builtin_add_overflow(base, (guint64)w->base.operand, &base); break;
    case '-': bad = base < (guint64)w->base.operand; base -= (guint64)w->base.operand; break;
    case '*': bad = __builtin_mul_overflow(base, (guint64)w->base.operand, &base); break;
    default: break;
    }
    if (bad) {
        report(st, tree, &st->p->ei->bad_length, *offset, 0, "The base address of '%s' is out of range", n->name);
        return;
    }
    gint start = *offset;
    guint64 last = base + (guint64)(end - start);
    if (last < base) last = G_MAXUINT64; /* the top of the address space */
    const dg_place *places = &st->p->places[w->place_first];
    /* Places starting at or before base - max_span end at or before base;
     * those starting at or after last are past the window. */
    guint lo = base > w->max_span ? first_at_or_after(places, 0, w->place_count, base - w->max_span + 1) : 0;
    guint hi = first_at_or_after(places, lo, w->place_count, last);
    if (w->address_order_is_document_order || hi - lo < 2) {
        for (guint k = lo; k < hi && !st->stopped; k++) dissect_place(st, &places[k], tree, start, base, last, in_summary);
    } else {
        const dg_place **order = wmem_alloc_array(st->pinfo->pool, const dg_place *, hi - lo);
        for (guint k = lo; k < hi; k++) order[k - lo] = &places[k];
        qsort(order, hi - lo, sizeof *order, compare_node_index);
        for (guint k = 0; k < hi - lo && !st->stopped; k++) dissect_place(st, order[k], tree, start, base, last, in_summary);
    }
    *offset = end;
}

void dissect_list(dg_state *st, guint16 first, guint16 count, proto_tree *tree, gint *offset, gint end,
                  gboolean in_summary)
{
    gboolean chain_taken = FALSE; /* a conditional sibling was decoded: its otherwise members are not */
    if (st->lists < DG_MAX_LISTS) {
        st->list_starts[st->lists] = *offset;
        st->list_ends[st->lists] = end;
    }
    st->lists++;
    for (guint16 i = 0; i < count && !st->stopped; i++) {
        const dg_node *n = &st->p->nodes[st->p->children[first + i]];
        if (!selected(st, n, *offset, &chain_taken)) continue;
        if (st->quiet && n->quiet_size && (gint64)n->quiet_size <= (gint64)(end - *offset)) {
            *offset += (gint)n->quiet_size; /* nobody would see it, and it cannot be malformed */
            continue;
        }
        if (n->extra && n->extra->offsets_slot >= 0)
            dissect_located(st, n, tree, offset, end, in_summary); /* offset table */
        else if (is_repeated(n))
            dissect_repeated(st, n, tree, offset, end, in_summary);
        else
            dissect_instance(st, n, tree, offset, end, in_summary, NULL);
    }
    st->lists--;
}

/* --- registration ------------------------------------------------------- */

struct dg_claim {
    const char *table;
    guint32 value;
    dissector_handle_t handle;
};

GArray *claims; /* of dg_claim: table entries this plugin must own */

/* Runs after every plugin's handoff and before Decode As choices (-d, the
 * profile's decode_as_entries) are applied: whatever the plugin load order,
 * our handle becomes the default for our values, and the other registrant
 * stays selectable in Decode As. */
void claim_tables(void)
{
    for (guint i = 0; claims && i < claims->len; i++) {
        const dg_claim *c = &g_array_index(claims, dg_claim, i);
        if (dissector_get_uint_handle(find_dissector_table(c->table), c->value) != c->handle)
            dissector_add_uint(c->table, c->value, c->handle);
    }
}

gboolean table_accepts_integers(const char *table)
{
    switch (get_dissector_table_selector_type(table)) {
    case FT_UINT8: case FT_UINT16: case FT_UINT24: case FT_UINT32: return TRUE;
    default: return FALSE;
    }
}

/* --- statistics: tshark -z FILTER,tree, Statistics menu in Wireshark ---- */

/* "Command (ecatr.datagram.cmd)": node names must be unique in the tree. */
const char *stats_node_name(const dg_node *n, const char *what)
{
    header_field_info *hfi = n->hf ? proto_registrar_get_nth(*n->hf) : NULL;
    return g_strdup_printf("%s%s (%s)", n->name, what, hfi ? hfi->abbrev : stats_protocol->filter);
}

char **stats_node_names;   /* per node: that node's name, or NULL (no statistics) */
int stats_frames_id;

void stats_init(stats_tree *st)
{
    const dg_protocol *p = stats_protocol;
    guint n_nodes = p->node_count;
    if (stats_node_names) g_strfreev(stats_node_names);
    stats_node_names = g_new0(char *, n_nodes + 1);
    stats_frames_id = stats_tree_create_node(st, "Messages", 0, STAT_DT_INT, FALSE);
    for (guint i = 0; i < n_nodes; i++) {
        const dg_node *n = &p->nodes[i];
        const char *what = NULL;
        if (is_repeated(n)) what = " per message";
        else if (n->kind == DG_LEAF && n->show == DG_SHOW_ENUM) what = "";
        if (!what) continue;
        /* The node itself appears with its first count: no rows of zeros. */
        stats_node_names[i] = (char *)stats_node_name(n, what);
    }
    if (p->pairing) dg_pairing_stats_init(p, st);
}

tap_packet_status stats_packet(stats_tree *st, packet_info *pinfo, epan_dissect_t *, const void *data, tap_flags_t)
{
    const dg_tap_data *t = (const dg_tap_data *)data;
    const dg_protocol *p = stats_protocol;
    tick_stat_node(st, "Messages", 0, FALSE);
    char buf[64];
    for (guint i = 0; i < t->count; i++) {
        const dg_tap_record *r = &t->records[i];
        const dg_node *n = &p->nodes[r->node];
        if (!stats_node_names[r->node]) continue;
        const char *label = NULL;
        if (n->kind == DG_LEAF && n->show == DG_SHOW_ENUM && !is_repeated(n)) {
            header_field_info *hfi = proto_registrar_get_nth(*n->hf);
            label = enum_name(hfi, r->value);
            if (!label) {
                /* padded like the tree item: "Unknown (0x07)" for an 8-bit field */
                g_snprintf(buf, sizeof buf, "Unknown (0x%0*" G_GINT64_MODIFIER "x)", (int)((n->bits + 3) / 4), r->value);
                label = buf;
            }
        } else {
            g_snprintf(buf, sizeof buf, "%" G_GINT64_MODIFIER "u", r->value);
            label = buf;
        }
        int id = tick_stat_node(st, stats_node_names[r->node], 0, TRUE);
        tick_stat_node(st, label, id, FALSE);
    }
    if (p->pairing) dg_pairing_stats_packet(p, st, pinfo, t->pairing);
    return TAP_PACKET_REDRAW;
}

void register_stats_tree(const dg_protocol *p)
{
    stats_protocol = p;
    stats_tap = register_tap(p->filter);
    stats_tree_register_plugin(p->filter, p->filter, p->name, 0, stats_packet, stats_init, NULL);
}

} /* namespace */

extern "C" {

gboolean dg_protocol_names_free(const dg_protocol *p)
{
    /* The very same protocol from another plugin (a packaged plugin and the
     * user's own build of the same rules): the first one registered wins, and
     * this one steps aside without a dialog at every start. */
    int same = proto_get_id_by_filter_name(p->filter);
    if (same != -1 && strcmp(proto_get_protocol_name(same), p->name) == 0 &&
        strcmp(proto_get_protocol_short_name(find_protocol_by_id(same)), p->short_name) == 0) {
        /* ws_log, not ws_info: that macro would compile the source path into the plugin */
        ws_log("dissgen", LOG_LEVEL_INFO, "\"%s\" (%s) is already registered by another plugin; this one steps aside",
               p->name, p->filter);
        return FALSE;
    }
    const char *what = NULL, *value = NULL;
    if (proto_get_id_by_filter_name(p->filter) != -1) {
        what = "filter name";
        value = p->filter;
    } else if (proto_get_id_by_short_name(p->short_name) != -1) {
        what = "abbreviation";
        value = p->short_name;
    } else if (proto_name_already_registered(p->name)) {
        what = "name";
        value = p->name;
    }
    if (!what) return TRUE;
    report_failure("The dissgen plugin for \"%s\" was not loaded: another protocol already has the %s \"%s\". "
                   "Change it in the rule file (<root %s=...>) and regenerate the plugin.",
                   p->name, what, value, strcmp(what, "abbreviation") == 0 || strcmp(what, "name") == 0 ? what : "filter");
    return FALSE;
}

void dg_name_fields(hf_register_info *hf, const char *const *names, guint count, const char *filter)
{
    for (guint i = 0; i < count; i++) hf[i].hfinfo.abbrev = g_strdup_printf("%s.%s", filter, names[i]);
}

void dg_name_experts(ei_register_info *ei, const char *const *names, guint count, const char *filter)
{
    for (guint i = 0; i < count; i++) ei[i].eiinfo.name = g_strdup_printf("%s.%s", filter, names[i]);
}

void dg_register(dg_protocol *p, hf_register_info *hf, int hf_count, gint **ett, int ett_count,
                 ei_register_info *ei, int ei_count)
{
    *p->proto = proto_register_protocol(p->name, p->short_name, p->filter);
    proto_register_field_array(*p->proto, hf, hf_count);
    /* Wireshark keeps a pointer to it: a static array, a name that lives until exit. */
    static hf_register_info runtime_hf[] = {DG_RUNTIME_FIELDS(DG_HF_ROW)};
    static const char *const names[] = {DG_RUNTIME_FIELDS(DG_FIELD_NAME)};
    dg_name_fields(runtime_hf, names, G_N_ELEMENTS(runtime_hf), p->filter);
    proto_register_field_array(*p->proto, runtime_hf, (int)G_N_ELEMENTS(runtime_hf));
    proto_register_subtree_array(ett, ett_count);
    expert_module_t *experts = expert_register_protocol(*p->proto);
    expert_register_field_array(experts, ei, ei_count);
    register_dissector(p->filter, p->dissect, *p->proto);
    register_stats_tree(p);
    if (p->reassembly) reassembly_table_register(p->reassembly, &addresses_reassembly_table_functions);
    if (p->pairing) dg_pairing_register(p);
}

/* The dissectors that dissector= names. A name this Wireshark does
 * not have is reported once, here, and that leaf's bytes are shown raw. */
static void find_handoff_dissectors(const dg_protocol *p)
{
    for (guint i = 0; i < p->node_count; i++) {
        const dg_extra *x = p->nodes[i].extra;
        if (!x || (!x->dissector && x->reassemble_id < 0)) continue;
        if (!handoff_handles) {
            handoff_handles = g_new0(dissector_handle_t, p->node_count);
            reassembled_names = g_new0(char *, p->node_count);
        }
        reassembled_names[i] = g_strdup_printf("Reassembled %s", p->nodes[i].name);
        if (!x->dissector) continue;
        handoff_handles[i] = find_dissector(x->dissector);
        if (!handoff_handles[i])
            ws_log("dissgen", LOG_LEVEL_WARNING,
                   "%s: '%s' hands its bytes to the dissector \"%s\", which this Wireshark does not have; "
                   "they are shown raw", p->name, p->nodes[i].name, x->dissector);
    }
}

void dg_handoff(const dg_protocol *p)
{
    if (*p->proto == -1) return; /* not registered: its names were taken */
    dissector_handle_t handle = find_dissector(p->filter);
    dissector_handle_t stream = p->dissect_stream ? create_dissector_handle(p->dissect_stream, *p->proto) : NULL;
    if (!claims) {
        claims = g_array_new(FALSE, FALSE, sizeof(dg_claim));
        register_final_registration_routine(claim_tables);
    }
    find_handoff_dissectors(p);
    for (guint i = 0; i < p->hook_count; i++) {
        const dg_hook *h = &p->hooks[i];
        if (!find_dissector_table(h->table) || !table_accepts_integers(h->table)) {
            report_failure("The dissgen plugin for \"%s\" cannot hook into \"%s\": Wireshark has no integer "
                           "dissector table of that name. The hook is ignored.", p->name, h->table);
            continue;
        }
        dissector_handle_t h_handle = (stream && strcmp(h->table, "tcp.port") == 0) ? stream : handle;
        dissector_add_uint(h->table, h->value, h_handle);
        dg_claim c = {h->table, h->value, h_handle};
        g_array_append_val(claims, c);
    }
}

/* Request when the port the hook (or Decode As) matched is the
 * destination port, response when it is only the source port. */
static guint8 direction_of(const packet_info *pinfo)
{
    if (pinfo->ptype == PT_NONE) return DG_DIR_ANY;
    if (pinfo->destport == pinfo->match_uint) return DG_DIR_REQUEST;
    if (pinfo->srcport == pinfo->match_uint) return DG_DIR_RESPONSE;
    return DG_DIR_ANY;
}

/* Key of the per-packet count of messages decoded (p_add_proto_data). */
#define DG_MESSAGES_KEY 0x6d736773u

int dg_dissect(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    col_set_str(pinfo->cinfo, COL_PROTOCOL, p->short_name);
    /* Several messages in one packet (a TCP segment): each adds its Info text. */
    guint *messages = (guint *)p_get_proto_data(pinfo->pool, pinfo, *p->proto, DG_MESSAGES_KEY);
    if (!messages) {
        messages = wmem_new0(pinfo->pool, guint);
        p_add_proto_data(pinfo->pool, pinfo, *p->proto, DG_MESSAGES_KEY, messages);
    }
    gboolean first_message = (*messages)++ == 0;
    if (first_message) col_clear(pinfo->cinfo, COL_INFO);

    dg_state st;
    memset(&st, 0, sizeof st);
    st.p = p;
    st.tvb = tvb;
    st.pinfo = pinfo;
    /* The values of one message live on the stack when they fit (most rule
     * files): two allocations fewer per message. Nothing keeps them after it. */
    enum { stack_slots = 128 };
    dg_slot slot_buf[stack_slots];
    guint8 present_buf[stack_slots];
    if (p->slot_count <= stack_slots) {
        st.slots = slot_buf;
        st.present = present_buf;
        memset(present_buf, 0, p->slot_count);
    } else {
        st.slots = wmem_alloc_array(pinfo->pool, dg_slot, p->slot_count);
        st.present = (guint8 *)wmem_alloc0(pinfo->pool, p->slot_count);
    }
    st.packet_end = (gint)tvb_captured_length(tvb);
    st.hook_value = pinfo->match_uint;
    st.direction = direction_of(pinfo);
    /* Summaries are text for the Info column and for container items; build
     * them only when someone sees them: tshark -T fields and -V have a visible
     * tree and no columns, summary lines have columns and no tree, and a
     * filter-only pass (-Y with -w) has neither. */
    st.want_info = pinfo->cinfo != NULL;
    st.want_text = st.want_info || (tree != NULL && PTREE_DATA(tree)->visible);
    /* The Info column and the summary scratch start on the stack. */
    dg_text info_text, scratch_text;
    char info_buf[256], scratch_buf[256];
    if (st.want_info) {
        text_init(&info_text, pinfo->pool, info_buf, sizeof info_buf);
        st.info = &info_text;
    }
    if (st.want_text) {
        text_init(&scratch_text, pinfo->pool, scratch_buf, sizeof scratch_buf);
        st.text = &scratch_text;
    }
    if (stats_tap >= 0 && have_tap_listener(stats_tap)) st.tap = wmem_new0(pinfo->pool, dg_tap_data);
    /* nobody sees items or the text of expert infos without a tree
     * and without a tap listener (the Expert dialog and -z expert are taps):
     * quiet nodes are stepped over, expert infos are raised without text
     * (their severity still reaches the Expert column). */
    st.quiet = tree == NULL && !tap_listeners_require_dissection();

    proto_item *root = tree ? proto_tree_add_item(tree, *p->proto, tvb, 0, 0, ENC_NA) : NULL;
    proto_tree *subtree = proto_item_add_subtree(root, *p->ett);
    gint offset = 0;
    dissect_list(&st, p->top_first, p->top_count, subtree, &offset, st.packet_end, FALSE);
    proto_item_set_len(root, offset);
    if (p->pairing) {
        const dg_frame_pairing *fp =
            dg_pairing_dissect(p, tvb, pinfo, subtree, st.keys, st.key_count, offset, *messages - 1, st.direction);
        if (st.tap) st.tap->pairing = fp;
    }

    if (st.tap) tap_queue_packet(stats_tap, pinfo, st.tap);
    const char *info = st.info && st.info->len > 0 ? st.info->data : p->name;
    if (first_message)
        col_add_str(pinfo->cinfo, COL_INFO, info);
    else
        col_append_sep_str(pinfo->cinfo, COL_INFO, " | ", info);
    return offset > 0 ? offset : st.packet_end;
}

} /* extern "C" */

/* --- stream transports -------------------------------------------------- */

extern "C" guint dg_message_length(packet_info *, tvbuff_t *tvb, int offset, void *data)
{
    const dg_protocol *p = (const dg_protocol *)data;
    const dg_node *n = &p->nodes[p->pdu_node];
    guint64 value = read_uint(tvb, offset + (gint)p->pdu_offset, n->length, encoding_of(n));
    if (n->flags & DG_GROUP) value = (value >> n->shift) & bit_mask(n->bits);
    gint64 total = (gint64)MIN(value, (guint64)G_MAXINT32) + p->pdu_add;
    /* A length shorter than the length field itself cannot make progress. */
    gint64 minimum = (gint64)(p->pdu_offset + n->length);
    return (guint)CLAMP(total, minimum, (gint64)G_MAXINT32);
}

namespace {

int dissect_message(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data)
{
    return dg_dissect((const dg_protocol *)data, tvb, pinfo, tree);
}

} /* namespace */

extern "C" int dg_dissect_stream(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    const dg_node *n = &p->nodes[p->pdu_node];
    tcp_dissect_pdus(tvb, pinfo, tree, TRUE, p->pdu_offset + n->length, dg_message_length, dissect_message, (void *)p);
    return (int)tvb_captured_length(tvb);
}

// SPDX-License-Identifier: GPL-2.0-or-later
/* The texts the walk shows besides items: a leaf's value as its tree item
 * shows it, container summaries (summary="..." with optional parts), and the
 * Info column, where a repeated node's summaries are gathered into one entry.
 *
 * Summary text is built with the dg_text appends of dissgen_text.h instead
 * of printf: it runs for every instance of a summarised container. Like the
 * whole runtime: no non-trivial C++ object (Wireshark's exceptions are
 * longjmps), memory from pinfo->pool.
 */
#include "dissgen_state.h"

#include <epan/oids.h>
#include <epan/to_str.h>
#include <wsutil/sign_ext.h>

#include <float.h>
#include <string.h>

namespace dg_rt {

void text_grow(dg_text *t, gsize n)
{
    gsize cap = MAX(2 * t->cap, t->len + n + 1);
    char *bigger = (char *)wmem_alloc(t->pool, cap);
    memcpy(bigger, t->data, t->len + 1);
    t->data = bigger; /* the old buffer goes with the pool */
    t->cap = cap;
}

const char *enum_name(const header_field_info *hfi, guint64 value)
{
    if (hfi->display & BASE_RANGE_STRING) return try_rval_to_str((guint32)value, (const range_string *)hfi->strings);
    if (hfi->display & BASE_VAL64_STRING) return try_val64_to_str(value, (const val64_string *)hfi->strings);
    return try_val_to_str((guint32)value, (const value_string *)hfi->strings);
}

void append_number(dg_text *out, const dg_node *n, guint64 value)
{
    if (n->show == DG_SHOW_DEC) {
        append_dec(out, value);
    } else if (n->show == DG_SHOW_INT) {
        char buf[24];
        const guint64 v = n->bits > 0 && n->bits < 64 ? ws_sign_ext64(value, (int)n->bits) : value;
        g_snprintf(buf, sizeof buf, "%" G_GINT64_MODIFIER "d", (gint64)v);
        append_str(out, buf);
    } else {
        append_hex(out, value, hex_digits(n, value));
    }
}

proto_item *add_variable_hex(const dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint length,
                             guint64 value)
{
    const int digits = (int)hex_digits(n, value);
    if (n->show != DG_SHOW_ENUM)
        return proto_tree_add_uint64_format_value(tree, *n->hf, st->tvb, offset, length, value,
                                                  "0x%0*" G_GINT64_MODIFIER "x", digits, value);
    const header_field_info *hfi = proto_registrar_get_nth(*n->hf);
    const char *name = hfi && hfi->strings ? enum_name(hfi, value) : NULL;
    return proto_tree_add_uint64_format_value(tree, *n->hf, st->tvb, offset, length, value,
                                              "%s (0x%0*" G_GINT64_MODIFIER "x)", name ? name : "Unknown", digits,
                                              value);
}

} // namespace dg_rt

using namespace dg_rt;

/* A datetime's bytes as Wireshark reads them for its item (the ENC_TIME_*
 * encodings the generator gives: seconds and nanoseconds, or a count of
 * ns, us, ms or s since 1970, or DG_TIME_FILETIME). */
nstime_t dg_rt::datetime_at(const dg_state *st, const dg_node *n, gint offset, gint length)
{
    guint encoding = encoding_of(n);
    guint64 count = read_uint(st->tvb, offset, (guint)length, encoding);
    nstime_t t;
    switch (n->extra ? n->extra->time_encoding : ENC_TIME_SECS_NSECS) {
    case ENC_TIME_NSECS: t.secs = (time_t)(count / 1000000000); t.nsecs = (int)(count % 1000000000); break;
    case ENC_TIME_USECS: t.secs = (time_t)(count / 1000000); t.nsecs = (int)(count % 1000000) * 1000; break;
    case ENC_TIME_MSECS: t.secs = (time_t)(count / 1000); t.nsecs = (int)(count % 1000) * 1000000; break;
    case ENC_TIME_SECS: t.secs = (time_t)count; t.nsecs = 0; break;
    case DG_TIME_FILETIME:
        if (!filetime_to_nstime(&t, count)) nstime_set_zero(&t); /* not a time this system shows */
        break;
    default: /* two 32-bit values */
        t.secs = (time_t)read_uint(st->tvb, offset, 4, encoding);
        t.nsecs = (int)read_uint(st->tvb, offset + 4, 4, encoding);
        break;
    }
    return t;
}

namespace {

/* --- shown values -------------------------------------------------------- */

/* The values of string, stringz, int, float, time, datetime, guid and
 * address leaves, for summaries and the Info column (as the tree item shows
 * them; a MAC address without its vendor's name, as tshark's fields). */
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
        const guint64 v = ws_sign_ext64(s->value, (int)MIN(n->bits, 64u));
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
    case DG_SHOW_DATETIME: {
        nstime_t t = datetime_at(st, n, s->offset, s->length);
        append_str(out, abs_time_to_str(st->pinfo->pool, &t, ABSOLUTE_TIME_UTC, TRUE));
        return;
    }
    case DG_SHOW_GUID: {
        e_guid_t guid;
        tvb_get_guid(st->tvb, s->offset, &guid, encoding_of(n));
        append_str(out, guid_to_str(st->pinfo->pool, &guid));
        return;
    }
    case DG_SHOW_IPV6: append_str(out, tvb_ip6_to_str(st->pinfo->pool, st->tvb, s->offset)); return;
    case DG_SHOW_MAC: append_str(out, tvb_ether_to_str(st->pinfo->pool, st->tvb, s->offset)); return;
    case DG_SHOW_OID: /* dotted, as its item: an empty one shows nothing */
        if (s->length > 0)
            append_str(out, oid_encoded2string(st->pinfo->pool,
                                               (const guint8 *)tvb_memdup(st->pinfo->pool, st->tvb, s->offset,
                                                                          s->length),
                                               (guint)s->length));
        return;
    case DG_SHOW_EUI64: {
        /* its item reads it in the node's byte order */
        const guint64 v = read_uint(st->tvb, s->offset, 8, encoding_of(n));
        for (int shift = 56; shift >= 0; shift -= 8) {
            g_snprintf(buf, sizeof buf, shift == 56 ? "%02x" : ":%02x", (unsigned)(v >> shift) & 0xff);
            append_str(out, buf);
        }
        return;
    }
    default: return;
    }
    append_str(out, buf);
}

/* A computed value shown as a signed number, a double or a time: its value
 * is in the slot, not in the bytes (it has none). */
void append_computed_value(const dg_state *st, dg_text *out, const dg_node *n, guint64 value)
{
    char buf[64];
    if (n->show == DG_SHOW_FLOAT) {
        gdouble d;
        memcpy(&d, &value, sizeof d);
        g_snprintf(buf, sizeof buf, "%.*g", DBL_DIG, d);
    } else if (n->show == DG_SHOW_TIME || n->show == DG_SHOW_DATETIME) {
        const nstime_t t = count_time(n, (gint64)value);
        if (n->show == DG_SHOW_DATETIME) {
            append_str(out, abs_time_to_str(st->pinfo->pool, &t, ABSOLUTE_TIME_UTC, TRUE));
            return;
        }
        append_str(out, rel_time_to_secs_str(st->pinfo->pool, &t));
        append_str(out, " seconds");
        return;
    } else {
        g_snprintf(buf, sizeof buf, "%" G_GINT64_MODIFIER "d", (gint64)value);
    }
    append_str(out, buf);
}

/* A leaf's value as its tree item shows it, without a unit label. */
void append_bare_value(const dg_state *st, dg_text *out, const dg_slot *s)
{
    wmem_allocator_t *pool = st->pinfo->pool;
    const dg_node *n = s->node;
    if (n->length_kind == DG_LEN_COMPUTED && n->show != DG_SHOW_HEX && n->show != DG_SHOW_BOOL &&
        n->show != DG_SHOW_ENUM) {
        append_computed_value(st, out, n, s->value);
        return;
    }
    switch (n->show) {
    case DG_SHOW_HEX:
        append_hex(out, s->value, hex_digits(n, s->value));
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
            append_hex(out, s->value, hex_digits(n, s->value));
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
    case DG_SHOW_TIME: case DG_SHOW_DATETIME: case DG_SHOW_GUID: case DG_SHOW_IPV6: case DG_SHOW_MAC:
    case DG_SHOW_EUI64: case DG_SHOW_OID:
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

/* --- summaries ----------------------------------------------------------- */

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

/* The separator before the next item of the Info column, when there is one before it. */
void info_separate(dg_state *st)
{
    if (st->info->len > 0) text_append(st->info, ", ", 2);
}

} // namespace

namespace dg_rt {

/* A <finding>'s text (dg_finding.text_first/count): the pieces as a summary has them. */
void append_text_pieces(const dg_state *st, dg_text *out, guint first, guint count)
{
    append_pieces(st, out, first, count);
}

void append_shown_value(const dg_state *st, dg_text *out, const dg_slot *s)
{
    if (s->node->kind != DG_LEAF) { /* a container's kept copy: its summary text (container_decoded) */
        append_str(out, (const char *)(guintptr)s->value);
        return;
    }
    append_bare_value(st, out, s);
    const dg_extra *x = s->node->extra;
    if (x && x->unit) append_str(out, x->unit);
}

const char *summary_text(const dg_state *st, const dg_node *n)
{
    dg_text *out = st->text;
    text_truncate(out, 0);
    if (n->summarize && !table_walk_only)
        n->summarize(st, out);
    else
        append_pieces(st, out, n->summary_first, n->summary_count);
    return out->data;
}

/* --- the Info column ------------------------------------------------------ */

void info_append(dg_state *st, const char *text, gsize len)
{
    info_separate(st);
    text_append(st->info, text, len);
}

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

} // namespace dg_rt

// SPDX-License-Identifier: GPL-2.0-or-later
/* The table walk behind every dissgen-generated dissector: a message's
 * nodes in document order, each a leaf (a value, a bit field, a hand-off) or
 * a container of more, decoded once, repeated (count, repeat flag, rest) or
 * placed by an offset table.
 *
 * Wireshark's exceptions are longjmps that skip C++ destructors, so nothing
 * here owns a non-trivial C++ object; memory comes from pinfo->pool. Every
 * read is checked against the bytes left first, so no tvb_ or proto_ call
 * can throw: malformed packets end in an expert info instead.
 */
#include "dissgen_label.h"
#include "dissgen_state.h"

#include <epan/proto_data.h>
#include <epan/show_exception.h>
#include <epan/tap.h>
#include <wsutil/sign_ext.h>

#include <string.h>

namespace dg_rt {

static void report_v(dg_state *st, proto_tree *tree, expert_field *ei, gint offset, gint length, const char *format,
                     va_list ap)
{
    if (offset > st->packet_end) offset = st->packet_end;
    if (length < 0 || offset + length > st->packet_end) length = st->packet_end - offset;
    st->stopped = TRUE;
    st->faulted = TRUE;
    if (st->quiet) {
        /* No tree and no tap listener: nobody reads the text, but the
         * severity still goes to the Expert column and the capture's highest
         * severity, as Wireshark does for every expert info. */
        proto_tree_add_expert(tree, st->pinfo, ei, st->tvb, offset, length);
        return;
    }
    char *text = wmem_strdup_vprintf(st->pinfo->pool, format, ap);
    proto_tree_add_expert_format(tree, st->pinfo, ei, st->tvb, offset, length, "%s", text);
}

void report(dg_state *st, proto_tree *tree, expert_field *ei, gint offset, gint length, const char *format, ...)
{
    va_list ap;
    va_start(ap, format);
    report_v(st, tree, ei, offset, length, format, ap);
    va_end(ap);
}

void report_missing(dg_state *st, proto_tree *tree, expert_field *ei, gint64 data_end, gint64 needed_end, gint offset,
                    gint length, const char *format, ...)
{
    if (cut_by_capture(st, data_end, needed_end)) {
        capture_cut(st, tree);
        return;
    }
    /* one cause, one expert info: a length past the end told already, or the
     * header of a stream message whose length is too short, where the data
     * missing past the header is that length's fault (report_short_stream_message) */
    if ((data_end >= st->told_short_at && needed_end <= st->told_end) ||
        (st->header_only && data_end >= st->packet_end)) {
        st->stopped = TRUE;
        st->faulted = TRUE;
        return;
    }
    va_list ap;
    va_start(ap, format);
    report_v(st, tree, ei, offset, length, format, ap);
    va_end(ap);
}

void capture_cut(dg_state *st, proto_tree *tree)
{
    st->stopped = TRUE;
    st->faulted = TRUE; /* no "bytes not decoded" after it either */
    if (st->cut_shown) return;
    st->cut_shown = TRUE;
    show_exception(st->tvb, st->pinfo, tree, BoundsError, NULL);
}

int hf_padding = -1;

} // namespace dg_rt

using namespace dg_rt;

namespace {

void walk_list(dg_state *st, dg_list_walk walk, guint16 first, guint16 count, proto_tree *tree, gint *offset,
               gint end, gboolean in_summary);

/* --- leaves -------------------------------------------------------------- */

/* Bytes from offset to the first NUL before end, NUL included; one more than
 * is left when there is none. */
gint64 stringz_length(const dg_state *st, gint offset, gint end)
{
    if (offset >= end) return 1;
    gint nul = dg_tvb_find_uint8(st->tvb, offset, end - offset, 0);
    return nul < 0 ? (gint64)(end - offset) + 1 : (gint64)(nul - offset) + 1;
}

/* A varint's bytes at offset: up to the first without bit 7 (a 1 to 10
 * byte number, lowest 7 bits first), or 10 when they all have it (too long:
 * decode_varint says so). One more than is left when its last
 * byte is past end or not captured (report_short_leaf tells which). */
gint64 varint_length(const dg_state *st, gint offset, gint end)
{
    const gint captured = (gint)tvb_captured_length(st->tvb);
    for (gint i = 0; i < DG_VARINT_MOST_BYTES; i++) {
        if (offset + i >= end || offset + i >= captured) return (gint64)(end - offset) + 1;
        if (!(dg_tvb_get_uint8(st->tvb, offset + i) & 0x80)) return i + 1;
    }
    return DG_VARINT_MOST_BYTES;
}

/* `rest - N` (N in n->length, 0 for plain `rest`): the bytes to the end but
 * the last N, which the trailer after the node takes; FALSE (reported) when
 * fewer than N are left. */
static gboolean rest_length(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint end, gint64 *out)
{
    /* In a frame the capture cut short, the bytes left end where the
     * container ends on the wire: the node runs past the captured bytes (not
     * shown, as any field cut so) rather than taking the captured ones as
     * all there is. At the top level, the trailer of `rest - N` ends where
     * the frame ends on the wire. */
    if (end == st->packet_end) {
        if (st->cut_end > end)
            end = st->cut_end;
        else if (n->length > 0 && st->cut_end != DG_END_KNOWN)
            end = (gint)tvb_reported_length(st->tvb);
    }
    gint64 v = (gint64)(end - offset) - (gint64)n->length;
    if (v < 0) {
        report(st, tree, &st->p->ei->bad_length, offset, 0,
               "The length of '%s' is negative (%" G_GINT64_MODIFIER "d): fewer than %u bytes are left after it",
               n->name, v, n->length);
        return FALSE;
    }
    *out = v;
    return TRUE;
}

/* A leaf's length in bytes at offset, or -1 when its length field is
 * missing or negative (reported). */
gint64 leaf_length(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint end)
{
    gint64 length = 0;
    switch (n->length_kind) {
    case DG_LEN_FIXED: length = n->length; break;
    case DG_LEN_FIELD:
        if (!ref_value(st, &n->length_ref, n, "length", tree, offset, &length)) return -1;
        break;
    case DG_LEN_REST:
        if (!rest_length(st, n, tree, offset, end, &length)) return -1;
        break;
    default:
        /* a stringz without a length runs to its NUL, included; a varint to its last byte. */
        length = n->show == DG_SHOW_STRINGZ  ? stringz_length(st, offset, end)
                 : n->show == DG_SHOW_VARINT ? varint_length(st, offset, end)
                                             : 0;
        break;
    }
    return length;
}

/* A leaf longer than the `left` bytes there are: in a malformed message,
 * show the bytes that are there, then say what is missing. A frame the
 * capture cut short (a snapshot length) shows none of the leaf, as
 * Wireshark: its value is not known, and a part of it would match filters. */
void report_short_leaf(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint64 length, gint left)
{
    const gint64 data_end = (gint64)offset + left, needed_end = (gint64)offset + length;
    /* An address, a float, a datetime or a GUID has one size only: Wireshark throws on fewer bytes;
     * an OID's first bytes would be another OID. */
    gboolean fixed_size = n->show == DG_SHOW_IPV4 || n->show == DG_SHOW_FLOAT || n->show == DG_SHOW_DATETIME ||
                          n->show == DG_SHOW_GUID || n->show == DG_SHOW_IPV6 || n->show == DG_SHOW_MAC ||
                          n->show == DG_SHOW_EUI64 || n->show == DG_SHOW_OID;
    if (!(n->flags & DG_NUMERIC) && !fixed_size && left > 0 && tree && !cut_by_capture(st, data_end, needed_end)) {
        proto_item *item = proto_tree_add_item(tree, *n->hf, st->tvb, offset, left, item_encoding(n));
        if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
    }
    if (n->show == DG_SHOW_STRINGZ && n->length_kind == DG_LEN_CHILDREN)
        report_missing(st, tree, &st->p->ei->truncated, data_end, needed_end, offset, left,
                       "Truncated: '%s' has no NUL before the end of its data (%d bytes left)", n->name, left);
    else if (n->show == DG_SHOW_VARINT)
        report_missing(st, tree, &st->p->ei->truncated, data_end, needed_end, offset, left,
                       "Truncated: '%s' has no last byte (bit 7 clear) before the end of its data (%d byte%s left)",
                       n->name, left, left == 1 ? "" : "s");
    else if (n->length_kind == DG_LEN_FIELD)
        report_missing(st, tree, &st->p->ei->past_end, data_end, needed_end, offset, left,
                       "'%s' has length %" G_GINT64_MODIFIER "d, past the end of its data (%d bytes left)", n->name,
                       length, left);
    else
        report_missing(st, tree, &st->p->ei->truncated, data_end, needed_end, offset, left,
                       "Truncated: '%s' needs %" G_GINT64_MODIFIER "d bytes, only %d left", n->name, length, left);
}

/* The `len` bytes of a leaf at offset, all there: its item and its value.
 * The value is read only when store() uses it, the item added only when
 * there is a tree. */
/* A float's unit label: Wireshark 4.0 shows BASE_UNIT_STRING on integers
 * only, so dissgen writes it after a float's value itself. */
void append_unit(const dg_node *n, proto_item *item)
{
    if (n->extra && n->extra->unit) proto_item_append_text(item, "%s", n->extra->unit);
}

/* A number whose length comes from a field: 1 to 8 bytes (its Wireshark
 * field has 64 bits); an `int` keeps its sign in its slot, as 64 bits. */
void decode_sized_number(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint len)
{
    if (len < 1 || len > 8) {
        report(st, tree, &st->p->ei->bad_length, offset, len,
               "'%s' is a number of %d bytes: one whose length comes from a field has 1 to 8", n->name, len);
        return;
    }
    guint64 value = read_uint(st->tvb, offset, (guint)len, encoding_of(n));
    if (n->show == DG_SHOW_INT) value = ws_sign_ext64(value, len * 8);
    if (tree) {
        proto_item *item;
        switch (n->show) {
        case DG_SHOW_INT: item = proto_tree_add_int64(tree, *n->hf, st->tvb, offset, len, (gint64)value); break;
        case DG_SHOW_BOOL: item = proto_tree_add_item(tree, *n->hf, st->tvb, offset, len, encoding_of(n)); break;
        case DG_SHOW_HEX: case DG_SHOW_ENUM: item = add_variable_hex(st, n, tree, offset, len, value); break;
        default: item = proto_tree_add_uint64(tree, *n->hf, st->tvb, offset, len, value); break;
        }
        if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
    }
    store(st, n, value, offset, len);
}

/* A varint of len bytes (varint_length): its value, or a malformed number
 * when its first 10 bytes all say that another follows, or its 10th holds
 * more than the 64th bit. */
void decode_varint(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint len)
{
    guint64 value = 0;
    if (!dg_read_varint(st->tvb, offset, len, &value)) {
        report(st, tree, &st->p->ei->bad_length, offset, len,
               "'%s' is a varint of more than 64 bits (%d bytes%s)", n->name, len,
               len == DG_VARINT_MOST_BYTES && (dg_tvb_get_uint8(st->tvb, offset + len - 1) & 0x80)
                   ? ", bit 7 set in each: another would follow"
                   : "");
        return;
    }
    if (tree) {
        proto_item *item = proto_tree_add_uint64(tree, *n->hf, st->tvb, offset, len, value);
        if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
    }
    store(st, n, value, offset, len);
}

void decode_leaf_value(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint len)
{
    guint64 value = 0;
    proto_item *item = NULL;
    if (n->show == DG_SHOW_TIME) {
        /* a count of units; the item shows it as seconds. */
        value = read_uint(st->tvb, offset, (guint)len, encoding_of(n));
        if (tree) {
            nstime_t t = time_of(n, value);
            item = proto_tree_add_time(tree, *n->hf, st->tvb, offset, len, &t);
        }
    } else if (n->show == DG_SHOW_DATETIME && n->extra && n->extra->time_encoding == DG_TIME_FILETIME) {
        if (tree) {
            const nstime_t t = datetime_at(st, n, offset, len);
            item = proto_tree_add_time(tree, *n->hf, st->tvb, offset, len, &t);
        }
    } else if (n->show == DG_SHOW_IPV4) {
        if (value_wanted(st, n)) value = read_uint(st->tvb, offset, 4, encoding_of(n));
        if (tree) item = proto_tree_add_item(tree, *n->hf, st->tvb, offset, len, encoding_of(n));
    } else if (n->flags & DG_NUMERIC) {
        if (n->show == DG_SHOW_VARINT) {
            decode_varint(st, n, tree, offset, len);
            return;
        }
        if (n->length_kind == DG_LEN_FIELD) {
            decode_sized_number(st, n, tree, offset, len);
            return;
        }
        decode_number(st, n, tree, offset, len);
        return;
    } else if ((len > 0 || n->show == DG_SHOW_STRING) && tree) { /* an empty text is a value: "" */
        item = proto_tree_add_item(tree, *n->hf, st->tvb, offset, len, item_encoding(n));
        if (n->show == DG_SHOW_FLOAT) append_unit(n, item);
    }
    if (item && (n->flags & DG_HIDDEN)) proto_item_set_hidden(item);
    store(st, n, value, offset, len);
}

/* A slot's value for the evaluator of computed values (dissgen_expr.h). */
gboolean read_slot(const void *context, gint16 slot, guint64 *value)
{
    const dg_state *st = (const dg_state *)context;
    if (slot < 0 || !st->present[slot]) return FALSE;
    *value = st->slots[slot].value;
    return TRUE;
}

/* `offset` in a computed value: where it sits (dg_state.here). */
gboolean read_offset(const void *context, guint64 *value)
{
    *value = (guint64)((const dg_state *)context)->here;
    return TRUE;
}

/* Whether a computed value would say that its message's request is not
 * known (P.expert.no_request_context): it reads request{...}, and no value
 * has found the request missing yet. */
gboolean would_miss_request(const dg_state *st, const dg_extra *x)
{
    if (!st->p->request_context || st->request_missed || st->request_none || (st->request && !st->request_pending))
        return FALSE;
    for (guint i = 0; i < x->expr_count; i++) {
        const guint8 code = st->p->exprs[x->expr_first + i].code;
        if (code == DG_OP_REQUEST_FIELD || code == DG_OP_REQUEST_FIELD_SIGNED || code == DG_OP_REQUEST_FIELD_FLOAT)
            return TRUE;
    }
    return FALSE;
}

/* value="EXPR": a generated item at the current offset, taking no bytes; an
 * undefined value (a field not decoded, a division by zero) shows nothing.
 * Without a tree only a value someone reads is computed, and one that reads
 * the request, whose note the Expert dialog and -z expert list. */
void dissect_computed(dg_state *st, const dg_node *n, proto_tree *tree, gint offset)
{
    const dg_extra *x = n->extra;
    if (!tree && !value_wanted(st, n) && !would_miss_request(st, x)) return;
    st->here = offset;
    dg_expr_value v = dg_expr_eval(&st->p->exprs[x->expr_first], x->expr_count, &message_readers, st,
                                   st->instance);
    if (!v.defined) return;
    guint64 bits = (guint64)v.integer;
    if (v.is_float) memcpy(&bits, &v.real, sizeof bits);
    store(st, n, bits, offset, 0);
    if (!tree || !n->hf) return;
    gint length = 0;
    if (x->covers_slot >= 0 && st->present[x->covers_slot]) { /* on the bytes of the node it covers */
        offset = st->slots[x->covers_slot].offset;
        length = st->slots[x->covers_slot].length;
    }
    proto_item *item;
    switch (n->show) {
    case DG_SHOW_FLOAT:
        item = proto_tree_add_double(tree, *n->hf, st->tvb, offset, length, v.real);
        append_unit(n, item);
        break;
    case DG_SHOW_BOOL: item = proto_tree_add_boolean(tree, *n->hf, st->tvb, offset, length, v.integer != 0); break;
    case DG_SHOW_TIME:
    case DG_SHOW_DATETIME: {
        const nstime_t t = count_time(n, v.integer);
        item = proto_tree_add_time(tree, *n->hf, st->tvb, offset, length, &t);
        break;
    }
    case DG_SHOW_HEX:
    case DG_SHOW_ENUM:
        /* a value masked to 32 bits or fewer has a field that wide (no wider value reaches it) */
        item = n->bits <= 32 ? proto_tree_add_uint(tree, *n->hf, st->tvb, offset, length, (guint32)bits)
                             : add_variable_hex(st, n, tree, offset, length, bits);
        break;
    default: item = proto_tree_add_int64(tree, *n->hf, st->tvb, offset, length, v.integer); break;
    }
    proto_item_set_generated(item);
    if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
}

void dissect_leaf(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end)
{
    if (n->flags & DG_GROUP) {
        dissect_bit_field(st, n, tree, offset, end);
        return;
    }
    if (n->length_kind == DG_LEN_COMPUTED) {
        dissect_computed(st, n, tree, *offset);
        return;
    }
    gint64 length = leaf_length(st, n, tree, *offset, end);
    if (length < 0) return;
    gint left = end - *offset;
    if (length > left) {
        report_short_leaf(st, n, tree, *offset, length, left);
        return;
    }
    gint len = (gint)length;
    if (n->extra && (n->extra->dissector || n->extra->reassemble_id >= 0) && len > 0) {
        dissect_handoff(st, n, tree, *offset, len);
        store(st, n, 0, *offset, len);
    } else {
        decode_leaf_value(st, n, tree, *offset, len);
    }
    *offset += len;
}

/* --- containers ---------------------------------------------------------- */

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

/* A container's length at start: -1 when its children make it; FALSE when
 * its length field is missing or negative (reported). */
gboolean container_length(dg_state *st, const dg_node *n, proto_tree *tree, gint start, gint end, gint64 *length)
{
    switch (n->length_kind) {
    case DG_LEN_FIXED: *length = n->length; break;
    case DG_LEN_FIELD: return ref_value(st, &n->length_ref, n, "length", tree, start, length);
    case DG_LEN_REST: return rest_length(st, n, tree, start, end, length);
    default: *length = -1; break;
    }
    return TRUE;
}

/* The container's item and subtree (NULL without a tree). Length 0 now, the
 * real length once the children are decoded: a length of -1 would throw when
 * the container starts at the end of the packet. An unnamed container
 * (filter="") is the text item proto_tree_add_subtree() would add, labelled
 * without printf (dg_set_label); its name is there at once, should decoding
 * end in an exception before its summary. */
proto_tree *open_container(const dg_state *st, const dg_node *n, proto_tree *tree, gint start, proto_item **item)
{
    if (!tree) return NULL; /* nothing to add to */
    if (n->hf) {
        *item = proto_tree_add_item(tree, *n->hf, st->tvb, start, 0, ENC_NA);
        return proto_item_add_subtree(*item, *n->ett);
    }
    /* Where no label is shown proto_tree_add_subtree() is as cheap; past the
     * captured bytes proto_tree_add_item() would throw, the text item not. */
    if (!PTREE_DATA(tree)->visible || start > st->packet_end)
        return proto_tree_add_subtree(tree, st->tvb, start, 0, *n->ett, item, n->name);
    *item = proto_tree_add_item(tree, hf_text_only, st->tvb, start, 0, ENC_NA);
    if (!dg_set_label(*item, n->name, NULL)) proto_item_set_text(*item, "%s", n->name);
    return proto_item_add_subtree(*item, *n->ett);
}

/* "Name: summary" on the container's item, written whole where the label is
 * still just the name (an unnamed container's, or a named one's field name
 * while it has no text); otherwise, or when it does not fit, appended by
 * Wireshark as before. */
void label_container(const dg_node *n, proto_item *item, const char *summary)
{
    field_info *fi = PITEM_FINFO(item);
    const char *name = !n->hf ? n->name : fi && !fi->rep ? fi->hfinfo->name : NULL;
    if (!name || !dg_set_label(item, name, summary)) proto_item_append_text(item, ": %s", summary);
}

/* The bytes between the end of a container's fields (at) and the end its
 * length gives (inner_end): padding when zero, otherwise not decoded. */
void show_trailing_bytes(dg_state *st, const dg_node *n, proto_tree *subtree, gint start, gint at, gint inner_end,
                         gint64 length)
{
    if (!st->p->no_padding && all_zero(st, at, inner_end - at)) {
        /* Zero bytes up to the length: padding, which senders may add (to
         * a minimum length, or a length rounded up). Nothing is wrong. */
        if (subtree) proto_tree_add_item(subtree, hf_padding, st->tvb, at, inner_end - at, ENC_NA);
    } else {
        /* The length says more than the fields hold: say so, then skip to the end. */
        proto_tree_add_expert_format(subtree, st->pinfo, &st->p->ei->unused, st->tvb, at, inner_end - at,
                                     "'%s' is %" G_GINT64_MODIFIER "d bytes, but its fields end after %d: "
                                     "%d bytes are not decoded",
                                     n->name, length, at - start, inner_end - at);
    }
}

/* A container that a summary refers to: decoded in this instance. */
void container_decoded(dg_state *st, const dg_node *n, gint start, gint end)
{
    dg_slot *s = &st->slots[n->slot];
    s->offset = start;
    s->length = end - start;
    s->node = n;
    st->present[n->slot] = TRUE;
    /* Named by a summary across a repeat (dg_extra.kept_slots): its text now,
     * which a later instance of the repeat without it leaves. */
    if (!n->extra || !n->extra->kept_count || !st->want_text) return;
    s->value = (guint64)(guintptr)wmem_strdup(st->pinfo->pool, summary_text(st, n));
    for (guint8 i = 0; i < n->extra->kept_count; i++) {
        st->slots[n->extra->kept_slots[i]] = *s;
        st->present[n->extra->kept_slots[i]] = TRUE;
    }
}

/* The container's summary on its item and, outside other summaries, in the
 * Info column (or in sink, for a repeated node's instances); an empty one
 * nowhere. */
void show_summary(dg_state *st, const dg_node *n, proto_item *item, gboolean in_summary, dg_summaries *sink)
{
    const char *text = summary_text(st, n);
    gsize text_len = st->text->len;
    /* A summary all of whose parts were absent says nothing: no "Name: ", no ", " in Info. */
    if (text_len == 0) return;
    if (item) label_container(n, item, text);
    if (in_summary || !st->want_info) return;
    if (sink) {
        if (sink->count++) text_append(&sink->text, ", ", 2);
        text_append(&sink->text, text, text_len);
    } else {
        info_append(st, text, text_len);
    }
}

void dissect_container(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end,
                       gboolean in_summary, dg_summaries *sink)
{
    gint start = *offset;
    if (G_UNLIKELY(st->header_only) && start >= st->packet_end) { /* past the header of a short stream message */
        st->stopped = TRUE;
        return;
    }
    gint64 length = -1;
    if (!container_length(st, n, tree, start, end, &length)) return;
    gboolean past_end = length > end - start;
    gint inner_end = (length >= 0 && !past_end) ? start + (gint)length : end;

    proto_item *item = NULL;
    proto_tree *subtree = open_container(st, n, tree, start, &item);
    /* A length field past the end is the fault, where it points; the
     * children's lengths that end within it are not faults of their own.
     * When the capture cut the bytes, that is said after what they hold. */
    const gint64 outer_told_end = st->told_end;
    const gint outer_told_short_at = st->told_short_at;
    const gboolean length_past_end = past_end && n->length_kind == DG_LEN_FIELD;
    const gboolean cut = past_end && cut_by_capture(st, end, start + length);
    if (length_past_end && !cut) {
        report_missing(st, subtree, &st->p->ei->past_end, end, start + length, start, end - start,
                       "'%s' has length %" G_GINT64_MODIFIER "d, past the end of its data (%d bytes left)", n->name,
                       length, end - start);
        if (start + length > st->told_end) {
            st->told_end = start + length;
            st->told_short_at = end;
        }
    }
    /* Decode what is there even when the length overruns. */
    gboolean was_stopped = st->stopped;
    st->stopped = FALSE;
    /* Where the children's bytes end on the wire, when the capture cut them
     * short: this container's end when it is cut; an end the capture kept,
     * none; a length from the children, the enclosing one's. */
    const gint outer_cut_end = st->cut_end;
    if (length >= 0)
        st->cut_end = cut ? (gint)(start + length) : DG_END_KNOWN;
    if (n->window >= 0) /* a window: children at addresses, not one after another */
        dissect_window(st, n, subtree, offset, inner_end, in_summary || n->summary_count > 0);
    else
        walk_list(st, n->walk, n->first_child, n->child_count, subtree, offset, inner_end,
                  in_summary || n->summary_count > 0);
    /* A length cut short: the child where the bytes ran out said so; only
     * when none did (they all fit) is the container itself short. */
    if (past_end && !st->stopped) {
        if (cut)
            capture_cut(st, subtree);
        else if (!length_past_end)
            report_missing(st, subtree, &st->p->ei->truncated, end, start + length, start, end - start,
                           "Truncated: '%s' needs %" G_GINT64_MODIFIER "d bytes, only %d left", n->name, length,
                           end - start);
    }
    st->cut_end = outer_cut_end;
    /* What was told inside stays inside, but for a list told short where the
     * data this container shares with its parent ends (list_told_short):
     * the parent's next field misses those bytes too. */
    if (st->told_end != G_MAXINT64 || st->told_short_at < end) {
        st->told_end = outer_told_end;
        st->told_short_at = outer_told_short_at;
    }
    st->stopped = st->stopped || was_stopped;
    if (!st->stopped && length >= 0 && *offset < inner_end &&
        (n->length_kind == DG_LEN_FIXED || n->length_kind == DG_LEN_FIELD)) {
        show_trailing_bytes(st, n, subtree, start, *offset, inner_end, length);
    }
    if (!st->stopped && length >= 0) *offset = inner_end;
    if (st->stopped && !was_stopped && !length_past_end && (n->flags & DG_SKIP_MALFORMED) && length >= 0) {
        /* malformed="skip": the spot is marked by its expert info; the rest of
         * this container is left undecoded and decoding goes on after it, as
         * for a PDU in a tvb of its own. */
        st->stopped = FALSE;
        *offset = inner_end;
    }
    proto_item_set_len(item, *offset - start);
    if (n->slot >= 0) container_decoded(st, n, start, *offset);
    /* The text only when something shows it: the item, or the Info column
     * (a summarised container inside another one only has its item). */
    if (n->summary_count > 0 && st->want_text && (item || (!in_summary && st->want_info)))
        show_summary(st, n, item, in_summary, sink);
}

/* --- repetition ---------------------------------------------------------- */

/* The most instances of a counted list whose instances take no bytes: the
 * packet's size does not bound it, this does. */
#define DG_MAX_INSTANCES_WITHOUT_BYTES 65535

/* A list told short where its data ends (a count or a repeat flag): that is
 * the one fault; a later field of the message that needs the bytes past
 * that end misses the same ones, and stops decoding without telling it again
 * (report_missing), while empty ones still decode. */
static void list_told_short(dg_state *st, gint end)
{
    if (!st->told_end || end < st->told_short_at) st->told_short_at = end;
    st->told_end = G_MAXINT64;
    st->stopped = FALSE;
}

/* repeat: another instance while the flag is set; count: exactly N. Every
 * instance must consume bytes, which bounds the loop by the packet size;
 * a counted list whose instances take none (computed values and overlays,
 * e.g. entries laid out by a learned mapping) is bounded by a limit. */
void dissect_repeated(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary)
{
    gint64 wanted = -1;
    if (n->count.slot >= 0 && !ref_value(st, &n->count, n, "count", tree, *offset, &wanted)) return;
    const gboolean no_bytes = n->extra && n->extra->no_bytes;
    if (no_bytes && wanted > DG_MAX_INSTANCES_WITHOUT_BYTES) {
        report(st, tree, &st->p->ei->bad_length, *offset, 0,
               "'%s' should occur %" G_GINT64_MODIFIER "d times; a list whose entries take no bytes has at most %d",
               n->name, wanted, DG_MAX_INSTANCES_WITHOUT_BYTES);
        return;
    }
    if (n->extra && n->extra->keep_values) table_reset(st, n, *offset); /* a new table for this repetition */
    dg_summaries summaries;
    gboolean collect = summaries_begin(st, n, in_summary, &summaries);

    guint instances = 0;
    const guint32 outer_instance = st->instance;
    for (gint64 done = 0; wanted < 0 || done < wanted; done++) {
        if (wanted >= 0 && *offset >= end && !no_bytes) {
            report_missing(st, tree, &st->p->ei->count_short, end, (gint64)end + 1, *offset, 0,
                           "'%s' should occur %" G_GINT64_MODIFIER "d times, but the data ends after "
                           "%" G_GINT64_MODIFIER "d", n->name, wanted, done);
            list_told_short(st, end); /* the data simply ended: siblings may still be empty-length */
            break;
        }
        if (n->extra && n->extra->repeat_rest && *offset >= end) break; /* repeat="rest": stop where the data ends */
        clear_slots(st, n);
        gint before = *offset;
        st->instance = instances;
        dissect_instance(st, n, tree, offset, end, in_summary, collect ? &summaries : NULL);
        instances++;
        if (st->stopped || (*offset == before && !no_bytes)) break;
        if (n->repeat_slot >= 0) {
            const dg_slot *flag = &st->slots[n->repeat_slot];
            if (!st->present[n->repeat_slot] || flag->value == 0) break;
            if (*offset >= end) {
                report_missing(st, tree, &st->p->ei->more_no_data, end, (gint64)end + 1, *offset, 0,
                               "'%s': the repeat flag '%s' says another follows, but no data is left", n->name,
                               flag->node->name);
                list_told_short(st, end);
                break;
            }
        }
    }
    st->instance = outer_instance;
    if (st->tap) tap_record(st, n, instances);
    if (collect) summaries_end(st, n, &summaries);
}

/* A packed list of bit fields (length="Nbit" with count, N dividing 8): `count`
 * values of N bits, filling each byte from its least significant bits in a
 * little-endian node, from its most significant otherwise; the list takes the
 * whole bytes they need, bits after the last value included. Each value is an
 * item on its byte showing its bits; the slot keeps the last. */
void dissect_packed_bits(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end)
{
    gint64 wanted = 0;
    if (!ref_value(st, &n->count, n, "count", tree, *offset, &wanted)) return;
    const guint per_byte = 8u / n->bits;
    const gint64 bytes = wanted / per_byte + (wanted % per_byte != 0); /* rounded up, no overflow */
    const gint64 have = MIN(bytes, (gint64)(end - *offset));
    const gint64 instances = MIN(wanted, have * per_byte);
    const guint mask = (1u << n->bits) - 1;
    const guint32 outer_instance = st->instance;
    for (gint64 i = 0; i < instances; i++) {
        const gint at = *offset + (gint)(i / per_byte);
        const guint pos = (guint)(i % per_byte) * n->bits;            /* bits before it in its byte */
        const guint from_msb = (n->flags & DG_LITTLE) ? 8 - pos - n->bits : pos;
        st->instance = (guint32)i;
        if (tree) {
            proto_item *item = proto_tree_add_bits_item(tree, *n->hf, st->tvb, at * 8 + (gint)from_msb, n->bits,
                                                        ENC_BIG_ENDIAN);
            if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
        }
        if (value_wanted(st, n))
            store(st, n, (dg_tvb_get_uint8(st->tvb, at) >> (8 - from_msb - n->bits)) & mask, at, 1);
    }
    st->instance = outer_instance;
    *offset += (gint)have;
    if (st->tap) tap_record(st, n, (guint64)instances);
    if (instances < wanted) {
        report_missing(st, tree, &st->p->ei->count_short, *offset, (gint64)*offset + 1, *offset, 0,
                       "'%s' should occur %" G_GINT64_MODIFIER "d times, but the data ends after %" G_GINT64_MODIFIER
                       "d", n->name, wanted, instances);
        list_told_short(st, *offset); /* the data simply ended, as for any repetition */
    }
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

/* Where the offsets of a located node count from (from="XPATH"): the first
 * byte of a field, or the start of an enclosing container's content. FALSE
 * (reported) when that field is not in this packet. */
gboolean offsets_base(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint64 *base)
{
    const dg_extra *x = n->extra;
    if (x->from_slot >= 0) {
        const dg_slot *fs = &st->slots[x->from_slot];
        if (!st->present[x->from_slot]) {
            report(st, tree, &st->p->ei->bad_length, offset, 0,
                   "The offsets of '%s' count from a field that is not in this packet", n->name);
            return FALSE;
        }
        *base = fs->offset;
    } else if (x->from_up <= st->lists && st->lists - x->from_up < DG_MAX_LISTS) {
        *base = st->list_starts[st->lists - x->from_up];
    } else {
        *base = 0; /* nested deeper than the lists kept: from the message */
    }
    return TRUE;
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
    if (!offsets_base(st, n, tree, *offset, &base)) return;
    if (t->overflow) {
        report(st, tree, &st->p->ei->bad_offset, ts->offset, ts->length,
               "The offset table '%s' has more than %u entries; '%s' is not decoded", ts->node->name,
               (guint)DG_MAX_TABLE, n->name);
        return;
    }
    dg_summaries summaries;
    gboolean collect = summaries_begin(st, n, in_summary, &summaries);
    guint instances = 0;
    const guint32 outer_instance = st->instance;
    gint first = *offset;
    for (guint i = 0; i < t->count && !st->stopped; i++) {
        if (i == 0 && !entry_ok(st, n, tree, t, 0, base, first, end, first)) break;
        gint64 from = base + (gint64)t->values[i]; /* checked: inside [first, end] */
        gint to = end;
        const gint outer_cut_end = st->cut_end; /* the last instance ends where the list does */
        if (i + 1 < t->count) {
            if (!entry_ok(st, n, tree, t, i + 1, base, from, end, first)) break;
            to = (gint)(base + (gint64)t->values[i + 1]);
            st->cut_end = DG_END_KNOWN; /* the next offset gives its end */
        }
        gint at = (gint)from;
        clear_slots(st, n);
        st->instance = i;
        dissect_instance(st, n, tree, &at, to, in_summary, collect ? &summaries : NULL);
        st->cut_end = outer_cut_end;
        instances++;
        if (!st->stopped) *offset = to;
    }
    st->instance = outer_instance;
    if (st->tap) tap_record(st, n, instances);
    if (collect) summaries_end(st, n, &summaries);
}

/* --- findings from the rules ---------------------------------------------- */

/* n's <finding>s, once an instance of it is decoded in [start, stop): each
 * whose condition holds (defined and not zero: a field it reads that was not
 * decoded keeps it quiet) is raised on those bytes, beside n's item, with its
 * text built as a summary is. */
void raise_findings(dg_state *st, const dg_node *n, proto_tree *tree, gint start, gint stop)
{
    const dg_protocol *p = st->p;
    for (guint i = 0; i < n->extra->finding_count; i++) {
        const dg_finding *f = &p->findings[n->extra->finding_first + i];
        dg_expr_value v = dg_expr_eval(&p->exprs[f->expr_first], f->expr_count, &message_readers, st,
                                       st->instance);
        if (!v.defined || (v.is_float ? v.real == 0.0 : v.integer == 0)) continue;
        char buf[256];
        dg_text text;
        text_init(&text, st->pinfo->pool, buf, sizeof buf);
        append_text_pieces(st, &text, f->text_first, f->text_count);
        gint at = MIN(start, st->packet_end);
        proto_tree_add_expert_format(tree, st->pinfo, f->ei, st->tvb, at, MAX(0, MIN(stop, st->packet_end) - at),
                                     "%s", text.data);
    }
}

/* --- overlays ------------------------------------------------------------ */

/* overlay="XPATH": the container decodes the bytes of an earlier node,
 * from its first byte to its end (its own length, if any, must fit in
 * them), and leaves the walk's position where it is. Skipped when that node
 * is not in this message. */
void dissect_overlay(dg_state *st, const dg_node *n, proto_tree *tree, gboolean in_summary)
{
    const gint16 target = n->extra->overlay_slot;
    if (!st->present[target]) return;
    const dg_slot *t = &st->slots[target];
    gint at = t->offset;
    const gint outer_cut_end = st->cut_end; /* the node overlaid was decoded whole: its end is known */
    st->cut_end = DG_END_KNOWN;
    dissect_container(st, n, tree, &at, t->offset + t->length, in_summary, NULL);
    st->cut_end = outer_cut_end;
    /* as for any container: one cut short says and teaches nothing */
    if (st->stopped) return;
    if (n->extra->finding_count) raise_findings(st, n, tree, t->offset, at);
    if (n->extra->learn_count) learn_values(st, n);
}

/* --- lists of siblings --------------------------------------------------- */

/* The table walk: the members of a list in the order dg_protocol.children
 * gives them (a list the generator did not compile). */
void dissect_list(dg_state *st, guint16 first, guint16 count, proto_tree *tree, gint *offset, gint end,
                  gboolean in_summary)
{
    gboolean chain_taken = FALSE; /* a conditional sibling was decoded: its otherwise members are not */
    list_begin(st, *offset, end);
    for (guint16 i = 0; i < count && !st->stopped; i++)
        dissect_child(st, st->p->conditions, &st->p->nodes[st->p->children[first + i]], tree, offset, end, in_summary,
                      &chain_taken);
    list_end(st);
}

/* A list of siblings: with the walk the generator compiled for it, else
 * (none, or DISSGEN_TABLE_WALK) with the table walk. */
void walk_list(dg_state *st, dg_list_walk walk, guint16 first, guint16 count, proto_tree *tree, gint *offset,
               gint end, gboolean in_summary)
{
    if (walk && !table_walk_only)
        walk(st, tree, offset, end, in_summary);
    else
        dissect_list(st, first, count, tree, offset, end, in_summary);
}

/* --- one message ----------------------------------------------------------- */

/* Request when the port the hook (or Decode As) matched is the
 * destination port, response when it is only the source port. */
guint8 direction_of(const packet_info *pinfo)
{
    if (pinfo->ptype == PT_NONE) return DG_DIR_ANY;
    if (pinfo->destport == pinfo->match_uint) return DG_DIR_REQUEST;
    if (pinfo->srcport == pinfo->match_uint) return DG_DIR_RESPONSE;
    return DG_DIR_ANY;
}

/* Request or response, as the pairing takes the message: what its <request>
 * field says when it was decoded, else the transport's direction. */
guint8 message_role(const dg_state *st, const dg_request_role *r)
{
    if (!r || !st->present[r->slot]) return st->direction;
    return role_holds(st, r) ? DG_DIR_REQUEST : DG_DIR_RESPONSE;
}

/* Whether the protocol below this message is Ethernet's type field. Asked
 * before the walk: then the last layer is ours and the one before it is what
 * called us (the walk's hand-offs add layers after ours). */
gboolean carried_by_ethertype(const dg_protocol *p, const packet_info *pinfo)
{
    static int ethertype = -2;
    if (ethertype == -2) ethertype = proto_get_id_by_filter_name("ethertype");
    wmem_list_frame_t *ours = wmem_list_tail(pinfo->layers);
    if (!ours || GPOINTER_TO_INT(wmem_list_frame_data(ours)) != *p->proto) return FALSE;
    wmem_list_frame_t *below = wmem_list_frame_prev(ours);
    return below && ethertype >= 0 && GPOINTER_TO_INT(wmem_list_frame_data(below)) == ethertype;
}

/* The bytes after the message's last field, when its walk went to its end
 * (not stopped: by a malformed spot, or by a value from a request not
 * captured) and reported nothing malformed on the way (then that report
 * explains them: a header whose length leaves the last datagram out, say).
 * Carried by an Ethernet type, the message ends at its fields and the rest is
 * the link layer's: zeros are Ethernet's padding, shown by nobody (as
 * Wireshark's own EtherCAT plugin leaves them), anything else is given back to
 * Ethernet (set_actual_length, as IP does), which shows it as its trailer.
 * Otherwise the message is all its transport gave (a UDP payload, a pdulength
 * PDU): as in a container of known length, zeros are padding and other bytes
 * are not decoded, a warning. */
void show_message_tail(dg_state *st, proto_tree *tree, gint offset, gboolean on_ethertype)
{
    if (st->stopped || st->faulted || offset <= 0 || offset >= st->packet_end) return;
    gint rest = st->packet_end - offset;
    gboolean zero = all_zero(st, offset, rest);
    if (on_ethertype) { /* Ethernet's own padding to 60 bytes, whatever the protocol says */
        if (!zero) set_actual_length(st->tvb, (guint)offset);
        return;
    }
    if (zero && !st->p->no_padding) {
        if (tree) proto_tree_add_item(tree, hf_padding, st->tvb, offset, rest, ENC_NA);
        return;
    }
    proto_tree_add_expert_format(tree, st->pinfo, &st->p->ei->unused, st->tvb, offset, rest,
                                 "%d byte%s after the message's last field %s not decoded", rest,
                                 rest == 1 ? "" : "s", rest == 1 ? "is" : "are");
}

/* Keys of the per-packet count of messages decoded and of their Info texts
 * joined (p_add_proto_data). */
#define DG_MESSAGES_KEY 0x6d736773u
#define DG_INFO_KEY 0x696e666fu

/* How many messages of this protocol the packet has had, this one included.
 * Wireshark counts the calls of a protocol in a packet (curr_proto_layer_num:
 * a message in a message, EtherCAT in EoE); the messages of one TCP segment
 * (pdulength, tcp_dissect_pdus) come in one call, so a protocol with a
 * pdulength counts them itself. */
guint count_message(const dg_protocol *p, packet_info *pinfo)
{
    if (p->pdu_node < 0 && pinfo->curr_proto_layer_num > 0) return pinfo->curr_proto_layer_num;
    guint *messages = (guint *)p_get_proto_data(pinfo->pool, pinfo, *p->proto, DG_MESSAGES_KEY);
    if (!messages) {
        messages = wmem_new0(pinfo->pool, guint);
        p_add_proto_data(pinfo->pool, pinfo, *p->proto, DG_MESSAGES_KEY, messages);
    }
    return ++*messages;
}

/* The buffers one message's state starts in, on dg_dissect's stack. The
 * values of one message live there when they fit (most rule files): two
 * allocations fewer per message. Nothing keeps them after it. */
enum { stack_slots = 128, stack_cycle_values = 64 };
struct dg_message_buffers {
    dg_slot slots[stack_slots];
    guint8 present[stack_slots];
    /* <cycles>: the first signature values of a message (dg_cycle_input) */
    guint64 cycle_values[stack_cycle_values];
    guint16 cycle_nodes[stack_cycle_values];
    const guint8 *cycle_bytes[stack_cycle_values];
    guint32 cycle_lengths[stack_cycle_values];
    dg_text info_text, scratch_text;
    char info_buf[256], scratch_buf[256];
};

void begin_message(dg_state *st, dg_message_buffers *b, const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo,
                   proto_tree *tree)
{
    memset(st, 0, offsetof(dg_state, list_starts)); /* the lists' bounds are written as they open */
    st->p = p;
    st->tvb = tvb;
    st->pinfo = pinfo;
    if (p->slot_count <= stack_slots) {
        st->slots = b->slots;
        st->present = b->present;
        memset(b->present, 0, p->slot_count);
    } else {
        st->slots = wmem_alloc_array(pinfo->pool, dg_slot, p->slot_count);
        st->present = (guint8 *)wmem_alloc0(pinfo->pool, p->slot_count);
    }
    st->packet_end = (gint)tvb_captured_length(tvb);
    st->hook_value = pinfo->match_uint;
    st->direction = direction_of(pinfo);
    /* The analysis reads its inputs on the first pass only (dissgen_pairing.h). */
    st->wants_view = p->pairing && p->pairing->analysis && !PINFO_FD_VISITED(pinfo);
    st->wants_cycles = p->cycles && !PINFO_FD_VISITED(pinfo);
    if (st->wants_cycles) {
        st->cycle.values = b->cycle_values;
        st->cycle.nodes = b->cycle_nodes;
        st->cycle.bytes = b->cycle_bytes;
        st->cycle.lengths = b->cycle_lengths;
        st->cycle_capacity = stack_cycle_values;
        st->cycle_on_stack = TRUE;
    }
    /* Summaries are text for the Info column and for container items; build
     * them only when someone sees them: tshark -T fields and -V have a visible
     * tree and no columns, summary lines have columns and no tree, and a
     * filter-only pass (-Y with -w) has neither. */
    st->want_info = pinfo->cinfo != NULL;
    st->want_text = st->want_info || (tree != NULL && PTREE_DATA(tree)->visible);
    /* The Info column and the summary scratch start on the stack. */
    if (st->want_info) {
        text_init(&b->info_text, pinfo->pool, b->info_buf, sizeof b->info_buf);
        st->info = &b->info_text;
    }
    if (st->want_text) {
        text_init(&b->scratch_text, pinfo->pool, b->scratch_buf, sizeof b->scratch_buf);
        st->text = &b->scratch_text;
    }
    if (stats_tap >= 0 && have_tap_listener(stats_tap)) st->tap = wmem_new0(pinfo->pool, dg_tap_data);
    /* nobody sees items or the text of expert infos without a tree
     * and without a tap listener (the Expert dialog and -z expert are taps):
     * quiet nodes are stepped over, expert infos are raised without text
     * (their severity still reaches the Expert column). */
    st->quiet = tree == NULL && !tap_listeners_require_dissection();
}

} // namespace

namespace dg_rt {

gboolean table_walk_only = FALSE;

const dg_expr_readers message_readers = {read_slot, read_request, read_learned, read_offset};

void dissect_node(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary)
{
    if (n->extra && (n->extra->offsets_slot >= 0 || n->extra->overlay_slot >= 0)) {
        if (n->extra->overlay_slot >= 0)
            dissect_overlay(st, n, tree, in_summary); /* the bytes of an earlier node */
        else
            dissect_located(st, n, tree, offset, end, in_summary); /* offset table */
    } else if (n->length_kind == DG_LEN_PACKED)
        dissect_packed_bits(st, n, tree, offset, end);
    else if (is_repeated(n))
        dissect_repeated(st, n, tree, offset, end, in_summary);
    else
        dissect_instance(st, n, tree, offset, end, in_summary, NULL);
}

void dissect_instance(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end,
                      gboolean in_summary, dg_summaries *sink)
{
    const gint start = *offset;
    if (n->kind == DG_LEAF)
        dissect_leaf(st, n, tree, offset, end);
    else
        dissect_container(st, n, tree, offset, end, in_summary, sink);
    /* Only a node decoded whole: one that reported a malformed spot has no value to judge. */
    if (n->extra && n->extra->finding_count && !st->stopped) raise_findings(st, n, tree, start, *offset);
    if (n->extra && n->extra->learn_count && !st->stopped) learn_values(st, n);
}

} // namespace dg_rt

namespace {

/* A TCP message whose length field says less than the bytes up to the end
 * of that field takes the rest of its segment (dg_message_length): only its
 * header is walked, the bytes after it are not decoded. -1 when the message's
 * length is sound (or it is not a stream message). */
gint64 short_stream_length(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, guint *header)
{
    if (p->pdu_node < 0 || pinfo->ptype != PT_TCP) return -1;
    if (tvb_captured_length(tvb) < stream_header_length(p)) return -1;
    const gint64 length = stream_message_length(p, tvb, 0, header);
    /* a varint length cut short or never ending: the walk says so at it */
    if (length == DG_STREAM_LENGTH_MORE || length == DG_STREAM_LENGTH_BAD) return -1;
    return length < (gint64)*header ? length : -1;
}

void report_short_stream_message(dg_state *st, proto_tree *tree, gint64 length, guint rest, guint header)
{
    const dg_protocol *p = st->p;
    const dg_node *n = &p->nodes[p->pdu_node];
    st->header_only = FALSE;
    st->stopped = FALSE; /* what the header lacked past its end was this fault */
    report(st, tree, &p->ei->bad_length, (gint)p->pdu_offset, (gint)(header - p->pdu_offset),
           "The message length '%s' gives (%" G_GINT64_MODIFIER "d) is shorter than the %u bytes up to its end; "
           "the %u byte%s after %s not decoded",
           n->name, length, header, rest, rest == 1 ? "" : "s", rest == 1 ? "it is" : "them are");
}

/* The Info column: the first message's text, each later one's joined with
 * " | ". The texts of the frame's earlier messages are kept per packet: a
 * dissector that carries several of ours (TPKT and COTP calling a heuristic
 * once per TPKT message) writes its own text over ours between them, and
 * then the column is written again from them. While the column still holds
 * ours, the text is appended (after a fence TCP set between two messages of
 * a segment, writing the column would repeat the first's). Beyond what the
 * column holds nothing is added.
 * A message inside the first (EtherCAT in EoE) appends to the column: the
 * first's text comes once it is decoded, and replaces it. */
void show_info(const dg_protocol *p, packet_info *pinfo, const char *info, gboolean first_message,
               gboolean on_ethertype)
{
    if (first_message && on_ethertype) { /* Ethernet carries one: nothing to keep (a message inside it appends) */
        col_add_str(pinfo->cinfo, COL_INFO, info);
        return;
    }
    wmem_strbuf_t *joined = (wmem_strbuf_t *)p_get_proto_data(pinfo->pool, pinfo, *p->proto, DG_INFO_KEY);
    if (first_message) {
        joined = wmem_strbuf_new(pinfo->pool, info);
        p_set_proto_data(pinfo->pool, pinfo, *p->proto, DG_INFO_KEY, joined);
        col_add_str(pinfo->cinfo, COL_INFO, info);
        return;
    }
    const char *shown = col_get_text(pinfo->cinfo, COL_INFO);
    const gboolean still_ours = !joined || (shown && strcmp(shown, wmem_strbuf_get_str(joined)) == 0);
    if (joined && wmem_strbuf_get_len(joined) < COL_MAX_INFO_LEN) {
        wmem_strbuf_append(joined, " | ");
        wmem_strbuf_append(joined, info);
    }
    if (still_ours)
        col_append_sep_str(pinfo->cinfo, COL_INFO, " | ", info);
    else
        col_add_str(pinfo->cinfo, COL_INFO, wmem_strbuf_get_str(joined));
}

} // namespace

int dg_dissect(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    col_set_str(pinfo->cinfo, COL_PROTOCOL, p->short_name);
    /* Several messages in one packet (a TCP segment): each adds its Info text. */
    const guint messages = count_message(p, pinfo);
    const gboolean on_ethertype = carried_by_ethertype(p, pinfo);
    gboolean first_message = messages == 1;
    if (first_message) col_clear(pinfo->cinfo, COL_INFO);

    guint header = 0;
    const gint64 short_length = short_stream_length(p, tvb, pinfo, &header);
    const guint segment_rest = (guint)tvb_reported_length(tvb) - (short_length >= 0 ? header : 0);
    if (short_length >= 0) tvb = tvb_new_subset_length(tvb, 0, (gint)header);

    dg_state st;
    dg_message_buffers buffers;
    begin_message(&st, &buffers, p, tvb, pinfo, tree);
    st.header_only = short_length >= 0;

    proto_item *root = tree ? proto_tree_add_item(tree, *p->proto, tvb, 0, 0, ENC_NA) : NULL;
    proto_tree *subtree = proto_item_add_subtree(root, *p->ett);
    gint offset = 0;
    st.message = messages - 1;
    if (p->request_context) request_begin(&st);
    walk_list(&st, p->top_walk, p->top_first, p->top_count, subtree, &offset, st.packet_end, FALSE);
    if (st.header_only) report_short_stream_message(&st, subtree, short_length, segment_rest, header);
    show_message_tail(&st, subtree, offset, on_ethertype);
    proto_item_set_len(root, offset);
    const dg_frame_pairing *fp = NULL;
    if (p->pairing) {
        if (st.request_pending) request_walked(&st);
        const gboolean analysis_cycles = st.wants_cycles && dg_analysis_times_cycles(p);
        const dg_view view = {st.views, st.view_count, analysis_cycles ? &st.cycle : NULL};
        if (takes_part_in_pairing(&st, p->pairing->unanswered))
            fp = dg_pairing_dissect(p, tvb, pinfo, subtree, st.keys, st.key_count, st.wants_view ? &view : NULL,
                                    offset, messages - 1, message_role(&st, p->pairing->request));
        if (st.tap) st.tap->pairing = fp;
        if (p->request_context) request_end(&st, fp, subtree);
    }

    if (p->cycles && !dg_analysis_times_cycles(p)) {
        dg_cycles_dissect(p, tvb, pinfo, subtree, st.wants_cycles ? &st.cycle : NULL, fp, messages - 1);
    }

    if (st.tap) tap_queue_packet(stats_tap, pinfo, st.tap);
    show_info(p, pinfo, st.info && st.info->len > 0 ? st.info->data : p->name, first_message, on_ethertype);
    /* The message is ours even when it took no bytes (an Ethernet frame that
     * ends after its type: its expert info says what is missing); 0 would
     * tell the caller (ethertype, udp) that it is not, and it would show the
     * frame as undissected under our tree. */
    return offset > 0 ? offset : MAX(st.packet_end, 1);
}

// SPDX-License-Identifier: GPL-2.0-or-later
/* What decides where and whether the walk decodes a node: the values of
 * references (lengths, counts, fragment offsets), offset tables, conditions
 * (if, ifhook, <when> with peeks ahead, otherwise chains, direction), and
 * windows, whose children sit at addresses rather than one after another.
 *
 * Like the whole runtime: no non-trivial C++ object (Wireshark's exceptions
 * are longjmps), memory from pinfo->pool, every read checked first.
 */
#include "dissgen_state.h"

#include <wsutil/sign_ext.h>

#include <stdlib.h>
#include <string.h>

namespace dg_rt {

/* --- references and offset tables ---------------------------------------- */

/* The value a length, count or peek reference takes from its slot: an
 * `int` leaf's sign is its top bit (a 1-byte -1 is -1, not 255). */
static gint64 ref_slot_value(const dg_slot *s, const dg_ref *ref)
{
    guint64 v = s->value;
    const dg_node *n = s->node;
    if (ref->is_signed && n && n->show == DG_SHOW_INT && n->bits > 0 && n->bits < 64) v = ws_sign_ext64(v, n->bits);
    return ref_arith(v, ref);
}

gboolean ref_value(dg_state *st, const dg_ref *ref, const dg_node *n, const char *what, proto_tree *tree,
                   gint offset, gint64 *out)
{
    const dg_slot *s = &st->slots[ref->slot];
    if (!st->present[ref->slot]) {
        if (st->request_missed || st->request_none) {
            /* For want of the request (its expert info says so once), or a
             * request's values read from the request it does not have: not
             * malformed, but nothing after it can be placed. */
            st->stopped = TRUE;
            return FALSE;
        }
        report(st, tree, &st->p->ei->bad_length, offset, 0, "The %s of '%s' comes from a field that is not in this packet",
               what, n->name);
        return FALSE;
    }
    gint64 v = ref_slot_value(s, ref);
    if (v < 0) {
        report(st, tree, &st->p->ei->bad_length, offset, 0, "The %s of '%s' is negative (%" G_GINT64_MODIFIER "d)",
               what, n->name, v);
        return FALSE;
    }
    *out = v;
    return TRUE;
}

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

void table_put(dg_state *st, const dg_node *n, guint64 value)
{
    dg_table *t = table_of(st, n->slot);
    const guint i = st->instance;
    if (i >= DG_MAX_TABLE) {
        t->overflow = TRUE;
        return;
    }
    if (i >= t->capacity) {
        guint capacity = t->capacity ? t->capacity : 16;
        while (capacity <= i) capacity *= 2;
        capacity = MIN(capacity, (guint)DG_MAX_TABLE);
        t->values = (guint64 *)wmem_realloc(st->pinfo->pool, t->values, capacity * sizeof(guint64));
        t->present = (guint8 *)wmem_realloc(st->pinfo->pool, t->present, capacity);
        memset(t->present + t->capacity, 0, capacity - t->capacity);
        t->capacity = capacity;
    }
    t->values[i] = value;
    t->present[i] = 1;
    if (i >= t->count) t->count = i + 1;
}

/* The slot says the table is there, even when no instance follows (a count of 0). */
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

} // namespace dg_rt

using namespace dg_rt;

/* --- conditions (selected() in dissgen_state.h) -------------------------- */

/* A peek's bytes up to needed_end lie past `limit`: DG_PEEK_CUT when only
 * the capture's cut hides them (its list reaches the captured end, and the
 * frame on the wire has them), else DG_PEEK_ABSENT. */
static gint peek_missing(const dg_state *st, gint64 list_end, gint64 needed_end)
{
    return list_end >= st->packet_end && cut_by_capture(st, st->packet_end, needed_end) ? DG_PEEK_CUT
                                                                                        : DG_PEEK_ABSENT;
}

/* The value of the leaf a peek reads ahead, when its bytes are there. */
gint dg_rt::peek_value(const dg_state *st, const dg_peek *pk, gint node_start, guint64 *out)
{
    if (pk->up > st->lists || st->lists - pk->up >= DG_MAX_LISTS) return DG_PEEK_ABSENT;
    gint64 at = (gint64)(pk->up ? st->list_starts[st->lists - pk->up] : node_start) + pk->offset;
    /* The leaf must lie inside the list it belongs to: bytes after a container's
     * end (padding, the next message) are not its value. */
    guint list = st->lists - 1 - pk->target_up;
    gint64 list_end = (pk->target_up < st->lists && list < DG_MAX_LISTS) ? st->list_ends[list] : st->packet_end;
    gint64 limit = MIN(list_end, st->packet_end);
    for (guint i = 0; i < pk->length_count; i++) {
        const dg_ref *ref = &st->p->peek_lengths[pk->length_first + i];
        const dg_slot *s = &st->slots[ref->slot];
        if (!st->present[ref->slot]) return DG_PEEK_ABSENT;
        gint64 v = ref_slot_value(s, ref);
        if (v < 0) return DG_PEEK_ABSENT;
        at += v;
        if (at > limit) return peek_missing(st, list_end, at);
    }
    const dg_node *t = &st->p->nodes[pk->target];
    if (at + t->length > limit) return peek_missing(st, list_end, at + t->length);
    guint64 v = read_uint(st->tvb, (gint)at, t->length, encoding_of(t));
    *out = (t->flags & DG_GROUP) ? bit_field(v, t->shift, t->bits) : v;
    return DG_PEEK_VALUE;
}

namespace {

/* --- windows ------------------------------------------------------------- */

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
    gboolean no_chain = FALSE;
    if (!selected(st, st->p->conditions, c, start, &no_chain)) {
        if (st->peek_cut) capture_cut(st, tree);
        return;
    }
    guint32 i = 0;
    if (pl->stride && base > pl->at) i = (guint32)MIN((base - pl->at + pl->stride - 1) / pl->stride, (guint64)pl->instances);
    for (; i < pl->instances && !st->stopped; i++) {
        guint64 a = pl->at + (guint64)pl->stride * i;
        if (a < base) continue;
        if (a + pl->size > last) break;
        gint offset = start + (gint)(a - base);
        proto_node *before = tree ? tree->last_child : NULL;
        clear_slots(st, c);
        const gint outer_cut_end = st->cut_end; /* a place's size gives its end */
        st->cut_end = DG_END_KNOWN;
        dissect_instance(st, c, tree, &offset, offset + (gint)pl->size, in_summary, NULL);
        st->cut_end = outer_cut_end;
        if (pl->stride) label_instance(st, c, tree, before, i);
    }
}

/* Whether every instance of the place starts before base: none of them is in
 * the window. The places just below a window are many (those within the
 * largest span of it): this spares them the call to dissect_place(). */
inline gboolean all_before(const dg_place *pl, guint64 base)
{
    if (pl->at >= base) return FALSE;
    if (!pl->stride || pl->instances <= 1) return TRUE;
    return (base - pl->at - 1) / pl->stride >= (guint64)pl->instances - 1; /* the last one starts before base */
}

/* Whether the window calls dissect_place() for the place: not when nobody
 * would see it (quiet: it cannot be malformed either), nor when none of its
 * instances can be inside. */
inline gboolean place_wanted(const dg_state *st, const dg_place *pl, guint64 base)
{
    return !(st->quiet && pl->quiet) && !all_before(pl, base);
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

/* The address of the window's first byte: its base reference's value with
 * the arithmetic applied; FALSE (reported) when missing or out of range. */
gboolean window_base(dg_state *st, const dg_node *n, const dg_window *w, proto_tree *tree, gint offset,
                     guint64 *out)
{
    const dg_slot *s = &st->slots[w->base.slot];
    if (!st->present[w->base.slot]) {
        report(st, tree, &st->p->ei->bad_length, offset, 0,
               "The base address of '%s' comes from a field that is not in this packet", n->name);
        return FALSE;
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
        report(st, tree, &st->p->ei->bad_length, offset, 0, "The base address of '%s' is out of range", n->name);
        return FALSE;
    }
    *out = base;
    return TRUE;
}

} // namespace

/* A window's children: each place (each instance of a block) wholly inside
 * [base, base + window length), in document order. Places are sorted by
 * address: a binary search finds the first that may be inside, a scan the
 * last, and those whose instances all start before base are skipped. */
void dg_rt::dissect_window(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end,
                           gboolean in_summary)
{
    const dg_window *w = &st->p->windows[n->window];
    guint64 base;
    if (!window_base(st, n, w, tree, *offset, &base)) return;
    gint start = *offset;
    guint64 last = base + (guint64)(end - start);
    if (last < base) last = G_MAXUINT64; /* the top of the address space */
    const dg_place *places = &st->p->places[w->place_first];
    /* Places starting at or before base - max_span end at or before base;
     * those starting at or after last are past the window. */
    guint lo = base > w->max_span ? first_at_or_after(places, 0, w->place_count, base - w->max_span + 1) : 0;
    /* the places that may be inside are few and read next: a scan, not a second search */
    guint hi = lo;
    while (hi < w->place_count && places[hi].at < last) hi++;
    if (w->address_order_is_document_order || hi - lo < 2) {
        for (guint k = lo; k < hi && !st->stopped; k++) {
            /* most places of a register window are quiet or below it: no call for them */
            if (place_wanted(st, &places[k], base)) dissect_place(st, &places[k], tree, start, base, last, in_summary);
        }
    } else {
        const dg_place **order = wmem_alloc_array(st->pinfo->pool, const dg_place *, hi - lo);
        guint count = 0;
        for (guint k = lo; k < hi; k++)
            if (place_wanted(st, &places[k], base)) order[count++] = &places[k];
        qsort(order, count, sizeof *order, compare_node_index);
        for (guint k = 0; k < count && !st->stopped; k++) dissect_place(st, order[k], tree, start, base, last, in_summary);
    }
    *offset = end;
}

// SPDX-License-Identifier: GPL-2.0-or-later
/* <learn> and learned{Name}: values that a message teaches later ones
 * (dg_learn in dissgen_runtime.h).
 *
 * The first pass walks the frames in order. Once an instance of a node with
 * <learn>s is decoded, each learn whose condition holds and whose value and
 * keys are defined records the value in the entry of its keys (and, with
 * sender="yes", of the sender's address and port). An entry keeps each value
 * it was taught with the frame and message that taught it, and only when the
 * value changes: memory grows with what is learned, not with the frames.
 *
 * learned{Name} finds the entry with the keys as the reader computes them (a
 * key's lookup, else its value) and takes the latest value taught by a
 * message before this one. Since each value knows when it was learned, every
 * pass reads the same: tshark -2 and the GUI, frames clicked in any order,
 * see what the first pass saw at that frame.
 */
#include "dissgen_state.h"

#include <epan/address.h>

#include <string.h>

using namespace dg_rt;

namespace {

/* The frame and message that taught a value, ordered as the first pass met them. */
typedef struct {
    guint32 frame;
    guint32 message;
    guint64 value;
} taught;

/* What one <learn> learned under one set of keys. */
typedef struct {
    guint32 hash;
    guint16 learn;
    guint16 key_count;
    guint32 port;
    address src;
    guint64 *keys;
    taught *values; /* in the order of their messages */
    guint count, capacity;
} entry;

/* Per capture: the entries (wmem_file_scope, emptied when a file closes). */
wmem_map_t *entries = NULL;

guint entry_hash(gconstpointer k) { return ((const entry *)k)->hash; }

gboolean entry_equal(gconstpointer a, gconstpointer b)
{
    const entry *x = (const entry *)a, *y = (const entry *)b;
    return x->hash == y->hash && x->learn == y->learn && x->key_count == y->key_count && x->port == y->port &&
           addresses_equal(&x->src, &y->src) && memcmp(x->keys, y->keys, x->key_count * sizeof(guint64)) == 0;
}

dg_expr_value evaluate(const dg_state *st, guint16 first, guint16 count)
{
    return dg_expr_eval(&st->p->exprs[first], count, &message_readers, st, st->instance);
}

/* The probe of learn `index`'s entry: its keys as the learner (lookup FALSE)
 * or a reader computes them, in keys[]; FALSE when one is undefined. */
gboolean probe_of(const dg_state *st, guint16 index, gboolean lookup, guint64 *keys, entry *probe)
{
    const dg_learn *l = &st->p->learns[index];
    memset(probe, 0, sizeof *probe);
    if (l->keys_of) index = (guint16)(l->keys_of - 1); /* a reader's keys: the entries are its learn's */
    probe->learn = index;
    probe->key_count = l->key_count;
    probe->keys = keys;
    clear_address(&probe->src);
    guint32 h = 2166136261u ^ index;
    for (guint16 i = 0; i < l->key_count; i++) {
        const dg_learn_key *k = &st->p->learn_keys[l->key_first + i];
        dg_expr_value v = lookup && k->lookup_count ? evaluate(st, k->lookup_first, k->lookup_count)
                                                    : evaluate(st, k->value_first, k->value_count);
        if (!v.defined) return FALSE;
        keys[i] = (guint64)v.integer;
        h = hash_mix(h, keys[i]);
    }
    if (l->by_sender) {
        probe->src = st->pinfo->src; /* shallow: copied when the entry is made */
        probe->port = st->pinfo->srcport;
        h = hash_mix(h, probe->port);
        h = add_address_to_hash(h, &probe->src);
    }
    probe->hash = h;
    return TRUE;
}

/* Whether (frame, message) comes before the value `t` was taught by. */
gboolean before(guint32 frame, guint32 message, const taught *t)
{
    return frame < t->frame || (frame == t->frame && message < t->message);
}

/* The number of values taught before (frame, message): the last of them is
 * the one a reader there sees. */
guint taught_before(const entry *e, guint32 frame, guint32 message)
{
    guint low = 0, high = e->count;
    while (low < high) {
        guint mid = low + (high - low) / 2;
        if (before(frame, message, &e->values[mid]) ||
            (e->values[mid].frame == frame && e->values[mid].message == message))
            high = mid;
        else
            low = mid + 1;
    }
    return low;
}

entry *new_entry(const entry *probe)
{
    entry *e = wmem_new0(wmem_file_scope(), entry);
    *e = *probe;
    e->keys = (guint64 *)wmem_memdup(wmem_file_scope(), probe->keys, probe->key_count * sizeof(guint64));
    copy_address_wmem(wmem_file_scope(), &e->src, &probe->src);
    e->values = NULL;
    e->count = e->capacity = 0;
    wmem_map_insert(entries, e, e);
    return e;
}

/* Records `value` as taught by (frame, message), in order: the first pass
 * meets the frames in order, so it is nearly always appended. Its message
 * teaching again replaces what it taught; the value the entry already had
 * is not recorded again. */
void teach(entry *e, guint32 frame, guint32 message, guint64 value)
{
    guint at = taught_before(e, frame, message);
    if (at < e->count && e->values[at].frame == frame && e->values[at].message == message) {
        e->values[at].value = value;
        return;
    }
    if (at > 0 && e->values[at - 1].value == value) return;
    if (e->count == e->capacity) {
        e->capacity = e->capacity ? 2 * e->capacity : 2;
        e->values = (taught *)wmem_realloc(wmem_file_scope(), e->values, e->capacity * sizeof(taught));
    }
    memmove(&e->values[at + 1], &e->values[at], (e->count - at) * sizeof(taught));
    e->values[at] = {frame, message, value};
    e->count++;
}

} // namespace

namespace dg_rt {

gboolean read_learned(const void *context, gint16 index, guint64 *value)
{
    const dg_state *st = (const dg_state *)context;
    if (!entries || index < 0 || index >= st->p->learn_count) return FALSE;
    guint64 keys[DG_MAX_LEARN_KEYS];
    entry probe;
    if (st->p->learns[index].key_count > G_N_ELEMENTS(keys)) return FALSE;
    if (!probe_of(st, (guint16)index, TRUE, keys, &probe)) return FALSE;
    const entry *e = (const entry *)wmem_map_lookup(entries, &probe);
    if (!e) return FALSE;
    guint n = taught_before(e, st->pinfo->num, st->message);
    if (n == 0) return FALSE;
    *value = e->values[n - 1].value;
    return TRUE;
}

void learn_values(dg_state *st, const dg_node *n)
{
    if (PINFO_FD_VISITED(st->pinfo) || !entries) return; /* later passes read what the first one learned */
    for (guint16 i = 0; i < n->extra->learn_count; i++) {
        const guint16 index = (guint16)(n->extra->learn_first + i);
        const dg_learn *l = &st->p->learns[index];
        if (l->if_count) {
            dg_expr_value holds = evaluate(st, l->if_first, l->if_count);
            if (!holds.defined || holds.integer == 0) continue;
        }
        dg_expr_value v = evaluate(st, l->value_first, l->value_count);
        guint64 keys[DG_MAX_LEARN_KEYS];
        entry probe;
        if (!v.defined || l->key_count > G_N_ELEMENTS(keys) || !probe_of(st, index, FALSE, keys, &probe)) continue;
        entry *e = (entry *)wmem_map_lookup(entries, &probe);
        if (!e) e = new_entry(&probe);
        teach(e, st->pinfo->num, st->message, (guint64)v.integer);
    }
}

void learned_register(const dg_protocol *p)
{
    if (p->learn_count && !entries)
        entries = wmem_map_new_autoreset(wmem_epan_scope(), wmem_file_scope(), entry_hash, entry_equal);
}

} // namespace dg_rt

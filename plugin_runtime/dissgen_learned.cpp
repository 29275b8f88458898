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
 *
 * A key with a span teaches windows: the learner's key value starts a range
 * of span keys (counted modulo 2^64, so that keys from unsigned 8-byte fields
 * and negative ones are alike). A window is its range, or with the key's id
 * what the id names (a slave's FMMU), which a later teaching moves or, with
 * a span of 0, removes. Each teaching of a window is a record (range, value,
 * when) that holds until the window's next teaching; the records of one learn
 * under the same other keys form a group, kept by start. A reader's key
 * finds, among the group's records that hold it at the reader's place, the
 * one taught latest (EtherCAT: a logical address finds the slave whose FMMU
 * holds it). Each teaching has its number in the first pass, so that
 * "latest" holds within one message too.
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

/* One teaching of a window: its range (span 0: the window removed), its
 * value, when, and until when it holds: the window's next teaching, from
 * whose message on readers see that one (G_MAXUINT32: still). */
typedef struct record {
    guint64 start, span;
    guint64 value, order;
    guint32 frame, message;
    guint32 until_frame, until_message;
} record;

/* Who an entry, window or group belongs to: a learn, its keys and, with
 * sender="yes", the sender; with conversation="yes", both ends, the lower
 * (address, then port) as src. First member of each, so one hash serves all. */
typedef struct identity {
    guint32 hash;
    guint16 learn;
    guint16 key_count;
    guint32 port, dst_port;
    address src, dst;
    guint64 *keys;
} identity;

/* What one <learn> without a span learned under one set of keys. */
typedef struct entry {
    identity id;
    taught *values; /* in the order of their messages */
    guint count, capacity;
} entry;

/* A window of a learn with a span: its range, or what its id names. */
typedef struct learned_window {
    identity id;
    record *latest;
} learned_window;

/* The records of the windows one learn with a span learned under one set of
 * its other keys, by their start. */
typedef struct window_group {
    identity id;
    record **ranges;
    guint range_count, range_capacity;
    guint64 widest; /* the longest of its ranges */
} window_group;

/* Per capture: the entries, windows and groups (wmem_file_scope, emptied
 * when a file closes). */
wmem_map_t *entries = NULL;
wmem_map_t *windows = NULL;
wmem_map_t *groups = NULL;
guint64 teachings = 0; /* numbers the teachings, in the first pass's order */

guint identity_hash(gconstpointer k) { return ((const identity *)k)->hash; }

gboolean identity_equal(gconstpointer a, gconstpointer b)
{
    const identity *x = (const identity *)a, *y = (const identity *)b;
    return x->hash == y->hash && x->learn == y->learn && x->key_count == y->key_count && x->port == y->port &&
           x->dst_port == y->dst_port && addresses_equal(&x->src, &y->src) && addresses_equal(&x->dst, &y->dst) &&
           (x->key_count == 0 || memcmp(x->keys, y->keys, x->key_count * sizeof(guint64)) == 0);
}

dg_expr_value evaluate(const dg_state *st, guint16 first, guint16 count)
{
    return dg_expr_eval(&st->p->exprs[first], count, &message_readers, st, st->instance);
}

/* The key of learn `l` with a span (a window), or -1; a reader's keys have
 * their learn's. */
gint span_key(const dg_protocol *p, const dg_learn *l)
{
    if (l->keys_of) l = &p->learns[l->keys_of - 1];
    for (guint16 i = 0; i < l->key_count; i++)
        if (p->learn_keys[l->key_first + i].span_count) return i;
    return -1;
}

/* The keys of learn `index` as the learner (lookup FALSE) or a reader
 * computes them, in keys[]; FALSE when one is undefined. */
gboolean keys_of(const dg_state *st, const dg_learn *l, gboolean lookup, guint64 *keys)
{
    for (guint16 i = 0; i < l->key_count; i++) {
        const dg_learn_key *k = &st->p->learn_keys[l->key_first + i];
        dg_expr_value v = lookup && k->lookup_count ? evaluate(st, k->lookup_first, k->lookup_count)
                                                    : evaluate(st, k->value_first, k->value_count);
        if (!v.defined) return FALSE;
        keys[i] = (guint64)v.integer;
    }
    return TRUE;
}

/* Whether the (address, port) end a comes before end b. */
gboolean end_before(const address *a, guint32 a_port, const address *b, guint32 b_port)
{
    const int by_address = cmp_address(a, b);
    return by_address < 0 || (by_address == 0 && a_port < b_port);
}

/* The transport's ends that are part of learn l's identity (shallow: copied
 * when the entry is made). */
void ends_of(const dg_state *st, const dg_learn *l, identity *probe)
{
    const packet_info *pinfo = st->pinfo;
    if (l->ends == DG_LEARN_ENDS_NONE) return;
    probe->src = pinfo->src;
    probe->port = pinfo->srcport;
    if (l->ends != DG_LEARN_ENDS_CONVERSATION) return;
    probe->dst = pinfo->dst;
    probe->dst_port = pinfo->destport;
    if (end_before(&probe->dst, probe->dst_port, &probe->src, probe->port)) {
        probe->src = pinfo->dst;
        probe->port = pinfo->destport;
        probe->dst = pinfo->src;
        probe->dst_port = pinfo->srcport;
    }
}

/* The identity of the entry, window or group of learn `index` under
 * keys[0 .. count) (and the transport's ends its `ends` names). */
void probe_of(const dg_state *st, guint16 index, guint64 *keys, guint16 count, identity *probe)
{
    const dg_learn *l = &st->p->learns[index];
    memset(probe, 0, sizeof *probe);
    if (l->keys_of) index = (guint16)(l->keys_of - 1); /* a reader's keys: the entries are its learn's */
    probe->learn = index;
    probe->key_count = count;
    probe->keys = keys;
    clear_address(&probe->src);
    clear_address(&probe->dst);
    ends_of(st, l, probe);
    guint32 h = 2166136261u ^ index;
    for (guint16 i = 0; i < count; i++) h = hash_mix(h, keys[i]);
    if (probe->src.type != AT_NONE) h = add_address_to_hash(hash_mix(h, probe->port), &probe->src);
    if (probe->dst.type != AT_NONE) h = add_address_to_hash(hash_mix(h, probe->dst_port), &probe->dst);
    probe->hash = h;
}

/* The keys without the spanned one, at keys[0 .. count - 1): a group's. */
void drop_key(guint64 *keys, guint16 count, gint spanned)
{
    memmove(&keys[spanned], &keys[spanned + 1], (count - spanned - 1) * sizeof(guint64));
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

/* A new T (entry, window or group) of identity `probe`, in `map`. */
template <typename T> T *new_keyed(wmem_map_t *map, const identity *probe)
{
    T *made = wmem_new0(wmem_file_scope(), T);
    identity *id = &made->id;
    *id = *probe;
    id->keys = (guint64 *)wmem_memdup(wmem_file_scope(), probe->keys, probe->key_count * sizeof(guint64));
    copy_address_wmem(wmem_file_scope(), &id->src, &probe->src);
    copy_address_wmem(wmem_file_scope(), &id->dst, &probe->dst);
    wmem_map_insert(map, id, made);
    return made;
}

gboolean holds(const record *r, guint64 key) { return key - r->start < r->span; }

/* Whether record r holds at (frame, message): taught before it, and the
 * window not taught again before it. */
gboolean holds_at(const record *r, guint32 frame, guint32 message)
{
    const gboolean taught = r->frame < frame || (r->frame == frame && r->message < message);
    const gboolean kept = frame < r->until_frame || (frame == r->until_frame && message <= r->until_message);
    return taught && kept;
}

/* The number of the group's records that start at or before `key`. */
guint starting_by(const window_group *group, guint64 key)
{
    guint low = 0, high = group->range_count;
    while (low < high) {
        guint mid = low + (high - low) / 2;
        if (group->ranges[mid]->start <= key)
            low = mid + 1;
        else
            high = mid;
    }
    return low;
}

/* Calls visit(record) on each record of `group` that starts less than
 * `reach` below `key` (modulo 2^64): going down from the last one that
 * starts by it, then from the top, for ranges that wrap past 2^64 to it. */
template <typename Visit> void near_ranges(const window_group *group, guint64 key, guint64 reach, Visit visit)
{
    const guint by = starting_by(group, key);
    for (guint i = by; i > 0 && key - group->ranges[i - 1]->start < reach; i--) visit(group->ranges[i - 1]);
    for (guint i = group->range_count; i > by && key - group->ranges[i - 1]->start < reach; i--)
        visit(group->ranges[i - 1]);
}

void add_range(window_group *group, record *r)
{
    if (group->range_count == group->range_capacity) {
        group->range_capacity = group->range_capacity ? 2 * group->range_capacity : 2;
        group->ranges =
            (record **)wmem_realloc(wmem_file_scope(), group->ranges, group->range_capacity * sizeof(record *));
    }
    const guint at = starting_by(group, r->start);
    memmove(&group->ranges[at + 1], &group->ranges[at], (group->range_count - at) * sizeof(record *));
    group->ranges[at] = r;
    group->range_count++;
    group->widest = MAX(group->widest, r->span);
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

/* Whether a record of `group` that still holds and overlaps `r` was taught
 * after it: teaching r's window again, even alike, makes it the one that
 * holds the overlap. The records that overlap r start less than its span
 * plus the widest's below its last key. */
gboolean overtaken(const window_group *group, const record *r)
{
    gboolean found = FALSE;
    near_ranges(group, r->start + r->span - 1, r->span + group->widest - 1, [&](const record *o) {
        if (o != r && o->until_frame == G_MAXUINT32 && o->order > r->order && (holds(o, r->start) || holds(r, o->start)))
            found = TRUE;
    });
    return found;
}

/* Teaches `value` to the window of learn `index` under keys[0 .. key_count)
 * (the spanned key at `spanned`): a new record, unless the window's latest
 * one says the same and nothing taught since overlaps it. With an id, a span
 * of 0 or less removes the window; without one it teaches nothing. */
void teach_window(dg_state *st, guint16 index, guint64 *keys, gint spanned, guint64 value)
{
    const dg_learn *l = &st->p->learns[index];
    const dg_learn_key *k = &st->p->learn_keys[l->key_first + spanned];
    const dg_expr_value span = evaluate(st, k->span_first, k->span_count);
    if (!span.defined) return;
    const guint64 start = keys[spanned];
    const guint64 length = span.integer > 0 ? (guint64)span.integer : 0;
    const guint16 others = (guint16)(l->key_count - 1);
    drop_key(keys, l->key_count, spanned);
    guint16 window_keys = (guint16)(others + 1);
    if (k->id_count) { /* the window is what the id names */
        const dg_expr_value id = evaluate(st, k->id_first, k->id_count);
        if (!id.defined) return;
        keys[others] = (guint64)id.integer;
    } else { /* the window is its range */
        if (!length) return;
        keys[others] = start;
        keys[others + 1] = start + length; /* modulo 2^64 */
        window_keys++;
    }
    identity probe;
    probe_of(st, index, keys, window_keys, &probe);
    learned_window *window = (learned_window *)wmem_map_lookup(windows, &probe);
    record *last = window ? window->latest : NULL;
    if ((!last || !last->span) && !length) return; /* removing a window not there */
    probe_of(st, index, keys, others, &probe);
    window_group *group = (window_group *)wmem_map_lookup(groups, &probe);
    if (last && last->start == start && last->span == length && last->value == value &&
        (!length || !overtaken(group, last)))
        return;
    const guint32 frame = st->pinfo->num, message = st->message;
    record *r = wmem_new(wmem_file_scope(), record);
    *r = {start, length, value, ++teachings, frame, message, G_MAXUINT32, G_MAXUINT32};
    if (last) {
        last->until_frame = frame;
        last->until_message = message;
    }
    if (!group) group = new_keyed<window_group>(groups, &probe);
    if (length) add_range(group, r);
    if (!window) {
        probe_of(st, index, keys, window_keys, &probe);
        window = new_keyed<learned_window>(windows, &probe);
    }
    window->latest = r;
}

} // namespace

namespace dg_rt {

gboolean read_learned(const void *context, gint16 index, guint64 *value)
{
    const dg_state *st = (const dg_state *)context;
    if (!entries || index < 0 || index >= st->p->learn_count) return FALSE;
    const dg_learn *l = &st->p->learns[index];
    guint64 keys[DG_MAX_LEARN_KEYS];
    if (l->key_count > G_N_ELEMENTS(keys) || !keys_of(st, l, TRUE, keys)) return FALSE;
    const gint spanned = span_key(st->p, l);
    identity probe;
    if (spanned < 0) {
        probe_of(st, (guint16)index, keys, l->key_count, &probe);
        const entry *e = (const entry *)wmem_map_lookup(entries, &probe);
        if (!e) return FALSE;
        guint n = taught_before(e, st->pinfo->num, st->message);
        if (n == 0) return FALSE;
        *value = e->values[n - 1].value;
        return TRUE;
    }
    /* the latest record that holds the key at this message: one that starts
     * less than the widest's span below it */
    const guint64 key = keys[spanned];
    drop_key(keys, l->key_count, spanned);
    probe_of(st, (guint16)index, keys, (guint16)(l->key_count - 1), &probe);
    const window_group *group = (const window_group *)wmem_map_lookup(groups, &probe);
    if (!group) return FALSE;
    const record *latest = NULL;
    near_ranges(group, key, group->widest, [&](const record *r) {
        if (holds(r, key) && holds_at(r, st->pinfo->num, st->message) && (!latest || r->order > latest->order))
            latest = r;
    });
    if (!latest) return FALSE;
    *value = latest->value;
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
        guint64 keys[DG_MAX_LEARN_KEYS + 1]; /* a window's range: its start and end at the end */
        if (!v.defined || l->key_count > DG_MAX_LEARN_KEYS || !keys_of(st, l, FALSE, keys)) continue;
        const gint spanned = span_key(st->p, l);
        if (spanned >= 0) {
            teach_window(st, index, keys, spanned, (guint64)v.integer);
            continue;
        }
        identity probe;
        probe_of(st, index, keys, l->key_count, &probe);
        entry *e = (entry *)wmem_map_lookup(entries, &probe);
        teach(e ? e : new_keyed<entry>(entries, &probe), st->pinfo->num, st->message, (guint64)v.integer);
    }
}

void learned_register(const dg_protocol *p)
{
    if (p->learn_count && !entries) {
        entries = wmem_map_new_autoreset(wmem_epan_scope(), wmem_file_scope(), identity_hash, identity_equal);
        windows = wmem_map_new_autoreset(wmem_epan_scope(), wmem_file_scope(), identity_hash, identity_equal);
        groups = wmem_map_new_autoreset(wmem_epan_scope(), wmem_file_scope(), identity_hash, identity_equal);
    }
}

} // namespace dg_rt

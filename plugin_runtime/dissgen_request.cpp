// SPDX-License-Identifier: GPL-2.0-or-later
/* request{Name}: computed values of a response that read fields of its
 * paired request (dg_request_context in dissgen_runtime.h).
 *
 * The pairing links a response to its request only after the response was
 * decoded; a response that reads its request needs it before. So:
 *  - a request keeps the values of the fields responses read in its
 *    transaction (wmem_file_scope), on the first pass, once it is paired;
 *  - on the first pass, before the message is decoded, its key fields are
 *    read at their fixed offsets; or, when they are not at fixed offsets,
 *    the walk's key values (DG_KEY) are taken when a value first reads the
 *    request (the validator puts every key field before such values), or at
 *    the end of the walk when none did. The request it would answer (its
 *    key's oldest one still waiting, or for a copy of the key's last response
 *    the one that response answered) is looked up, always before the message
 *    itself is paired; what that request kept (or that there is none) is
 *    saved for the frame (p_add_proto_data), and later passes (tshark -2,
 *    the GUI in any order) read only that: every pass decodes the message
 *    alike.
 * A message whose values read a request that is not known (not captured,
 * too short to hold its keys) shows them undefined and says so once
 * (P.expert.no_request_context); a request itself, or one that expects no
 * response (<unanswered>), has no request: its values are undefined, with
 * no note.
 */
#include "dissgen_state.h"

#include <epan/proto_data.h>

using namespace dg_rt;

namespace {

/* Key of the per-frame request values (p_add_proto_data), plus the message number. */
const guint32 frame_key = 0x72716378u; /* "rqcx" */

/* Saved for a message that found no request: a frame without it was not
 * decoded on the first pass. */
const dg_request_values no_request = {0, NULL, NULL, NULL};

expert_field ei_no_request_context = EI_INIT;

/* The key values at their fixed offsets, FALSE when the message is too short. */
gboolean read_keys(const dg_state *st, guint64 *keys)
{
    const dg_request_context *rc = st->p->request_context;
    for (guint16 i = 0; i < rc->key_count; i++) {
        const dg_fixed_field *k = &rc->keys[i];
        if ((gint64)k->offset + k->length > (gint64)st->packet_end) return FALSE;
        guint64 v = read_uint(st->tvb, (gint)k->offset, k->length, k->little ? ENC_LITTLE_ENDIAN : ENC_BIG_ENDIAN);
        keys[i] = k->bits ? bit_field(v, k->shift, k->bits) : v;
    }
    return TRUE;
}

/* Whether the message may be a response, before it is decoded: a message
 * that goes to the hooked port is a request and answers nothing, unless the
 * pairing's <request> field says which it is (known only once decoded). */
gboolean may_answer(const dg_state *st)
{
    return st->direction != DG_DIR_REQUEST || st->p->pairing->request;
}

/* Whether the message is known to be a request where a value reads its
 * request: by the transport, or by the pairing's <request> field decoded
 * before the value (not decoded yet: it may still be a response). */
gboolean is_request(const dg_state *st)
{
    const dg_request_role *r = st->p->pairing->request;
    if (!r) return st->direction == DG_DIR_REQUEST;
    return st->present[r->slot] && role_holds(st, r);
}

/* The direction the pairing will give the message if it answers a request:
 * a response, when a <request> field will say so; else the transport's. */
guint8 answer_direction(const dg_state *st)
{
    return st->p->pairing->request ? (guint8)DG_DIR_RESPONSE : st->direction;
}

/* First pass: what the waiting request of this message's key kept. */
const dg_request_values *find_request(const dg_state *st)
{
    if (!may_answer(st)) return NULL;
    const dg_request_context *rc = st->p->request_context;
    guint64 *keys = wmem_alloc_array(st->pinfo->pool, guint64, rc->key_count);
    if (!read_keys(st, keys)) return NULL;
    return dg_pairing_request_of(keys, rc->key_count, st->tvb, st->pinfo, answer_direction(st));
}

/* Saves what the first pass found for the message, for every later pass. */
void save(const dg_state *st, const dg_request_values *v)
{
    p_add_proto_data(wmem_file_scope(), st->pinfo, *st->p->proto, frame_key + st->message,
                     (void *)(v ? v : &no_request));
}

/* First pass, keys from the walk: the waiting request of the keys decoded so
 * far (none decoded: the message is not paired, and answers nothing). */
void find_from_walk(const dg_state *st)
{
    st->request_pending = FALSE;
    st->request = st->key_count ? dg_pairing_request_of(st->keys, st->key_count, st->tvb, st->pinfo,
                                                        answer_direction(st))
                                : NULL;
    save(st, st->request);
}

/* A request's kept values, from the slots of the message just decoded. */
const dg_request_values *keep_values(const dg_state *st)
{
    const dg_request_context *rc = st->p->request_context;
    dg_request_values *v = wmem_new(wmem_file_scope(), dg_request_values);
    v->count = rc->kept_count;
    v->values = wmem_alloc_array(wmem_file_scope(), guint64, rc->kept_count);
    v->present = (guint8 *)wmem_alloc0(wmem_file_scope(), rc->kept_count);
    v->tables = NULL;
    for (guint16 i = 0; i < rc->kept_count; i++) {
        const gint16 slot = rc->slots[i];
        v->present[i] = st->present[slot];
        v->values[i] = st->present[slot] ? st->slots[slot].value : 0;
    }
    if (rc->by_position) {
        dg_request_table *tables = wmem_alloc0_array(wmem_file_scope(), dg_request_table, rc->kept_count);
        for (guint16 i = 0; i < rc->kept_count; i++) {
            const dg_table *t = rc->by_position[i] && st->tables ? &st->tables[rc->slots[i]] : NULL;
            if (!t || !t->count) continue;
            tables[i].count = t->count;
            tables[i].values = (const guint64 *)wmem_memdup(wmem_file_scope(), t->values, t->count * sizeof(guint64));
            tables[i].present = (const guint8 *)wmem_memdup(wmem_file_scope(), t->present, t->count);
        }
        v->tables = tables;
    }
    return v;
}

} // namespace

namespace dg_rt {

void request_begin(dg_state *st)
{
    const guint message = st->message;
    const dg_request_values *v;
    if (PINFO_FD_VISITED(st->pinfo)) {
        v = (const dg_request_values *)p_get_proto_data(wmem_file_scope(), st->pinfo, *st->p->proto,
                                                        frame_key + message);
    } else if (st->p->request_context->key_count == 0 && may_answer(st)) {
        st->request_pending = TRUE; /* find_from_walk(), once the keys are decoded */
        v = NULL;
    } else {
        v = find_request(st);
        save(st, v);
    }
    st->request = v && v != &no_request ? v : NULL;
}

void request_walked(dg_state *st)
{
    find_from_walk(st);
}

void request_end(dg_state *st, const dg_frame_pairing *fp, proto_tree *tree)
{
    if (!PINFO_FD_VISITED(st->pinfo) && fp && fp->role == DG_ROLE_REQUEST && fp->txn && !fp->txn->values)
        fp->txn->values = keep_values(st);
    /* Told with the whole message known: a <request> or <unanswered> field
     * decoded after the value that missed may make it a request or a
     * message that expects no response, which miss no request. */
    if (st->request_missed && takes_part_in_pairing(st, st->p->pairing->unanswered) && !is_request(st))
        proto_tree_add_expert(tree, st->pinfo, &ei_no_request_context, st->tvb, 0, 0);
}

gboolean read_request(const void *context, gint16 index, guint64 *value)
{
    const dg_state *st = (const dg_state *)context;
    if (!takes_part_in_pairing(st, st->p->pairing->unanswered)) return FALSE; /* no request, and none missing */
    if (is_request(st)) { /* a request answers none: none is missing */
        st->request_none = TRUE;
        return FALSE;
    }
    if (st->request_pending) find_from_walk(st);
    if (!st->request) {
        st->request_missed = TRUE;
        return FALSE;
    }
    if (index < 0 || (guint)index >= st->request->count) return FALSE;
    const dg_request_context *rc = st->p->request_context;
    if (rc->by_position && rc->by_position[index]) {
        /* by position: the request's instance of the reader's own instance number */
        const dg_request_table *t = &st->request->tables[index];
        if (st->instance >= t->count || !t->present[st->instance]) return FALSE;
        *value = t->values[st->instance];
        return TRUE;
    }
    if (!st->request->present[index]) return FALSE;
    *value = st->request->values[index];
    return TRUE;
}

} // namespace dg_rt

extern "C" void dg_request_register(const dg_protocol *p, expert_module_t *experts)
{
    static ei_register_info ei[] = {DG_REQUEST_CONTEXT_EXPERTS(DG_EI_ROW)};
    static const char *const names[] = {DG_REQUEST_CONTEXT_EXPERTS(DG_EXPERT_NAME)};
    dg_name_experts(ei, names, G_N_ELEMENTS(ei), p->filter);
    expert_register_field_array(experts, ei, (int)G_N_ELEMENTS(ei));
}

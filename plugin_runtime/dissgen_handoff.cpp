// SPDX-License-Identifier: GPL-2.0-or-later
/* Where bytes leave the table walk: a leaf handed to another dissector
 * (dissector="NAME"), fragments reassembled across frames (reassemble-*),
 * and stream transports (pdulength), where TCP segments are cut into
 * messages before the walk sees them.
 *
 * The other dissector may throw: its exceptions (longjmps, which skip C++
 * destructors) are caught here and end its own tree, not the walk. Like the
 * whole runtime: no non-trivial C++ object, memory from pinfo->pool.
 */
#include "dissgen_state.h"

using namespace dg_rt;

namespace {

/* Per node: the handle its dissector= names (NULL: absent from this Wireshark,
 * the bytes are shown raw), and the name of its reassembled data source.
 * Filled at handoff; one protocol per plugin, like the statistics'. */
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

/* --- reassembly ---------------------------------------------------------- */

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

} // namespace

/* --- hand-off ------------------------------------------------------------ */

void dg_rt::dissect_handoff(dg_state *st, const dg_node *n, proto_tree *tree, gint offset, gint len)
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

/* A name this Wireshark does not have is reported once, here, and that
 * leaf's bytes are shown raw. */
void dg_rt::find_handoff_dissectors(const dg_protocol *p)
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

/* --- stream transports --------------------------------------------------- */

gint64 dg_rt::stream_message_length(const dg_protocol *p, tvbuff_t *tvb, int offset, guint *header)
{
    const dg_node *n = &p->nodes[p->pdu_node];
    const gint at = offset + (gint)p->pdu_offset;
    if (n->show == DG_SHOW_VARINT) {
        const gint have = MIN(tvb_captured_length_remaining(tvb, at), DG_VARINT_MOST_BYTES);
        guint64 value = 0;
        const guint got = have > 0 ? tvb_get_varint(tvb, (guint)at, (guint)have, &value, ENC_VARINT_PROTOBUF) : 0;
        if (!got) return have == DG_VARINT_MOST_BYTES ? DG_STREAM_LENGTH_BAD : DG_STREAM_LENGTH_MORE;
        if (!dg_read_varint(tvb, at, (gint)got, &value)) return DG_STREAM_LENGTH_BAD; /* more than 64 bits */
        *header = p->pdu_offset + got;
        return (gint64)MIN(value, (guint64)G_MAXINT32) + *header + p->pdu_add;
    }
    guint64 value = read_uint(tvb, at, n->length, encoding_of(n));
    if (n->flags & DG_GROUP) value = bit_field(value, n->shift, n->bits);
    *header = stream_header_length(p);
    return (gint64)MIN(value, (guint64)G_MAXINT32) + p->pdu_add;
}

extern "C" guint dg_message_length(packet_info *pinfo, tvbuff_t *tvb, int offset, void *data)
{
    const dg_protocol *p = (const dg_protocol *)data;
    guint header = 0;
    const gint64 total = stream_message_length(p, tvb, offset, &header);
    const guint rest = (guint)tvb_reported_length_remaining(tvb, offset);
    /* A varint length whose last byte is in the next segment: one more (0). */
    if (total == DG_STREAM_LENGTH_MORE) return pinfo->can_desegment ? 0 : rest;
    /* A length shorter than the bytes up to the end of the length field is
     * malformed (and so is a varint that never ends): that message takes the
     * rest of the segment, where the walk shows its header and says so at the
     * length field (dg_dissect), rather than messages being made up from
     * what follows. */
    if (total < (gint64)header) return rest;
    return (guint)MIN(total, (gint64)G_MAXINT32);
}

namespace {

int dissect_message(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data)
{
    return dg_dissect((const dg_protocol *)data, tvb, pinfo, tree);
}

} // namespace

int dg_dissect_stream(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    tcp_dissect_pdus(tvb, pinfo, tree, TRUE, stream_header_length(p), dg_message_length, dissect_message, (void *)p);
    return (int)tvb_captured_length(tvb);
}

// SPDX-License-Identifier: GPL-2.0-or-later
/* valid="LIST" fields and <heuristic> registration: see dissgen_validity.h. */
#include "dissgen_validity.h"
#include "dissgen_values.h"

#include <epan/conversation.h>
#include <epan/dissectors/packet-tcp.h>

#include <string.h>

namespace {

/* The field's value; its bytes are known to be there. */
guint64 field_value(const dg_valid_field *f, tvbuff_t *tvb, gint at)
{
    guint64 value = 0;
    for (guint i = 0; i < f->length; i++) {
        guint8 byte = dg_tvb_get_uint8(tvb, at + (gint)(f->little ? f->length - 1 - i : i));
        value = (value << 8) | byte;
    }
    if (f->bits > 0 && f->bits < 64) value = (value >> f->shift) & ((G_GUINT64_CONSTANT(1) << f->bits) - 1);
    return value;
}

/* The bytes at the start of a message that the test reads (at least 1). */
gint tested_length(const dg_validity *v)
{
    gint64 bytes = 1;
    for (guint16 i = 0; i < v->field_count; i++) bytes = MAX(bytes, (gint64)v->fields[i].offset + v->fields[i].length);
    return (gint)MIN(bytes, (gint64)v->header_length);
}

/* tcp_dissect_pdus: the length of a message that passes the test; a message
 * that fails takes the rest of the segment, which is then shown as data,
 * instead of a length that would hold back the messages after it. The test
 * comes first, as soon as the bytes it reads are there: a short tail that
 * fails it does not wait for the next segment, which would be read as the
 * rest of its header. */
guint valid_message_length(packet_info *pinfo, tvbuff_t *tvb, int offset, void *data)
{
    const dg_validity *v = (const dg_validity *)data;
    const gint available = tvb_captured_length_remaining(tvb, offset);
    const guint rest = (guint)tvb_reported_length_remaining(tvb, offset);
    if (!dg_valid_at(v, tvb, pinfo, offset, available)) return rest;
    if (available < (gint)v->header_length) return pinfo->can_desegment ? 0 : rest; /* 0: one more segment */
    guint length = dg_message_length(pinfo, tvb, offset, (void *)v->p);
    if (length == 0) return 0; /* a varint length whose last byte is in the next segment */
    if (dg_valid_at(v, tvb, pinfo, offset, MIN(available, (gint)MIN(length, (guint)G_MAXINT32)))) return length;
    return rest;
}

int dissect_valid_message(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data)
{
    const dg_validity *v = (const dg_validity *)data;
    if (dg_valid_at(v, tvb, pinfo, 0, (gint)tvb_captured_length(tvb))) return dg_dissect(v->p, tvb, pinfo, tree);
    return call_data_dissector(tvb, pinfo, tree);
}

/* Per capture: a conversation (its conversation_t) -> the port its opener
 * sent its first message to, for conversations a heuristic found messages in. */
wmem_map_t *opened_to;

/* The port of the service a heuristic found this message's conversation
 * talking to, so that its messages get a direction as through a port hook (to
 * that port a request, from it a response): over TCP the port the SYN went
 * to; otherwise the port this protocol's first message of the conversation
 * went to (its sender opened the conversation). 0 when it cannot tell. */
guint32 service_port(packet_info *pinfo)
{
    if (pinfo->ptype != PT_TCP && pinfo->ptype != PT_UDP) return 0;
    conversation_t *conv = find_or_create_conversation(pinfo);
    if (pinfo->ptype == PT_TCP) {
        struct tcp_analysis *tcpd = get_tcp_conversation_data(conv, pinfo);
        if (tcpd && tcpd->server_port) return tcpd->server_port;
    }
    if (!opened_to) opened_to = wmem_map_new_autoreset(wmem_epan_scope(), wmem_file_scope(), g_direct_hash, g_direct_equal);
    gpointer port = wmem_map_lookup(opened_to, conv);
    if (port) return GPOINTER_TO_UINT(port);
    if (PINFO_FD_VISITED(pinfo) || !pinfo->destport) return 0; /* the first pass saw no message of ours here */
    wmem_map_insert(opened_to, conv, GUINT_TO_POINTER(pinfo->destport));
    return pinfo->destport;
}

/* A stream's segment: 0 when it does not start with a message of ours. */
int dissect_valid_segment(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    gint have = (gint)tvb_captured_length(tvb);
    const gint tested = tested_length(v);
    /* Too few bytes to tell: only reassembly can bring the rest of what the test reads. */
    if (have >= tested ? !dg_valid_at(v, tvb, pinfo, 0, have) : !pinfo->can_desegment) return 0;
    tcp_dissect_pdus(tvb, pinfo, tree, TRUE, (guint)tested, valid_message_length, dissect_valid_message, (void *)v);
    return have;
}

} /* namespace */

extern "C" {

gboolean dg_valid_at(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, gint offset, gint available)
{
    for (guint16 i = 0; i < v->field_count; i++) {
        const dg_valid_field *f = &v->fields[i];
        if (f->hook_count && !dg_rt::in_ranges(v->ranges, f->hook_first, f->hook_count, pinfo->match_uint)) continue;
        if ((gint64)f->offset + f->length > (gint64)available) return FALSE;
        if (!dg_rt::in_ranges(v->ranges, f->in_first, f->in_count, field_value(f, tvb, offset + (gint)f->offset))) return FALSE;
    }
    return TRUE;
}

int dg_valid_dissect(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data)
{
    if (!dg_valid_at(v, tvb, pinfo, 0, (gint)tvb_captured_length(tvb))) return dg_displaced_dissect(tvb, pinfo, tree, data);
    return dg_dissect(v->p, tvb, pinfo, tree);
}

int dg_valid_dissect_stream(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data)
{
    const int taken = dissect_valid_segment(v, tvb, pinfo, tree);
    return taken ? taken : dg_displaced_dissect(tvb, pinfo, tree, data);
}

gboolean dg_valid_heuristic(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    if (!dg_valid_at(v, tvb, pinfo, 0, (gint)tvb_captured_length(tvb))) return FALSE;
    /* As a port hook would: the message's direction comes from the service's port. */
    const guint32 hooked = pinfo->match_uint, port = service_port(pinfo);
    if (port) pinfo->match_uint = port;
    if (v->p->pdu_node >= 0 && pinfo->ptype == PT_TCP)
        dissect_valid_segment(v, tvb, pinfo, tree);
    else
        dg_dissect(v->p, tvb, pinfo, tree);
    pinfo->match_uint = hooked;
    return TRUE;
}

void dg_validity_handoff(const dg_validity *v)
{
    if (*v->p->proto == -1) return; /* not registered: its names were taken */
    for (guint16 i = 0; i < v->heuristic_count; i++) {
        const dg_heuristic *h = &v->heuristics[i];
        if (!find_heur_dissector_list(h->list)) {
            ws_log("dissgen", LOG_LEVEL_WARNING,
                   "%s: this Wireshark has no heuristic list \"%s\"; the protocol is not looked for there",
                   v->p->name, h->list);
            continue;
        }
        if (find_heur_dissector_by_unique_short_name(h->short_name)) {
            ws_log("dissgen", LOG_LEVEL_WARNING, "%s: the heuristic name \"%s\" is taken; this one is not registered",
                   v->p->name, h->short_name);
            continue;
        }
        heur_dissector_add(h->list, v->heuristic, h->display_name, h->short_name, *v->p->proto,
                           h->enabled ? HEURISTIC_ENABLE : HEURISTIC_DISABLE);
    }
}

} /* extern "C" */

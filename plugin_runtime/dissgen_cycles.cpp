// SPDX-License-Identifier: GPL-2.0-or-later
/* Cycles of any protocol (dissgen_cycles.h; the manual, "Cycles of any
 * protocol"), decided on the first pass from what came before each message:
 *
 *  - A message belongs to a stream when it holds a value of the signature
 *    fields, every <only> test held and no <never> test did. Its stream is
 *    the signature's values in decoding order (and, with sender="yes", the
 *    sender's address and port; with sender="connection", the receiver's
 *    too: each side of each connection its own count); a field of text, an
 *    address or bytes is compared by its bytes, which the stream keeps (its
 *    value is their hash).
 *  - With a sequence count of range R (2^bits, or wrap="R": 0 .. R - 1),
 *    from the stream's second message on, the step d = (count - previous
 *    count) mod R says: d = 0, the previous message again (a duplicate:
 *    P.cycle.duplicate, not timed); 1 <= d <= R / 2, d - 1 messages
 *    lost right before this one (P.cycle.lost); a larger d, the count went
 *    back (a restart, or a message overtaken): nothing lost. A message
 *    without its count (the field not decoded, or with wrap= a count of R or
 *    more) is timed as one without, and the stream's next count is its
 *    first again: what came between is not known.
 *  - With lost="period" (no count), a cycle's period rounded to n >= 2 whole
 *    nominal periods means n - 1 messages lost right before this one; more
 *    than max_gap_periods is a pause: nothing lost, not regular.
 *  - A period is the time since the stream's previous message (duplicates
 *    aside). It is regular when it is above 0 and no message was lost and
 *    the count did not go back in between.
 *  - A stream becomes a cycle with its first `window` regular periods in a
 *    row, all within half of their median either way: the message that
 *    completes the window is the cycle's first marked one, and every later
 *    message of the stream is in the cycle. Periods are kept in 64-bit ns:
 *    a heartbeat of a minute is a cycle too.
 *  - A marked message shows its period; a regular one joins the cycle's
 *    periods and has a jitter: the period minus the cycle's nominal period,
 *    the median (the lower of the two middle values for an even count) of
 *    its regular periods so far, the window's and this one included.
 *  - With requests="yes" only the pairing's requests are in streams, and a
 *    period is regular only when the stream's previous request was answered
 *    before this one was sent (not a retry after a timeout) and this one is
 *    not a poll: sent less than that round trip after the answer (a master
 *    asking again as soon as it has its answer, as while it waits for a
 *    state). A response adds its round trip to its request's cycle; a
 *    request of a cycle is unanswered when a later one of the cycle was
 *    answered and it was not (those after the latest answered may still be
 *    in flight at the capture's end).
 *
 * Memory: a record per message of a stream that shows something (its
 * cycle, a loss, a duplicate), in wmem_file_scope, and a pointer per frame
 * (the table of first messages' records); per cycle 16 bytes per regular
 * period (the running median and the figures of -z P,cycles) and, with
 * requests="yes", 8 bytes per round trip and per stream its last
 * pending_ring requests.
 */
#include "dissgen_cycles.h"

#include "dissgen_compat.h"
#include "dissgen_pairing.h"
#include "dissgen_state.h"
#include "dissgen_periods.h"
#include "dissgen_values.h"

#include <epan/addr_resolv.h>
#include <epan/charsets.h>
#include <epan/expert.h>
#include <epan/to_str.h>
#include <epan/proto_data.h>
#include <epan/stat_tap_ui.h>
#include <epan/stats_tree.h>
#include <epan/tap.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

namespace {

using namespace dg_periods;

/* p_add_proto_data key of a message's mark: this, or-ed with the message's number in its frame. */
const guint32 mark_key = 0x63790000u;

struct cycle;
struct stream;

/* requests="yes": a stream's request not answered yet. Only a stream's last
 * pending_ring requests are kept: an answer to an older one (a response
 * after many timeouts) is not counted, and its request stays unanswered. */
const guint pending_ring = 16;

struct pending_request {
    guint64 seq;        /* the pairing's number of the request (dg_transaction.seq); 0: a free slot */
    guint32 ordinal;    /* its number among its cycle's messages, from 1; 0: sent before the cycle */
    stream *s;
};

struct stream {
    guint32 hash;
    guint count;
    guint64 *values;
    guint16 *nodes;
    const guint8 **bytes;   /* a text, address or bytes field's own bytes (NULL for a number) */
    guint32 *lengths;
    address src;            /* sender="yes": the sender's address and port; AT_NONE otherwise */
    guint32 port;
    address dst;            /* sender="connection": the receiver's address and port too */
    guint32 dst_port;
    guint32 last_frame;     /* the stream's latest message that was not a duplicate; 0: none yet */
    nstime_t last_time;
    guint64 last_sequence;
    guint64 learned_step; /* step="learned": the count's advance per message, 0 until known */
    gboolean has_sequence;
    guint64 recent[most_window]; /* its last regular periods, a ring */
    guint regular, next_slot;
    guint messages, lost, duplicates;
    cycle *cyc;
    /* requests="yes": its latest request (the pairing's number), the latest
     * answered, when that answer came and its round trip */
    guint64 last_request, last_answered;
    nstime_t last_return, last_rtt;
    pending_request *pending;   /* a ring of pending_ring, from its first request */
    guint next_pending;
};

struct cycle {
    guint32 number;
    const stream *s;
    running_median_of<guint64> periods; /* the regular periods: the window's and the marked messages' */
    u64_vec marked;          /* the marked messages' regular periods, for the quantiles */
    guint frames;            /* marked messages */
    guint32 first_frame;
    double jitter_sum, jitter_squares;
    u64_vec rtts;            /* requests="yes": the round trips of its messages answered, ns */
    guint answered;
    guint32 latest_answered; /* the ordinal of the latest of its messages answered */
    cycle *next;
};

/* What one message of a stream shows, on every pass. */
struct mark {
    guint32 cycle;          /* 0: not (yet) in a cycle */
    guint32 lost;           /* messages lost right before it */
    guint32 duplicate_of;   /* 0: not a duplicate */
    guint8 timed, jittered; /* period_ns, jitter_ns are set */
    gint64 period_ns, jitter_ns;
};

struct capture_state {
    wmem_map_t *streams;    /* stream -> itself */
    /* per frame number, its first message's mark (NULL: none): a table is
     * cheaper than p_add_proto_data, which the later messages of a frame use */
    const mark **by_frame;
    guint32 by_frame_size;
    cycle *first, *last;
    guint32 cycles;
    guint32 last_frame;     /* the last frame the first pass brought here */
    guint messages_timed;   /* and how many of its messages were timed */
    wmem_map_t *pending;    /* requests="yes": a request's number -> its pending_request */
};

const dg_protocol *protocol;
capture_state *capture;

int hf_stream_cycle = -1, hf_stream_period = -1, hf_stream_jitter = -1, hf_stream_lost = -1,
    hf_stream_duplicate = -1;
expert_field ei_stream_lost_expert = EI_INIT, ei_stream_duplicate_expert = EI_INIT;

void capture_init(void) { capture = NULL; }
void capture_cleanup(void) { capture = NULL; /* its memory goes with wmem_file_scope */ }

/* Equal hashes, values and senders, and the same bytes in each field
 * compared by its bytes (a value is only their hash). */
gboolean same_stream(gconstpointer a, gconstpointer b)
{
    const stream *x = (const stream *)a, *y = (const stream *)b;
    if (x->hash != y->hash || x->count != y->count || x->port != y->port || !addresses_equal(&x->src, &y->src) ||
        x->dst_port != y->dst_port || !addresses_equal(&x->dst, &y->dst) ||
        memcmp(x->values, y->values, x->count * sizeof(guint64)) ||
        memcmp(x->nodes, y->nodes, x->count * sizeof(guint16)))
        return FALSE;
    for (guint i = 0; i < x->count; i++)
        if (x->bytes[i] && (x->lengths[i] != y->lengths[i] || memcmp(x->bytes[i], y->bytes[i], x->lengths[i])))
            return FALSE;
    return TRUE;
}

capture_state *current_capture(void)
{
    if (!capture) {
        capture = wmem_new0(wmem_file_scope(), capture_state);
        capture->streams = wmem_map_new(wmem_file_scope(), [](gconstpointer p) { return ((const stream *)p)->hash; },
                                        same_stream);
    }
    return capture;
}

stream *stream_of(capture_state *c, const dg_cycle_input *in, const packet_info *pinfo)
{
    stream probe; /* what the map's hash and equality read, no more */
    probe.count = in->count;
    probe.values = (guint64 *)in->values;
    probe.nodes = (guint16 *)in->nodes;
    probe.bytes = in->bytes;
    probe.lengths = in->lengths;
    clear_address(&probe.src);
    clear_address(&probe.dst);
    probe.port = probe.dst_port = 0;
    if (protocol->cycles->by_sender != DG_STREAM_ENDS_NONE) {
        probe.src = pinfo->src; /* shallow: copied below if the stream is new */
        probe.port = pinfo->srcport;
    }
    if (protocol->cycles->by_sender == DG_STREAM_ENDS_CONNECTION) {
        probe.dst = pinfo->dst;
        probe.dst_port = pinfo->destport;
    }
    guint32 h = dg_rt::hash_mix(dg_cycle_input_hash(in), probe.port);
    if (probe.src.type != AT_NONE) h = add_address_to_hash(h, &probe.src);
    if (probe.dst.type != AT_NONE) h = add_address_to_hash(dg_rt::hash_mix(h, probe.dst_port), &probe.dst);
    probe.hash = h;
    stream *s = (stream *)wmem_map_lookup(c->streams, &probe);
    if (s) return s;
    s = wmem_new0(wmem_file_scope(), stream);
    s->hash = h;
    s->count = in->count;
    s->values = (guint64 *)wmem_memdup(wmem_file_scope(), in->values, in->count * sizeof(guint64));
    s->nodes = (guint16 *)wmem_memdup(wmem_file_scope(), in->nodes, in->count * sizeof(guint16));
    s->lengths = (guint32 *)wmem_memdup(wmem_file_scope(), in->lengths, in->count * sizeof(guint32));
    s->bytes = wmem_alloc0_array(wmem_file_scope(), const guint8 *, in->count);
    for (guint i = 0; i < in->count; i++) {
        if (!in->bytes[i]) continue;
        guint8 *copy = (guint8 *)wmem_alloc(wmem_file_scope(), in->lengths[i] + 1); /* NUL-ended: text */
        memcpy(copy, in->bytes[i], in->lengths[i]);
        copy[in->lengths[i]] = 0;
        s->bytes[i] = copy;
    }
    copy_address_wmem(wmem_file_scope(), &s->src, &probe.src);
    s->port = probe.port;
    copy_address_wmem(wmem_file_scope(), &s->dst, &probe.dst);
    s->dst_port = probe.dst_port;
    wmem_map_insert(c->streams, s, s);
    return s;
}

cycle *new_cycle(capture_state *c, stream *s, guint window, guint32 frame)
{
    cycle *cy = wmem_new0(wmem_file_scope(), cycle);
    cy->number = ++c->cycles;
    cy->s = s;
    cy->first_frame = frame;
    if (c->last)
        c->last->next = cy;
    else
        c->first = cy;
    c->last = cy;
    /* the window's periods, oldest first; the last is the marking message's own */
    for (guint i = 0; i + 1 < window; i++) cy->periods.add(s->recent[(s->next_slot + i) % window]);
    return cy;
}

/* Half the range 0 .. top of a count, rounded down: the largest advance
 * taken as forward (4 of a 3-bit count's 8 values; what lies beyond went back). */
guint64 half_range(guint64 top) { return (top >> 1) + (top & 1); }

/* Messages lost before an advance of the count by `advance` (not 0) in a
 * stream whose count advances by `step` per message and runs up to `top`:
 * G_MAXUINT32 when the count went back (more than half the range: a
 * restart, a message overtaken) or jumped by no whole number of steps. */
guint32 lost_before(guint64 advance, guint64 step, guint64 top)
{
    if (advance > half_range(top) || advance % step) return G_MAXUINT32;
    return (guint32)MIN(advance / step - 1, (guint64)G_MAXUINT32 - 1);
}

/* lost="period": the messages lost in a gap of `period` in a cycle whose
 * nominal period is `nominal`: the period rounded to whole nominal periods,
 * minus one; G_MAXUINT32 for more than `most` lost (a pause: the stream
 * stopped and came back; nothing is counted, as for a count that went back).
 * By default at most 15: further out, a gap in whole periods depends on ppm
 * of clock drift. */
const guint32 most_lost_by_period = 15;

guint32 lost_in_gap(gint64 period, guint64 nominal, guint32 most)
{
    if (period <= 0 || !nominal) return 0;
    const guint64 periods = ((guint64)period + nominal / 2) / nominal;
    if (periods > (guint64)most + 1) return G_MAXUINT32;
    return periods >= 2 ? (guint32)(periods - 1) : 0;
}

/* The sequence count's advance since the stream's previous message: FALSE
 * when it is a duplicate; else *lost messages lost (G_MAXUINT32: the count
 * went back). A learned step (`step` 0) is the stream's first advance, or a
 * smaller one that divides it (the first held a loss). */
gboolean sequence_step(stream *s, const dg_cycle_input *in, const dg_cycles *cy, guint32 *lost)
{
    *lost = 0;
    const guint bits = cy->sequence_bits;
    const guint64 step = cy->sequence_step, wrap = cy->sequence_wrap;
    if (!bits) return TRUE;
    if (!in->has_sequence) { /* a message without its count: the next count starts afresh */
        s->has_sequence = FALSE;
        return TRUE;
    }
    const guint64 mask = bits >= 64 ? G_MAXUINT64 : ((guint64)1 << bits) - 1;
    const guint64 count = in->sequence & mask;
    if (wrap && count >= wrap) { /* outside the count's range: no count, and the next one starts afresh */
        s->has_sequence = FALSE;
        return TRUE;
    }
    const guint64 top = wrap ? wrap - 1 : mask; /* the highest count */
    if (s->has_sequence) {
        const guint64 last = s->last_sequence;
        const guint64 advance = wrap ? (count >= last ? count - last : count + (wrap - last)) : (count - last) & mask;
        if (advance == 0) return FALSE;
        if (!step && advance <= half_range(top) && (!s->learned_step || s->learned_step % advance == 0))
            s->learned_step = advance;
        const guint64 by = step ? step : s->learned_step;
        *lost = by ? lost_before(advance, by, top) : G_MAXUINT32;
        if (cy->max_lost && *lost != G_MAXUINT32 && *lost > cy->max_lost)
            *lost = G_MAXUINT32; /* maxlost="N": a longer gap is a restart (a device reset, a new connection) */
    }
    s->last_sequence = count;
    s->has_sequence = TRUE;
    return TRUE;
}

gpointer request_key(guint64 seq) { return GSIZE_TO_POINTER((gsize)seq); /* unique below 2^32 requests */ }

/* requests="yes", first pass: a request of stream s, the cycle's message
 * number `ordinal` (0: before the cycle), waits for its answer. */
void request_sent(capture_state *c, stream *s, const dg_transaction *txn, guint32 ordinal)
{
    if (!c->pending) c->pending = wmem_map_new(wmem_file_scope(), g_direct_hash, g_direct_equal);
    if (!s->pending) s->pending = wmem_alloc0_array(wmem_file_scope(), pending_request, pending_ring);
    pending_request *r = &s->pending[s->next_pending];
    s->next_pending = (s->next_pending + 1) % pending_ring;
    if (r->seq) wmem_map_remove(c->pending, request_key(r->seq)); /* the oldest kept: given up */
    r->seq = txn->seq;
    r->ordinal = ordinal;
    r->s = s;
    wmem_map_insert(c->pending, request_key(txn->seq), r);
    s->last_request = txn->seq;
}

/* requests="yes", first pass: a response answering `txn`. */
void request_answered(capture_state *c, const dg_transaction *txn, const packet_info *pinfo)
{
    pending_request *r = c->pending ? (pending_request *)wmem_map_remove(c->pending, request_key(txn->seq)) : NULL;
    if (!r) return; /* a request in no stream, or given up */
    stream *s = r->s;
    const guint32 ordinal = r->ordinal;
    r->seq = 0;
    if (txn->seq >= s->last_answered) {
        s->last_answered = txn->seq;
        s->last_return = pinfo->abs_ts;
        s->last_rtt = txn->round_trip;
    }
    cycle *cy = s->cyc;
    if (!cy || !ordinal) return;
    cy->rtts.push(period_of(ns_of(&txn->round_trip)));
    cy->answered++;
    cy->latest_answered = MAX(cy->latest_answered, ordinal);
}

/* requests="yes": whether a request's period since the stream's previous
 * request can be regular: that one was answered before this one was sent,
 * and this one is no poll (sent less than that round trip after the answer). */
gboolean answered_before(const stream *s, const packet_info *pinfo)
{
    if (!s->last_request || s->last_answered != s->last_request) return FALSE;
    return ns_of(&pinfo->abs_ts) - ns_of(&s->last_return) >= ns_of(&s->last_rtt);
}

/* First pass: times the message in its stream; what it shows, or NULL. */
mark *time_message(capture_state *c, const dg_cycle_input *in, const dg_frame_pairing *fp, const packet_info *pinfo)
{
    const dg_cycles *cy = protocol->cycles;
    if (cy->requests_only) { /* only requests are timed; a response tells its request's stream */
        if (!fp || !fp->txn) return NULL;
        if (fp->role == DG_ROLE_RESPONSE) request_answered(c, fp->txn, pinfo);
        if (fp->role != DG_ROLE_REQUEST) return NULL;
    }
    if (!dg_cycle_input_in_stream(cy, in)) return NULL;
    stream *s = stream_of(c, in, pinfo);
    s->messages++;
    mark m = {};
    guint32 lost;
    if (!sequence_step(s, in, cy, &lost)) {
        s->duplicates++;
        m.duplicate_of = s->last_frame;
        m.cycle = s->cyc ? s->cyc->number : 0;
        return (mark *)wmem_memdup(wmem_file_scope(), &m, sizeof m);
    }
    const gboolean first = s->last_frame == 0;
    const gint64 period = first ? 0 : ns_of(&pinfo->abs_ts) - ns_of(&s->last_time);
    if (cy->lost_by_period && s->cyc)
        lost = lost_in_gap(period, s->cyc->periods.median(), cy->max_lost ? cy->max_lost : most_lost_by_period);
    const gboolean went_back = lost == G_MAXUINT32;
    if (!went_back) {
        m.lost = lost;
        s->lost += lost;
    }
    const gboolean paired_regular = !cy->requests_only || answered_before(s, pinfo);
    s->last_frame = pinfo->num;
    s->last_time = pinfo->abs_ts;
    const gboolean regular = !first && period > 0 && lost == 0 && paired_regular;
    if (!first && !s->cyc) {
        if (!regular) {
            s->regular = 0;
        } else {
            s->recent[s->next_slot] = period_of(period);
            s->next_slot = (s->next_slot + 1) % cy->window;
            if (s->regular < cy->window) s->regular++;
            if (s->regular == cy->window && steady_median(s->recent, cy->window))
                s->cyc = new_cycle(c, s, cy->window, pinfo->num);
        }
    }
    cycle *cyc = s->cyc;
    if (cyc) {
        m.cycle = cyc->number;
        m.timed = TRUE;
        m.period_ns = period;
        cyc->frames++;
        if (regular) {
            cyc->periods.add(period_of(period));
            cyc->marked.push(period_of(period));
            m.jittered = TRUE;
            m.jitter_ns = period - (gint64)cyc->periods.median();
            cyc->jitter_sum += (double)m.jitter_ns;
            cyc->jitter_squares += (double)m.jitter_ns * (double)m.jitter_ns;
        }
    }
    if (cy->requests_only) request_sent(c, s, fp->txn, cyc ? cyc->frames : 0);
    if (!m.cycle && !m.lost) return NULL;
    return (mark *)wmem_memdup(wmem_file_scope(), &m, sizeof m);
}

void keep_first_mark(capture_state *c, guint32 frame, const mark *m)
{
    if (frame >= c->by_frame_size) {
        guint32 size = MAX(frame + 1, 2 * c->by_frame_size);
        c->by_frame = (const mark **)wmem_realloc(wmem_file_scope(), c->by_frame, size * sizeof *c->by_frame);
        memset(c->by_frame + c->by_frame_size, 0, (size - c->by_frame_size) * sizeof *c->by_frame);
        c->by_frame_size = size;
    }
    c->by_frame[frame] = m;
}

void add_generated_time(proto_tree *tree, int hf, tvbuff_t *tvb, gint64 ns)
{
    nstime_t t = nstime_of(ns);
    proto_item_set_generated(proto_tree_add_time(tree, hf, tvb, 0, 0, &t));
}

void show(const mark *m, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    if (!tree && !m->lost && !m->duplicate_of) return; /* nothing to add, no expert to raise */
    if (m->cycle) proto_item_set_generated(proto_tree_add_uint(tree, hf_stream_cycle, tvb, 0, 0, m->cycle));
    if (m->timed) add_generated_time(tree, hf_stream_period, tvb, m->period_ns);
    if (m->jittered) add_generated_time(tree, hf_stream_jitter, tvb, m->jitter_ns);
    if (m->lost) {
        proto_item *it = proto_tree_add_uint(tree, hf_stream_lost, tvb, 0, 0, m->lost);
        proto_item_set_generated(it);
        expert_add_info_format(pinfo, it, &ei_stream_lost_expert, "%u message%s of this stream lost right before this one",
                               m->lost, m->lost == 1 ? "" : "s");
    }
    if (m->duplicate_of) {
        proto_item *it = proto_tree_add_uint(tree, hf_stream_duplicate, tvb, 0, 0, m->duplicate_of);
        proto_item_set_generated(it);
        expert_add_info_format(pinfo, it, &ei_stream_duplicate_expert,
                               "Repeats frame %u: the same sequence count", m->duplicate_of);
    }
}

/* --- -z P,cycles and the statistics tree --------------------------------- */

/* A cycle's whole-capture figures, from the capture's state. */
struct figures {
    guint64 nominal;
    quantiles_of_t<guint64> period, rtt;
    double jitter_sd;
    guint unanswered;       /* requests="yes" */
};

figures figures_of(const cycle *c)
{
    figures f = {};
    f.nominal = c->periods.median();
    f.period = quantiles_of(c->marked);
    guint n = c->marked.n;
    double mean = n ? c->jitter_sum / n : 0;
    double var = n ? c->jitter_squares / n - mean * mean : 0;
    f.jitter_sd = var > 0 ? sqrt(var) : 0.0;
    f.rtt = quantiles_of(c->rtts);
    f.unanswered = c->latest_answered - MIN(c->answered, c->latest_answered);
    return f;
}

/* A field compared by its bytes: text in quotes up to its first NUL
 * (non-printable characters escaped), an IPv4 or IPv6 address as its item
 * shows it, other bytes in hex separated by colons, in capture order (a MAC
 * address, an EUI-64, a GUID, raw bytes). */
void append_bytes(GString *t, const dg_node *n, const guint8 *b, guint32 length)
{
    if (n->show == DG_SHOW_STRING || n->show == DG_SHOW_STRINGZ) {
        const guint8 *nul = (const guint8 *)memchr(b, 0, length); /* the text ends there, as its item shows it */
        guint32 text = nul ? (guint32)(nul - b) : length;
        /* ISO-8859-1 text in UTF-8 first, as its item shows it */
        guint8 *utf8 = n->extra && n->extra->encoding == ENC_ISO_8859_1 ? get_8859_1_string(NULL, b, (gint)text) : NULL;
        if (utf8) text = (guint32)strlen((const char *)utf8);
        char *shown = dg_format_text(NULL, utf8 ? utf8 : b, text);
        g_string_append_printf(t, "%s \"%s\"", n->name, shown);
        wmem_free(NULL, shown);
        wmem_free(NULL, utf8);
        return;
    }
    g_string_append_printf(t, "%s ", n->name);
    if (n->show == DG_SHOW_IPV6 && length == 16) {
        address a;
        set_address(&a, AT_IPv6, 16, b);
        char *shown = address_to_str(NULL, &a);
        g_string_append(t, shown);
        wmem_free(NULL, shown);
        return;
    }
    /* an IPv4 address or an EUI-64 in the node's byte order, as its item reads it */
    const gboolean ipv4 = n->show == DG_SHOW_IPV4;
    const gboolean reversed = (ipv4 || n->show == DG_SHOW_EUI64) && (n->flags & DG_LITTLE);
    for (guint32 i = 0; i < length; i++) {
        const guint8 byte = b[reversed ? length - 1 - i : i];
        if (ipv4)
            g_string_append_printf(t, i ? ".%u" : "%u", byte);
        else
            g_string_append_printf(t, i ? ":%02x" : "%02x", byte);
    }
}

/* The name an enum signature field's <enum> gives its value, or NULL. */
const char *stream_enum_name(const dg_node *n, guint64 value)
{
    const header_field_info *hfi = n->hf && *n->hf > 0 ? proto_registrar_get_nth(*n->hf) : NULL;
    return hfi && hfi->strings ? dg_rt::enum_name(hfi, value) : NULL;
}

/* ", sender 192.168.1.10:2222" (no port when the transport has none) */
void append_end(GString *t, const char *which, const address *a, guint32 port)
{
    if (a->type == AT_NONE) return;
    char *addr = address_to_str(NULL, a);
    g_string_append_printf(t, port ? ", %s %s:%u" : ", %s %s", which, addr, port);
    wmem_free(NULL, addr);
}

/* "Connection ID 0x00ff0001, sender 192.168.1.10:2222": each signature field
 * by its node's name and value as the stream first had them. */
char *stream_text(const stream *s)
{
    GString *t = g_string_new("");
    for (guint i = 0; i < s->count; i++) {
        const dg_node *n = &protocol->nodes[s->nodes[i]];
        if (i) g_string_append(t, ", ");
        const char *name = n->show == DG_SHOW_ENUM && !s->bytes[i] ? stream_enum_name(n, s->values[i]) : NULL;
        if (s->bytes[i]) {
            append_bytes(t, n, s->bytes[i], s->lengths[i]);
            continue;
        }
        char buf[32]; /* the longest number: "-9223372036854775808" */
        dg_rt::dg_text number;
        dg_rt::text_init(&number, NULL, buf, sizeof buf);
        dg_rt::append_number(&number, n, s->values[i]);
        if (name) /* "MessageType PReq (0x03)", as the tree shows an enum */
            g_string_append_printf(t, "%s %s (%s)", n->name, name, number.data);
        else
            g_string_append_printf(t, "%s %s", n->name, number.data);
    }
    append_end(t, "sender", &s->src, s->port);
    append_end(t, "receiver", &s->dst, s->dst_port);
    return g_string_free(t, FALSE);
}

/* What -z P,cycles and the statistics tree count beside the timing: losses
 * with a sequence count or lost="period", duplicates only with a count. */
gboolean losses_counted(void) { return protocol->cycles->sequence_bits || protocol->cycles->lost_by_period; }
gboolean duplicates_counted(void) { return protocol->cycles->sequence_bits > 0; }

/* At the end of the capture, from the capture's state (complete by then). */
void cycles_draw(void *)
{
    printf("===================================================================\n");
    printf("%s cycles (%s)\n", protocol->name, protocol->filter);
    if (!capture || !capture->first) printf("No cycles\n");
    for (const cycle *c = capture ? capture->first : NULL; c; c = c->next) {
        figures f = figures_of(c);
        char *name = stream_text(c->s);
        printf("Cycle %u: %s\n", c->number, name);
        g_free(name);
        printf("  first frame: %u\n", c->first_frame);
        printf("  messages: %u\n", c->frames);
        printf("  nominal period (ns): %" G_GUINT64_FORMAT "\n", f.nominal);
        print_quantiles("period", &f.period);
        printf("  jitter std dev (ns): %.1f\n", f.jitter_sd);
        if (losses_counted()) printf("  messages lost: %u\n", c->s->lost);
        if (duplicates_counted()) printf("  duplicates: %u\n", c->s->duplicates);
        if (protocol->cycles->requests_only) {
            print_quantiles("round trip", &f.rtt);
            printf("  requests answered: %u\n", c->answered);
            printf("  requests unanswered: %u\n", f.unanswered);
        }
    }
    printf("===================================================================\n");
}

const char *cli_filter;

dg_tap_init_result cycles_cli_init(const char *, void *)
{
    return dg_tap_init_done(listen_to_the_end(&cli_filter, cycles_draw));
}

/* The statistics tree (Wireshark's Statistics menu): the same figures,
 * filled once the capture's state is complete (st_fill_now). */
gboolean st_filled;

void st_init(stats_tree *) { st_filled = FALSE; }

tap_packet_status st_packet(stats_tree *st, packet_info *pinfo, epan_dissect_t *, const void *, tap_flags_t)
{
    if (!st_fill_now(&st_filled, capture != NULL, pinfo->num, capture ? capture->last_frame : 0))
        return TAP_PACKET_DONT_REDRAW;
    for (const cycle *c = capture->first; c; c = c->next) {
        figures f = figures_of(c);
        char *text = stream_text(c->s);
        int id = st_cycle_node(st, c->number, text, c->frames);
        g_free(text);
        st_cycle_row(st, c->number, "messages", id, c->frames);
        const st_time_unit unit = st_unit_of(f);
        st_time_row(st, c->number, "nominal period", id, f.nominal, unit);
        st_quantile_rows(st, c->number, "period", &f.period, id, unit);
        st_time_row(st, c->number, "jitter std dev", id, (guint64)(f.jitter_sd + 0.5), unit);
        if (losses_counted()) st_cycle_row(st, c->number, "messages lost", id, c->s->lost);
        if (duplicates_counted()) st_cycle_row(st, c->number, "duplicates", id, c->s->duplicates);
        if (protocol->cycles->requests_only) {
            st_quantile_rows(st, c->number, "round trip", &f.rtt, id, unit);
            st_cycle_row(st, c->number, "requests answered", id, c->answered);
            st_cycle_row(st, c->number, "requests unanswered", id, f.unanswered);
        }
    }
    return TAP_PACKET_REDRAW;
}

} /* namespace */

void dg_cycles_register(const dg_protocol *p)
{
    protocol = p;
    cli_filter = p->filter;
    /* Wireshark keeps pointers to these: static arrays, names that live until exit. */
    static hf_register_info hf[] = {DG_CYCLES_FIELDS(DG_HF_ROW)};
    static const char *const names[] = {DG_CYCLES_FIELDS(DG_FIELD_NAME)};
    dg_name_fields(hf, names, G_N_ELEMENTS(hf), p->filter);
    proto_register_field_array(*p->proto, hf, (int)G_N_ELEMENTS(hf));
    static ei_register_info ei[] = {DG_CYCLES_EXPERTS(DG_EI_ROW)};
    static const char *const ei_names[] = {DG_CYCLES_EXPERTS(DG_EXPERT_NAME)};
    dg_name_experts(ei, ei_names, G_N_ELEMENTS(ei), p->filter);
    expert_register_field_array(expert_register_protocol(*p->proto), ei, (int)G_N_ELEMENTS(ei));
    register_init_routine(capture_init);
    register_cleanup_routine(capture_cleanup);

    static stat_tap_ui ui = {REGISTER_STAT_GROUP_GENERIC, NULL, NULL, cycles_cli_init, 0, NULL};
    ui.cli_string = g_strdup_printf("%s,cycles", p->filter);
    register_stat_tap_ui(&ui, NULL);
    /* Statistics > "P cycles" in Wireshark (tshark -2 -z P.cycles,tree) */
    stats_tree_register_plugin("frame", g_strdup_printf("%s.cycles", p->filter),
                               g_strdup_printf("%s cycles", p->short_name), 0, st_packet, st_init, NULL);
}

void dg_cycles_dissect(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree,
                       const dg_cycle_input *in, const dg_frame_pairing *fp, guint message)
{
    const mark *m = NULL;
    capture_state *c = current_capture();
    /* The first pass may bring a message back (a frame dissected again, as
     * TCP reassembly can): it is timed once, then shown as it was. */
    const gboolean timed = PINFO_FD_VISITED(pinfo) || (pinfo->num == c->last_frame && message < c->messages_timed);
    if (!timed) {
        if (pinfo->num != c->last_frame) {
            c->last_frame = pinfo->num;
            c->messages_timed = 0;
        }
        c->messages_timed = MAX(c->messages_timed, message + 1);
        m = in ? time_message(c, in, fp, pinfo) : NULL;
        if (m && message == 0)
            keep_first_mark(c, pinfo->num, m);
        else if (m)
            p_add_proto_data(wmem_file_scope(), pinfo, *p->proto, mark_key | message, (void *)m);
    } else if (message == 0) {
        m = pinfo->num < c->by_frame_size ? c->by_frame[pinfo->num] : NULL;
    } else {
        m = (const mark *)p_get_proto_data(wmem_file_scope(), pinfo, *p->proto, mark_key | message);
    }
    if (m) show(m, tvb, pinfo, tree);
}

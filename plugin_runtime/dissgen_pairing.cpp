/* Request/response pairing across frames: see dissgen_pairing.h.
 *
 * First pass, per message, in capture order:
 *  1. Requests that can no longer be answered are given up: older than the
 *     timeout, or overtaken by the responses to more than max_overtaken later
 *     requests. Given up unanswered, a request is lost, and this message is
 *     the one that proves it (give_up: its expert info in one pass).
 *  2. The direction: the transport's (to the hooked port a request, from it
 *     a response), else what the analysis reads from the message itself.
 *  3. The same bytes from the same source as the last message with that key,
 *     soon after it (within_copy_window), when that message was a response or
 *     the message just before: a duplicate (a frame captured twice); it is
 *     not paired. Except where the analysis cannot tell the directions apart
 *     (returns not marked): a request's copy right after it is a frame that
 *     came back unprocessed, its response.
 *  4. A response answers its key's oldest waiting request that its source
 *     fits (else the one request waiting if only its key changed), or is an
 *     orphan (its request was not captured). A request gives up its key's
 *     waiting requests from the same sender and waits. A message whose
 *     direction nothing tells: with an analysis that reads directions, a new
 *     request unless it is its key's waiting request come back untouched;
 *     without one, the order decides (the first message of a key is the
 *     request, the next one its response).
 *  5. A request known to be one (by the transport or <request>) and sent to
 *     a group address (over UDP also the Ethernet broadcast) is a group
 *     request: each station of the group may answer, so after its first
 *     answer it keeps waiting, and a later response with its key answers it
 *     too when no request of the key waits for its first answer. Any other
 *     message of the key ends its wait, as does step 1; answered, it is then
 *     not lost.
 * Nothing here is touched on later passes.
 */
#include "dissgen_pairing.h"
#include "dissgen_periods.h"
#include "dissgen_state.h"
#include "dissgen_values.h"


#include <epan/conversation.h>
#include <epan/proto_data.h>
#include <epan/expert.h>

#include <math.h>
#include <string.h>

namespace {

/* Key of the per-frame state (p_add_proto_data), plus the message number. */
const guint32 frame_key = 0x70616972u; /* "pair" */

struct pair_key {
    guint count;
    guint64 *values;
};

/* What later passes show of one message: kept for the whole capture, so 16
 * bytes. The first message of each frame keeps it in the capture's frame
 * table (inline, indexed by frame number), any other message of a frame
 * with p_add_proto_data. What few messages need sits in maps beside the
 * table: the requests it proved lost, a round trip beyond 2 s, and (in an
 * array) the transaction of a request not answered (which says why on
 * display), and a group request's answers after its first; once answered,
 * the two frames' numbers and the round trip say everything. */
struct kept {
    guint32 partner;      /* request: its response's frame (0: none yet); response: its
                           * request's; duplicate: the frame it repeats */
    guint8 role;          /* dg_role; 0: not paired on the first pass */
    guint8 out_of_order;  /* response: a later request was answered first */
    guint16 lost_count;   /* requests it proved lost (capture_state.lost_lists) */
    gint32 round_trip;    /* response: in ns; long_trip: see capture_state.long_trips;
                           * request not answered: its slot in capture_state.unanswered + 1 */
    guint32 analysis;     /* response: the analysis's comparison; request: its sent() result */
};
static_assert(sizeof(kept) == 16, "kept grew");
const gint32 long_trip = G_MININT32;

/* Frames per chunk of the frame table: chunks never move, so a kept record
 * stays where pending requests and key entries point. */
const guint table_shift = 12;
const guint table_chunk = 1u << table_shift;

/* A request waiting for its response. It is in two queues, oldest first:
 * its key's and the capture's; answered or given-up ones are marked done and
 * leave each queue when they reach its head. */
struct pending {
    pending *next;        /* in the key's queue */
    pending *next_sent;   /* in the capture's queue */
    guint8 queues;        /* how many queues still hold it */
    gboolean done;
    dg_transaction *txn;
    address src;
    guint8 src_bytes[16];  /* src's data when it fits (kept_address) */
    guint8 *bytes;  /* the request's bytes and view, kept for the analysis until retired */
    guint length;
    guint view_count; /* values of its view (kept_view) */
    guint capacity; /* of bytes (a buffer used again: capture_state.spare) */
    guint64 key;    /* its first key value (dg_lost) */
    kept *record;              /* the request's record */
    gboolean guessed;          /* taken for a request for want of a better idea */
    /* Sent to a group of stations (group_request): each may answer, so it
     * waits for more answers after its first until it is given up, and then
     * it is not lost. */
    gboolean group;
    gboolean answered;         /* a group request: answered at least once */
};

struct queue {
    pending *head, *tail;
};

struct key_entry {
    pair_key *key;               /* its key in capture_state.keys */
    key_entry *older, *newer;    /* capture_state's list, least recently used first */
    queue waiting;               /* this key's requests */
    guint32 last_frame;          /* the last message with this key (duplicates) */
    nstime_t last_time;
    guint8 last_role;            /* dg_role */
    kept *last_record;           /* its record (adopt_orphan) */
    const dg_request_values *last_answered; /* a response: what the request it answered kept */
    address last_src;
    guint8 last_src_bytes[16];
    guint8 *last_bytes;          /* and, with an analysis, its view (kept_view) */
    guint last_length;
    guint last_captured;         /* the bytes its tvb held (its copy's tvb holds as many) */
    guint last_view_count;
    guint last_capacity;         /* of last_bytes, which each message of the key fills again */
    nstime_t last_request_time;  /* this key's last request */
    nstime_t request_period;     /* between its last two requests; 0 until there are two */
};

/* An order scope's requests: how many were sent, and the highest of their
 * numbers in it (dg_transaction.order_seq) answered so far. */
struct order_count {
    guint64 sent, answered;
};

struct capture_state {
    wmem_map_t *keys;            /* pair_key -> key_entry */
    key_entry *oldest, *newest;  /* key entries by their last message, least recent first */
    queue sent;                  /* every key's requests, in capture order */
    guint waiting;               /* requests not yet answered nor given up (group requests answered not counted) */
    guint guessed;               /* of them, taken for requests for want of a better idea */
    guint64 requests;            /* the last request's seq */
    guint64 answered_max;        /* the highest seq answered so far, in any order scope */
    const struct kept *just_answered; /* the latest response, and the seq it answered: */
    guint64 just_answered_seq;        /* its view on the first pass says which request */
    /* Per order scope, its requests counted and the highest of their
     * numbers answered so far (order_count). A server answers a connection's
     * requests in order, not those of other connections: the out-of-order
     * note and overtaken requests go by the request's TCP or UDP
     * conversation, or (scope 0) by the whole capture for a protocol right
     * over a link layer, such as EtherCAT over Ethernet. */
    wmem_array_t *scope_answered;
    guint32 last_frame;          /* the last message paired (its frame) */
    void *analysis;              /* the analysis's capture-wide state */
    nstime_t clock;              /* what forgetting goes by (forget_clock) */
    nstime_t previous_time;      /* the last message's time */
    gboolean clock_set;
    const dg_view *view;         /* the analysis inputs of the message being paired (first pass) */
    wmem_array_t *table;         /* the frame table: chunks of table_chunk kept records */
    wmem_map_t *lost_lists;      /* kept record -> the dg_lost it proved (kept.lost_count) */
    wmem_map_t *long_trips;      /* kept record -> its round trip in ns (gint64), beyond a gint32 */
    wmem_map_t *more_responses;  /* kept record of a group request -> its answers after the first (wmem_array_t of guint32) */
    /* The transactions of requests not answered, at the slot their records
     * name (kept.round_trip); a slot let go of (NULL) is on free_slots, for
     * the next request: an array, where a map would hash and allocate on
     * every request and its answer. */
    wmem_array_t *unanswered;    /* dg_transaction * */
    guint32 *free_slots;
    guint free_count, free_capacity;
    /* The requests the message being paired proves lost (give_up). */
    guint32 frame;               /* that message's frame */
    dg_lost *lost;
    guint lost_count, lost_capacity;
    /* A request's bytes buffer its answer freed, for the next request
     * (one allocation and one free fewer per pair). */
    guint8 *spare;
    guint spare_capacity;
    /* Transactions answered and requests let go of, for the next requests:
     * most are answered within a few messages, so these stay short. */
    struct recycled *free_transactions, *free_pending;
    /* Over UDP, the client of the latest request sent to a group address,
     * by its key values (pair_key -> guint64): a response sent to a group
     * names no client of its own (with_client). Kept while that request's
     * key entry is (forget_group_client). */
    wmem_map_t *group_clients;
};

/* A freed transaction or pending request on a capture_state free list. */
struct recycled {
    recycled *next;
};
static_assert(sizeof(recycled) <= sizeof(dg_transaction) && sizeof(recycled) <= sizeof(pending), "recycled");

/* A zeroed T from `list` (wmem_file_scope()'s when it is empty). */
template <typename T> T *new_recycled(recycled **list)
{
    recycled *r = *list;
    if (!r) return wmem_new0(wmem_file_scope(), T);
    *list = r->next;
    memset((void *)r, 0, sizeof(T));
    return (T *)(void *)r;
}

/* p is no longer used: on `list` for new_recycled(). */
void recycle(recycled **list, void *p)
{
    recycled *r = (recycled *)p;
    r->next = *list;
    *list = r;
}

/* One protocol per plugin, and each plugin links its own runtime. */
const dg_protocol *protocol;
const dg_analysis *analysis;
const char *key_name = "key"; /* the first key field's name, for texts */
const dg_node *key_node;      /* the first key field, whose display base the texts follow */
capture_state *capture; /* NULL between captures */

int hf_response_in = -1, hf_request_in = -1, hf_time = -1, hf_no_response_to = -1, hf_no_request = -1;
expert_field ei_no_response = EI_INIT, ei_duplicate = EI_INIT, ei_out_of_order = EI_INIT;

guint key_hash(gconstpointer v)
{
    const pair_key *k = (const pair_key *)v;
    guint h = 2166136261u ^ k->count;
    for (guint i = 0; i < k->count; i++) {
        guint64 x = k->values[i];
        h = (h ^ (guint)x) * 16777619u;
        h = (h ^ (guint)(x >> 32)) * 16777619u;
    }
    return h;
}

gboolean key_equal(gconstpointer a, gconstpointer b)
{
    const pair_key *x = (const pair_key *)a, *y = (const pair_key *)b;
    return x->count == y->count && (x->count == 0 || memcmp(x->values, y->values, x->count * sizeof(guint64)) == 0);
}

/* An address kept in `bytes` (a buffer of its holder) when it fits, which
 * spares an allocation and a free per message; larger ones are copied. */
template <gsize N> void keep_address(address *to, guint8 (&bytes)[N], const address *from)
{
    if (from->len >= 0 && (gsize)from->len <= N) {
        if (from->len > 0) memcpy(bytes, from->data, (gsize)from->len);
        set_address(to, from->type, from->len, from->len > 0 ? bytes : NULL);
    } else {
        copy_address_wmem(wmem_file_scope(), to, from);
    }
}

template <gsize N> void drop_address(address *a, const guint8 (&bytes)[N])
{
    if (a->data && a->data != bytes) free_address_wmem(wmem_file_scope(), a);
    clear_address(a);
}

void capture_init(void) { capture = NULL; }
void capture_cleanup(void) { capture = NULL; /* its memory goes with wmem_file_scope */ }

capture_state *current_capture(void)
{
    if (!capture) {
        capture = wmem_new0(wmem_file_scope(), capture_state);
        capture->keys = wmem_map_new(wmem_file_scope(), key_hash, key_equal);
        capture->scope_answered = wmem_array_sized_new(wmem_file_scope(), sizeof(order_count), 4);
        capture->table = wmem_array_new(wmem_file_scope(), sizeof(kept *));
        capture->lost_lists = wmem_map_new(wmem_file_scope(), g_direct_hash, g_direct_equal);
        capture->long_trips = wmem_map_new(wmem_file_scope(), g_direct_hash, g_direct_equal);
        capture->more_responses = wmem_map_new(wmem_file_scope(), g_direct_hash, g_direct_equal);
        capture->unanswered = wmem_array_new(wmem_file_scope(), sizeof(dg_transaction *));
        capture->group_clients = wmem_map_new(wmem_file_scope(), key_hash, key_equal);
        order_count none = {0, 0};
        wmem_array_append_one(capture->scope_answered, none);
        if (analysis && analysis->capture_new) capture->analysis = analysis->capture_new(protocol);
    }
    return capture;
}

/* The kept record of the first message of `frame`, in the frame table; with
 * `create` the table grows to hold it, else NULL when it has none. */
kept *table_slot(capture_state *c, guint32 frame, gboolean create)
{
    guint chunk = frame >> table_shift;
    if (chunk >= wmem_array_get_count(c->table)) {
        if (!create) return NULL;
        kept *none = NULL;
        while (wmem_array_get_count(c->table) <= chunk) wmem_array_append_one(c->table, none);
    }
    kept **at = (kept **)wmem_array_index(c->table, chunk);
    if (!*at) {
        if (!create) return NULL;
        *at = wmem_alloc0_array(wmem_file_scope(), kept, table_chunk);
    }
    return &(*at)[frame & (table_chunk - 1)];
}

/* The kept record of message `message` of this frame (see kept), or NULL. */
kept *record_of(capture_state *c, packet_info *pinfo, guint message, gboolean create)
{
    if (message == 0) return table_slot(c, pinfo->num, create);
    kept *k = (kept *)p_get_proto_data(wmem_file_scope(), pinfo, *protocol->proto, frame_key + message);
    if (!k && create) {
        k = wmem_new0(wmem_file_scope(), kept);
        p_add_proto_data(wmem_file_scope(), pinfo, *protocol->proto, frame_key + message, k);
    }
    return k;
}

/* Request k, not answered, has transaction t until answered (set_answered). */
void set_unanswered(capture_state *c, kept *k, dg_transaction *t)
{
    guint32 slot;
    if (c->free_count) {
        slot = c->free_slots[--c->free_count];
        *(dg_transaction **)wmem_array_index(c->unanswered, slot) = t;
    } else {
        slot = wmem_array_get_count(c->unanswered);
        wmem_array_append_one(c->unanswered, t);
    }
    k->round_trip = (gint32)(slot + 1);
}

/* Request k is no longer waiting (answered, or an orphan after all): its slot goes. */
void set_answered(capture_state *c, kept *k)
{
    if (k->round_trip <= 0) return; /* none: an orphan taken for the request */
    guint32 slot = (guint32)k->round_trip - 1;
    *(dg_transaction **)wmem_array_index(c->unanswered, slot) = NULL;
    if (c->free_count == c->free_capacity) {
        c->free_capacity = c->free_capacity ? 2 * c->free_capacity : 16;
        c->free_slots = (guint32 *)wmem_realloc(wmem_file_scope(), c->free_slots, c->free_capacity * sizeof(guint32));
    }
    c->free_slots[c->free_count++] = slot;
    k->round_trip = 0;
}

/* The transaction of request k, not answered. */
dg_transaction *unanswered_of(const capture_state *c, const kept *k)
{
    if (k->round_trip <= 0) return NULL;
    return *(dg_transaction **)wmem_array_index(c->unanswered, (guint)k->round_trip - 1);
}

/* The order scope of a request sent in this packet (capture_state.scope_answered). */
guint32 order_scope_of(capture_state *c, packet_info *pinfo)
{
    if (pinfo->ptype != PT_TCP && pinfo->ptype != PT_UDP) return 0;
    conversation_t *conv = find_or_create_conversation(pinfo);
    guint32 scope = GPOINTER_TO_UINT(conversation_get_proto_data(conv, *protocol->proto));
    if (scope) return scope;
    scope = wmem_array_get_count(c->scope_answered);
    order_count none = {0, 0};
    wmem_array_append_one(c->scope_answered, none);
    conversation_add_proto_data(conv, *protocol->proto, GUINT_TO_POINTER(scope));
    return scope;
}

order_count *order_of(const capture_state *c, guint32 scope)
{
    return (order_count *)wmem_array_index(c->scope_answered, scope);
}

/* Puts a new request t in the order scope of its packet, numbered in it. */
void place_in_order(capture_state *c, dg_transaction *t, packet_info *pinfo)
{
    t->order_scope = order_scope_of(c, pinfo);
    t->order_seq = ++order_of(c, t->order_scope)->sent;
}

guint64 *answered_in(const capture_state *c, const dg_transaction *t) { return &order_of(c, t->order_scope)->answered; }

/* More than `by` later requests of t's order scope were answered: t is overtaken
 * (never where responses come in any order). Requests on other connections
 * do not count: a busy session beside a slow one overtakes nothing. */
gboolean overtaken(const capture_state *c, const dg_transaction *t, guint64 by)
{
    return protocol->pairing->ordered && *answered_in(c, t) > t->order_seq + by;
}

key_entry *entry_for(capture_state *c, const guint64 *keys, guint key_count)
{
    pair_key probe = {key_count, (guint64 *)keys};
    key_entry *e = (key_entry *)wmem_map_lookup(c->keys, &probe);
    if (e) return e;
    pair_key *k = wmem_new(wmem_file_scope(), pair_key);
    k->count = key_count;
    k->values = (guint64 *)wmem_memdup(wmem_file_scope(), keys, key_count * sizeof(guint64));
    e = wmem_new0(wmem_file_scope(), key_entry);
    e->key = k;
    wmem_map_insert(c->keys, k, e);
    return e;
}

/* How soon a copy of a key's last message must follow it to be that message
 * again (a frame captured twice, or one that came back unprocessed) rather
 * than the sender's next message: within a hundredth of the timeout, and
 * within half the key's request period once that is known (a cyclic request
 * sent unchanged every cycle is a new request each time, even when the
 * response in between was lost). */
gboolean within_copy_window(const key_entry *e, const nstime_t *then, const packet_info *pinfo)
{
    /* in whole nanoseconds: a copy exactly at the window's end is a copy */
    nstime_t gap;
    nstime_delta(&gap, &pinfo->abs_ts, then);
    gint64 window = (gint64)(protocol->pairing->timeout * 1e7 + 0.5); /* timeout / 100, in ns */
    const gint64 period = dg_periods::ns_of(&e->request_period);
    if (period > 0 && period / 2 < window) window = period / 2;
    return dg_periods::ns_of(&gap) <= window;
}

/* The last message of this key again: its bytes from the same source, soon
 * after it (within_copy_window). */
gboolean repeats_last(const key_entry *e, tvbuff_t *tvb, const packet_info *pinfo)
{
    return e->last_frame && addresses_equal(&e->last_src, &pinfo->src) && within_copy_window(e, &e->last_time, pinfo) &&
           tvb_memeql(tvb, 0, e->last_bytes, e->last_length) == 0;
}

/* The same bytes from the same source as the last message of this key, soon
 * after it, and that message a response or the one just before. */
gboolean same_again(const capture_state *c, const key_entry *e, tvbuff_t *tvb, packet_info *pinfo, guint length)
{
    if (e->last_length != length) return FALSE;
    if (e->last_role != DG_ROLE_RESPONSE && e->last_frame != c->last_frame) return FALSE;
    return repeats_last(e, tvb, pinfo);
}

/* A message the same as the last one (same_again) is a frame that came back
 * unprocessed, the request's response, when that one was a request, nothing
 * says this one is a request (its direction) and the analysis knows returns
 * that carry no mark (an EtherCAT simulator's); a copy of anything else is a
 * duplicate. */
gboolean unchanged_return(const key_entry *e)
{
    return e->last_role == DG_ROLE_REQUEST && analysis && analysis->is_response;
}

/* Takes e out of the capture's least-recently-used list (if it is there). */
void unlink_entry(capture_state *c, key_entry *e)
{
    if (e->older)
        e->older->newer = e->newer;
    else if (c->oldest == e)
        c->oldest = e->newer;
    if (e->newer)
        e->newer->older = e->older;
    else if (c->newest == e)
        c->newest = e->older;
    e->older = e->newer = NULL;
}

/* Where a kept message's view starts in its buffer: after its bytes, aligned
 * for the values (one allocation for both). */
guint view_start(guint length) { return (length + 7u) & ~7u; }

/* *buffer (of *capacity bytes) holds the first `length` bytes of tvb and
 * then the values of `view` (NULL: none), in a larger buffer only when they
 * do not fit. */
void fill_buffer(guint8 **buffer, guint *capacity, tvbuff_t *tvb, guint length, const dg_view *view)
{
    guint values = view ? view->count : 0;
    guint size = values ? view_start(length) + values * (guint)sizeof(dg_view_value) : length;
    if (size > *capacity || !*buffer) {
        wmem_free(wmem_file_scope(), *buffer);
        *buffer = size ? (guint8 *)wmem_alloc(wmem_file_scope(), size) : NULL;
        *capacity = size;
    }
    if (length) tvb_memcpy(tvb, *buffer, 0, length);
    if (values) memcpy(*buffer + view_start(length), view->values, values * sizeof(dg_view_value));
}

/* The view kept after a message's `length` bytes by fill_buffer(). */
dg_view kept_view(const guint8 *buffer, guint length, guint count)
{
    dg_view v = {count ? (const dg_view_value *)(const void *)(buffer + view_start(length)) : NULL, count, NULL};
    return v;
}

void remember_last(capture_state *c, key_entry *e, tvbuff_t *tvb, packet_info *pinfo, guint length, guint8 role)
{
    unlink_entry(c, e);
    e->older = c->newest;
    if (c->newest)
        c->newest->newer = e;
    else
        c->oldest = e;
    c->newest = e;
    e->last_time = pinfo->abs_ts;
    e->last_role = role;
    e->last_frame = pinfo->num;
    /* Mostly the key's previous message came from the same source with as
     * many bytes: its address and buffer serve again. */
    if (!addresses_equal(&e->last_src, &pinfo->src)) {
        drop_address(&e->last_src, e->last_src_bytes);
        keep_address(&e->last_src, e->last_src_bytes, &pinfo->src);
    }
    fill_buffer(&e->last_bytes, &e->last_capacity, tvb, length, c->view);
    e->last_length = length;
    e->last_captured = tvb_captured_length(tvb);
    e->last_view_count = c->view ? c->view->count : 0;
}

/* Answered or given up: what it kept goes now, the rest once both queues let go. */
void retire(capture_state *c, pending *q)
{
    if (q->done) return;
    q->done = TRUE;
    if (!q->answered) c->waiting--;
    if (q->guessed) c->guessed--;
    if (q->bytes && (!c->spare || q->capacity > c->spare_capacity)) {
        wmem_free(wmem_file_scope(), c->spare);
        c->spare = q->bytes;
        c->spare_capacity = q->capacity;
    } else {
        wmem_free(wmem_file_scope(), q->bytes);
    }
    q->bytes = NULL;
    drop_address(&q->src, q->src_bytes);
}

/* Given up unanswered while the current message was paired: that message
 * proves it lost (its expert info goes there in one pass). A group request
 * answered is only retired: it waited for more answers, and had one. */
void give_up(capture_state *c, pending *q)
{
    if (q->done) return;
    if (q->answered) {
        /* a group request answered: no more answers are waited for */
        recycle(&c->free_transactions, q->txn);
        q->txn = NULL;
        retire(c, q);
        return;
    }
    q->txn->given_up_in = c->frame;
    if (c->lost_count == c->lost_capacity) {
        c->lost_capacity = c->lost_capacity ? 2 * c->lost_capacity : 4;
        c->lost = (dg_lost *)wmem_realloc(wmem_file_scope(), c->lost, c->lost_capacity * sizeof(dg_lost));
    }
    c->lost[c->lost_count].txn = q->txn;
    c->lost[c->lost_count].key = q->key;
    c->lost_count++;
    retire(c, q);
}

void release(capture_state *c, pending *q)
{
    if (--q->queues == 0) recycle(&c->free_pending, q);
}

/* A response may come back after those of later requests (a reordering, or
 * capture interfaces with their own clocks), but not after this many. */
const guint64 max_overtaken = 16;

gboolean given_up(const capture_state *c, const pending *q, const packet_info *pinfo, double timeout)
{
    if (overtaken(c, q->txn, max_overtaken)) return TRUE;
    nstime_t age;
    nstime_delta(&age, &pinfo->abs_ts, &q->txn->request_time);
    return nstime_to_sec(&age) > timeout;
}

/* Takes a done request off the head of a queue. `in_key` says which link the
 * queue uses. */
void drop_head(capture_state *c, queue *qu, gboolean in_key)
{
    pending *q = qu->head;
    qu->head = in_key ? q->next : q->next_sent;
    if (!qu->head) qu->tail = NULL;
    release(c, q);
}

/* The oldest request of a queue still waiting (given-up ones retired on the
 * way), or NULL. */
pending *oldest_waiting(capture_state *c, queue *qu, gboolean in_key, const packet_info *pinfo)
{
    while (qu->head) {
        pending *q = qu->head;
        if (!q->done && given_up(c, q, pinfo, protocol->pairing->timeout)) give_up(c, q);
        if (!q->done) return q;
        drop_head(c, qu, in_key);
    }
    return NULL;
}

void give_up_all(capture_state *c, queue *qu, const packet_info *pinfo)
{
    for (pending *q; (q = oldest_waiting(c, qu, TRUE, pinfo));) give_up(c, q);
}

/* The pending request of this key that this message answers, or NULL when
 * the message is a new request. */
pending *take_answered(capture_state *c, key_entry *e, tvbuff_t *tvb, packet_info *pinfo, guint length,
                       gboolean unchanged)
{
    pending *q = oldest_waiting(c, &e->waiting, TRUE, pinfo);
    if (!q) return NULL;
    int verdict = analysis && analysis->is_response ? analysis->is_response(c->analysis, &q->src, &pinfo->src) : -1;
    /* The very request again, from its sender: a repetition, not an answer
     * (unless it came straight back unchanged). */
    if (e->last_frame == q->txn->request_frame && e->last_length == length &&
        addresses_equal(&q->src, &pinfo->src) && tvb_memeql(tvb, 0, e->last_bytes, length) == 0 && !unchanged)
        verdict = 0;
    if (verdict == 0) {
        /* The sender sent the same key again: what was pending is given up. */
        give_up_all(c, &e->waiting, pinfo);
        return NULL;
    }
    return q;
}

/* A response that answers nothing pending of its key (its key came back
 * changed): once the capture has shown a pair, when exactly one request is
 * waiting, its sender fits and the analysis sees the same request in it but
 * for the key, it is that one's. (With several waiting, a capture that missed
 * frames could not be told from one whose keys changed; a response to another
 * request, whose own request was not captured, is an orphan.) */
pending *take_oldest(capture_state *c, packet_info *pinfo)
{
    /* Before the first pair, a response is far likelier one whose request
     * was sent before the capture started. */
    if (!c->answered_max) return NULL;
    pending *q = oldest_waiting(c, &c->sent, FALSE, pinfo);
    while (q && (q->done || q->answered)) q = q->next_sent;
    if (!q || c->waiting != 1 || !analysis || !analysis->is_response || analysis->is_response(c->analysis, &q->src, &pinfo->src) != 1)
        return NULL;
    if (analysis->key_changed && q->bytes) {
        const dg_view request = kept_view(q->bytes, q->length, q->view_count);
        if (!analysis->key_changed(&request, c->view)) return NULL;
    }
    return q;
}

void enqueue(queue *qu, pending *q, gboolean in_key)
{
    if (qu->tail) {
        if (in_key)
            qu->tail->next = q;
        else
            qu->tail->next_sent = q;
    } else {
        qu->head = q;
    }
    qu->tail = q;
    q->queues++;
}

/* --- what the first pass forgets --------------------------------------------
 * Keys that are never used again (an ENIP sender context, a generated
 * capture's random EtherCAT indexes) would otherwise keep their entry, their
 * last message's bytes and their unanswered requests' bytes for the whole
 * capture. Nothing decides anything about them after `stale_after` timeouts
 * (duplicates need a hundredth of one, answers one), so a request that old is
 * given up now and a key entry that old is removed: a message with that key
 * later finds a fresh entry, which behaves exactly as the stale one would.
 * The margin keeps captures whose clocks step back a little (two interfaces)
 * paired as before. Forgetting goes by a clock of its own: the earlier of
 * the last two messages' times. One message stamped an hour ahead (a merge, a
 * broken timestamp) then moves nothing, while a real gap in the capture is
 * followed from its second message on. */
const double stale_after = 10;

void forget_clock(capture_state *c, const packet_info *pinfo)
{
    if (!c->clock_set) {
        c->clock = c->previous_time = pinfo->abs_ts;
        c->clock_set = TRUE;
        return;
    }
    c->clock = nstime_cmp(&pinfo->abs_ts, &c->previous_time) < 0 ? pinfo->abs_ts : c->previous_time;
    c->previous_time = pinfo->abs_ts;
}

/* Whether `then` is more than stale_after timeouts away from the clock, either
 * way: an entry stamped far ahead of it goes too, so that it does not hold up
 * the entries behind it in the list. */
gboolean long_ago(const capture_state *c, const nstime_t *then)
{
    nstime_t age;
    nstime_delta(&age, &c->clock, then);
    return fabs(nstime_to_sec(&age)) > stale_after * protocol->pairing->timeout;
}

/* Whether a request sent `then` has waited longer than the timeout, by the
 * forgetting clock (one message stamped far ahead proves nothing lost). */
gboolean timed_out(const capture_state *c, const nstime_t *then)
{
    nstime_t age;
    nstime_delta(&age, &c->clock, then);
    return nstime_to_sec(&age) > protocol->pairing->timeout;
}

/* Requests at the head of the capture's queue that nothing can answer any
 * more (overtaken, or older than the timeout): lost, as this message proves. */
void forget_requests(capture_state *c)
{
    while (c->sent.head) {
        pending *q = c->sent.head;
        if (!q->done) {
            if (!overtaken(c, q->txn, max_overtaken) && !timed_out(c, &q->txn->request_time)) return;
            give_up(c, q);
        }
        drop_head(c, &c->sent, FALSE);
    }
}

/* Whether a message of this transport and direction is paired with its
 * client as one more key value (with_client): over TCP or UDP, when its
 * direction is known. */
gboolean keyed_by_client(const packet_info *pinfo, guint8 direction)
{
    return (pinfo->ptype == PT_TCP || pinfo->ptype == PT_UDP) &&
           (direction == DG_DIR_REQUEST || direction == DG_DIR_RESPONSE);
}

/* Whether a message to `a` goes to a group of stations: an IPv4 multicast
 * address or the limited broadcast, an IPv6 multicast address, an Ethernet
 * multicast or broadcast address (its group bit). (A subnet's broadcast
 * address cannot be told from a station's here.) */
gboolean group_address(const address *a)
{
    const guint8 *b = (const guint8 *)a->data;
    if (a->type == AT_ETHER && a->len == 6) return (b[0] & 1) != 0;
    if (a->type == AT_IPv4 && a->len == 4)
        return (b[0] & 0xf0) == 0xe0 || (b[0] == 0xff && b[1] == 0xff && b[2] == 0xff && b[3] == 0xff);
    return a->type == AT_IPv6 && a->len == 16 && b[0] == 0xff;
}

/* Whether a request goes to a group of stations: by its address, or over
 * UDP by the link layer's broadcast address (a subnet's broadcast,
 * 192.168.1.255, which its IP address does not tell from a station's). Not
 * any multicast MAC: a unicast IP address may sit behind one (a cluster). */
gboolean group_request(const packet_info *pinfo)
{
    static const guint8 all_ones[6] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
    const address *mac = &pinfo->dl_dst;
    return group_address(&pinfo->dst) || (pinfo->ptype == PT_UDP && mac->type == AT_ETHER && mac->len == 6 &&
                                          memcmp(mac->data, all_ones, 6) == 0);
}

/* A new request over UDP sent to a group address: its client (its keys'
 * last value, with_client) becomes the one a response sent to a group with
 * the same key values goes to (with_client). */
void remember_group_client(capture_state *c, const packet_info *pinfo, guint8 direction, const guint64 *keys,
                           guint key_count)
{
    if (pinfo->ptype != PT_UDP || !keyed_by_client(pinfo, direction) || !group_address(&pinfo->dst)) return;
    pair_key probe = {key_count - 1, (guint64 *)keys};
    guint64 *client = (guint64 *)wmem_map_lookup(c->group_clients, &probe);
    if (!client) {
        pair_key *key = wmem_new(wmem_file_scope(), pair_key);
        key->count = key_count - 1;
        key->values = (guint64 *)wmem_memdup(wmem_file_scope(), keys, key->count * sizeof(guint64));
        client = wmem_new(wmem_file_scope(), guint64);
        wmem_map_insert(c->group_clients, key, client);
    }
    *client = keys[key_count - 1];
}

/* The group client remembered for the key values of `key` (with its client
 * last) is let go of with the key's entry, unless a later request's client
 * took its place: the map holds no more than the key entries. */
void forget_group_client(capture_state *c, const pair_key *key)
{
    if (key->count == 0) return;
    pair_key probe = {key->count - 1, key->values};
    const void *stored;
    void *client;
    if (!wmem_map_lookup_extended(c->group_clients, &probe, &stored, &client) ||
        *(const guint64 *)client != key->values[key->count - 1])
        return;
    wmem_map_remove(c->group_clients, &probe);
    pair_key *kept_key = (pair_key *)(void *)stored;
    wmem_free(wmem_file_scope(), kept_key->values);
    wmem_free(wmem_file_scope(), kept_key);
    wmem_free(wmem_file_scope(), client);
}

/* Removes e and what it keeps. Its requests are given up: its last message,
 * and so each of them, is long ago. */
void forget_key(capture_state *c, key_entry *e)
{
    for (pending *q = e->waiting.head, *next; q; q = next) {
        next = q->next;
        give_up(c, q);
        release(c, q);
    }
    unlink_entry(c, e);
    forget_group_client(c, e->key);
    wmem_map_remove(c->keys, e->key);
    wmem_free(wmem_file_scope(), e->key->values);
    wmem_free(wmem_file_scope(), e->key);
    wmem_free(wmem_file_scope(), e->last_bytes);
    drop_address(&e->last_src, e->last_src_bytes);
    wmem_free(wmem_file_scope(), e);
}

/* Key entries whose last message is long ago, least recently used first. */
void forget_keys(capture_state *c)
{
    while (c->oldest && long_ago(c, &c->oldest->last_time)) forget_key(c, c->oldest);
}

/* The key's waiting requests from this message's source are given up: the
 * sender used the key again, so it no longer waits for them. */
void give_up_sent_again(capture_state *c, key_entry *e, const packet_info *pinfo)
{
    for (pending *q = e->waiting.head; q; q = q->next)
        if (!q->done && addresses_equal(&q->src, &pinfo->src)) give_up(c, q);
}

/* The key's group requests that were answered wait no more (give_up
 * retires them quietly). */
void retire_answered_groups(capture_state *c, key_entry *e)
{
    for (pending *q = e->waiting.head; q; q = q->next)
        if (!q->done && q->answered) give_up(c, q);
}

/* Messages taken for requests only for want of a better idea, from a source
 * now known to send responses only (a slave's marked return), were
 * responses whose requests were not captured: orphans, not lost. */
void orphan_guessed_from(capture_state *c, const packet_info *pinfo)
{
    for (pending *q = c->sent.head; q && c->guessed; q = q->next_sent) {
        if (q->done || !q->guessed || !addresses_equal(&q->src, &pinfo->src)) continue;
        q->record->role = DG_ROLE_ORPHAN;
        set_answered(c, q->record);
        retire(c, q);
        recycle(&c->free_transactions, q->txn); /* retired without a loss: nothing names it */
    }
}

/* A message known to be a response: of its key's waiting requests the
 * oldest whose source says it is answered (the analysis' is_response), else
 * the oldest it does not rule out; else the one request waiting if its key
 * came back changed (take_oldest); NULL: an orphan. */
pending *take_response(capture_state *c, key_entry *e, packet_info *pinfo)
{
    oldest_waiting(c, &e->waiting, TRUE, pinfo); /* gives up the expired ones */
    pending *maybe = NULL, *group = NULL;
    for (pending *q = e->waiting.head; q; q = q->next) {
        if (q->done) continue;
        int verdict = analysis && analysis->is_response ? analysis->is_response(c->analysis, &q->src, &pinfo->src) : -1;
        if (q->answered) { /* a group request answered: only when no request waits for its first */
            if (verdict != 0 && !group) group = q;
            continue;
        }
        if (verdict == 1) {
            if (c->guessed) orphan_guessed_from(c, pinfo);
            return q;
        }
        if (verdict < 0 && !maybe) maybe = q;
    }
    if (maybe) return maybe;
    return group ? group : take_oldest(c, pinfo);
}

/* A message its own bytes cannot place (the analysis has a direction()):
 * the key's waiting request come back untouched, soon after it was sent, or
 * NULL (a new request). */
pending *take_unchanged(capture_state *c, key_entry *e, tvbuff_t *tvb, packet_info *pinfo, guint length)
{
    pending *q = oldest_waiting(c, &e->waiting, TRUE, pinfo);
    if (!q || !q->bytes || !within_copy_window(e, &q->txn->request_time, pinfo)) return NULL;
    tvbuff_t *request = tvb_new_real_data(q->bytes, q->length, (gint)q->length);
    const dg_view request_view = kept_view(q->bytes, q->length, q->view_count);
    gboolean same = analysis->unchanged ? analysis->unchanged(request, &request_view, tvb, length)
                                        : q->length == length && tvb_memeql(tvb, 0, q->bytes, length) == 0;
    tvb_free(request);
    /* Lets the analysis learn from the two sources (a marked return). */
    if (same && analysis->is_response && analysis->is_response(c->analysis, &q->src, &pinfo->src) == 0) return NULL;
    return same ? q : NULL;
}

/* What the message is: the transport's direction, else what the analysis
 * reads from the message itself. */
guint8 direction_of(capture_state *c, tvbuff_t *tvb, packet_info *pinfo, guint8 transport)
{
    if (transport != DG_DIR_ANY || !analysis || !analysis->direction) return transport;
    return analysis->direction(c->analysis, tvb, c->view, pinfo);
}

/* The requests this message proved lost go with its record (rare: a map
 * beside the frame table). */
void with_lost(capture_state *c, kept *k)
{
    if (!c->lost_count) return;
    wmem_map_insert(c->lost_lists, k, wmem_memdup(wmem_file_scope(), c->lost, c->lost_count * sizeof(dg_lost)));
    k->lost_count = (guint16)MIN(c->lost_count, G_MAXUINT16);
}

/* This message, k, answers transaction t: its record names the request and
 * keeps the round trip (t's too). */
void link_response(capture_state *c, dg_transaction *t, kept *k, packet_info *pinfo)
{
    k->role = DG_ROLE_RESPONSE;
    nstime_delta(&t->round_trip, &pinfo->abs_ts, &t->request_time);
    k->partner = t->request_frame;
    /* nstime_delta gives seconds and nanoseconds of one sign: exact both ways. */
    gint64 ns = dg_periods::ns_of(&t->round_trip);
    if (ns > long_trip && ns <= G_MAXINT32) {
        k->round_trip = (gint32)ns;
    } else {
        k->round_trip = long_trip;
        wmem_map_insert(c->long_trips, k, wmem_memdup(wmem_file_scope(), &ns, sizeof ns));
    }
    c->just_answered = k;
    c->just_answered_seq = t->seq;
}

/* The analysis compares response k with its request's bytes (and view). */
void compare_with_request(capture_state *c, dg_transaction *t, const guint8 *request_bytes, guint request_length,
                          guint request_view_count, kept *k, tvbuff_t *tvb, packet_info *pinfo)
{
    if (!analysis || !analysis->compare || !request_bytes) return;
    tvbuff_t *bytes = tvb_new_real_data(request_bytes, request_length, (gint)request_length);
    const dg_view request_view = kept_view(request_bytes, request_length, request_view_count);
    k->analysis = analysis->compare(c->analysis, bytes, &request_view, tvb, c->view, t, pinfo);
    tvb_free(bytes);
}

/* This message, k, is the first answer to transaction t, whose request's
 * record and bytes (and view) are given. Unless `keep` (a group request,
 * which more answers may follow), the transaction is freed: the two records
 * say what it did. */
void response_to(capture_state *c, dg_transaction *t, kept *request, const guint8 *request_bytes,
                 guint request_length, guint request_view_count, kept *k, tvbuff_t *tvb, packet_info *pinfo,
                 gboolean keep = FALSE)
{
    t->response_frame = pinfo->num;
    link_response(c, t, k, pinfo);
    guint64 *answered = answered_in(c, t);
    k->out_of_order = protocol->pairing->ordered && t->order_seq < *answered;
    if (t->order_seq > *answered) *answered = t->order_seq;
    if (t->seq > c->answered_max) c->answered_max = t->seq;
    compare_with_request(c, t, request_bytes, request_length, request_view_count, k, tvb, pinfo);
    request->partner = pinfo->num;
    set_answered(c, request);
    if (!keep) recycle(&c->free_transactions, t);
}

/* Message k answers group request q again (another station of the group):
 * never out of order, as the stations answer in no order of their own. */
void answer_again(capture_state *c, pending *q, kept *k, tvbuff_t *tvb, packet_info *pinfo)
{
    link_response(c, q->txn, k, pinfo);
    compare_with_request(c, q->txn, q->bytes, q->length, q->view_count, k, tvb, pinfo);
    wmem_array_t *more = (wmem_array_t *)wmem_map_lookup(c->more_responses, q->record);
    if (!more) {
        more = wmem_array_sized_new(wmem_file_scope(), sizeof(guint32), 4);
        wmem_map_insert(c->more_responses, q->record, more);
    }
    wmem_array_append_one(more, pinfo->num);
}

void answer(capture_state *c, pending *q, kept *k, tvbuff_t *tvb, packet_info *pinfo)
{
    if (q->answered) {
        answer_again(c, q, k, tvb, pinfo);
        return;
    }
    response_to(c, q->txn, q->record, q->bytes, q->length, q->view_count, k, tvb, pinfo, q->group);
    if (q->group) {
        q->answered = TRUE; /* waits for the other stations' answers */
        c->waiting--;       /* ... but for no first one */
        return;
    }
    q->txn = NULL; /* freed: a retired request is never looked at again */
    retire(c, q);
}

/* A response with nothing to answer, right after an orphan of its key from
 * the same sender (or the same one with the returned-frame mark): that
 * "orphan" was its request after all, one sent with a working counter above
 * 0 (which only a faulty master does) or the first frame of a capture whose
 * marking was not known yet. It becomes the request, answered by this one.
 * (In one pass it was shown as an orphan already.) Only where the analysis
 * guessed the direction: a transport's direction is never wrong. */
gboolean adopt_orphan(capture_state *c, key_entry *e, kept *k, tvbuff_t *tvb, packet_info *pinfo)
{
    if (e->last_role != DG_ROLE_ORPHAN || !e->last_record) return FALSE;
    nstime_t gap;
    nstime_delta(&gap, &pinfo->abs_ts, &e->last_time);
    if (nstime_to_sec(&gap) > protocol->pairing->timeout) return FALSE;
    int verdict = analysis && analysis->is_response ? analysis->is_response(c->analysis, &e->last_src, &pinfo->src) : -1;
    if (verdict == 0 || (verdict < 0 && !addresses_equal(&e->last_src, &pinfo->src))) return FALSE;
    dg_transaction *t = new_recycled<dg_transaction>(&c->free_transactions);
    t->request_frame = e->last_frame;
    t->request_time = e->last_time;
    t->seq = ++c->requests;
    place_in_order(c, t, pinfo);
    kept *request = e->last_record;
    request->role = DG_ROLE_REQUEST;
    response_to(c, t, request, e->last_bytes, e->last_length, e->last_view_count, k, tvb, pinfo);
    return TRUE;
}

/* This message, k, is a new request: it waits for its response, a new
 * transaction (returned). */
dg_transaction *new_request(capture_state *c, key_entry *e, kept *k, tvbuff_t *tvb, packet_info *pinfo, guint length,
                 guint64 key, gboolean guessed, gboolean group)
{
    if (analysis && analysis->sent) k->analysis = analysis->sent(c->analysis, tvb, c->view, pinfo);
    /* Kept until it is answered (response_to frees it; a group request's
     * when it is retired, give_up), or for good when it is not. */
    dg_transaction *t = new_recycled<dg_transaction>(&c->free_transactions);
    t->request_frame = pinfo->num;
    t->request_time = pinfo->abs_ts;
    t->seq = ++c->requests;
    place_in_order(c, t, pinfo);
    k->role = DG_ROLE_REQUEST;
    set_unanswered(c, k, t);
    if (!nstime_is_zero(&e->last_request_time) && nstime_cmp(&pinfo->abs_ts, &e->last_request_time) > 0)
        nstime_delta(&e->request_period, &pinfo->abs_ts, &e->last_request_time);
    e->last_request_time = pinfo->abs_ts;
    pending *n = new_recycled<pending>(&c->free_pending);
    n->txn = t;
    n->key = key;
    n->record = k;
    n->guessed = guessed;
    n->group = group;
    if (guessed) c->guessed++;
    keep_address(&n->src, n->src_bytes, &pinfo->src);
    if (analysis && analysis->compare) {
        if (length && c->spare && c->spare_capacity >= length) {
            n->bytes = c->spare;
            n->capacity = c->spare_capacity;
            c->spare = NULL;
        }
        fill_buffer(&n->bytes, &n->capacity, tvb, length, c->view);
        n->length = length;
        n->view_count = c->view ? c->view->count : 0;
    }
    enqueue(&e->waiting, n, TRUE);
    enqueue(&c->sent, n, FALSE);
    c->waiting++;
    return t;
}

/* The pending request this message answers, or NULL for a new request
 * (`orphan` set: a response whose request was not captured). */
pending *classify(capture_state *c, key_entry *e, tvbuff_t *tvb, packet_info *pinfo, guint length, guint8 direction,
                  gboolean unchanged, gboolean *orphan)
{
    *orphan = FALSE;
    pending *q = NULL;
    /* Only a response answers a group request again: another message of the
     * key is a request, or where the order decides the next exchange's. */
    if (direction != DG_DIR_RESPONSE) retire_answered_groups(c, e);
    if (direction == DG_DIR_RESPONSE) {
        q = take_response(c, e, pinfo);
        *orphan = !q;
    } else if (direction == DG_DIR_REQUEST) {
        give_up_sent_again(c, e, pinfo);
    } else if (analysis && analysis->direction) {
        q = take_unchanged(c, e, tvb, pinfo, length);
        if (!q) give_up_sent_again(c, e, pinfo);
    } else {
        /* Neither the transport nor an analysis can tell: the order decides. */
        q = take_answered(c, e, tvb, pinfo, length, unchanged);
        if (!q && analysis && analysis->is_returned && analysis->is_returned(c->analysis, &pinfo->src)) {
            q = take_oldest(c, pinfo);
            *orphan = !q;
        }
    }
    return q;
}

/* Pairs message k on the first pass and fills its record. Returns the
 * transaction of a new request (capture_state.unanswered has it too), else NULL. */
dg_transaction *first_pass(capture_state *c, kept *k, tvbuff_t *tvb, packet_info *pinfo, const guint64 *keys, guint key_count,
                const dg_view *view, guint length, guint8 transport_direction)
{
    c->frame = pinfo->num;
    c->view = view;
    c->lost_count = 0;
    forget_clock(c, pinfo);
    forget_requests(c);
    forget_keys(c);
    if (analysis && analysis->see) analysis->see(c->analysis, tvb, view, pinfo);
    guint8 verdict = direction_of(c, tvb, pinfo, transport_direction);
    guint8 direction = verdict & ~DG_DIR_FROM_SOURCE;
    if (verdict == (DG_DIR_RESPONSE | DG_DIR_FROM_SOURCE) && c->guessed) orphan_guessed_from(c, pinfo);
    key_entry *e = entry_for(c, keys, key_count);
    gboolean again = same_again(c, e, tvb, pinfo, length);
    gboolean unchanged = again && direction != DG_DIR_REQUEST && unchanged_return(e);
    c->last_frame = pinfo->num;
    if (again && !unchanged) {
        k->role = DG_ROLE_DUPLICATE;
        k->partner = e->last_frame;
        with_lost(c, k);
        return NULL;
    }
    if (unchanged) direction = DG_DIR_ANY; /* the waiting request, come back */

    gboolean orphan;
    dg_transaction *t = NULL;
    pending *q = classify(c, e, tvb, pinfo, length, direction, unchanged, &orphan);
    e->last_answered = q ? q->txn->values : NULL;
    if (q)
        answer(c, q, k, tvb, pinfo);
    else if (orphan && transport_direction == DG_DIR_ANY && adopt_orphan(c, e, k, tvb, pinfo))
        ;
    else if (orphan)
        k->role = DG_ROLE_ORPHAN;
    else {
        t = new_request(c, e, k, tvb, pinfo, length, keys[0], direction == DG_DIR_ANY,
                        transport_direction == DG_DIR_REQUEST && group_request(pinfo));
        remember_group_client(c, pinfo, transport_direction, keys, key_count);
    }
    remember_last(c, e, tvb, pinfo, length, k->role);
    e->last_record = k;
    with_lost(c, k);
    return t;
}

/* What later passes show of record k (the first pass too, so that every pass
 * shows the same), in pinfo->pool: the frame's record and its transaction as
 * dissgen_pairing.h has them. `fresh`: the transaction the first pass just
 * made for k, a new request (else NULL: capture_state.unanswered has it). */
const dg_frame_pairing *view_of(const capture_state *c, const kept *k, packet_info *pinfo,
                                const dg_transaction *fresh)
{
    struct view {
        dg_frame_pairing fp;
        dg_transaction txn;
    };
    view *v = wmem_new0(pinfo->pool, view);
    dg_frame_pairing *fp = &v->fp;
    fp->role = k->role;
    fp->out_of_order = k->out_of_order;
    fp->lost_count = k->lost_count;
    fp->analysis = k->analysis;
    if (k->lost_count) fp->lost = (const dg_lost *)wmem_map_lookup(c->lost_lists, k);
    switch (k->role) {
    case DG_ROLE_REQUEST:
        if (!k->partner) {
            /* not answered: its own transaction */
            fp->txn = fresh ? (dg_transaction *)fresh : unanswered_of(c, k);
            break;
        }
        v->txn.request_frame = pinfo->num;
        v->txn.response_frame = k->partner;
        fp->txn = &v->txn;
        if (wmem_array_t *more = (wmem_array_t *)wmem_map_lookup(c->more_responses, k)) {
            fp->more_responses = (const guint32 *)wmem_array_get_raw(more);
            fp->more_response_count = wmem_array_get_count(more);
        }
        break;
    case DG_ROLE_RESPONSE: {
        v->txn.request_frame = k->partner;
        v->txn.response_frame = pinfo->num;
        gint64 ns = k->round_trip;
        if (k->round_trip == long_trip) ns = *(const gint64 *)wmem_map_lookup(c->long_trips, k);
        v->txn.round_trip.secs = (time_t)(ns / 1000000000);
        v->txn.round_trip.nsecs = (int)(ns % 1000000000);
        fp->txn = &v->txn;
        break;
    }
    case DG_ROLE_DUPLICATE:
        fp->duplicate_of = k->partner;
        break;
    default: break;
    }
    return fp;
}

/* A request not answered: lost when a later message proved it (given_up_in),
 * or, once the capture has been read, when a later request was answered (the
 * first pass waits for max_overtaken of them, in case of reordering, which
 * the end of the capture cuts short) or the capture went on for longer than
 * the timeout after it. One sent at the capture's very end is in flight. */
gboolean known_lost(const dg_transaction *t)
{
    if (t->given_up_in) return TRUE;
    if (!capture) return FALSE;
    if (overtaken(capture, t, 0)) return TRUE;
    nstime_t waited;
    nstime_delta(&waited, &capture->previous_time, &t->request_time);
    return nstime_to_sec(&waited) > protocol->pairing->timeout;
}

/* The first key's value as its field shows it: decimal for a decimal field
 * (signed for a signed one), hex padded to the field's width otherwise, so
 * that the note names the request the way its tree does. */
const char *key_text(packet_info *pinfo, guint64 key)
{
    dg_rt::dg_text *text = dg_rt::text_new(pinfo->pool);
    if (key_node)
        dg_rt::append_number(text, key_node, key);
    else
        dg_rt::append_hex(text, key, 16);
    return text->data;
}

/* The requests this message proved lost, each linked. The expert info goes
 * here in the first pass (one pass, a live capture), where nothing later can
 * be shown; once the capture has been read (tshark -2, the GUI) it sits on
 * the lost request itself and this message keeps the link. */
void show_lost(const dg_frame_pairing *fp, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    for (guint i = 0; i < fp->lost_count; i++) {
        const dg_lost *l = &fp->lost[i];
        proto_item *item = proto_tree_add_uint(tree, hf_no_response_to, tvb, 0, 0, l->txn->request_frame);
        proto_item_set_generated(item);
        if (PINFO_FD_VISITED(pinfo)) continue;
        nstime_t since;
        nstime_delta(&since, &pinfo->abs_ts, &l->txn->request_time);
        proto_tree_add_expert_format(tree, pinfo, &ei_no_response, tvb, 0, 0,
                                     "No response to frame %u (%s %s), sent %.3f ms before",
                                     l->txn->request_frame, key_name, key_text(pinfo, l->key), nstime_to_msec(&since));
    }
}

void show(const dg_frame_pairing *fp, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    proto_item *item;
    const dg_transaction *t = fp->txn;
    switch (fp->role) {
    case DG_ROLE_REQUEST:
        if (t->response_frame) {
            item = proto_tree_add_uint(tree, hf_response_in, tvb, 0, 0, t->response_frame);
            proto_item_set_generated(item);
            for (guint i = 0; i < fp->more_response_count; i++) {
                item = proto_tree_add_uint(tree, hf_response_in, tvb, 0, 0, fp->more_responses[i]);
                proto_item_set_generated(item);
            }
        } else if (PINFO_FD_VISITED(pinfo) && known_lost(t)) {
            /* Only once the whole capture has been read can "never" be said
             * here; in one pass the frame that proved it says so (show_lost). */
            if (t->given_up_in)
                proto_tree_add_expert_format(tree, pinfo, &ei_no_response, tvb, 0, 0,
                                             "No response seen (given up in frame %u)", t->given_up_in);
            else
                proto_tree_add_expert(tree, pinfo, &ei_no_response, tvb, 0, 0);
        }
        break;
    case DG_ROLE_RESPONSE:
        item = proto_tree_add_uint(tree, hf_request_in, tvb, 0, 0, t->request_frame);
        proto_item_set_generated(item);
        item = proto_tree_add_time(tree, hf_time, tvb, 0, 0, &t->round_trip);
        proto_item_set_generated(item);
        if (fp->out_of_order)
            proto_tree_add_expert_format(tree, pinfo, &ei_out_of_order, tvb, 0, 0,
                                         "Response to frame %u came back after the response to a later request",
                                         t->request_frame);
        if (analysis && analysis->show && fp->analysis)
            analysis->show(current_capture()->analysis, fp->analysis, tvb, pinfo, tree);
        break;
    case DG_ROLE_ORPHAN:
        item = proto_tree_add_item(tree, hf_no_request, tvb, 0, 0, ENC_NA);
        proto_item_set_generated(item);
        break;
    case DG_ROLE_DUPLICATE:
        proto_tree_add_expert_format(tree, pinfo, &ei_duplicate, tvb, 0, 0,
                                     "Duplicate of frame %u (same source, same bytes); not paired", fp->duplicate_of);
        break;
    default: break;
    }
    if (fp->role == DG_ROLE_REQUEST && analysis && analysis->show_sent && fp->analysis)
        analysis->show_sent(current_capture()->analysis, fp->analysis, tvb, pinfo, tree);
    if (fp->lost_count) show_lost(fp, tvb, pinfo, tree);
}

/* --- statistics ---------------------------------------------------------- */

const char *const st_pairing = "Requests and responses";
const char *const st_requests = "Requests";
const char *const st_responses = "Responses";
const char *const st_lost = "No response";
const char *const st_duplicates = "Duplicates";
const char *const st_orphans = "Responses to requests not captured";
const char *const st_rtt = "Round trip (ms)";
int st_pairing_id;

} /* namespace */

extern "C" {

void dg_pairing_register(const dg_protocol *p)
{
    protocol = p;
    analysis = p->pairing->analysis; /* the generated code names it */

    /* Wireshark keeps pointers to these: static arrays, names that live until exit. */
    static hf_register_info hf[] = {DG_PAIRING_FIELDS(DG_HF_ROW)};
    static const char *const names[] = {DG_PAIRING_FIELDS(DG_FIELD_NAME)};
    dg_name_fields(hf, names, G_N_ELEMENTS(hf), p->filter);
    for (guint i = 0; i < p->node_count; i++)
        if (p->nodes[i].flags & DG_KEY) {
            key_name = p->nodes[i].name;
            key_node = &p->nodes[i];
            break;
        }
    proto_register_field_array(*p->proto, hf, (int)G_N_ELEMENTS(hf));

    static ei_register_info ei[] = {DG_PAIRING_EXPERTS(DG_EI_ROW)};
    static const char *const ei_names[] = {DG_PAIRING_EXPERTS(DG_EXPERT_NAME)};
    dg_name_experts(ei, ei_names, G_N_ELEMENTS(ei), p->filter);
    expert_module_t *experts = expert_register_protocol(*p->proto);
    expert_register_field_array(experts, ei, (int)G_N_ELEMENTS(ei));

    if (p->request_context) dg_request_register(p, experts);
    if (analysis && analysis->register_info) analysis->register_info(*p->proto, p->filter);
    register_init_routine(capture_init);
    register_cleanup_routine(capture_cleanup);
}

namespace {

/* An endpoint as one key value: an address of up to 6 bytes and a port
 * are the value itself, a longer address (IPv6) with its port the 64-bit
 * FNV-1a hash. */
guint64 endpoint_key(const address *a, guint32 port)
{
    const guint8 *bytes = (const guint8 *)a->data;
    if (a->len > 6) return (dg_rt::fnv1a64(14695981039346656037ull, bytes, (gsize)a->len) ^ port) * 1099511628211ull;
    guint64 value = 0;
    for (int i = 0; i < a->len; i++) value = value << 8 | bytes[i];
    return value << 16 | (port & 0xffff);
}

/* Over TCP or UDP, when a message's direction is known, its client is one
 * more key value: a request's sender, a response's receiver (its address,
 * and over TCP its port). Over TCP the other end is one more (a request's
 * receiver, a response's sender, with its port): the key is the
 * connection, so that requests sent from a server's port on two
 * connections stay apart. Two clients using the same key values (Modbus/TCP
 * transaction 1 from two masters) are then paired apart, as Wireshark pairs
 * them by conversation. Over UDP the receiver is left out: a request sent
 * to a broadcast or multicast address is answered from the device's own;
 * a response sent to a group address names no client: it goes to the
 * client of the latest request with the same key values sent to a group
 * (remember_group_client; PTP's Delay_Resp to 224.0.1.129).
 * Returns the keys to pair by, and their count in *count. */
const guint64 *with_client(const guint64 *keys, guint *count, const packet_info *pinfo, guint8 direction)
{
    if (!keyed_by_client(pinfo, direction)) return keys;
    const gboolean request = direction == DG_DIR_REQUEST;
    const gboolean tcp = pinfo->ptype == PT_TCP;
    guint64 *out = wmem_alloc_array(pinfo->pool, guint64, *count + 2);
    memcpy(out, keys, *count * sizeof(guint64));
    guint64 client = endpoint_key(request ? &pinfo->src : &pinfo->dst,
                                  tcp ? (request ? pinfo->srcport : pinfo->destport) : 0);
    if (!tcp && !request && capture && group_address(&pinfo->dst)) {
        pair_key probe = {*count, (guint64 *)keys};
        const guint64 *group = (const guint64 *)wmem_map_lookup(capture->group_clients, &probe);
        if (group) client = *group;
    }
    out[(*count)++] = client;
    if (tcp)
        out[(*count)++] = endpoint_key(request ? &pinfo->dst : &pinfo->src, request ? pinfo->destport : pinfo->srcport);
    return out;
}

} // namespace

const dg_frame_pairing *dg_pairing_dissect(const dg_protocol *, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree,
                                           const guint64 *keys, guint key_count, const dg_view *view, gint length,
                                           guint message, guint8 direction)
{
    /* A message cut short before its first key field answers and asks nothing. */
    if (key_count == 0) return NULL;
    keys = with_client(keys, &key_count, pinfo, direction);
    kept *k = capture ? record_of(capture, pinfo, message, FALSE) : NULL;
    const dg_transaction *fresh = NULL;
    if (!k || !k->role) {
        if (PINFO_FD_VISITED(pinfo)) return NULL; /* not paired on the first pass: nothing to show */
        guint len = length > 0 ? (guint)length : tvb_captured_length(tvb);
        capture_state *c = current_capture();
        k = record_of(c, pinfo, message, TRUE);
        fresh = first_pass(c, k, tvb, pinfo, keys, key_count, view, len, direction);
    }
    const dg_frame_pairing *fp = view_of(capture, k, pinfo, fresh);
    if (!PINFO_FD_VISITED(pinfo) && fp->txn && k == capture->just_answered) fp->txn->seq = capture->just_answered_seq;
    show(fp, tvb, pinfo, tree);
    return fp;
}

const dg_request_values *dg_pairing_request_of(const guint64 *keys, guint key_count, tvbuff_t *tvb,
                                               const packet_info *pinfo, guint8 direction)
{
    if (!capture || key_count == 0) return NULL;
    keys = with_client(keys, &key_count, pinfo, direction);
    pair_key probe = {key_count, (guint64 *)keys};
    const key_entry *e = (const key_entry *)wmem_map_lookup(capture->keys, &probe);
    if (!e) return NULL;
    const pending *group = NULL; /* as take_response: a group request answered comes last */
    for (const pending *q = e->waiting.head; q; q = q->next) {
        if (q->done || given_up(capture, q, pinfo, protocol->pairing->timeout)) continue;
        if (!q->answered) return q->txn->values;
        if (!group) group = q;
    }
    if (group) return group->txn->values;
    /* a copy of the key's last response (same_again; the message's own length
     * is not known before its walk, its tvb's is) */
    const gboolean copy = e->last_answered && e->last_role == DG_ROLE_RESPONSE &&
                          tvb_captured_length(tvb) == e->last_captured && repeats_last(e, tvb, pinfo);
    return copy ? e->last_answered : NULL;
}

void dg_pairing_stats_init(const dg_protocol *, stats_tree *st)
{
    /* The section and its first rows, always in this order; the other rows
     * appear with their first count (no rows of zeros). */
    st_pairing_id = stats_tree_create_node(st, st_pairing, 0, STAT_DT_INT, TRUE);
    stats_tree_create_node(st, st_requests, st_pairing_id, STAT_DT_INT, FALSE);
    stats_tree_create_node(st, st_responses, st_pairing_id, STAT_DT_INT, FALSE);
    stats_tree_create_node(st, st_rtt, st_pairing_id, STAT_DT_FLOAT, FALSE);
    if (analysis && analysis->stats_init) analysis->stats_init(st, st_pairing_id);
}

void dg_pairing_stats_packet(const dg_protocol *, stats_tree *st, packet_info *, const dg_frame_pairing *fp)
{
    if (!fp) return;
    tick_stat_node(st, st_pairing, 0, TRUE);
    switch (fp->role) {
    case DG_ROLE_REQUEST:
        tick_stat_node(st, st_requests, st_pairing_id, FALSE);
        break;
    case DG_ROLE_RESPONSE:
        tick_stat_node(st, st_responses, st_pairing_id, FALSE);
        avg_stat_node_add_value_float(st, st_rtt, st_pairing_id, FALSE,
                                      (gfloat)(nstime_to_sec(&fp->txn->round_trip) * 1000.0));
        if (analysis && analysis->stats_response && fp->analysis)
            analysis->stats_response(current_capture()->analysis, st, st_pairing_id, fp->analysis);
        break;
    case DG_ROLE_DUPLICATE:
        tick_stat_node(st, st_duplicates, st_pairing_id, FALSE);
        break;
    case DG_ROLE_ORPHAN:
        tick_stat_node(st, st_orphans, st_pairing_id, FALSE);
        break;
    default: break;
    }
    /* Requests lost: those a later message proved lost, counted on that
     * message, and those only the capture's end shows (known_lost), counted
     * on themselves: the same as the expert infos, one pass or two. (A tap
     * cannot tell the passes apart: tshark marks a frame visited before its
     * taps run.) */
    guint lost = fp->lost_count;
    if (fp->role == DG_ROLE_REQUEST && !fp->txn->response_frame && !fp->txn->given_up_in && known_lost(fp->txn))
        lost++;
    if (lost) increase_stat_node(st, st_lost, st_pairing_id, FALSE, lost);
}

} /* extern "C" */

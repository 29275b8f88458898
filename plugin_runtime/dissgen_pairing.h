/* Request/response pairing across frames, declared in the rule
 * file by <pairing> (key fields) and used by every protocol the same way.
 *
 * State lives in Wireshark's per-capture memory (wmem_file_scope) and is
 * computed once, on the first pass over each frame (!PINFO_FD_VISITED):
 *
 *   capture state (one per open capture, reset by the init routine)
 *     key values -> pending requests (oldest first), the last message seen
 *     the analysis's capture-wide state (e.g. a model of the EtherCAT bus)
 *   frame state (a compact record per message: the capture's frame table,
 *   indexed by frame number, for a frame's first message; p_add_proto_data
 *   for the others), only what display needs: the role, the partner's
 *   frame, the round trip, the analysis's result; a request's transaction
 *   only while it is not answered (a group request's while it waits for more
 *   answers), and a group request's later answers. dg_pairing_dissect() hands out the
 *   record as a dg_frame_pairing (and its dg_transaction) in pinfo->pool.
 *
 * Later passes (tshark -2, the GUI in any order, display filters) only read
 * what the first pass stored, so they show the same items. A protocol
 * analysis (dg_analysis, each in its own folder, named by the generated
 * code in dg_pairing; EtherCAT's is ethercat/ethercat_analysis.cpp) adds what
 * one protocol knows about how its responses relate to its requests.
 */
#pragma once

#include "dissgen_runtime.h"

#include <epan/stats_tree.h>

/* One request and, once seen, its response. */
typedef struct dg_transaction {
    guint32 request_frame;
    guint32 response_frame;  /* 0: no response seen */
    nstime_t request_time;   /* pinfo->abs_ts of the request */
    nstime_t round_trip;     /* response time - request time */
    guint64 seq;             /* requests in capture order, from 1; a response's view
                              * has its request's on the first pass, 0 later */
    guint32 given_up_in;     /* no response: the frame that proved it (the key
                              * reused, the timeout passed); 0 while not known */
    guint32 order_scope;     /* the connection it was sent on (its order scope), 0 the capture's */
    guint64 order_seq;       /* its number among that scope's requests, from 1 */
    const struct dg_request_values *values; /* request{...}: what the request kept, or NULL */
} dg_transaction;

/* The values of the fields a request keeps for its responses
 * (dg_request_context.slots, in that order), in wmem_file_scope. */
typedef struct dg_request_values {
    guint count;
    guint64 *values;
    guint8 *present;         /* per value: the request had the field */
    /* per value, for a field kept by position (dg_request_context.by_position):
     * its instances (NULL when the request had none, or no field is kept so) */
    const struct dg_request_table *tables;
} dg_request_values;

/* A field's value in each instance of its repeated node, in a request. */
typedef struct dg_request_table {
    guint count;
    const guint64 *values;
    const guint8 *present;   /* per instance: decoded */
} dg_request_table;

/* The requests a message proved lost: each was given up while this message
 * was paired (its key reused, or its timeout passed). */
typedef struct dg_lost {
    const dg_transaction *txn;
    guint64 key;             /* its first key value, for the expert's text */
} dg_lost;

enum dg_role {
    DG_ROLE_REQUEST = 1,
    DG_ROLE_RESPONSE = 2,
    DG_ROLE_DUPLICATE = 3,
    DG_ROLE_ORPHAN = 4 /* a response (the analysis says so) whose request is not in the capture */
};

/* Or-ed into an analysis' direction(): the message's source alone says so,
 * and that source sends nothing the other way. */
enum { DG_DIR_FROM_SOURCE = 0x10 };

/* What the first pass found for one message of a frame. */
typedef struct dg_frame_pairing {
    dg_transaction *txn;     /* NULL for a duplicate */
    guint8 role;             /* dg_role */
    guint8 out_of_order;     /* response: a later request was answered first */
    guint16 lost_count;      /* requests this message proved lost */
    guint32 duplicate_of;    /* duplicate: the frame it repeats */
    guint32 analysis;        /* response: the analysis's comparison; request: its sent() result; 0 none */
    const dg_lost *lost;     /* lost_count of them, or NULL */
    /* request sent to a group: the answers after the first (txn->response_frame) */
    const guint32 *more_responses;
    guint more_response_count;
} dg_frame_pairing;

/* What an analysis reads from a message, as the walk decoded it: the
 * fields the rule file binds to the analysis's inputs (<pairing><input
 * name="..." field="..."/>), one value each in decoding order. The analysis
 * names its inputs by number (its list, e.g. ethercat/ethercat_inputs.h),
 * so it reads nothing from the bytes that the rules describe. Flat (no
 * pointers inside), so that the pairing keeps a request's view with its
 * bytes. */
typedef struct dg_view_value {
    guint64 value;
    gint32 offset;      /* of the field's bytes (its bit group's) in the message */
    guint16 length;     /* those bytes */
    guint8 input;       /* the analysis's input number */
    guint32 instance;   /* the instance of its repeated node (0 for a message's own input) */
} dg_view_value;

struct dg_cycle_input;

typedef struct dg_view {
    const dg_view_value *values;
    guint count;
    /* <cycles> with an analysis that times them (dg_analysis.times_cycles):
     * what the walk decoded for them in the message being dissected, first
     * pass; NULL otherwise, and in a request's view the pairing kept */
    const struct dg_cycle_input *cycle;
} dg_view;

/* The register the pairing's analysis reads as its input `input`, where
 * the rule file's register map puts it; NULL when the rule file binds none. */
static inline const dg_input_place *dg_input_place_of(const dg_protocol *p, guint input)
{
    const dg_pairing *pairing = p ? p->pairing : NULL;
    for (guint i = 0; pairing && i < pairing->place_count; i++)
        if (pairing->places[i].input == input) return &pairing->places[i];
    return NULL;
}

/* What one protocol knows about its requests and responses. Every callback
 * may be NULL. Those given a dg_view get the message's (and the request's);
 * its bytes come as a tvb for what the rules do not describe (e.g. whether
 * data came back unchanged). */
typedef struct dg_analysis {
    const char *name;        /* the rule file's <pairing analysis="..."> */
    /* TRUE: the analysis times the rule file's <cycles> itself, with what it
     * knows of the protocol (dg_view.cycle), under the names P.cycle...: the
     * generic cycle analysis (dissgen_cycles.h) stays out */
    gboolean times_cycles;
    /* Registers the analysis's own fields and expert infos (once, at start-up). */
    void (*register_info)(int proto, const char *filter);
    /* Capture-wide state, allocated in wmem_file_scope (e.g. the EtherCAT
     * slave model, which reads p->analysis_data), or NULL. */
    void *(*capture_new)(const dg_protocol *p);
    /* First pass, every message in capture order, before pairing. */
    void (*see)(void *capture, tvbuff_t *tvb, const dg_view *view, packet_info *pinfo);
    /* Whether a message from `src` can be the response to a pending request
     * from `request_src`: 1 yes, 0 no (it is a new request), -1 cannot tell. */
    int (*is_response)(void *capture, const address *request_src, const address *src);
    /* Whether a message from `src` that answers nothing pending is a response
     * all the same (its request was not captured): TRUE, or FALSE when it may
     * be a request. */
    gboolean (*is_returned)(void *capture, const address *src);
    /* First pass, once per pair: what the response changed, as a number the
     * analysis gives its result (kept in wmem_file_scope; 0: none): the
     * pairing keeps 4 bytes a message for it. `request` holds the request's
     * bytes, `txn` the pair (its request frame, its round trip). */
    guint32 (*compare)(void *capture, tvbuff_t *request, const dg_view *request_view, tvbuff_t *response,
                       const dg_view *response_view, const dg_transaction *txn, packet_info *pinfo);
    /* Every pass: shows a compare() result on the response. `capture` is
     * capture_new()'s state, complete after the first pass. */
    void (*show)(const void *capture, guint32 result, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree);
    /* Statistics (tshark -z FILTER,tree): nodes under the pairing's own. */
    void (*stats_init)(stats_tree *st, int parent);
    void (*stats_response)(const void *capture, stats_tree *st, int parent, guint32 result);
    /* First pass, a request: the number of the analysis's result for it (as
     * compare's), or 0. */
    guint32 (*sent)(void *capture, tvbuff_t *tvb, const dg_view *view, packet_info *pinfo);
    /* Every pass: shows a sent() result. */
    void (*show_sent)(const void *capture, guint32 result, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree);
    /* First pass, before pairing: what the message's own bytes and source say
     * it is, DG_DIR_REQUEST or DG_DIR_RESPONSE, or DG_DIR_ANY when they cannot
     * tell. With this callback a message that cannot tell is a request unless
     * it is its key's waiting request come back unchanged (unchanged()). */
    guint8 (*direction)(void *capture, tvbuff_t *tvb, const dg_view *view, packet_info *pinfo);
    /* Whether `message` (its first `length` bytes, the message the rules
     * decoded) can be `request` come back untouched by the other side (a
     * frame no station processed); NULL: the same bytes. */
    gboolean (*unchanged)(tvbuff_t *request, const dg_view *request_view, tvbuff_t *message, guint length);
    /* Whether `message`, a response whose key matches no waiting request, is
     * `request` come back with its key changed (the same request otherwise);
     * NULL: it may be. */
    gboolean (*key_changed)(const dg_view *request, const dg_view *message);
} dg_analysis;

/* Whether the protocol's analysis times its <cycles> (and the generic cycle
 * analysis stays out). */
static inline gboolean dg_analysis_times_cycles(const dg_protocol *p)
{
    return p->pairing && p->pairing->analysis && p->pairing->analysis->times_cycles;
}

/* C linkage like dissgen_runtime.h's entry points: plain symbol names. */
extern "C" {

/* At registration: the pairing's fields and expert infos, its analysis's,
 * and the per-capture init/cleanup routines. */
void dg_pairing_register(const dg_protocol *p);

/* After a message was decoded: pairs it on the first pass, then shows the
 * pairing in `tree`. `keys` are the values of the DG_KEY fields in decoding
 * order; `view` the analysis inputs the walk decoded (first pass; NULL
 * without an analysis or on later passes); `length` the bytes the message took; `message` its number within the
 * frame (0 for the first); `direction` what the transport says (dg_direction:
 * to the hooked port a request, from it a response). Without a tree only the expert infos are raised
 * (their severity reaches the Expert column). Returns what was found, for
 * the statistics. */
const dg_frame_pairing *dg_pairing_dissect(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree,
                                           const guint64 *keys, guint key_count, const dg_view *view, gint length,
                                           guint message, guint8 direction);

/* First pass, before a message is decoded: what the request with these key
 * values that the message would answer kept (its key's oldest request still
 * waiting; for a duplicate of the key's last response, the request that one
 * answered, so that a copy decodes as its original), or NULL; `direction` as
 * dg_pairing_dissect()'s (over TCP or UDP, the client is a key too). Changes
 * nothing. */
const dg_request_values *dg_pairing_request_of(const guint64 *keys, guint key_count, tvbuff_t *tvb,
                                               const packet_info *pinfo, guint8 direction);

/* At registration (dg_pairing_register): request{...}'s expert info. */
void dg_request_register(const dg_protocol *p, expert_module_t *experts);

void dg_pairing_stats_init(const dg_protocol *p, stats_tree *st);
void dg_pairing_stats_packet(const dg_protocol *p, stats_tree *st, packet_info *pinfo, const dg_frame_pairing *fp);

}

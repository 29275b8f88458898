/* The "ethercat-esc" analysis of a <pairing>: the hub of EtherCAT's
 * analyses. It receives each frame's dg_view (the datagrams the walk decoded),
 * compares a returned frame with the frame as sent by the slave controllers'
 * (ESC) forwarding rules below, hands both to the bus model
 * (ethercat_bus.cpp) and the cycles (ethercat_cycles.cpp), keeps what a frame
 * shows as a small record per frame (interned shapes), shows it on every
 * pass, and registers the fields, experts, preference and statistics. The
 * pairing itself (which frame answers which) is generic; the commands and
 * their classes are ethercat_commands.h's.
 *
 * The frame (IEC 61158-4-12): a 16-bit little-endian header (length of the
 * datagrams in bits 0-10, type in bits 12-15; type 1 = datagrams), then
 * datagrams: command (1), index (1), address (4: ADP + ADO, or a 32-bit
 * logical address), length/flags (2: length in bits 0-10, M = more in bit
 * 15), interrupt (2), data (length), working counter (2).
 *
 * What every ESC does as the frame passes it:
 *  - never changes a datagram's command, index or length, nor the frame's
 *    length;
 *  - auto-increment (APRD, APWR, APRW, ARMW) and broadcast (BRD, BWR, BRW)
 *    commands: adds 1 to the ADP, so every such datagram of a frame comes
 *    back advanced by the number of slaves the frame passed; the ADO is
 *    unchanged;
 *  - configured-address (FPRD, FPWR, FPRW, FRMW) and NOP: ADP and ADO
 *    unchanged; logical (LRD, LWR, LRW): the logical address unchanged;
 *  - writes (APWR, FPWR, BWR, LWR) leave the data as the master sent it; reads
 *    and read/writes may change it;
 *  - the working counter only grows (+1 per read, +1 per write, +3 per
 *    read/write by one slave).
 * The source MAC: the first ESC sets the locally administered bit
 * (0x02 in the first byte) of the frame it returns; simulators may not, so
 * the bit is a hint for the pairing, not a rule.
 */
#include "ethercat_analysis.h"
#include "ethercat_bus.h"
#include "ethercat_commands.h"
#include "ethercat_cycles.h"
#include "dissgen_label.h"

#include <epan/expert.h>
#include <epan/prefs.h>

#include <string.h>

namespace {

using namespace dg_ecat;

enum esc_change { CHANGED_CMD = 1, CHANGED_IDX = 2, CHANGED_LEN = 4, CHANGED_ADDR = 8 };

/* One returned datagram compared with the one sent, as a frame's comparison
 * (a shape) keeps it. Its items go over `back`, the returned datagram. */
struct compared {
    datagram sent, back;
    guint16 advance;        /* ADP advance: slaves passed */
    guint16 majority;       /* the frame's usual advance */
    guint8 changed;         /* esc_change bits */
    guint8 has_advance : 1; /* auto-increment/broadcast: advance is meaningful */
    guint8 data_changed : 1;
    guint8 forwarding : 1;  /* advanced differently from the frame's others */
};

gint32 wkc_added(const compared *c) { return (gint32)c->back.wkc - (gint32)c->sent.wkc; }

/* A returned frame compared with the one sent: the same for every frame of a
 * cycle (what changes from frame to frame, the datagram indexes, is left
 * out unless it is what changed), so interned (capture_hints.shapes). */
struct shape {
    guint count;
    gboolean length_changed;
    guint sent_length, back_length;   /* header lengths */
    guint sent_count, back_count;     /* datagrams */
    compared *d;                      /* count of them, right after the shape */
};

/* What a frame shows that frames alike share: its comparison, its slaves
 * and its cycle (the cycle's number, the same for every frame of a cycle). */
struct kind {
    const shape *esc;                 /* NULL: a frame as sent */
    const bus_shape *bus;             /* the slaves (ethercat_bus.cpp) */
    guint16 cycle;                    /* bus_frame's */
};

/* One EtherCAT frame, sent or returned: kept for every frame of the
 * capture, so 12 bytes, in chunks (capture_hints.records); the pairing keeps
 * its number (from 1). */
struct record {
    guint32 kind;                     /* into capture_hints.kinds */
    guint32 timing[2];                /* its bus_frame's timing (memcpy: 4-byte aligned) */
};
static_assert(sizeof(record) == 12 && sizeof(record::timing) == sizeof(bus_frame::timing), "record grew");
const guint records_shift = 12, records_per_chunk = 1u << records_shift;
const guint recent_slots = 64;

/* The slot of capture_hints.recent for a frame with these slaves. */
guint recent_slot(const void *bus) { return (guint)(((guintptr)bus >> 3) * 2654435761u) >> 26; }
static_assert(recent_slots == 64, "recent_slot gives 6 bits");

struct capture_hints {
    gboolean marking_seen; /* a slave set the locally administered bit: the capture shows direction */
    guint8 master[6];      /* the (unmarked) source of the frames answered so far */
    esc_registers registers; /* where the registers sit (the rule file's register map) */
    bus_model *bus;        /* the slaves the capture shows (ethercat_bus.cpp) */
    cycle_model *cycles;   /* the cycles it finds (ethercat_cycles.cpp) */
    wmem_map_t *shapes;    /* shape -> itself */
    wmem_array_t *kinds;   /* the kinds of frame seen */
    wmem_map_t *kind_ids;  /* kind -> its index in kinds + 1 */
    wmem_array_t *records; /* chunks of records_per_chunk records */
    guint32 record_count;
    /* The comparison and the kind last found for a frame of each slot's
     * slaves (its bus_shape): frames alike follow each other, so most find
     * theirs here, with a comparison instead of hashing. */
    struct {
        const shape *esc;
        guint32 kind;                 /* its index in kinds + 1, 0: none yet */
    } recent[recent_slots];
};

int hf_esc = -1, hf_datagram = -1, hf_wkc_added = -1, hf_slaves_passed = -1, hf_data_changed = -1;
gint ett_esc = -1, ett_datagram = -1;
expert_field ei_changed = EI_INIT, ei_frame_length = EI_INIT, ei_write_changed = EI_INIT, ei_wkc_down = EI_INIT,
             ei_forwarding = EI_INIT;

/* Command numbers and classes: ethercat_commands.h. */
using namespace dg_ecat_commands;

void compare_datagram(compared *c, const datagram *s, const datagram *b, tvbuff_t *request, tvbuff_t *response)
{
    c->sent = *s;
    c->back = *b;
    if (s->cmd != b->cmd) c->changed |= CHANGED_CMD;
    if (s->idx != b->idx) c->changed |= CHANGED_IDX;
    if (s->length != b->length) c->changed |= CHANGED_LEN;
    if (is_logical(s->cmd)) {
        if (s->adp != b->adp || s->ado != b->ado) c->changed |= CHANGED_ADDR;
    } else if (advances_address(s->cmd)) {
        if (s->ado != b->ado) c->changed |= CHANGED_ADDR;
        c->has_advance = TRUE;
        c->advance = (guint16)(b->adp - s->adp);
    } else if (s->adp != b->adp || s->ado != b->ado) {
        c->changed |= CHANGED_ADDR;
    }
    guint16 common = MIN(s->length, b->length);
    c->data_changed = s->length != b->length ||
                      (common > 0 && tvb_memeql(response, data_offset(b),
                                                (const guint8 *)tvb_get_ptr(request, data_offset(s), common), common) != 0);
}

/* The frame's usual advance is the most common one among its auto-increment
 * and broadcast datagrams (a tie goes to the earliest); a datagram that
 * advanced otherwise did not pass the same slaves. */
void check_forwarding(shape *r)
{
    guint best_votes = 0;
    guint16 usual = 0;
    for (guint i = 0; i < r->count; i++) {
        if (!r->d[i].has_advance) continue;
        guint votes = 0;
        for (guint j = 0; j < r->count; j++)
            if (r->d[j].has_advance && r->d[j].advance == r->d[i].advance) votes++;
        if (votes > best_votes) {
            best_votes = votes;
            usual = r->d[i].advance;
        }
    }
    for (guint i = 0; i < r->count; i++) {
        compared *c = &r->d[i];
        c->majority = usual;
        c->forwarding = c->has_advance && c->advance != usual;
    }
}

compared kept_compared(const compared *c)
{
    compared k;
    memset(&k, 0, sizeof k);
    k.sent = kept_datagram(&c->sent, c->changed & CHANGED_IDX);
    k.back = kept_datagram(&c->back, c->changed & CHANGED_IDX);
    k.advance = c->advance;
    k.majority = c->majority;
    k.changed = c->changed;
    k.has_advance = c->has_advance;
    k.data_changed = c->data_changed;
    k.forwarding = c->forwarding;
    return k;
}

guint shape_hash(gconstpointer v)
{
    const shape *s = (const shape *)v;
    const guint fields[] = {s->count, (guint)s->length_changed, s->sent_length, s->back_length, s->sent_count,
                            s->back_count};
    return hash_bytes(hash_bytes(2166136261u, fields, sizeof fields), s->d, s->count * sizeof(compared));
}

gboolean shape_equal(gconstpointer a, gconstpointer b)
{
    const shape *x = (const shape *)a, *y = (const shape *)b;
    return x->count == y->count && x->length_changed == y->length_changed && x->sent_length == y->sent_length &&
           x->back_length == y->back_length && x->sent_count == y->sent_count && x->back_count == y->back_count &&
           memcmp(x->d, y->d, x->count * sizeof(compared)) == 0;
}

/* The interned copy of `probe` (its d[] in kept_compared form), for a
 * returned frame with these slaves. */
const shape *intern(capture_hints *h, const shape *probe, const void *bus)
{
    guint slot = recent_slot(bus);
    const shape *last = h->recent[slot].esc;
    if (last && shape_equal(last, probe)) return last;
    const shape *found = (const shape *)wmem_map_lookup(h->shapes, probe);
    if (found) return h->recent[slot].esc = found;
    /* One allocation for the shape and its datagrams. */
    shape *s = (shape *)wmem_alloc(wmem_file_scope(), sizeof(shape) + probe->count * sizeof(compared));
    *s = *probe;
    s->d = (compared *)(s + 1);
    if (probe->count) memcpy(s->d, probe->d, probe->count * sizeof(compared));
    wmem_map_insert(h->shapes, s, s);
    return h->recent[slot].esc = s;
}

guint kind_hash(gconstpointer v)
{
    const kind *k = (const kind *)v;
    return g_direct_hash(k->esc) ^ g_direct_hash(k->bus) ^ k->cycle;
}

gboolean kind_equal(gconstpointer a, gconstpointer b)
{
    const kind *x = (const kind *)a, *y = (const kind *)b;
    return x->esc == y->esc && x->bus == y->bus && x->cycle == y->cycle;
}

/* A frame's record: its comparison (NULL for a frame as sent) and its slaves. */
guint32 new_record(capture_hints *h, const shape *esc, const bus_frame *f)
{
    kind probe = {esc, f->shape, f->cycle};
    guint slot = recent_slot(f->shape);
    guint id = h->recent[slot].kind;
    if (!id || !kind_equal((const kind *)wmem_array_index(h->kinds, id - 1), &probe)) {
        id = GPOINTER_TO_UINT(wmem_map_lookup(h->kind_ids, &probe));
    }
    if (!id) {
        wmem_array_append_one(h->kinds, probe);
        id = wmem_array_get_count(h->kinds);
        wmem_map_insert(h->kind_ids, wmem_memdup(wmem_file_scope(), &probe, sizeof probe), GUINT_TO_POINTER(id));
    }
    h->recent[slot].kind = id;
    if (h->record_count % records_per_chunk == 0) {
        record *chunk = wmem_alloc_array(wmem_file_scope(), record, records_per_chunk);
        wmem_array_append_one(h->records, chunk);
    }
    guint32 n = h->record_count++;
    record *r = &(*(record **)wmem_array_index(h->records, n >> records_shift))[n % records_per_chunk];
    r->kind = id - 1;
    memcpy(r->timing, &f->timing, sizeof r->timing);
    return n + 1;
}

/* What record `number` keeps: its frame's slaves and timing, and its comparison. */
bus_frame frame_of(const capture_hints *h, guint32 number, const shape **esc)
{
    guint32 n = number - 1;
    const record *r = &(*(record **)wmem_array_index(h->records, n >> records_shift))[n % records_per_chunk];
    const kind *k = (const kind *)wmem_array_index(h->kinds, r->kind);
    if (esc) *esc = k->esc;
    bus_frame f;
    f.shape = k->bus;
    f.cycle = k->cycle;
    memcpy(&f.timing, r->timing, sizeof f.timing);
    return f;
}

void *esc_capture_new(const dg_protocol *p)
{
    capture_hints *h = wmem_new0(wmem_file_scope(), capture_hints);
    h->shapes = wmem_map_new(wmem_file_scope(), shape_hash, shape_equal);
    h->kinds = wmem_array_new(wmem_file_scope(), sizeof(kind));
    h->kind_ids = wmem_map_new(wmem_file_scope(), kind_hash, kind_equal);
    h->records = wmem_array_new(wmem_file_scope(), sizeof(record *));
    h->registers = esc_registers_of(p);
    h->bus = bus_new(static_cast<const dg_bus *>(p->analysis_data), &h->registers);
    h->cycles = cycles_new(&h->registers, p->cycles);
    return h;
}

int esc_is_response(void *capture, const address *request_src, const address *src)
{
    capture_hints *h = (capture_hints *)capture;
    if (request_src->type != AT_ETHER || src->type != AT_ETHER || request_src->len != 6 || src->len != 6) return -1;
    const guint8 *a = (const guint8 *)request_src->data, *b = (const guint8 *)src->data;
    if (memcmp(a + 1, b + 1, 5) != 0) return -1;
    if (!(a[0] & 0x02) && b[0] == (a[0] | 0x02)) {
        h->marking_seen = TRUE;
        memcpy(h->master, a, 6);
        return 1;
    }
    /* The master's own address again, in a capture whose slaves mark returned frames: a new frame. */
    if (a[0] == b[0] && !(a[0] & 0x02) && h->marking_seen) return 0;
    return -1;
}

/* What a frame's source and working counters say it is. Once returns were
 * seen marked, the master's address is a frame sent and the marked one a
 * frame returned. Otherwise a working counter above 0 says a slave processed
 * the frame (a master sends every working counter as 0): returned, whether
 * or not the capture marks returns and whether or not its request was
 * captured. A frame with every working counter 0 cannot tell by itself. */
guint8 esc_direction(void *capture, tvbuff_t *, const dg_view *view, packet_info *pinfo)
{
    const capture_hints *h = (const capture_hints *)capture;
    const address *src = &pinfo->src;
    if (h->marking_seen && src->type == AT_ETHER && src->len == 6) {
        const guint8 *b = (const guint8 *)src->data;
        if (memcmp(b + 1, h->master + 1, 5) == 0) {
            if (b[0] == h->master[0]) return DG_DIR_REQUEST | DG_DIR_FROM_SOURCE;
            if (b[0] == (h->master[0] | 0x02)) return DG_DIR_RESPONSE | DG_DIR_FROM_SOURCE;
        }
    }
    datagram d[max_datagrams];
    guint header_length;
    guint n = frame_datagrams(view, &header_length, d, max_datagrams);
    for (guint i = 0; i < n; i++)
        if (d[i].wkc != 0) return DG_DIR_RESPONSE;
    return DG_DIR_ANY;
}

/* A frame that no slave processed comes back as it was sent, except for the
 * auto-increment address of auto-increment and broadcast datagrams, which
 * every slave it passes advances. */
gboolean esc_unchanged(tvbuff_t *request, const dg_view *request_view, tvbuff_t *message, guint message_length)
{
    guint length = tvb_captured_length(request);
    if (message_length != length || tvb_captured_length(message) < length) return FALSE;
    datagram d[max_datagrams];
    guint header_length;
    guint n = frame_datagrams(request_view, &header_length, d, max_datagrams);
    const guint8 *sent = (const guint8 *)tvb_get_ptr(request, 0, (gint)length);
    guint from = 0; /* bytes before `from` are compared */
    for (guint i = 0; i < n; i++) {
        if (!advances_address(d[i].cmd)) continue;
        guint adp = (guint)d[i].address_offset;
        if (tvb_memeql(message, (gint)from, sent + from, adp - from) != 0) return FALSE;
        from = adp + 2;
    }
    return from >= length || tvb_memeql(message, (gint)from, sent + from, length - from) == 0;
}

/* A returned frame whose index matches no frame sent is the one frame
 * waiting only if its datagrams are that frame's but for the index (the same
 * commands and addresses): otherwise it answers a frame not captured. */
gboolean esc_key_changed(const dg_view *request, const dg_view *message)
{
    datagram s[max_datagrams], b[max_datagrams];
    guint sent_length, back_length;
    guint n = frame_datagrams(request, &sent_length, s, max_datagrams);
    if (frame_datagrams(message, &back_length, b, max_datagrams) != n) return FALSE;
    for (guint i = 0; i < n; i++)
        if (s[i].cmd != b[i].cmd || s[i].ado != b[i].ado || (!advances_address(s[i].cmd) && s[i].adp != b[i].adp))
            return FALSE;
    return TRUE;
}


guint32 esc_compare(void *capture, tvbuff_t *request, const dg_view *request_view, tvbuff_t *response,
                    const dg_view *response_view, const dg_transaction *txn, packet_info *pinfo)
{
    datagram sent[max_datagrams], back[max_datagrams];
    guint sent_length, back_length;
    guint sent_count = frame_datagrams(request_view, &sent_length, sent, max_datagrams);
    guint back_count = frame_datagrams(response_view, &back_length, back, max_datagrams);
    guint count = MIN(sent_count, back_count);
    compared d[max_datagrams];
    memset(d, 0, count * sizeof(compared));
    shape probe;
    memset(&probe, 0, sizeof probe);
    probe.d = d;
    probe.count = count;
    probe.sent_length = sent_length;
    probe.back_length = back_length;
    probe.sent_count = sent_count;
    probe.back_count = back_count;
    probe.length_changed = sent_length != back_length || sent_count != back_count;
    for (guint i = 0; i < count; i++) compare_datagram(&d[i], &sent[i], &back[i], request, response);
    check_forwarding(&probe);
    for (guint i = 0; i < count; i++) d[i] = kept_compared(&d[i]);
    capture_hints *h = (capture_hints *)capture;
    bus_frame f = {};
    const frame_pair pair = {request, response, request_view, response_view};
    bus_returned(h->bus, &pair, sent, back, count, pinfo, &f);
    if (!probe.length_changed) cycles_returned(h->cycles, sent, back, count, txn, pinfo);
    bus_set_dc_drift(&f, dc_returned(h->cycles, sent, back, count, response, pinfo));
    return new_record(h, intern(h, &probe, f.shape), &f);
}

/* The datagram's items, when someone looks at them; `tree` is the analysis's subtree. */
proto_tree *show_datagram_items(const compared *c, guint i, tvbuff_t *tvb, proto_tree *tree)
{
    /* "Datagram 1 (FPRD): working counter +1, 2 slaves passed, data changed" */
    dg_label label = {"", 0};
    dg_label_str(&label, "Datagram ");
    dg_label_uint(&label, i + 1);
    dg_label_str(&label, " (");
    dg_label_str(&label, command_name(c->back.cmd));
    dg_label_str(&label, "): working counter ");
    dg_label_int(&label, wkc_added(c), TRUE);
    if (c->has_advance) {
        dg_label_str(&label, ", ");
        dg_label_uint(&label, c->advance);
        dg_label_str(&label, " slaves passed");
    }
    dg_label_str(&label, c->data_changed ? ", data changed" : ", data unchanged");
    proto_item *item = proto_tree_add_none_format(tree, hf_datagram, tvb, c->back.offset, datagram_span(&c->back), "%s", label.text);
    proto_item_set_generated(item);
    proto_tree *sub = proto_item_add_subtree(item, ett_datagram);
    proto_item *it = proto_tree_add_int(sub, hf_wkc_added, tvb, wkc_offset(&c->back), datagram_wkc, wkc_added(c));
    proto_item_set_generated(it);
    if (c->has_advance) {
        it = proto_tree_add_uint(sub, hf_slaves_passed, tvb, c->back.address_offset, 2, c->advance);
        proto_item_set_generated(it);
    }
    it = proto_tree_add_boolean(sub, hf_data_changed, tvb, data_offset(&c->back), c->back.length, c->data_changed);
    proto_item_set_generated(it);
    return sub;
}

/* The expert infos of one datagram, over its bytes in `tree`. */
void show_datagram_experts(const compared *c, guint i, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    const char *cmd = command_name(c->sent.cmd);
    if (c->changed) {
        wmem_strbuf_t *what = wmem_strbuf_new(pinfo->pool, "");
        if (c->changed & CHANGED_CMD)
            wmem_strbuf_append_printf(what, ", command %s came back as %s", cmd, command_name(c->back.cmd));
        if (c->changed & CHANGED_IDX)
            wmem_strbuf_append_printf(what, ", index 0x%02x came back as 0x%02x", c->sent.idx, c->back.idx);
        if (c->changed & CHANGED_LEN)
            wmem_strbuf_append_printf(what, ", length %u came back as %u", c->sent.length, c->back.length);
        if (c->changed & CHANGED_ADDR)
            wmem_strbuf_append_printf(what, ", address 0x%04x%04x came back as 0x%04x%04x", c->sent.ado, c->sent.adp,
                                      c->back.ado, c->back.adp);
        proto_tree_add_expert_format(tree, pinfo, &ei_changed, tvb, c->back.offset, datagram_span(&c->back), "Datagram %u (%s)%s", i + 1,
                                     cmd, wmem_strbuf_get_str(what));
    }
    if (is_write_only(c->sent.cmd) && c->data_changed && !(c->changed & CHANGED_LEN))
        proto_tree_add_expert_format(tree, pinfo, &ei_write_changed, tvb, data_offset(&c->back), c->back.length,
                                     "Datagram %u (%s): the written data came back changed", i + 1, cmd);
    if (wkc_added(c) < 0)
        proto_tree_add_expert_format(tree, pinfo, &ei_wkc_down, tvb, wkc_offset(&c->back), datagram_wkc,
                                     "Datagram %u (%s): working counter went down from %u to %u", i + 1, cmd,
                                     c->sent.wkc, c->back.wkc);
    if (c->forwarding)
        proto_tree_add_expert_format(tree, pinfo, &ei_forwarding, tvb, c->back.address_offset, 2,
                                     "Datagram %u (%s): auto-increment address advanced by %u, the frame's other "
                                     "datagrams by %u",
                                     i + 1, cmd, c->advance, c->majority);
}

/* "Show slave and ESC details on every datagram" (the preference): off, a
 * datagram's comparison is printed only when something is unusual. */
dg_pref_bool show_details = FALSE;

/* Someone may read the comparison: a visible tree (the details pane, -V,
 * -T fields), or a filter or column naming one of its fields. */
gboolean comparison_wanted(proto_tree *tree)
{
    const int *hfs[] = {&hf_esc, &hf_datagram, &hf_wkc_added, &hf_slaves_passed, &hf_data_changed};
    for (const int *hf : hfs)
        if (proto_field_is_referenced(tree, *hf)) return TRUE;
    return FALSE;
}

/* What an expert info of show_datagram_experts() says: worth printing. */
gboolean unusual(const compared *c)
{
    return c->changed || (is_write_only(c->sent.cmd) && c->data_changed) || wkc_added(c) < 0 || c->forwarding;
}

void esc_show(const void *capture, guint32 data, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    const capture_hints *h = (const capture_hints *)capture;
    const shape *r;
    const bus_frame frame = frame_of(h, data, &r);
    /* Printed: every datagram with the preference, else the unusual ones. The
     * others are added hidden (filterable, not printed) for whoever may read
     * them. Expert infos always. */
    gboolean any_unusual = r->length_changed;
    for (guint i = 0; i < r->count && !any_unusual; i++) any_unusual = unusual(&r->d[i]);
    gboolean wanted = tree && comparison_wanted(tree);
    gboolean printed = tree && (show_details || any_unusual);
    proto_tree *sub = tree;
    if (printed || wanted) {
        proto_item *item = proto_tree_add_item(tree, hf_esc, tvb, 0, 0, ENC_NA);
        proto_item_set_generated(item);
        if (!printed) proto_item_set_hidden(item);
        sub = proto_item_add_subtree(item, ett_esc);
    }
    if (r->length_changed)
        proto_tree_add_expert_format(sub, pinfo, &ei_frame_length, tvb, 0, MIN(2, (gint)tvb_captured_length(tvb)),
                                     "Frame length changed: sent with %u bytes of datagrams (%u datagrams), came "
                                     "back with %u (%u datagrams)",
                                     r->sent_length, r->sent_count, r->back_length, r->back_count);
    gboolean dc_shown = !tree;
    for (guint i = 0; i < r->count; i++) {
        const compared *c = &r->d[i];
        gboolean shown = printed && (show_details || unusual(c));
        proto_tree *dg = sub;
        if (shown || wanted) {
            dg = show_datagram_items(c, i, tvb, sub);
            if (!shown) proto_item_set_hidden(proto_tree_get_parent(dg));
        }
        show_datagram_experts(c, i, tvb, pinfo, dg);
        if (!dc_shown && dc_datagram(h->registers.system_time, &c->sent, &c->back)) {
            dc_show(&c->back, bus_dc_drift(&frame), tvb, tree);
            dc_shown = TRUE;
        }
    }
    bus_show(&frame, tvb, pinfo, tree, show_details);
}

/* A frame as sent: its slaves and its cycle. */
guint32 esc_sent(void *capture, tvbuff_t *, const dg_view *view, packet_info *pinfo)
{
    capture_hints *h = (capture_hints *)capture;
    datagram d[max_datagrams];
    guint header_length;
    guint n = frame_datagrams(view, &header_length, d, max_datagrams);
    bus_frame f = {};
    bus_sent(h->bus, d, n, &f);
    cycle_mark c = cycles_sent(h->cycles, view ? view->cycle : NULL, d, n, pinfo);
    if (c.cycle) bus_set_cycle(&f, &c);
    return new_record(h, NULL, &f);
}

void esc_show_sent(const void *capture, guint32 data, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    const capture_hints *h = (const capture_hints *)capture;
    const bus_frame f = frame_of(h, data, NULL);
    cycle_mark c = bus_cycle(&f);
    cycles_show(h->cycles, &c, tvb, pinfo, tree);
    bus_show(&f, tvb, pinfo, tree, show_details);
}

/* --- statistics ---------------------------------------------------------- */

const char *const st_wkc = "Working counter per command (returned)";
const char *const st_wkc_down = "Working counter went down";

/* Rows appear with their first count (no rows of zeros). */
void esc_stats_init(stats_tree *st, int parent)
{
    bus_stats_init(st, parent);
}

void esc_stats_response(const void *capture, stats_tree *st, int parent, guint32 data)
{
    const shape *r;
    const bus_frame frame = frame_of((const capture_hints *)capture, data, &r);
    char label[32];
    for (guint i = 0; i < r->count; i++) {
        const compared *c = &r->d[i];
        int wkc_id = tick_stat_node(st, st_wkc, parent, TRUE);
        int cmd_id = tick_stat_node(st, command_name(c->back.cmd), wkc_id, TRUE);
        g_snprintf(label, sizeof label, "working counter %u", c->back.wkc);
        tick_stat_node(st, label, cmd_id, FALSE);
        if (wkc_added(c) < 0) tick_stat_node(st, st_wkc_down, parent, FALSE);
    }
    bus_stats_frame(st, parent, &frame);
}

void esc_register(int proto, const char *filter)
{
    static hf_register_info hf[] = {DG_ESC_FIELDS(DG_HF_ROW)};
    static const char *const names[] = {DG_ESC_FIELDS(DG_FIELD_NAME)};
    dg_name_fields(hf, names, G_N_ELEMENTS(hf), filter);
    proto_register_field_array(proto, hf, (int)G_N_ELEMENTS(hf));
    static gint *ett[] = {&ett_esc, &ett_datagram};
    proto_register_subtree_array(ett, (int)G_N_ELEMENTS(ett));

    static ei_register_info ei[] = {DG_ESC_EXPERTS(DG_EI_ROW)};
    static const char *const ei_names[] = {DG_ESC_EXPERTS(DG_EXPERT_NAME)};
    dg_name_experts(ei, ei_names, G_N_ELEMENTS(ei), filter);
    expert_register_field_array(expert_register_protocol(proto), ei, (int)G_N_ELEMENTS(ei));
    module_t *prefs = prefs_register_protocol(proto, NULL);
    prefs_register_bool_preference(prefs, "show_details", "Show slave and ESC details on every datagram",
                                   "Print every datagram's slave (position, station, identity) and its comparison "
                                   "with the frame as sent. Off: one line names the slave, the comparison is "
                                   "printed where something is unusual, and every field stays filterable.",
                                   &show_details);
    bus_register(proto, filter);
    cycles_register(proto, filter);
}

/* The analysis, callback by callback. */
constexpr dg_analysis esc_analysis(void)
{
    dg_analysis a = {};
    a.name = DG_ANALYSIS_ETHERCAT_ESC;
    a.times_cycles = DG_ESC_TIMES_CYCLES; /* with the frames' returns and working counters (ethercat_cycles.cpp) */
    a.register_info = esc_register;
    a.capture_new = esc_capture_new;
    a.is_response = esc_is_response;  /* is_returned: none, esc_direction() says so, marked or not */
    a.compare = esc_compare;
    a.show = esc_show;
    a.stats_init = esc_stats_init;
    a.stats_response = esc_stats_response;
    a.sent = esc_sent;
    a.show_sent = esc_show_sent;
    a.direction = esc_direction;
    a.unchanged = esc_unchanged;
    a.key_changed = esc_key_changed;
    return a;
}

} /* namespace */

extern "C" const dg_analysis dg_ethercat_esc = esc_analysis();

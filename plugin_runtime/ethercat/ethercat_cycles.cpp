// SPDX-License-Identifier: GPL-2.0-or-later
/* The cycles of an EtherCAT capture (see ethercat_cycles.h and the manual,
 * "Cycles"), decided on the first pass from what came before each frame:
 *
 *  - What is timed is what the rule file's <cycles> says (the manual,
 *    "Cycles of any protocol"): a frame's signature is the values of its
 *    <signature> fields, in decoding order (in rules/ethercat.xml the
 *    command, address and data length of each datagram); a frame in which
 *    an <only> test failed or a <never> test held is in no signature (in
 *    rules/ethercat.xml: a datagram that transfers a mailbox or does what
 *    only a start-up does). Without <cycles>, nothing is timed.
 *  - A period is the time from a frame sent to the next one sent with its
 *    signature. It is regular when it is above 0, the previous frame came
 *    back before this one was sent (not a retry after a timeout) and this
 *    frame is not a poll: sent less than one round trip after that return
 *    (a master sending the same frame again as soon as it is back, as while
 *    waiting for a state or an EEPROM read).
 *  - A signature becomes a cycle with its first window of `window` (8; the
 *    <cycles window="...">)
 *    regular periods in a row, all within half of their median either way
 *    (and that median below 2^32 ns): the frame that completes the window is
 *    the cycle's first marked frame. From then on every frame sent with that
 *    signature is in the cycle, whatever its period.
 *  - A marked frame's period is the time since the signature's previous
 *    frame (0 if the timestamps went backwards); its nominal period the median (the lower of the two middle
 *    values for an even count) of the cycle's periods so far: the window's
 *    and those of every marked frame up to this one; its jitter the period
 *    minus the nominal period.
 *
 * Memory: each sent frame's mark lives in its frame's record
 * (ethercat_analysis.cpp: the cycle number with what the frames of the cycle
 * share, the periods in the frame's own 8 bytes); the
 * model keeps per cycle its periods (4 bytes each, in two heaps for the
 * running median) and the round trips of its returned frames (4 bytes each),
 * for `-z ecatr,cycles`.
 */
#include "ethercat_cycles.h"
#include "ethercat_commands.h"

#include "../dissgen_cycles.h"
#include "../dissgen_periods.h"

#include <epan/stat_tap_ui.h>
#include <epan/stats_tree.h>
#include <epan/tap.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

namespace dg_ecat {

namespace {

using namespace dg_periods;

const guint ring = 16; /* the last frames of a cycle whose return may still come */

struct sig_datagram {
    guint8 cmd;
    guint16 adp, ado, length;
};

struct cycle {
    guint16 number;
    guint count;             /* datagrams of its first frame */
    const sig_datagram *sig; /* ... as -z ecatr,cycles names them */
    running_median periods;  /* its periods */
    guint window;                        /* its detection window's periods */
    guint32 window_periods[most_window]; /* the qualifying window's: not carried by a marked frame */
    guint frames;            /* marked frames */
    guint32 first_frame;     /* the first marked frame */
    double jitter_sum, jitter_squares;
    u32_vec rtts;            /* round trips of the marked frames answered, ns */
    guint answered;
    guint32 recent[ring];    /* the last marked frames sent, oldest overwritten */
    guint32 latest_answered; /* the latest marked frame answered */
    guint unanswered_tail;   /* marked frames sent after it */
    guint wkc_errors;
    guint16 *wkc_high;       /* per datagram, the highest working counter returned */
    cycle *next;
};

/* The frames whose <signature> fields have the same values. */
struct signature {
    guint32 hash;
    guint value_count;
    guint64 *values;             /* the <signature> fields' values, in decoding order */
    guint16 *nodes;              /* the node of each */
    guint count;                 /* datagrams of its first frame, */
    sig_datagram *d;             /* ... which name it */
    guint32 last_sent_frame;
    nstime_t last_sent;
    guint32 last_answered_frame; /* the last of its frames answered, and when */
    nstime_t last_return;
    nstime_t last_rtt;
    guint32 recent[most_window]; /* its last regular periods, a ring */
    guint regular;               /* how many in a row (up to window) */
    guint next_slot;
    cycle *cyc;
};

} /* namespace */

/* The first system time of each width returned in the capture, and when. */
struct dc_reference {
    gboolean known;
    guint64 systime;
    gint64 at;   /* capture time, ns */
};

/* A frame sent in a signature, until its return comes. */
struct sent_frame {
    guint32 frame;
    signature *sig;              /* NULL: in no signature, or returned */
};

struct cycle_model {
    const dg_cycles *declared;   /* the rule file's <cycles>; NULL: none */
    guint window;
    wmem_map_t *signatures;      /* signature -> itself */
    cycle *first, *last;
    guint16 cycles;
    wmem_map_t *long_periods;    /* frame -> gint64 *, periods of 2^32 ns or more */
    esc_registers regs;          /* where the registers it reads sit */
    dc_reference dc32, dc64;
    guint32 last_frame;          /* the last frame the first pass brought here */
    /* the last frames sent and their signatures, so that returns find
     * theirs; a frame whose slot is reused before its return came moves to
     * `overtaken` (frame -> signature; a frame never returned stays there) */
    sent_frame recent_sent[ring];
    wmem_map_t *overtaken;
};

namespace {

/* The open capture's model, for -z ecatr,cycles and the statistics tree:
 * Wireshark's tap and stats-tree callbacks carry no capture state. */
cycle_model *current;

guint sig_hash(gconstpointer p) { return ((const signature *)p)->hash; }

gboolean sig_equal(gconstpointer a, gconstpointer b)
{
    const signature *x = (const signature *)a, *y = (const signature *)b;
    return x->hash == y->hash && x->value_count == y->value_count &&
           !memcmp(x->values, y->values, x->value_count * sizeof(guint64)) &&
           !memcmp(x->nodes, y->nodes, x->value_count * sizeof(guint16));
}

/* The signature of a frame sent (its <cycles> input `in`, its n datagrams),
 * or NULL when it is in none. */
signature *signature_of(cycle_model *m, const dg_cycle_input *in, const datagram *d, guint n)
{
    if (!m->declared || !in || !n || !dg_cycle_input_in_stream(m->declared, in)) return NULL;
    const guint32 h = dg_cycle_input_hash(in);
    signature probe; /* what sig_hash() and sig_equal() read, no more */
    probe.hash = h;
    probe.value_count = in->count;
    probe.values = in->values;
    probe.nodes = in->nodes;
    signature *s = (signature *)wmem_map_lookup(m->signatures, &probe);
    if (s) return s;
    s = wmem_new0(wmem_file_scope(), signature);
    s->hash = h;
    s->value_count = in->count;
    s->values = (guint64 *)wmem_memdup(wmem_file_scope(), in->values, in->count * sizeof(guint64));
    s->nodes = (guint16 *)wmem_memdup(wmem_file_scope(), in->nodes, in->count * sizeof(guint16));
    s->count = n;
    s->d = wmem_alloc_array(wmem_file_scope(), sig_datagram, n);
    for (guint i = 0; i < n; i++) s->d[i] = {d[i].cmd, d[i].adp, d[i].ado, d[i].length};
    wmem_map_insert(m->signatures, s, s);
    return s;
}

/* First pass: the frame sent is in signature s (NULL: none), in the ring of
 * frames whose return may still come. */
void remember_sent(cycle_model *m, guint32 frame, signature *s)
{
    sent_frame *slot = &m->recent_sent[frame % ring];
    if (slot->sig) {
        if (!m->overtaken) m->overtaken = wmem_map_new(wmem_file_scope(), g_direct_hash, g_direct_equal);
        wmem_map_insert(m->overtaken, GUINT_TO_POINTER(slot->frame), slot->sig);
    }
    slot->frame = frame;
    slot->sig = s;
}

/* First pass: the signature of the frame sent as `frame`, whose return came
 * (once: it is forgotten); NULL when it was in none. */
signature *returned_signature(cycle_model *m, guint32 frame)
{
    sent_frame *slot = &m->recent_sent[frame % ring];
    if (slot->frame == frame) {
        signature *s = slot->sig;
        slot->sig = NULL;
        return s;
    }
    if (!m->overtaken) return NULL;
    return (signature *)wmem_map_remove(m->overtaken, GUINT_TO_POINTER(frame));
}

cycle *new_cycle(cycle_model *m, signature *s, guint32 frame)
{
    cycle *c = wmem_new0(wmem_file_scope(), cycle);
    c->number = ++m->cycles;
    c->count = s->count;
    c->sig = s->d;
    c->first_frame = frame;
    c->window = m->window;
    c->wkc_high = wmem_alloc0_array(wmem_file_scope(), guint16, s->count ? s->count : 1);
    if (m->last)
        m->last->next = c;
    else
        m->first = c;
    m->last = c;
    /* the window's periods, oldest first; the last is the marking frame's own */
    for (guint i = 0; i + 1 < m->window; i++) {
        guint32 p = s->recent[(s->next_slot + i) % m->window];
        c->window_periods[i] = p;
        c->periods.add(p);
    }
    return c;
}

void capture_cleanup(void) { current = NULL; }

} /* namespace */

cycle_model *cycles_new(const esc_registers *r, const dg_cycles *declared)
{
    cycle_model *m = wmem_new0(wmem_file_scope(), cycle_model);
    m->regs = *r;
    m->declared = declared;
    m->window = declared ? MIN(MAX(declared->window, 1u), most_window) : most_window;
    m->signatures = wmem_map_new(wmem_file_scope(), sig_hash, sig_equal);
    current = m;
    return m;
}

cycle_mark cycles_sent(cycle_model *m, const dg_cycle_input *in, const datagram *d, guint n,
                       const packet_info *pinfo)
{
    cycle_mark mark = {0, 0, 0};
    m->last_frame = pinfo->num;
    signature *s = signature_of(m, in, d, n);
    remember_sent(m, pinfo->num, s);
    if (!s) return mark;
    guint32 previous = s->last_sent_frame;
    nstime_t previous_time = s->last_sent;
    s->last_sent_frame = pinfo->num;
    s->last_sent = pinfo->abs_ts;
    if (!previous) return mark;
    gint64 period = ns_of(&pinfo->abs_ts) - ns_of(&previous_time);
    if (!s->cyc) {
        gboolean answered = s->last_answered_frame == previous;
        gboolean poll = answered && ns_of(&pinfo->abs_ts) - ns_of(&s->last_return) < ns_of(&s->last_rtt);
        if (period <= 0 || !answered || poll) {
            s->regular = 0;
            return mark;
        }
        s->recent[s->next_slot] = clamp_period(period);
        s->next_slot = (s->next_slot + 1) % m->window;
        if (s->regular < m->window) s->regular++;
        if (s->regular < m->window || !steady_median(s->recent, m->window)) return mark;
        s->cyc = new_cycle(m, s, pinfo->num);
    }
    cycle *c = s->cyc;
    guint32 stored = clamp_period(period);
    if (stored == G_MAXUINT32) {
        if (!m->long_periods) m->long_periods = wmem_map_new(wmem_file_scope(), g_direct_hash, g_direct_equal);
        gint64 *exact = wmem_new(wmem_file_scope(), gint64);
        *exact = period;
        wmem_map_insert(m->long_periods, GUINT_TO_POINTER(pinfo->num), exact);
    }
    c->periods.add(stored);
    mark.cycle = c->number;
    mark.period_ns = stored;
    mark.nominal_ns = c->periods.median();
    gint64 shown = stored == G_MAXUINT32 ? period : stored; /* what cycles_show() shows */
    double jitter = (double)(shown - (gint64)mark.nominal_ns);
    c->frames++;
    c->jitter_sum += jitter;
    c->jitter_squares += jitter * jitter;
    c->recent[c->frames % ring] = pinfo->num;
    c->unanswered_tail++;
    return mark;
}

void cycles_returned(cycle_model *m, const datagram *s, const datagram *b, guint n, const dg_transaction *txn,
                     const packet_info *pinfo)
{
    m->last_frame = pinfo->num;
    if (!txn) return;
    signature *sig = returned_signature(m, txn->request_frame);
    if (!sig) return;
    if (txn->request_frame >= sig->last_answered_frame) {
        sig->last_answered_frame = txn->request_frame;
        sig->last_return = pinfo->abs_ts;
        sig->last_rtt = txn->round_trip;
    }
    cycle *c = sig->cyc;
    if (!c || txn->request_frame < c->first_frame) return;
    c->rtts.push(clamp_period(ns_of(&txn->round_trip)));
    c->answered++;
    if (txn->request_frame > c->latest_answered) {
        c->latest_answered = txn->request_frame;
        guint tail = 0;
        for (guint i = 0; i < ring; i++) /* unused slots hold 0 */
            if (c->recent[i] > txn->request_frame) tail++;
        c->unanswered_tail = tail;
    }
    gboolean error = FALSE;
    for (guint i = 0; i < n && i < c->count; i++) {
        if (b[i].wkc <= s[i].wkc || b[i].wkc < c->wkc_high[i]) error = TRUE;
        if (b[i].wkc > c->wkc_high[i]) c->wkc_high[i] = b[i].wkc;
    }
    if (error) c->wkc_errors++;
}

/* --- distributed clocks ---------------------------------------------------- */

gboolean dc_datagram(const dg_input_place *system_time, const datagram *s, const datagram *b)
{
    return system_time && (s->cmd == dg_ecat_commands::ARMW || s->cmd == dg_ecat_commands::FRMW) &&
           s->ado == system_time->at && (s->length == 4 || s->length == 8) &&
           b->cmd == s->cmd && b->ado == s->ado && b->length == s->length && b->wkc > s->wkc;
}

namespace {

guint64 systime_of(tvbuff_t *tvb, const datagram *b)
{
    return b->length == 8 ? dg_tvb_get_uint64(tvb, data_offset(b), ENC_LITTLE_ENDIAN)
                           : dg_tvb_get_uint32(tvb, data_offset(b), ENC_LITTLE_ENDIAN);
}

} /* namespace */

/* The drift is the DC time elapsed since the reference less the capture time
 * elapsed, per second of capture time. A 32-bit system time wraps every
 * 4.29 s: it is unwrapped to the value nearest the reference plus the
 * capture time elapsed. */
double dc_returned(cycle_model *m, const datagram *s, const datagram *b, guint n, tvbuff_t *back,
                   const packet_info *pinfo)
{
    guint i = 0;
    while (i < n && !dc_datagram(m->regs.system_time, &s[i], &b[i])) i++;
    if (i == n || (guint)data_offset(&b[i]) + b[i].length > tvb_captured_length(back)) return NAN;
    guint64 raw = systime_of(back, &b[i]);
    gint64 at = ns_of(&pinfo->abs_ts);
    dc_reference *ref = b[i].length == 8 ? &m->dc64 : &m->dc32;
    if (!ref->known) {
        ref->known = TRUE;
        ref->systime = raw;
        ref->at = at;
        return NAN;
    }
    gint64 elapsed = at - ref->at;
    if (elapsed <= 0) return NAN;
    gint64 dc_elapsed;
    if (b[i].length == 8) {
        dc_elapsed = (gint64)(raw - ref->systime);
    } else {
        /* the wrap count that puts the value nearest the capture's clock */
        gint64 low = (gint64)((raw - ref->systime) & 0xFFFFFFFFu);
        gint64 wraps = (elapsed - low + ((gint64)1 << 31)) >> 32;
        dc_elapsed = low + (wraps << 32);
    }
    return (double)(dc_elapsed - elapsed) * 1e9 / (double)elapsed;
}

/* --- items -------------------------------------------------------------- */

namespace {

int hf_cycle = -1, hf_period = -1, hf_jitter = -1, hf_systime = -1, hf_drift = -1;

gint64 period_of(const cycle_model *m, const cycle_mark *c, guint32 frame)
{
    if (c->period_ns != G_MAXUINT32 || !m || !m->long_periods) return c->period_ns;
    const gint64 *exact = (const gint64 *)wmem_map_lookup(m->long_periods, GUINT_TO_POINTER(frame));
    return exact ? *exact : c->period_ns;
}

} /* namespace */

namespace {

/* proto_field_is_referenced: a visible tree, or a filter, column or -e naming
 * the field; tshark -T fields of other fields skips the items. */
gboolean any_referenced(proto_tree *tree, const int *hf, guint n)
{
    for (guint i = 0; i < n; i++)
        if (proto_field_is_referenced(tree, hf[i])) return TRUE;
    return FALSE;
}

} /* namespace */

void dc_show(const datagram *b, double drift, tvbuff_t *tvb, proto_tree *tree)
{
    const int dc_fields[] = {hf_systime, hf_drift};
    if (!tree || !any_referenced(tree, dc_fields, G_N_ELEMENTS(dc_fields))) return;
    proto_item *it = proto_tree_add_uint64(tree, hf_systime, tvb, data_offset(b), b->length, systime_of(tvb, b));
    proto_item_set_generated(it);
    if (isnan(drift)) return;
    it = proto_tree_add_double(tree, hf_drift, tvb, data_offset(b), b->length, drift);
    proto_item_set_generated(it);
}

void cycles_show(const cycle_model *m, const cycle_mark *c, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    const int cycle_fields[] = {hf_cycle, hf_period, hf_jitter};
    if (!tree || !c->cycle || !any_referenced(tree, cycle_fields, G_N_ELEMENTS(cycle_fields))) return;
    proto_item *it = proto_tree_add_uint(tree, hf_cycle, tvb, 0, 0, c->cycle);
    proto_item_set_generated(it);
    gint64 period = period_of(m, c, pinfo->num);
    nstime_t t = nstime_of(period);
    it = proto_tree_add_time(tree, hf_period, tvb, 0, 0, &t);
    proto_item_set_generated(it);
    t = nstime_of(period - (gint64)c->nominal_ns);
    it = proto_tree_add_time(tree, hf_jitter, tvb, 0, 0, &t);
    proto_item_set_generated(it);
}

/* --- -z ecatr,cycles and the statistics tree ----------------------------- */

namespace {

/* A cycle's whole-capture figures, from the capture's state. */
struct figures {
    guint32 nominal;
    quantiles period, rtt;
    double jitter_sd;
    guint lost;
};

figures figures_of(const cycle *c)
{
    figures f = {};
    f.nominal = c->periods.median();
    /* the marked frames' periods: the cycle's less the window's */
    guint total = c->periods.count();
    guint32 *all = g_new(guint32, total + 1);
    c->periods.copy_to(all);
    qsort(all, total, sizeof *all, compare_periods<guint32>);
    guint32 win[most_window];
    memcpy(win, c->window_periods, sizeof win);
    qsort(win, c->window - 1, sizeof *win, compare_periods<guint32>);
    guint n = 0, w = 0;
    for (guint i = 0; i < total; i++) {
        if (w + 1 < c->window && all[i] == win[w])
            w++;
        else
            all[n++] = all[i];
    }
    f.period = quantiles_of(all, n);
    g_free(all);
    double mean = c->frames ? c->jitter_sum / c->frames : 0;
    double var = c->frames ? c->jitter_squares / c->frames - mean * mean : 0;
    f.jitter_sd = var > 0 ? sqrt(var) : 0.0;
    f.rtt = quantiles_of(c->rtts);
    guint unanswered = c->frames - c->answered;
    f.lost = unanswered - MIN(c->unanswered_tail, unanswered);
    return f;
}

/* "LRW 0x00010000 (4 bytes), FRMW 0x1001:0x0910 (8 bytes)" */
char *signature_text(const cycle *c)
{
    GString *t = g_string_new("");
    for (guint i = 0; i < c->count; i++) {
        const sig_datagram *d = &c->sig[i];
        if (i) g_string_append(t, ", ");
        if (dg_ecat_commands::is_logical(d->cmd))
            g_string_append_printf(t, "%s 0x%08x", command_name(d->cmd), (guint32)d->ado << 16 | d->adp);
        else
            g_string_append_printf(t, "%s 0x%04x:0x%04x", command_name(d->cmd), d->adp, d->ado);
        g_string_append_printf(t, " (%u bytes)", d->length);
    }
    return g_string_free(t, FALSE);
}

const char *cycles_filter = "ecatr";

/* At the end of the capture, from the capture's state (complete by then). */
void cycles_draw(void *)
{
    printf("===================================================================\n");
    printf("EtherCAT cycles (%s)\n", cycles_filter);
    if (!current || !current->first) printf("No cycles\n");
    for (const cycle *c = current ? current->first : NULL; c; c = c->next) {
        figures f = figures_of(c);
        char *sig = signature_text(c);
        printf("Cycle %u: %s\n", c->number, sig);
        g_free(sig);
        printf("  frames: %u\n", c->frames);
        printf("  nominal period (ns): %u\n", f.nominal);
        print_quantiles("period", &f.period);
        printf("  jitter std dev (ns): %.1f\n", f.jitter_sd);
        print_quantiles("round trip", &f.rtt);
        printf("  frames returned: %u\n", c->answered);
        printf("  frames lost: %u\n", f.lost);
        printf("  working counter errors: %u\n", c->wkc_errors);
    }
    printf("===================================================================\n");
}

dg_tap_init_result cycles_cli_init(const char *, void *)
{
    return dg_tap_init_done(listen_to_the_end(&cycles_filter, cycles_draw));
}

/* The statistics tree (Wireshark's Statistics menu): the same figures,
 * filled once the capture's state is complete (st_fill_now). */
gboolean st_filled;

void st_init(stats_tree *) { st_filled = FALSE; }

tap_packet_status st_packet(stats_tree *st, packet_info *pinfo, epan_dissect_t *, const void *, tap_flags_t)
{
    if (!st_fill_now(&st_filled, current != NULL, pinfo->num, current ? current->last_frame : 0))
        return TAP_PACKET_DONT_REDRAW;
    for (const cycle *c = current->first; c; c = c->next) {
        figures f = figures_of(c);
        char *sig = signature_text(c);
        int id = st_cycle_node(st, c->number, sig, c->frames);
        g_free(sig);
        st_cycle_row(st, c->number, "frames", id, c->frames);
        const st_time_unit unit = st_unit_of(f);
        st_time_row(st, c->number, "nominal period", id, f.nominal, unit);
        st_quantile_rows(st, c->number, "period", &f.period, id, unit);
        st_time_row(st, c->number, "jitter std dev", id, (guint64)(f.jitter_sd + 0.5), unit);
        st_quantile_rows(st, c->number, "round trip", &f.rtt, id, unit);
        st_cycle_row(st, c->number, "frames returned", id, c->answered);
        st_cycle_row(st, c->number, "frames lost", id, f.lost);
        st_cycle_row(st, c->number, "working counter errors", id, c->wkc_errors);
    }
    return TAP_PACKET_REDRAW;
}

} /* namespace */

void cycles_register(int proto, const char *filter)
{
    static hf_register_info hf[] = {DG_CYCLE_FIELDS(DG_HF_ROW) DG_DC_FIELDS(DG_HF_ROW)};
    static const char *const names[] = {DG_CYCLE_FIELDS(DG_FIELD_NAME) DG_DC_FIELDS(DG_FIELD_NAME)};
    dg_name_fields(hf, names, G_N_ELEMENTS(hf), filter);
    proto_register_field_array(proto, hf, (int)G_N_ELEMENTS(hf));
    register_cleanup_routine(capture_cleanup);
    cycles_filter = filter;
    static stat_tap_ui ui = {REGISTER_STAT_GROUP_GENERIC, NULL, NULL, cycles_cli_init, 0, NULL};
    ui.cli_string = g_strdup_printf("%s,cycles", filter);
    register_stat_tap_ui(&ui, NULL);
    /* Statistics > "EtherCAT cycles" in Wireshark (tshark -2 -z ecatr.cycles,tree) */
    stats_tree_register_plugin("frame", g_strdup_printf("%s.cycles", filter),
                               g_strdup_printf("%s cycles", proto_get_protocol_short_name(find_protocol_by_id(proto))),
                               0, st_packet, st_init, NULL);
}

} /* namespace dg_ecat */

/* The table walk behind every dissgen-generated dissector.
 *
 * Wireshark's exceptions are longjmps that skip C++ destructors, so nothing
 * here owns a non-trivial C++ object; memory comes from pinfo->pool. Every
 * read is checked against the bytes left first, so no tvb_ or proto_ call
 * can throw: malformed packets end in an expert info instead.
 */
#include "dissgen_runtime.h"

#include "dissgen_pairing.h"

#include <epan/proto_data.h>
#include <epan/stats_tree.h>
#include <epan/tap.h>

#include <string.h>

namespace {

struct dg_slot {
    guint64 value;
    gint offset;
    gint length;
    gboolean present;
    const dg_node *node;
};

/* One counted thing for the stats tree: an enum leaf's value, or how many
 * instances a repeated node had in this message. */
struct dg_tap_record {
    guint16 node;
    guint64 value;
};

struct dg_tap_data {
    dg_tap_record *records;
    guint count, capacity;
    const dg_frame_pairing *pairing; /* issue 11: what the pairing found, or NULL */
};

/* Each plugin links its own copy of the runtime and holds one protocol, so
 * the stats tree callbacks (which get no user pointer) find it here. */
const dg_protocol *stats_protocol;
int stats_tap = -1;

/* Summaries of one repeated node's instances, gathered for the Info column. */
struct dg_summaries {
    wmem_strbuf_t *text;
    guint count;
};

struct dg_state {
    const dg_protocol *p;
    tvbuff_t *tvb;
    packet_info *pinfo;
    dg_slot *slots;
    gint packet_end;      /* captured bytes */
    gboolean stopped;     /* a malformed spot was reported: decode nothing more */
    gboolean want_text;   /* summaries are shown: a visible tree, or columns */
    gboolean want_info;   /* the Info column is shown (pinfo->cinfo) */
    wmem_strbuf_t *info;  /* the Info column being built (want_info) */
    wmem_strbuf_t *text;  /* scratch for one container's summary (want_text) */
    guint64 group_value;  /* the bit group being decoded */
    guint32 hook_value;   /* pinfo->match_uint on entry: the hook (or Decode As) value, for ifhook */
    dg_tap_data *tap;     /* what the stats tree counts; NULL when nobody listens */
    /* issue 11: the values of the <pairing> key fields (DG_KEY), in decoding order */
    guint64 *keys;
    guint key_count, key_capacity;
};

void key_append(dg_state *st, guint64 value)
{
    if (st->key_count == st->key_capacity) {
        st->key_capacity = st->key_capacity ? 2 * st->key_capacity : 16;
        st->keys = (guint64 *)wmem_realloc(st->pinfo->pool, st->keys, st->key_capacity * sizeof(guint64));
    }
    st->keys[st->key_count++] = value;
}

void tap_record(dg_state *st, const dg_node *n, guint64 value)
{
    dg_tap_data *t = st->tap;
    if (t->count == t->capacity) {
        t->capacity = t->capacity ? 2 * t->capacity : 16;
        t->records = (dg_tap_record *)wmem_realloc(st->pinfo->pool, t->records, t->capacity * sizeof(dg_tap_record));
    }
    t->records[t->count].node = (guint16)(n - st->p->nodes);
    t->records[t->count].value = value;
    t->count++;
}

guint encoding_of(const dg_node *n) { return (n->flags & DG_LITTLE) ? ENC_LITTLE_ENDIAN : ENC_BIG_ENDIAN; }

guint64 read_uint(tvbuff_t *tvb, gint offset, guint length, guint encoding)
{
    switch (length) {
    case 1: return dg_tvb_get_uint8(tvb, offset);
    case 2: return dg_tvb_get_uint16(tvb, offset, encoding);
    case 3: return dg_tvb_get_uint24(tvb, offset, encoding);
    case 4: return dg_tvb_get_uint32(tvb, offset, encoding);
    case 5: return dg_tvb_get_uint40(tvb, offset, encoding);
    case 6: return dg_tvb_get_uint48(tvb, offset, encoding);
    case 7: return dg_tvb_get_uint56(tvb, offset, encoding);
    default: return dg_tvb_get_uint64(tvb, offset, encoding);
    }
}

guint64 bit_mask(guint bits) { return bits >= 64 ? G_MAXUINT64 : ((G_GUINT64_CONSTANT(1) << bits) - 1); }

/* Reports a malformed spot at `offset` (clamped into the packet) and stops decoding. */
void report(dg_state *st, proto_tree *tree, expert_field *ei, gint offset, gint length, const char *format, ...)
    G_GNUC_PRINTF(6, 7);

void report(dg_state *st, proto_tree *tree, expert_field *ei, gint offset, gint length, const char *format, ...)
{
    va_list ap;
    va_start(ap, format);
    char *text = wmem_strdup_vprintf(st->pinfo->pool, format, ap);
    va_end(ap);
    if (offset > st->packet_end) offset = st->packet_end;
    if (length < 0 || offset + length > st->packet_end) length = st->packet_end - offset;
    proto_tree_add_expert_format(tree, st->pinfo, ei, st->tvb, offset, length, "%s", text);
    st->stopped = TRUE;
}

/* The value of a length or count reference, or FALSE (reported) when it is
 * missing or negative. */
gboolean ref_value(dg_state *st, const dg_ref *ref, const dg_node *n, const char *what, proto_tree *tree,
                   gint offset, gint64 *out)
{
    const dg_slot *s = &st->slots[ref->slot];
    if (!s->present) {
        report(st, tree, &st->p->ei->bad_length, offset, 0, "The %s of '%s' comes from a field that is not in this packet",
               what, n->name);
        return FALSE;
    }
    /* Values beyond 2^31 are past any packet's end anyway; clamping there keeps
     * even "* 999999999" (the largest operand the generator accepts) in range. */
    gint64 v = s->value > (G_GUINT64_CONSTANT(1) << 31) ? (G_GINT64_CONSTANT(1) << 31) : (gint64)s->value;
    switch (ref->op) {
    case '+': v += ref->operand; break;
    case '-': v -= ref->operand; break;
    case '*': v *= ref->operand; break;
    default: break;
    }
    if (v < 0) {
        report(st, tree, &st->p->ei->bad_length, offset, 0, "The %s of '%s' is negative (%" G_GINT64_MODIFIER "d)",
               what, n->name, v);
        return FALSE;
    }
    *out = v;
    return TRUE;
}

void store(dg_state *st, const dg_node *n, guint64 value, gint offset, gint length)
{
    if (st->tap && n->show == DG_SHOW_ENUM) tap_record(st, n, value);
    if (n->flags & DG_KEY) key_append(st, value);
    if (n->slot < 0) return;
    dg_slot *s = &st->slots[n->slot];
    s->value = value;
    s->offset = offset;
    s->length = length;
    s->present = TRUE;
    s->node = n;
}

/* Whether store() uses a leaf's value: a later node reads it (slot) or the
 * stats tree counts it. Otherwise the walk need not read it from the tvb. */
gboolean value_wanted(const dg_state *st, const dg_node *n)
{
    return n->slot >= 0 || (st->tap && n->show == DG_SHOW_ENUM) || (n->flags & DG_KEY);
}

/* Whether value lies in one of the `count` ranges from ranges[first] on. */
gboolean in_ranges(const dg_protocol *p, guint16 first, guint16 count, guint64 value)
{
    for (guint i = 0; i < count; i++) {
        const dg_range *r = &p->ranges[first + i];
        if (value >= r->low && value <= r->high) return TRUE;
    }
    return FALSE;
}

gboolean condition_holds(const dg_state *st, const dg_node *n)
{
    const dg_slot *s = &st->slots[n->if_slot];
    return s->present && in_ranges(st->p, n->in_first, n->in_count, s->value);
}

/* Summary text is built with memcpy appends (wmem_strbuf_append copies with
 * g_strlcpy, byte by byte) and hand-made numbers instead of printf: it runs
 * for every instance of a summarised container. */
void append_str(wmem_strbuf_t *out, const char *text) { wmem_strbuf_append_len(out, text, strlen(text)); }

/* Same text as "%" G_GINT64_MODIFIER "u". */
void append_dec(wmem_strbuf_t *out, guint64 v)
{
    char buf[24];
    gsize i = sizeof buf;
    do {
        buf[--i] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    wmem_strbuf_append_len(out, buf + i, sizeof buf - i);
}

/* Same text as "0x%0*" G_GINT64_MODIFIER "x" with width `digits` (at most 16 used). */
void append_hex(wmem_strbuf_t *out, guint64 v, guint digits)
{
    static const char hex[] = "0123456789abcdef";
    char buf[2 + 16];
    gsize i = sizeof buf;
    guint n = 0;
    do {
        buf[--i] = hex[v & 0xf];
        v >>= 4;
        n++;
    } while (v);
    for (; n < digits && n < 16; n++) buf[--i] = '0';
    buf[--i] = 'x';
    buf[--i] = '0';
    wmem_strbuf_append_len(out, buf + i, sizeof buf - i);
}

/* Appends a leaf's value as its tree item shows it, for summaries. */
void append_shown_value(const dg_state *st, wmem_strbuf_t *out, const dg_slot *s)
{
    wmem_allocator_t *pool = st->pinfo->pool;
    const dg_node *n = s->node;
    switch (n->show) {
    case DG_SHOW_HEX:
        append_hex(out, s->value, (n->bits + 3) / 4);
        return;
    case DG_SHOW_BOOL:
        append_str(out, s->value ? "True" : "False");
        return;
    case DG_SHOW_ENUM: {
        header_field_info *hfi = proto_registrar_get_nth(*n->hf);
        const char *name = NULL;
        if (hfi->display & BASE_VAL64_STRING)
            name = try_val64_to_str(s->value, (const val64_string *)hfi->strings);
        else
            name = try_val_to_str((guint32)s->value, (const value_string *)hfi->strings);
        if (name) {
            append_str(out, name);
        } else {
            /* As the tree shows it: as many hex digits as the field's bits need. */
            wmem_strbuf_append_len(out, "Unknown (", 9);
            append_hex(out, s->value, (n->bits + 3) / 4);
            wmem_strbuf_append_len(out, ")", 1);
        }
        return;
    }
    /* An empty byte field (length 0 from a field, or 'rest' with nothing left)
     * shows nothing: tvb_bytes_to_str_punct() asserts len > 0. */
    case DG_SHOW_ADDRESS:
        if (s->length > 0) append_str(out, tvb_bytes_to_str_punct(pool, st->tvb, s->offset, s->length, ':'));
        return;
    case DG_SHOW_BYTES:
        if (s->length > 0) append_str(out, tvb_bytes_to_str_punct(pool, st->tvb, s->offset, s->length, ' '));
        return;
    default:
        if (n->flags & DG_NUMERIC)
            append_dec(out, s->value);
        else if (s->length > 0)
            append_str(out, tvb_bytes_to_str_punct(pool, st->tvb, s->offset, s->length, ' '));
        return;
    }
}

/* The summary of container n, in st->text (valid until the next summary). */
const char *summary_text(const dg_state *st, const dg_node *n)
{
    wmem_strbuf_t *out = st->text;
    wmem_strbuf_truncate(out, 0);
    for (guint i = 0; i < n->summary_count; i++) {
        const dg_summary_piece *piece = &st->p->pieces[n->summary_first + i];
        if (piece->slot < 0) {
            append_str(out, piece->text);
        } else {
            const dg_slot *s = &st->slots[piece->slot];
            if (s->present)
                append_shown_value(st, out, s);
            else
                wmem_strbuf_append_len(out, "-", 1);
        }
    }
    return wmem_strbuf_get_str(out);
}

void info_append(dg_state *st, const char *text, gsize len)
{
    if (wmem_strbuf_get_len(st->info) > 0) wmem_strbuf_append_len(st->info, ", ", 2);
    wmem_strbuf_append_len(st->info, text, len);
}

void dissect_list(dg_state *st, guint16 first, guint16 count, proto_tree *tree, gint *offset, gint end,
                  gboolean in_summary);

void dissect_bit_field(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end)
{
    if (n->flags & DG_GROUP_FIRST) {
        if ((gint)n->length > end - *offset) {
            report(st, tree, &st->p->ei->truncated, *offset, -1, "Truncated: '%s' needs %u bytes, only %d left",
                   n->name, n->length, end - *offset);
            return;
        }
        st->group_value = read_uint(st->tvb, *offset, n->length, encoding_of(n));
    }
    /* No tree (e.g. tshark's summary lines): only values later nodes read are
     * wanted. proto_tree_add_item() would check the length and return NULL. */
    if (tree) {
        proto_item *item = proto_tree_add_item(tree, *n->hf, st->tvb, *offset, n->length, encoding_of(n));
        if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
    }
    if (value_wanted(st, n)) store(st, n, (st->group_value >> n->shift) & bit_mask(n->bits), *offset, n->length);
    if (n->flags & DG_GROUP_LAST) *offset += n->length;
}

void dissect_leaf(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end)
{
    if (n->flags & DG_GROUP) {
        dissect_bit_field(st, n, tree, offset, end);
        return;
    }
    gint64 length = 0;
    switch (n->length_kind) {
    case DG_LEN_FIXED: length = n->length; break;
    case DG_LEN_FIELD:
        if (!ref_value(st, &n->length_ref, n, "length", tree, *offset, &length)) return;
        break;
    case DG_LEN_REST: length = end - *offset; break;
    default: length = 0; break;
    }
    gint left = end - *offset;
    if (length > left) {
        /* Show the bytes that are there, then say what is missing. */
        if (!(n->flags & DG_NUMERIC) && left > 0 && tree) {
            proto_item *item = proto_tree_add_item(tree, *n->hf, st->tvb, *offset, left, ENC_NA);
            if (n->flags & DG_HIDDEN) proto_item_set_hidden(item);
        }
        if (n->length_kind == DG_LEN_FIELD)
            report(st, tree, &st->p->ei->past_end, *offset, left,
                   "'%s' has length %" G_GINT64_MODIFIER "d, past the end of its data (%d bytes left)", n->name,
                   length, left);
        else
            report(st, tree, &st->p->ei->truncated, *offset, left,
                   "Truncated: '%s' needs %" G_GINT64_MODIFIER "d bytes, only %d left", n->name, length, left);
        return;
    }
    gint len = (gint)length;
    guint64 value = 0;
    proto_item *item = NULL;
    /* The value is read only when store() uses it, the item added only when
     * there is a tree. */
    if (n->flags & DG_NUMERIC) {
        if (value_wanted(st, n)) value = read_uint(st->tvb, *offset, (guint)len, encoding_of(n));
        if (tree) item = proto_tree_add_item(tree, *n->hf, st->tvb, *offset, len, encoding_of(n));
    } else if (len > 0 && tree) {
        item = proto_tree_add_item(tree, *n->hf, st->tvb, *offset, len, ENC_NA);
    }
    if (item && (n->flags & DG_HIDDEN)) proto_item_set_hidden(item);
    store(st, n, value, *offset, len);
    *offset += len;
}

void dissect_container(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end,
                       gboolean in_summary, dg_summaries *sink)
{
    gint start = *offset;
    gint64 length = -1;
    switch (n->length_kind) {
    case DG_LEN_FIXED: length = n->length; break;
    case DG_LEN_FIELD:
        if (!ref_value(st, &n->length_ref, n, "length", tree, start, &length)) return;
        break;
    case DG_LEN_REST: length = end - start; break;
    default: break;
    }
    gboolean past_end = length > end - start;
    gint inner_end = (length >= 0 && !past_end) ? start + (gint)length : end;

    proto_item *item = NULL;
    proto_tree *subtree = NULL;
    /* Length 0 now, the real length once the children are decoded: a length
     * of -1 would throw when the container starts at the end of the packet. */
    if (!tree) {
        /* nothing to add to */
    } else if (n->hf) {
        item = proto_tree_add_item(tree, *n->hf, st->tvb, start, 0, ENC_NA);
        subtree = proto_item_add_subtree(item, *n->ett);
    } else {
        subtree = proto_tree_add_subtree(tree, st->tvb, start, 0, *n->ett, &item, n->name);
    }
    if (past_end)
        report(st, subtree, n->length_kind == DG_LEN_FIELD ? &st->p->ei->past_end : &st->p->ei->truncated, start,
               end - start, "'%s' has length %" G_GINT64_MODIFIER "d, past the end of its data (%d bytes left)",
               n->name, length, end - start);
    /* Decode what is there even when the length overruns. */
    gboolean was_stopped = st->stopped;
    st->stopped = FALSE;
    dissect_list(st, n->first_child, n->child_count, subtree, offset, inner_end,
                 in_summary || n->summary_count > 0);
    st->stopped = st->stopped || was_stopped;
    if (!st->stopped && length >= 0 && *offset < inner_end &&
        (n->length_kind == DG_LEN_FIXED || n->length_kind == DG_LEN_FIELD)) {
        /* The length says more than the fields hold: say so, then skip to the end. */
        proto_tree_add_expert_format(subtree, st->pinfo, &st->p->ei->unused, st->tvb, *offset, inner_end - *offset,
                                     "'%s' is %" G_GINT64_MODIFIER "d bytes, but its fields end after %d: "
                                     "%d bytes are not decoded",
                                     n->name, length, *offset - start, inner_end - *offset);
    }
    if (!st->stopped && length >= 0) *offset = inner_end;
    proto_item_set_len(item, *offset - start);

    if (n->summary_count > 0 && st->want_text) {
        const char *text = summary_text(st, n);
        gsize text_len = wmem_strbuf_get_len(st->text);
        if (item) proto_item_append_text(item, ": %s", text);
        if (!in_summary && st->want_info) {
            if (sink) {
                if (sink->count++) wmem_strbuf_append_len(sink->text, ", ", 2);
                wmem_strbuf_append_len(sink->text, text, text_len);
            } else {
                info_append(st, text, text_len);
            }
        }
    }
}

void clear_slots(dg_state *st, const dg_node *n)
{
    if (n->slot_count) memset(&st->slots[n->slot_first], 0, n->slot_count * sizeof(dg_slot));
}

void dissect_instance(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end,
                      gboolean in_summary, dg_summaries *sink)
{
    if (n->kind == DG_LEAF)
        dissect_leaf(st, n, tree, offset, end);
    else
        dissect_container(st, n, tree, offset, end, in_summary, sink);
}

/* repeat: another instance while the flag is set; count: exactly N. Every
 * instance must consume bytes, which bounds the loop by the packet size. */
void dissect_repeated(dg_state *st, const dg_node *n, proto_tree *tree, gint *offset, gint end, gboolean in_summary)
{
    gint64 wanted = -1;
    if (n->count.slot >= 0 && !ref_value(st, &n->count, n, "count", tree, *offset, &wanted)) return;
    dg_summaries summaries = {NULL, 0};
    gboolean collect = !in_summary && n->summary_count > 0 && st->want_info;
    if (collect) summaries.text = wmem_strbuf_new(st->pinfo->pool, "");

    guint instances = 0;
    for (gint64 done = 0; wanted < 0 || done < wanted; done++) {
        if (wanted >= 0 && *offset >= end) {
            report(st, tree, &st->p->ei->count_short, *offset, 0,
                   "'%s' should occur %" G_GINT64_MODIFIER "d times, but the data ends after %" G_GINT64_MODIFIER "d",
                   n->name, wanted, done);
            st->stopped = FALSE; /* the data simply ended: siblings may still be empty-length */
            break;
        }
        clear_slots(st, n);
        gint before = *offset;
        dissect_instance(st, n, tree, offset, end, in_summary, collect ? &summaries : NULL);
        instances++;
        if (st->stopped || *offset == before) break;
        if (n->repeat_slot >= 0) {
            const dg_slot *flag = &st->slots[n->repeat_slot];
            if (!flag->present || flag->value == 0) break;
            if (*offset >= end) {
                report(st, tree, &st->p->ei->more_no_data, *offset, 0,
                       "'%s': the repeat flag '%s' says another follows, but no data is left", n->name,
                       flag->node->name);
                st->stopped = FALSE;
                break;
            }
        }
    }
    if (st->tap) tap_record(st, n, instances);
    if (collect && summaries.count > 1) {
        /* "NAME ×COUNT: SUMMARY, SUMMARY, ..." */
        if (wmem_strbuf_get_len(st->info) > 0) wmem_strbuf_append_len(st->info, ", ", 2);
        append_str(st->info, n->name);
        wmem_strbuf_append_len(st->info, " \xc3\x97", 3);
        append_dec(st->info, summaries.count);
        wmem_strbuf_append_len(st->info, ": ", 2);
        wmem_strbuf_append_len(st->info, wmem_strbuf_get_str(summaries.text), wmem_strbuf_get_len(summaries.text));
    } else if (collect && summaries.count == 1) {
        info_append(st, wmem_strbuf_get_str(summaries.text), wmem_strbuf_get_len(summaries.text));
    }
}

gboolean hook_holds(const dg_state *st, const dg_node *n)
{
    return in_ranges(st->p, n->hook_first, n->hook_count, st->hook_value);
}

void dissect_list(dg_state *st, guint16 first, guint16 count, proto_tree *tree, gint *offset, gint end,
                  gboolean in_summary)
{
    for (guint16 i = 0; i < count && !st->stopped; i++) {
        const dg_node *n = &st->p->nodes[st->p->children[first + i]];
        if (n->hook_count && !hook_holds(st, n)) continue;
        if (n->if_slot >= 0 && !condition_holds(st, n)) continue;
        if (n->count.slot >= 0 || n->repeat_slot >= 0)
            dissect_repeated(st, n, tree, offset, end, in_summary);
        else
            dissect_instance(st, n, tree, offset, end, in_summary, NULL);
    }
}

/* --- registration ------------------------------------------------------- */

struct dg_claim {
    const char *table;
    guint32 value;
    dissector_handle_t handle;
};

GArray *claims; /* of dg_claim: table entries this plugin must own */

/* Runs after every plugin's handoff and before Decode As choices (-d, the
 * profile's decode_as_entries) are applied: whatever the plugin load order,
 * our handle becomes the default for our values, and the other registrant
 * stays selectable in Decode As. */
void claim_tables(void)
{
    for (guint i = 0; claims && i < claims->len; i++) {
        const dg_claim *c = &g_array_index(claims, dg_claim, i);
        if (dissector_get_uint_handle(find_dissector_table(c->table), c->value) != c->handle)
            dissector_add_uint(c->table, c->value, c->handle);
    }
}

gboolean table_accepts_integers(const char *table)
{
    switch (get_dissector_table_selector_type(table)) {
    case FT_UINT8: case FT_UINT16: case FT_UINT24: case FT_UINT32: return TRUE;
    default: return FALSE;
    }
}

/* --- statistics: tshark -z FILTER,tree, Statistics menu in Wireshark ---- */

/* "Command (ecatr.datagram.cmd)": node names must be unique in the tree. */
const char *stats_node_name(const dg_node *n, const char *what)
{
    header_field_info *hfi = n->hf ? proto_registrar_get_nth(*n->hf) : NULL;
    return g_strdup_printf("%s%s (%s)", n->name, what, hfi ? hfi->abbrev : stats_protocol->filter);
}

int *stats_node_ids;       /* per node: its stats tree node, or 0 */
char **stats_node_names;   /* per node: that node's name, or NULL */
int stats_frames_id;

void stats_init(stats_tree *st)
{
    const dg_protocol *p = stats_protocol;
    guint n_nodes = p->node_count;
    g_free(stats_node_ids);
    if (stats_node_names) g_strfreev(stats_node_names);
    stats_node_ids = g_new0(int, n_nodes ? n_nodes : 1);
    stats_node_names = g_new0(char *, n_nodes + 1);
    stats_frames_id = stats_tree_create_node(st, "Messages", 0, STAT_DT_INT, FALSE);
    for (guint i = 0; i < n_nodes; i++) {
        const dg_node *n = &p->nodes[i];
        const char *what = NULL;
        if (n->count.slot >= 0 || n->repeat_slot >= 0) what = " per message";
        else if (n->kind == DG_LEAF && n->show == DG_SHOW_ENUM) what = "";
        if (!what) continue;
        stats_node_names[i] = (char *)stats_node_name(n, what);
        stats_node_ids[i] = stats_tree_create_node(st, stats_node_names[i], 0, STAT_DT_INT, TRUE);
    }
    if (p->pairing) dg_pairing_stats_init(p, st);
}

tap_packet_status stats_packet(stats_tree *st, packet_info *pinfo, epan_dissect_t *, const void *data, tap_flags_t)
{
    const dg_tap_data *t = (const dg_tap_data *)data;
    const dg_protocol *p = stats_protocol;
    tick_stat_node(st, "Messages", 0, FALSE);
    char buf[64];
    for (guint i = 0; i < t->count; i++) {
        const dg_tap_record *r = &t->records[i];
        const dg_node *n = &p->nodes[r->node];
        if (!stats_node_ids[r->node]) continue;
        const char *label = NULL;
        if (n->kind == DG_LEAF && n->show == DG_SHOW_ENUM && n->count.slot < 0 && n->repeat_slot < 0) {
            header_field_info *hfi = proto_registrar_get_nth(*n->hf);
            label = (hfi->display & BASE_VAL64_STRING) ? try_val64_to_str(r->value, (const val64_string *)hfi->strings)
                                                       : try_val_to_str((guint32)r->value, (const value_string *)hfi->strings);
            if (!label) {
                /* padded like the tree item: "Unknown (0x07)" for an 8-bit field */
                g_snprintf(buf, sizeof buf, "Unknown (0x%0*" G_GINT64_MODIFIER "x)", (int)((n->bits + 3) / 4), r->value);
                label = buf;
            }
        } else {
            g_snprintf(buf, sizeof buf, "%" G_GINT64_MODIFIER "u", r->value);
            label = buf;
        }
        tick_stat_node(st, stats_node_names[r->node], 0, TRUE);
        tick_stat_node(st, label, stats_node_ids[r->node], FALSE);
    }
    if (p->pairing) dg_pairing_stats_packet(p, st, pinfo, t->pairing);
    return TAP_PACKET_REDRAW;
}

void register_stats_tree(const dg_protocol *p)
{
    stats_protocol = p;
    stats_tap = register_tap(p->filter);
    stats_tree_register_plugin(p->filter, p->filter, p->name, 0, stats_packet, stats_init, NULL);
}

} /* namespace */

extern "C" {

gboolean dg_protocol_names_free(const dg_protocol *p)
{
    /* The very same protocol from another plugin (a packaged plugin and the
     * user's own build of the same rules): the first one registered wins, and
     * this one steps aside without a dialog at every start. */
    int same = proto_get_id_by_filter_name(p->filter);
    if (same != -1 && strcmp(proto_get_protocol_name(same), p->name) == 0 &&
        strcmp(proto_get_protocol_short_name(find_protocol_by_id(same)), p->short_name) == 0) {
        /* ws_log, not ws_info: that macro would compile the source path into the plugin */
        ws_log("dissgen", LOG_LEVEL_INFO, "\"%s\" (%s) is already registered by another plugin; this one steps aside",
               p->name, p->filter);
        return FALSE;
    }
    const char *what = NULL, *value = NULL;
    if (proto_get_id_by_filter_name(p->filter) != -1) {
        what = "filter name";
        value = p->filter;
    } else if (proto_get_id_by_short_name(p->short_name) != -1) {
        what = "abbreviation";
        value = p->short_name;
    } else if (proto_name_already_registered(p->name)) {
        what = "name";
        value = p->name;
    }
    if (!what) return TRUE;
    report_failure("The dissgen plugin for \"%s\" was not loaded: another protocol already has the %s \"%s\". "
                   "Change it in the rule file (<root %s=...>) and regenerate the plugin.",
                   p->name, what, value, strcmp(what, "abbreviation") == 0 || strcmp(what, "name") == 0 ? what : "filter");
    return FALSE;
}

void dg_register(dg_protocol *p, hf_register_info *hf, int hf_count, gint **ett, int ett_count,
                 ei_register_info *ei, int ei_count)
{
    *p->proto = proto_register_protocol(p->name, p->short_name, p->filter);
    proto_register_field_array(*p->proto, hf, hf_count);
    proto_register_subtree_array(ett, ett_count);
    expert_module_t *experts = expert_register_protocol(*p->proto);
    expert_register_field_array(experts, ei, ei_count);
    register_dissector(p->filter, p->dissect, *p->proto);
    register_stats_tree(p);
    if (p->pairing) dg_pairing_register(p);
}

void dg_handoff(const dg_protocol *p)
{
    if (*p->proto == -1) return; /* not registered: its names were taken */
    dissector_handle_t handle = find_dissector(p->filter);
    dissector_handle_t stream = p->dissect_stream ? create_dissector_handle(p->dissect_stream, *p->proto) : NULL;
    if (!claims) {
        claims = g_array_new(FALSE, FALSE, sizeof(dg_claim));
        register_final_registration_routine(claim_tables);
    }
    for (guint i = 0; i < p->hook_count; i++) {
        const dg_hook *h = &p->hooks[i];
        if (!find_dissector_table(h->table) || !table_accepts_integers(h->table)) {
            report_failure("The dissgen plugin for \"%s\" cannot hook into \"%s\": Wireshark has no integer "
                           "dissector table of that name. The hook is ignored.", p->name, h->table);
            continue;
        }
        dissector_handle_t h_handle = (stream && strcmp(h->table, "tcp.port") == 0) ? stream : handle;
        dissector_add_uint(h->table, h->value, h_handle);
        dg_claim c = {h->table, h->value, h_handle};
        g_array_append_val(claims, c);
    }
}

/* Key of the per-packet count of messages decoded (p_add_proto_data). */
#define DG_MESSAGES_KEY 0x6d736773u

int dg_dissect(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    col_set_str(pinfo->cinfo, COL_PROTOCOL, p->short_name);
    /* Several messages in one packet (a TCP segment): each adds its Info text. */
    guint *messages = (guint *)p_get_proto_data(pinfo->pool, pinfo, *p->proto, DG_MESSAGES_KEY);
    if (!messages) {
        messages = wmem_new0(pinfo->pool, guint);
        p_add_proto_data(pinfo->pool, pinfo, *p->proto, DG_MESSAGES_KEY, messages);
    }
    gboolean first_message = (*messages)++ == 0;
    if (first_message) col_clear(pinfo->cinfo, COL_INFO);

    dg_state st;
    memset(&st, 0, sizeof st);
    st.p = p;
    st.tvb = tvb;
    st.pinfo = pinfo;
    st.slots = wmem_alloc0_array(pinfo->pool, dg_slot, p->slot_count ? p->slot_count : 1);
    st.packet_end = (gint)tvb_captured_length(tvb);
    st.hook_value = pinfo->match_uint;
    /* Summaries are text for the Info column and for container items; build
     * them only when someone sees them: tshark -T fields and -V have a visible
     * tree and no columns, summary lines have columns and no tree, and a
     * filter-only pass (-Y with -w) has neither. */
    st.want_info = pinfo->cinfo != NULL;
    st.want_text = st.want_info || (tree != NULL && PTREE_DATA(tree)->visible);
    st.info = st.want_info ? wmem_strbuf_new(pinfo->pool, "") : NULL;
    st.text = st.want_text ? wmem_strbuf_new(pinfo->pool, "") : NULL;
    if (stats_tap >= 0 && have_tap_listener(stats_tap)) st.tap = wmem_new0(pinfo->pool, dg_tap_data);

    proto_item *root = proto_tree_add_item(tree, *p->proto, tvb, 0, 0, ENC_NA);
    proto_tree *subtree = proto_item_add_subtree(root, *p->ett);
    gint offset = 0;
    dissect_list(&st, p->top_first, p->top_count, subtree, &offset, st.packet_end, FALSE);
    proto_item_set_len(root, offset);
    if (p->pairing) {
        const dg_frame_pairing *fp =
            dg_pairing_dissect(p, tvb, pinfo, subtree, st.keys, st.key_count, offset, *messages - 1);
        if (st.tap) st.tap->pairing = fp;
    }

    if (st.tap) tap_queue_packet(stats_tap, pinfo, st.tap);
    const char *info = st.info && wmem_strbuf_get_len(st.info) > 0 ? wmem_strbuf_get_str(st.info) : p->name;
    if (first_message)
        col_add_str(pinfo->cinfo, COL_INFO, info);
    else
        col_append_sep_str(pinfo->cinfo, COL_INFO, " | ", info);
    return offset > 0 ? offset : st.packet_end;
}

} /* extern "C" */

/* --- stream transports -------------------------------------------------- */

namespace {

guint message_length(packet_info *, tvbuff_t *tvb, int offset, void *data)
{
    const dg_protocol *p = (const dg_protocol *)data;
    const dg_node *n = &p->nodes[p->pdu_node];
    guint64 value = read_uint(tvb, offset + (gint)p->pdu_offset, n->length, encoding_of(n));
    if (n->flags & DG_GROUP) value = (value >> n->shift) & bit_mask(n->bits);
    gint64 total = (gint64)MIN(value, (guint64)G_MAXINT32) + p->pdu_add;
    /* A length shorter than the length field itself cannot make progress. */
    gint64 minimum = (gint64)(p->pdu_offset + n->length);
    return (guint)CLAMP(total, minimum, (gint64)G_MAXINT32);
}

int dissect_message(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data)
{
    return dg_dissect((const dg_protocol *)data, tvb, pinfo, tree);
}

} /* namespace */

extern "C" int dg_dissect_stream(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree)
{
    const dg_node *n = &p->nodes[p->pdu_node];
    tcp_dissect_pdus(tvb, pinfo, tree, TRUE, p->pdu_offset + n->length, message_length, dissect_message, (void *)p);
    return (int)tvb_captured_length(tvb);
}

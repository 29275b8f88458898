// SPDX-License-Identifier: GPL-2.0-or-later
/* What a generated plugin does once, at start-up: check that its names are
 * free, register the protocol, its fields and expert infos, hook into
 * dissector tables (and keep its entries the default whatever the plugin
 * load order), and the statistics tree (tshark -z FILTER,tree, Wireshark's
 * Statistics menu) that counts what the walk records.
 *
 * Each plugin links its own copy of the runtime and holds one protocol, so
 * the callbacks that get no user pointer find it in this file's globals.
 * Like the whole runtime: no non-trivial C++ object (Wireshark's exceptions
 * are longjmps).
 */
#include "dissgen_state.h"
#include "dissgen_validity.h"

#include <epan/stats_tree.h>
#include <epan/tap.h>

#include <string.h>

int dg_rt::stats_tap = -1;

using namespace dg_rt;

namespace {

/* --- hand-off tables ------------------------------------------------------ */

struct dg_claim {
    const char *table;
    guint32 value;
    dissector_handle_t handle;
    int proto;
    dissector_handle_t displaced; /* the other registrant of the value (built in or a plugin), or NULL */
    dissector_handle_t placed;    /* what this plugin last put in the table */
};

GArray *claims; /* of dg_claim: table entries this plugin must own */

/* This plugin's protocol once handed off, for the dissectors its leaves name. */
const dg_protocol *handed_off;

/* Runs after every plugin's handoff: each dissgen protocol registers its
 * dissector name at its own handoff (dissgen_compat.h), so one named by
 * another rule file's dissector= exists only once every plugin is handed off. */
void find_dissectors_named(void)
{
    if (handed_off) find_handoff_dissectors(handed_off);
}

/* The other registrant of a value, or NULL when there is none or it is this
 * protocol itself (a value hooked twice, or its TCP stream entry beside its
 * plain one): a refused message must never come back to us. */
dissector_handle_t other_than(dissector_handle_t h, int proto)
{
    return h && dissector_handle_get_protocol_index(h) != proto ? h : NULL;
}

/* Runs after every plugin's handoff and before Decode As choices (-d, the
 * profile's decode_as_entries) are applied: whatever the plugin load order,
 * our handle becomes the default for our values, and the other registrant
 * stays selectable in Decode As. */
void claim_tables(void)
{
    for (guint i = 0; claims && i < claims->len; i++) {
        dg_claim *c = &g_array_index(claims, dg_claim, i);
        dissector_handle_t now = dissector_get_uint_handle(find_dissector_table(c->table), c->value);
        if (now != c->handle) {
            if (other_than(now, c->proto)) c->displaced = now;
            dissector_add_uint(c->table, c->value, c->handle);
        }
        c->placed = c->handle;
    }
}

/* Before each capture is read, once the enabled protocols are known (tshark
 * --disable-protocol, the GUI's Enabled Protocols): with our protocol
 * disabled the value goes back to the dissector it displaced, so that
 * disabling ours selects Wireshark's, and to ours again once it is enabled.
 * A Decode As choice (anything we did not place) is left alone. */
void follow_enabled_protocols(void)
{
    for (guint i = 0; claims && i < claims->len; i++) {
        dg_claim *c = &g_array_index(claims, dg_claim, i);
        if (!c->displaced || !c->placed) continue;
        if (dissector_get_uint_handle(find_dissector_table(c->table), c->value) != c->placed) continue;
        dissector_handle_t want = proto_is_protocol_enabled(find_protocol_by_id(c->proto)) ? c->handle : c->displaced;
        if (want == c->placed) continue;
        dissector_add_uint(c->table, c->value, want);
        c->placed = want;
    }
}

/* Whether a message of transport `ptype` could have come through `table`:
 * a port table only on its own transport, any other table on any. */
gboolean came_through(const char *table, port_type ptype, gboolean port_tables)
{
    const port_type own = strcmp(table, "udp.port") == 0   ? PT_UDP
                          : strcmp(table, "tcp.port") == 0 ? PT_TCP
                          : strcmp(table, "sctp.port") == 0 ? PT_SCTP
                                                           : PT_NONE;
    return port_tables ? own != PT_NONE && own == ptype : own == PT_NONE;
}

gboolean table_accepts_integers(const char *table)
{
    switch (get_dissector_table_selector_type(table)) {
    case FT_UINT8: case FT_UINT16: case FT_UINT24: case FT_UINT32: return TRUE;
    default: return FALSE;
    }
}

} // namespace

int dg_displaced_dissect(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data)
{
    /* A port table of the message's own transport first: a protocol hooked
     * on UDP and TCP port 3671 gives each its own displaced dissector. */
    for (int port_tables = 1; port_tables >= 0; port_tables--)
        for (guint i = 0; claims && i < claims->len; i++) {
            const dg_claim *c = &g_array_index(claims, dg_claim, i);
            if (c->displaced && c->value == pinfo->match_uint && came_through(c->table, pinfo->ptype, port_tables))
                return call_dissector_only(c->displaced, tvb, pinfo, tree, data);
        }
    return 0;
}

namespace {

/* --- statistics: tshark -z FILTER,tree, Statistics menu in Wireshark ---- */

/* The protocol the stats tree callbacks (which get no user pointer) count for. */
const dg_protocol *stats_protocol;

/* "Command (ecatr.datagram.cmd)": node names must be unique in the tree. */
const char *stats_node_name(const dg_node *n, const char *what)
{
    header_field_info *hfi = n->hf ? proto_registrar_get_nth(*n->hf) : NULL;
    char *name = stats_top_name(n->name);
    char *shown = g_strdup_printf("%s%s (%s)", name, what, hfi ? hfi->abbrev : stats_protocol->filter);
    g_free(name);
    return shown;
}

char **stats_node_names;   /* per node: that node's name, or NULL (no statistics) */
int stats_frames_id;
/* per node: a repeated node's instances in the message being counted, and
 * whether its row was ticked; back to 0 after each message */
guint64 *stats_instances;
gboolean *stats_ticked;

void stats_init(stats_tree *st)
{
    const dg_protocol *p = stats_protocol;
    guint n_nodes = p->node_count;
    if (stats_node_names) g_strfreev(stats_node_names);
    stats_node_names = g_new0(char *, n_nodes + 1);
    g_free(stats_instances);
    g_free(stats_ticked);
    stats_instances = g_new0(guint64, n_nodes);
    stats_ticked = g_new0(gboolean, n_nodes);
    stats_frames_id = stats_tree_create_node(st, "Messages", 0, STAT_DT_INT, FALSE);
    for (guint i = 0; i < n_nodes; i++) {
        const dg_node *n = &p->nodes[i];
        const char *what = NULL;
        if (is_repeated(n)) what = " per message";
        else if (n->kind == DG_LEAF && n->show == DG_SHOW_ENUM) what = "";
        if (!what) continue;
        /* The node itself appears with its first count: no rows of zeros. */
        stats_node_names[i] = (char *)stats_node_name(n, what);
    }
    if (p->pairing) dg_pairing_stats_init(p, st);
}

tap_packet_status stats_packet(stats_tree *st, packet_info *pinfo, epan_dissect_t *, const void *data, tap_flags_t)
{
    const dg_tap_data *t = (const dg_tap_data *)data;
    const dg_protocol *p = stats_protocol;
    tick_stat_node(st, "Messages", 0, FALSE);
    char buf[64];
    /* A repeated node inside another repeat is recorded once per instance of
     * the outer one: its instances per message are the sum of its records. */
    guint64 *per_message = stats_instances;
    gboolean *seen = stats_ticked;
    for (guint i = 0; i < t->count; i++)
        if (is_repeated(&p->nodes[t->records[i].node])) per_message[t->records[i].node] += t->records[i].value;
    for (guint i = 0; i < t->count; i++) {
        const dg_tap_record *r = &t->records[i];
        const dg_node *n = &p->nodes[r->node];
        if (!stats_node_names[r->node]) continue;
        const char *label = NULL;
        if (is_repeated(n)) {
            if (seen[r->node]) continue; /* ticked at its first record, with the sum */
            seen[r->node] = TRUE;
            g_snprintf(buf, sizeof buf, "%" G_GINT64_MODIFIER "u", per_message[r->node]);
            label = buf;
        } else if (n->kind == DG_LEAF && n->show == DG_SHOW_ENUM) {
            header_field_info *hfi = proto_registrar_get_nth(*n->hf);
            label = enum_name(hfi, r->value);
            if (!label) {
                /* padded like the tree item: "Unknown (0x07)" for an 8-bit field */
                g_snprintf(buf, sizeof buf, "Unknown (0x%0*" G_GINT64_MODIFIER "x)", (int)hex_digits(n, r->value), r->value);
                label = buf;
            }
        } else {
            g_snprintf(buf, sizeof buf, "%" G_GINT64_MODIFIER "u", r->value);
            label = buf;
        }
        int id = tick_stat_node(st, stats_node_names[r->node], 0, TRUE);
        tick_stat_node(st, label, id, FALSE);
    }
    for (guint i = 0; i < t->count; i++) {
        per_message[t->records[i].node] = 0;
        seen[t->records[i].node] = FALSE;
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

} // namespace

/* --- registration --------------------------------------------------------- */

/* Whether the protocol registered as `filter` is a dissgen plugin's: every one
 * has the runtime's own expert infos (a dissector of Wireshark's, built in
 * or a plugin, has not). */
static gboolean registered_by_dissgen(const char *filter)
{
    char *marker = g_strdup_printf("%s.expert.truncated", filter);
    const gboolean ours = proto_registrar_get_byname(marker) != NULL;
    g_free(marker);
    return ours;
}

gboolean dg_protocol_names_free(const dg_protocol *p)
{
    /* The very same protocol from another dissgen plugin (a packaged plugin and
     * the user's own build of the same rules): the first one registered wins,
     * and this one steps aside without a dialog at every start. A dissector of
     * Wireshark's with the same three names is a clash, told below. */
    int same = proto_get_id_by_filter_name(p->filter);
    if (same != -1 && strcmp(proto_get_protocol_name(same), p->name) == 0 &&
        strcmp(proto_get_protocol_short_name(find_protocol_by_id(same)), p->short_name) == 0 &&
        registered_by_dissgen(p->filter)) {
        /* ws_log, not ws_info: that macro would compile the source path into the plugin */
        ws_log("dissgen", LOG_LEVEL_INFO, "\"%s\" (%s) is already registered by another plugin; this one steps aside",
               p->name, p->filter);
        return FALSE;
    }
    /* Every name taken, in one message: Wireshark refuses any one of them. */
    struct taken {
        const char *what, *value, *attribute;
    } clashes[3];
    guint n = 0;
    if (proto_get_id_by_filter_name(p->filter) != -1) clashes[n++] = {"filter name", p->filter, "filter"};
    if (proto_get_id_by_short_name(p->short_name) != -1)
        clashes[n++] = {"abbreviation", p->short_name, "abbreviation"};
    if (proto_name_already_registered(p->name)) clashes[n++] = {"name", p->name, "name"};
    if (n == 0) return TRUE;
    GString *names = g_string_new(NULL), *attributes = g_string_new(NULL);
    for (guint i = 0; i < n; i++) {
        g_string_append_printf(names, "%s%s \"%s\"", i == 0 ? "" : i + 1 == n ? " and the " : ", the ",
                               clashes[i].what, clashes[i].value);
        g_string_append_printf(attributes, "%s%s=...", i == 0 ? "" : " ", clashes[i].attribute);
    }
    report_failure("The dissgen plugin for \"%s\" was not loaded: another protocol already has the %s. "
                   "Change %s in the rule file (<root %s>) and regenerate the plugin.",
                   p->name, names->str, n == 1 ? "it" : "them", attributes->str);
    g_string_free(names, TRUE);
    g_string_free(attributes, TRUE);
    return FALSE;
}

void dg_name_fields(hf_register_info *hf, const char *const *names, guint count, const char *filter)
{
    for (guint i = 0; i < count; i++) hf[i].hfinfo.abbrev = g_strdup_printf("%s.%s", filter, names[i]);
}

void dg_name_experts(ei_register_info *ei, const char *const *names, guint count, const char *filter)
{
    for (guint i = 0; i < count; i++) ei[i].eiinfo.name = g_strdup_printf("%s.%s", filter, names[i]);
}

void dg_register(dg_protocol *p, hf_register_info *hf, int hf_count, gint **ett, int ett_count,
                 ei_register_info *ei, int ei_count)
{
    *p->proto = proto_register_protocol(p->name, p->short_name, p->filter);
    proto_register_field_array(*p->proto, hf, hf_count);
    /* Wireshark keeps a pointer to it: a static array, a name that lives until exit. */
    static hf_register_info runtime_hf[] = {DG_RUNTIME_FIELDS(DG_HF_ROW)};
    static const char *const names[] = {DG_RUNTIME_FIELDS(DG_FIELD_NAME)};
    dg_name_fields(runtime_hf, names, G_N_ELEMENTS(runtime_hf), p->filter);
    proto_register_field_array(*p->proto, runtime_hf, (int)G_N_ELEMENTS(runtime_hf));
    proto_register_subtree_array(ett, ett_count);
    expert_module_t *experts = expert_register_protocol(*p->proto);
    expert_register_field_array(experts, ei, ei_count);
    register_dissector(p->filter, p->dissect, *p->proto);
    register_stats_tree(p);
    if (p->reassembly) reassembly_table_register(p->reassembly, &addresses_reassembly_table_functions);
    if (p->pairing) dg_pairing_register(p);
    if (p->cycles && !dg_analysis_times_cycles(p)) dg_cycles_register(p);
    learned_register(p);
    /* To compare the compiled walks with the table walk (dissgen_state.h). */
    table_walk_only = g_getenv("DISSGEN_TABLE_WALK") != NULL;
}

/* Handoff: the protocol's hooks, the dissectors its leaves hand bytes to. */
void dg_handoff(const dg_protocol *p)
{
    if (*p->proto == -1) return; /* not registered: its names were taken */
    dissector_handle_t handle = find_dissector(p->filter);
    dissector_handle_t stream = p->dissect_stream ? create_dissector_handle(p->dissect_stream, *p->proto) : NULL;
    if (!claims) {
        claims = g_array_new(FALSE, FALSE, sizeof(dg_claim));
        register_final_registration_routine(claim_tables);
        register_final_registration_routine(find_dissectors_named);
        register_init_routine(follow_enabled_protocols);
    }
    handed_off = p;
    for (guint i = 0; i < p->hook_count; i++) {
        const dg_hook *h = &p->hooks[i];
        if (!find_dissector_table(h->table) || !table_accepts_integers(h->table)) {
            report_failure("The dissgen plugin for \"%s\" cannot hook into \"%s\": Wireshark has no integer "
                           "dissector table of that name. The hook is ignored.", p->name, h->table);
            continue;
        }
        dissector_handle_t h_handle = (stream && strcmp(h->table, "tcp.port") == 0) ? stream : handle;
        /* Dissectors built into libwireshark (POWERLINK on 0x88AB) took their
         * values before any plugin's handoff: recorded now, before ours
         * replaces them, so that disabling ours gives the value back. Later
         * plugins' entries are recorded by claim_tables. */
        dissector_handle_t builtin =
            other_than(dissector_get_uint_handle(find_dissector_table(h->table), h->value), *p->proto);
        dissector_add_uint(h->table, h->value, h_handle);
        dg_claim c = {h->table, h->value, h_handle, *p->proto, builtin, NULL};
        g_array_append_val(claims, c);
    }
}


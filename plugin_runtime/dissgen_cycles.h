/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Periodic traffic declared by <cycles> in the rule file, for any protocol
 * (docs/manual.md, "Cycles of any protocol"): the messages of one stream
 * (the same values of the signature fields, and sender) are timed, and
 * those that come at a regular period are a cycle, with its period and
 * jitter; a sequence count adds the messages lost and repeated.
 *
 * Worked out once, on the first pass, from what the walk decoded (the
 * leaves whose dg_extra.cycle_role is set), and kept per message in
 * Wireshark's per-capture memory, so that later passes (tshark -2, the GUI
 * in any order) show the same items. */
#pragma once

#include "dissgen_runtime.h"
#include "dissgen_values.h"

/* What the walk decoded of one message for <cycles> (first pass). */
typedef struct dg_cycle_input {
    guint64 *values;           /* the signature fields' values, in decoding order */
    guint16 *nodes;            /* the node of each (dg_protocol.nodes), for the stream's name */
    /* a text, address or bytes field's bytes, compared byte for byte (its
     * value is their hash); NULL for a number */
    const guint8 **bytes;
    guint32 *lengths;
    guint count;
    guint64 sequence;
    gboolean has_sequence;
    guint32 only_held;         /* bit i: <only> test i held */
    gboolean never;            /* a <never> test held */
} dg_cycle_input;

/* Whether a message belongs to a stream: a signature field was decoded,
 * every <only> test held and no <never> test did. */
static inline gboolean dg_cycle_input_in_stream(const dg_cycles *c, const dg_cycle_input *in)
{
    const guint32 all_only = c->only_count >= 32 ? G_MAXUINT32 : ((guint32)1 << c->only_count) - 1;
    return in->count && !in->never && (in->only_held & all_only) == all_only;
}

/* The 32-bit hash of a message's signature values and their nodes (a
 * stream's, before its sender is added). */
static inline guint32 dg_cycle_input_hash(const dg_cycle_input *in)
{
    guint32 h = 2166136261u;
    for (guint i = 0; i < in->count; i++) h = dg_rt::hash_mix(h, in->values[i] ^ ((guint64)in->nodes[i] << 48));
    return h;
}

extern "C" {

/* At registration: the fields, expert infos, -z P,cycles and the
 * statistics tree, and the per-capture init/cleanup routines. */
void dg_cycles_register(const dg_protocol *p);

/* After a message was decoded: on the first pass (`in` given) times it in
 * its stream; on every pass shows what was found in `tree` (the expert infos
 * also without a tree). `fp`: what the pairing found for the message (NULL
 * without one), which requests="yes" reads. `message`: its number within the
 * frame (0 first). */
void dg_cycles_dissect(const dg_protocol *p, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree,
                       const dg_cycle_input *in, const struct dg_frame_pairing *fp, guint message);
}

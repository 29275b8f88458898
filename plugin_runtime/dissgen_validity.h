// SPDX-License-Identifier: GPL-2.0-or-later
/* Whose message is it: valid="LIST" fields and <heuristic> registration.
 *
 * A message belongs to the protocol only when every valid field (a numeric
 * leaf at a fixed offset from the start of the message) holds a value of its
 * list; a message too short to hold one is not the protocol's either. The
 * test reads bytes only, before anything is added to the tree, so a dissector
 * that fails it returns 0 and Wireshark goes on to the next one (another
 * heuristic, or data). Generated code gives a dg_validity only to protocols
 * with valid fields or heuristics; the others call dg_dissect directly and
 * pay nothing for it.
 */
#pragma once

#include "dissgen_runtime.h"

/* One valid field: its value is read from `length` bytes (a bit field: its
 * group's) `offset` bytes into the message; bits > 0: a bit field, `bits`
 * wide, `shift` bits up. in_*: its list in dg_validity.ranges; hook_count > 0:
 * tested only in messages whose hook value (pinfo->match_uint) is in
 * ranges[hook_first ..] (the field's 'ifhook' containers). */
typedef struct dg_valid_field {
    guint32 offset;
    guint8 length;
    guint8 little;
    guint8 shift, bits;
    guint16 in_first, in_count;
    guint16 hook_first, hook_count;
} dg_valid_field;

/* <heuristic table="LIST" enabled="..."/> */
typedef struct dg_heuristic {
    const char *list;          /* Wireshark heuristic list: "udp", "tcp", "eth", ... */
    const char *short_name;    /* --enable-heuristic / --disable-heuristic name: FILTER_LIST */
    const char *display_name;  /* shown in Enabled Protocols */
    gboolean enabled;          /* enabled by default */
} dg_heuristic;

typedef struct dg_validity {
    const dg_protocol *p;
    const dg_valid_field *fields;
    guint16 field_count;
    const dg_range *ranges;
    guint32 header_length;     /* stream: bytes needed for the valid fields and the pdulength field */
    const dg_heuristic *heuristics;
    guint16 heuristic_count;
    heur_dissector_t heuristic; /* the generated entry, calling dg_valid_heuristic */
} dg_validity;

extern "C" {

/* TRUE when the `available` bytes at `offset` hold every valid field that
 * applies to this message and each value is in its list. */
gboolean dg_valid_at(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, gint offset, gint available);

/* dg_dissect for a message that passes the test. One that fails goes to the
 * dissector our hook displaced on the value it came through (Wireshark's
 * own for that port), as if this protocol were not there; 0 when there is
 * none, or it takes nothing. */
int dg_valid_dissect(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data);

/* dg_dissect_stream that claims a segment only when the message it starts
 * with passes the test: a bad header starts no reassembly (and the segment
 * goes to the displaced dissector, as above). A message inside the segment
 * that fails ends its messages; the rest is data. */
int dg_valid_dissect_stream(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data);

/* The heuristic: TRUE (and the message dissected) when the test passes. */
gboolean dg_valid_heuristic(const dg_validity *v, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree);

/* Registers the heuristics on their lists (after dg_handoff); a list the
 * running Wireshark does not have is reported and skipped. */
void dg_validity_handoff(const dg_validity *v);

}

/* A message refused on a hooked value: the dissector this plugin's hook
 * displaced on the table and value it came through (pinfo->match_uint, the
 * port table of its transport) dissects it; 0 when there is none
 * (dissgen_register.cpp, which keeps the hooks). */
int dg_displaced_dissect(tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, void *data);

// SPDX-License-Identifier: GPL-2.0-or-later
/* Item labels built without printf. Wireshark formats a label
 * with g_vsnprintf, which costs over a thousand instructions for a few
 * conversions; these appends cost tens, and the text then goes in as "%s".
 * Labels longer than Wireshark's ITEM_LABEL_LENGTH are cut, as Wireshark
 * would cut them. */
#pragma once

#include "dissgen_compat.h"

#include <string.h>

typedef struct dg_label {
    char text[ITEM_LABEL_LENGTH];
    gsize len;
} dg_label;

static inline void dg_label_str(dg_label *l, const char *s)
{
    while (*s && l->len + 1 < sizeof l->text) l->text[l->len++] = *s++;
    l->text[l->len] = '\0';
}

/* As "%" G_GINT64_MODIFIER "u". */
static inline void dg_label_uint(dg_label *l, guint64 v)
{
    char digits[24];
    gsize i = sizeof digits - 1;
    digits[i] = '\0';
    do {
        digits[--i] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    dg_label_str(l, digits + i);
}

/* As "%d", or "%+d" with `plus`. */
static inline void dg_label_int(dg_label *l, gint64 v, gboolean plus)
{
    if (v < 0) dg_label_str(l, "-");
    else if (plus) dg_label_str(l, "+");
    dg_label_uint(l, v < 0 ? (guint64)0 - (guint64)v : (guint64)v);
}

/* Sets item's label to "name" or, with a summary, "name: summary": what
 * proto_item_set_text() with "%s" or "%s: %s" would write, without its
 * g_vsnprintf (about 900 instructions, most of a container's cost in -V).
 * As there, nothing is written in a tree nobody sees, nor on a hidden item.
 * FALSE when the label does not fit ITEM_LABEL_LENGTH: the caller then asks
 * Wireshark, which cuts it its own way. */
static inline gboolean dg_set_label(proto_item *item, const char *name, const char *summary)
{
    if (!item || !PTREE_DATA(item)->visible || proto_item_is_hidden(item)) return TRUE;
    field_info *fi = PITEM_FINFO(item);
    if (!fi) return TRUE;
    gsize name_len = strlen(name);
    gsize summary_len = summary ? strlen(summary) : 0;
    if (name_len + (summary ? 2 + summary_len : 0) >= ITEM_LABEL_LENGTH) return FALSE;
    item_label_t *rep = fi->rep;
    if (!rep) {
        rep = wmem_new(PNODE_POOL(item), item_label_t);
        /* Wireshark versions whose labels hold more than the text: zeros there. */
        if (sizeof(item_label_t) > ITEM_LABEL_LENGTH)
            memset((char *)rep + ITEM_LABEL_LENGTH, 0, sizeof(item_label_t) - ITEM_LABEL_LENGTH);
    }
    char *at = rep->representation;
    memcpy(at, name, name_len);
    at += name_len;
    if (summary) {
        *at++ = ':';
        *at++ = ' ';
        memcpy(at, summary, summary_len);
        at += summary_len;
    }
    *at = '\0';
    fi->rep = rep;
    return TRUE;
}

// SPDX-License-Identifier: GPL-2.0-or-later
/* Item labels built without printf. Wireshark formats a label
 * with g_vsnprintf, which costs over a thousand instructions for a few
 * conversions; these appends cost tens, and the text then goes in as "%s".
 * Labels longer than Wireshark's ITEM_LABEL_LENGTH are cut, as Wireshark
 * would cut them. */
#pragma once

#include "dissgen_compat.h"

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

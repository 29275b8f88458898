// SPDX-License-Identifier: GPL-2.0-or-later
/* Text being built (summaries, the Info column, instance names): a buffer of
 * the caller's (on its stack) or in the packet pool, moved to the pool when
 * it outgrows it, with inline appends and hand-made numbers.
 * wmem_strbuf_new(), its appends and printf cost several times more, and
 * summary lines run this on every frame.
 *
 * No per-message state: the unit tests call it directly
 * (tests/unit/test_runtime.cpp). The appends are static inline so that
 * every runtime source inlines them into its loops.
 */
#pragma once

#include "dissgen_compat.h"

#include <string.h>

namespace dg_rt __attribute__((visibility("hidden"))) {

struct dg_text {
    wmem_allocator_t *pool;
    char *data;   /* NUL-terminated */
    gsize len, cap;
};

/* A text in `buf` (the caller's, usually on its stack) until it outgrows it. */
static inline void text_init(dg_text *t, wmem_allocator_t *pool, char *buf, gsize cap)
{
    t->pool = pool;
    t->data = buf;
    t->data[0] = '\0';
    t->len = 0;
    t->cap = cap;
}

/* One allocation: the struct and a first buffer that most texts never outgrow. */
static inline dg_text *text_new(wmem_allocator_t *pool)
{
    const gsize first = 120;
    dg_text *t = (dg_text *)wmem_alloc(pool, sizeof(dg_text) + first);
    text_init(t, pool, (char *)(t + 1), first);
    return t;
}

/* Room for n more bytes and the NUL, in the pool (dissgen_text.cpp; seldom run). */
void text_grow(dg_text *t, gsize n);

/* Inlined: it runs for every piece of every summary. */
static inline __attribute__((always_inline)) void text_append(dg_text *t, const char *s, gsize n)
{
    if (G_UNLIKELY(t->len + n >= t->cap)) text_grow(t, n);
    memcpy(t->data + t->len, s, n);
    t->len += n;
    t->data[t->len] = '\0';
}

static inline void text_truncate(dg_text *t, gsize len)
{
    if (len < t->len) {
        t->len = len;
        t->data[len] = '\0';
    }
}

static inline void append_str(dg_text *out, const char *text) { text_append(out, text, strlen(text)); }

/* Same text as "%" G_GINT64_MODIFIER "u". */
static inline void append_dec(dg_text *out, guint64 v)
{
    char buf[24];
    gsize i = sizeof buf;
    do {
        buf[--i] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    text_append(out, buf + i, sizeof buf - i);
}

/* Same text as "0x%0*" G_GINT64_MODIFIER "x" with width `digits` (at most 16 used). */
static inline void append_hex(dg_text *out, guint64 v, guint digits)
{
    static const char hex[] = "0123456789abcdef";
    char buf[2 + 16];
    buf[0] = '0';
    buf[1] = 'x';
    guint n = digits < 16 ? digits : 16;
    if (n == 0 || (n < 16 && (v >> (4 * n)) != 0)) {
        n = 1; /* wider than `digits`: the digits v needs */
        while (n < 16 && (v >> (4 * n)) != 0) n++;
    }
    /* one loop writes the digits and the zeros before them */
    for (guint k = n; k > 0; k--, v >>= 4) buf[1 + k] = hex[v & 0xf];
    text_append(out, buf, 2 + n);
}

/* A name for the top level of a statistics tree, g_free()d by the caller:
 * there a name shows only what follows its last '/' (a field named
 * "Read/Write", a text signature such as GOOSE's "IED2LD0/LLN0$GO$gcbB"), so
 * each '/' becomes U+2215, which looks alike. */
static inline char *stats_top_name(const char *text)
{
    char **parts = g_strsplit(text, "/", -1);
    char *shown = g_strjoinv("\xe2\x88\x95", parts);
    g_strfreev(parts);
    return shown;
}

} // namespace dg_rt

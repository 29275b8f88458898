// SPDX-License-Identifier: GPL-2.0-or-later
/* The runtime's arithmetic on values: a field's bytes read as a number, bit
 * masks, value ranges, reference arithmetic, time units.
 *
 * None of it depends on the message being decoded, so the unit tests call it
 * directly (tests/unit/test_runtime.cpp). Static inline: the walk calls
 * these for every field, and each runtime source inlines them into its loops.
 */
#pragma once

#include "dissgen_runtime.h"

namespace dg_rt __attribute__((visibility("hidden"))) {

static inline guint encoding_of(const dg_node *n) { return (n->flags & DG_LITTLE) ? ENC_LITTLE_ENDIAN : ENC_BIG_ENDIAN; }

/* The `length` bytes at offset (1 to 8; more reads 8) as an unsigned number. */
static inline guint64 read_uint(tvbuff_t *tvb, gint offset, guint length, guint encoding)
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

/* The low `bits` bits set (all 64 from 64 on). */
static inline guint64 bit_mask(guint bits) { return bits >= 64 ? G_MAXUINT64 : ((G_GUINT64_CONSTANT(1) << bits) - 1); }

/* A bit field's value: `bits` bits from bit `shift` of its group's value. */
static inline guint64 bit_field(guint64 group, guint shift, guint bits) { return (group >> shift) & bit_mask(bits); }

/* Whether value lies in one of the `count` ranges from ranges[first] on. */
static inline gboolean in_ranges(const dg_range *ranges, guint16 first, guint16 count, guint64 value)
{
#pragma GCC unroll 8 /* constant ranges (compiled walks) fold to comparisons */
    for (guint i = 0; i < count; i++) {
        const dg_range *r = &ranges[first + i];
        if (value >= r->low && value <= r->high) return TRUE;
    }
    return FALSE;
}

/* A referenced field's value with the reference's arithmetic applied,
 * exact up to 2^62 either way (a 4-byte length of 4294967295 is reported as
 * that), saturated beyond: any such value is past any packet's end. */
static inline gint64 ref_arith(guint64 value, const dg_ref *ref)
{
    const gint64 limit = G_GINT64_CONSTANT(1) << 62;
    const gint64 base = ref->is_signed && (gint64)value < 0 ? MAX((gint64)value, -limit)
                        : value > (guint64)limit          ? limit
                                                          : (gint64)value;
    const gint64 operand = ref->operand;
    gint64 v = base;
    switch (ref->op) {
    case '+': v = base + operand; break; /* |base| <= 2^62, |operand| < 2^30: no overflow */
    case '-': v = base - operand; break;
    case '*':
        if (__builtin_mul_overflow(base, operand, &v)) return (base < 0) != (operand < 0) ? -limit : limit;
        break;
    default: break;
    }
    return CLAMP(v, -limit, limit);
}

/* A time leaf's count of units as an nstime. */
static inline nstime_t time_of(const dg_node *n, guint64 value)
{
    guint64 per_second = n->extra && n->extra->units_per_second ? n->extra->units_per_second : 1000000000u;
    nstime_t t;
    t.secs = (time_t)(value / per_second);
    t.nsecs = (int)((value % per_second) * (1000000000u / per_second));
    return t;
}

/* A computed time's or datetime's signed count of units as an nstime. A
 * negative length of time has negative seconds and nanoseconds, as Wireshark
 * keeps one; a point before 1970 has whole seconds before it and nanoseconds
 * after them (-0.5 s: 23:59:59.5 on Dec 31, 1969). */
static inline nstime_t count_time(const dg_node *n, gint64 count)
{
    const gint64 per_second = n->extra && n->extra->units_per_second ? n->extra->units_per_second : 1000000000;
    nstime_t t;
    t.secs = (time_t)(count / per_second);
    t.nsecs = (int)((count % per_second) * (1000000000 / per_second));
    if (n->show == DG_SHOW_DATETIME && t.nsecs < 0) {
        t.secs -= 1;
        t.nsecs += 1000000000;
    }
    return t;
}

/* Whether the node is decoded more than once: a count, a repeat flag,
 * repeat="rest" or an offset table. */
static inline gboolean is_repeated(const dg_node *n)
{
    return n->count.slot >= 0 || n->repeat_slot >= 0 ||
           (n->extra && (n->extra->repeat_rest || n->extra->offsets_slot >= 0));
}

/* 64-bit FNV-1a of n bytes, from h (14695981039346656037 to start): a value
 * that stands for bytes (a signature field's text, an IPv6 client). */
static inline guint64 fnv1a64(guint64 h, const guint8 *b, gsize n)
{
    for (gsize i = 0; i < n; i++) h = (h ^ b[i]) * G_GUINT64_CONSTANT(1099511628211);
    return h;
}

/* Folds a 64-bit word into a 32-bit hash (a stream's signature, a learn's
 * keys): the word's bits mixed (MurmurHash3's finaliser step), then FNV's
 * multiply. Start from 2166136261u. */
static inline guint32 hash_mix(guint32 h, guint64 v)
{
    v ^= v >> 33;
    v *= G_GUINT64_CONSTANT(0xff51afd7ed558ccd);
    v ^= v >> 33;
    return (h ^ (guint32)v) * 16777619u;
}

} // namespace dg_rt

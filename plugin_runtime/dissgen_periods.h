/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The arithmetic of periods that every cycle analysis shares: the rule
 * files' cycles (dissgen_cycles.cpp) and EtherCAT's (ethercat_cycles.cpp).
 * Periods are nanoseconds, kept in wmem_file_scope: in 32 bits for
 * EtherCAT's (up to 4.29 s, which its long periods extend), in 64 for the
 * rule files' (a heartbeat of minutes is a cycle too):
 *
 *   vec_of<T>        a growing array (u32_vec, u64_vec)
 *   running_median_of<T>  the lower median of every period added so far,
 *                    in O(log n) per period (two heaps)
 *   quantiles_of()   minimum, median, 99th percentile and maximum
 *   steady_median()  whether a detection window's periods make a cycle
 *   and what their reports share: -z P,cycles drawn at the end of the
 *   capture (listen_to_the_end), its quantile lines, statistics tree rows
 *
 * C++ only, inside the runtime. */
#pragma once

#include "dissgen_text.h"

#include <epan/stats_tree.h>
#include <epan/tap.h>
#include <epan/wmem_scopes.h>
#include <glib.h>
#include <wsutil/nstime.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

namespace dg_periods __attribute__((visibility("hidden"))) {

/* A growing array in wmem_file_scope. */
template <typename T> struct vec_of {
    T *v;
    guint n, cap;
    void push(T x)
    {
        if (n == cap) {
            cap = cap ? 2 * cap : 16;
            v = (T *)wmem_realloc(wmem_file_scope(), v, cap * sizeof(T));
        }
        v[n++] = x;
    }
};
using u32_vec = vec_of<guint32>;
using u64_vec = vec_of<guint64>;

/* A binary heap over vec_of: max-heap when `max`, else min-heap. */
template <typename T> gboolean heap_before(T a, T b, gboolean max) { return max ? a > b : a < b; }

template <typename T> void heap_push(vec_of<T> *h, T x, gboolean max)
{
    h->push(x);
    for (guint i = h->n - 1; i > 0;) {
        guint p = (i - 1) / 2;
        if (!heap_before(h->v[i], h->v[p], max)) break;
        T t = h->v[i];
        h->v[i] = h->v[p];
        h->v[p] = t;
        i = p;
    }
}

template <typename T> T heap_pop(vec_of<T> *h, gboolean max)
{
    T top = h->v[0];
    h->v[0] = h->v[--h->n];
    for (guint i = 0;;) {
        guint l = 2 * i + 1, r = l + 1, best = i;
        if (l < h->n && heap_before(h->v[l], h->v[best], max)) best = l;
        if (r < h->n && heap_before(h->v[r], h->v[best], max)) best = r;
        if (best == i) break;
        T t = h->v[i];
        h->v[i] = h->v[best];
        h->v[best] = t;
        i = best;
    }
    return top;
}

/* Every period added, in two heaps: `low` (a max-heap) the lower half, one
 * more when the count is odd, so that its top is the lower median. */
template <typename T> struct running_median_of {
    vec_of<T> low, high;
    void add(T p)
    {
        if (low.n == 0 || p <= low.v[0])
            heap_push(&low, p, TRUE);
        else
            heap_push(&high, p, FALSE);
        if (low.n > high.n + 1)
            heap_push(&high, heap_pop(&low, TRUE), FALSE);
        else if (high.n > low.n)
            heap_push(&low, heap_pop(&high, FALSE), TRUE);
    }
    T median() const { return low.n ? low.v[0] : 0; }
    guint count() const { return low.n + high.n; }
    /* Every period added, in no order, into `out` (count() of them). */
    void copy_to(T *out) const
    {
        if (low.n) memcpy(out, low.v, low.n * sizeof(T));
        if (high.n) memcpy(out + low.n, high.v, high.n * sizeof(T));
    }
};
using running_median = running_median_of<guint32>;

template <typename T> int compare_periods(const void *a, const void *b)
{
    T x = *(const T *)a, y = *(const T *)b;
    return x < y ? -1 : x > y;
}

/* Minimum, lower median, nearest-rank 99th percentile and maximum. */
template <typename T> struct quantiles_of_t {
    guint n;
    T min, median, p99, max;
};
using quantiles = quantiles_of_t<guint32>;

/* Sorts v (n values) and takes its quantiles. */
template <typename T> quantiles_of_t<T> quantiles_of(T *v, guint n)
{
    quantiles_of_t<T> q = {n, 0, 0, 0, 0};
    if (!n) return q;
    qsort(v, n, sizeof *v, compare_periods<T>);
    q.min = v[0];
    q.median = v[(n - 1) / 2];
    q.p99 = v[(99 * (guint64)n + 99) / 100 - 1];
    q.max = v[n - 1];
    return q;
}

/* The quantiles of the values of v, left as they are (a sorted copy). */
template <typename T> quantiles_of_t<T> quantiles_of(const vec_of<T> &v)
{
    T *copy = g_new(T, v.n + 1);
    if (v.n) memcpy(copy, v.v, v.n * sizeof(T));
    const quantiles_of_t<T> q = quantiles_of(copy, v.n);
    g_free(copy);
    return q;
}

/* A period in ns as the 32 bits EtherCAT's analysis keeps: 0 when time
 * went backwards, G_MAXUINT32 from 4.29 s up (its long periods aside). */
inline guint32 clamp_period(gint64 ns)
{
    return ns < 0 ? 0 : ns >= (gint64)G_MAXUINT32 ? G_MAXUINT32 : (guint32)ns;
}

/* A period in ns as the 64 bits the rule files' cycles keep (a KNX
 * heartbeat of a minute is a cycle): 0 when time went backwards. */
inline guint64 period_of(gint64 ns) { return ns < 0 ? 0 : (guint64)ns; }

inline gint64 ns_of(const nstime_t *t) { return (gint64)t->secs * 1000000000 + t->nsecs; }

inline nstime_t nstime_of(gint64 ns)
{
    nstime_t t;
    t.secs = (time_t)(ns / 1000000000);
    t.nsecs = (int)(ns % 1000000000);
    return t;
}

/* the longest detection window of a cycle analysis: the generator accepts
 * window="1" to "64" */
const guint most_window = 64;

/* The median of a detection window's periods (n of them, at most
 * most_window, in any order) when all of them lie within half of it either
 * way: a steady stream, a cycle. 0 when they do not, or when the median is
 * no period (0, or clamped: the largest value of T). */
template <typename T> T steady_median(const T *periods, guint n)
{
    T v[most_window];
    memcpy(v, periods, n * sizeof(T));
    qsort(v, n, sizeof *v, compare_periods<T>);
    T median = v[(n - 1) / 2];
    if (median == 0 || median == (T)~(T)0) return 0;
    if (v[0] < median - median / 2 || v[n - 1] - median > median / 2) return 0;
    return median;
}

/* --- reports ------------------------------------------------------------ */

template <typename T> void print_quantiles(const char *what, const quantiles_of_t<T> *q)
{
    if (!q->n)
        printf("  %s: none\n", what);
    else
        printf("  %s min/median/p99/max (ns): %" G_GUINT64_FORMAT " %" G_GUINT64_FORMAT " %" G_GUINT64_FORMAT
               " %" G_GUINT64_FORMAT "\n",
               what, (guint64)q->min, (guint64)q->median, (guint64)q->p99, (guint64)q->max);
}

/* A statistics tree row `name` under `parent` set to `value`. */
inline void st_set(stats_tree *st, const char *name, int parent, guint64 value)
{
    stats_tree_create_node(st, name, parent, STAT_DT_INT, FALSE);
    set_stat_node(st, name, parent, FALSE, (gint)MIN(value, (guint64)G_MAXINT));
}

/* The statistics tree's node of cycle `number` ("Cycle N: TEXT", counting
 * its frames) under the root; its id, the parent of the cycle's rows. */
inline int st_cycle_node(stats_tree *st, guint number, const char *text, guint frames)
{
    char *shown = dg_rt::stats_top_name(text);
    char *name = g_strdup_printf("Cycle %u: %s", number, shown);
    g_free(shown);
    int id = stats_tree_create_node(st, name, 0, STAT_DT_INT, TRUE);
    set_stat_node(st, name, 0, FALSE, (gint)frames);
    g_free(name);
    return id;
}

/* A row "Cycle N WHAT" of cycle `number` under its node `parent`. */
inline void st_cycle_row(stats_tree *st, guint number, const char *what, int parent, guint64 value)
{
    char *label = g_strdup_printf("Cycle %u %s", number, what);
    st_set(st, label, parent, value);
    g_free(label);
}

/* The unit of a cycle's time rows in the statistics tree, whose values are
 * gint (up to 2.1 s in ns): ns when its largest time fits, else the first
 * of us, ms and s that holds it (a heartbeat of a minute in ms). */
struct st_time_unit {
    const char *name;
    guint64 ns;
};

inline st_time_unit st_unit_for(guint64 largest_ns)
{
    static const st_time_unit units[] = {{"ns", 1}, {"us", 1000}, {"ms", 1000000}, {"s", 1000000000}};
    guint i = 0;
    /* rounded as st_time_row() shows it */
    while (i + 1 < G_N_ELEMENTS(units) && (largest_ns + units[i].ns / 2) / units[i].ns > (guint64)G_MAXINT) i++;
    return units[i];
}

/* The unit of a cycle's figures f (nominal, period and round-trip quantiles). */
template <typename F> st_time_unit st_unit_of(const F &f)
{
    return st_unit_for(MAX(MAX((guint64)f.nominal, (guint64)f.period.max), (guint64)f.rtt.max));
}

/* A row "Cycle N WHAT (UNIT)": a time in ns, rounded to the unit. */
inline void st_time_row(stats_tree *st, guint number, const char *what, int parent, guint64 ns, st_time_unit unit)
{
    char *row = g_strdup_printf("%s (%s)", what, unit.name);
    st_cycle_row(st, number, row, parent, (ns + unit.ns / 2) / unit.ns);
    g_free(row);
}

/* The rows "Cycle N WHAT min/median/p99/max (UNIT)", when there are values. */
template <typename T>
void st_quantile_rows(stats_tree *st, guint number, const char *what, const quantiles_of_t<T> *q, int parent,
                      st_time_unit unit)
{
    const char *const names[] = {"min", "median", "p99", "max"};
    const guint64 values[] = {q->min, q->median, q->p99, q->max};
    for (guint i = 0; q->n && i < 4; i++) {
        char *row = g_strdup_printf("%s %s", what, names[i]);
        st_time_row(st, number, row, parent, values[i], unit);
        g_free(row);
    }
}

/* Whether to fill a statistics tree now: once per tap run, and only once the
 * capture's state is complete, which it is when a frame is tapped that the
 * first pass has gone beyond (the GUI taps a capture once it is read, tshark
 * -2 in its second pass). In one pass tshark taps each frame as the first
 * pass reaches it: the tree stays empty; -z P,cycles is the way there. */
inline gboolean st_fill_now(gboolean *filled, gboolean have_state, guint32 frame, guint32 last_frame)
{
    if (*filled || !have_state || frame >= last_frame) return FALSE;
    *filled = TRUE;
    return TRUE;
}

inline tap_packet_status no_packet(void *, packet_info *, epan_dissect_t *, const void *, tap_flags_t)
{
    return TAP_PACKET_DONT_REDRAW;
}

/* -z FILTER,cycles: draw() runs once the capture is read, when the capture's
 * state is complete. It listens to the frame tap (every frame) only for that;
 * `filter` must outlive the listener. FALSE (and a message) when it cannot. */
inline gboolean listen_to_the_end(const char *const *filter, tap_draw_cb draw)
{
    GString *error = register_tap_listener("frame", (void *)filter, NULL, TL_REQUIRES_NOTHING, NULL, no_packet,
                                           draw, NULL);
    if (!error) return TRUE;
    fprintf(stderr, "%s,cycles: %s\n", *filter, error->str);
    g_string_free(error, TRUE);
    return FALSE;
}

} /* namespace dg_periods */

/* The cycles of an EtherCAT capture: sent frames whose datagram signature
 * (commands, addresses, lengths) repeats at regular periods, e.g. LRW +
 * FRMW 0x0910 every millisecond. ethercat_analysis.cpp calls it for every frame
 * sent and every frame returned on the first pass; each sent frame of a
 * cycle keeps its mark (cycle number, period, nominal period) in its
 * bus_frame. The rules: ethercat_cycles.cpp and the manual, "Cycles".
 * C++ only, inside the runtime. */
#pragma once

#include "ethercat_bus.h"

namespace dg_ecat {

/* What a sent frame of a cycle shows; cycle 0: not in a cycle. */
struct cycle_mark {
    guint16 cycle;        /* 1, 2, ... in order of first appearance */
    guint32 period_ns;    /* since the cycle's previous frame; G_MAXUINT32: see the model's long periods */
    guint32 nominal_ns;   /* the cycle's median period so far */
};

struct cycle_model;   /* capture-wide, wmem_file_scope */

/* r: where the reference clock's system time sits (unbound: no drift);
 * declared: the rule file's <cycles> (NULL: none, nothing is timed). */
cycle_model *cycles_new(const esc_registers *r, const dg_cycles *declared);
/* First pass, a frame as sent: what the walk decoded of it for <cycles>
 * (NULL: nothing), its n datagrams. */
cycle_mark cycles_sent(cycle_model *m, const dg_cycle_input *in, const datagram *d, guint n,
                       const packet_info *pinfo);
/* First pass, a returned frame answering `txn`: s and b its first n datagrams
 * as sent and as returned. */
void cycles_returned(cycle_model *m, const datagram *s, const datagram *b, guint n, const dg_transaction *txn,
                     const packet_info *pinfo);
/* First pass, a returned frame (s and b its first n datagrams as sent and as
 * returned, `back` its bytes): the drift of the reference clock's system time
 * that its first DC datagram (dc_datagram) carries against the capture's
 * clock, in ns per second, since the capture's first such time; NAN when the
 * frame has none or it is that first one. */
double dc_returned(cycle_model *m, const datagram *s, const datagram *b, guint n, tvbuff_t *back,
                   const packet_info *pinfo);
/* Whether a returned datagram carries the reference clock's system time: an
 * FRMW or ARMW of 4 or 8 bytes at its register that a slave processed. */
gboolean dc_datagram(const dg_input_place *system_time, const datagram *s, const datagram *b);
/* Every pass: ecatr.dc.systime over b (a dc_datagram) and the drift unless NAN. */
void dc_show(const datagram *b, double drift, tvbuff_t *tvb, proto_tree *tree);
/* Every pass: the cycle items of a sent frame of m's capture. */
void cycles_show(const cycle_model *m, const cycle_mark *c, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree);
void cycles_register(int proto, const char *filter);

} /* namespace dg_ecat */

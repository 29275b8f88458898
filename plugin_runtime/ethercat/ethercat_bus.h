/* The EtherCAT bus as the capture shows it: what ethercat_analysis.cpp
 * and ethercat_bus.cpp share. ethercat_analysis.cpp compares each returned frame
 * with the one sent; ethercat_bus.cpp learns the slaves from the same frames
 * (count, positions, station addresses, identities from the SII EEPROM) and
 * checks them against the network design embedded with `--network`.
 * C++ only, inside the runtime. */
#pragma once

#include "ethercat_design.h"
#include "ethercat_inputs.h"
#include "dissgen_pairing.h"

namespace dg_ecat {

/* The inputs of a frame's dg_view, by number (ethercat_inputs.h). */
enum esc_input {
#define DG_ESC_INPUT_ID(id, name, kind) id,
    DG_ESC_INPUTS(DG_ESC_INPUT_ID)
#undef DG_ESC_INPUT_ID
};

/* One datagram as the walk decoded it (the frame's dg_view). */
struct datagram {
    gint offset;         /* of the datagram (its command) in its tvb */
    gint address_offset; /* of its address (the ADP, or the logical address) */
    gint wkc_at;         /* of its working counter, which follows its data */
    guint8 cmd, idx;
    guint16 adp, ado;    /* the 32-bit address: ADP low half, ADO high half */
    guint16 length;      /* of the data */
    guint16 wkc;
};

/* A returned frame with the frame as sent: their bytes and what the walk
 * decoded of each (their dg_views). */
struct frame_pair {
    tvbuff_t *sent, *back;
    const dg_view *sent_view, *back_view;
};

/* A datagram ends with its data and a 2-byte working counter. */
const gint datagram_wkc = 2;
inline gint wkc_offset(const datagram *d) { return d->wkc_at; }
inline gint data_offset(const datagram *d) { return d->wkc_at - d->length; }
inline gint datagram_span(const datagram *d) { return d->wkc_at + datagram_wkc - d->offset; }

/* At most this many datagrams per frame: 1500 bytes hold at most 124. */
const guint max_datagrams = 128;

/* The frame's header length, and its datagrams (up to `max`), from the
 * values the walk decoded (`view`, NULL: none): a datagram counts when its
 * working counter was decoded, so only whole datagrams do. */
guint frame_datagrams(const dg_view *view, guint *header_length, datagram *out, guint max);

const char *command_name(guint8 cmd);

/* d with every byte set (padding 0), its index only with `index`: how the
 * shapes of frames (what the frames of a cycle share, interned by
 * ethercat_bus.cpp and ethercat_analysis.cpp) keep a datagram, so that frames
 * alike compare equal byte for byte. */
datagram kept_datagram(const datagram *d, gboolean index);
/* FNV-1a of n bytes (32-bit words, then the bytes left), on from h (2166136261 to start). */
guint hash_bytes(guint h, const void *bytes, gsize n);

struct bus_model;   /* capture-wide, wmem_file_scope */
struct bus_shape;   /* what the frames of a cycle share, interned by the model */

/* One frame's slaves and network-check findings (its shape, which frames
 * alike share) and its timing: kept for every EtherCAT frame, so small. */
struct bus_frame {
    const bus_shape *shape;
    union {                              /* ethercat_cycles.cpp's */
        struct {
            guint32 period, nominal;     /* a sent frame's cycle_mark */
        } cycle_times;
        double dc_drift;                 /* a returned frame's DC drift (NAN: none) */
    } timing;
    guint16 cycle;
};

/* Where the registers the model reads sit: the rule file's register map
 * says it (its <input>s of registers, dg_pairing.places); NULL: not bound,
 * the model learns nothing from that register. */
struct esc_registers {
    const dg_input_place *station, *alias, *al_status;
    const dg_input_place *sii_control, *sii_address, *sii_data;
    const dg_input_place *fmmus, *syncmanagers;
    const dg_input_place *system_time;
};
esc_registers esc_registers_of(const dg_protocol *p);

/* ESC addresses below this are registers (an FMMU there maps e.g. a
 * SyncManager's status bit for mailbox polling); from it on, the process
 * memory that holds the mailboxes and the process data. */
const guint16 process_ram = 0x1000;

/* The ESC address `offset` bytes into instance `instance` of register r
 * (instance r->instances: the address just past its last instance). */
static inline guint64 register_address(const dg_input_place *r, guint instance, guint32 offset)
{
    return r->at + (guint64)r->stride * instance + offset;
}

/* Where `n` bytes from `offset` into register r (its instance `instance`)
 * sit in the datagram's data, or -1: not covered, or r not bound. */
gint register_at(const datagram *d, const dg_input_place *r, guint instance, guint32 offset, guint32 n);

bus_model *bus_new(const dg_bus *design, const esc_registers *registers);
/* First pass. A frame as sent (a request, or one whose response is not paired),
 * its n datagrams as frame_datagrams() gives them: which slave each one addresses, in *f. */
void bus_sent(bus_model *m, const datagram *d, guint n, bus_frame *f);
/* First pass. A returned frame with the frame as sent: what it teaches about
 * the bus, and which slave each datagram addresses, in *f. s and b are their
 * first n datagrams as frame_datagrams() gives them. */
void bus_returned(bus_model *m, const frame_pair *fp, const datagram *s, const datagram *b, guint n,
                  packet_info *pinfo, bus_frame *f);
/* A sent frame's cycle (ethercat_cycles.h), kept with its slaves. */
struct cycle_mark;
void bus_set_cycle(bus_frame *f, const cycle_mark *c);
cycle_mark bus_cycle(const bus_frame *f);
/* A returned frame's distributed-clock drift (ethercat_cycles.h), NAN when none. */
void bus_set_dc_drift(bus_frame *f, double drift);
double bus_dc_drift(const bus_frame *f);
/* Every pass: the slave items and the network-check expert infos. A line per
 * datagram names its slave; `details` (the preference) prints the slave's
 * fields under it, else they are added hidden when a filter names them. */
void bus_show(const bus_frame *f, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, gboolean details);
void bus_register(int proto, const char *filter);
/* Statistics (tshark -z ecatr,tree): per slave position, from returned frames. */
void bus_stats_init(stats_tree *st, int parent);
void bus_stats_frame(stats_tree *st, int parent, const bus_frame *f);

} /* namespace dg_ecat */

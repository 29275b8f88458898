/* The EtherCAT bus as the capture shows it: the slave model the
 * master's own frames reveal, and the check against the designed network.
 *
 * What is learnt, on the first pass, from each returned frame together with
 * the frame as sent (a datagram counts only when its working counter grew):
 *  - the slave count: the working counter a broadcast read (BRD) adds, since
 *    every slave increments it;
 *  - station addresses: an auto-increment write (APWR/APRW) to the
 *    configured station address register at ADP = -position (16-bit wrap)
 *    gives that position its station;
 *  - aliases: the station alias register, read or written;
 *  - identities from the SII EEPROM: a write of the EEPROM address register
 *    (with the control word asking for a read when it is written as well),
 *    then a read of the data register (4 or 8 bytes) gives the words from
 *    that address on; TwinCAT reads control, address and data in one.
 *    Words 0x0008/9 hold the vendor id, 0x000A/B the product code, 0x000C/D
 *    the revision, 0x000E/F the serial number.
 * Where each register sits is the rule file's (its register map, bound by
 * <input>s of registers: esc_registers); what the bytes there mean is the
 * slave controller's, here.
 * Datagrams addressed to one slave (APxx: ADP = -position on the frame as
 * sent; FPxx: ADP = station address) carry that slave's items. On the first
 * pass they show what is known at that point of the capture; on later passes
 * (tshark -2, the GUI) the model of the whole capture, so that frames before
 * the scan get names too. The network-check findings are stored with the
 * frame where the capture showed them, so every pass shows the same ones.
 */
#include "ethercat_bus.h"
#include "ethercat_commands.h"
#include "ethercat_cycles.h"
#include "dissgen_label.h"

#include <epan/expert.h>
#include <wsutil/sign_ext.h>

#include <math.h>
#include <string.h>

namespace dg_ecat {

namespace {

/* Beyond this position the model keeps nothing (real segments have far fewer slaves). */
const guint max_positions = 1024;

/* An FMMU of a slave: where its share of the logical process image is. */
struct fmmu {
    gboolean known, active;
    guint32 logical;
    guint16 length;
    guint8 start_bit;              /* of the logical start */
    guint16 physical;              /* ESC address it maps: 0x1000 on is process RAM */
    guint8 type;                   /* bit 0: read (inputs), bit 1: write (outputs) */
};

const guint max_fmmus = 16;

/* PDO assignment and mapping the master writes over CoE (0x1C12/0x1C13,
 * 0x1600..0x17FF, 0x1A00..0x1BFF): what the model keeps at most. */
const guint max_pdo_objects = 64;     /* objects per slave */
const guint max_object_entries = 64;  /* subindexes 1..64 of one object */
const guint max_configs = 256;        /* configurations per slave over the capture */
const guint max_placed = 1024;        /* entries of one slave's inputs or outputs */

/* One assignment or mapping object as the master wrote it (or a slave's
 * upload response showed it); a complete one is copied and never changed. */
struct pdo_object {
    guint16 index;
    guint8 count;                        /* subindex 0 */
    gboolean complete;                   /* subindex 0 written non-zero, or a complete-access transfer */
    guint32 value[max_object_entries];   /* subindex k at [k - 1]: a PDO index, or index << 16 | sub << 8 | bits */
};

/* An entry of a configured slave's inputs or outputs. */
struct placed {
    guint32 bit;                /* from the start of the slave's inputs or outputs */
    guint16 bits;
    guint16 index;
    guint8 subindex;
    const dg_pdo_entry *known;  /* the ESI's, NULL when it does not have it */
};

/* A configuration's inputs or outputs, worked out for one model when first shown. */
struct placed_list {
    gboolean known;
    gint32 device;              /* the catalogue's device it was worked out for */
    guint count;
    const placed *list;
};

/* A slave's learned objects from one frame on (the returned frame that
 * completed one of them); immutable but for the lists worked out from it. */
struct pdo_config {
    guint32 from_frame;
    guint count;
    const pdo_object *objects[max_pdo_objects];
    mutable placed_list layout[2];  /* inputs, outputs */
};

enum ident_word { W_VENDOR = 0x08, W_PRODUCT = 0x0a, W_REVISION = 0x0c, W_SERIAL = 0x0e, SII_WORDS = 0x10 };

struct slave_state {
    gboolean station_known, sii_address_known;
    guint16 station, alias;
    guint8 alias_bytes;            /* bit per byte of the alias read back */
    guint32 sii_address;           /* in words, the last one the master asked for */
    guint16 sii[SII_WORDS];        /* SII words 0x0000..0x000F as read */
    guint32 sii_known;             /* bit per word of sii[] */
    gboolean checked;              /* compared with the design */
    fmmu fmmus[max_fmmus];         /* as the master configured them */
    guint16 mailbox_start[2], mailbox_length[2];  /* SM0 (out), SM1 (in) in mailbox mode */
    gboolean al_known;
    guint8 al_state;               /* AL status bits 0-3, last seen */
    pdo_object *writing[max_pdo_objects];  /* the objects as written so far */
    guint writing_count;
    const pdo_config **configs;    /* learned configurations, in frame order */
    guint config_count;
};

enum event_kind { EV_COUNT, EV_MODEL, EV_OK, EV_WKC };

struct bus_event {
    guint8 kind;
    gint offset, length;
    const char *text;
};

/* Kept for every datagram of the capture (wmem_file_scope): small. Its items
 * go over dgram, the datagram in this frame. */
struct addressed {
    datagram dgram;
    gint32 expected_wkc; /* logical commands: -1 when not known */
    gint16 position;     /* -1: not known on the first pass */
    guint16 station;     /* FPxx: the ADP */
    guint8 stats;        /* returned frames: stat_flags, for the statistics tree */
    guint8 by_station : 1;
    guint8 logical : 1;  /* LRD/LWR/LRW */
};

enum stat_flags { ST_WKC_ERROR = 1, ST_AL_CHANGE = 2, ST_MAILBOX = 4 };

} /* namespace */

struct bus_model {
    const dg_bus *design;  /* NULL: nothing embedded */
    slave_state *slaves[max_positions];
    guint positions;       /* slaves[] below this may be set */
    wmem_map_t *stations;  /* station address -> position + 1 */
    gboolean count_known;
    guint count;
    gint64 count_reported; /* the last count that differed from the design, -1 none */
    gboolean mismatch, ok_noted;
    gboolean fmmus_known;  /* some slave's FMMU configuration was seen */
    wmem_map_t *shapes;    /* bus_shape -> itself: the frames' shapes without events */
    esc_registers regs;    /* where the registers it reads sit */
};

/* What a frame's datagrams address and what the network check found there:
 * the same for every frame of a cycle, so it is interned (bus_model.shapes)
 * and a capture of a million cyclic frames keeps a handful. The datagram
 * indexes, which change from frame to frame and which nothing here shows,
 * are left out (0). A shape with expert infos (events) is its frame's own. */
struct bus_shape {
    const bus_model *model;
    addressed *d;        /* count of them, right after the shape */
    bus_event *events;
    guint16 count;       /* datagrams: at most max_datagrams */
    guint16 event_count;
    guint8 returned;     /* inputs are shown from returned frames, outputs from frames as sent */
};
/* One per EtherCAT frame: the cycle and clock figures must not make it grow. */
static_assert(sizeof(bus_frame) <= sizeof(void *) + 16, "bus_frame grew");

namespace {

int hf_process_data = -1, hf_wkc_expected = -1, hf_slave = -1, hf_position = -1, hf_station = -1, hf_alias = -1, hf_vendor = -1, hf_product = -1,
    hf_revision = -1, hf_serial = -1, hf_name = -1, hf_pdo_entry = -1, hf_pdo_value = -1;
gint ett_slave = -1, ett_process_data = -1, ett_pdo_entry = -1;
expert_field ei_count = EI_INIT, ei_model = EI_INIT, ei_ok = EI_INIT, ei_wkc = EI_INIT;

/* Command numbers and classes: ethercat_commands.h. */
using namespace dg_ecat_commands;

/* The position an auto-increment datagram as sent addresses. */
guint16 position_of(guint16 adp) { return (guint16)(0x10000u - adp); }

/* The bytes of the 16-bit register r that a datagram covers, put into
 * `value`: a slave controller takes each byte written, and a master may write
 * (or read) one of the two alone. `shift` moves from the sent datagram's data
 * to the bytes read (the returned frame's). Returns a bit per byte taken. */
guint take_register16(const datagram *s, tvbuff_t *tvb, gint shift, const dg_input_place *r, guint16 *value)
{
    guint taken = 0;
    for (guint32 k = 0; k < 2; k++) {
        gint at = register_at(s, r, 0, k, 1);
        if (at < 0) continue;
        guint byte = dg_tvb_get_uint8(tvb, at + shift);
        *value = (guint16)((*value & ~(0xffu << (8 * k))) | byte << (8 * k));
        taken |= 1u << k;
    }
    return taken;
}

slave_state *slave_at(bus_model *m, guint32 position)
{
    if (position >= max_positions) return NULL;
    if (!m->slaves[position]) m->slaves[position] = wmem_new0(wmem_file_scope(), slave_state);
    if (position >= m->positions) m->positions = position + 1;
    return m->slaves[position];
}

gint32 station_position(const bus_model *m, guint16 station)
{
    guint v = GPOINTER_TO_UINT(wmem_map_lookup(m->stations, GUINT_TO_POINTER((guint)station)));
    return v ? (gint32)v - 1 : -1;
}

gboolean words_known(const slave_state *s, guint word) { return (s->sii_known >> word & 3u) == 3u; }
guint32 word32(const slave_state *s, guint word) { return s->sii[word] | (guint32)s->sii[word + 1] << 16; }

/* The catalogue's device with this identity: the same revision, else the
 * product's latest; -1 when the product is not in the catalogue. */
gint32 find_device(const dg_bus *bus, guint32 vendor, guint32 product, guint32 revision)
{
    if (!bus || !bus->device_count) return -1;
    guint lo = 0, hi = bus->device_count;
    while (lo < hi) {
        guint mid = lo + (hi - lo) / 2;
        const dg_device *d = &bus->devices[mid];
        if (d->vendor < vendor || (d->vendor == vendor && d->product < product)) lo = mid + 1;
        else hi = mid;
    }
    gint32 found = -1;
    for (guint i = lo; i < bus->device_count && bus->devices[i].vendor == vendor && bus->devices[i].product == product;
         i++) {
        found = (gint32)i;
        if (bus->devices[i].revision == revision) break;
    }
    return found;
}

/* The catalogue's device of a slave whose identity was read from its SII, or -1. */
gint32 learned_device(const dg_bus *bus, const slave_state *s)
{
    if (!s || !words_known(s, W_VENDOR) || !words_known(s, W_PRODUCT)) return -1;
    return find_device(bus, word32(s, W_VENDOR), word32(s, W_PRODUCT),
                       words_known(s, W_REVISION) ? word32(s, W_REVISION) : 0);
}

/* "EL1004 (vendor 0x00000002, product 0x03ec3052)", or the numbers alone. */
const char *model_text(const dg_bus *bus, guint32 vendor, guint32 product, gint32 device)
{
    if (device >= 0)
        return wmem_strdup_printf(wmem_file_scope(), "%s (vendor 0x%08x, product 0x%08x)", bus->devices[device].type,
                                  vendor, product);
    return wmem_strdup_printf(wmem_file_scope(), "vendor 0x%08x, product 0x%08x", vendor, product);
}

/* The findings of one frame, collected on the first pass. */
struct events {
    bus_event list[max_datagrams + 4];
    guint count;
    void add(guint8 kind, const datagram *d, const char *text)
    {
        if (count >= G_N_ELEMENTS(list)) return;
        list[count++] = {kind, d->offset, datagram_span(d), text};
    }
};

/* Once the count and every designed slave's identity are known and match: the note, once. */
void check_complete(bus_model *m, const datagram *d, events *ev)
{
    const dg_bus *b = m->design;
    if (!b || !b->slaves || m->ok_noted || m->mismatch || !m->count_known || m->count != b->slave_count) return;
    for (guint i = 0; i < b->slave_count; i++)
        if (!m->slaves[i] || !m->slaves[i]->checked) return;
    m->ok_noted = TRUE;
    ev->add(EV_OK, d, wmem_strdup_printf(wmem_file_scope(), "The bus matches the design: %u slaves, every model as designed",
                                         b->slave_count));
}

void learn_count(bus_model *m, guint count, const datagram *d, events *ev)
{
    m->count_known = TRUE;
    m->count = count;
    const dg_bus *b = m->design;
    if (!b || !b->slaves) return;
    if (count != b->slave_count) {
        m->mismatch = TRUE;
        if (m->count_reported != (gint64)count)
            ev->add(EV_COUNT, d, wmem_strdup_printf(wmem_file_scope(), "design: %u slaves, bus: %u", b->slave_count, count));
        m->count_reported = count;
    }
    check_complete(m, d, ev);
}

/* A slave's identity, once read, against the design's slave at its position. */
void check_identity(bus_model *m, guint position, slave_state *s, const datagram *d, events *ev)
{
    const dg_bus *b = m->design;
    if (!b || !b->slaves || s->checked || position >= b->slave_count) return;
    const dg_slave *want = &b->slaves[position];
    if (!words_known(s, W_VENDOR) || !words_known(s, W_PRODUCT)) return;
    if (want->revision_given && !words_known(s, W_REVISION)) return;
    s->checked = TRUE;
    guint32 vendor = word32(s, W_VENDOR), product = word32(s, W_PRODUCT);
    guint32 revision = words_known(s, W_REVISION) ? word32(s, W_REVISION) : 0;
    gboolean same = vendor == want->vendor && product == want->product &&
                    (!want->revision_given || revision == want->revision);
    if (!same) {
        m->mismatch = TRUE;
        const char *expected = want->device >= 0 ? model_text(b, want->vendor, want->product, want->device)
                                                 : model_text(b, want->vendor, want->product, -1);
        const char *found = model_text(b, vendor, product, find_device(b, vendor, product, revision));
        if (want->revision_given && vendor == want->vendor && product == want->product)
            ev->add(EV_MODEL, d, wmem_strdup_printf(wmem_file_scope(),
                                                    "Position %u: design %s revision 0x%08x, bus revision 0x%08x",
                                                    position, expected, want->revision, revision));
        else
            ev->add(EV_MODEL, d, wmem_strdup_printf(wmem_file_scope(), "Position %u: design %s, bus %s", position,
                                                    expected, found));
    }
    check_complete(m, d, ev);
}

/* The SII words a read of the EEPROM data register returned, stored from the EEPROM address on. */
void learn_sii_data(bus_model *m, guint position, slave_state *s, const datagram *b, tvbuff_t *back, events *ev)
{
    gint data = register_at(b, m->regs.sii_data, 0, 0, 4);
    if (data < 0) return;
    guint32 address;
    gint status = register_at(b, m->regs.sii_control, 0, 0, 2);
    guint bytes = MIN(8u, (guint)(wkc_offset(b) - data));
    if (status >= 0) {
        guint16 st = dg_tvb_get_uint16(back, status, ENC_LITTLE_ENDIAN);
        if (st & 0x8000) return;        /* busy: the data is not there yet */
        if (!(st & 0x0040)) bytes = 4;  /* the ESC reads 4 bytes at a time */
    }
    gint at = register_at(b, m->regs.sii_address, 0, 0, 2);
    if (at >= 0) address = dg_tvb_get_uint16(back, at, ENC_LITTLE_ENDIAN);
    else if (s->sii_address_known) address = s->sii_address;
    else return;
    for (guint i = 0; i < bytes / 2; i++) {
        guint32 word = address + i;
        if (word >= SII_WORDS) break;
        s->sii[word] = dg_tvb_get_uint16(back, data + 2 * (gint)i, ENC_LITTLE_ENDIAN);
        s->sii_known |= 1u << word;
    }
    check_identity(m, position, s, b, ev);
}

/* A write of the EEPROM address (with a read command when the control word is written too). */
void learn_sii_address(const esc_registers *r, slave_state *s, const datagram *d, tvbuff_t *sent)
{
    gint at = register_at(d, r->sii_address, 0, 0, 2);
    if (at < 0) return;
    gint control = register_at(d, r->sii_control, 0, 0, 2);
    if (control >= 0 && !(dg_tvb_get_uint16(sent, control, ENC_LITTLE_ENDIAN) & 0x0100)) return;
    s->sii_address = dg_tvb_get_uint16(sent, at, ENC_LITTLE_ENDIAN);
    s->sii_address_known = TRUE;
}

/* FMMU configuration writes: 16 bytes per FMMU, one FMMU per instance of
 * the register (logical start 4, length 2, start/stop bit, physical start 2
 * and bit, type at +11, activate at +12), or the activate byte alone. */
void learn_fmmus(bus_model *m, slave_state *st, const datagram *d, tvbuff_t *sent)
{
    const dg_input_place *r = m->regs.fmmus;
    if (!r || d->ado >= register_address(r, r->instances, 0) || (guint32)d->ado + d->length <= r->at) return;
    for (guint n = 0; n < max_fmmus && n < r->instances; n++) {
        fmmu *f = &st->fmmus[n];
        gint at = register_at(d, r, n, 0, 16);
        if (at >= 0) {
            f->known = TRUE;
            f->logical = dg_tvb_get_uint32(sent, at, ENC_LITTLE_ENDIAN);
            f->length = dg_tvb_get_uint16(sent, at + 4, ENC_LITTLE_ENDIAN);
            f->start_bit = dg_tvb_get_uint8(sent, at + 6) & 7;
            f->physical = dg_tvb_get_uint16(sent, at + 8, ENC_LITTLE_ENDIAN);
            f->type = dg_tvb_get_uint8(sent, at + 11) & 3;
            f->active = dg_tvb_get_uint8(sent, at + 12) & 1;
            m->fmmus_known = TRUE;
        } else if (f->known && (at = register_at(d, r, n, 12, 1)) >= 0) {
            f->active = dg_tvb_get_uint8(sent, at) & 1;
        }
    }
}

/* One slave's part in a logical datagram's working counter. */
struct share {
    guint position;
    guint8 read, write;   /* what it adds for reading (inputs) and writing (outputs) */
};

/* The slaves whose active FMMUs overlap a logical datagram, and what each
 * adds: LRD +1 per reading slave, LWR +1 per writing one, LRW +1 and +2. */
guint shares_of(const bus_model *m, const datagram *d, share *out, guint max)
{
    guint32 start = d->adp | (guint32)d->ado << 16;
    guint64 end = (guint64)start + d->length;
    guint n = 0;
    for (guint p = 0; p < m->positions && n < max; p++) {
        const slave_state *s = m->slaves[p];
        if (!s) continue;
        guint8 type = 0;
        for (guint i = 0; i < max_fmmus; i++) {
            const fmmu *f = &s->fmmus[i];
            if (f->known && f->active && f->length && f->logical < end && start < (guint64)f->logical + f->length)
                type |= f->type;
        }
        share sh = {p, 0, 0};
        if ((type & 1) && d->cmd != LWR) sh.read = 1;
        if ((type & 2) && d->cmd != LRD) sh.write = d->cmd == LRW ? 2 : 1;
        if (sh.read || sh.write) out[n++] = sh;
    }
    return n;
}

/* The working counter a logical datagram should come back with: the ENI's
 * cyclic command (Cnt) when one matches, else from the FMMUs; -1 unknown. */
gint32 expected_wkc(const bus_model *m, const datagram *d, share *shares, guint *share_count)
{
    *share_count = 0;
    if (!is_logical(d->cmd)) return -1;
    const dg_bus *b = m->design;
    guint32 start = d->adp | (guint32)d->ado << 16;
    if (b && b->cyclic)
        for (guint i = 0; i < b->cyclic_count; i++) {
            const dg_cyclic_cmd *c = &b->cyclic[i];
            if (c->cmd == d->cmd && c->logical_address == start && c->length == d->length && c->expected_wkc >= 0) {
                if (shares) *share_count = shares_of(m, d, shares, max_positions);
                return c->expected_wkc;
            }
        }
    if (!m->fmmus_known) return -1;
    share local[64];
    share *list = shares ? shares : local;
    *share_count = shares_of(m, d, list, shares ? max_positions : G_N_ELEMENTS(local));
    gint32 sum = 0;
    for (guint i = 0; i < *share_count; i++) sum += list[i].read + list[i].write;
    return sum;
}

/* "EL2004 at position 2", or "the slave at position 2". */
const char *slave_text(const bus_model *m, guint position)
{
    gint32 device = learned_device(m->design, position < max_positions ? m->slaves[position] : NULL);
    if (device >= 0) return wmem_strdup_printf(wmem_file_scope(), "%s at position %u", m->design->devices[device].type, position);
    return wmem_strdup_printf(wmem_file_scope(), "the slave at position %u", position);
}

/* A returned logical datagram whose working counter is not the expected one;
 * when exactly one slave's part accounts for the difference, it is named. */
void check_wkc(const bus_model *m, const datagram *s, const datagram *b, events *ev)
{
    share shares[max_positions];
    guint n;
    gint32 expected = expected_wkc(m, s, shares, &n);
    gint32 got = (gint32)b->wkc - (gint32)s->wkc;
    /* A counter that went down is the ESC analysis's finding (wkc_down), not
     * a count of slaves: no "got -N" here. */
    if (expected < 0 || got < 0 || got == expected) return;
    wmem_strbuf_t *text = wmem_strbuf_new(wmem_file_scope(), "");
    wmem_strbuf_append_printf(text, "%s: expected working counter %d, got %d", command_name(s->cmd), expected, got);
    gint32 missing = expected - got;
    const char *what = NULL;
    guint who = 0, found = 0;
    for (guint i = 0; i < n && missing > 0; i++) {
        const char *parts[3] = {"did not read its inputs", "did not write its outputs", "did not process it"};
        gint32 values[3] = {shares[i].read, shares[i].write, shares[i].read + shares[i].write};
        for (guint k = 0; k < 3; k++) {
            if (values[k] != missing || (k == 2 && (!shares[i].read || !shares[i].write))) continue;
            found++;
            who = shares[i].position;
            what = parts[k];
        }
    }
    if (found == 1) wmem_strbuf_append_printf(text, ": %s %s", slave_text(m, who), what);
    ev->add(EV_WKC, b, wmem_strbuf_get_str(text));
}

/* SyncManager 0 and 1 configured as mailboxes (one SyncManager per
 * instance of the register: start 2, length 2, control 1 with mode bits
 * 0-1 = 2). */
void learn_mailboxes(const esc_registers *r, slave_state *st, const datagram *d, tvbuff_t *sent)
{
    for (guint n = 0; n < 2; n++) {
        gint at = register_at(d, r->syncmanagers, n, 0, 5);
        if (at < 0 || (dg_tvb_get_uint8(sent, at + 4) & 3) != 2) continue;
        st->mailbox_start[n] = dg_tvb_get_uint16(sent, at, ENC_LITTLE_ENDIAN);
        st->mailbox_length[n] = dg_tvb_get_uint16(sent, at + 2, ENC_LITTLE_ENDIAN);
    }
}

gboolean is_mailbox(const slave_state *st, const datagram *d)
{
    for (guint n = 0; n < 2; n++)
        if (st->mailbox_length[n] && d->ado >= st->mailbox_start[n] &&
            d->ado < (guint32)st->mailbox_start[n] + st->mailbox_length[n])
            return TRUE;
    return FALSE;
}

/* --- PDO assignment and mapping over CoE ---------------------------------- */

/* The SDO transfer of a frame's datagram `instance` as the walk decoded its
 * CoE mailbox (the view's sdo inputs): an initiate download request as the
 * master writes it to SyncManager 0, or an initiate upload response the
 * master reads from SyncManager 1. The rules decode the command byte's bits
 * of those two commands alone, so their presence says which command it is;
 * its expedited data is there when the command says so. Expedited transfers
 * carry up to 4 bytes in the header, normal ones a size and the data after
 * it; one whose size is more than the mailbox holds continues in segments,
 * which are not followed (nothing is learnt from it). */
struct sdo_data {
    guint16 index;
    guint8 subindex;
    gboolean complete_access;
    gint offset;
    guint32 length;
};

/* The eight sdo inputs of a download and of an upload, in this order (ethercat_inputs.h). */
enum sdo_input {
    SDO_SIZE_INDICATED,
    SDO_UNUSED_BYTES,
    SDO_COMPLETE_ACCESS,
    SDO_INDEX,
    SDO_SUBINDEX,
    SDO_EXPEDITED,
    SDO_SIZE,
    SDO_DATA,
    SDO_INPUTS
};
G_STATIC_ASSERT(ESC_IN_DOWNLOAD_DATA - ESC_IN_DOWNLOAD_SIZE_INDICATED == SDO_DATA);
G_STATIC_ASSERT(ESC_IN_UPLOAD_DATA - ESC_IN_UPLOAD_SIZE_INDICATED == SDO_DATA);

gboolean sdo_transfer(const dg_view *view, guint instance, gboolean upload, sdo_data *out)
{
    const guint first = upload ? ESC_IN_UPLOAD_SIZE_INDICATED : ESC_IN_DOWNLOAD_SIZE_INDICATED;
    const dg_view_value *in[SDO_INPUTS] = {};
    for (guint i = 0; view && i < view->count; i++) {
        const dg_view_value *x = &view->values[i];
        if (x->instance == instance && x->input >= first && x->input < first + SDO_INPUTS) in[x->input - first] = x;
    }
    if (!in[SDO_SIZE_INDICATED] || !in[SDO_COMPLETE_ACCESS] || !in[SDO_INDEX] || !in[SDO_SUBINDEX]) return FALSE;
    const gboolean size_indicated = in[SDO_SIZE_INDICATED]->value != 0;
    out->index = (guint16)in[SDO_INDEX]->value;
    out->subindex = (guint8)in[SDO_SUBINDEX]->value;
    out->complete_access = in[SDO_COMPLETE_ACCESS]->value != 0;
    if (in[SDO_EXPEDITED]) { /* 4 - unused bytes when the size is indicated */
        if (size_indicated && !in[SDO_UNUSED_BYTES]) return FALSE;
        out->offset = in[SDO_EXPEDITED]->offset;
        out->length = size_indicated ? 4u - (guint32)MIN(in[SDO_UNUSED_BYTES]->value, 4u) : 4u;
        return TRUE;
    }
    if (!size_indicated || !in[SDO_SIZE] || !in[SDO_DATA]) return FALSE;
    if (in[SDO_SIZE]->value > in[SDO_DATA]->length) return FALSE; /* segmented */
    out->offset = in[SDO_DATA]->offset;
    out->length = (guint32)in[SDO_SIZE]->value;
    return TRUE;
}

gboolean is_pdo_object(guint16 index)
{
    return index == 0x1c12 || index == 0x1c13 || (index >= 0x1600 && index <= 0x17ff) ||
           (index >= 0x1a00 && index <= 0x1bff);
}

pdo_object *writing_object(slave_state *st, guint16 index)
{
    for (guint i = 0; i < st->writing_count; i++)
        if (st->writing[i]->index == index) return st->writing[i];
    if (st->writing_count >= max_pdo_objects) return NULL;
    pdo_object *o = wmem_new0(wmem_file_scope(), pdo_object);
    o->index = index;
    return st->writing[st->writing_count++] = o;
}

/* A new configuration from `frame` on: the last one with a copy of `o` in
 * place of its earlier version. */
void add_config(slave_state *st, const pdo_object *o, guint32 frame)
{
    if (st->config_count >= max_configs) return;
    if (!st->configs) st->configs = wmem_alloc0_array(wmem_file_scope(), const pdo_config *, max_configs);
    pdo_config *c = wmem_new0(wmem_file_scope(), pdo_config);
    if (st->config_count) *c = *st->configs[st->config_count - 1];
    c->from_frame = frame;
    c->layout[0].known = c->layout[1].known = FALSE;
    const pdo_object *copy = (const pdo_object *)wmem_memdup(wmem_file_scope(), o, sizeof *o);
    guint i = 0;
    while (i < c->count && c->objects[i]->index != o->index) i++;
    if (i == c->count) c->count++;
    c->objects[i] = copy;
    st->configs[st->config_count++] = c;
}

/* One SDO transfer of an assignment (entries of 16 bits) or mapping object
 * (32 bits). One subindex at a time, the object is complete when subindex 0
 * is written non-zero; a complete-access transfer from subindex 0 holds
 * subindex 0 padded to 16 bits, then the entries (from subindex 1: the
 * entries alone), and completes it; one from subindex 0 that holds no entry
 * (the count alone) sets the count of the entries written before. */
void learn_object(slave_state *st, tvbuff_t *tvb, const sdo_data *sd, guint32 frame)
{
    if (!is_pdo_object(sd->index)) return;
    pdo_object *o = writing_object(st, sd->index);
    if (!o) return;
    guint32 size = sd->index >= 0x1c00 ? 2 : 4;
    if (sd->complete_access) {
        if (sd->subindex > 1 || (sd->subindex == 0 && sd->length < 1)) return;
        guint32 at = 0, count = sd->length / size;
        if (sd->subindex == 0) {
            count = dg_tvb_get_uint8(tvb, sd->offset);
            at = 2;
        }
        guint n = 0;
        for (; n < count && n < max_object_entries && at + size <= sd->length; n++, at += size)
            o->value[n] = size == 2 ? dg_tvb_get_uint16(tvb, sd->offset + (gint)at, ENC_LITTLE_ENDIAN)
                                    : dg_tvb_get_uint32(tvb, sd->offset + (gint)at, ENC_LITTLE_ENDIAN);
        o->count = (guint8)(sd->subindex == 0 && n == 0 ? MIN(count, max_object_entries) : n);
        o->complete = TRUE;
        add_config(st, o, frame);
        return;
    }
    if (sd->subindex == 0) {
        if (sd->length < 1) return;
        o->count = (guint8)MIN(dg_tvb_get_uint8(tvb, sd->offset), max_object_entries);
        o->complete = o->count != 0;
        if (o->complete) add_config(st, o, frame);
        return;
    }
    if (sd->subindex > max_object_entries || sd->length < size) return;
    o->value[sd->subindex - 1] = size == 2 ? dg_tvb_get_uint16(tvb, sd->offset, ENC_LITTLE_ENDIAN)
                                           : dg_tvb_get_uint32(tvb, sd->offset, ENC_LITTLE_ENDIAN);
    o->complete = FALSE;
}

/* A mailbox datagram to a slave: a download to its SyncManager 0 (the frame
 * as sent), or an upload response read from SyncManager 1 (returned). */
void learn_coe(slave_state *st, const datagram *s, const frame_pair *fp, guint instance, guint32 frame)
{
    sdo_data sd;
    if (writes_registers(s->cmd) && !reads_registers(s->cmd) && st->mailbox_length[0] && s->ado == st->mailbox_start[0] &&
        sdo_transfer(fp->sent_view, instance, FALSE, &sd))
        learn_object(st, fp->sent, &sd, frame);
    if (reads_registers(s->cmd) && !writes_registers(s->cmd) && st->mailbox_length[1] && s->ado == st->mailbox_start[1] &&
        sdo_transfer(fp->back_view, instance, TRUE, &sd))
        learn_object(st, fp->back, &sd, frame);
}

/* An AL status read showing another state than the last one. */
gboolean al_changed(const esc_registers *r, slave_state *st, const datagram *b, tvbuff_t *back)
{
    gint at = register_at(b, r->al_status, 0, 0, 1);
    if (at < 0) return FALSE;
    guint8 state = dg_tvb_get_uint8(back, at) & 0x0f;
    gboolean changed = st->al_known && state != st->al_state;
    st->al_known = TRUE;
    st->al_state = state;
    return changed;
}

/* What one datagram pair teaches about the slave it addressed; its stat_flags. */
guint8 learn_slave(bus_model *m, guint position, const datagram *s, const datagram *b, const frame_pair *fp,
                   guint instance, guint32 frame, events *ev)
{
    tvbuff_t *sent = fp->sent, *back = fp->back;
    slave_state *st = slave_at(m, position);
    if (!st) return 0;
    guint8 flags = is_mailbox(st, s) ? ST_MAILBOX : 0;
    if (b->wkc <= s->wkc) return flags | ST_WKC_ERROR;
    guint16 was = st->station;
    if (writes_registers(s->cmd) && is_auto_increment(s->cmd) && take_register16(s, sent, 0, m->regs.station, &st->station)) {
        /* a station given anew: the old address no longer reaches this slave */
        if (st->station_known && was != st->station && station_position(m, was) == (gint32)position)
            wmem_map_remove(m->stations, GUINT_TO_POINTER((guint)was));
        st->station_known = TRUE;
        wmem_map_insert(m->stations, GUINT_TO_POINTER((guint)st->station), GUINT_TO_POINTER(position + 1));
    }
    /* The alias is loaded from the EEPROM: the segment only reads it (a write
     * leaves it), and it is known once both its bytes came back. */
    if (reads_registers(s->cmd))
        st->alias_bytes |= (guint8)take_register16(s, back, b->offset - s->offset, m->regs.alias, &st->alias);
    if (writes_registers(s->cmd) && s->cmd != APRW && s->cmd != FPRW) {
        learn_sii_address(&m->regs, st, s, sent);
        learn_fmmus(m, st, s, sent);
        learn_mailboxes(&m->regs, st, s, sent);
    }
    learn_coe(st, s, fp, instance, frame);
    if (reads_registers(s->cmd) && !writes_registers(s->cmd)) {
        learn_sii_data(m, position, st, b, back, ev);
        if (al_changed(&m->regs, st, b, back)) flags |= ST_AL_CHANGE;
    }
    return flags;
}

/* The slave a datagram as sent addresses. */
addressed address_of(const bus_model *m, const datagram *s)
{
    addressed a = {};
    a.dgram = *s;
    a.position = -1;
    a.logical = is_logical(s->cmd);
    guint shares;
    a.expected_wkc = expected_wkc(m, s, NULL, &shares);
    if (is_auto_increment(s->cmd)) {
        guint16 p = position_of(s->adp);
        if (p < max_positions) a.position = (gint16)p;
    } else if (is_configured(s->cmd)) {
        a.by_station = TRUE;
        a.station = s->adp;
        a.position = (gint16)station_position(m, s->adp);
    }
    return a;
}

/* a as a shape keeps it: every byte set (padding 0), so that equal shapes
 * compare equal byte for byte; no index. */
addressed kept_form(const addressed *a)
{
    addressed k;
    memset(&k, 0, sizeof k);
    k.dgram = kept_datagram(&a->dgram, FALSE);
    k.expected_wkc = a->expected_wkc;
    k.position = a->position;
    k.station = a->station;
    k.stats = a->stats;
    k.by_station = a->by_station;
    k.logical = a->logical;
    return k;
}

guint shape_hash(gconstpointer v)
{
    const bus_shape *s = (const bus_shape *)v;
    return hash_bytes(2166136261u ^ s->count ^ ((guint)s->returned << 16), s->d, s->count * sizeof(addressed));
}

gboolean shape_equal(gconstpointer a, gconstpointer b)
{
    const bus_shape *x = (const bus_shape *)a, *y = (const bus_shape *)b;
    return x->count == y->count && x->returned == y->returned &&
           memcmp(x->d, y->d, x->count * sizeof(addressed)) == 0;
}

/* The frame's shape: its datagrams `d` (kept_form) and its events. */
const bus_shape *shape_of(bus_model *m, addressed *d, guint count, gboolean returned, const events *ev)
{
    bus_shape probe = {m, d, NULL, (guint16)count, 0, (guint8)returned};
    gboolean own = ev && ev->count;
    if (!own) {
        const bus_shape *found = (const bus_shape *)wmem_map_lookup(m->shapes, &probe);
        if (found) return found;
    }
    /* One allocation for the shape and its datagrams. */
    bus_shape *s = (bus_shape *)wmem_alloc0(wmem_file_scope(), sizeof(bus_shape) + count * sizeof(addressed));
    *s = probe;
    s->d = (addressed *)(s + 1);
    if (count) memcpy(s->d, d, count * sizeof(addressed));
    if (own) {
        s->event_count = (guint16)MIN(ev->count, G_MAXUINT16);
        s->events = (bus_event *)wmem_memdup(wmem_file_scope(), ev->list, ev->count * sizeof(bus_event));
    } else {
        wmem_map_insert(m->shapes, s, s);
    }
    return s;
}

/* Someone may read the slave's fields: a visible tree (the details pane, -V,
 * -T fields), or a filter or column naming one. */
gboolean slave_fields_wanted(proto_tree *tree)
{
    const int *hfs[] = {&hf_position, &hf_station, &hf_alias, &hf_vendor, &hf_product, &hf_revision, &hf_serial,
                        &hf_name};
    for (const int *hf : hfs)
        if (proto_field_is_referenced(tree, *hf)) return TRUE;
    return FALSE;
}

/* "Slave 2: EL1004 'Door switches', station 0x1002": the design's name when it has its own. */
void slave_label(dg_label *label, const bus_model *m, guint position, gint32 device, gboolean has_station,
                 guint16 station)
{
    const dg_bus *b = m->design;
    dg_label_str(label, "Slave ");
    dg_label_int(label, position, FALSE);
    if (device >= 0) {
        dg_label_str(label, ": ");
        dg_label_str(label, b->devices[device].type);
    }
    const char *designed = b && b->slaves && position < b->slave_count ? b->slaves[position].name : NULL;
    if (designed && *designed && (device < 0 || strcmp(designed, b->devices[device].type) != 0)) {
        dg_label_str(label, " '");
        dg_label_str(label, designed);
        dg_label_str(label, "'");
    }
    if (has_station) {
        char hex[8];
        g_snprintf(hex, sizeof hex, "0x%04x", station);
        dg_label_str(label, ", station ");
        dg_label_str(label, hex);
    }
}

void show_slave(const bus_model *m, const addressed *a, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree,
                gboolean details)
{
    gint32 position = a->position;
    if (position < 0 && a->by_station && PINFO_FD_VISITED(pinfo)) position = station_position(m, a->station);
    if (position < 0) return;
    gint offset = a->dgram.offset, length = datagram_span(&a->dgram);
    const slave_state *s = m->slaves[position];
    const dg_bus *b = m->design;
    gint32 device = learned_device(b, s);
    gboolean has_station = a->by_station || (s && s->station_known);
    guint16 station = a->by_station ? a->station : s ? s->station : 0;
    dg_label label = {"", 0};
    slave_label(&label, m, (guint)position, device, has_station, station);
    proto_item *item = proto_tree_add_none_format(tree, hf_slave, tvb, offset, length, "%s", label.text);
    proto_item_set_generated(item);
    /* The details: printed with the preference, else added hidden (filterable,
     * not printed), as Wireshark's TCP analysis adds its flags. */
    gboolean hidden = !details;
    if (!slave_fields_wanted(tree)) return;
    proto_tree *sub = proto_item_add_subtree(item, ett_slave);
    auto add = [hidden](proto_item *it) {
        proto_item_set_generated(it);
        if (hidden) proto_item_set_hidden(it);
    };
    add(proto_tree_add_uint(sub, hf_position, tvb, offset, length, (guint32)position));
    if (has_station) add(proto_tree_add_uint(sub, hf_station, tvb, offset, length, station));
    if (!s) return;
    if (s->alias_bytes == 3) add(proto_tree_add_uint(sub, hf_alias, tvb, offset, length, s->alias));
    const int *hfs[] = {&hf_vendor, &hf_product, &hf_revision, &hf_serial};
    const guint words[] = {W_VENDOR, W_PRODUCT, W_REVISION, W_SERIAL};
    for (guint i = 0; i < G_N_ELEMENTS(words); i++)
        if (words_known(s, words[i])) add(proto_tree_add_uint(sub, *hfs[i], tvb, offset, length, word32(s, words[i])));
    if (device >= 0) add(proto_tree_add_string(sub, hf_name, tvb, offset, length, b->devices[device].type));
}

/* Up to 64 bits of the process image, least significant bit first. */
guint64 image_bits(tvbuff_t *tvb, gint offset, guint bit, guint count)
{
    guint64 v = 0;
    for (guint i = 0; i < count; i++) {
        guint b = bit + i;
        if (dg_tvb_get_uint8(tvb, offset + (gint)(b / 8)) >> (b % 8) & 1) v |= G_GUINT64_CONSTANT(1) << i;
    }
    return v;
}

/* One PDO entry at `bit` bits into the datagram's data. */
void show_entry(proto_tree *tree, const dg_pdo_entry *e, tvbuff_t *tvb, gint data, guint32 bit)
{
    gint offset = data + (gint)(bit / 8), bytes = (gint)((bit % 8 + e->bit_length + 7) / 8);
    if (bit % 8 == 0 && e->bit_length % 8 == 0 && e->bit_length > 1) {
        proto_tree_add_item(tree, *e->hf, tvb, offset, e->bit_length / 8, ENC_LITTLE_ENDIAN);
        return;
    }
    if (e->bit_length == 0 || e->bit_length > 64) return;
    guint64 v = image_bits(tvb, data, bit, e->bit_length);
    header_field_info *hfi = proto_registrar_get_nth(*e->hf);
    if (!hfi) return;
    /* A switch on the type, not the IS_FT_* macros: Wireshark 4.4 renamed those. */
    gint64 value = (gint64)ws_sign_ext64(v, (int)e->bit_length);
    switch (hfi->type) {
    case FT_BOOLEAN: proto_tree_add_boolean(tree, *e->hf, tvb, offset, bytes, v ? 1 : 0); break;
    case FT_UINT8: case FT_UINT16: case FT_UINT24: case FT_UINT32:
        proto_tree_add_uint(tree, *e->hf, tvb, offset, bytes, (guint32)v);
        break;
    case FT_UINT40: case FT_UINT48: case FT_UINT56: case FT_UINT64:
        proto_tree_add_uint64(tree, *e->hf, tvb, offset, bytes, v);
        break;
    case FT_INT8: case FT_INT16: case FT_INT24: case FT_INT32:
        proto_tree_add_int(tree, *e->hf, tvb, offset, bytes, (gint32)value);
        break;
    case FT_INT40: case FT_INT48: case FT_INT56: case FT_INT64:
        proto_tree_add_int64(tree, *e->hf, tvb, offset, bytes, value);
        break;
    default: break;
    }
}

/* The logical bit where a slave's inputs (FMMU read) or outputs (FMMU write)
 * start: the design's, else the first active FMMU of that kind that maps
 * process RAM, at its logical start bit; -1 unknown. */
gint64 image_start(const dg_slave *ds, const slave_state *st, gboolean output)
{
    gint64 given = !ds ? -1 : output ? ds->output_logical_bit : ds->input_logical_bit;
    if (given >= 0) return given;
    if (!st) return -1;
    for (guint i = 0; i < max_fmmus; i++) {
        const fmmu *f = &st->fmmus[i];
        if (f->known && f->active && f->physical >= process_ram && (f->type & (output ? 2 : 1)))
            return (gint64)f->logical * 8 + f->start_bit;
    }
    return -1;
}

/* The subtree of one slave's inputs or outputs in a logical datagram, made
 * when its first entry is shown. */
proto_tree *data_subtree(proto_tree **sub, proto_tree *tree, const char *name, guint position, gboolean output,
                         const datagram *d, tvbuff_t *tvb)
{
    if (!*sub) {
        proto_item *it = proto_tree_add_none_format(tree, hf_process_data, tvb, d->offset, datagram_span(d),
                                                    "%s (position %u): %s", name, position, output ? "outputs" : "inputs");
        proto_item_set_generated(it);
        *sub = proto_item_add_subtree(it, ett_process_data);
    }
    return *sub;
}

/* One slave's entries[first, first + count) that lie wholly inside a logical
 * datagram, in a subtree; `start` is the logical bit where its inputs or
 * outputs begin. */
void show_slave_data(const dg_bus *b, const char *name, guint position, guint32 first, guint32 count, gint64 start,
                     const datagram *d, gboolean output, tvbuff_t *tvb, proto_tree *tree)
{
    gint64 begin = (gint64)(d->adp | (guint32)d->ado << 16) * 8, end = begin + (gint64)d->length * 8;
    proto_tree *sub = NULL;
    for (guint32 i = first; i < first + count; i++) {
        const dg_pdo_entry *e = &b->entries[i];
        if (!e->hf || *e->hf < 0 || (gboolean)e->output != output) continue;
        gint64 at = e->logical_bit >= 0 ? e->logical_bit : start + e->bit_offset;
        if (at < begin || at + e->bit_length > end) continue;
        show_entry(data_subtree(&sub, tree, name, position, output, d, tvb), e, tvb, data_offset(d),
                   (guint32)(at - begin));
    }
}

/* --- process data as the master configured it over CoE ------------------- */

/* The configuration a slave had in frame `frame`: the last one learnt in it
 * or before; NULL: none (the ESI defaults). The same in every pass. */
const pdo_config *config_at(const slave_state *st, guint32 frame)
{
    if (!st) return NULL;
    for (guint i = st->config_count; i > 0; i--)
        if (st->configs[i - 1]->from_frame <= frame) return st->configs[i - 1];
    return NULL;
}

const pdo_object *config_object(const pdo_config *c, guint16 index)
{
    for (guint i = 0; c && i < c->count; i++)
        if (c->objects[i]->index == index) return c->objects[i];
    return NULL;
}

gboolean is_output_pdo(guint16 index) { return index >= 0x1600 && index <= 0x17ff; }

/* Does the configuration change a slave's inputs or outputs: their assignment,
 * or the mapping of a PDO of that direction? */
gboolean config_changes(const pdo_config *c, gboolean output)
{
    for (guint i = 0; c && i < c->count; i++) {
        guint16 index = c->objects[i]->index;
        if (index == (output ? 0x1c12 : 0x1c13) || (index != 0x1c12 && index != 0x1c13 && is_output_pdo(index) == output))
            return TRUE;
    }
    return FALSE;
}

/* The catalogue's PDO `index` of a device, or NULL. */
const dg_pdo *catalogue_pdo(const dg_bus *b, gint32 device, guint16 index)
{
    if (!b || device < 0) return NULL;
    const dg_device *dev = &b->devices[device];
    for (guint32 p = dev->pdo_first; p < dev->pdo_first + dev->pdo_count && p < b->pdo_count; p++)
        if (b->pdos[p].index == index && b->pdos[p].output == is_output_pdo(index)) return &b->pdos[p];
    return NULL;
}

/* Object index:subindex among all the PDOs of a device: its default
 * entries (with their fields), then the objects only other PDOs map; NULL
 * when the ESI file does not map it. */
const dg_pdo_entry *catalogue_entry(const dg_bus *b, gint32 device, gboolean output, guint16 index, guint8 subindex)
{
    if (!b || device < 0) return NULL;
    const dg_device *dev = &b->devices[device];
    const guint32 first[] = {dev->entry_first, dev->object_first}, count[] = {dev->entry_count, dev->object_count};
    for (guint r = 0; r < G_N_ELEMENTS(first); r++)
        for (guint32 i = first[r]; i < first[r] + count[r] && i < b->entry_count; i++) {
            const dg_pdo_entry *e = &b->entries[i];
            if (e->index == index && e->subindex == subindex && (gboolean)e->output == output) return e;
        }
    return NULL;
}

/* The PDOs a device assigns by default in one direction, in the order they
 * are packed (the catalogue lists them first, in that order), empty ones too. */
guint default_pdos(const dg_bus *b, gint32 device, gboolean output, guint16 *out, guint max)
{
    guint n = 0;
    if (!b || device < 0) return 0;
    const dg_device *dev = &b->devices[device];
    for (guint32 p = dev->pdo_first; p < dev->pdo_first + dev->pdo_count && p < b->pdo_count && n < max; p++)
        if (b->pdos[p].assigned && (gboolean)b->pdos[p].output == output) out[n++] = b->pdos[p].index;
    return n;
}

/* A slave's inputs or outputs under a learnt configuration: the assigned
 * PDOs (learnt, else the ESI's defaults), each with its learnt mapping, else
 * the ESI's; a PDO that neither gives ends the list (what follows it has no
 * known place). Padding (index 0) takes its bits. */
guint configured_entries(const dg_bus *b, gint32 device, const pdo_config *c, gboolean output, placed *out, guint max)
{
    guint16 pdos[max_object_entries];
    guint pdo_count;
    const pdo_object *assign = config_object(c, output ? 0x1c12 : 0x1c13);
    if (assign) {
        pdo_count = assign->count;
        for (guint i = 0; i < pdo_count; i++) pdos[i] = (guint16)assign->value[i];
    } else {
        pdo_count = default_pdos(b, device, output, pdos, max_object_entries);
    }
    guint n = 0;
    guint32 bit = 0;
    for (guint p = 0; p < pdo_count; p++) {
        const pdo_object *map = config_object(c, pdos[p]);
        gboolean out_pdo = is_output_pdo(pdos[p]);
        if (map) {
            for (guint k = 0; k < map->count; k++) {
                guint32 v = map->value[k];
                placed e = {bit, (guint16)(v & 0xff), (guint16)(v >> 16), (guint8)(v >> 8), NULL};
                bit += e.bits;
                if (!e.index || n == max) continue;
                e.known = catalogue_entry(b, device, out_pdo, e.index, e.subindex);
                out[n++] = e;
            }
            continue;
        }
        const dg_pdo *pdo = catalogue_pdo(b, device, pdos[p]);
        if (!pdo) break;
        for (guint32 i = pdo->map_first; i < pdo->map_first + pdo->map_count && i < b->map_count; i++) {
            const dg_map_entry *en = &b->maps[i];
            placed e = {bit, en->bit_length, en->index, en->subindex, NULL};
            bit += en->bit_length;
            if (!e.index || n == max) continue;
            e.known = catalogue_entry(b, device, out_pdo, e.index, e.subindex);
            out[n++] = e;
        }
    }
    return n;
}

/* An entry without a registered field: its object as text, its value in its
 * bit length (up to 64 bits). */
void show_generic(proto_tree *tree, const placed *e, tvbuff_t *tvb, gint data, guint32 bit)
{
    gint offset = data + (gint)(bit / 8), bytes = (gint)((bit % 8 + e->bits + 7) / 8);
    char object[16];
    g_snprintf(object, sizeof object, "0x%04x:%02x", e->index, e->subindex);
    proto_item *it;
    if (e->known)
        it = proto_tree_add_string_format_value(tree, hf_pdo_entry, tvb, offset, bytes, object, "%s%s%s (%s%s%u bit)",
                                                object, *e->known->name ? " " : "", e->known->name,
                                                e->known->data_type,
                                                *e->known->data_type ? ", " : "", e->bits);
    else
        it = proto_tree_add_string_format_value(tree, hf_pdo_entry, tvb, offset, bytes, object,
                                                "%s (not in the ESI file, %u bit)", object, e->bits);
    proto_item_set_generated(it);
    if (e->bits == 0 || e->bits > 64) return;
    guint64 v = image_bits(tvb, data, bit, e->bits);
    proto_tree *sub = proto_item_add_subtree(it, ett_pdo_entry);
    proto_item_set_generated(proto_tree_add_uint64_format_value(sub, hf_pdo_value, tvb, offset, bytes, v,
                                                                "%" G_GUINT64_FORMAT " (0x%0*" G_GINT64_MODIFIER "x)",
                                                                v, (int)(e->bits + 3) / 4, v));
}

/* A configured slave's entries that lie wholly inside a logical datagram. */
void show_configured_data(const dg_bus *b, gint32 device, const pdo_config *c, const char *name, guint position,
                          gint64 start, const datagram *d, gboolean output, tvbuff_t *tvb, proto_tree *tree)
{
    placed_list *l = &c->layout[output ? 1 : 0];
    if (!l->known || l->device != device) {  /* once per configuration and model (which may become known later) */
        placed found[max_placed];
        guint count = configured_entries(b, device, c, output, found, max_placed);
        *l = {TRUE, device, count, (const placed *)wmem_memdup(wmem_file_scope(), found, (count ? count : 1) * sizeof *found)};
    }
    const placed *list = l->list;
    guint n = l->count;
    gint64 begin = (gint64)(d->adp | (guint32)d->ado << 16) * 8, end = begin + (gint64)d->length * 8;
    proto_tree *sub = NULL;
    for (guint i = 0; i < n; i++) {
        const placed *e = &list[i];
        gint64 at = start + e->bit;
        if (at < begin || at + e->bits > end) continue;
        proto_tree *into = data_subtree(&sub, tree, name, position, output, d, tvb);
        if (e->known && e->known->hf && *e->known->hf >= 0 && e->known->bit_length == e->bits)
            show_entry(into, e->known, tvb, data_offset(d), (guint32)(at - begin));
        else
            show_generic(into, e, tvb, data_offset(d), (guint32)(at - begin));
    }
}

/* A logical datagram's process data, one subtree per slave: outputs in the
 * frame as sent, inputs in the returned one. The slaves of the design with
 * their process data; without one, the slaves the capture identified (SII)
 * with their model's default process data from the catalogue. A slave whose
 * assignment or mapping the master configured over CoE by this frame gets
 * that instead (not with an ENI, whose process image is the configuration). */
void show_process_data(const bus_model *m, const datagram *d, gboolean returned, guint32 frame, tvbuff_t *tvb,
                       proto_tree *tree)
{
    const dg_bus *b = m->design;
    if (!is_logical(d->cmd)) return;
    gboolean output = !returned;
    if ((output && d->cmd == LRD) || (!output && d->cmd == LWR)) return;
    if (b && b->slaves) {
        for (guint p = 0; p < b->slave_count; p++) {
            const dg_slave *ds = &b->slaves[p];
            const slave_state *st = p < max_positions ? m->slaves[p] : NULL;
            gint64 start = image_start(ds, st, output);
            const pdo_config *c = config_at(st, frame);
            if (start < 0) continue;
            if (config_changes(c, output) && ds->input_logical_bit < 0 && ds->output_logical_bit < 0)
                show_configured_data(b, ds->device, c, ds->name, p, start, d, output, tvb, tree);
            else
                show_slave_data(b, ds->name, p, ds->entry_first, ds->entry_count, start, d, output, tvb, tree);
        }
        return;
    }
    for (guint p = 0; p < m->positions && p < max_positions; p++) {
        const slave_state *st = m->slaves[p];
        gint32 device = learned_device(b, st);
        const pdo_config *c = config_at(st, frame);
        gboolean configured = config_changes(c, output);
        gint64 start = device >= 0 || configured ? image_start(NULL, st, output) : -1;
        if (start < 0) continue;
        const char *name = device >= 0 ? b->devices[device].type : "Slave";
        if (configured) show_configured_data(b, device, c, name, p, start, d, output, tvb, tree);
        else show_slave_data(b, name, p, b->devices[device].entry_first, b->devices[device].entry_count, start, d, output,
                             tvb, tree);
    }
}

} /* namespace */

const char *command_name(guint8 cmd)
{
    const char *name = command_name_of(cmd);
    return name ? name : "unknown";
}

/* One value of the view into its datagram. */
static void place_input(datagram *d, const dg_view_value *x)
{
    switch (x->input) {
    case ESC_IN_COMMAND: d->cmd = (guint8)x->value; d->offset = x->offset; break;
    case ESC_IN_INDEX: d->idx = (guint8)x->value; break;
    case ESC_IN_ADP: d->adp = (guint16)x->value; d->address_offset = x->offset; break;
    case ESC_IN_ADO: d->ado = (guint16)x->value; break;
    case ESC_IN_LOGICAL: /* the same 32 bits as ADP (low half) and ADO */
        d->adp = (guint16)x->value;
        d->ado = (guint16)(x->value >> 16);
        d->address_offset = x->offset;
        break;
    case ESC_IN_LENGTH: d->length = (guint16)x->value; break;
    case ESC_IN_WKC: d->wkc = (guint16)x->value; d->wkc_at = x->offset; break;
    default: break;
    }
}

guint frame_datagrams(const dg_view *view, guint *header_length, datagram *out, guint max)
{
    *header_length = 0;
    guint n = 0, cleared = 0;
    for (guint i = 0; view && i < view->count; i++) {
        const dg_view_value *x = &view->values[i];
        if (x->input == ESC_IN_FRAME_LENGTH) {
            *header_length = (guint)x->value;
            continue;
        }
        if (x->instance >= max) continue;
        while (cleared <= x->instance) memset(&out[cleared++], 0, sizeof *out);
        place_input(&out[x->instance], x);
        /* The working counter, last on the wire, makes the datagram whole:
         * its data is the `length` bytes before it. A rule file that puts
         * the counter elsewhere (the data would start before the datagram's
         * own command) gives no datagram the analysis could compare. */
        if (x->input == ESC_IN_WKC) {
            if (data_offset(&out[x->instance]) <= out[x->instance].offset) return x->instance;
            n = x->instance + 1;
        }
    }
    return n;
}

datagram kept_datagram(const datagram *d, gboolean index)
{
    datagram k;
    memset(&k, 0, sizeof k);
    k.offset = d->offset;
    k.address_offset = d->address_offset;
    k.wkc_at = d->wkc_at;
    k.cmd = d->cmd;
    k.idx = index ? d->idx : 0;
    k.adp = d->adp;
    k.ado = d->ado;
    k.length = d->length;
    k.wkc = d->wkc;
    return k;
}

guint hash_bytes(guint h, const void *bytes, gsize n)
{
    const guint8 *b = (const guint8 *)bytes;
    gsize i = 0;
    for (; i + 4 <= n; i += 4) { /* a word at a time: every frame's shapes are hashed */
        guint32 w;
        memcpy(&w, b + i, 4);
        h = (h ^ w) * 16777619u;
    }
    for (; i < n; i++) h = (h ^ b[i]) * 16777619u;
    return h;
}

gint register_at(const datagram *d, const dg_input_place *r, guint instance, guint32 offset, guint32 n)
{
    if (!r || instance >= r->instances) return -1;
    guint64 reg = register_address(r, instance, offset);
    if (d->ado > reg || reg + n > (guint64)d->ado + d->length) return -1;
    return data_offset(d) + (gint)(reg - d->ado);
}

esc_registers esc_registers_of(const dg_protocol *p)
{
    esc_registers r;
    r.station = dg_input_place_of(p, ESC_REG_STATION);
    r.alias = dg_input_place_of(p, ESC_REG_ALIAS);
    r.al_status = dg_input_place_of(p, ESC_REG_AL_STATUS);
    r.sii_control = dg_input_place_of(p, ESC_REG_SII_CONTROL);
    r.sii_address = dg_input_place_of(p, ESC_REG_SII_ADDRESS);
    r.sii_data = dg_input_place_of(p, ESC_REG_SII_DATA);
    r.fmmus = dg_input_place_of(p, ESC_REG_FMMU);
    r.syncmanagers = dg_input_place_of(p, ESC_REG_SYNCMANAGER);
    r.system_time = dg_input_place_of(p, ESC_REG_SYSTEM_TIME);
    return r;
}

bus_model *bus_new(const dg_bus *design, const esc_registers *registers)
{
    bus_model *m = wmem_new0(wmem_file_scope(), bus_model);
    m->design = design;
    m->regs = *registers;
    m->stations = wmem_map_new(wmem_file_scope(), g_direct_hash, g_direct_equal);
    m->shapes = wmem_map_new(wmem_file_scope(), shape_hash, shape_equal);
    m->count_reported = -1;
    return m;
}

void bus_sent(bus_model *m, const datagram *d, guint n, bus_frame *f)
{
    addressed a[max_datagrams];
    for (guint i = 0; i < n; i++) {
        addressed x = address_of(m, &d[i]);
        a[i] = kept_form(&x);
    }
    f->shape = shape_of(m, a, n, FALSE, NULL);
}

void bus_set_cycle(bus_frame *f, const cycle_mark *c)
{
    f->cycle = c->cycle;
    f->timing.cycle_times.period = c->period_ns;
    f->timing.cycle_times.nominal = c->nominal_ns;
}

cycle_mark bus_cycle(const bus_frame *f)
{
    cycle_mark c = {0, 0, 0};
    if (f->shape->returned) return c;
    c.cycle = f->cycle;
    c.period_ns = f->timing.cycle_times.period;
    c.nominal_ns = f->timing.cycle_times.nominal;
    return c;
}

void bus_set_dc_drift(bus_frame *f, double drift) { f->timing.dc_drift = drift; }

double bus_dc_drift(const bus_frame *f) { return f->shape->returned ? f->timing.dc_drift : NAN; }

void bus_returned(bus_model *m, const frame_pair *fp, const datagram *s, const datagram *b, guint n,
                  packet_info *pinfo, bus_frame *f)
{
    tvbuff_t *sent = fp->sent;
    /* Only what is used is set: zeroing every possible event and datagram
     * would cost more than the rest of a cyclic frame's work. */
    events ev;
    ev.count = 0;
    guint8 flags[max_datagrams];
    memset(flags, 0, n * sizeof flags[0]);
    for (guint i = 0; i < n; i++) {
        if (is_logical(s[i].cmd) && s[i].cmd == b[i].cmd && s[i].adp == b[i].adp && s[i].ado == b[i].ado &&
            s[i].length == b[i].length)
            check_wkc(m, &s[i], &b[i], &ev);
        if (s[i].cmd != b[i].cmd || s[i].ado != b[i].ado || s[i].length != b[i].length) continue;
        gint32 position = is_auto_increment(s[i].cmd) ? position_of(s[i].adp)
                          : is_configured(s[i].cmd) ? station_position(m, s[i].adp) : -1;
        if (position >= 0) flags[i] = learn_slave(m, (guint)position, &s[i], &b[i], fp, i, pinfo->num, &ev);
        if (b[i].wkc <= s[i].wkc) continue;
        guint added = (guint)(b[i].wkc - s[i].wkc);
        if (s[i].cmd == BRD) learn_count(m, added, &b[i], &ev);
        else if (s[i].cmd == BWR)
            for (guint p = 0; m->count_known && p < m->count && p < max_positions; p++)
                learn_sii_address(&m->regs, slave_at(m, p), &s[i], sent);
    }
    addressed a[max_datagrams];
    for (guint i = 0; i < n; i++) {
        addressed x = address_of(m, &s[i]);
        x.stats = flags[i];
        x.dgram = b[i]; /* the items go over the returned datagram */
        a[i] = kept_form(&x);
    }
    f->shape = shape_of(m, a, n, TRUE, &ev);
    f->timing.dc_drift = NAN;
}

void bus_show(const bus_frame *frame, tvbuff_t *tvb, packet_info *pinfo, proto_tree *tree, gboolean details)
{
    if (!frame) return;
    const bus_shape *f = frame->shape;
    /* Items only into a tree (without one, e.g. summary lines, the labels
     * would be built for nobody); the expert infos below always. */
    for (guint i = 0; tree && i < f->count; i++) {
        const addressed *a = &f->d[i];
        show_slave(f->model, a, tvb, pinfo, tree, details);
        if (a->logical) show_process_data(f->model, &a->dgram, f->returned, pinfo->num, tvb, tree);
        if (a->expected_wkc >= 0)
            proto_item_set_generated(proto_tree_add_uint(tree, hf_wkc_expected, tvb, wkc_offset(&a->dgram),
                                                         datagram_wkc, (guint32)a->expected_wkc));
    }
    for (guint i = 0; i < f->event_count; i++) {
        const bus_event *e = &f->events[i];
        expert_field *ei = e->kind == EV_COUNT ? &ei_count : e->kind == EV_MODEL ? &ei_model
                           : e->kind == EV_WKC ? &ei_wkc : &ei_ok;
        proto_tree_add_expert_format(tree, pinfo, ei, tvb, e->offset, e->length, "%s", e->text);
    }
}

/* --- statistics: a node per slave position ------------------------------ */

namespace {
const char *const st_slaves = "Slaves (returned datagrams)";
const char *const st_datagrams = "Datagrams";
const char *const st_wkc_error = "Working counter not raised";
const char *const st_al = "AL state changes";
const char *const st_mailbox = "Mailbox datagrams";
const char *const st_wkc_expected = "Unexpected working counter";
} /* namespace */

/* Rows appear with their first count (no rows of zeros). */
void bus_stats_init(stats_tree *, int) {}

void bus_stats_frame(stats_tree *st, int parent, const bus_frame *frame)
{
    if (!frame) return;
    const bus_shape *f = frame->shape;
    char label[48];
    for (guint i = 0; i < f->count; i++) {
        const addressed *a = &f->d[i];
        if (a->position < 0) continue;
        g_snprintf(label, sizeof label, "Position %d", a->position);
        int slaves_id = tick_stat_node(st, st_slaves, parent, TRUE);
        int id = tick_stat_node(st, label, slaves_id, TRUE);
        tick_stat_node(st, st_datagrams, id, FALSE);
        if (a->stats & ST_WKC_ERROR) tick_stat_node(st, st_wkc_error, id, FALSE);
        if (a->stats & ST_AL_CHANGE) tick_stat_node(st, st_al, id, FALSE);
        if (a->stats & ST_MAILBOX) tick_stat_node(st, st_mailbox, id, FALSE);
    }
    for (guint i = 0; i < f->event_count; i++)
        if (f->events[i].kind == EV_WKC) tick_stat_node(st, st_wkc_expected, parent, FALSE);
}

void bus_register(int proto, const char *filter)
{
    static hf_register_info hf[] = {DG_BUS_FIELDS(DG_HF_ROW)};
    static const char *const names[] = {DG_BUS_FIELDS(DG_FIELD_NAME)};
    dg_name_fields(hf, names, G_N_ELEMENTS(hf), filter);
    proto_register_field_array(proto, hf, (int)G_N_ELEMENTS(hf));
    static gint *ett[] = {&ett_slave, &ett_process_data, &ett_pdo_entry};
    proto_register_subtree_array(ett, (int)G_N_ELEMENTS(ett));

    static ei_register_info ei[] = {DG_BUS_EXPERTS(DG_EI_ROW)};
    static const char *const ei_names[] = {DG_BUS_EXPERTS(DG_EXPERT_NAME)};
    dg_name_experts(ei, ei_names, G_N_ELEMENTS(ei), filter);
    expert_register_field_array(expert_register_protocol(proto), ei, (int)G_N_ELEMENTS(ei));
}

} /* namespace dg_ecat */

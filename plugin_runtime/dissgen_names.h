/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Every display-filter name that the runtime, the request/response pairing
 * and each analysis register under a protocol's filter name P, as P.NAME.
 *
 * One list, read on both sides: the runtime builds its hf_register_info and
 * ei_register_info from it (labels, types and the NAME of each abbrev), and
 * the generator reserves every name in it (no rule field may take one),
 * emits the generic expert infos and fragment fields from it and lists them
 * all in `dissgen fields`. A name added here is registered, reserved, listed
 * and tested at once.
 *
 * Plain C X-macros: a list applies the macro it is given to each row.
 *   fields:   X(ID, NAME, TYPE, DISPLAY, STRINGS, LABEL, BLURB)
 *   experts:  X(ID, NAME, GROUP, SEVERITY, SUMMARY)
 *   prefixes: X(PREFIX)  fields registered under P.PREFIX (ends with '.')
 *   reserved: X(NAME)    taken, but not registered by this runtime yet
 * ID is a C identifier for the row (hf_ID, ei_ID or a member ID), NAME the
 * part of the filter name after "P.". Expert infos are fields to Wireshark
 * too (FT_NONE, named by their summary).
 */
#ifndef DISSGEN_NAMES_H
#define DISSGEN_NAMES_H

/* --- Every protocol ------------------------------------------------------ */

/* The generated code registers these for every protocol (dg_experts). */
#define DG_RUNTIME_EXPERTS(X)                                                                              \
    X(truncated, "expert.truncated", PI_MALFORMED, PI_ERROR, "The packet ends inside a field")             \
    X(past_end, "expert.past_end", PI_MALFORMED, PI_ERROR, "A length field points past the end of its data") \
    X(more_no_data, "expert.more_no_data", PI_MALFORMED, PI_WARN, /* RULES-SPEC: "an expert warning" */      \
      "The repeat flag says more follow, but no data is left")                                           \
    X(count_short, "expert.count_short", PI_MALFORMED, PI_ERROR, "Fewer instances than the count field says") \
    X(bad_length, "expert.bad_length", PI_MALFORMED, PI_ERROR, "A length or count is missing or negative")   \
    X(unused, "expert.unused", PI_PROTOCOL, PI_WARN, "A length says more bytes than its fields hold")        \
    X(bad_offset, "expert.bad_offset", PI_MALFORMED, PI_ERROR,                                             \
      "An offset table entry is out of order or out of range")

/* The runtime registers these for every protocol (dg_register). */
#define DG_RUNTIME_FIELDS(X)                                                                               \
    X(padding, "padding", FT_BYTES, BASE_NONE, NULL, "Padding",                                            \
      "Zero bytes after a container's fields, up to the end of its length")

/* --- A protocol that reassembles (Wireshark's fragment_items) -------------- */

/* The generated code registers these as frag_hf_ID. */
#define DG_FRAGMENT_FIELDS(X)                                                                              \
    X(fragments, "fragments", FT_NONE, BASE_NONE, NULL, "Message fragments", NULL)                          \
    X(fragment, "fragment", FT_FRAMENUM, BASE_NONE, NULL, "Message fragment", NULL)                         \
    X(fragment_overlap, "fragment.overlap", FT_BOOLEAN, BASE_NONE, NULL, "Message fragment overlap", NULL)  \
    X(fragment_overlap_conflicts, "fragment.overlap.conflicts", FT_BOOLEAN, BASE_NONE, NULL,                \
      "Message fragment overlapping with conflicting data", NULL)                                         \
    X(fragment_multiple_tails, "fragment.multiple_tails", FT_BOOLEAN, BASE_NONE, NULL,                      \
      "Message has multiple tail fragments", NULL)                                                        \
    X(fragment_too_long_fragment, "fragment.too_long_fragment", FT_BOOLEAN, BASE_NONE, NULL,                \
      "Message fragment too long", NULL)                                                                  \
    X(fragment_error, "fragment.error", FT_FRAMENUM, BASE_NONE, NULL, "Message defragmentation error", NULL) \
    X(fragment_count, "fragment.count", FT_UINT32, BASE_DEC, NULL, "Message fragment count", NULL)          \
    X(reassembled_in, "reassembled_in", FT_FRAMENUM, BASE_NONE, NULL, "Reassembled in", NULL)               \
    X(reassembled_length, "reassembled.length", FT_UINT32, BASE_DEC, NULL, "Reassembled length", NULL)      \
    X(reassembled_data, "reassembled.data", FT_BYTES, BASE_NONE, NULL, "Reassembled data", NULL)

/* --- A protocol with <pairing> (dissgen_pairing.cpp) ----------------------- */

#define DG_PAIRING_FIELDS(X)                                                                               \
    X(response_in, "response_in", FT_FRAMENUM, BASE_NONE, FRAMENUM_TYPE(FT_FRAMENUM_RESPONSE), "Response in", \
      "The frame that answers this one")                                                                  \
    X(request_in, "request_in", FT_FRAMENUM, BASE_NONE, FRAMENUM_TYPE(FT_FRAMENUM_REQUEST), "Request in",    \
      "The frame this one answers")                                                                       \
    X(time, "time", FT_RELATIVE_TIME, BASE_NONE, NULL, "Round trip", "Time from the request to this response") \
    X(no_response_to, "no_response_to", FT_FRAMENUM, BASE_NONE, FRAMENUM_TYPE(FT_FRAMENUM_REQUEST),          \
      "No response to", "A request this message proves lost (its key reused, or its timeout passed)")     \
    X(no_request, "no_request", FT_NONE, BASE_NONE, NULL, "Request not captured",                           \
      "A response whose request is not known: not captured, or given up as lost before it came")

#define DG_PAIRING_EXPERTS(X)                                                                              \
    X(no_response, "expert.no_response", PI_SEQUENCE, PI_WARN, "No response seen")                          \
    X(duplicate, "expert.duplicate", PI_SEQUENCE, PI_NOTE, "Duplicate message")                             \
    X(out_of_order, "expert.out_of_order", PI_SEQUENCE, PI_NOTE, "Response out of order")

/* --- A protocol whose values read request{...} (dissgen_request.cpp) ------- */

#define DG_REQUEST_CONTEXT_EXPERTS(X)                                                                      \
    X(no_request_context, "expert.no_request_context", PI_SEQUENCE, PI_NOTE,                                \
      "The request of this response is not known (not captured or given up as lost before it came): the values read from it are unknown")

/* --- A protocol with <cycles> (dissgen_cycles.cpp) ------------------------- */

#define DG_CYCLES_FIELDS(X)                                                                                \
    X(stream_cycle, "cycle", FT_UINT32, BASE_DEC, NULL, "Cycle",                                            \
      "The cycle this message belongs to: 1, 2, ... in the order the streams became cycles")              \
    X(stream_period, "cycle.period", FT_RELATIVE_TIME, BASE_NONE, NULL, "Cycle period",                     \
      "Time since the stream's previous message")                                                         \
    X(stream_jitter, "cycle.jitter", FT_RELATIVE_TIME, BASE_NONE, NULL, "Cycle jitter",                     \
      "The period minus the cycle's nominal period (the median of its periods so far)")                    \
    X(stream_lost, "cycle.lost", FT_UINT32, BASE_DEC, NULL, "Messages lost",                                \
      "Messages of the stream missing right before this one (its sequence count, or its period)")          \
    X(stream_duplicate, "cycle.duplicate", FT_FRAMENUM, BASE_NONE, NULL, "Duplicate of",                    \
      "The stream's previous message, whose sequence count this one repeats")

#define DG_CYCLES_EXPERTS(X)                                                                               \
    X(stream_lost_expert, "expert.cycle_lost", PI_SEQUENCE, PI_WARN,                                        \
      "Messages of the stream lost (a gap in its sequence count or its period)")                            \
    X(stream_duplicate_expert, "expert.cycle_duplicate", PI_SEQUENCE, PI_NOTE,                              \
      "Message of the stream repeated (its sequence count did not advance)")

/* --- The ethercat-esc analysis (ethercat_analysis.cpp) ------------------------ */

#define DG_ANALYSIS_ETHERCAT_ESC "ethercat-esc"

#define DG_ESC_FIELDS(X)                                                                                   \
    X(esc, "esc", FT_NONE, BASE_NONE, NULL, "Out and back (ESC forwarding)",                                \
      "What the segment did to the frame, datagram by datagram")                                          \
    X(datagram, "esc.datagram", FT_NONE, BASE_NONE, NULL, "Datagram", "One returned datagram against the one sent") \
    X(wkc_added, "esc.wkc_added", FT_INT32, BASE_DEC, NULL, "Working counter added",                        \
      "Returned working counter minus the one sent")                                                      \
    X(slaves_passed, "esc.slaves_passed", FT_UINT16, BASE_DEC, NULL, "Slaves passed",                       \
      "How far the auto-increment address advanced (auto-increment and broadcast commands)")              \
    X(data_changed, "esc.data_changed", FT_BOOLEAN, BASE_NONE, NULL, "Data changed",                        \
      "The data came back different from what was sent")

/* ethercat_cycles.cpp: a sent frame of a cycle (manual, "Cycles"). */
#define DG_CYCLE_FIELDS(X)                                                                                 \
    X(cycle, "cycle", FT_UINT16, BASE_DEC, NULL, "Cycle",                                                   \
      "The cycle this sent frame belongs to: 1, 2, ... in order of first appearance")                      \
    X(period, "cycle.period", FT_RELATIVE_TIME, BASE_NONE, NULL, "Cycle period",                            \
      "Time since the cycle's previous frame sent")                                                       \
    X(jitter, "cycle.jitter", FT_RELATIVE_TIME, BASE_NONE, NULL, "Cycle jitter",                            \
      "The period minus the cycle's nominal period (the median of its periods so far)")

/* ethercat_cycles.cpp: the reference clock's system time in a returned frame. */
#define DG_DC_FIELDS(X)                                                                                    \
    X(systime, "dc.systime", FT_UINT64, BASE_DEC, NULL, "DC system time (ns)",                              \
      "The reference clock's system time as the returned FRMW/ARMW of 0x0910 carries it (32 or 64 bits)")  \
    X(drift, "dc.drift", FT_DOUBLE, BASE_NONE, NULL, "DC drift (ns/s)",                                     \
      "DC time elapsed minus capture time elapsed since the capture's first system time, per second "      \
      "of capture time (ppb); positive: the reference clock runs faster than the capture's")

#define DG_ESC_EXPERTS(X)                                                                                  \
    X(changed, "expert.changed", PI_PROTOCOL, PI_ERROR,                                                     \
      "Returned datagram's command, index, length or address changed")                                    \
    X(frame_length, "expert.frame_length", PI_PROTOCOL, PI_ERROR, "Returned frame's length changed")        \
    X(write_changed, "expert.write_changed", PI_PROTOCOL, PI_ERROR, "Written data came back changed")       \
    X(wkc_down, "expert.wkc_down", PI_PROTOCOL, PI_ERROR, "Working counter went down")                      \
    X(forwarding, "expert.forwarding", PI_PROTOCOL, PI_WARN,                                                \
      "Auto-increment address advanced differently from the frame's other datagrams")

/* --- The ethercat-esc analysis: the bus model (ethercat_bus.cpp) ----------- */

#define DG_BUS_FIELDS(X)                                                                                   \
    X(process_data, "process_data", FT_NONE, BASE_NONE, NULL, "Process data",                               \
      "One slave's PDO entries in this logical datagram (designed, or identified from its SII)")          \
    X(wkc_expected, "wkc.expected", FT_UINT16, BASE_DEC, NULL, "Expected working counter",                  \
      "From the ENI's cyclic commands (Cnt), else from the slaves' FMMU configuration")                    \
    X(slave, "slave", FT_NONE, BASE_NONE, NULL, "Slave", "The slave this datagram addresses, as the capture shows it") \
    X(position, "slave.position", FT_UINT16, BASE_DEC, NULL, "Position", "Position on the segment, from 0")  \
    X(station, "slave.station", FT_UINT16, BASE_HEX, NULL, "Station address",                               \
      "Configured station address (register 0x0010)")                                                     \
    X(alias, "slave.alias", FT_UINT16, BASE_HEX, NULL, "Station alias", "Configured station alias (register 0x0012)") \
    X(vendor, "slave.vendor", FT_UINT32, BASE_HEX, NULL, "Vendor id", "From the SII EEPROM (word 0x0008)")   \
    X(product, "slave.product", FT_UINT32, BASE_HEX, NULL, "Product code", "From the SII EEPROM (word 0x000A)") \
    X(revision, "slave.revision", FT_UINT32, BASE_HEX, NULL, "Revision", "From the SII EEPROM (word 0x000C)") \
    X(serial, "slave.serial", FT_UINT32, BASE_HEX, NULL, "Serial number", "From the SII EEPROM (word 0x000E)") \
    X(name, "slave.name", FT_STRING, BASE_NONE, NULL, "Model",                                              \
      "The device type of the ESI catalogue embedded with --esi")                                         \
    X(pdo_entry, "pdo.entry", FT_STRING, BASE_NONE, NULL, "PDO entry",                                      \
      "A PDO entry the master mapped over CoE that has no registered field: its object "                  \
      "(index:subindex), with the ESI name and type when the model's ESI file has it")                    \
    X(pdo_value, "pdo.value", FT_UINT64, BASE_DEC, NULL, "Value",                                           \
      "The PDO entry's bits (up to 64), least significant first, as an unsigned number")

#define DG_BUS_EXPERTS(X)                                                                                  \
    X(count, "expert.network.count", PI_PROTOCOL, PI_WARN, "Slave count differs from the network design")   \
    X(model, "expert.network.model", PI_PROTOCOL, PI_WARN, "Slave model differs from the network design")   \
    X(ok, "expert.network.ok", PI_PROTOCOL, PI_CHAT, "The bus matches the network design")                  \
    X(wkc, "expert.wkc", PI_PROTOCOL, PI_WARN, "Working counter differs from the expected one")

/* The fields of the embedded ESI catalogue's PDO entries (P.pdo.MODEL.PDO.ENTRY,
 * emitted with --esi or --network), beside pdo.entry and pdo.value above. */
#define DG_BUS_PDO_PREFIX "pdo."
#define DG_BUS_PREFIXES(X) X(DG_BUS_PDO_PREFIX)

/* --- Building the runtime's registration arrays from the lists ------------ */

/* An hf_register_info initializer whose abbrev the registration fills in
 * (P.NAME, with g_strdup_printf): {&hf_ID, {LABEL, NULL, TYPE, ...}}. */
#define DG_HF_ROW(id, name, type, display, strings, label, blurb) \
    {&hf_##id, {label, NULL, type, display, strings, 0x0, blurb, HFILL}},
/* An ei_register_info initializer, its name filled in likewise. */
#define DG_EI_ROW(id, name, group, severity, summary) {&ei_##id, {NULL, group, severity, summary, EXPFILL}},
/* The NAME of a row, for an array of names parallel to the rows. */
#define DG_FIELD_NAME(id, name, type, display, strings, label, blurb) name,
#define DG_EXPERT_NAME(id, name, group, severity, summary) name,

#endif /* DISSGEN_NAMES_H */

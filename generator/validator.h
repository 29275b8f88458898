// SPDX-License-Identifier: GPL-2.0-or-later
// Stage 2: check a parsed protocol against the rule language and derive what
// the emitter needs: effective byte orders and display types, bit groups and
// masks, display-filter names, and the value slots that lengths, counts,
// repeat flags, conditions and summaries read at run time.
#pragma once

#include "diagnostics.h"
#include "model.h"

namespace dissgen {

// Returns true when the protocol has no errors (warnings allowed).
bool validate(Protocol& proto, Diagnostics& diags);

// The filter-name segment a node gets from its name alone ("" when the name
// has no ASCII letters or digits).
std::string segment_from_name(const std::string& name);

bool is_valid_filter_segment(const std::string& s);

// issue 10b: a node's name without its "{i}" (instance number) markers, for
// the filter name of a block repeated at a stride.
std::string name_without_index(const std::string& name);

// Every generated protocol registers these expert infos as P.expert.NAME
// (emit_cpp.cpp), so no field may take those filter names.
constexpr const char* kExpertNames[] = {"truncated", "past_end", "more_no_data", "count_short", "bad_length",
                                        "unused", "bad_offset"};
// issue 10a: a protocol that reassembles registers these fields as P.NAME
// (emit_cpp.cpp; the fragment_items of Wireshark's reassembly API).
constexpr const char* kFragmentNames[] = {"fragments",        "fragment",
                                          "fragment.overlap", "fragment.overlap.conflicts",
                                          "fragment.multiple_tails", "fragment.too_long_fragment",
                                          "fragment.error",   "fragment.count",
                                          "reassembled_in",   "reassembled.length",
                                          "reassembled.data"};

bool is_reserved_expert_name(const std::string& protocol_filter, const std::string& field_filter);

// Fields the runtime registers for every protocol as P.NAME (plugin_runtime/
// dissgen_runtime.cpp): the zero padding after a known-length container's fields.
constexpr const char* kRuntimeFieldNames[] = {"padding"};
bool is_reserved_runtime_field(const std::string& protocol_filter, const std::string& field_filter);

// issue 11: fields and expert infos the runtime registers as P.NAME for a
// protocol with <pairing> (plugin_runtime/dissgen_pairing.cpp), and for the
// "ethercat-esc" analysis (plugin_runtime/ethercat_esc.cpp).
constexpr const char* kPairingNames[] = {"response_in", "request_in", "time", "expert.no_response",
                                         "expert.duplicate", "expert.out_of_order"};
constexpr const char* kEthercatEscNames[] = {"esc",
                                             "esc.datagram",
                                             "esc.wkc_added",
                                             "esc.slaves_passed",
                                             "esc.data_changed",
                                             "expert.changed",
                                             "expert.frame_length",
                                             "expert.write_changed",
                                             "expert.wkc_down",
                                             "expert.forwarding"};
// The name a field may not take because <pairing> (or its analysis) uses it; "" if none.
std::string reserved_pairing_name(const Protocol& proto, const std::string& field_filter);

}  // namespace dissgen

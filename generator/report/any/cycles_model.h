// SPDX-License-Identifier: GPL-2.0-or-later
// The report's model of a capture of any protocol whose rules declare
// <cycles> or <pairing>, as its plugin shows it: each cycle's figures as
// `tshark -z P,cycles` prints them (the plugin's one definition: the report
// computes none of them), each cycle's period and jitter per message
// (P.cycle.period, P.cycle.jitter), the losses and repeats of its streams
// (P.cycle.lost, P.cycle.duplicate), the round trips and lost requests of its
// pairing (P.time, P.no_response_to). Every field is named through
// runtime_names.h.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "../capture_stream.h"
#include "../charts.h"
#include "../tshark_values.h"

namespace dissgen {

// One cycle's block of -z P,cycles, each figure as printed there.
struct StreamCycleFigures {
    uint64_t first_frame = 0;
    uint64_t messages = 0;
    int64_t nominal = 0;           // nominal period (ns)
    bool has_period = false;       // false: "period: none" (no regular period yet)
    Quantiles period;
    std::string jitter_sd = "";    // jitter std dev (ns), the text printed ("812.4")
    bool counted = false;          // losses are told (a sequence count, or lost="period"): lost is printed
    bool duplicates_counted = false;  // the stream has a sequence count: duplicates are printed
    uint64_t lost = 0, duplicates = 0;
    bool requests = false;         // requests="yes": the round trips and answers are printed
    bool has_round_trip = false;   // false: "round trip: none"
    Quantiles round_trip;
    uint64_t answered = 0, unanswered = 0;
};

struct StreamCycle {
    unsigned number = 0;
    std::string signature;  // "Connection ID 0x..., sender 10.0.0.1:2222"
    StreamCycleFigures figures;
    std::vector<TimedValue> period, jitter;  // per message, from P.cycle.period / P.cycle.jitter
};

// A frame that marks something: messages lost before it (count), a repeat
// (count 1), a request it proves unanswered (frame: that request).
struct StreamEvent {
    double t;
    uint32_t frame;
    unsigned cycle;   // 0: not (yet) a cycle's message
    uint64_t count;
};

struct CyclesModel {
    std::vector<std::string> captures;  // the files read, in order, as one capture
    std::string protocol;                // the plugin's filter name ("enipr")
    uint64_t frames = 0;
    double duration = 0;                 // seconds, first to last frame
    bool has_cycles = false;             // the plugin has <cycles> fields
    bool has_pairing = false;            // the plugin has <pairing> fields
    std::map<unsigned, StreamCycle> cycles;
    std::vector<StreamEvent> lost;        // P.cycle.lost
    std::vector<StreamEvent> duplicates;  // P.cycle.duplicate
    std::vector<TimedValue> round_trip;   // P.time
    std::vector<StreamEvent> no_response; // P.no_response_to: the requests, when each was sent
    uint64_t messages_lost() const;
};

// The filter names of the protocols of `known` (the installed tshark's
// fields) whose plugins show cycles (P.expert.cycle_lost) or dissgen's
// pairing (P.expert.no_response with P.time, P.request_in and
// P.no_response_to), but not `except` (the EtherCAT one, which has its own
// report), sorted.
std::vector<std::string> cycles_protocols(const std::vector<std::string>& known, const std::string& except);

// Builds the model row by row from a capture read with fields(), then from
// -z P,cycles printed after the rows (statistics_args()).
class CyclesModelBuilder {
public:
    static std::vector<std::string> fields(const std::string& filter, const std::vector<std::string>& known);
    static std::vector<std::string> statistics_args(const std::string& filter, const std::vector<std::string>& known);

    CyclesModelBuilder(const std::string& filter, const std::vector<std::string>& fields, CyclesModel& model);
    void add(const FieldRow& row);
    void add_statistics_line(std::string_view line);

private:
    std::string_view value(const FieldRow& row, const char* runtime_name) const;
    void add_cycle_messages(const FieldRow& row, double t, unsigned cycle);
    void add_cycle_message(const FieldRow& row, double t, unsigned cycle, size_t index, size_t count);
    void add_stream_marks(const FieldRow& row, double t, uint32_t frame, unsigned cycle);
    void add_pairing(const FieldRow& row, double t);

    std::string filter_;
    CyclesModel& model_;
    FieldColumns columns_;
    CaptureClock clock_;
    StreamCycle* statistics_cycle_ = nullptr;  // the -z P,cycles block being read
    // each frame's time (NaN: not one of the protocol's), so that a request
    // proved unanswered is marked when it was sent, not when it was proved
    std::vector<double> frame_times_;
};

}  // namespace dissgen

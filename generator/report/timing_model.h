// SPDX-License-Identifier: GPL-2.0-or-later
// The report's model of an EtherCAT capture's timing, built from the fields
// the plugin shows (ecatr.cycle*, ecatr.time, the losses and working-counter
// experts, the slaves' AL status): what `dissgen report` draws, and the same
// figures as `tshark -z ecatr,cycles`.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "capture_stream.h"

namespace dissgen {

// A point in a time series: seconds since the capture's first frame, a value in ns.
struct TimedValue {
    double t;
    int64_t ns;
};

// min/median/p99/max of a set of ns values (the lower median, the nearest-rank
// 99th percentile, as tshark -z ecatr,cycles); zero when empty.
struct Spread {
    size_t count = 0;
    int64_t min = 0, median = 0, p99 = 0, max = 0;
    double mean = 0, stddev = 0;  // population standard deviation
};
Spread spread_of(std::vector<int64_t> values);

// One cycle, as `tshark -z ecatr,cycles` counts it (docs/manual.md, "Cycles").
struct Cycle {
    unsigned number = 0;
    std::string signature;          // "LRW 0x00010000 (4 bytes), FRMW 0x1001:0x0910 (8 bytes)"
    uint64_t frames = 0;            // sent frames of the cycle
    uint64_t returned = 0;          // of them, those that came back
    uint64_t wkc_errors = 0;        // returns with a datagram whose counter was not raised, or below
                                    // the highest that datagram of the cycle returned before
    int64_t nominal = 0;            // the last frame's nominal period (its period minus its jitter)
    std::vector<TimedValue> period, jitter, round_trip;
    std::vector<uint32_t> sent;     // its frames, in order
    std::vector<uint32_t> answered; // those that came back, in the order their returns came
    std::vector<int64_t> wkc_high;  // per datagram, the highest working counter returned so far
    // Lost: not answered while a later frame of the cycle was (those still in
    // flight at the end are not lost).
    uint64_t lost() const;
};

struct Event {
    double t;
    uint32_t frame;
    unsigned cycle;  // 0: not a cycle's frame
};

// AL state of one slave over time, from its AL status reads.
struct SlaveTimeline {
    std::string name;                                 // the model's name from the ESI ("EL2004"), or ""
    std::vector<std::pair<double, unsigned>> states;  // (t, AL state), when it changed
};

struct TimingModel {
    std::string capture;
    uint64_t frames = 0;
    double duration = 0;            // seconds, first to last frame
    std::map<unsigned, Cycle> cycles;
    std::vector<TimedValue> round_trip;  // every return, cycle or not
    std::vector<Event> lost, wkc_errors;  // ecatr.no_response_to, ecatr.expert.wkc
    std::map<unsigned, SlaveTimeline> slaves;  // by position
    std::vector<std::string> network;          // the network check's findings (the expert infos' texts)
    std::vector<uint32_t> network_frames;      // the frames that carry them
    bool has_cycle_fields = false;             // the plugin shows ecatr.cycle
};

// Builds the model row by row from a capture read with timing_fields().
class TimingModelBuilder {
public:
    // The fields to ask tshark for, among `known` (those the installed tshark has).
    static std::vector<std::string> timing_fields(const std::vector<std::string>& known);

    // What else to ask tshark for: the network check's expert infos (-z expert),
    // whose texts come after the rows.
    static std::vector<std::string> statistics_args(const std::vector<std::string>& known);

    TimingModelBuilder(const std::vector<std::string>& fields, TimingModel& model);
    void add(const FieldRow& row);
    // A line of the statistics after the rows.
    void add_statistics_line(std::string_view line);

private:
    int column(const char* field) const;
    std::string_view value(const FieldRow& row, int column) const;
    void add_cycle_frame(const FieldRow& row, uint32_t frame, double t, unsigned cycle);
    std::string signature_text(const FieldRow& row) const;
    void add_return(const FieldRow& row, double t);
    void count_wkc_error(Cycle& c, const FieldRow& row);
    void add_slave_states(const FieldRow& row, double t);

    TimingModel& model_;
    std::unordered_map<std::string, int> columns_;
    std::unordered_map<uint32_t, unsigned> cycle_of_frame_;  // sent frames of a cycle
    int64_t first_s_ = -1, first_ns_ = 0;
};

// "0.001000250" or "-0.000000125" (seconds, as tshark prints relative times) -> ns.
bool parse_seconds_ns(std::string_view text, int64_t& ns);

// EtherCAT's command names (APRD, ..., FRMW); "cmd 0xNN" for others.
std::string ethercat_command_name(unsigned cmd);

// "INIT", "PREOP", "BOOT", "SAFEOP", "OP", with " +ERR" when the error bit is set.
std::string al_state_name(unsigned status);

}  // namespace dissgen

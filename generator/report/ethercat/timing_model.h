// SPDX-License-Identifier: GPL-2.0-or-later
// The report's model of an EtherCAT capture's timing, as the plugin shows it:
// each cycle's figures as `tshark -z P,cycles` prints them (the plugin's one
// definition: the report computes none of them), the time series the charts
// draw from the plugin's fields (P.cycle*, P.time, the losses and
// working-counter experts, the slaves' AL status), the network check's
// findings. Every runtime field is named through runtime_names.h.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "../capture_stream.h"
#include "../charts.h"
#include "../tshark_values.h"

namespace dissgen {

// One cycle's figures, the lines of its -z P,cycles block (docs/manual.md, "Cycles").
struct CycleFigures {
    uint64_t frames = 0;        // sent frames of the cycle
    int64_t nominal = 0;        // nominal period (ns)
    Quantiles period;
    double jitter_sd = 0;       // jitter std dev (ns)
    Quantiles round_trip;
    uint64_t returned = 0;      // frames returned
    uint64_t lost = 0;          // frames lost
    uint64_t wkc_errors = 0;    // working counter errors (the per-cycle kind: not raised, or below
                                // the highest that datagram of the cycle returned before)
};

struct Cycle {
    unsigned number = 0;
    std::string signature;       // "LRW 0x00010000 (4 bytes), FRMW 0x1001:0x0910 (8 bytes)"
    CycleFigures figures;
    std::vector<TimedValue> period, jitter;  // per sent frame, from P.cycle.period / P.cycle.jitter
};

struct Event {
    double t;
    uint32_t frame;
};

// AL state of one slave over time, from its AL status reads.
struct SlaveTimeline {
    std::string name;                                 // the model's name from the ESI ("EL2004"), or ""
    std::vector<std::pair<double, unsigned>> states;  // (t, AL state), when it changed
    void observe(double t, unsigned status);          // an AL status read at t
};

struct TimingModel {
    std::vector<std::string> captures;  // the files read, in order, as one capture
    std::string protocol;           // the plugin's filter name ("ecatr")
    uint64_t frames = 0;
    double duration = 0;            // seconds, first to last frame
    std::map<unsigned, Cycle> cycles;
    std::vector<TimedValue> round_trip;  // every return, cycle or not (P.time)
    std::vector<Event> lost;             // P.no_response_to
    std::vector<Event> wkc_differs;      // P.expert.wkc: differs from the expected (designed) one
    std::map<unsigned, SlaveTimeline> slaves;    // by position
    std::map<unsigned, SlaveTimeline> stations;  // by configured station address, whose position
                                                 // was never learned (a capture started after the scan)
    std::vector<std::string> network;          // the network check's findings (the expert infos' texts)
    std::vector<uint32_t> network_frames;      // the frames that carry them
    bool has_cycle_fields = false;             // the plugin shows P.cycle
};

// The filter name of the protocol whose plugin runs the ethercat-esc analysis
// (its fields among `known`, those the installed tshark has), or "".
std::string ethercat_protocol(const std::vector<std::string>& known);

// Builds the model row by row from a capture read with fields(), then from
// the statistics printed after the rows (statistics_args()).
class TimingModelBuilder {
public:
    // The fields to ask tshark for, among `known`, for protocol `filter`.
    static std::vector<std::string> fields(const std::string& filter, const std::vector<std::string>& known);

    // The statistics to ask tshark for: -z P,cycles, and the network check's
    // expert infos (-z expert), whose texts come after the rows.
    static std::vector<std::string> statistics_args(const std::string& filter, const std::vector<std::string>& known);

    TimingModelBuilder(const std::string& filter, const std::vector<std::string>& fields, TimingModel& model);
    void add(const FieldRow& row);
    // A line of the statistics after the rows.
    void add_statistics_line(std::string_view line);

private:
    int column(const std::string& field) const;
    int runtime_column(const char* name) const;
    std::string_view value(const FieldRow& row, int column) const;
    void add_cycle_frame(const FieldRow& row, double t, unsigned cycle);
    void add_return(const FieldRow& row, double t);
    void add_slave_states(const FieldRow& row, double t);
    void add_station_states(const FieldRow& row, const std::vector<std::string_view>& statuses, double t);
    bool add_cycle_statistics_line(std::string_view line);
    void add_network_line(std::string_view line);

    std::string filter_;
    TimingModel& model_;
    std::unordered_map<std::string, int> columns_;
    Cycle* statistics_cycle_ = nullptr;  // the -z P,cycles block being read
    CaptureClock clock_;
};

// "INIT", "PREOP", "BOOT", "SAFEOP", "OP" (the state bits only, not the error bit).
std::string al_state_name(unsigned status);

}  // namespace dissgen

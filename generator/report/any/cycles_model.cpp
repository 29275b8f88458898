// SPDX-License-Identifier: GPL-2.0-or-later
#include "cycles_model.h"

#include <algorithm>
#include <cmath>

#include "../../runtime_names.h"

namespace dissgen {

namespace {

// The runtime's fields the report reads, each optional: asked for only when
// the installed plugin has it (a protocol with <pairing> and no <cycles>).
const char* const kRuntimeFields[] = {
    runtime_field::stream_cycle, runtime_field::stream_period,    runtime_field::stream_jitter,
    runtime_field::stream_lost,  runtime_field::stream_duplicate, runtime_field::time,
    runtime_field::no_response_to,
};

// "P.NAME" of `known` -> "P", for the names ending in ".NAME".
std::vector<std::string> filters_with(const std::vector<std::string>& known, const char* name) {
    const std::string tail = std::string(".") + name;
    std::vector<std::string> filters;
    for (const std::string& f : known)
        if (f.size() > tail.size() && f.compare(f.size() - tail.size(), tail.size(), tail) == 0)
            filters.push_back(f.substr(0, f.size() - tail.size()));
    return filters;
}

// Wireshark's own dissectors have P.time and P.request_in too (http, dcerpc):
// dissgen's pairing is told by its expert info, which they lack.
bool has_pairing(const std::vector<std::string>& known, const std::string& filter) {
    for (const char* name : {runtime_field::time, runtime_field::request_in, runtime_field::no_response_to})
        if (!has_field(known, runtime_filter_name(filter, name))) return false;
    return true;
}

// One "  label: value" line of a cycle's block into its figure, as
// plugin_runtime/dissgen_cycles.cpp prints it.
bool set_figure(StreamCycleFigures& f, std::string_view label, std::string_view text) {
    uint64_t n = 0;
    if (label == "first frame") return parse_uint(text, f.first_frame, 10);
    if (label == "messages") return parse_uint(text, f.messages, 10);
    if (label == "nominal period (ns)") return parse_uint(text, n, 10) && (f.nominal = static_cast<int64_t>(n), true);
    if (label == "period") return text == "none";
    if (label == "period min/median/p99/max (ns)") return (f.has_period = parse_quantiles(text, f.period));
    if (label == "jitter std dev (ns)") return (f.jitter_sd = std::string(text), true);
    if (label == "messages lost") return (f.counted = true) && parse_uint(text, f.lost, 10);
    if (label == "duplicates") return (f.duplicates_counted = true) && parse_uint(text, f.duplicates, 10);
    if (label == "round trip") return (f.requests = true) && text == "none";
    if (label == "round trip min/median/p99/max (ns)")
        return (f.requests = true) && (f.has_round_trip = parse_quantiles(text, f.round_trip));
    if (label == "requests answered") return (f.requests = true) && parse_uint(text, f.answered, 10);
    if (label == "requests unanswered") return (f.requests = true) && parse_uint(text, f.unanswered, 10);
    return false;
}

}  // namespace

uint64_t CyclesModel::messages_lost() const {
    uint64_t n = 0;
    for (const StreamEvent& e : lost) n += e.count;
    return n;
}

std::vector<std::string> cycles_protocols(const std::vector<std::string>& known, const std::string& except) {
    std::vector<std::string> found = filters_with(known, runtime_expert::stream_lost_expert);
    for (const std::string& f : filters_with(known, runtime_expert::no_response))
        if (has_pairing(known, f)) found.push_back(f);
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
    found.erase(std::remove(found.begin(), found.end(), except), found.end());
    return found;
}

std::vector<std::string> CyclesModelBuilder::fields(const std::string& filter, const std::vector<std::string>& known) {
    std::vector<std::string> asked{"frame.number", "frame.time_epoch"};
    for (const char* f : kRuntimeFields) {
        std::string name = runtime_filter_name(filter, f);
        if (has_field(known, name)) asked.push_back(name);
    }
    return asked;
}

std::vector<std::string> CyclesModelBuilder::statistics_args(const std::string& filter,
                                                             const std::vector<std::string>& known) {
    if (!has_field(known, runtime_filter_name(filter, runtime_expert::stream_lost_expert))) return {};
    return {"-z", filter + ",cycles"};
}

CyclesModelBuilder::CyclesModelBuilder(const std::string& filter, const std::vector<std::string>& fields,
                                       CyclesModel& model)
    : filter_(filter), model_(model), columns_(fields) {
    model_.protocol = filter;
    auto asked = [&](const char* name) { return has_field(fields, runtime_filter_name(filter, name)); };
    model_.has_cycles = asked(runtime_field::stream_cycle);
    model_.has_pairing = asked(runtime_field::time);
}

std::string_view CyclesModelBuilder::value(const FieldRow& row, const char* runtime_name) const {
    return columns_.get(row, runtime_filter_name(filter_, runtime_name));
}

// -z P,cycles: "Cycle N: SIGNATURE", then its figures as "  label: value".
void CyclesModelBuilder::add_statistics_line(std::string_view line) {
    uint64_t number = 0;
    size_t colon = line.find(": ");
    if (line.rfind("Cycle ", 0) == 0 && colon != std::string_view::npos &&
        parse_uint(line.substr(6, colon - 6), number, 10)) {
        statistics_cycle_ = &model_.cycles[static_cast<unsigned>(number)];
        statistics_cycle_->number = static_cast<unsigned>(number);
        statistics_cycle_->signature = std::string(line.substr(colon + 2));
        return;
    }
    if (!statistics_cycle_ || line.rfind("  ", 0) != 0 || colon == std::string_view::npos) {
        statistics_cycle_ = nullptr;
        return;
    }
    set_figure(statistics_cycle_->figures, line.substr(2, colon - 2), line.substr(colon + 2));
}

void CyclesModelBuilder::add(const FieldRow& row) {
    uint64_t frame = 0, cycle = 0;
    double t = 0;
    if (!parse_uint(columns_.get(row, "frame.number"), frame) || !clock_.at(columns_.get(row, "frame.time_epoch"), t))
        return;
    model_.frames++;
    model_.duration = t;
    if (frame >= frame_times_.size()) frame_times_.resize(frame + 1, std::nan(""));
    frame_times_[frame] = t;
    // A message of no cycle (yet) has no P.cycle but may still show losses.
    // A frame of several messages (a TCP segment) has a P.cycle for each one
    // in a cycle; its periods, jitters, losses and repeats go to its cycle
    // when all its messages are of one.
    const std::vector<std::string_view> cycles = split_values(value(row, runtime_field::stream_cycle));
    auto same = [&](std::string_view c) { return c == cycles[0]; };
    const bool one_cycle = !cycles.empty() && std::all_of(cycles.begin(), cycles.end(), same);
    if (one_cycle && parse_uint(cycles[0], cycle) && cycle > 0) {
        add_cycle_messages(row, t, static_cast<unsigned>(cycle));
    } else {
        for (size_t i = 0; i < cycles.size(); ++i)
            if (parse_uint(cycles[i], cycle) && cycle > 0)
                add_cycle_message(row, t, static_cast<unsigned>(cycle), i, cycles.size());
    }
    if (!one_cycle || !parse_uint(cycles[0], cycle)) cycle = 0;
    add_stream_marks(row, t, static_cast<uint32_t>(frame), static_cast<unsigned>(cycle));
    add_pairing(row, t);
}

// Every period and jitter of a frame whose messages are all of cycle `number`.
void CyclesModelBuilder::add_cycle_messages(const FieldRow& row, double t, unsigned number) {
    StreamCycle& c = model_.cycles[number];
    c.number = number;
    int64_t ns = 0;
    for (std::string_view shown : split_values(value(row, runtime_field::stream_period)))
        if (parse_seconds_ns(shown, ns)) c.period.push_back({t, ns});
    for (std::string_view shown : split_values(value(row, runtime_field::stream_jitter)))
        if (parse_seconds_ns(shown, ns)) c.jitter.push_back({t, ns});
}

// Message `index` of the `count` in the frame that are in a cycle, in a
// frame of several cycles: a duplicate has no period and only regular
// messages have a jitter, so the frame's periods (jitters) are matched to
// its messages only when every one has one.
void CyclesModelBuilder::add_cycle_message(const FieldRow& row, double t, unsigned number, size_t index, size_t count) {
    StreamCycle& c = model_.cycles[number];
    c.number = number;
    const std::vector<std::string_view> periods = split_values(value(row, runtime_field::stream_period));
    const std::vector<std::string_view> jitters = split_values(value(row, runtime_field::stream_jitter));
    int64_t period = 0, jitter = 0;
    if (periods.size() == count && parse_seconds_ns(periods[index], period)) c.period.push_back({t, period});
    if (jitters.size() == count && parse_seconds_ns(jitters[index], jitter)) c.jitter.push_back({t, jitter});
}

// Each message's loss and repeat: a frame of several messages has a value of
// each for every message that shows one.
void CyclesModelBuilder::add_stream_marks(const FieldRow& row, double t, uint32_t frame, unsigned cycle) {
    for (std::string_view shown : split_values(value(row, runtime_field::stream_lost))) {
        uint64_t lost = 0;
        if (parse_uint(shown, lost, 10) && lost > 0) model_.lost.push_back({t, frame, cycle, lost});
    }
    for (size_t i = 0; i < split_values(value(row, runtime_field::stream_duplicate)).size(); ++i)
        model_.duplicates.push_back({t, frame, cycle, 1});
}

void CyclesModelBuilder::add_pairing(const FieldRow& row, double t) {
    // a frame holding several responses (a TCP segment) has a round trip for each
    for (std::string_view shown : split_values(value(row, runtime_field::time))) {
        int64_t rtt = 0;
        if (parse_seconds_ns(shown, rtt)) model_.round_trip.push_back({t, rtt});
    }
    for (std::string_view request : split_values(value(row, runtime_field::no_response_to))) {
        uint64_t f = 0;
        if (!parse_uint(request, f)) continue;
        const double sent = f < frame_times_.size() && !std::isnan(frame_times_[f]) ? frame_times_[f] : t;
        model_.no_response.push_back({sent, static_cast<uint32_t>(f), 0, 1});
    }
}

}  // namespace dissgen

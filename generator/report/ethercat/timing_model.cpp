// SPDX-License-Identifier: GPL-2.0-or-later
#include "timing_model.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "../../runtime_names.h"
#include "../../../plugin_runtime/ethercat/ethercat_commands.h"

namespace dissgen {

namespace {

// The rule file's names of what the report reads beyond the runtime's
// (rules/ethercat.xml): an AL status read (register 0x0130), and the
// addressing of the datagrams, which names the slave read when the plugin
// never learned its position. P.datagram.adp and .ado are shown for the
// datagrams that are not logical (LRD/LWR/LRW) only.
const char kAlStatusField[] = "datagram.reg.alstatus.status";
const char kCommandField[] = "datagram.cmd";
const char kAddressField[] = "datagram.adp";
const char kOffsetField[] = "datagram.ado";
const char* const kRuleFields[] = {kAlStatusField, kCommandField, kAddressField, kOffsetField};
constexpr uint64_t kAlStatusRegister = 0x0130;

// The runtime's fields the report reads (runtime_names.h), each optional:
// asked for only when the installed plugin has it.
const char* const kRuntimeFields[] = {
    runtime_field::cycle,    runtime_field::period,         runtime_field::jitter,
    runtime_field::time,     runtime_field::request_in,     runtime_field::no_response_to,
    runtime_field::position, runtime_field::name,
};
const char* const kRuntimeExperts[] = {
    runtime_expert::wkc, runtime_expert::ok, runtime_expert::count, runtime_expert::model,
};
// The network check's expert infos.
const char* const kNetworkExperts[] = {runtime_expert::ok, runtime_expert::count, runtime_expert::model};

}  // namespace

std::string al_state_name(unsigned status) {
    switch (status & 0x0f) {
    case 1: return "INIT";
    case 2: return "PREOP";
    case 3: return "BOOT";
    case 4: return "SAFEOP";
    case 8: return "OP";
    default: {
        char buf[16];
        std::snprintf(buf, sizeof buf, "0x%x", status & 0x0f);
        return buf;
    }
    }
}

std::string ethercat_protocol(const std::vector<std::string>& known) {
    const std::string tail = std::string(".") + runtime_field::wkc_added;
    for (const std::string& f : known)
        if (f.size() > tail.size() && f.compare(f.size() - tail.size(), tail.size(), tail) == 0) {
            std::string filter = f.substr(0, f.size() - tail.size());
            if (has_field(known, runtime_filter_name(filter, runtime_field::time))) return filter;
        }
    return "";
}

std::vector<std::string> TimingModelBuilder::fields(const std::string& filter, const std::vector<std::string>& known) {
    std::vector<std::string> names{"frame.number", "frame.time_epoch"};
    for (const char* f : kRuleFields) names.push_back(runtime_filter_name(filter, f));
    for (const char* f : kRuntimeFields) names.push_back(runtime_filter_name(filter, f));
    for (const char* e : kRuntimeExperts) names.push_back(runtime_filter_name(filter, e));
    std::vector<std::string> asked;
    for (const std::string& n : names)
        if (has_field(known, n)) asked.push_back(n);
    return asked;
}

std::vector<std::string> TimingModelBuilder::statistics_args(const std::string& filter,
                                                             const std::vector<std::string>& known) {
    std::vector<std::string> args;
    if (has_field(known, runtime_filter_name(filter, runtime_field::cycle)))
        args.insert(args.end(), {"-z", filter + ",cycles"});
    if (has_field(known, runtime_filter_name(filter, runtime_expert::ok))) {
        std::string experts;
        for (const char* e : kNetworkExperts) experts += (experts.empty() ? "" : " || ") + runtime_filter_name(filter, e);
        args.insert(args.end(), {"-z", "expert,chat," + experts});
    }
    return args;
}

TimingModelBuilder::TimingModelBuilder(const std::string& filter, const std::vector<std::string>& fields,
                                       TimingModel& model)
    : filter_(filter), model_(model) {
    model_.protocol = filter;
    for (size_t i = 0; i < fields.size(); ++i) columns_[fields[i]] = static_cast<int>(i);
    model_.has_cycle_fields = runtime_column(runtime_field::cycle) >= 0;
}

int TimingModelBuilder::column(const std::string& field) const {
    auto it = columns_.find(field);
    return it == columns_.end() ? -1 : it->second;
}

int TimingModelBuilder::runtime_column(const char* name) const { return column(runtime_filter_name(filter_, name)); }

std::string_view TimingModelBuilder::value(const FieldRow& row, int col) const {
    return col < 0 || static_cast<size_t>(col) >= row.size() ? std::string_view() : row[static_cast<size_t>(col)];
}

void TimingModelBuilder::add_statistics_line(std::string_view line) {
    if (!add_cycle_statistics_line(line)) add_network_line(line);
}

// "           1   Protocol              ECATR  The bus matches the design: ..."
// (frequency, group, protocol, summary): the network check's summaries.
void TimingModelBuilder::add_network_line(std::string_view line) {
    if (line.find("design") == std::string_view::npos) return;
    size_t at = 0;
    for (int token = 0; token < 3; ++token) {
        at = line.find_first_not_of(' ', at);
        if (at == std::string_view::npos) return;
        at = line.find(' ', at);
        if (at == std::string_view::npos) return;
    }
    at = line.find_first_not_of(' ', at);
    if (at != std::string_view::npos) model_.network.emplace_back(line.substr(at));
}

namespace {

bool parse_count(std::string_view rest, uint64_t& count) { return parse_uint(rest, count, 10); }

// One "  label: value" line of a cycle's block into its figure.
bool set_figure(CycleFigures& f, std::string_view label, std::string_view rest) {
    uint64_t n = 0;
    if (label == "frames") return parse_count(rest, f.frames);
    if (label == "nominal period (ns)") return parse_count(rest, n) && (f.nominal = static_cast<int64_t>(n), true);
    if (label == "period min/median/p99/max (ns)" || label == "period") return parse_quantiles(rest, f.period);
    if (label == "round trip min/median/p99/max (ns)" || label == "round trip")
        return parse_quantiles(rest, f.round_trip);
    if (label == "jitter std dev (ns)") return (f.jitter_sd = std::strtod(std::string(rest).c_str(), nullptr), true);
    if (label == "frames returned") return parse_count(rest, f.returned);
    if (label == "frames lost") return parse_count(rest, f.lost);
    if (label == "working counter errors") return parse_count(rest, f.wkc_errors);
    return false;
}

}  // namespace

// -z P,cycles: "Cycle N: SIGNATURE", then its figures as "  label: value".
bool TimingModelBuilder::add_cycle_statistics_line(std::string_view line) {
    uint64_t number = 0;
    size_t colon = line.find(": ");
    if (line.rfind("Cycle ", 0) == 0 && colon != std::string_view::npos && parse_uint(line.substr(6, colon - 6), number, 10)) {
        statistics_cycle_ = &model_.cycles[static_cast<unsigned>(number)];
        statistics_cycle_->number = static_cast<unsigned>(number);
        statistics_cycle_->signature = std::string(line.substr(colon + 2));
        return true;
    }
    if (!statistics_cycle_ || line.rfind("  ", 0) != 0 || colon == std::string_view::npos) {
        statistics_cycle_ = nullptr;
        return false;
    }
    return set_figure(statistics_cycle_->figures, line.substr(2, colon - 2), line.substr(colon + 2));
}

void TimingModelBuilder::add(const FieldRow& row) {
    uint64_t frame = 0;
    double t = 0;
    if (!parse_uint(value(row, column("frame.number")), frame) || !clock_.at(value(row, column("frame.time_epoch")), t))
        return;
    model_.frames++;
    model_.duration = t;

    uint64_t cycle = 0;
    if (parse_uint(value(row, runtime_column(runtime_field::cycle)), cycle) && cycle > 0)
        add_cycle_frame(row, t, static_cast<unsigned>(cycle));
    add_return(row, t);
    for (std::string_view lost : split_values(value(row, runtime_column(runtime_field::no_response_to)))) {
        uint64_t f = 0;
        if (parse_uint(lost, f)) model_.lost.push_back({t, static_cast<uint32_t>(f)});
    }
    add_slave_states(row, t);
    bool network_finding = false;
    for (const char* e : kNetworkExperts) network_finding |= !value(row, runtime_column(e)).empty();
    if (network_finding) model_.network_frames.push_back(static_cast<uint32_t>(frame));
}

void TimingModelBuilder::add_cycle_frame(const FieldRow& row, double t, unsigned number) {
    Cycle& c = model_.cycles[number];
    c.number = number;
    int64_t period = 0, jitter = 0;
    if (parse_seconds_ns(value(row, runtime_column(runtime_field::period)), period)) c.period.push_back({t, period});
    if (parse_seconds_ns(value(row, runtime_column(runtime_field::jitter)), jitter)) c.jitter.push_back({t, jitter});
}

void TimingModelBuilder::add_return(const FieldRow& row, double t) {
    int64_t rtt = 0;
    if (!parse_seconds_ns(value(row, runtime_column(runtime_field::time)), rtt)) return;
    model_.round_trip.push_back({t, rtt});
    uint64_t request = 0;
    parse_uint(value(row, runtime_column(runtime_field::request_in)), request);
    size_t differs = split_values(value(row, runtime_column(runtime_expert::wkc))).size();
    for (size_t i = 0; i < differs; ++i) model_.wkc_differs.push_back({t, static_cast<uint32_t>(request)});
}

void SlaveTimeline::observe(double t, unsigned status) {
    unsigned state = status & 0x0f;
    if (states.empty() || states.back().second != state) states.push_back({t, state});
}

// A return's AL status reads, paired with the slaves they address when the
// frame names as many slaves as it has reads (one datagram each); when it
// names none, by the station addresses they were read from.
void TimingModelBuilder::add_slave_states(const FieldRow& row, double t) {
    if (value(row, runtime_column(runtime_field::request_in)).empty()) return;
    auto statuses = split_values(value(row, column(runtime_filter_name(filter_, kAlStatusField))));
    if (statuses.empty()) return;
    auto positions = split_values(value(row, runtime_column(runtime_field::position)));
    if (positions.empty()) return add_station_states(row, statuses, t);
    if (positions.size() != statuses.size()) return;
    auto names = split_values(value(row, runtime_column(runtime_field::name)));
    for (size_t i = 0; i < positions.size(); ++i) {
        uint64_t position = 0, status = 0;
        if (!parse_uint(positions[i], position) || !parse_uint(statuses[i], status)) continue;
        SlaveTimeline& s = model_.slaves[static_cast<unsigned>(position)];
        if (names.size() == positions.size()) s.name = std::string(names[i]);
        s.observe(t, static_cast<unsigned>(status));
    }
}

// The statuses of a frame whose every AL status read is an FPRD starting at
// register 0x0130 (one per slave, as masters poll it), by station address.
// Anything else (a broadcast, a read that starts below 0x0130) is not guessed.
void TimingModelBuilder::add_station_states(const FieldRow& row, const std::vector<std::string_view>& statuses,
                                            double t) {
    auto commands = split_values(value(row, column(runtime_filter_name(filter_, kCommandField))));
    auto addresses = split_values(value(row, column(runtime_filter_name(filter_, kAddressField))));
    auto offsets = split_values(value(row, column(runtime_filter_name(filter_, kOffsetField))));
    std::vector<unsigned> stations;
    size_t addressed = 0;  // adp/ado are listed for the datagrams that are not logical
    for (std::string_view text : commands) {
        uint64_t cmd = 0, station = 0, offset = 0;
        if (!parse_uint(text, cmd)) return;
        if (cmd <= 0xff && dg_ecat_commands::is_logical(static_cast<unsigned>(cmd))) continue;
        if (addressed >= addresses.size() || addressed >= offsets.size()) return;
        if (!parse_uint(addresses[addressed], station) || !parse_uint(offsets[addressed], offset)) return;
        addressed++;
        if (offset != kAlStatusRegister) continue;
        if (cmd != dg_ecat_commands::FPRD) return;
        stations.push_back(static_cast<unsigned>(station));
    }
    if (stations.size() != statuses.size()) return;
    for (size_t i = 0; i < stations.size(); ++i) {
        uint64_t status = 0;
        if (parse_uint(statuses[i], status)) model_.stations[stations[i]].observe(t, static_cast<unsigned>(status));
    }
}

}  // namespace dissgen

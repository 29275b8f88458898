// SPDX-License-Identifier: GPL-2.0-or-later
#include "timing_model.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace dissgen {

namespace {

// Optional fields: asked for only when the installed plugin has them.
const char* const kTimingFields[] = {
    "frame.number",          "frame.time_epoch",        "ecatr.cycle",
    "ecatr.cycle.period",    "ecatr.cycle.jitter",      "ecatr.datagram.cmd",
    "ecatr.datagram.ado",    "ecatr.datagram.lad",      "ecatr.time",
    "ecatr.request_in",      "ecatr.no_response_to",    "ecatr.expert.wkc",
    "ecatr.slave.position",  "ecatr.slave.name",        "ecatr.datagram.reg.alstatus.status",
    "ecatr.expert.network.ok", "ecatr.expert.network.count", "ecatr.expert.network.model",
    "_ws.expert.message",
};

// base 0: "0x0130" as tshark prints hexadecimal fields, "12" as decimal ones.
bool parse_uint(std::string_view text, uint64_t& value, int base = 0) {
    if (text.empty() || text[0] == '-') return false;
    std::string s(text);
    char* end = nullptr;
    value = std::strtoull(s.c_str(), &end, base);
    return end && *end == '\0';
}

// frame.time_epoch "1700000000.123456789" -> whole seconds and ns.
bool parse_epoch(std::string_view text, int64_t& s, int64_t& ns) {
    size_t dot = text.find('.');
    uint64_t whole = 0, frac = 0;
    if (!parse_uint(text.substr(0, dot), whole, 10)) return false;
    ns = 0;
    if (dot != std::string_view::npos) {
        std::string_view digits = text.substr(dot + 1, 9);
        if (!digits.empty() && !parse_uint(digits, frac, 10)) return false;
        ns = static_cast<int64_t>(frac);
        for (size_t i = digits.size(); i < 9; ++i) ns *= 10;
    }
    s = static_cast<int64_t>(whole);
    return true;
}

// The nearest-rank percentile of sorted values (p in 0..100).
int64_t nearest_rank(const std::vector<int64_t>& sorted, double p) {
    size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(sorted.size())));
    return sorted[rank == 0 ? 0 : rank - 1];
}

}  // namespace

Spread spread_of(std::vector<int64_t> values) {
    Spread s;
    s.count = values.size();
    if (values.empty()) return s;
    std::sort(values.begin(), values.end());
    s.min = values.front();
    s.max = values.back();
    s.median = nearest_rank(values, 50);
    s.p99 = nearest_rank(values, 99);
    double sum = 0, squares = 0;
    for (int64_t v : values) sum += static_cast<double>(v);
    s.mean = sum / static_cast<double>(values.size());
    for (int64_t v : values) squares += (static_cast<double>(v) - s.mean) * (static_cast<double>(v) - s.mean);
    s.stddev = std::sqrt(squares / static_cast<double>(values.size()));
    return s;
}

bool parse_seconds_ns(std::string_view text, int64_t& ns) {
    bool negative = !text.empty() && text[0] == '-';
    if (negative) text.remove_prefix(1);
    int64_t s = 0, frac = 0;
    if (!parse_epoch(text, s, frac)) return false;
    ns = s * 1000000000 + frac;
    if (negative) ns = -ns;
    return true;
}

std::string ethercat_command_name(unsigned cmd) {
    static const char* const names[] = {"NOP", "APRD", "APWR", "APRW", "FPRD", "FPWR", "FPRW", "BRD",
                                        "BWR", "BRW",  "LRD",  "LWR",  "LRW",  "ARMW", "FRMW"};
    if (cmd < sizeof names / sizeof names[0]) return names[cmd];
    char buf[16];
    std::snprintf(buf, sizeof buf, "cmd 0x%02x", cmd);
    return buf;
}

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

std::vector<std::string> TimingModelBuilder::timing_fields(const std::vector<std::string>& known) {
    std::vector<std::string> fields;
    for (const char* f : kTimingFields)
        if (std::find(known.begin(), known.end(), f) != known.end()) fields.push_back(f);
    return fields;
}

TimingModelBuilder::TimingModelBuilder(const std::vector<std::string>& fields, TimingModel& model) : model_(model) {
    for (size_t i = 0; i < fields.size(); ++i) columns_[fields[i]] = static_cast<int>(i);
    model_.has_cycle_fields = column("ecatr.cycle") >= 0;
}

int TimingModelBuilder::column(const char* field) const {
    auto it = columns_.find(field);
    return it == columns_.end() ? -1 : it->second;
}

std::string_view TimingModelBuilder::value(const FieldRow& row, int col) const {
    return col < 0 || static_cast<size_t>(col) >= row.size() ? std::string_view() : row[static_cast<size_t>(col)];
}

void TimingModelBuilder::add(const FieldRow& row) {
    uint64_t frame = 0;
    int64_t s = 0, ns = 0;
    if (!parse_uint(value(row, column("frame.number")), frame) ||
        !parse_epoch(value(row, column("frame.time_epoch")), s, ns))
        return;
    if (first_s_ < 0) {
        first_s_ = s;
        first_ns_ = ns;
    }
    double t = static_cast<double>(s - first_s_) + static_cast<double>(ns - first_ns_) * 1e-9;
    model_.frames++;
    model_.duration = t;

    uint64_t cycle = 0;
    if (parse_uint(value(row, column("ecatr.cycle")), cycle) && cycle > 0)
        add_cycle_frame(row, static_cast<uint32_t>(frame), t, static_cast<unsigned>(cycle));
    add_return(row, t);
    for (std::string_view lost : split_values(value(row, column("ecatr.no_response_to")))) {
        uint64_t f = 0;
        if (!parse_uint(lost, f)) continue;
        auto it = cycle_of_frame_.find(static_cast<uint32_t>(f));
        unsigned c = it == cycle_of_frame_.end() ? 0 : it->second;
        model_.lost.push_back({t, static_cast<uint32_t>(f), c});
        if (c) model_.cycles[c].lost++;
    }
    add_slave_states(row, t);
    const char* network[] = {"ecatr.expert.network.ok", "ecatr.expert.network.count", "ecatr.expert.network.model"};
    bool network_finding = false;
    for (const char* f : network) network_finding |= !value(row, column(f)).empty();
    if (network_finding) {
        // The frame's expert messages; keep those of the network check.
        for (std::string_view m : split_values(value(row, column("_ws.expert.message"))))
            if (m.find("design") != std::string_view::npos)
                model_.network.push_back("frame " + std::to_string(frame) + ": " + std::string(m));
    }
}

void TimingModelBuilder::add_cycle_frame(const FieldRow& row, uint32_t frame, double t, unsigned number) {
    Cycle& c = model_.cycles[number];
    if (c.frames++ == 0) {
        c.number = number;
        // The signature, from the first frame: commands with their addresses.
        auto cmds = split_values(value(row, column("ecatr.datagram.cmd")));
        auto ados = split_values(value(row, column("ecatr.datagram.ado")));
        auto lads = split_values(value(row, column("ecatr.datagram.lad")));
        size_t next_ado = 0, next_lad = 0;
        for (std::string_view cmd_text : cmds) {
            uint64_t cmd = 0;
            parse_uint(cmd_text, cmd);
            bool logical = cmd >= 10 && cmd <= 12;
            std::string address;
            if (logical && next_lad < lads.size()) address = std::string(lads[next_lad++]);
            else if (!logical && next_ado < ados.size()) address = std::string(ados[next_ado++]);
            if (!c.signature.empty()) c.signature += " + ";
            c.signature += ethercat_command_name(static_cast<unsigned>(cmd));
            if (!address.empty()) c.signature += " " + address;
        }
    }
    cycle_of_frame_[frame] = number;
    int64_t ns = 0;
    if (parse_seconds_ns(value(row, column("ecatr.cycle.period")), ns)) c.period.push_back({t, ns});
    if (parse_seconds_ns(value(row, column("ecatr.cycle.jitter")), ns)) c.jitter.push_back({t, ns});
}

void TimingModelBuilder::add_return(const FieldRow& row, double t) {
    int64_t rtt = 0;
    uint64_t request = 0;
    if (!parse_seconds_ns(value(row, column("ecatr.time")), rtt)) return;
    model_.round_trip.push_back({t, rtt});
    parse_uint(value(row, column("ecatr.request_in")), request);
    auto it = cycle_of_frame_.find(static_cast<uint32_t>(request));
    unsigned c = it == cycle_of_frame_.end() ? 0 : it->second;
    if (c) model_.cycles[c].round_trip.push_back({t, rtt});
    if (!value(row, column("ecatr.expert.wkc")).empty()) {
        size_t errors = split_values(value(row, column("ecatr.expert.wkc"))).size();
        for (size_t i = 0; i < errors; ++i) model_.wkc_errors.push_back({t, static_cast<uint32_t>(request), c});
        if (c) model_.cycles[c].wkc_errors += errors;
    }
}

// A return's AL status reads, paired with the slaves they address when the
// frame names as many slaves as it has reads (one datagram each).
void TimingModelBuilder::add_slave_states(const FieldRow& row, double t) {
    if (value(row, column("ecatr.request_in")).empty()) return;
    auto statuses = split_values(value(row, column("ecatr.datagram.reg.alstatus.status")));
    if (statuses.empty()) return;
    auto positions = split_values(value(row, column("ecatr.slave.position")));
    if (positions.size() != statuses.size()) return;
    auto names = split_values(value(row, column("ecatr.slave.name")));
    for (size_t i = 0; i < positions.size(); ++i) {
        uint64_t position = 0, status = 0;
        if (!parse_uint(positions[i], position) || !parse_uint(statuses[i], status)) continue;
        SlaveTimeline& s = model_.slaves[static_cast<unsigned>(position)];
        if (names.size() == positions.size()) s.name = std::string(names[i]);
        unsigned state = static_cast<unsigned>(status & 0x0f);
        if (s.states.empty() || s.states.back().second != state) s.states.push_back({t, state});
    }
}

}  // namespace dissgen

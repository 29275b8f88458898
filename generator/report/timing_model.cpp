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
    "ecatr.datagram.adp",    "ecatr.datagram.ado",      "ecatr.datagram.lad",
    "ecatr.datagram.len",    "ecatr.datagram.wkc",      "ecatr.esc.wkc_added",     "ecatr.time",
    "ecatr.request_in",      "ecatr.no_response_to",    "ecatr.expert.wkc",
    "ecatr.slave.position",  "ecatr.slave.name",        "ecatr.datagram.reg.alstatus.status",
    "ecatr.expert.network.ok", "ecatr.expert.network.count", "ecatr.expert.network.model",
};
const char kNetworkExperts[] = "ecatr.expert.network.ok || ecatr.expert.network.count || ecatr.expert.network.model";

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

// The nearest-rank percentile of sorted values (p in 1..100), in integers: ceil(p n / 100).
int64_t nearest_rank(const std::vector<int64_t>& sorted, unsigned p) {
    size_t rank = (p * sorted.size() + 99) / 100;
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
    s.median = values[(values.size() - 1) / 2];  // the lower median
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

uint64_t Cycle::lost() const {
    // Frames after the latest frame answered may still be in flight.
    uint32_t latest = 0;
    for (uint32_t f : answered) latest = std::max(latest, f);
    std::vector<uint32_t> done(answered);
    std::sort(done.begin(), done.end());
    uint64_t lost = 0;
    for (uint32_t f : sent)
        if (f < latest && !std::binary_search(done.begin(), done.end(), f)) lost++;
    return lost;
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

std::vector<std::string> TimingModelBuilder::statistics_args(const std::vector<std::string>& known) {
    if (std::find(known.begin(), known.end(), "ecatr.expert.network.ok") == known.end()) return {};
    return {"-z", std::string("expert,chat,") + kNetworkExperts};
}

// "           1   Protocol              ECATR  The bus matches the design: ..."
// (frequency, group, protocol, summary): the network check's summaries.
void TimingModelBuilder::add_statistics_line(std::string_view line) {
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
    }
    add_slave_states(row, t);
    const char* network[] = {"ecatr.expert.network.ok", "ecatr.expert.network.count", "ecatr.expert.network.model"};
    bool network_finding = false;
    for (const char* f : network) network_finding |= !value(row, column(f)).empty();
    if (network_finding) model_.network_frames.push_back(static_cast<uint32_t>(frame));
}

// The frame's datagrams in the words of -z ecatr,cycles:
// "LRW 0x00010000 (4 bytes), FRMW 0x1001:0x0910 (8 bytes)".
std::string TimingModelBuilder::signature_text(const FieldRow& row) const {
    std::string signature;
    auto cmds = split_values(value(row, column("ecatr.datagram.cmd")));
    auto adps = split_values(value(row, column("ecatr.datagram.adp")));
    auto ados = split_values(value(row, column("ecatr.datagram.ado")));
    auto lads = split_values(value(row, column("ecatr.datagram.lad")));
    auto lens = split_values(value(row, column("ecatr.datagram.len")));
    size_t next_address = 0, next_lad = 0;
    for (size_t i = 0; i < cmds.size(); ++i) {
        uint64_t cmd = 0, a = 0, b = 0, len = 0;
        parse_uint(cmds[i], cmd);
        char one[96];
        if (cmd >= 10 && cmd <= 12) {
            if (next_lad < lads.size()) parse_uint(lads[next_lad++], a);
            std::snprintf(one, sizeof one, "%s 0x%08llx", ethercat_command_name(static_cast<unsigned>(cmd)).c_str(),
                          static_cast<unsigned long long>(a));
        } else {
            if (next_address < adps.size()) parse_uint(adps[next_address], a);
            if (next_address < ados.size()) parse_uint(ados[next_address], b);
            next_address++;
            std::snprintf(one, sizeof one, "%s 0x%04llx:0x%04llx",
                          ethercat_command_name(static_cast<unsigned>(cmd)).c_str(),
                          static_cast<unsigned long long>(a), static_cast<unsigned long long>(b));
        }
        if (i < lens.size()) parse_uint(lens[i], len);
        if (!signature.empty()) signature += ", ";
        signature += std::string(one) + " (" + std::to_string(len) + " bytes)";
    }
    return signature;
}

void TimingModelBuilder::add_cycle_frame(const FieldRow& row, uint32_t frame, double t, unsigned number) {
    Cycle& c = model_.cycles[number];
    if (c.frames++ == 0) {
        c.number = number;
        c.signature = signature_text(row);
    }
    c.sent.push_back(frame);
    cycle_of_frame_[frame] = number;
    int64_t period = 0, jitter = 0;
    if (parse_seconds_ns(value(row, column("ecatr.cycle.period")), period)) c.period.push_back({t, period});
    if (parse_seconds_ns(value(row, column("ecatr.cycle.jitter")), jitter)) {
        c.jitter.push_back({t, jitter});
        c.nominal = period - jitter;
    }
}

void TimingModelBuilder::add_return(const FieldRow& row, double t) {
    int64_t rtt = 0;
    uint64_t request = 0;
    if (!parse_seconds_ns(value(row, column("ecatr.time")), rtt)) return;
    model_.round_trip.push_back({t, rtt});
    parse_uint(value(row, column("ecatr.request_in")), request);
    auto it = cycle_of_frame_.find(static_cast<uint32_t>(request));
    unsigned c = it == cycle_of_frame_.end() ? 0 : it->second;
    if (c) {
        Cycle& cyc = model_.cycles[c];
        // As the statistics clamp it: round trips within 0 .. 2^32-1 ns.
        cyc.round_trip.push_back({t, std::clamp<int64_t>(rtt, 0, 0xffffffffLL)});
        cyc.returned++;
        cyc.answered.push_back(static_cast<uint32_t>(request));
        count_wkc_error(cyc, row);
    }
    if (!value(row, column("ecatr.expert.wkc")).empty()) {
        size_t errors = split_values(value(row, column("ecatr.expert.wkc"))).size();
        for (size_t i = 0; i < errors; ++i) model_.wkc_errors.push_back({t, static_cast<uint32_t>(request), c});
    }
}

// A return of the cycle is an error when a datagram's counter was not raised on
// the way round, or came back below the highest that datagram returned before.
void TimingModelBuilder::count_wkc_error(Cycle& c, const FieldRow& row) {
    auto back = split_values(value(row, column("ecatr.datagram.wkc")));
    auto added = split_values(value(row, column("ecatr.esc.wkc_added")));
    bool error = false;
    if (c.wkc_high.empty()) c.wkc_high.assign(back.size(), -1);
    for (size_t i = 0; i < back.size() && i < added.size() && i < c.wkc_high.size(); ++i) {
        uint64_t wkc = 0;
        int64_t plus = 0;
        if (!parse_uint(back[i], wkc)) continue;
        std::string a(added[i]);
        plus = std::strtoll(a.c_str(), nullptr, 10);
        if (plus <= 0 || static_cast<int64_t>(wkc) < c.wkc_high[i]) error = true;
        c.wkc_high[i] = std::max<int64_t>(c.wkc_high[i], static_cast<int64_t>(wkc));
    }
    if (error) c.wkc_errors++;
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

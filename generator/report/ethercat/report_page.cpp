// SPDX-License-Identifier: GPL-2.0-or-later
#include "report_page.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "../../runtime_names.h"

namespace dissgen {

namespace {

constexpr size_t kPlotBuckets = 4000;     // points per curve, at most
constexpr size_t kMarkerLimit = 4000;     // lost / working-counter markers drawn, at most

std::string events_json(const std::vector<Event>& events) {
    return markers_json(events, [](const Event& e) { return e.frame; }, kMarkerLimit);
}

// The Slaves section's rows: by position, then by station address those
// whose position the capture never showed.
struct SlaveRow {
    std::string key;  // "3", "station 0x1001"
    const SlaveTimeline* timeline;
};

std::vector<SlaveRow> slave_rows(const TimingModel& m) {
    std::vector<SlaveRow> rows;
    for (const auto& [position, s] : m.slaves) rows.push_back({std::to_string(position), &s});
    for (const auto& [station, s] : m.stations) {
        char key[24];
        std::snprintf(key, sizeof key, "station 0x%04x", station);
        rows.push_back({key, &s});
    }
    return rows;
}

std::string slaves_json(const std::vector<SlaveRow>& rows) {
    std::string out = "[";
    bool first = true;
    for (const SlaveRow& row : rows) {
        const SlaveTimeline& s = *row.timeline;
        std::string label = row.key + (s.name.empty() ? "" : ": " + s.name);
        out += std::string(first ? "" : ",") + "{\"label\":" + json_string(label) + ",\"states\":[";
        first = false;
        for (size_t i = 0; i < s.states.size(); ++i)
            out += (i ? "," : "") + std::string("[") + num(s.states[i].first, 6) + "," +
                   std::to_string(s.states[i].second) + "]";
        out += "]}";
    }
    return out + "]";
}

void slaves_section(const std::vector<SlaveRow>& rows, std::ostream& out) {
    out << "<h2>Slaves</h2>\n";
    if (rows.empty()) {
        out << "<p class=\"note\">No AL status read from a single slave in this capture.</p>\n";
        return;
    }
    out << "<table id=\"slaves\"><thead><tr><th>Position or station</th><th>Slave</th><th>AL states</th></tr>"
           "</thead><tbody>\n";
    for (const SlaveRow& row : rows) {
        std::string states;
        for (const auto& [t, state] : row.timeline->states)
            states += (states.empty() ? "" : " → ") + al_state_name(state) + " (" + num(t, 3) + " s)";
        out << "<tr><td>" << escape_html(row.key) << "</td><td>" << escape_html(row.timeline->name) << "</td><td>"
            << escape_html(states) << "</td></tr>\n";
    }
    out << "</tbody></table>\n<div class=\"chart wide\" id=\"al-states\"></div>\n";
}

// Some capture drivers stamp a frame's return with its sending time: every
// round trip is then 0, which a chart would draw as a flat line.
bool stamps_out_and_back_alike(const TimingModel& m) {
    if (m.round_trip.empty()) return false;
    for (const TimedValue& v : m.round_trip)
        if (v.ns != 0) return false;
    return true;
}

void round_trip_section(const TimingModel& m, std::ostream& out) {
    out << "<h2>Round trip</h2>\n";
    if (stamps_out_and_back_alike(m))
        out << "<p class=\"note\" id=\"round-trip-same-stamp\">Every one of the " << m.round_trip.size()
            << " returns has the same timestamp as its frame sent: the capture driver stamps out and back "
               "alike, so this capture cannot tell round trips.</p>\n";
    else
        out << "<div class=\"chart wide\" id=\"round-trip\"></div>\n";
}

// One figure per cell, as -z P,cycles prints it; times in µs with 3 decimals
// (exact: they are whole ns).
void cycle_table(const TimingModel& m, std::ostream& out) {
    out << "<table id=\"cycles\"><thead><tr><th>Cycle</th><th>Signature</th><th>Frames</th>"
           "<th>Nominal period (µs)</th><th>Period min</th><th>median</th><th>p99</th><th>max</th>"
           "<th>Jitter std dev (µs)</th><th>Round trip min</th><th>median</th><th>p99</th><th>max</th>"
           "<th>Returned</th><th>Lost</th><th>Working counter errors</th></tr></thead><tbody>\n";
    for (const auto& [number, c] : m.cycles) {
        const CycleFigures& f = c.figures;
        out << "<tr data-cycle=\"" << number << "\"><td>" << number << "</td><td>" << escape_html(c.signature)
            << "</td><td>" << f.frames << "</td><td>" << us(f.nominal) << "</td>";
        for (int64_t v : {f.period.min, f.period.median, f.period.p99, f.period.max}) out << "<td>" << us(v) << "</td>";
        out << "<td>" << num(f.jitter_sd / 1000.0) << "</td>";
        for (int64_t v : {f.round_trip.min, f.round_trip.median, f.round_trip.p99, f.round_trip.max})
            out << "<td>" << us(v) << "</td>";
        out << "<td>" << f.returned << "</td><td>" << f.lost << "</td><td>" << f.wkc_errors << "</td></tr>\n";
    }
    out << "</tbody></table>\n";
}

// The page's script: draws the charts from the embedded data.
const char kScript[] = R"JS(
(function () {
  const data = JSON.parse(document.getElementById('report-data').textContent);
  const stateNames = {1: 'INIT', 2: 'PREOP', 3: 'BOOT', 4: 'SAFEOP', 8: 'OP'};
  const stateLevel = {1: 1, 2: 2, 3: 2.5, 4: 3, 8: 4};
  const common = {customBars: true, legend: 'follow', labelsSeparateLines: true,
                  xlabel: 'Capture time (s)', animatedZooms: false,
                  axes: {x: captureTimeAxis, y: {axisLabelWidth: 64}}};
  cycleCharts(data.cycles, common, 'Frames');
  // Round trips with the lost frames and working-counter errors as marks on top.
  const top = data.round_trip.reduce((m, p) => Math.max(m, p[1][2]), 0) * 1.05 || 1;
  const rows = bars(data.round_trip).map(p => [p[0], p[1], null, null]);
  data.lost.forEach(e => rows.push([e[0], null, [top, top, top], null]));
  data.unexpected_wkc.forEach(e => rows.push([e[0], null, null, [top * 0.95, top * 0.95, top * 0.95]]));
  rows.sort((a, b) => a[0] - b[0]);
  chart('round-trip', rows, Object.assign({labels: ['t', 'Round trip (µs)', 'Lost frame', 'Unexpected WKC'],
      ylabel: 'Round trip (µs)', title: 'Round trip over time',
      series: {'Lost frame': {strokeWidth: 0, drawPoints: true, pointSize: 4, color: '#d62728'},
               'Unexpected WKC': {strokeWidth: 0, drawPoints: true, pointSize: 4, color: '#ff7f0e'}}}, common));
  // AL states: one step line per slave.
  if (data.slaves.length) {
    const times = new Set([data.duration]);
    data.slaves.forEach(s => s.states.forEach(p => times.add(p[0])));
    const sorted = Array.from(times).sort((a, b) => a - b);
    const at = s => { let v = null; return t => { s.states.forEach(p => { if (p[0] <= t) v = stateLevel[p[1]] || null; }); return v; }; };
    const lookups = data.slaves.map(at);
    const stateRows = sorted.map(t => [t].concat(lookups.map(f => f(t))));
    const names = {1: 'INIT', 2: 'PREOP', 2.5: 'BOOT', 3: 'SAFEOP', 4: 'OP'};
    chart('al-states', stateRows, {labels: ['t'].concat(data.slaves.map(s => s.label)), stepPlot: true,
        xlabel: 'Capture time (s)', ylabel: 'AL state', title: 'Slaves: AL state over time', legend: 'follow',
        labelsSeparateLines: true, valueRange: [0.5, 4.5], yLabelWidth: 20,
        axes: {x: captureTimeAxis,
               y: {axisLabelWidth: 70, valueFormatter: v => names[v] || '', axisLabelFormatter: v => names[v] || ''}}});
  }
})();
)JS";

}  // namespace

std::string write_report_html(const TimingModel& m, const std::string& tool_version, std::ostream& out) {
    std::string js, css, error = read_dygraphs(js, css);
    if (!error.empty()) return error;

    write_page_head("EtherCAT timing: " + capture_name(m.captures), js, css, out);
    // The headline's working-counter count is the expert info's kind (differs
    // from the expected), not the cycle table's: it says so in the expert's words.
    out << "<h1>EtherCAT timing: " << escape_html(capture_name(m.captures)) << "</h1>\n<p class=\"note\">"
        << m.frames << " frames, " << num(m.duration, 3) << " s; " << m.cycles.size() << " cycle"
        << (m.cycles.size() == 1 ? "" : "s") << ", " << m.lost.size() << " lost frame"
        << (m.lost.size() == 1 ? "" : "s") << ", " << m.wkc_differs.size() << " with “"
        << escape_html(runtime_expert_summary(runtime_expert::wkc)) << "”. Generated by dissgen " << tool_version
        << " from the fields and statistics of the installed plugin.</p>\n";

    out << "<h2>Cycles</h2>\n";
    if (!m.has_cycle_fields)
        out << "<p class=\"note\">The installed plugin shows no cycle fields ("
            << escape_html(runtime_filter_name(m.protocol, runtime_field::cycle))
            << "): regenerate it with this dissgen.</p>\n";
    else if (m.cycles.empty())
        out << "<p class=\"note\">No cyclic traffic in this capture.</p>\n";
    else cycle_table(m, out);
    for (const auto& [number, c] : m.cycles)
        out << "<div class=\"pair\"><div class=\"chart\" id=\"period-" << number
            << "\"></div><div class=\"chart\" id=\"jitter-" << number << "\"></div></div>\n";

    round_trip_section(m, out);
    std::vector<SlaveRow> slaves = slave_rows(m);
    slaves_section(slaves, out);

    out << "<h2>Network check</h2>\n";
    if (m.network.empty())
        out << "<p class=\"note\" id=\"network\">No finding: the plugin has no network design embedded, or the capture "
               "never read the slaves' identities.</p>\n";
    else {
        out << "<ul id=\"network\">\n";
        for (const std::string& f : m.network) out << "<li>" << escape_html(f) << "</li>\n";
        out << "</ul>\n<p class=\"note\">In frame";
        if (m.network_frames.size() > 1) out << "s";
        for (size_t i = 0; i < m.network_frames.size(); ++i) out << (i ? ", " : " ") << m.network_frames[i];
        out << ".</p>\n";
    }

    // The data the charts draw.
    out << "<script type=\"application/json\" id=\"report-data\">{\"duration\":" << num(m.duration, 6)
        << ",\"cycles\":" << cycles_json(m.cycles, kPlotBuckets) << ",\"round_trip\":" << series_json(m.round_trip, kPlotBuckets) << ",\"lost\":" << events_json(m.lost)
        << ",\"unexpected_wkc\":" << events_json(m.wkc_differs) << ",\"slaves\":" << slaves_json(slaves) << "}</script>\n";
    out << "<script>" << kChartScript << kScript << "</script>\n</body></html>\n";
    return out ? "" : "cannot write the report";
}

}  // namespace dissgen

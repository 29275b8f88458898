// SPDX-License-Identifier: GPL-2.0-or-later
#include "report_html.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "../xml_input.h"

namespace dissgen {

namespace {

constexpr size_t kPlotBuckets = 4000;     // points per curve, at most
constexpr size_t kMarkerLimit = 4000;     // lost / working-counter markers drawn, at most
constexpr size_t kHistogramBins = 80;

std::string escape_html(const std::string& text) {
    std::string out;
    for (char c : text) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        default: out += c;
        }
    }
    return out;
}

// A JSON string literal, safe inside <script> (no "</").
std::string json_string(const std::string& text) {
    std::string out = "\"";
    for (unsigned char c : text) {
        if (c == '"' || c == '\\') out += '\\', out += static_cast<char>(c);
        else if (c == '<') out += "\\u003c";
        else if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else out += static_cast<char>(c);
    }
    return out + "\"";
}

std::string num(double v, int decimals = 3) {
    if (!std::isfinite(v)) return "null";
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

// ns -> "1000.250" µs, as the tables print them.
std::string us(int64_t ns) { return num(static_cast<double>(ns) / 1000.0, 3); }

std::vector<int64_t> values_of(const std::vector<TimedValue>& series) {
    std::vector<int64_t> v;
    v.reserve(series.size());
    for (const TimedValue& p : series) v.push_back(p.ns);
    return v;
}

std::string events_json(const std::vector<Event>& events) {
    std::string out = "[";
    size_t step = events.size() > kMarkerLimit ? (events.size() + kMarkerLimit - 1) / kMarkerLimit : 1;
    for (size_t i = 0; i < events.size(); i += step)
        out += (i ? "," : "") + std::string("[") + num(events[i].t, 6) + "," + std::to_string(events[i].frame) + "]";
    return out + "]";
}

std::string slaves_json(const TimingModel& m) {
    std::string out = "[";
    bool first = true;
    for (const auto& [position, s] : m.slaves) {
        std::string label = std::to_string(position) + (s.name.empty() ? "" : ": " + s.name);
        out += std::string(first ? "" : ",") + "{\"label\":" + json_string(label) + ",\"states\":[";
        first = false;
        for (size_t i = 0; i < s.states.size(); ++i)
            out += (i ? "," : "") + std::string("[") + num(s.states[i].first, 6) + "," +
                   std::to_string(s.states[i].second) + "]";
        out += "]}";
    }
    return out + "]";
}

// One figure per cell; times in µs with 3 decimals (exact: they are whole ns).
void cycle_table(const TimingModel& m, std::ostream& out) {
    out << "<table id=\"cycles\"><thead><tr><th>Cycle</th><th>Signature</th><th>Frames</th>"
           "<th>Nominal period (µs)</th><th>Period min</th><th>median</th><th>p99</th><th>max</th>"
           "<th>Jitter std dev (µs)</th><th>Round trip min</th><th>median</th><th>p99</th><th>max</th>"
           "<th>Returned</th><th>Lost</th><th>WKC errors</th></tr></thead><tbody>\n";
    for (const auto& [number, c] : m.cycles) {
        Spread period = spread_of(values_of(c.period)), jitter = spread_of(values_of(c.jitter)),
               rtt = spread_of(values_of(c.round_trip));
        out << "<tr data-cycle=\"" << number << "\"><td>" << number << "</td><td>" << escape_html(c.signature)
            << "</td><td>" << c.frames << "</td><td>" << us(c.nominal) << "</td>";
        for (int64_t v : {period.min, period.median, period.p99, period.max}) out << "<td>" << us(v) << "</td>";
        out << "<td>" << num(jitter.stddev / 1000.0) << "</td>";
        for (int64_t v : {rtt.min, rtt.median, rtt.p99, rtt.max}) out << "<td>" << us(v) << "</td>";
        out << "<td>" << c.returned << "</td><td>" << c.lost() << "</td><td>" << c.wkc_errors << "</td></tr>\n";
    }
    out << "</tbody></table>\n";
}

std::string capture_name(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The page's script: draws the charts from the embedded data.
const char kScript[] = R"JS(
(function () {
  const data = JSON.parse(document.getElementById('report-data').textContent);
  const stateNames = {1: 'INIT', 2: 'PREOP', 3: 'BOOT', 4: 'SAFEOP', 8: 'OP'};
  const stateLevel = {1: 1, 2: 2, 3: 2.5, 4: 3, 8: 4};
  const common = {customBars: true, legend: 'follow', labelsSeparateLines: true,
                  xlabel: 'Capture time (s)', animatedZooms: false, axes: {y: {axisLabelWidth: 64}}};
  function bars(series) { return series.map(p => [p[0], p[1]]); }
  function chart(id, rows, options) {
    const el = document.getElementById(id);
    if (!el) return;
    if (!rows.length) { el.textContent = 'No values.'; el.className += ' empty'; return; }
    new Dygraph(el, rows, options);
  }
  data.cycles.forEach(c => {
    chart('period-' + c.number, bars(c.period),
          Object.assign({labels: ['t', 'Period (µs)'], ylabel: 'Period (µs)',
                         title: 'Cycle ' + c.number + ': period over time'}, common));
    chart('jitter-' + c.number, c.histogram,
          {labels: ['Jitter (µs)', 'Frames'], stepPlot: true, fillGraph: true, xRangePad: 12, xlabel: 'Jitter (µs)',
           ylabel: 'Frames', title: 'Cycle ' + c.number + ': jitter histogram', axes: {y: {axisLabelWidth: 64}}});
  });
  // Round trips with the lost frames and working-counter errors as marks on top.
  const top = data.round_trip.reduce((m, p) => Math.max(m, p[1][2]), 0) * 1.05 || 1;
  const rows = bars(data.round_trip).map(p => [p[0], p[1], null, null]);
  data.lost.forEach(e => rows.push([e[0], null, [top, top, top], null]));
  data.wkc_errors.forEach(e => rows.push([e[0], null, null, [top * 0.95, top * 0.95, top * 0.95]]));
  rows.sort((a, b) => a[0] - b[0]);
  chart('round-trip', rows, Object.assign({labels: ['t', 'Round trip (µs)', 'Lost frame', 'WKC error'],
      ylabel: 'Round trip (µs)', title: 'Round trip over time',
      series: {'Lost frame': {strokeWidth: 0, drawPoints: true, pointSize: 4, color: '#d62728'},
               'WKC error': {strokeWidth: 0, drawPoints: true, pointSize: 4, color: '#ff7f0e'}}}, common));
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
        axes: {y: {axisLabelWidth: 70, valueFormatter: v => names[v] || '', axisLabelFormatter: v => names[v] || ''}}});
  }
})();
)JS";

const char kStyle[] = R"CSS(
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 1.6em; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; text-align: right; }
td:nth-child(2), th:nth-child(2) { text-align: left; }
.pair { display: flex; gap: 1em; flex-wrap: wrap; }
.chart { width: 640px; height: 280px; }
.chart.wide { width: 1300px; }
.empty { height: auto; color: #777; }
.note { color: #555; }
)CSS";

}  // namespace

std::string dygraphs_dir() {
    const char* env = std::getenv("DISSGEN_DYGRAPHS_DIR");
    return env && *env ? env : "/usr/share/javascript/dygraphs";
}

std::string histogram_json(const std::vector<TimedValue>& series) {
    if (series.empty()) return "[]";
    int64_t lo = series.front().ns, hi = lo;
    for (const TimedValue& p : series) lo = std::min(lo, p.ns), hi = std::max(hi, p.ns);
    int64_t width = std::max<int64_t>(1, (hi - lo) / static_cast<int64_t>(kHistogramBins) + 1);
    std::vector<uint64_t> counts(static_cast<size_t>((hi - lo) / width + 1));
    for (const TimedValue& p : series) counts[static_cast<size_t>((p.ns - lo) / width)]++;
    // A step plot draws a bin from its x to the next one's: each bin at its
    // lower edge, and an empty one after the last to close it.
    std::string out = "[";
    for (size_t i = 0; i <= counts.size(); ++i) {
        double edge = static_cast<double>(lo + static_cast<int64_t>(i) * width);
        out += (i ? "," : "") + std::string("[") + num(edge / 1000.0) + "," +
               std::to_string(i < counts.size() ? counts[i] : 0) + "]";
    }
    return out + "]";
}

std::string series_json(const std::vector<TimedValue>& series, size_t buckets) {
    std::string out = "[";
    if (series.empty()) return out + "]";
    double t0 = series.front().t, t1 = series.back().t;
    size_t per = series.size() <= buckets ? 1 : 0;
    double width = per ? 0 : (t1 - t0) / static_cast<double>(buckets);
    bool first = true;
    auto emit = [&](double t, int64_t lo, double mean, int64_t hi) {
        out += std::string(first ? "" : ",") + "[" + num(t, 6) + ",[" + us(lo) + "," + num(mean / 1000.0) + "," +
               us(hi) + "]]";
        first = false;
    };
    if (per) {
        for (const TimedValue& p : series) emit(p.t, p.ns, static_cast<double>(p.ns), p.ns);
        return out + "]";
    }
    size_t i = 0;
    while (i < series.size()) {
        size_t bucket = static_cast<size_t>((series[i].t - t0) / width);
        double end = t0 + static_cast<double>(bucket + 1) * width;
        int64_t lo = series[i].ns, hi = lo;
        double sum = 0;
        size_t n = 0;
        double t = series[i].t;
        for (; i < series.size() && (series[i].t < end || bucket + 1 >= buckets); ++i, ++n) {
            lo = std::min(lo, series[i].ns);
            hi = std::max(hi, series[i].ns);
            sum += static_cast<double>(series[i].ns);
        }
        emit(t, lo, sum / static_cast<double>(n), hi);
    }
    return out + "]";
}

std::string write_report_html(const TimingModel& m, const std::string& tool_version, std::ostream& out) {
    std::string js, css, why;
    std::string dir = dygraphs_dir();
    if (!read_whole_file(dir + "/dygraph.min.js", js, why) || !read_whole_file(dir + "/dygraph.min.css", css, why))
        return "cannot read dygraphs from " + dir + " (" + why +
               "; install Debian's libjs-dygraphs, or set DISSGEN_DYGRAPHS_DIR)";

    out << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>EtherCAT timing: "
        << escape_html(capture_name(m.capture)) << "</title>\n<style>" << css << "</style>\n<style>" << kStyle
        << "</style>\n<script>" << js << "</script>\n</head><body>\n";
    out << "<h1>EtherCAT timing: " << escape_html(capture_name(m.capture)) << "</h1>\n<p class=\"note\">"
        << m.frames << " frames, " << num(m.duration, 3) << " s; " << m.cycles.size() << " cycle"
        << (m.cycles.size() == 1 ? "" : "s") << ", " << m.lost.size() << " lost frame"
        << (m.lost.size() == 1 ? "" : "s") << ", " << m.wkc_errors.size() << " working-counter error"
        << (m.wkc_errors.size() == 1 ? "" : "s") << ". Generated by dissgen " << tool_version
        << " from the fields of the installed plugin.</p>\n";

    out << "<h2>Cycles</h2>\n";
    if (!m.has_cycle_fields)
        out << "<p class=\"note\">The installed plugin shows no cycle fields (ecatr.cycle): regenerate it with this "
               "dissgen.</p>\n";
    else if (m.cycles.empty())
        out << "<p class=\"note\">No cyclic traffic in this capture.</p>\n";
    else cycle_table(m, out);
    for (const auto& [number, c] : m.cycles)
        out << "<div class=\"pair\"><div class=\"chart\" id=\"period-" << number
            << "\"></div><div class=\"chart\" id=\"jitter-" << number << "\"></div></div>\n";

    out << "<h2>Round trip</h2>\n<div class=\"chart wide\" id=\"round-trip\"></div>\n";

    out << "<h2>Slaves</h2>\n";
    if (m.slaves.empty())
        out << "<p class=\"note\">No AL status read from a single slave in this capture.</p>\n";
    else {
        out << "<table id=\"slaves\"><thead><tr><th>Position</th><th>Slave</th><th>AL states</th></tr></thead><tbody>\n";
        for (const auto& [position, s] : m.slaves) {
            std::string states;
            for (const auto& [t, state] : s.states)
                states += (states.empty() ? "" : " → ") + al_state_name(state) + " (" + num(t, 3) + " s)";
            out << "<tr><td>" << position << "</td><td>" << escape_html(s.name) << "</td><td>"
                << escape_html(states) << "</td></tr>\n";
        }
        out << "</tbody></table>\n<div class=\"chart wide\" id=\"al-states\"></div>\n";
    }

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
        << ",\"cycles\":[";
    bool first = true;
    for (const auto& [number, c] : m.cycles) {
        out << (first ? "" : ",") << "{\"number\":" << number << ",\"signature\":" << json_string(c.signature)
            << ",\"period\":" << series_json(c.period, kPlotBuckets) << ",\"histogram\":" << histogram_json(c.jitter)
            << "}";
        first = false;
    }
    out << "],\"round_trip\":" << series_json(m.round_trip, kPlotBuckets) << ",\"lost\":" << events_json(m.lost)
        << ",\"wkc_errors\":" << events_json(m.wkc_errors) << ",\"slaves\":" << slaves_json(m) << "}</script>\n";
    out << "<script>" << kScript << "</script>\n</body></html>\n";
    return out ? "" : "cannot write the report";
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "charts.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "../xml_input.h"

namespace dissgen {

namespace {

constexpr size_t kHistogramBins = 80;

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


std::string file_name(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

// The functions both reports' scripts draw with (before their own script).
const char kChartScript[] = R"JS(
function bars(series) { return series.map(p => [p[0], p[1]]); }
// Capture-time axis labels to the µs: Dygraph's default two decimals repeat
// (0.02 0.02 0.03) on a capture a few hundredths of a second long.
const captureTimeAxis = {axisLabelFormatter: v => String(+v.toFixed(6))};
function chart(id, rows, options) {
  const el = document.getElementById(id);
  if (!el) return;
  if (!rows.length) { el.textContent = 'No values.'; el.className += ' empty'; return; }
  new Dygraph(el, rows, options);
}
// Per cycle, its period over time and its jitter histogram, counting `what`.
function cycleCharts(cycles, common, what) {
  cycles.forEach(c => {
    chart('period-' + c.number, bars(c.period),
          Object.assign({customBars: true, labels: ['t', 'Period (µs)'], ylabel: 'Period (µs)',
                         title: 'Cycle ' + c.number + ': period over time'}, common));
    chart('jitter-' + c.number, c.histogram,
          {labels: ['Jitter (µs)', what], stepPlot: true, fillGraph: true, xRangePad: 12, xlabel: 'Jitter (µs)',
           ylabel: what, title: 'Cycle ' + c.number + ': jitter histogram', axes: {y: {axisLabelWidth: 64}}});
  });
}
)JS";

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

std::string num(double v, int decimals) {
    if (!std::isfinite(v)) return "null";
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

std::string us(int64_t ns) { return num(static_cast<double>(ns) / 1000.0, 3); }

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

std::string read_dygraphs(std::string& js, std::string& css) {
    std::string why, dir = dygraphs_dir();
    if (!read_whole_file(dir + "/dygraph.min.js", js, why) || !read_whole_file(dir + "/dygraph.min.css", css, why))
        return "cannot read dygraphs from " + dir + " (" + why +
               "; install Debian's libjs-dygraphs, or set DISSGEN_DYGRAPHS_DIR)";
    return "";
}

std::string capture_name(const std::vector<std::string>& paths) {
    std::string name;
    for (const std::string& p : paths) name += (name.empty() ? "" : " + ") + file_name(p);
    return name;
}

void write_page_head(const std::string& title, const std::string& js, const std::string& css, std::ostream& out) {
    out << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" << escape_html(title)
        << "</title>\n<style>" << css << "</style>\n<style>" << kStyle << "</style>\n<script>" << js
        << "</script>\n</head><body>\n";
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// What any protocol's report page is made of: HTML and JSON text that is safe
// to embed, figures as the tables print them, time series and histograms as
// dygraphs (Debian's libjs-dygraphs) draws them, embedded so that the page
// opens offline in any browser.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace dissgen {

// A point in a time series: seconds since the capture's first frame, a value in ns.
struct TimedValue {
    double t;
    int64_t ns;
};

std::string escape_html(const std::string& text);

// A JSON string literal, safe inside <script> (no "</").
std::string json_string(const std::string& text);

// v with `decimals` decimals; "null" when not finite (JSON).
std::string num(double v, int decimals = 3);

// ns -> "1000.250" µs, as the tables print them (exact: whole ns).
std::string us(int64_t ns);

// The folder holding dygraph.min.js and dygraph.min.css: $DISSGEN_DYGRAPHS_DIR,
// else Debian's /usr/share/javascript/dygraphs.
std::string dygraphs_dir();

// Reads dygraphs' script and style; "" on success, else a message for the user.
std::string read_dygraphs(std::string& js, std::string& css);

// A long series as at most `buckets` points of [t, [min, mean, max]] (µs),
// so that hours of capture draw quickly and no spike is lost.
std::string series_json(const std::vector<TimedValue>& series, size_t buckets);

// The histogram of a series as [[bin's lower edge µs, frames], ...]: at most
// 80 bins of whole nanoseconds from the smallest value to the largest, then
// an empty bin that closes the step plot.
std::string histogram_json(const std::vector<TimedValue>& series);

// Marks on a chart as [[t, value(event)], ...]: at most `limit`, every so
// many of `events` when there are more, so that a page stays quick to draw.
template <class Event, class Value>
std::string markers_json(const std::vector<Event>& events, Value value, size_t limit) {
    std::string out = "[";
    size_t step = events.size() > limit ? (events.size() + limit - 1) / limit : 1;
    for (size_t i = 0; i < events.size(); i += step)
        out += (i ? "," : "") + std::string("[") + num(events[i].t, 6) + "," + std::to_string(value(events[i])) + "]";
    return out + "]";
}

// The cycles' chart data as cycleCharts() reads it: [{number, signature,
// period (series_json), histogram (of the jitter)}, ...]. A Cycle has
// `signature` and the series `period` and `jitter`, by number.
template <class Cycles>
std::string cycles_json(const Cycles& cycles, size_t buckets) {
    std::string out = "[";
    for (const auto& [number, c] : cycles)
        out += std::string(out.size() > 1 ? "," : "") + "{\"number\":" + std::to_string(number) +
               ",\"signature\":" + json_string(c.signature) + ",\"period\":" + series_json(c.period, buckets) +
               ",\"histogram\":" + histogram_json(c.jitter) + "}";
    return out + "]";
}

// The script functions the reports' charts are drawn with: bars(series),
// chart(id, rows, options) (a note instead of an empty chart) and
// cycleCharts(cycles, common, what) (each cycle's period-N and jitter-N).
extern const char kChartScript[];

// "bus.pcapng", or "ring_00001.pcap + ring_00002.pcap" for a file set.
std::string capture_name(const std::vector<std::string>& paths);

// The page up to its <body>: the title, dygraphs' script and style (read by
// read_dygraphs()) and the reports' own style, all embedded.
void write_page_head(const std::string& title, const std::string& js, const std::string& css, std::ostream& out);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// What any protocol's report page is made of: HTML and JSON text that is safe
// to embed, figures as the tables print them, time series and histograms as
// dygraphs (Debian's libjs-dygraphs) draws them, embedded so that the page
// opens offline in any browser.
#pragma once

#include <cstdint>
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

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Writes the timing model as one self-contained HTML page: the figures as
// tables, the time series drawn by dygraphs (Debian's libjs-dygraphs),
// embedded in the page so that it opens offline in any browser.
#pragma once

#include <ostream>
#include <string>

#include "timing_model.h"

namespace dissgen {

// The folder holding dygraph.min.js and dygraph.min.css: $DISSGEN_DYGRAPHS_DIR,
// else Debian's /usr/share/javascript/dygraphs.
std::string dygraphs_dir();

// Returns "" on success, else a message for the user (e.g. dygraphs missing).
std::string write_report_html(const TimingModel& model, const std::string& tool_version, std::ostream& out);

// A long series as at most `buckets` points of [t, [min, mean, max]] (µs),
// so that hours of capture draw quickly and no spike is lost.
std::string series_json(const std::vector<TimedValue>& series, size_t buckets);

// The jitter histogram as [[bin's lower edge µs, frames], ...]: at most 80
// bins of whole nanoseconds from the smallest value to the largest, then an
// empty bin that closes the step plot.
std::string histogram_json(const std::vector<TimedValue>& series);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Writes an EtherCAT capture's timing model as one self-contained HTML page:
// the plugin's figures as tables, the time series drawn by dygraphs
// (charts.h), embedded so that it opens offline in any browser.
#pragma once

#include <ostream>
#include <string>

#include "timing_model.h"

namespace dissgen {

// Returns "" on success, else a message for the user (e.g. dygraphs missing).
std::string write_report_html(const TimingModel& model, const std::string& tool_version, std::ostream& out);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Writes the cycles and round trips of any protocol (cycles_model.h) as one
// self-contained HTML page: -z P,cycles as a table, per cycle its period over
// time and its jitter histogram, the streams' losses and repeats, the round
// trips with the requests left unanswered, drawn by dygraphs (charts.h).
#pragma once

#include <ostream>
#include <string>

#include "cycles_model.h"

namespace dissgen {

// Returns "" on success, else a message for the user (e.g. dygraphs missing).
std::string write_cycles_report_html(const CyclesModel& model, const std::string& tool_version, std::ostream& out);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// The protocol analyses a rule file can name with <pairing analysis="...">.
// Each lives in its own folder of plugin_runtime/ (its dg_analysis object and
// the sources that define it) and, when it reads more input than the rule
// file, of generator/. Adding one: its folders and its entry in
// plugin_runtime/runtime.list (runtime_list.h), which lists the analyses.
#pragma once

#include <string>
#include <vector>

#include "model.h"

namespace dissgen {

// One input an analysis reads from each message (<pairing><input name="...">):
// one value per message, or one per instance of a repeated node; or, read
// once, where a child of a window (a register of a register map) is.
struct AnalysisInputSpec {
    std::string name;
    bool per_instance = false;
    bool bytes = false;     // where a field's bytes are (its offset and length), not a number
    bool optional = false;  // a rule file may leave it unbound (the analysis does without)
    bool address = false;   // where a window child is (its at=, stride=, instances=), not a value of each message
};

struct Analysis {
    std::string name;                          // the rule file's <pairing analysis="...">
    std::string symbol;                        // its dg_analysis object in the runtime
    std::vector<std::string> runtime_sources;  // relative to the runtime folder
    std::vector<std::string> runtime_headers;  // likewise
    // what it reads from each message, every one required, in the order of
    // its dg_view (the runtime's list, e.g. ethercat_inputs.h)
    std::vector<AnalysisInputSpec> inputs;
    // it times the rule file's <cycles> itself (its runtime's dg_analysis.times_cycles)
    bool times_cycles = false;
};

// Every analysis, in the order of plugin_runtime/runtime.list.
const std::vector<Analysis>& analyses();

// The analysis called `name`, or nullptr.
const Analysis* find_analysis(const std::string& name);

// The analysis `proto`'s pairing names, or nullptr.
const Analysis* analysis_of(const Protocol& proto);

// Whether `proto`'s analysis times its <cycles> (the generic cycle analysis stays out).
bool analysis_times_cycles(const Protocol& proto);

// The runtime sources a plugin of `proto` compiles beyond the generic runtime:
// those of the analysis its pairing names, none without one.
std::vector<std::string> analysis_runtime_sources(const Protocol& proto);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "analyses.h"

#include "runtime_list.h"
#include "../plugin_runtime/ethercat/ethercat_inputs.h"

namespace dissgen {
namespace {

// What the analysis called `name` reads from each message, in its dg_view's order.
std::vector<AnalysisInputSpec> inputs_of(const std::string& name) {
#define DG_INPUT_SPEC(id, input, kind) \
    {input, ((kind) & DG_INPUT_PER_INSTANCE) != 0, ((kind) & DG_INPUT_BYTES) != 0, ((kind) & DG_INPUT_OPTIONAL) != 0, \
     ((kind) & DG_INPUT_ADDRESS) != 0},
    if (name == "ethercat-esc") return {DG_ESC_INPUTS(DG_INPUT_SPEC)};
#undef DG_INPUT_SPEC
    return {};
}

}  // namespace

const std::vector<Analysis>& analyses() {
    // runtime.list names each analysis and its files; what it reads from each
    // message is its runtime's own list (e.g. ethercat_inputs.h).
    static const std::vector<Analysis> list = [] {
        std::vector<Analysis> out = runtime_list().analyses;
        for (Analysis& a : out) {
            a.inputs = inputs_of(a.name);
            a.times_cycles = a.name == "ethercat-esc" && DG_ESC_TIMES_CYCLES;
        }
        return out;
    }();
    return list;
}

const Analysis* find_analysis(const std::string& name) {
    for (const Analysis& a : analyses())
        if (a.name == name) return &a;
    return nullptr;
}

const Analysis* analysis_of(const Protocol& proto) {
    return proto.pairing ? find_analysis(proto.pairing->analysis) : nullptr;
}

bool analysis_times_cycles(const Protocol& proto) {
    const Analysis* a = analysis_of(proto);
    return a && a->times_cycles;
}

std::vector<std::string> analysis_runtime_sources(const Protocol& proto) {
    const Analysis* a = analysis_of(proto);
    return a ? a->runtime_sources : std::vector<std::string>{};
}

}  // namespace dissgen

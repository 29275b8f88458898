// SPDX-License-Identifier: GPL-2.0-or-later
#include "analyses.h"

#include "../plugin_runtime/ethercat/ethercat_inputs.h"

namespace dissgen {

const std::vector<Analysis>& analyses() {
    static const std::vector<Analysis> list = {
        // What an EtherCAT slave controller does to a frame, and the bus model
        // (plugin_runtime/ethercat/).
#define DG_INPUT_SPEC(id, name, per_instance) {name, per_instance != 0},
        {"ethercat-esc", "dg_ethercat_esc", {"ethercat/ethercat_esc.cpp", "ethercat/ethercat_bus.cpp", "ethercat/ethercat_cycles.cpp"},
         {DG_ESC_INPUTS(DG_INPUT_SPEC)}},
#undef DG_INPUT_SPEC
    };
    return list;
}

const Analysis* find_analysis(const std::string& name) {
    for (const Analysis& a : analyses())
        if (a.name == name) return &a;
    return nullptr;
}

std::vector<std::string> analysis_runtime_sources(const Protocol& proto) {
    const Analysis* a = proto.pairing ? find_analysis(proto.pairing->analysis) : nullptr;
    return a ? a->runtime_sources : std::vector<std::string>{};
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "analyses.h"

#include "runtime_list.h"

namespace dissgen {

const std::vector<Analysis>& analyses() {
    return runtime_list().analyses;
}

const Analysis* find_analysis(const std::string& name) {
    for (const Analysis& a : analyses())
        if (a.name == name) return &a;
    return nullptr;
}

const Analysis* analysis_of(const Protocol& proto) {
    return proto.pairing ? find_analysis(proto.pairing->analysis) : nullptr;
}

std::vector<std::string> analysis_runtime_sources(const Protocol& proto) {
    const Analysis* a = analysis_of(proto);
    return a ? a->runtime_sources : std::vector<std::string>{};
}

}  // namespace dissgen

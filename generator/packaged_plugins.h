// SPDX-License-Identifier: GPL-2.0-or-later
// The plugins the dissgen package installs into Wireshark's global folder,
// one per shipped rule file: dissgen-packaged-STEM.so, built from
// share/dissgen/rules/STEM.xml. `dissgen install` looks for the one a new
// plugin would compete with.
#pragma once

#include <string>

#include "model.h"

namespace dissgen {

struct PackagedPlugin {
    std::string plugin;  // its path; "" when there is none
    std::string filter;  // the filter name of the protocol it provides
};

// The packaged plugin in `system_dir` whose protocol shares a name (filter,
// abbreviation or full name) with `p`, its rule file read from `rules_dir`.
// A file set aside (dissgen-packaged-STEM.so.disabled) is not one.
PackagedPlugin packaged_plugin_for(const Protocol& p, const std::string& system_dir, const std::string& rules_dir);

}  // namespace dissgen

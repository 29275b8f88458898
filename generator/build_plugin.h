// SPDX-License-Identifier: GPL-2.0-or-later
// Stage 4 (install): compile generated C++ with the runtime against the
// installed libwireshark and place the plugin where Wireshark loads it.
#pragma once

#include <string>
#include <vector>

namespace dissgen {

struct BuildRequest {
    std::string generated_source;  // the emitted C++
    std::string stem;              // rule file stem: plugin is dissgen_<stem>.so
    std::string target_dir;        // where the plugin goes
    std::string runtime_dir;       // plugin_runtime sources
    // Beyond the generic runtime, relative to runtime_dir: what the rules use
    // (analysis_runtime_sources), so a plugin carries no other analysis's code.
    std::vector<std::string> analysis_sources;
};

// Returns "" on success, else a message for the user.
std::string build_and_install(const BuildRequest& request, std::string& installed_path);

// A private folder `prefix`-XXXXXX: under $TMPDIR, else /tmp, else the user's
// cache folder (a machine whose /tmp this user may not write). Empty when
// none can be made; `tried` then lists where, with why.
std::string make_temp_folder(const std::string& prefix, std::string& tried);

// <exe>/../share/dissgen: the runtime and shipped rules of an installed
// dissgen, and (through links CMake makes) of build/bin/dissgen.
std::string share_dir(const std::string& argv0);

// The folder holding dissgen_runtime.h and the runtime sources: $DISSGEN_RUNTIME_DIR, else
// share_dir()/runtime; "" when neither has it.
std::string find_runtime_dir(const std::string& argv0);

// "dissgen_<stem>" with the stem reduced to [A-Za-z0-9_-].
std::string plugin_basename(const std::string& rule_path);

}  // namespace dissgen

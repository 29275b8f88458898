// SPDX-License-Identifier: GPL-2.0-or-later
// plugin_runtime/runtime.list, the one list of the plugin runtime's files,
// of the analyses and of the options plugin code is compiled with. CMake
// reads it to build and install the runtime and embeds its text into
// dissgen, which compiles plugins from it (`dissgen install`) and prints it
// for the scripts (`dissgen sources`).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "analyses.h"

namespace dissgen {

struct RuntimeList {
    std::vector<std::string> flags;    // compile options of all plugin code
    std::vector<std::string> sources;  // compiled into every plugin, relative to the runtime folder
    std::vector<std::string> headers;  // the generic runtime's headers
    std::vector<Analysis> analyses;    // with their own sources and headers
};

// Reads the text of a runtime list into `out`; false with "LINE: MESSAGE" in
// `error` on a line it does not understand.
bool parse_runtime_list(std::string_view text, RuntimeList& out, std::string& error);

// The list dissgen was built with.
const RuntimeList& runtime_list();

// What `dissgen sources` prints: "flags OPTION...", then a "source PATH" line
// per source and a "header PATH" line per header of the generic runtime and
// of `analyses` (paths relative to the runtime folder).
std::string runtime_files_text(const RuntimeList& list, const std::vector<const Analysis*>& analyses);

}  // namespace dissgen

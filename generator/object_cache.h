// SPDX-License-Identifier: GPL-2.0-or-later
// Stage 4 (install), the compile step: each translation unit of a plugin (the
// generated source, the runtime's, an analysis's) compiled once into a cache
// keyed by everything that decides the object, as ccache does. A rule file
// edited and installed again recompiles only its generated source; the runtime's
// objects, the same for every plugin, are compiled once per runtime and flags.
#pragma once

#include <string>
#include <vector>

namespace dissgen {

struct CompileJob {
    std::vector<std::string> compiler;  // the compiler and every option (without -c, -o, sources)
    std::vector<std::string> sources;   // translation units to compile
    std::vector<std::string> headers;   // every header they may include beyond the system's
    std::string cache_dir;              // "" or unusable: compile into work_dir, keep nothing
    std::string work_dir;               // the build's temporary folder
    std::string salt;                   // what else decides the objects (Wireshark's version)
};

// Compiles each source (in parallel, up to the machine's cores) unless the cache holds
// its object; `objects` gets one object per source, in order. Returns "" or the
// compiler's complaint.
std::string compile_objects(const CompileJob& job, std::vector<std::string>& objects);

// $DISSGEN_CACHE_DIR (empty: no cache), else $XDG_CACHE_HOME/dissgen, else
// $HOME/.cache/dissgen; "" when none is set.
std::string default_cache_dir();

}  // namespace dissgen

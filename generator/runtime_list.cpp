// SPDX-License-Identifier: GPL-2.0-or-later
#include "runtime_list.h"

#include <cstdlib>
#include <iostream>
#include <sstream>

#include "runtime_list_text.h"  // kRuntimeListText, configured by CMake from plugin_runtime/runtime.list

namespace dissgen {

namespace {

// Adds one line's words to `out`; "" when understood, else why not. The
// grammar is the one CMakeLists.txt's dissgen_read_runtime_list reads.
std::string add_line(const std::string& kind, const std::vector<std::string>& words, RuntimeList& out) {
    if (kind == "flags") {
        out.flags.insert(out.flags.end(), words.begin(), words.end());
    } else if (kind == "analysis") {
        if (words.size() != 2) return "'analysis' takes a name and its dg_analysis symbol";
        out.analyses.push_back({words[0], words[1], {}, {}, {}});
    } else if (kind == "source" || kind == "header") {
        // Lines after an 'analysis' line list that analysis's files.
        Analysis* owner = out.analyses.empty() ? nullptr : &out.analyses.back();
        auto& list = kind == "source" ? (owner ? owner->runtime_sources : out.sources)
                                      : (owner ? owner->runtime_headers : out.headers);
        list.insert(list.end(), words.begin(), words.end());
    } else {
        return "unknown entry '" + kind + "' (flags, source, header, analysis)";
    }
    return words.empty() ? "'" + kind + "' lists nothing" : "";
}

}  // namespace

bool parse_runtime_list(std::string_view text, RuntimeList& out, std::string& error) {
    std::istringstream in{std::string(text)};
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        std::istringstream words_in(line);
        std::string kind, word;
        if (!(words_in >> kind) || kind[0] == '#') continue;
        std::vector<std::string> words;
        while (words_in >> word) words.push_back(word);
        error = add_line(kind, words, out);
        if (!error.empty()) {
            error = std::to_string(number) + ": " + error;
            return false;
        }
    }
    return true;
}

const RuntimeList& runtime_list() {
    static const RuntimeList list = [] {
        RuntimeList parsed;
        std::string error;
        // CMake has read the same text with the same grammar: a mistake here
        // is a broken build, not a user's.
        if (!parse_runtime_list(kRuntimeListText, parsed, error)) {
            std::cerr << "dissgen: plugin_runtime/runtime.list:" << error << "\n";
            std::abort();
        }
        return parsed;
    }();
    return list;
}

std::string runtime_files_text(const RuntimeList& list, const std::vector<const Analysis*>& analyses) {
    std::string out = "flags";
    for (const std::string& flag : list.flags) out += " " + flag;
    out += "\n";
    auto add = [&out](const char* kind, const std::vector<std::string>& paths) {
        for (const std::string& path : paths) out += std::string(kind) + " " + path + "\n";
    };
    add("source", list.sources);
    for (const Analysis* a : analyses) add("source", a->runtime_sources);
    add("header", list.headers);
    for (const Analysis* a : analyses) add("header", a->runtime_headers);
    return out;
}

}  // namespace dissgen

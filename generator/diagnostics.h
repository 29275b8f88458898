// SPDX-License-Identifier: GPL-2.0-or-later
// Diagnostics: every message carries the source line of the element it is
// about, from parsing to the final "FILE:LINE: error: MESSAGE" text.
#pragma once

#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace dissgen {

enum class Severity { Warning, Error };

struct Diagnostic {
    Severity severity;
    int line;  // 1-based line in the rule file; 0 when the file as a whole is meant
    std::string message;
};

class Diagnostics {
public:
    // A message already given for the line is not repeated: the nodes of a
    // group are checked once per use, and their mistake is one mistake.
    void error(int line, std::string message) { add(Severity::Error, line, std::move(message)); }
    void warning(int line, std::string message) { add(Severity::Warning, line, std::move(message)); }
    bool has_errors() const;
    const std::vector<Diagnostic>& items() const { return items_; }

    // gcc style, one per line, in the order found, sorted by line.
    std::string format(const std::string& file) const;

private:
    void add(Severity severity, int line, std::string message);

    std::vector<Diagnostic> items_;
    std::set<std::tuple<Severity, int, std::string>> given_;  // items_, to refuse repeats
};

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Diagnostics: every message carries the source line of the element it is
// about, from parsing to the final "FILE:LINE: error: MESSAGE" text.
#pragma once

#include <map>
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
    // group are checked once per use, and their mistake is one mistake, told
    // once with the lines of the uses it was found through.
    void error(int line, std::string message) { add(Severity::Error, line, std::move(message)); }
    void warning(int line, std::string message) { add(Severity::Warning, line, std::move(message)); }
    bool has_errors() const;
    const std::vector<Diagnostic>& items() const { return items_; }

    // gcc style, one per line, in the order found, sorted by line.
    std::string format(const std::string& file) const;

private:
    void add(Severity severity, int line, std::string message);

    // The same mistake found through several uses of a group: its messages
    // differ only in the "used on line N" of each use.
    struct Uses {
        size_t item;               // in items_
        std::string first;         // the message as first given
        std::vector<std::string> lines;  // the one use's line in each message (one use named)
        size_t more = 0;           // further messages naming several nested uses
        std::set<std::string> seen;  // every message merged here, each counted once
    };
    void merge_use(Uses& uses, const std::string& message);

    std::vector<Diagnostic> items_;
    std::map<std::tuple<Severity, int, std::string>, Uses> given_;  // by the message with its use lines left out
};

}  // namespace dissgen

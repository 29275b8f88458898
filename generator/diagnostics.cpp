// SPDX-License-Identifier: GPL-2.0-or-later
#include "diagnostics.h"

#include <algorithm>

namespace dissgen {

void Diagnostics::add(Severity severity, int line, std::string message) {
    if (!given_.emplace(severity, line, message).second) return;
    items_.push_back({severity, line, std::move(message)});
}

bool Diagnostics::has_errors() const {
    return std::any_of(items_.begin(), items_.end(),
                       [](const Diagnostic& d) { return d.severity == Severity::Error; });
}

std::string Diagnostics::format(const std::string& file) const {
    std::vector<Diagnostic> sorted = items_;
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
    std::string out;
    for (const Diagnostic& d : sorted) {
        out += file;
        if (d.line > 0) out += ":" + std::to_string(d.line);
        out += d.severity == Severity::Error ? ": error: " : ": warning: ";
        out += d.message;
        out += '\n';
    }
    return out;
}

}  // namespace dissgen

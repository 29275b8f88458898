// SPDX-License-Identifier: GPL-2.0-or-later
#include "diagnostics.h"

#include <algorithm>
#include <iterator>
#include <regex>

namespace dissgen {

namespace {

const std::regex& use_line() {
    static const std::regex re(R"(used on line (\d+))");
    return re;
}

std::string listed(const std::vector<std::string>& lines) {
    std::string out;
    for (size_t i = 0; i < lines.size(); ++i)
        out += (i == 0 ? "" : i + 1 == lines.size() ? " and " : ", ") + lines[i];
    return out;
}

}  // namespace

void Diagnostics::add(Severity severity, int line, std::string message) {
    const std::string key = std::regex_replace(message, use_line(), "used on line #");
    auto found = given_.find({severity, line, key});
    if (found != given_.end()) {
        merge_use(found->second, message);
        return;
    }
    Uses uses{items_.size(), message, {}, 0, {message}};
    std::smatch m;
    if (std::regex_search(message, m, use_line())) uses.lines.push_back(m[1]);
    given_.emplace(std::make_tuple(severity, line, key), uses);
    items_.push_back({severity, line, std::move(message)});
}

void Diagnostics::merge_use(Uses& uses, const std::string& message) {
    const auto count = std::distance(std::sregex_iterator(message.begin(), message.end(), use_line()),
                                     std::sregex_iterator());
    if (count == 0 || !uses.seen.insert(message).second) return;  // a message already merged
    std::smatch m;
    if (count == 1 && uses.more == 0 && std::regex_search(message, m, use_line())) {
        if (std::find(uses.lines.begin(), uses.lines.end(), m[1].str()) != uses.lines.end()) return;
        uses.lines.push_back(m[1]);
        items_[uses.item].message =
            std::regex_replace(uses.first, use_line(), "used on lines " + listed(uses.lines),
                               std::regex_constants::format_first_only);
        return;
    }
    ++uses.more;  // uses within uses: the first is named, the others counted
    items_[uses.item].message = uses.first + " (and through " + std::to_string(uses.more) + " more use" +
                                (uses.more == 1 ? "" : "s") + " of the groups)";
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

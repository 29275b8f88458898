// SPDX-License-Identifier: GPL-2.0-or-later
#include "findings.h"

#include <utility>

namespace dissgen {
namespace {

using Words = std::vector<std::pair<std::string, std::string>>;

// Wireshark 4.0's expert.h severities; "warn" as Wireshark spells it, "warning" as the manual does.
const Words kSeverities = {{"chat", "PI_CHAT"}, {"note", "PI_NOTE"}, {"warning", "PI_WARN"}, {"warn", "PI_WARN"},
                           {"error", "PI_ERROR"}};

// Wireshark 4.0's expert.h groups (PI_COMMENTS_GROUP: packet comments, not for dissectors).
const Words kGroups = {{"checksum", "PI_CHECKSUM"},         {"sequence", "PI_SEQUENCE"},
                       {"response_code", "PI_RESPONSE_CODE"}, {"request_code", "PI_REQUEST_CODE"},
                       {"undecoded", "PI_UNDECODED"},       {"reassemble", "PI_REASSEMBLE"},
                       {"malformed", "PI_MALFORMED"},       {"debug", "PI_DEBUG"},
                       {"protocol", "PI_PROTOCOL"},         {"security", "PI_SECURITY"},
                       {"decryption", "PI_DECRYPTION"},     {"assumption", "PI_ASSUMPTION"},
                       {"deprecated", "PI_DEPRECATED"}};

std::string lookup(const Words& words, const std::string& word) {
    for (const auto& [name, constant] : words)
        if (name == word) return constant;
    return "";
}

std::vector<std::string> names_of(const Words& words) {
    std::vector<std::string> names;
    for (const auto& w : words) names.push_back(w.first);
    return names;
}

}  // namespace

std::string severity_constant(const std::string& severity) { return lookup(kSeverities, severity); }
std::string group_constant(const std::string& group) { return lookup(kGroups, group); }

const std::vector<std::string>& severity_names() {
    static const std::vector<std::string> names = names_of(kSeverities);
    return names;
}

const std::vector<std::string>& group_names() {
    static const std::vector<std::string> names = names_of(kGroups);
    return names;
}

}  // namespace dissgen

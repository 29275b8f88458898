// SPDX-License-Identifier: GPL-2.0-or-later
// <finding>: the words a rule file may use for an expert info's severity and
// group, and the Wireshark constants they stand for.
#pragma once

#include <string>
#include <vector>

namespace dissgen {

// "chat", "note", "warning" (or "warn"), "error"; "" when unknown.
std::string severity_constant(const std::string& severity);
// Wireshark's PI_ groups by their lowercased names ("malformed" -> PI_MALFORMED); "" when unknown.
std::string group_constant(const std::string& group);
// The words accepted, for messages.
const std::vector<std::string>& severity_names();
const std::vector<std::string>& group_names();

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Stage 1: rule file (XML) -> model. Reads the document with libxml2,
// checks elements and attributes, parses attribute values and resolves every
// XPath with libxml2's XPath engine (the node itself is the context node).
#pragma once

#include <memory>
#include <string>

#include "diagnostics.h"
#include "model.h"

namespace dissgen {

// Limits that keep an untrusted rule file from exhausting the generator.
constexpr size_t kMaxRuleFileBytes = 16u << 20;
constexpr int kMaxNesting = 64;

// Parses `text` (the contents of a rule file). Returns the protocol, or
// nullptr when the file cannot be read as a rule file at all; either way the
// problems found are in `diags`.
std::unique_ptr<Protocol> parse_rules(const std::string& text, Diagnostics& diags);

// Reads and parses a file; a missing file is reported in `diags`.
std::unique_ptr<Protocol> parse_rule_file(const std::string& path, Diagnostics& diags);

// "0x1f" or "31" (whitespace around allowed). Returns false on anything else.
bool parse_number(const std::string& text, uint64_t& value);

}  // namespace dissgen

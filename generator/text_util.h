// SPDX-License-Identifier: GPL-2.0-or-later
// Small string helpers shared by the generator stages.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dissgen {

std::string trim(const std::string& s);

// The candidate closest to `word` by edit distance ("" when none is close).
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

// "0x1f", or with at least `digits` hex digits "0x001f".
std::string hex(uint64_t v, int digits = 0);

// s itself, or when longer than `limit` its start and how long it is
// ("1 + 1 + 1... (80000 characters)"): what a diagnostic quotes stays readable.
std::string excerpt(const std::string& s, size_t limit = 80);

// "a, b, c"
std::string join(const std::vector<std::string>& items, const std::string& sep);

// "unknown attribute 'NAME' on <ELEMENT>", then "; did you mean 'NEAR'?" or,
// when no valid name is near, "; valid: " and the valid names.
std::string unknown_attribute(const std::string& name, const std::string& element, const std::string& near,
                              const std::vector<std::string>& valid);

}  // namespace dissgen

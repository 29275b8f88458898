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

// "a, b, c"
std::string join(const std::vector<std::string>& items, const std::string& sep);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Small string helpers shared by the generator stages.
#pragma once

#include <string>
#include <vector>

namespace dissgen {

std::string trim(const std::string& s);

// The candidate closest to `word` by edit distance ("" when none is close).
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

// "a, b, c"
std::string join(const std::vector<std::string>& items, const std::string& sep);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "tshark_values.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace dissgen {

bool parse_uint(std::string_view text, uint64_t& value, int base) {
    if (text.empty() || text[0] == '-') return false;
    std::string s(text);
    char* end = nullptr;
    value = std::strtoull(s.c_str(), &end, base);
    return end && *end == '\0';
}

bool parse_epoch(std::string_view text, int64_t& s, int64_t& ns) {
    size_t dot = text.find('.');
    uint64_t whole = 0, frac = 0;
    if (!parse_uint(text.substr(0, dot), whole, 10)) return false;
    ns = 0;
    if (dot != std::string_view::npos) {
        std::string_view digits = text.substr(dot + 1, 9);
        if (!digits.empty() && !parse_uint(digits, frac, 10)) return false;
        ns = static_cast<int64_t>(frac);
        for (size_t i = digits.size(); i < 9; ++i) ns *= 10;
    }
    s = static_cast<int64_t>(whole);
    return true;
}

bool parse_seconds_ns(std::string_view text, int64_t& ns) {
    bool negative = !text.empty() && text[0] == '-';
    if (negative) text.remove_prefix(1);
    int64_t s = 0, frac = 0;
    if (!parse_epoch(text, s, frac)) return false;
    ns = s * 1000000000 + frac;
    if (negative) ns = -ns;
    return true;
}

bool parse_quantiles(std::string_view text, Quantiles& q) {
    if (text == "none") return true;
    std::string copy(text);
    long long v[4];
    if (std::sscanf(copy.c_str(), "%lld %lld %lld %lld", &v[0], &v[1], &v[2], &v[3]) != 4) return false;
    q = {v[0], v[1], v[2], v[3]};
    return true;
}

bool CaptureClock::at(std::string_view epoch, double& t) {
    int64_t s = 0, ns = 0;
    if (!parse_epoch(epoch, s, ns)) return false;
    if (first_s_ < 0) {
        first_s_ = s;
        first_ns_ = ns;
    }
    t = static_cast<double>(s - first_s_) + static_cast<double>(ns - first_ns_) * 1e-9;
    return true;
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// tshark's text as the report reads it, parsed exactly: unresolved field
// values (frame numbers, "0x0130", relative times, epoch times) and the
// quantile lines of `-z P,cycles`. Shared by every protocol's report model.
#pragma once

#include <cstdint>
#include <string_view>

namespace dissgen {

// base 0: "0x0130" as tshark prints hexadecimal fields, "12" as decimal ones.
bool parse_uint(std::string_view text, uint64_t& value, int base = 0);

// frame.time_epoch "1700000000.123456789" -> whole seconds and ns.
bool parse_epoch(std::string_view text, int64_t& s, int64_t& ns);

// "0.001000250" or "-0.000000125" (seconds, as tshark prints relative times) -> ns.
bool parse_seconds_ns(std::string_view text, int64_t& ns);

// min/median/p99/max in ns, as -z P,cycles prints them; zero for "none".
struct Quantiles {
    int64_t min = 0, median = 0, p99 = 0, max = 0;
};

// The value of "  period min/median/p99/max (ns): 1 2 3 4", or of "  period: none".
bool parse_quantiles(std::string_view text, Quantiles& q);

// Seconds since the capture's first frame, from each frame's epoch time:
// whole seconds and ns apart, so that hours of capture keep their ns.
class CaptureClock {
public:
    // False when `epoch` is not a time; the first one read is t = 0.
    bool at(std::string_view epoch, double& t);

private:
    int64_t first_s_ = -1, first_ns_ = 0;
};

}  // namespace dissgen

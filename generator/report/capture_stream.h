// SPDX-License-Identifier: GPL-2.0-or-later
// Reads a capture through tshark, one row of field values per frame
// (`tshark -T fields`), as it decodes: the report sees exactly the numbers
// the installed plugin shows, and memory does not grow with the capture.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace dissgen {

// One frame's values, in the order the fields were asked for. A field that
// occurs several times in the frame holds its values joined by kValueSeparator
// (a control character, so that names and messages may hold commas); a field
// the frame lacks is empty.
constexpr char kValueSeparator = '\x1f';
using FieldRow = std::vector<std::string_view>;

struct CaptureStream {
    std::string tshark = "tshark";       // $DISSGEN_TSHARK, else from PATH
    std::vector<std::string> fields;     // display-filter names
    std::vector<std::string> extra_args; // e.g. -o preferences
    std::vector<std::pair<std::string, std::string>> environment;  // added to tshark's environment
};

// Runs tshark on `capture` and calls `on_row` for every frame. Progress goes
// to stderr (a line every few seconds, or one updated line on a terminal).
// Returns "" on success, else a message for the user (tshark's own error text
// when it failed).
std::string read_capture(const CaptureStream& stream, const std::string& capture,
                         const std::function<void(const FieldRow&)>& on_row);

// The display-filter field names the installed tshark knows (`tshark -G fields`).
std::vector<std::string> known_fields(const CaptureStream& stream);

// The values of one field of a row, split at kValueSeparator.
std::vector<std::string_view> split_values(std::string_view joined);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Reads a capture through tshark, one row of field values per frame, as it
// decodes: the report sees exactly the numbers the installed plugin shows,
// and memory does not grow with the capture. The fields are custom columns
// of summary lines (`-T tabs`, unresolved values): tshark then builds only
// the items they name, where `-T fields` builds every frame's whole tree
// (twice the time in Wireshark 4.0).
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace dissgen {

// One frame's values, in the order the fields were asked for. A field that
// occurs several times in the frame holds its values joined by kValueSeparator
// (a column's: a text value may hold one too); a field the frame lacks is
// empty, an item without a value (FT_NONE) shows as a check mark.
constexpr char kValueSeparator = ',';
using FieldRow = std::vector<std::string_view>;

struct CaptureStream {
    std::string tshark = "tshark";       // $DISSGEN_TSHARK, else from PATH
    std::string mergecap = "mergecap";   // joins several files; beside tshark (wireshark-common)
    std::vector<std::string> fields;     // display-filter names
    std::vector<std::string> extra_args; // e.g. -z statistics, printed after the rows
    std::function<void(std::string_view)> on_other_line;  // lines that are not rows (statistics)
    std::vector<std::pair<std::string, std::string>> environment;  // added to tshark's environment
};

// Runs tshark on `captures` and calls `on_row` for every frame. Several files
// (a ring-buffer set from `dumpcap -b`, in order) are read as one capture:
// mergecap concatenates them into tshark's input, so frame numbers and the
// plugin's state run on from one file into the next. Progress goes to stderr
// (a line every few seconds, or one updated line on a terminal). Returns "" on
// success, else a message for the user (tshark's own error text when it failed).
std::string read_capture(const CaptureStream& stream, const std::vector<std::string>& captures,
                         const std::function<void(const FieldRow&)>& on_row);

// The display-filter field names the installed tshark knows (`tshark -G fields`).
std::vector<std::string> known_fields(const CaptureStream& stream);

// The values of one field of a row, split at kValueSeparator.
std::vector<std::string_view> split_values(std::string_view joined);

// Whether `name` is among `known` (known_fields()).
bool has_field(const std::vector<std::string>& known, const std::string& name);

// A row's values by field name, for rows read with `fields`: "" for a field
// not asked for (the installed plugin lacks it) as for one the frame lacks.
class FieldColumns {
public:
    explicit FieldColumns(const std::vector<std::string>& fields);
    std::string_view get(const FieldRow& row, const std::string& field) const;

private:
    std::unordered_map<std::string, size_t> columns_;
};

}  // namespace dissgen

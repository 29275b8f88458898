// SPDX-License-Identifier: GPL-2.0-or-later
// libFuzzer target for the generator's front end: bytes in, diagnostics or a
// model (and its generated C++) out. Any crash, leak, hang or sanitizer
// report on a mutated rule file is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "diagnostics.h"
#include "emit_cpp.h"
#include "parser.h"
#include "validator.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string text(reinterpret_cast<const char*>(data), size);
    dissgen::Diagnostics diags;
    auto proto = dissgen::parse_rules(text, diags);
    if (proto && !diags.has_errors() && dissgen::validate(*proto, diags)) {
        std::string code = dissgen::emit_cpp(*proto, "fuzz.xml");
        std::string fields = dissgen::list_fields(*proto);
        if (code.empty() || fields.empty()) __builtin_trap();  // a valid file always yields code
    }
    (void)diags.format("fuzz.xml");
    return 0;
}

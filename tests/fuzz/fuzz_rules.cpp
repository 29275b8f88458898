// SPDX-License-Identifier: GPL-2.0-or-later
// libFuzzer target for the generator's front ends: bytes in, diagnostics or a
// model (and its generated C++) out. Every input goes to the rule-file front
// end and to the ESI and network (design/ENI) readers, all untrusted input.
// Any crash, leak, hang or sanitizer report on a mutated file is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "diagnostics.h"
#include "ethercat/emit_catalogue.h"
#include "emit_cpp.h"
#include "ethercat/esi_reader.h"
#include "ethercat/network_reader.h"
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

    dissgen::Catalogue cat;
    dissgen::Diagnostics esi_diags, net_diags;
    dissgen::read_esi(text, "fuzz.xml", cat, esi_diags);
    dissgen::Network net;
    if (dissgen::read_network(text, "fuzz.xml", cat, net, net_diags))
        (void)dissgen::emit_bus(cat, {&net, false}, "fuzz").tables;
    (void)esi_diags.format("fuzz.xml");
    (void)net_diags.format("fuzz.xml");
    return 0;
}

// SPDX-License-Identifier: GPL-2.0-or-later
// valid="LIST" fields and <heuristic> (parser, validator, generator/emit_validity.cpp):
// what the rule file says, where each valid field sits, and what the plugin is given.
#include <gtest/gtest.h>

#include "emit_cpp.h"
#include "emit_validity.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

const char* kModbusLike =
    "  <node name=\"Transaction\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Protocol\" length=\"2byte\" displaytype=\"numberdec\" valid=\"0\"/>\n"
    "  <node name=\"Length\" length=\"2byte\" displaytype=\"numberdec\" valid=\"2-254\"/>\n"
    "  <node name=\"Unit\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Data\" length=\"rest\" displaytype=\"origin\"/>\n";

std::string modbus_like(const std::string& root_children = "  <hook table=\"tcp.port\" value=\"5020\"/>\n") {
    return rules(root_children + kModbusLike, "pdulength=\"node[@name='Length']\" pdulengthadd=\"6\"");
}

TEST(Validity, ParsesListsAndHeuristics) {
    Front f = front_end(modbus_like("  <heuristic table=\"udp\"/>\n  <heuristic table=\"tcp\" enabled=\"false\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* length = find(*f.proto, "Length");
    EXPECT_TRUE(length->has_valid);
    ASSERT_EQ(length->valid_list.size(), 1u);
    EXPECT_EQ(length->valid_list[0].low, 2u);
    EXPECT_EQ(length->valid_list[0].high, 254u);
    EXPECT_FALSE(find(*f.proto, "Unit")->has_valid);
    ASSERT_EQ(f.proto->heuristics.size(), 2u);
    EXPECT_EQ(f.proto->heuristics[0].table, "udp");
    EXPECT_TRUE(f.proto->heuristics[0].enabled);
    EXPECT_EQ(f.proto->heuristics[0].line, 2);
    EXPECT_EQ(f.proto->heuristics[1].table, "tcp");
    EXPECT_FALSE(f.proto->heuristics[1].enabled);
}

TEST(Validity, OffsetsCountFromTheMessageStartThroughContainersAndBitGroups) {
    Front f = front_end(rules("  <node name=\"Magic\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"Header\">\n"
                              "    <node name=\"Pad\" length=\"3byte\"/>\n"
                              "    <node name=\"Version\" length=\"4bit\" displaytype=\"numberdec\" valid=\"1\"/>\n"
                              "    <node name=\"Flags\" length=\"12bit\" displaytype=\"numberhex\" valid=\"0-0xff\"/>\n"
                              "    <node name=\"Kind\" length=\"2byte\" displaytype=\"numberhex\" byteorder=\"little\" valid=\"5\"/>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "Version")->valid_offset, 4u);
    EXPECT_EQ(find(*f.proto, "Flags")->valid_offset, 4u);  // its bit group's first byte
    EXPECT_EQ(find(*f.proto, "Kind")->valid_offset, 6u);
    const std::string code = emit_cpp(*f.proto, "rules.xml");
    EXPECT_TRUE(contains(code, "/* Version, line 5 */ { 4, 2, 0, 12, 4, 0, 1, 0, 0 }")) << code;
    EXPECT_TRUE(contains(code, "/* Flags, line 6 */ { 4, 2, 0, 0, 12, 1, 1, 0, 0 }")) << code;
    EXPECT_TRUE(contains(code, "/* Kind, line 7 */ { 6, 2, 1, 0, 0, 2, 1, 0, 0 }")) << code;
    // the stream needs no header here (no pdulength): the bytes of the valid fields
    EXPECT_TRUE(contains(code, "tst_valid_fields, 3, tst_valid_ranges, 8,")) << code;
}

TEST(Validity, IfhookContainersLimitTheMessagesAFieldIsTestedIn) {
    Front f = front_end(rules("  <hook table=\"udp.port\" value=\"1000\"/>\n"
                              "  <node name=\"Outer\" ifhook=\"1000-1999\">\n"
                              "    <node name=\"Inner\" ifhook=\"1500-2500,7\">\n"
                              "      <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\" valid=\"9\"/>\n"
                              "    </node>\n"
                              "  </node>\n",
                              ""));
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::string code = emit_cpp(*f.proto, "rules.xml");
    // tested only where both lists hold: 1500-1999
    EXPECT_TRUE(contains(code, "{ { 0x9, 0x9 }, { 0x5dc, 0x7cf } }")) << code;
    EXPECT_TRUE(contains(code, "{ 0, 1, 0, 0, 0, 0, 1, 1, 1 }")) << code;
}

TEST(Validity, DisjointIfhooksNeverTestTheField) {
    Front f = front_end(rules("  <node name=\"Outer\" ifhook=\"1\">\n"
                              "    <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\" ifhook=\"2\" valid=\"9\"/>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::string code = emit_cpp(*f.proto, "rules.xml");
    EXPECT_TRUE(contains(code, "{ 0x1, 0x0 }")) << code;  // a range no value is in
}

TEST(Validity, EntriesTestFirstAndTheHeuristicIsRegistered) {
    Front f = front_end(modbus_like("  <hook table=\"tcp.port\" value=\"5020\"/>\n  <heuristic table=\"udp\"/>\n"
                                    "  <heuristic table=\"usb.bulk\" enabled=\"false\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::string code = emit_cpp(*f.proto, "rules.xml");
    EXPECT_TRUE(contains(code, "#include \"dissgen_validity.h\"\n")) << code;
    EXPECT_TRUE(contains(code, "return dg_valid_dissect(&tst_validity, tvb, pinfo, tree, data);")) << code;
    EXPECT_TRUE(contains(code, "return dg_valid_dissect_stream(&tst_validity, tvb, pinfo, tree, data);")) << code;
    EXPECT_FALSE(contains(code, "return dg_dissect(")) << code;
    EXPECT_TRUE(contains(code, "{ \"udp\", \"tst_udp\", \"Test over UDP\", TRUE }")) << code;
    EXPECT_TRUE(contains(code, "{ \"usb.bulk\", \"tst_usb.bulk\", \"Test over USB.BULK\", FALSE }")) << code;
    EXPECT_TRUE(contains(code, "    dg_handoff(&tst_protocol);\n    dg_validity_handoff(&tst_validity);\n")) << code;
    EXPECT_TRUE(contains(code, "return dg_valid_heuristic(&tst_validity, tvb, pinfo, tree) != 0;")) << code;
    // the header the stream reads before it can tell: the valid fields and the length, 6 bytes
    EXPECT_TRUE(contains(code, "tst_valid_fields, 2, tst_valid_ranges, 6,")) << code;
}

TEST(Validity, WithoutHeuristicsNothingIsRegistered) {
    Front f = front_end(modbus_like());
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::string code = emit_cpp(*f.proto, "rules.xml");
    EXPECT_TRUE(contains(code, "return dg_valid_dissect(&tst_validity")) << code;
    EXPECT_TRUE(contains(code, "    NULL, 0, NULL\n};")) << code;
    EXPECT_FALSE(contains(code, "dg_validity_handoff")) << code;
}

TEST(Validity, ProtocolsWithoutItAreGeneratedAsBefore) {
    Front f = front_end(rules(kModbusLike, "pdulength=\"node[@name='Length']\" pdulengthadd=\"6\" ethertype=\"0x88b5\""));
    std::string xml = rules(kModbusLike, "pdulength=\"node[@name='Length']\" pdulengthadd=\"6\" ethertype=\"0x88b5\"");
    for (size_t at; (at = xml.find(" valid=\"")) != std::string::npos;) xml.erase(at, xml.find('"', at + 8) + 1 - at);
    Front plain = front_end(xml);
    ASSERT_TRUE(plain.ok()) << plain.messages();
    EXPECT_FALSE(has_validity(*plain.proto));
    const std::string code = emit_cpp(*plain.proto, "rules.xml");
    EXPECT_FALSE(contains(code, "valid")) << code;
    EXPECT_TRUE(contains(code, "return dg_dissect(&tst_protocol, tvb, pinfo, tree);")) << code;
    EXPECT_TRUE(contains(code, "return dg_dissect_stream(&tst_protocol, tvb, pinfo, tree);")) << code;
    EXPECT_TRUE(has_validity(*f.proto));
}

TEST(Validity, HeuristicAloneIsWhereTheProtocolIsFound) {
    Front f = front_end(rules("  <heuristic table=\"eth\"/>\n"
                              "  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\" valid=\"1\"/>\n",
                              ""));
    EXPECT_TRUE(f.ok()) << f.messages();
}

TEST(Validity, Diagnostics) {
    Front conditional = front_end(rules("  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                                        "  <node name=\"Version\" length=\"1byte\" displaytype=\"numberdec\" valid=\"1\" "
                                        "direction=\"request\"/>\n",
                                        "ethertype=\"0x88b5\""));
    EXPECT_TRUE(contains(conditional.messages(),
                         "rules.xml:3: error: 'valid' field 'Version' must be at a fixed offset from the start of the "
                         "message, in every message: it is decoded only under a condition"))
        << conditional.messages();
    Front window = front_end(rules("  <node name=\"Addr\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                                   "  <node name=\"Map\" base=\"../node[@name='Addr']\" length=\"8byte\">\n"
                                   "    <node name=\"Reg\" at=\"2\" length=\"2byte\" displaytype=\"numberhex\" valid=\"1\"/>\n"
                                   "  </node>\n"));
    EXPECT_TRUE(contains(window.messages(), "'valid' field 'Reg' must be at a fixed offset")) << window.messages();
    EXPECT_TRUE(contains(window.messages(), "placed by address in a window")) << window.messages();
    Front sized = front_end(rules("  <node name=\"Size\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                                  "  <node name=\"Box\" length=\"../node[@name='Size']\">\n"
                                  "    <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\" valid=\"1\"/>\n"
                                  "  </node>\n"));
    EXPECT_TRUE(contains(sized.messages(), "it is inside 'Box' (line 3), which takes its length from a field"))
        << sized.messages();
    Front wide = front_end(rules("  <node name=\"Kind\" length=\"4bit\" displaytype=\"numberdec\" valid=\"3,8-20\"/>\n"
                                 "  <node name=\"Rest\" length=\"4bit\" displaytype=\"numberdec\"/>\n"));
    EXPECT_TRUE(wide.ok()) << wide.messages();
    EXPECT_TRUE(contains(wide.messages(), "rules.xml:2: warning: 'valid' value 8-20 does not fit the 4-bit field "
                                          "'Kind' (line 2): values above 15 never match"))
        << wide.messages();
    // echoed in the form written, not as 0x0-0x12c
    Front decimal = front_end(rules("  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\" valid=\"0-300\"/>\n"));
    EXPECT_TRUE(contains(decimal.messages(), "rules.xml:2: warning: 'valid' value 0-300 does not fit the 8-bit field "
                                             "'Kind' (line 2): values above 255 never match"))
        << decimal.messages();
}

}  // namespace
}  // namespace dissgen::testing

// Typed values in the generator: string/stringz/ipv4/int/float/time displays,
// range enums, repeat="rest", direction, dissector= and reassembly, from the
// parsed model to the registered field types and the emitted tables.
#include <gtest/gtest.h>

#include "emit_cpp.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

FieldType type_of(const Protocol& p, const std::string& name) {
    const Node* n = find(p, name);
    EXPECT_NE(n, nullptr) << name;
    return n ? field_type(*n) : FieldType{};
}

TEST(TypedValues, FieldTypesOfTheTypedDisplays) {
    Front f = front_end(rules("  <node name=\"text\" length=\"8byte\" displaytype=\"string\"/>\n"
                              "  <node name=\"z\" displaytype=\"stringz\"/>\n"
                              "  <node name=\"zfixed\" length=\"4byte\" displaytype=\"stringz\" encoding=\"ascii\"/>\n"
                              "  <node name=\"ip\" length=\"4byte\" displaytype=\"ipv4\"/>\n"
                              "  <node name=\"i8\" length=\"1byte\" displaytype=\"int\"/>\n"
                              "  <node name=\"i24\" length=\"3byte\" displaytype=\"int\"/>\n"
                              "  <node name=\"i64\" length=\"8byte\" displaytype=\"int\"/>\n"
                              "  <node name=\"lo\" length=\"3bit\" displaytype=\"int\"/>\n"
                              "  <node name=\"hi\" length=\"5bit\" displaytype=\"int\"/>\n"
                              "  <node name=\"real\" length=\"4byte\" displaytype=\"float\"/>\n"
                              "  <node name=\"lreal\" length=\"64bit\" displaytype=\"float\"/>\n"
                              "  <node name=\"t\" length=\"8byte\" displaytype=\"time\"/>\n"
                              "  <node name=\"ts\" length=\"2byte\" displaytype=\"time\" unit=\"s\"/>\n",
                              "ethertype=\"0x88b5\" byteorder=\"little\""));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Protocol& p = *f.proto;
    EXPECT_EQ(type_of(p, "text").type, "FT_STRING");
    EXPECT_EQ(type_of(p, "z").type, "FT_STRINGZ");
    EXPECT_EQ(type_of(p, "zfixed").type, "FT_STRINGZ");
    EXPECT_EQ(type_of(p, "ip").type, "FT_IPv4");
    for (const char* name : {"text", "z", "zfixed", "ip", "real", "lreal", "t", "ts", "i8", "i64"})
        EXPECT_EQ(type_of(p, name).mask, 0u) << name << ": no bitmask on a whole field";
    EXPECT_EQ(type_of(p, "i8").type, "FT_INT8");
    EXPECT_EQ(type_of(p, "i24").type, "FT_INT24");
    EXPECT_EQ(type_of(p, "i64").type, "FT_INT64");
    EXPECT_EQ(type_of(p, "i64").display, "BASE_DEC");
    // Bit fields: the group's width, the field's mask (little: first takes the low bits).
    EXPECT_EQ(type_of(p, "lo").type, "FT_INT8");
    EXPECT_EQ(type_of(p, "lo").mask, 0x07u);
    EXPECT_EQ(type_of(p, "hi").mask, 0xf8u);
    EXPECT_EQ(type_of(p, "real").type, "FT_FLOAT");
    EXPECT_EQ(type_of(p, "lreal").type, "FT_DOUBLE");
    EXPECT_EQ(type_of(p, "t").type, "FT_RELATIVE_TIME");
    // int and time are numeric: lengths, counts and conditions may read them.
    EXPECT_TRUE(find(p, "i8")->is_numeric());
    EXPECT_TRUE(find(p, "ts")->is_numeric());
    EXPECT_FALSE(find(p, "real")->is_numeric());
    EXPECT_FALSE(find(p, "ip")->is_numeric());

    std::string code = emit_cpp(p, "t.xml");
    EXPECT_TRUE(contains(code, "DG_SHOW_STRINGZ")) << code;
    EXPECT_TRUE(contains(code, "dg_node_extra().encoding(ENC_ASCII),")) << code;
    EXPECT_TRUE(contains(code, "dg_node_extra().units_per_second(1),")) << code;
}

TEST(TypedValues, Latin1TextUnderEitherName) {
    Front f = front_end(rules("  <node name=\"a\" length=\"8byte\" displaytype=\"string\" encoding=\"iso-8859-1\"/>\n"
                              "  <node name=\"b\" displaytype=\"stringz\" encoding=\"latin-1\"/>\n"
                              "  <node name=\"c\" length=\"8byte\" displaytype=\"string\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "b")->encoding, "iso-8859-1");
    const std::string code = emit_cpp(*f.proto, "t.xml");
    size_t first = code.find("dg_node_extra().encoding(ENC_ISO_8859_1),");
    ASSERT_NE(first, std::string::npos) << code;
    EXPECT_NE(code.find("dg_node_extra().encoding(ENC_ISO_8859_1),", first + 1), std::string::npos) << code;
    EXPECT_FALSE(contains(code, "ENC_ASCII")) << code;
}

TEST(TypedValues, LengthsFromAnIntOrTimeField) {
    Front f = front_end(rules("  <node name=\"n\" length=\"1byte\" displaytype=\"int\"/>\n"
                              "  <node name=\"data\" length=\"../node[@name='n']\"/>\n"));
    EXPECT_TRUE(f.ok()) << f.messages();
}

TEST(TypedValues, RangeEnumsBecomeARangeString) {
    Front f = front_end(rules("  <node name=\"code\" length=\"2byte\" displaytype=\"enum\">\n"
                              "    <enum value=\"0\" name=\"OK\"/>\n"
                              "    <enum value=\"0x0011-0x001f\" name=\"State\"/>\n"
                              "    <enum value=\"32-47\" name=\"Config\"/>\n"
                              "  </node>\n"
                              "  <node name=\"plain\" length=\"1byte\" displaytype=\"enum\">\n"
                              "    <enum value=\"1\" name=\"One\"/>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(type_of(*f.proto, "code").display, "BASE_HEX|BASE_RANGE_STRING");
    EXPECT_EQ(type_of(*f.proto, "plain").display, "BASE_HEX");
    std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, "static const range_string tst_code_rvals[] = {\n"
                               "    { 0x0000, 0x0000, \"OK\" },\n"
                               "    { 0x0011, 0x001f, \"State\" },\n"
                               "    { 0x0020, 0x002f, \"Config\" },\n"
                               "    { 0, 0, NULL }\n};"))
        << code;
    EXPECT_TRUE(contains(code, "RVALS(tst_code_rvals)"));
    EXPECT_TRUE(contains(code, "VALS(tst_plain_vals)"));
}

TEST(TypedValues, RepeatRestIsARepetition) {
    Front f = front_end(rules("  <node name=\"item\" length=\"2byte\" displaytype=\"numberhex\" repeat=\"rest\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* n = find(*f.proto, "item");
    EXPECT_TRUE(n->repeat_rest);
    EXPECT_FALSE(n->repeat.has_value());  // "rest" is not an XPath here
    EXPECT_TRUE(n->is_repeated());
    EXPECT_TRUE(contains(emit_cpp(*f.proto, "t.xml"), "dg_node_extra().repeat_rest(),"));
}

TEST(TypedValues, DirectionIsAConditionAndIsEmitted) {
    Front f = front_end(rules("  <hook table=\"udp.port\" value=\"502\"/>\n"
                              "  <node name=\"ask\" length=\"2byte\" direction=\"request\"/>\n"
                              "  <node name=\"box\" length=\"4byte\">\n"
                              "    <node name=\"answer\" length=\"2byte\" direction=\"response\"/>\n"
                              "    <node name=\"tail\" length=\"2byte\"/>\n"
                              "  </node>\n",
                              ""));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_TRUE(find(*f.proto, "ask")->is_conditional());
    EXPECT_EQ(f.diags.format("rules.xml").find("warning"), std::string::npos) << f.messages();
    std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, "DG_DIR_REQUEST"));
    EXPECT_TRUE(contains(code, "DG_DIR_RESPONSE"));
}

// A dissector name is printable ASCII without blanks, quotes or backslashes (it is
// written into the generated C++ as a string): every character from 0x20 to 0x7e
// inside a name, accepted exactly when it is one of those.
TEST(TypedValues, DissectorNameCharacters) {
    for (int c = 0x20; c <= 0x7e; ++c) {
        const std::string ch = c == '"' ? "&quot;" : c == '<' ? "&lt;" : c == '&' ? "&amp;" : std::string(1, static_cast<char>(c));
        Front f = front_end(rules("  <node name=\"frame\" length=\"rest\" dissector=\"eth" + ch + "x\"/>\n"));
        const bool allowed = c > 0x20 && c != '"' && c != '\\';
        EXPECT_EQ(f.ok(), allowed) << "character 0x" << std::hex << c << ": " << f.messages();
        if (!allowed) EXPECT_TRUE(contains(f.messages(), "bad dissector name")) << f.messages();
    }
    EXPECT_FALSE(front_end(rules("  <node name=\"frame\" length=\"rest\" dissector=\"eth\u00e9x\"/>\n")).ok());  // not ASCII
}

TEST(TypedValues, HandOffAndReassemblyTables) {
    Front f = front_end(rules("  <node name=\"id\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"offset\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"last\" length=\"1byte\" displaytype=\"bool\"/>\n"
                              "  <node name=\"frame\" length=\"rest\" dissector=\"eth_withoutfcs\"\n"
                              "        reassemble-id=\"../node[@name='id']\" reassemble-offset=\"../node[@name='offset'] * 32\"\n"
                              "        reassemble-last=\"../node[@name='last']\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* frame = find(*f.proto, "frame");
    ASSERT_TRUE(frame->reassemble_offset.has_value());
    EXPECT_EQ(frame->reassemble_offset->op, '*');
    EXPECT_EQ(frame->reassemble_offset->operand, 32);
    std::string code = emit_cpp(*f.proto, "t.xml");
    // The id, offset and last fields get value slots 0, 1 and 2.
    EXPECT_TRUE(contains(code, "dg_node_extra().dissector(\"eth_withoutfcs\").reassemble_id(0).reassemble_offset({1, '*', 0, 32})"))
        << code;
    EXPECT_TRUE(contains(code, ".reassemble_last(2),")) << code;
    EXPECT_TRUE(contains(code, "static reassembly_table tst_reassembly;"));
    EXPECT_TRUE(contains(code, ".reassembly(&tst_reassembly, &tst_fragment_items)")) << code;
    std::string fields = list_fields(*f.proto);
    EXPECT_TRUE(contains(fields, "tst.reassembled_in\tFT_FRAMENUM\t"));
    EXPECT_TRUE(contains(fields, "tst.fragment.count\tFT_UINT32\t"));
}

TEST(TypedValues, NoReassemblyNoFragmentFields) {
    Front f = front_end(rules("  <node name=\"frame\" length=\"rest\" dissector=\"eth_withoutfcs\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_FALSE(contains(list_fields(*f.proto), "fragment"));
    EXPECT_FALSE(contains(emit_cpp(*f.proto, "t.xml"), "reassembly_table"));
    // Without the constructs, nodes carry no dg_extra (the golden files of older rules stay as they were).
    Front plain = front_end(rules("  <node name=\"x\" length=\"2byte\"/>\n"));
    EXPECT_FALSE(contains(emit_cpp(*plain.proto, "t.xml"), "dg_extra"));
}

}  // namespace
}  // namespace dissgen::testing

// Absolute dates and times (datetime) and GUIDs (guid): from the parsed
// model to the registered field types and the emitted tables.
#include <gtest/gtest.h>

#include "emit_cpp.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

TEST(DatesAndGuids, FieldTypesAndEncodings) {
    Front f = front_end(rules("  <node name=\"net\" length=\"8byte\" displaytype=\"datetime\"/>\n"
                              "  <node name=\"ns\" length=\"8byte\" displaytype=\"datetime\" unit=\"ns\"/>\n"
                              "  <node name=\"us\" length=\"64bit\" displaytype=\"datetime\" unit=\"us\"/>\n"
                              "  <node name=\"ms\" length=\"8byte\" displaytype=\"datetime\" unit=\"ms\"/>\n"
                              "  <node name=\"s\" length=\"4byte\" displaytype=\"datetime\" unit=\"s\"/>\n"
                              "  <node name=\"id\" length=\"16byte\" displaytype=\"guid\"/>\n",
                              "ethertype=\"0x88b5\" byteorder=\"little\""));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Protocol& p = *f.proto;
    // No bitmask on either (Wireshark refuses one on a field that is no integer).
    for (const char* name : {"net", "ns", "us", "ms", "s"}) {
        EXPECT_EQ(field_type(*find(p, name)).type, "FT_ABSOLUTE_TIME") << name;
        EXPECT_EQ(field_type(*find(p, name)).display, "ABSOLUTE_TIME_UTC") << name;
        EXPECT_EQ(field_type(*find(p, name)).mask, 0u) << name;
        // not numbers: no length, count or condition may read them
        EXPECT_FALSE(find(p, name)->is_numeric()) << name;
    }
    EXPECT_EQ(field_type(*find(p, "id")).type, "FT_GUID");
    EXPECT_EQ(field_type(*find(p, "id")).display, "BASE_NONE");
    EXPECT_EQ(field_type(*find(p, "id")).mask, 0u);
    EXPECT_FALSE(find(p, "id")->is_numeric());

    std::string code = emit_cpp(p, "t.xml");
    EXPECT_EQ(count_of(code, "DG_SHOW_DATETIME"), 5u) << code;
    EXPECT_EQ(count_of(code, "DG_SHOW_GUID"), 1u) << code;
    // s+ns is the runtime's default (no dg_extra row); the other units say their encoding.
    EXPECT_EQ(count_of(code, "time_encoding("), 4u) << code;
    for (const char* enc : {"ENC_TIME_NSECS", "ENC_TIME_USECS", "ENC_TIME_MSECS", "ENC_TIME_SECS)"})
        EXPECT_TRUE(contains(code, std::string("dg_node_extra().time_encoding(") + enc)) << enc << "\n" << code;
    EXPECT_FALSE(contains(code, "ENC_TIME_SECS_NSECS")) << code;
    EXPECT_FALSE(contains(code, "BASE_UNIT_STRING")) << "a datetime's unit is no label";
}

TEST(DatesAndGuids, WrongLengthsAreErrorsOnTheirLine) {
    struct Case {
        const char* node;
        const char* message;
    };
    const Case cases[] = {
        {"length=\"4byte\" displaytype=\"datetime\"", "datetime display with unit 's+ns' needs a length of 8byte"},
        {"length=\"4byte\" displaytype=\"datetime\" unit=\"ns\"", "datetime display with unit 'ns' needs a length of 8byte"},
        {"length=\"2byte\" displaytype=\"datetime\" unit=\"s\"", "datetime display with unit 's' needs a length of 4byte or 8byte"},
        {"length=\"rest\" displaytype=\"datetime\"", "datetime display with unit 's+ns' needs a length of 8byte"},
        {"length=\"15byte\" displaytype=\"guid\"", "guid display needs a length of 16byte"},
        {"length=\"rest\" displaytype=\"guid\"", "guid display needs a length of 16byte"},
        {"length=\"4byte\" displaytype=\"ipv6\"", "ipv6 display needs a length of 16byte"},
        {"length=\"8byte\" displaytype=\"mac\"", "mac display needs a length of 6byte"},
        {"length=\"rest\" displaytype=\"mac\"", "mac display needs a length of 6byte"},
        {"length=\"6byte\" displaytype=\"eui64\"", "eui64 display needs a length of 8byte"},
    };
    for (const Case& c : cases) {
        Front f = front_end(rules("  <node name=\"k\" length=\"1byte\"/>\n  <node name=\"v\" " + std::string(c.node) + "/>\n"));
        EXPECT_FALSE(f.ok()) << c.node;
        EXPECT_TRUE(contains(f.messages(), "rules.xml:3: error: " + std::string(c.message))) << f.messages();
    }
}

// Addresses of one size and OIDs of any: Wireshark's types, no bitmask, compared by their bytes.
TEST(DatesAndGuids, AddressesAreWiresharksAddressTypes) {
    Front f = front_end(rules("  <node name=\"v6\" length=\"16byte\" displaytype=\"ipv6\"/>\n"
                              "  <node name=\"mac\" length=\"6byte\" displaytype=\"mac\"/>\n"
                              "  <node name=\"eui\" length=\"64bit\" displaytype=\"eui64\" byteorder=\"little\"/>\n"
                              "  <node name=\"k\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"oid\" length=\"../node[@name='k']\" displaytype=\"oid\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Protocol& p = *f.proto;
    const std::pair<const char*, const char*> types[] = {
        {"v6", "FT_IPv6"}, {"mac", "FT_ETHER"}, {"eui", "FT_EUI64"}, {"oid", "FT_OID"}};
    for (const auto& [name, type] : types) {
        EXPECT_EQ(field_type(*find(p, name)).type, type) << name;
        EXPECT_EQ(field_type(*find(p, name)).display, "BASE_NONE") << name;
        EXPECT_EQ(field_type(*find(p, name)).mask, 0u) << name;
        EXPECT_FALSE(find(p, name)->is_numeric()) << name;
        EXPECT_TRUE(find(p, name)->is_compared_by_bytes()) << name;
    }
    std::string code = emit_cpp(p, "t.xml");
    for (const char* show : {"DG_SHOW_IPV6", "DG_SHOW_MAC", "DG_SHOW_EUI64", "DG_SHOW_OID"})
        EXPECT_EQ(count_of(code, show), 1u) << show << "\n" << code;
}

TEST(DatesAndGuids, EightByteSecondsAndUnitsOfTimeStayAsTheyWere) {
    Front f = front_end(rules("  <node name=\"s64\" length=\"8byte\" displaytype=\"datetime\" unit=\"s\"/>\n"
                              "  <node name=\"t\" length=\"4byte\" displaytype=\"time\" unit=\"us\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    Front bad = front_end(rules("  <node name=\"t\" length=\"4byte\" displaytype=\"time\" unit=\"s+ns\"/>\n"));
    EXPECT_TRUE(contains(bad.messages(), "bad unit 's+ns': expected 'ns', 'us', 'ms' or 's'")) << bad.messages();
}

TEST(DatesAndGuids, ComputedTimesAreCountsOfTheirUnit) {
    Front f = front_end(rules("  <node name=\"secs\" length=\"4byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"at\" value=\"{secs} * 1000000000\" displaytype=\"datetime\"/>\n"
                              "  <node name=\"day\" value=\"{secs} / 86400\" displaytype=\"datetime\" unit=\"s\"/>\n"
                              "  <node name=\"since\" value=\"{secs} - 5\" displaytype=\"time\" unit=\"ms\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Protocol& p = *f.proto;
    EXPECT_EQ(field_type(*find(p, "at")).type, "FT_ABSOLUTE_TIME");
    EXPECT_EQ(field_type(*find(p, "at")).display, "ABSOLUTE_TIME_UTC");
    EXPECT_EQ(field_type(*find(p, "since")).type, "FT_RELATIVE_TIME");
    std::string code = emit_cpp(p, "t.xml");
    // a count: nanoseconds the runtime's default, other units per second; no byte encoding
    EXPECT_TRUE(contains(code, "dg_node_extra().value(0, 3),")) << code;
    EXPECT_TRUE(contains(code, "dg_node_extra().units_per_second(1).value(3, 3),")) << code;
    EXPECT_TRUE(contains(code, "dg_node_extra().units_per_second(1000).value(6, 3),")) << code;
    EXPECT_FALSE(contains(code, "time_encoding(")) << code;
}

}  // namespace
}  // namespace dissgen::testing

// Alternatives that share one filter name: which nodes are alternatives,
// the errors for fields that differ, and one registered field for all.
#include <gtest/gtest.h>

#include "alternatives.h"
#include "emit_cpp.h"
#include "test_support.h"

#include <regex>

namespace dissgen::testing {
namespace {

const char* kShared =
    "  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Short\" filter=\"\" if=\"../node[@name='Kind']\" in=\"1\">\n"
    "    <node name=\"Option\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
    "  </node>\n"
    "  <node name=\"Long\" filter=\"\" otherwise=\"true\">\n"
    "    <node name=\"Length\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "    <node name=\"Option\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
    "  </node>\n";

TEST(SharedFilterNames, AlternativesAreRegisteredOnce) {
    Front f = front_end(rules(kShared));
    ASSERT_TRUE(f.ok()) << f.messages();
    std::string code = emit_cpp(*f.proto, "t.xml");
    // One hf entry, one declaration, and both nodes' rows point at it.
    EXPECT_EQ(count_of(code, "\"tst.option\""), 1u) << code;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(code, m, std::regex(R"(\{ &(hf_\w+),\s*\{ "Option", "tst.option")"))) << code;
    const std::string hf = m[1];
    EXPECT_EQ(count_of(code, "static int hf_tst_option"), 1u) << code;
    EXPECT_EQ(count_of(code, "&" + hf + ")"), 2u) << "both Option rows use " << hf << "\n" << code;
    // dissgen fields lists it once
    EXPECT_EQ(count_of(list_fields(*f.proto), "tst.option\t"), 1u);
}

TEST(SharedFilterNames, WhichNodesAreAlternatives) {
    Front f = front_end(rules(
        "  <node name=\"K\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
        "  <node name=\"M\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
        "  <node name=\"a\" length=\"1byte\" if=\"../node[@name='K']\" in=\"1-3\"/>\n"
        "  <node name=\"b\" length=\"1byte\" if=\"../node[@name='K']\" in=\"4,5\"/>\n"
        "  <node name=\"c\" length=\"1byte\" if=\"../node[@name='K']\" in=\"3\"/>\n"
        "  <node name=\"d\" length=\"1byte\" if=\"../node[@name='M']\" in=\"7\"/>\n"
        "  <node name=\"e\" length=\"1byte\" otherwise=\"true\"/>\n"
        "  <node name=\"f\" length=\"1byte\" direction=\"request\"/>\n"
        "  <node name=\"g\" length=\"1byte\" direction=\"response\"/>\n"
        "  <node name=\"h\" length=\"1byte\"/>\n"
        "  <node name=\"w\" length=\"1byte\"><node name=\"x\" length=\"1byte\"/></node>\n",
        "byteorder=\"little\"><hook table=\"udp.port\" value=\"1\"/"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Protocol& p = *f.proto;
    auto alt = [&](const char* a, const char* b) { return are_alternatives(p, *find(p, a), *find(p, b)); };
    EXPECT_TRUE(alt("a", "b"));   // disjoint lists on one field
    EXPECT_FALSE(alt("a", "c"));  // 3 is in both
    EXPECT_FALSE(alt("a", "d"));  // different fields: both may hold
    EXPECT_TRUE(alt("d", "e"));   // one chain
    EXPECT_FALSE(alt("c", "e"));  // e is d's otherwise, not c's
    EXPECT_TRUE(alt("f", "g"));   // request and response
    EXPECT_FALSE(alt("g", "h"));  // h is always decoded
    EXPECT_FALSE(alt("w", "x"));  // one inside the other
    EXPECT_TRUE(are_alternatives(p, *find(p, "b"), *find(p, "a")));  // either order
}

TEST(SharedFilterNames, MaskedHexValuesOfOneNameKeepSixtyFourBits) {
    // Each mask alone would narrow its value (0xFF: FT_UINT8); sharing a field they are
    // 64 bits, as every other computed value: FT_UINT64.
    Front f = front_end(rules("  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Raw\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"Code\" value=\"{Raw} &amp; 0xFF\" displaytype=\"numberhex\"\n"
                              "        if=\"../node[@name='Kind']\" in=\"1\"/>\n"
                              "  <node name=\"Code\" value=\"{Raw} &gt;&gt; 8\" displaytype=\"numberhex\" otherwise=\"true\"/>\n"
                              "  <node name=\"Low\" value=\"{Raw} &amp; 0xFF\" displaytype=\"numberhex\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_EQ(count_of(code, "\"tst.code\""), 1u) << code;
    EXPECT_NE(code.find("\"tst.code\", FT_UINT64, BASE_HEX"), std::string::npos) << code;
    EXPECT_NE(code.find("\"tst.low\", FT_UINT8, BASE_HEX"), std::string::npos) << code;  // alone: narrowed
}

TEST(SharedFilterNames, WideningStopsAtAFieldThatIsNoMaskedValue) {
    // A masked value and a 16-bit field share a name; a third, 64 bits wide, would widen the
    // masked value, but the 16-bit field keeps its width: an error, not a field of two types.
    Front f = front_end(rules("  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Word\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"V\" filter=\"x\" value=\"{Word} &amp; 0xFFFF\" displaytype=\"numberhex\"\n"
                              "        if=\"../node[@name='Kind']\" in=\"1\"/>\n"
                              "  <node name=\"V\" filter=\"x\" length=\"2byte\" displaytype=\"numberhex\"\n"
                              "        if=\"../node[@name='Kind']\" in=\"2\"/>\n"
                              "  <node name=\"V\" filter=\"x\" length=\"8byte\" displaytype=\"numberhex\"\n"
                              "        if=\"../node[@name='Kind']\" in=\"3\"/>\n"));
    EXPECT_FALSE(f.ok());
    EXPECT_TRUE(contains(f.messages(), "rules.xml:8: error: alternatives 'V' (line 4) and 'V' (line 6) share the "
                                       "filter name 'tst.x' but not its field type"))
        << f.messages();
}

TEST(SharedFilterNames, NamesThatDifferWarn) {
    Front f = front_end(rules(
        "  <node name=\"K\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
        "  <node name=\"First\" filter=\"v\" length=\"1byte\" if=\"../node[@name='K']\" in=\"1\"/>\n"
        "  <node name=\"Second\" filter=\"v\" length=\"1byte\" if=\"../node[@name='K']\" in=\"2\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_TRUE(contains(f.messages(), "rules.xml:4: warning: 'Second' shares the filter name 'tst.v' with 'First' "
                                       "(line 3) and is shown with its name 'First'"))
        << f.messages();
    EXPECT_EQ(find(*f.proto, "Second")->shares_field, find(*f.proto, "First"));
}

}  // namespace
}  // namespace dissgen::testing

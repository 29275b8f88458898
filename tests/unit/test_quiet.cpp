// Which nodes a walk with no tree and no tap steps over, and how
// many bytes it steps (generator/quiet.cpp). Behaviour with tshark: summary
// lines against the bytes in tests/integration/language/test_info_column.py and
// test_quiet.py.
#include <gtest/gtest.h>

#include "quiet.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

std::map<const Node*, uint64_t> quiet_of(const Front& f) {
    return quiet_sizes(*f.proto, [](const Node& n) { return n.name == "Key"; });
}

// -1: not stepped over.
int64_t size_of(const std::map<const Node*, uint64_t>& q, const Front& f, const std::string& name) {
    auto it = q.find(find(*f.proto, name));
    return it == q.end() ? -1 : static_cast<int64_t>(it->second);
}

TEST(Quiet, FixedFieldsNobodyReadsAreSteppedOver) {
    Front f = front_end(rules("  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Flags\" length=\"2byte\">\n"
                              "    <node name=\"A\" length=\"4bit\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"B\" length=\"12bit\" displaytype=\"numberdec\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Pair\">\n"
                              "    <node name=\"X\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"Y\" length=\"4byte\" displaytype=\"ipv4\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Data\" length=\"../node[@name='Len']\" displaytype=\"origin\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    auto q = quiet_of(f);
    EXPECT_EQ(size_of(q, f, "Flags"), 2);   // a bit group filling its container
    EXPECT_EQ(size_of(q, f, "A"), -1);      // group members go with their group
    EXPECT_EQ(size_of(q, f, "Pair"), 6);    // length: the sum of its children
    EXPECT_EQ(size_of(q, f, "X"), 2);
    EXPECT_EQ(size_of(q, f, "Len"), -1);    // Data's length reads it
    EXPECT_EQ(size_of(q, f, "Data"), -1);   // its length is not fixed
}

TEST(Quiet, WhatOthersSeeIsDecoded) {
    Front f = front_end(rules("  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Key\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Named\" length=\"1byte\" summary=\"named\">\n"
                              "    <node name=\"V\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Outer\" length=\"2byte\">\n"
                              "    <node name=\"W\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"Z\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Eth\" length=\"2byte\" displaytype=\"origin\" dissector=\"eth_withoutfcs\"/>\n"
                              "  <node name=\"Tail\" length=\"1byte\" displaytype=\"numberdec\"\n"
                              "        if=\"../node[@name='Outer']/node[@name='Z']\" in=\"1\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    auto q = quiet_of(f);
    EXPECT_EQ(size_of(q, f, "Kind"), 1);
    EXPECT_EQ(size_of(q, f, "Key"), -1);    // a pairing key
    EXPECT_EQ(size_of(q, f, "Named"), -1);  // its summary goes to the Info column, even with no value in it
    EXPECT_EQ(size_of(q, f, "Outer"), -1);  // Z inside it decides Tail
    EXPECT_EQ(size_of(q, f, "W"), 1);
    EXPECT_EQ(size_of(q, f, "Eth"), -1);    // another dissector sees it
    EXPECT_EQ(size_of(q, f, "Tail"), 1);    // conditional itself: its condition is still evaluated
}

TEST(Quiet, WhatMayBeMalformedIsDecoded) {
    Front f = front_end(rules("  <node name=\"N\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Loose\" length=\"4byte\">\n"
                              "    <node name=\"A\" length=\"../../node[@name='N']\" displaytype=\"origin\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Choice\" length=\"2byte\">\n"
                              "    <node name=\"B\" length=\"2byte\" displaytype=\"numberdec\"\n"
                              "          if=\"../../node[@name='N']\" in=\"1\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Counted\" length=\"1byte\" displaytype=\"numberdec\"\n"
                              "        count=\"../node[@name='N']\"/>\n"
                              "  <node name=\"Text\" displaytype=\"stringz\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    auto q = quiet_of(f);
    EXPECT_EQ(size_of(q, f, "Loose"), -1);    // A may run past it, or leave bytes unused
    EXPECT_EQ(size_of(q, f, "Choice"), -1);   // what it holds depends on a value
    EXPECT_EQ(size_of(q, f, "B"), 2);
    EXPECT_EQ(size_of(q, f, "Counted"), -1);  // repeated: may run out of data
    EXPECT_EQ(size_of(q, f, "Text"), -1);     // runs to its NUL
}

}  // namespace
}  // namespace dissgen::testing

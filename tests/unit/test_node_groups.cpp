// SPDX-License-Identifier: GPL-2.0-or-later
// Node groups (<group>, <use>): the front end puts a copy of the group's
// nodes where each use stands, before the parser reads the file. (Misuses:
// tests/rules_err/group_*.xml and use_*.xml; with tshark: test_goose.py's
// nested Data values.)
#include <gtest/gtest.h>

#include "test_support.h"

namespace dissgen::testing {
namespace {

// Filter names and lines of every node, in document order.
std::vector<std::pair<std::string, int>> names_and_lines(const Protocol& proto) {
    std::vector<std::pair<std::string, int>> out;
    for_each_node(proto.nodes, [&](const Node& n) { out.emplace_back(n.filter_name, n.line); });
    return out;
}

TEST(NodeGroups, EachUseIsACopyNamedWhereItStandsWithTheGroupsLines) {
    Front f = front_end(rules(R"(  <group name="Point">
    <node name="X" length="1byte" displaytype="numberdec"/>
    <node name="Sum" value="{X} + 1"/>
  </group>
  <node name="From"><use group="Point"/></node>
  <node name="To"><use group="Point"/></node>
)"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::vector<std::pair<std::string, int>> want = {
        {"tst.from", 6}, {"tst.from.x", 3}, {"tst.from.sum", 4}, {"tst.to", 7}, {"tst.to.x", 3}, {"tst.to.sum", 4}};
    EXPECT_EQ(names_and_lines(*f.proto), want);
}

TEST(NodeGroups, AGroupNestsInItselfToItsDepthThenTheRestIsOneRawLeaf) {
    Front f = front_end(rules(R"(  <group name="Value" depth="3">
    <node name="Kind" length="1byte" displaytype="numberdec"/>
    <node name="Inner" if="../node[@name='Kind']" in="1"><use group="Value"/></node>
  </group>
  <node name="Top"><use group="Value"/></node>
)"));
    ASSERT_TRUE(f.ok()) << f.messages();
    std::vector<std::string> names;
    for (const auto& [name, line] : names_and_lines(*f.proto)) names.push_back(name);
    const std::vector<std::string> want = {"tst.top", "tst.top.kind", "tst.top.inner", "tst.top.inner.kind",
                                           "tst.top.inner.inner", "tst.top.inner.inner.kind",
                                           "tst.top.inner.inner.inner", "tst.top.inner.inner.inner.deeper"};
    EXPECT_EQ(names, want);
    const Node* deeper = find(*f.proto, "Value (nested deeper than 3 levels)");
    ASSERT_NE(deeper, nullptr);
    EXPECT_EQ(deeper->line, 4);  // the use it stands for
    EXPECT_EQ(deeper->display, Display::Origin);
}

TEST(NodeGroups, UsesInsideGroupsExpandAndAFileWithoutGroupsIsUnchanged) {
    Front grouped = front_end(rules(R"(  <group name="Length">
    <node name="Length" length="1byte" displaytype="numberdec"/>
  </group>
  <group name="Block">
    <use group="Length"/>
    <node name="Body" length="../node[@name='Length']"/>
  </group>
  <node name="First"><use group="Block"/></node>
)"));
    Front plain = front_end(rules(R"(  <node name="First">
    <node name="Length" length="1byte" displaytype="numberdec"/>
    <node name="Body" length="../node[@name='Length']"/>
  </node>
)"));
    ASSERT_TRUE(grouped.ok()) << grouped.messages();
    ASSERT_TRUE(plain.ok()) << plain.messages();
    std::vector<std::string> a, b;
    for (const auto& [name, line] : names_and_lines(*grouped.proto)) a.push_back(name);
    for (const auto& [name, line] : names_and_lines(*plain.proto)) b.push_back(name);
    EXPECT_EQ(a, b);
    EXPECT_NE(find(*grouped.proto, "Body")->length_ref.target, nullptr);
}

}  // namespace
}  // namespace dissgen::testing

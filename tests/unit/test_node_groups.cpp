// SPDX-License-Identifier: GPL-2.0-or-later
// Node groups (<group>, <use>): the front end puts a copy of the group's
// nodes where each use stands, before the parser reads the file. (Misuses:
// tests/rules_err/group_*.xml and use_*.xml; with tshark: test_goose.py's
// nested Data values.)
#include <gtest/gtest.h>

#include "emit_cpp.h"
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

// Two copies of a group read learned{...} with a lookup: each computes the
// key from its own copy's field, the closest before it (the <learn> alone
// would resolve {Entry} to the last one in the file).
TEST(NodeGroups, ALookupInEachCopyReadsTheFieldOfItsOwnCopy) {
    Front f = front_end(rules(R"(  <group name="Entries">
    <node name="Entry" length="1byte" displaytype="numberdec"/>
    <node name="Size" value="learned{Size}"/>
  </group>
  <node name="Kind" length="1byte" displaytype="numberdec"/>
  <node name="Inputs" if="../node[@name='Kind']" in="1"><use group="Entries"/></node>
  <node name="Outputs" otherwise="true" if="../node[@name='Kind']" in="2"><use group="Entries"/></node>
  <node name="Map" otherwise="true" if="../node[@name='Kind']" in="3">
    <node name="Number" length="1byte" displaytype="numberdec"/>
    <node name="Bytes" length="1byte" displaytype="numberdec"/>
    <learn name="Size" value="{Bytes}"><key value="{Number}" lookup="{Entry}"/></learn>
  </node>
)"));
    ASSERT_TRUE(f.ok()) << f.messages();
    ASSERT_EQ(f.proto->learns.size(), 1u);
    // the learn resolved {Entry} to Outputs' (the last): Inputs' reader has keys of its own
    ASSERT_EQ(f.proto->learned_read_keys.size(), 1u);
    const LearnedReadKeys& own = *f.proto->learned_read_keys[0];
    EXPECT_EQ(own.learn, f.proto->learns[0]);
    ASSERT_EQ(own.lookups.size(), 1u);
    ASSERT_TRUE(own.lookups[0]);
    ASSERT_NE(own.lookups[0]->target, nullptr);
    EXPECT_EQ(own.lookups[0]->target->parent->name, "Inputs");
    EXPECT_EQ(f.proto->learns[0]->keys[0].lookup->target->parent->name, "Outputs");
    // the plugin's learns table: the learn, then the reader's keys for it (keys_of = row 0 + 1)
    const std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_NE(code.find("/* learned{Size} at line 4 */ { 0, 0, 0, 0, 1, 1, DG_LEARN_ENDS_NONE, 1 }"), std::string::npos) << code;
}

}  // namespace
}  // namespace dissgen::testing

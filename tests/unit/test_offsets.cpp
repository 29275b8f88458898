// Offset tables (offsets="XPATH" from="XPATH"): instances of a node
// placed by the values of an earlier repeated leaf, through the parser, the
// validator and the emitter. (Misuses: tests/rules_err/offsets_*.xml and
// from_*.xml; behaviour with tshark: tests/integration/protocols/test_enip.py.)
#include <gtest/gtest.h>

#include "emit_cpp.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

// A count, an offset table counted from the count's first byte, and the items.
const char* kTable =
    "  <node name=\"Count\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Offset\" length=\"2byte\" displaytype=\"numberdec\" count=\"../node[@name='Count']\"/>\n"
    "  <node name=\"Item\" length=\"rest\" offsets=\"../node[@name='Offset']\" from=\"../node[@name='Count']\">\n"
    "    <node name=\"Code\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
    "    <node name=\"Data\" length=\"rest\"/>\n"
    "  </node>\n";

TEST(Offsets, ParsedResolvedAndTheTableKeepsItsValues) {
    Front f = front_end(rules(kTable));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* item = find(*f.proto, "Item");
    ASSERT_TRUE(item->is_located());
    EXPECT_TRUE(item->is_repeated());
    EXPECT_EQ(item->offsets->target, find(*f.proto, "Offset"));
    EXPECT_EQ(item->from->target, find(*f.proto, "Count"));
    EXPECT_EQ(item->from_up, 0u);
    EXPECT_TRUE(find(*f.proto, "Offset")->keeps_values);
    EXPECT_FALSE(find(*f.proto, "Count")->keeps_values);
    EXPECT_GE(find(*f.proto, "Offset")->slot, 0);
    EXPECT_GE(find(*f.proto, "Count")->slot, 0);  // its first byte is the base
}

TEST(Offsets, FromAnEnclosingContainerCountsLevels) {
    Front f = front_end(rules(
        "  <node name=\"Box\" length=\"rest\">\n"
        "    <node name=\"Inner\" length=\"rest\">\n"
        "      <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
        "      <node name=\"Offset\" length=\"1byte\" displaytype=\"numberdec\" count=\"../node[@name='Count']\"/>\n"
        "      <node name=\"Item\" length=\"rest\" displaytype=\"origin\" offsets=\"../node[@name='Offset']\" from=\"../..\"/>\n"
        "    </node>\n"
        "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* item = find(*f.proto, "Item");
    EXPECT_EQ(item->from_up, 2u);
    // no slot for Box: the runtime takes the start of its content
    EXPECT_EQ(find(*f.proto, "Box")->slot, -1);
    std::string code = emit_cpp(*f.proto, "t.xml");
    // Item's extra: offsets slot, no from slot, 2 levels up, values not kept; Offset's: kept
    EXPECT_TRUE(contains(code, "dg_node_extra().offsets_slot(1).from_up(2),")) << code;
    EXPECT_TRUE(contains(code, "dg_node_extra().keep_values(),")) << code;
}

TEST(Offsets, EmittedInTheExtraTableAndWithTheNewExpert) {
    Front f = front_end(rules(kTable));
    ASSERT_TRUE(f.ok()) << f.messages();
    std::string code = emit_cpp(*f.proto, "t.xml");
    // Count is slot 0, Offset slot 1: Item reads the table in slot 1 from slot 0's first byte
    EXPECT_TRUE(contains(code, "dg_node_extra().offsets_slot(1).from_slot(0),")) << code;
    EXPECT_TRUE(contains(code, "\"tst.expert.bad_offset\", PI_MALFORMED, PI_ERROR")) << code;
}

TEST(Offsets, ProtocolsWithoutTablesKeepTheirExtraRowsShort) {
    Front f = front_end(rules("  <node name=\"Rest\" length=\"rest\" repeat=\"rest\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, "dg_node_extra().repeat_rest(),")) << code;
    EXPECT_FALSE(contains(code, "offsets_slot")) << code;
}

TEST(Offsets, AReferenceIntoAPlacedInstanceFromOutsideIsRejected) {
    Front f = front_end(rules(std::string(kTable) +
                              "  <node name=\"After\" length=\"../node[@name='Item']/node[@name='Code']\"/>\n"));
    EXPECT_FALSE(f.ok());
    EXPECT_TRUE(contains(f.messages(), "is inside repeated node 'Item'")) << f.messages();
}

}  // namespace
}  // namespace dissgen::testing

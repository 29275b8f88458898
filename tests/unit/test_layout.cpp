// <when> conditions, peek look-ahead, otherwise chains and
// register windows, through the parser, the validator and the emitter.
// (Misuses: one file each in tests/rules_err; behaviour with tshark:
// tests/integration/language/test_layout.py.)
#include <gtest/gtest.h>

#include "emit_cpp.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

const char* kHeader =
    "  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Addr\" length=\"2byte\" displaytype=\"numberhex\"/>\n";

TEST(Layout, WhenChildrenAreParsedAndAnded) {
    Front f = front_end(rules(std::string(kHeader) +
                              "  <node name=\"Body\" length=\"2byte\" if=\"../node[@name='Kind']\" in=\"1\">\n"
                              "    <when field=\"../node[@name='Addr']\" in=\"0-0x0fff, 0x2000\"/>\n"
                              "    <when peek=\"../node[@name='Tail']\" in=\"1\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Tail\" length=\"1byte\" displaytype=\"numberdec\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* body = find(*f.proto, "Body");
    ASSERT_EQ(body->whens.size(), 2u);
    EXPECT_FALSE(body->whens[0].peek);
    EXPECT_EQ(body->whens[0].ref.target, find(*f.proto, "Addr"));
    ASSERT_EQ(body->whens[0].in_list.size(), 2u);
    EXPECT_EQ(body->whens[0].in_list[0].high, 0x0fffu);
    EXPECT_EQ(body->whens[0].in_list[1].low, 0x2000u);
    EXPECT_TRUE(body->whens[1].peek);
    EXPECT_EQ(body->whens[1].offset, 2u);  // Body's own 2 bytes
    EXPECT_TRUE(body->is_conditional());
    EXPECT_GE(find(*f.proto, "Addr")->slot, 0);  // the runtime keeps the value a <when> reads
}

TEST(Layout, PeekOffsetAddsFixedBytesAndEarlierLengthFields) {
    Front f = front_end(rules(std::string(kHeader) +
                              "  <node name=\"Body\" length=\"../node[@name='Len']\">\n"
                              "    <when peek=\"../node[@name='Tail']\" in=\"1\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Pad\" length=\"3byte\"/>\n"
                              "  <node name=\"More\" length=\"../node[@name='Len'] * 2\"/>\n"
                              "  <node name=\"Hi\" length=\"4bit\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Tail\" length=\"4bit\" displaytype=\"numberdec\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const When& w = find(*f.proto, "Body")->whens[0];
    EXPECT_EQ(w.offset, 3u);  // Pad; Tail shares its byte with Hi: the group's start
    ASSERT_EQ(w.lengths.size(), 2u);
    EXPECT_EQ(w.lengths[0]->target, find(*f.proto, "Len"));
    EXPECT_EQ(w.lengths[1]->op, '*');
}

TEST(Layout, PeekSkipsLaterMembersOfItsChainAndClimbsSummedContainers) {
    Front f = front_end(rules(std::string(kHeader) +
                              "  <node name=\"Box\">\n"
                              "    <node name=\"Regs\" length=\"../../node[@name='Len']\" if=\"../../node[@name='Kind']\" in=\"1\"/>\n"
                              "    <node name=\"Mbx\" length=\"../../node[@name='Len']\" otherwise=\"true\">\n"
                              "      <when peek=\"../../node[@name='Wkc']\" in=\"1\"/>\n"
                              "    </node>\n"
                              "    <node name=\"Raw\" length=\"../../node[@name='Len']\" otherwise=\"true\"/>\n"
                              "    <node name=\"Pad\" length=\"1byte\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Wkc\" length=\"2byte\" displaytype=\"numberdec\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const When& w = find(*f.proto, "Mbx")->whens[0];
    EXPECT_EQ(w.offset, 1u);  // Raw skipped (same chain), Pad counted, then up out of Box
    ASSERT_EQ(w.lengths.size(), 1u);
}

TEST(Layout, PeekCountsFromAContainerThatEndsWhereItsLengthSays) {
    // EtherCAT's shape: the data (its length from the header) holds the
    // alternatives, each 'rest'; the working counter follows the data.
    Front f = front_end(rules(std::string(kHeader) +
                              "  <node name=\"Data\" length=\"../node[@name='Len']\">\n"
                              "    <node name=\"Inner\">\n"
                              "      <node name=\"Tag\" length=\"1byte\"/>\n"
                              "      <node name=\"Mbx\" length=\"rest\">\n"
                              "        <when peek=\"../../../node[@name='Wkc']\" in=\"1\"/>\n"
                              "      </node>\n"
                              "    </node>\n"
                              "  </node>\n"
                              "  <node name=\"Pad\" length=\"2byte\"/>\n"
                              "  <node name=\"Wkc\" length=\"2byte\" displaytype=\"numberdec\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const When& w = find(*f.proto, "Mbx")->whens[0];
    EXPECT_EQ(w.up, 2u);      // from the start of Data, Mbx's second container
    EXPECT_EQ(w.target_up, 2u);  // Wkc: in the list two containers up (the message)
    EXPECT_EQ(w.offset, 2u);  // Pad
    ASSERT_EQ(w.lengths.size(), 1u);
    EXPECT_EQ(w.lengths[0]->target, find(*f.proto, "Len"));
    std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, "{ 8, 2, 0, 1, 2, 2 }")) << code;
}

TEST(Layout, OtherwiseChains) {
    Front f = front_end(rules(std::string(kHeader) +
                              "  <node name=\"A\" length=\"1byte\" if=\"../node[@name='Kind']\" in=\"1\"/>\n"
                              "  <node name=\"B\" length=\"1byte\" otherwise=\"true\" if=\"../node[@name='Kind']\" in=\"2\"/>\n"
                              "  <node name=\"C\" length=\"1byte\" otherwise=\"true\"/>\n"
                              "  <node name=\"D\" length=\"1byte\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_TRUE(find(*f.proto, "B")->otherwise);
    EXPECT_TRUE(find(*f.proto, "C")->is_conditional());
    std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, ".alt(DG_ALT_OTHERWISE).quiet_size(1u),")) << code;  // quiet: 1 byte
}

const char* kWindow =
    "  <node name=\"Window\" filter=\"win\" length=\"../node[@name='Len']\" base=\"../node[@name='Addr'] - 16\">\n"
    "    <node name=\"Status\" at=\"0x0110\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
    "    <node name=\"Id\" at=\"0x0000\" length=\"4byte\" displaytype=\"numberhex\"/>\n"
    "    <node name=\"FMMU {i}\" at=\"0x0600\" stride=\"16\" instances=\"16\">\n"
    "      <node name=\"Logical start\" length=\"4byte\" displaytype=\"numberhex\"/>\n"
    "      <node name=\"Rest\" length=\"12byte\"/>\n"
    "    </node>\n"
    "  </node>\n";

TEST(Layout, WindowChildrenArePlacedAndSortedByAddress) {
    Front f = front_end(rules(std::string(kHeader) + kWindow));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* w = find(*f.proto, "Window");
    EXPECT_TRUE(w->is_window());
    EXPECT_EQ(w->base->op, '-');
    EXPECT_EQ(find(*f.proto, "FMMU {i}")->place_bytes, 16u);
    EXPECT_EQ(*find(*f.proto, "FMMU {i}")->stride, 16u);
    // the instance number is left out of the filter name
    EXPECT_EQ(find(*f.proto, "FMMU {i}")->filter_name, "tst.win.fmmu");
    std::string code = emit_cpp(*f.proto, "t.xml");
    // by address: Id (node 5), Status (4), FMMU (6); the largest span is 15*16+16;
    // the base is Addr's value (slot 1, after Len's) minus 16
    // each quiet within its size (nothing reads them): a walk nobody sees steps over them
    EXPECT_TRUE(contains(code, "{ 5, TRUE, 0x0, 4, 0, 1 },\n    { 4, TRUE, 0x110, 2, 0, 1 },\n    { 6, TRUE, 0x600, 16, 16, 16 },"))
        << code;
    EXPECT_TRUE(contains(code, "{ {1, '-', 0, 16}, 0, 3, 256, FALSE }")) << code;
    EXPECT_TRUE(contains(code, "tst_conditions = { tst_ranges, NULL };")) << "no <when> rows: " << code;
    EXPECT_FALSE(contains(code, ".peeks(")) << code;
    EXPECT_TRUE(contains(code, ".windows(tst_windows).places(tst_places)")) << code;
}

TEST(Layout, APlaceSomeoneReadsIsNotSteppedOver) {
    // Status shows in the window's summary: a walk without a tree still reads it
    std::string window = kWindow;
    window.replace(window.find("base="), 5, "summary=\"{Status}\" base=");
    Front f = front_end(rules(std::string(kHeader) + window));
    ASSERT_TRUE(f.ok()) << f.messages();
    std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, "{ 5, TRUE, 0x0, 4, 0, 1 },\n    { 4, FALSE, 0x110, 2, 0, 1 },")) << code;
}

TEST(Layout, WindowLengthNeedNotBeItsChildrensSum) {
    Front f = front_end(rules(std::string(kHeader) +
                              "  <node name=\"Window\" length=\"4096byte\" base=\"../node[@name='Addr']\">\n"
                              "    <node name=\"Reg\" at=\"0x0130\" length=\"2byte\"/>\n"
                              "  </node>\n"));
    EXPECT_TRUE(f.ok()) << f.messages();
}

TEST(Layout, ProtocolsWithoutTheConstructsEmitNoNewTables) {
    Front f = front_end(rules(kHeader));
    ASSERT_TRUE(f.ok()) << f.messages();
    std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_FALSE(contains(code, "dg_when"));
    EXPECT_FALSE(contains(code, "dg_window"));
}

}  // namespace
}  // namespace dissgen::testing

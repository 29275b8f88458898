// SPDX-License-Identifier: GPL-2.0-or-later
// Stage 2 (generator/validator.cpp): display-filter names, bit-group layout,
// defaults and inheritance, references, slots, pdulength and summaries.
#include <gtest/gtest.h>

#include "test_support.h"

namespace dissgen::testing {
namespace {

// ---- filter names: the segment rule ------------------------------------------------

TEST(Segment, LowercasesAndJoinsRunsWithUnderscore) {
    EXPECT_EQ(segment_from_name("Length"), "length");
    EXPECT_EQ(segment_from_name("WKC"), "wkc");
    EXPECT_EQ(segment_from_name("A b"), "a_b");
    EXPECT_EQ(segment_from_name("a-b"), "a_b");
    EXPECT_EQ(segment_from_name("a  -- b"), "a_b");
    EXPECT_EQ(segment_from_name("Slave address (ADP)"), "slave_address_adp");
    EXPECT_EQ(segment_from_name("MiXeD123case"), "mixed123case");
    EXPECT_EQ(segment_from_name("a_b"), "a_b");  // '_' is outside [a-z0-9] too: a run of one
    EXPECT_EQ(segment_from_name("a__b"), "a_b");
}

TEST(Segment, TrimsSeparatorsAtBothEnds) {
    EXPECT_EQ(segment_from_name("  Length  "), "length");
    EXPECT_EQ(segment_from_name("(x)"), "x");
    EXPECT_EQ(segment_from_name("--Deep--Leaf--"), "deep_leaf");
    EXPECT_EQ(segment_from_name("_private_"), "private");
}

TEST(Segment, NonAsciiIsOutsideTheSet) {
    EXPECT_EQ(segment_from_name("命令"), "");
    EXPECT_EQ(segment_from_name("EtherCAT头"), "ethercat");
    EXPECT_EQ(segment_from_name("索引 idx"), "idx");
    EXPECT_EQ(segment_from_name("长度Len长度"), "len");
    EXPECT_EQ(segment_from_name("Länge"), "l_nge");
    EXPECT_EQ(segment_from_name("Ä"), "");
}

TEST(Segment, LeadingDigitGetsF) {
    EXPECT_EQ(segment_from_name("1st"), "f1st");
    EXPECT_EQ(segment_from_name("2nd byte"), "f2nd_byte");
    EXPECT_EQ(segment_from_name("  3"), "f3");
    EXPECT_EQ(segment_from_name("数据1"), "f1");  // the digit leads once the rest is trimmed
    EXPECT_EQ(segment_from_name("a1"), "a1");
}

TEST(Segment, NothingLeft) {
    for (const char* name : {"", " ", "_", "()", "命令", "---"}) EXPECT_EQ(segment_from_name(name), "") << name;
}

TEST(Segment, ValidFilterSegments) {
    for (const char* ok : {"a", "ecat", "a_b", "a1", "x_", "abc_123"}) EXPECT_TRUE(is_valid_filter_segment(ok)) << ok;
    for (const char* bad : {"", "A", "Cmd", "1x", "_x", "a.b", "a-b", "a b", "é", "ab\xc3\xa9"})
        EXPECT_FALSE(is_valid_filter_segment(bad)) << bad;
}

// ---- filter names: full names -------------------------------------------------------

TEST(FilterNames, PrefixedByProtocolAndContainers) {
    Front f = front_end(rules("  <node name=\"Header\">\n"
                              "    <node name=\"Length\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"Sub Block\">\n"
                              "      <node name=\"Slave address (ADP)\" length=\"2byte\"/>\n"
                              "    </node>\n"
                              "  </node>\n"
                              "  <node name=\"Length\" length=\"1byte\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Protocol& p = *f.proto;
    EXPECT_EQ(p.nodes[0]->filter_name, "tst.header");  // containers are fields too
    EXPECT_EQ(p.nodes[0]->children[0]->filter_name, "tst.header.length");
    EXPECT_EQ(p.nodes[0]->children[1]->filter_name, "tst.header.sub_block");
    EXPECT_EQ(p.nodes[0]->children[1]->children[0]->filter_name, "tst.header.sub_block.slave_address_adp");
    EXPECT_EQ(p.nodes[1]->filter_name, "tst.length");
    EXPECT_EQ(p.nodes[1]->segment, "length");
}

TEST(FilterNames, FilterAttributeReplacesTheSegment) {
    Front f = front_end(rules("  <node name=\"Datagram\" filter=\"dg\">\n"
                              "    <node name=\"Command\" filter=\"cmd\" length=\"1byte\"/>\n"
                              "    <node name=\"命令\" filter=\"cmd2\" length=\"1byte\"/>\n"
                              "  </node>\n",
                              "filter=\"my_proto\" ethertype=\"1\""));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "Datagram")->filter_name, "my_proto.dg");
    EXPECT_EQ(find(*f.proto, "Command")->filter_name, "my_proto.dg.cmd");
    EXPECT_EQ(find(*f.proto, "命令")->filter_name, "my_proto.dg.cmd2");
    EXPECT_FALSE(contains(f.messages(), "warning"));  // no fallback needed
}

TEST(FilterNames, EmptyFilterLeavesContainerOut) {
    Front f = front_end(rules("  <node name=\"Datagrams\" filter=\"\">\n"
                              "    <node name=\"Datagram\">\n"
                              "      <node name=\"Address\" filter=\"\">\n"
                              "        <node name=\"ADP\" length=\"2byte\"/>\n"
                              "      </node>\n"
                              "    </node>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "Datagrams")->filter_name, "");
    EXPECT_EQ(find(*f.proto, "Datagrams")->segment, "");
    EXPECT_EQ(find(*f.proto, "Datagram")->filter_name, "tst.datagram");
    EXPECT_EQ(find(*f.proto, "Address")->filter_name, "");
    EXPECT_EQ(find(*f.proto, "ADP")->filter_name, "tst.datagram.adp");
}

TEST(FilterNames, FallbackIsFAndPositionAmongAllNodesWithWarning) {
    Front f = front_end("<root name=\"Test\" abbreviation=\"TST\" ethertype=\"1\">\n"
                        "  <node name=\"头\" length=\"2byte\">\n"              // 1
                        "    <node name=\"A\" length=\"1byte\"/>\n"            // 2
                        "    <node name=\"命令\" length=\"1byte\"/>\n"         // 3
                        "  </node>\n"
                        "  <hook table=\"udp.port\" value=\"1\"/>\n"
                        "  <node name=\"Datagram\" filter=\"\">\n"            // 4
                        "    <node name=\"--\" length=\"1byte\"/>\n"          // 5
                        "    <node name=\"数据\" filter=\"data\" length=\"1byte\"/>\n"  // 6
                        "    <node name=\"长度\" length=\"1byte\"/>\n"         // 7
                        "  </node>\n"
                        "</root>\n");
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "头")->filter_name, "tst.f1");
    EXPECT_EQ(find(*f.proto, "A")->filter_name, "tst.f1.a");
    EXPECT_EQ(find(*f.proto, "命令")->filter_name, "tst.f1.f3");
    EXPECT_EQ(find(*f.proto, "--")->filter_name, "tst.f5");
    EXPECT_EQ(find(*f.proto, "数据")->filter_name, "tst.data");
    EXPECT_EQ(find(*f.proto, "长度")->filter_name, "tst.f7");
    const std::string m = f.messages();
    EXPECT_TRUE(contains(m, "rules.xml:2: warning: name '头' gives no filter name; using 'f1': add filter=\"...\" for a readable one")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:4: warning: name '命令' gives no filter name; using 'f3'")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:8: warning: name '--' gives no filter name; using 'f5'")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:10: warning: name '长度' gives no filter name; using 'f7'")) << m;
    EXPECT_FALSE(contains(m, "数据")) << m;                  // has a filter: no warning
    EXPECT_FALSE(contains(m, "Datagram")) << m;              // filter="": no warning
}

TEST(FilterNames, DuplicatesAreErrorsOnTheSecondNode) {
    struct Case {
        const char* first;
        const char* second;
        const char* name;
    };
    const Case cases[] = {
        {"name=\"A b\"", "name=\"a-b\"", "tst.a_b"},
        {"name=\"A b\"", "name=\" a__B \"", "tst.a_b"},
        {"name=\"CRC\"", "name=\"crc\"", "tst.crc"},
        {"name=\"Length\" filter=\"len\"", "name=\"Len\"", "tst.len"},
        {"name=\"x\" filter=\"y\"", "name=\"z\" filter=\"y\"", "tst.y"},
        {"name=\"1st\"", "name=\"F1st\"", "tst.f1st"},
        {"name=\"命令\"", "name=\"F1\"", "tst.f1"},
    };
    for (const Case& c : cases) {
        Front f = front_end(rules("  <node " + std::string(c.first) + " length=\"1byte\"/>\n"
                                  "  <node " + std::string(c.second) + " length=\"1byte\"/>\n"));
        EXPECT_FALSE(f.ok()) << c.first << " / " << c.second;
        EXPECT_TRUE(contains(f.messages(), "rules.xml:3: error: duplicate filter name '" + std::string(c.name) +
                                               "' (also used by "))
            << f.messages();
    }
}

TEST(FilterNames, ContainerAndLeafCanCollide) {
    Front f = front_end(rules("  <node name=\"Header\"><node name=\"T\" length=\"1byte\"/></node>\n"
                              "  <node name=\"Wrap\" filter=\"\"><node name=\"header\" length=\"1byte\"/></node>\n"));
    EXPECT_FALSE(f.ok());
    EXPECT_TRUE(contains(f.messages(), "rules.xml:3: error: duplicate filter name 'tst.header' (also used by 'Header' (line 2))"))
        << f.messages();
}

TEST(FilterNames, SameNameInDifferentContainersIsFine) {
    Front f = front_end(rules("  <node name=\"Header\"><node name=\"Length\" length=\"1byte\"/></node>\n"
                              "  <node name=\"Body\"><node name=\"Length\" length=\"1byte\"/></node>\n"));
    EXPECT_TRUE(f.ok()) << f.messages();
}

TEST(FilterNames, BadFilterAttributes) {
    Front f = front_end(rules("  <node name=\"a\" filter=\"Cmd\" length=\"1byte\"/>\n"
                              "  <node name=\"b\" filter=\"1b\" length=\"1byte\"/>\n"
                              "  <node name=\"c\" filter=\"\" length=\"1byte\"/>\n"));
    const std::string m = f.messages();
    EXPECT_TRUE(contains(m, "rules.xml:2: error: bad filter 'Cmd': it must match [a-z][a-z0-9_]*")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:3: error: bad filter '1b'")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:4: error: filter=\"\" only applies to containers; leaf 'c' needs a filter name")) << m;
}

TEST(FilterNames, ProtocolFilterName) {
    Front bad = front_end("<root name=\"X\" abbreviation=\"EtherCAT-R\" ethertype=\"1\"/>\n");
    EXPECT_TRUE(contains(bad.messages(), "rules.xml:1: error: protocol filter name 'ethercat-r' (the abbreviation "
                                         "lowercased) is not valid"))
        << bad.messages();
    Front given = front_end("<root name=\"X\" abbreviation=\"X\" filter=\"Ecat\" ethertype=\"1\"/>\n");
    EXPECT_TRUE(contains(given.messages(), "rules.xml:1: error: protocol filter name 'Ecat' is not valid: it must match "
                                           "[a-z][a-z0-9_]*\n"))
        << given.messages();
}

// ---- bit groups --------------------------------------------------------------------

struct Bits {
    unsigned shift, bits, group_bytes;
    bool first, last;
};

void expect_layout(const Node* n, const Bits& b) {
    ASSERT_NE(n, nullptr);
    SCOPED_TRACE(n->name);
    EXPECT_TRUE(n->in_bit_group);
    EXPECT_EQ(n->shift, b.shift);
    EXPECT_EQ(n->bits, b.bits);
    EXPECT_EQ(n->group_bytes, b.group_bytes);
    EXPECT_EQ(n->group_first, b.first);
    EXPECT_EQ(n->group_last, b.last);
}

TEST(BitGroups, EtherCatLittleEndianWord) {
    Front f = front_end(read_file(source_path("rules/ethercat.xml")));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* datagram = find(*f.proto, "Datagram");
    ASSERT_NE(datagram, nullptr);
    auto child = [&](const std::string& name) -> const Node* {
        for (const auto& c : datagram->children)
            if (c->name == name) return c.get();
        return nullptr;
    };
    expect_layout(child("Length"), {0, 11, 2, true, false});
    expect_layout(child("Reserved"), {11, 3, 2, false, false});
    expect_layout(child("Circulating"), {14, 1, 2, false, false});
    expect_layout(child("More"), {15, 1, 2, false, true});
    EXPECT_FALSE(child("Command")->in_bit_group);
    EXPECT_FALSE(child("Interrupt")->in_bit_group);
    // the frame header: 11 / 1 / 4
    const Node* header = f.proto->nodes[0].get();
    expect_layout(header->children[0].get(), {0, 11, 2, true, false});
    expect_layout(header->children[1].get(), {11, 1, 2, false, false});
    expect_layout(header->children[2].get(), {12, 4, 2, false, true});
}

TEST(BitGroups, BigEndianFirstFieldTakesTheMostSignificantBits) {
    Front f = front_end(rules("  <node name=\"Version\" length=\"4bit\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"IHL\" length=\"4bit\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Flags\" length=\"3bit\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"Offset\" length=\"13bit\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Whole\" length=\"2byte\" displaytype=\"numberhex\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    expect_layout(find(*f.proto, "Version"), {4, 4, 1, true, false});
    expect_layout(find(*f.proto, "IHL"), {0, 4, 1, false, true});
    expect_layout(find(*f.proto, "Flags"), {13, 3, 2, true, false});
    expect_layout(find(*f.proto, "Offset"), {0, 13, 2, false, true});
    EXPECT_FALSE(find(*f.proto, "Whole")->in_bit_group);
}

TEST(BitGroups, ByteOrderIsInheritedAndOverridden) {
    Front f = front_end(rules("  <node name=\"LE\" byteorder=\"little\">\n"
                              "    <node name=\"a\" length=\"3bit\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"b\" length=\"5bit\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"BE\" byteorder=\"big\">\n"
                              "      <node name=\"c\" length=\"3bit\" displaytype=\"numberhex\"/>\n"
                              "      <node name=\"d\" length=\"5bit\" displaytype=\"numberhex\"/>\n"
                              "    </node>\n"
                              "  </node>\n",
                              "ethertype=\"1\" byteorder=\"big\""));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "LE")->byteorder, ByteOrder::Little);
    EXPECT_EQ(find(*f.proto, "a")->byteorder, ByteOrder::Little);
    EXPECT_EQ(find(*f.proto, "BE")->byteorder, ByteOrder::Big);
    EXPECT_EQ(find(*f.proto, "d")->byteorder, ByteOrder::Big);
    expect_layout(find(*f.proto, "a"), {0, 3, 1, true, false});
    expect_layout(find(*f.proto, "b"), {3, 5, 1, false, true});
    expect_layout(find(*f.proto, "c"), {5, 3, 1, true, false});
    expect_layout(find(*f.proto, "d"), {0, 5, 1, false, true});
}

TEST(BitGroups, AWordOfBitFieldsIsOneGroup) {
    // A 2-byte container of bit fields alone: its byte-sized groups join into one 16-bit
    // group, so each mask is on the word (IEC 104's sequence number beside its format bit).
    Front f = front_end(rules("  <node name=\"Big\" length=\"2byte\">\n"
                              "    <node name=\"f\" length=\"1bit\" displaytype=\"bool\"/>\n"
                              "    <node name=\"g\" length=\"7bit\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"h\" length=\"3bit\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"i\" length=\"5bit\" displaytype=\"numberhex\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Little\" length=\"3byte\" byteorder=\"little\">\n"
                              "    <node name=\"format\" length=\"1bit\" displaytype=\"bool\"/>\n"
                              "    <node name=\"low\" length=\"7bit\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"mid\" length=\"4bit\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"high\" length=\"12bit\" displaytype=\"numberdec\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Mixed\" length=\"2byte\">\n"
                              "    <node name=\"x\" length=\"8bit\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"y\" length=\"1bit\" displaytype=\"bool\"/>\n"
                              "    <node name=\"z\" length=\"7bit\" displaytype=\"numberhex\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Bytes\" length=\"2byte\">\n"
                              "    <node name=\"raw\" length=\"1byte\"/>\n"
                              "    <node name=\"p\" length=\"1bit\" displaytype=\"bool\"/>\n"
                              "    <node name=\"q\" length=\"7bit\" displaytype=\"numberhex\"/>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    expect_layout(find(*f.proto, "f"), {15, 1, 2, true, false});
    expect_layout(find(*f.proto, "g"), {8, 7, 2, false, false});
    expect_layout(find(*f.proto, "h"), {5, 3, 2, false, false});
    expect_layout(find(*f.proto, "i"), {0, 5, 2, false, true});
    expect_layout(find(*f.proto, "format"), {0, 1, 3, true, false});
    expect_layout(find(*f.proto, "low"), {1, 7, 3, false, false});
    expect_layout(find(*f.proto, "mid"), {8, 4, 3, false, false});
    expect_layout(find(*f.proto, "high"), {12, 12, 3, false, true});
    // a whole-byte number joins the word (a spare octet beside flags)
    expect_layout(find(*f.proto, "x"), {8, 8, 2, true, false});
    expect_layout(find(*f.proto, "y"), {7, 1, 2, false, false});
    expect_layout(find(*f.proto, "z"), {0, 7, 2, false, true});
    // raw bytes (no displaytype: origin) are no number: no word
    EXPECT_FALSE(find(*f.proto, "raw")->in_bit_group);
    expect_layout(find(*f.proto, "p"), {7, 1, 1, true, false});
    expect_layout(find(*f.proto, "q"), {0, 7, 1, false, true});
}

TEST(BitGroups, WideGroupsAndWholeByteMembers) {
    Front f = front_end(rules("  <node name=\"a\" length=\"20bit\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"b\" length=\"4bit\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"top\" length=\"1bit\" displaytype=\"bool\"/>\n"
                              "  <node name=\"low\" length=\"63bit\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"lo\" length=\"4bit\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"mid\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"hi\" length=\"4bit\" displaytype=\"numberhex\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    expect_layout(find(*f.proto, "a"), {4, 20, 3, true, false});
    expect_layout(find(*f.proto, "b"), {0, 4, 3, false, true});
    expect_layout(find(*f.proto, "top"), {63, 1, 8, true, false});
    expect_layout(find(*f.proto, "low"), {0, 63, 8, false, true});
    // a whole-byte leaf that does not start on a byte boundary joins the group
    expect_layout(find(*f.proto, "lo"), {12, 4, 2, true, false});
    expect_layout(find(*f.proto, "mid"), {4, 8, 2, false, false});
    expect_layout(find(*f.proto, "hi"), {0, 4, 2, false, true});
}

TEST(BitGroups, GroupsNeverCrossContainers) {
    Front f = front_end(rules("  <node name=\"A\">\n"
                              "    <node name=\"x\" length=\"4bit\" displaytype=\"numberhex\"/>\n"
                              "  </node>\n"
                              "  <node name=\"B\">\n"
                              "    <node name=\"y\" length=\"4bit\" displaytype=\"numberhex\"/>\n"
                              "  </node>\n"));
    const std::string m = f.messages();
    EXPECT_TRUE(contains(m, "rules.xml:3: error: bit group starting at 'x' ends after 4 bits, not on a byte boundary\n")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:6: error: bit group starting at 'y' ends after 4 bits")) << m;
}

TEST(BitGroups, Errors) {
    struct Case {
        const char* body;
        const char* message;
    };
    const Case cases[] = {
        {"<node name=\"a\" length=\"4bit\" displaytype=\"numberhex\"/><node name=\"C\"><node name=\"c\" length=\"1byte\"/></node>",
         "bit group starting at 'a' ends after 4 bits, not on a byte boundary (next is 'C' (line 2))"},
        {"<node name=\"a\" length=\"60bit\" displaytype=\"numberhex\"/><node name=\"b\" length=\"12bit\" displaytype=\"numberhex\"/>",
         "bit group starting at 'a' is 72 bits; a bit group spans 1 to 8 bytes"},
        {"<node name=\"a\" length=\"4bit\" displaytype=\"origin\"/><node name=\"b\" length=\"4bit\" displaytype=\"numberhex\"/>",
         "origin display needs whole bytes; bit field 'a' is part of a bit group"},
        {"<node name=\"a\" length=\"4bit\" displaytype=\"numberhex\" byteorder=\"little\"/><node name=\"b\" length=\"4bit\" displaytype=\"numberhex\"/>",
         "bit field 'b' has another byte order than its bit group starting at 'a'"},
        {"<node name=\"a\" length=\"4bit\" displaytype=\"numberhex\"/><node name=\"b\" length=\"4bit\" displaytype=\"bool\" repeat=\".\"/>",
         "bit field 'b' cannot have 'repeat'"},
    };
    for (const Case& c : cases) {
        Front f = front_end(rules("  " + std::string(c.body) + "\n"));
        EXPECT_FALSE(f.ok()) << c.body;
        EXPECT_TRUE(contains(f.messages(), std::string("rules.xml:2: error: ") + c.message)) << f.messages();
    }
}

// ---- displays, numbers, enums ---------------------------------------------------------

TEST(Displays, DefaultsForLeavesAndContainers) {
    Front f = front_end(rules("  <node name=\"leaf\" length=\"2byte\"/>\n"
                              "  <node name=\"box\"><node name=\"x\" length=\"1byte\"/></node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "leaf")->display, Display::Origin);
    EXPECT_EQ(find(*f.proto, "box")->display, Display::NonDisplay);
    EXPECT_FALSE(find(*f.proto, "leaf")->is_numeric());
}

TEST(Displays, NumericLeaves) {
    Front f = front_end(rules("  <node name=\"hex\" length=\"8byte\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"hidden\" length=\"1byte\" displaytype=\"nondisplay\"/>\n"
                              "  <node name=\"wide hidden\" length=\"9byte\" displaytype=\"nondisplay\"/>\n"
                              "  <node name=\"bytes\" length=\"2byte\" displaytype=\"origin\"/>\n"
                              "  <node name=\"mac\" length=\"6byte\" displaytype=\"address\"/>\n"
                              "  <node name=\"box\" length=\"1byte\"><node name=\"x\" length=\"1byte\" displaytype=\"numberdec\"/></node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_TRUE(find(*f.proto, "hex")->is_numeric());
    EXPECT_EQ(find(*f.proto, "hex")->bits, 64u);
    EXPECT_TRUE(find(*f.proto, "hidden")->is_numeric());
    EXPECT_FALSE(find(*f.proto, "wide hidden")->is_numeric());
    EXPECT_FALSE(find(*f.proto, "bytes")->is_numeric());
    EXPECT_FALSE(find(*f.proto, "mac")->is_numeric());
    EXPECT_FALSE(find(*f.proto, "box")->is_numeric());
    EXPECT_TRUE(find(*f.proto, "x")->is_numeric());
}

TEST(Displays, NumericDisplayErrors) {
    for (const char* display : {"numberhex", "numberdec", "bool", "enum"}) {
        Front f = front_end(rules("  <node name=\"n\" length=\"9byte\" displaytype=\"" + std::string(display) + "\"/>\n"
                                  "  <node name=\"v\" length=\"rest\" displaytype=\"" + std::string(display) + "\"/>\n"));
        const std::string m = f.messages();
        EXPECT_TRUE(contains(m, "rules.xml:2: error: " + std::string(display) + " display on more than 64 bits: 'n' is 72 bits")) << m;
        EXPECT_TRUE(contains(m, "rules.xml:3: error: " + std::string(display) + " display needs a fixed length of 1-64 bits or a length from a field; 'v' has a variable length")) << m;
    }
}

TEST(Displays, EnumValuesMustFit) {
    Front f = front_end(rules("  <node name=\"one\" length=\"1bit\" displaytype=\"enum\"><enum value=\"1\" name=\"ok\"/>"
                              "<enum value=\"2\" name=\"no\"/></node>\n"
                              "  <node name=\"seven\" length=\"7bit\" displaytype=\"enum\"><enum value=\"0x7f\" name=\"ok\"/></node>\n"
                              "  <node name=\"byte\" length=\"1byte\" displaytype=\"enum\">\n"
                              "    <enum value=\"0xff\" name=\"ok\"/>\n"
                              "    <enum value=\"256\" name=\"no\"/>\n"
                              "  </node>\n"
                              "  <node name=\"wide\" length=\"8byte\" displaytype=\"enum\"><enum value=\"0xffffffffffffffff\" name=\"ok\"/></node>\n"));
    const std::string m = f.messages();
    EXPECT_TRUE(contains(m, "rules.xml:2: error: enum value 2 does not fit the 1-bit field 'one'")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:6: error: enum value 256 does not fit the 8-bit field 'byte'")) << m;
    EXPECT_EQ(std::count(m.begin(), m.end(), '\n'), 2) << m;
}

TEST(Conditions, InValuesMustFitTheFieldTheyTest) {
    // in="0-7" on 3 bits and in="0xff" on a byte fit; one value more does not.
    Front f = front_end(rules("  <node name=\"k\" length=\"3bit\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"f\" length=\"5bit\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"b\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"a\" length=\"1byte\" if=\"../node[@name='k']\" in=\"0-7\"/>\n"
                              "  <node name=\"c\" length=\"1byte\" if=\"../node[@name='b']\" in=\"0xff\"/>\n"
                              "  <node name=\"d\" length=\"1byte\" if=\"../node[@name='k']\" in=\"1,8\"/>\n"
                              "  <node name=\"e\" length=\"1byte\"><when field=\"../node[@name='b']\" in=\"0x100\"/></node>\n"));
    const std::string m = f.messages();
    EXPECT_TRUE(f.ok()) << m;
    EXPECT_TRUE(contains(m, "rules.xml:7: warning: 'in' value 8 does not fit the 3-bit field 'k' (line 2): it never matches")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:8: warning: 'in' value 0x100 does not fit the 8-bit field 'b' (line 4): it never matches")) << m;
    EXPECT_EQ(std::count(m.begin(), m.end(), '\n'), 2) << m;
}

TEST(Conditions, RequestAndCycleTestValuesMustFitTheirFields) {
    // <request>, <only> and <never> test a field's value as 'in' does: a value it cannot hold never matches.
    Front f = front_end("<root name=\"T\" abbreviation=\"T\" ethertype=\"0x88b5\">\n"
                        "  <pairing><key field=\"node[@name='Ref']\"/>\n"
                        "    <request field=\"node[@name='Kind']\" in=\"0x100-0x1ff\"/></pairing>\n"
                        "  <cycles><signature field=\"node[@name='Ref']\"/>\n"
                        "    <only field=\"node[@name='Class']\" in=\"1-3\"/>\n"
                        "    <never field=\"node[@name='Flag']\" in=\"2\"/></cycles>\n"
                        "  <node name=\"Ref\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                        "  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                        "  <node name=\"Class\" length=\"7bit\" displaytype=\"numberdec\"/>\n"
                        "  <node name=\"Flag\" length=\"1bit\" displaytype=\"numberdec\"/>\n</root>\n");
    const std::string m = f.messages();
    EXPECT_TRUE(f.ok()) << m;
    EXPECT_TRUE(contains(m, "rules.xml:3: warning: 'in' value 0x100-0x1ff does not fit the 8-bit field 'Kind' (line 8): "
                            "it never matches")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:6: warning: 'in' value 2 does not fit the 1-bit field 'Flag' (line 10): "
                            "it never matches")) << m;
    EXPECT_EQ(std::count(m.begin(), m.end(), '\n'), 2) << m;
}

TEST(Conditions, InValuesOnAComputedValueFitItsSixtyFourBits) {
    // A computed value takes no bytes but is a 64-bit integer: any 'in' value may match it.
    Front f = front_end(rules("  <node name=\"b\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"v\" value=\"{b} * 3\"/>\n"
                              "  <node name=\"w\" value=\"{b} == 1\" displaytype=\"nondisplay\"\n"
                              "        if=\"../node[@name='b']\" in=\"1-9\"/>\n"
                              "  <node name=\"x\" length=\"1byte\" if=\"../node[@name='v']\" in=\"3,300-765\"/>\n"
                              "  <node name=\"y\" length=\"1byte\"><when field=\"../node[@name='w']\" in=\"1\"/></node>\n"));
    const std::string m = f.messages();
    EXPECT_TRUE(f.ok()) << m;
    EXPECT_EQ(m, "") << m;
}

TEST(Displays, Warnings) {
    Front f = front_end(rules("  <node name=\"box\" displaytype=\"numberhex\"><node name=\"x\" length=\"1byte\"/></node>\n"
                              "  <node name=\"plain\" length=\"1byte\" displaytype=\"numberhex\"><enum value=\"1\" name=\"one\"/></node>\n"
                              "  <node name=\"twice\" length=\"1byte\" displaytype=\"enum\">\n"
                              "    <enum value=\"1\" name=\"one\"/>\n"
                              "    <enum value=\"0x01\" name=\"uno\"/>\n"
                              "  </node>\n"
                              "  <node name=\"empty\"/>\n"
                              "  <node name=\"sum\" length=\"1byte\" summary=\"{x}\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::string m = f.messages();
    EXPECT_TRUE(contains(m, "rules.xml:2: warning: displaytype 'numberhex' has no effect on container 'box'")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:3: warning: enum items of 'plain' are ignored: its displaytype is not 'enum'")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:6: warning: enum value 1 of 'twice' is listed twice; the first item is used")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:8: warning: leaf 'empty' has no length and no children: it takes no bytes")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:9: warning: summary on leaf 'sum' is ignored")) << m;
}

// ---- fixed-length containers ---------------------------------------------------------

TEST(FixedContainers, ChildrenMustFill) {
    Front ok = front_end(rules("  <node name=\"H\" length=\"3byte\">\n"
                               "    <node name=\"a\" length=\"12bit\" displaytype=\"numberhex\"/>\n"
                               "    <node name=\"b\" length=\"4bit\" displaytype=\"numberhex\"/>\n"
                               "    <node name=\"c\"><node name=\"d\" length=\"1byte\"/></node>\n"
                               "  </node>\n"
                               "  <node name=\"V\" length=\"2byte\">\n"  // variable children: checked at run time
                               "    <node name=\"n\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                               "    <node name=\"e\" length=\"../node[@name='n']\"/>\n"
                               "  </node>\n"));
    EXPECT_TRUE(ok.ok()) << ok.messages();
    Front bad = front_end(rules("  <node name=\"H\" length=\"4byte\">\n"
                                "    <node name=\"a\" length=\"12bit\" displaytype=\"numberhex\"/>\n"
                                "    <node name=\"b\" length=\"4bit\" displaytype=\"numberhex\"/>\n"
                                "    <node name=\"c\"><node name=\"d\" length=\"1byte\"/></node>\n"
                                "  </node>\n"));
    EXPECT_TRUE(contains(bad.messages(), "rules.xml:2: error: children of 'H' add up to 3 bytes, but its length is 4 bytes"))
        << bad.messages();
}

// ---- references --------------------------------------------------------------------

TEST(References, EarlierFieldInTheSameInstanceOrOutsideRepeats) {
    Front f = front_end(rules("  <node name=\"N\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Item\" count=\"../node[@name='N']\">\n"
                              "    <node name=\"L\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"Inner\" repeat=\"node[@name='M']\">\n"
                              "      <node name=\"D1\" length=\"../../node[@name='L']\"/>\n"
                              "      <node name=\"D2\" length=\"//node[@name='N']\"/>\n"
                              "      <node name=\"M\" length=\"1byte\" displaytype=\"bool\"/>\n"
                              "    </node>\n"
                              "  </node>\n"));
    EXPECT_TRUE(f.ok()) << f.messages();
}

TEST(References, Errors) {
    struct Case {
        const char* body;
        int line;
        const char* message;
    };
    const Case cases[] = {
        {"<node name=\"L\" length=\"2byte\" displaytype=\"origin\"/>\n  <node name=\"D\" length=\"../node[@name='L']\"/>", 3,
         "length field 'L' (line 2) is not numeric: it must be a leaf of 1-64 bits"},
        {"<node name=\"D\" length=\"../node[@name='L']\"/>\n  <node name=\"L\" length=\"1byte\" displaytype=\"numberdec\"/>", 2,
         "length field 'L' (line 3) is not decoded before 'D'; it must come earlier in the file"},
        {"<node name=\"R\" count=\"node[@name='L']\"><node name=\"L\" length=\"1byte\" displaytype=\"numberdec\"/></node>", 2,
         "count field 'L' (line 2) is not decoded before 'R'"},
        {"<node name=\"R\" repeat=\"node[@name='M']\"><node name=\"M\" length=\"1byte\" displaytype=\"bool\"/></node>\n"
         "  <node name=\"D\" length=\"../node[@name='R']/node[@name='M']\"/>", 3,
         "length field 'M' (line 2) is inside repeated node 'R' (line 2), which does not contain 'D'"},
        {"<node name=\"M\" length=\"1byte\" displaytype=\"bool\"/>\n  <node name=\"R\" repeat=\"../node[@name='M']\"><node name=\"x\" length=\"1byte\"/></node>", 3,
         "repeat flag 'M' (line 2) is outside the repeated node 'R'; it must be one of its fields"},
        {"<node name=\"R\" repeat=\"node[@name='M']\"><node name=\"M\" length=\"1byte\"/></node>", 2,
         "repeat field 'M' (line 2) is not numeric"},
        {"<node name=\"T\" length=\"1byte\" displaytype=\"address\"/>\n  <node name=\"B\" length=\"1byte\" if=\"../node[@name='T']\" in=\"1\"/>", 3,
         "if field 'T' (line 2) is not numeric"},
        {"<node name=\"B\" length=\"1byte\" if=\"../node[@name='T']\" in=\"1\"/>\n  <node name=\"T\" length=\"1byte\" displaytype=\"numberdec\"/>", 2,
         "if field 'T' (line 3) is not decoded before 'B'"},
        {"<node name=\"N\" length=\"1byte\" displaytype=\"numberdec\"/>\n  <node name=\"R\" count=\"../node[@name='N']\" repeat=\"node[@name='M']\">"
         "<node name=\"M\" length=\"1byte\" displaytype=\"bool\"/></node>", 3,
         "node 'R' has both 'repeat' and 'count'; use one of them"},
    };
    for (const Case& c : cases) {
        Front f = front_end(rules("  " + std::string(c.body) + "\n"));
        EXPECT_FALSE(f.ok()) << c.body;
        EXPECT_TRUE(contains(f.messages(), "rules.xml:" + std::to_string(c.line) + ": error: " + c.message))
            << c.body << "\n" << f.messages();
    }
}

// ---- slots, pdulength, summaries ----------------------------------------------------

TEST(Slots, OnlyReferencedFieldsInDocumentOrder) {
    Front f = front_end(read_file(source_path("rules/ethercat.xml")));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Protocol& p = *f.proto;
    const Node* header = p.nodes[0].get();
    const Node* datagram = find(p, "Datagram");
    EXPECT_EQ(header->children[0]->slot, 0);  // Header/Length: Datagrams' and Payload's length
    EXPECT_EQ(header->children[1]->slot, -1);
    EXPECT_EQ(header->children[2]->slot, 1);  // Header/Type: if
    std::map<std::string, int> slots;
    for (const auto& c : datagram->children) slots[c->name] = c->slot;
    EXPECT_EQ(slots["Command"], 2);  // if, <when> and summary
    EXPECT_EQ(slots["Index"], -1);
    EXPECT_EQ(slots["Address"], 3);  // a container in the summary: whether it was decoded
    EXPECT_EQ(find(p, "Slave address (ADP)")->slot, 4);   // the address's summary
    EXPECT_EQ(find(p, "Offset address (ADO)")->slot, 5);  // <when>, the register window's base, summary
    EXPECT_EQ(slots["Logical address"], 6);  // summary
    EXPECT_EQ(slots["Length"], 7);   // the data's lengths, <when> and summary
    EXPECT_EQ(slots["More"], 8);     // repeat flag
    EXPECT_EQ(slots["Working counter"], -1);  // read ahead by <when peek>, not from a slot
}

TEST(Pdulength, FixedOffsetGivesBytesToRead) {
    Front f = front_end(rules("  <hook table=\"tcp.port\" value=\"1\"/>\n"
                              "  <node name=\"Cmd\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"H\" length=\"4byte\">\n"
                              "    <node name=\"x\" length=\"2byte\"/>\n"
                              "    <node name=\"Length\" length=\"12bit\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"y\" length=\"4bit\" displaytype=\"numberdec\"/>\n"
                              "  </node>\n",
                              "pdulength=\"node[@name='H']/node[@name='Length']\" pdulengthadd=\"-4\""));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(f.proto->pdu_fixed_len, 6u);  // 2 + 2 + the 2-byte group holding Length
    EXPECT_EQ(f.proto->pdulengthadd, -4);
    EXPECT_GE(find(*f.proto, "Length")->slot, 0);
}

TEST(Pdulength, Errors) {
    Front var = front_end(rules("  <hook table=\"tcp.port\" value=\"1\"/>\n"
                                "  <node name=\"Rest\" length=\"rest\"/>\n"
                                "  <node name=\"Length\" length=\"2byte\" displaytype=\"numberdec\"/>\n",
                                "pdulength=\"node[@name='Length']\""));
    EXPECT_TRUE(contains(var.messages(), "rules.xml:1: error: pdulength field 'Length' must be at a fixed offset"))
        << var.messages();
    Front cond = front_end(rules("  <hook table=\"tcp.port\" value=\"1\"/>\n"
                                 "  <node name=\"T\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                                 "  <node name=\"Length\" length=\"2byte\" displaytype=\"numberdec\" if=\"../node[@name='T']\" in=\"1\"/>\n",
                                 "pdulength=\"node[@name='Length']\""));
    EXPECT_TRUE(contains(cond.messages(), "rules.xml:1: error: pdulength field 'Length' must be at a fixed offset"))
        << cond.messages();
    Front text = front_end(rules("  <hook table=\"tcp.port\" value=\"1\"/>\n"
                                 "  <node name=\"Length\" length=\"2byte\"/>\n",
                                 "pdulength=\"node[@name='Length']\""));
    EXPECT_TRUE(contains(text.messages(), "rules.xml:1: error: pdulength field 'Length' (line 3) is not numeric"))
        << text.messages();
}

TEST(Summary, PiecesAndSlots) {
    Front f = front_end(rules("  <node name=\"DG\" summary=\"{命令} len {长度}!\">\n"
                              "    <node name=\"命令\" filter=\"cmd\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"Inner\"><node name=\"长度\" filter=\"len\" length=\"1byte\" displaytype=\"numberdec\"/></node>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* dg = find(*f.proto, "DG");
    ASSERT_EQ(dg->summary_pieces.size(), 4u);
    EXPECT_EQ(dg->summary_pieces[0].leaf, find(*f.proto, "命令"));
    EXPECT_EQ(dg->summary_pieces[1].text, " len ");
    EXPECT_EQ(dg->summary_pieces[1].leaf, nullptr);
    EXPECT_EQ(dg->summary_pieces[2].leaf, find(*f.proto, "长度"));
    EXPECT_EQ(dg->summary_pieces[3].text, "!");
    EXPECT_EQ(find(*f.proto, "命令")->slot, 0);
    EXPECT_EQ(find(*f.proto, "长度")->slot, 1);
}

// {?...} owns the pieces up to its closing '}' (nested parts inside); {X}
// names the first node X that is a leaf or has a summary, in document order.
TEST(Summary, OptionalPartsAndContainerSummaries) {
    Front f = front_end(rules("  <node name=\"M\" summary=\"{Kind}{? at {Where}{? ({Code})}}!\">\n"
                              "    <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"Plain\"><node name=\"Where\" length=\"1byte\"/></node>\n"
                              "    <node name=\"Where\" summary=\"{Code}\">\n"
                              "      <node name=\"Code\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    </node>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* m = find(*f.proto, "M");
    const auto& p = m->summary_pieces;
    ASSERT_EQ(p.size(), 9u);
    EXPECT_EQ(p[0].leaf, find(*f.proto, "Kind"));
    EXPECT_EQ(p[1].group, 6u);  // " at ", {Where}, {? ({Code})} (4 pieces)
    EXPECT_EQ(p[2].text, " at ");
    // the leaf 'Where' inside 'Plain' comes first in document order
    const Node* plain = find(*f.proto, "Plain");
    EXPECT_EQ(p[3].leaf, plain->children[0].get());
    EXPECT_EQ(p[4].group, 3u);
    EXPECT_EQ(p[5].text, " (");
    EXPECT_EQ(p[6].leaf, find(*f.proto, "Code"));
    EXPECT_EQ(p[7].text, ")");
    EXPECT_EQ(p[8].text, "!");
    EXPECT_EQ(p[8].group, 0u);
}

TEST(Summary, ContainerWithSummaryAndQuestionMarkNames) {
    Front f = front_end(rules("  <node name=\"M\" summary=\"{T} {?x}\">\n"
                              "    <node name=\"?x\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"T\" summary=\"{A}\"><node name=\"A\" length=\"1byte\"/></node>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* m = find(*f.proto, "M");
    ASSERT_EQ(m->summary_pieces.size(), 3u);
    EXPECT_EQ(m->summary_pieces[0].leaf, find(*f.proto, "T"));  // a container: its summary
    EXPECT_GE(find(*f.proto, "T")->slot, 0);                      // its slot says it was decoded
    EXPECT_EQ(m->summary_pieces[2].leaf, find(*f.proto, "?x"));  // no '{' inside: a name
    EXPECT_EQ(m->summary_pieces[2].group, 0u);
}

TEST(Summary, Errors) {
    Front missing = front_end(rules("  <node name=\"DG\" summary=\"{Cmd}\"><node name=\"Command\" length=\"1byte\"/></node>\n"));
    EXPECT_TRUE(contains(missing.messages(), "rules.xml:2: error: summary of 'DG' refers to {Cmd}, but no leaf named 'Cmd' is inside it"))
        << missing.messages();
    Front container = front_end(rules("  <node name=\"DG\" summary=\"{In}\"><node name=\"In\"><node name=\"x\" length=\"1byte\"/></node></node>\n"));
    EXPECT_TRUE(contains(container.messages(), "rules.xml:2: error: summary of 'DG' refers to {In}, a container without "
                                               "a summary: give 'In' a summary or name a leaf"))
        << container.messages();
    Front open = front_end(rules("  <node name=\"DG\" summary=\"{x\"><node name=\"x\" length=\"1byte\"/></node>\n"));
    EXPECT_TRUE(contains(open.messages(), "rules.xml:2: error: summary of 'DG' has '{' without '}'")) << open.messages();
}

// ---- root ------------------------------------------------------------------------

TEST(Root, NeedsEthertypeOrHook) {
    Front none = front_end("<root name=\"X\" abbreviation=\"X\">\n  <node name=\"a\" length=\"1byte\"/>\n</root>\n");
    EXPECT_TRUE(contains(none.messages(), "rules.xml:1: error: <root> needs an 'ethertype' or at least one <hook>"))
        << none.messages();
    Front hook = front_end("<root name=\"X\" abbreviation=\"X\">\n  <hook table=\"udp.port\" value=\"1\"/>\n"
                           "  <node name=\"a\" length=\"1byte\"/>\n</root>\n");
    EXPECT_TRUE(hook.ok()) << hook.messages();
    Front empty = front_end("<root name=\"X\" abbreviation=\"X\" ethertype=\"1\"/>\n");
    EXPECT_TRUE(empty.ok());
    EXPECT_TRUE(contains(empty.messages(), "rules.xml:1: warning: <root> has no <node>")) << empty.messages();
}

TEST(Root, AValueHookedTwiceIsAWarning) {
    Front f = front_end("<root name=\"X\" abbreviation=\"X\" ethertype=\"0x88b5\">\n"
                        "  <hook table=\"ethertype\" value=\"0x88b5\"/>\n"
                        "  <hook table=\"udp.port\" value=\"9600\"/>\n  <hook table=\"udp.port\" value=\"9600\"/>\n"
                        "  <hook table=\"tcp.port\" value=\"9600\"/>\n  <node name=\"a\" length=\"1byte\"/>\n</root>\n");
    EXPECT_TRUE(f.ok()) << f.messages();
    EXPECT_TRUE(contains(f.messages(), "rules.xml:2: warning: <hook table=\"ethertype\" value=\"34997\"> repeats line 1"))
        << f.messages();
    EXPECT_TRUE(contains(f.messages(), "rules.xml:4: warning: <hook table=\"udp.port\" value=\"9600\"> repeats line 3"))
        << f.messages();
    EXPECT_FALSE(contains(f.messages(), "rules.xml:5:")) << "another table is another hook: " << f.messages();
}

TEST(Root, HookTable) {
    Front f = front_end("<root name=\"X\" abbreviation=\"X\">\n  <hook table=\"UDP port\" value=\"1\"/>\n</root>\n");
    EXPECT_TRUE(contains(f.messages(), "rules.xml:2: error: bad hook table 'UDP port'")) << f.messages();
}

}  // namespace
}  // namespace dissgen::testing

namespace dissgen::testing {
namespace {

TEST(Validator, BitFieldWithoutDisplaytypeIsShownInHex) {
    Front f = front_end(read_file(source_path("tests/rules_ok/bitfield_default_display.xml")));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node& flags = *f.proto->nodes[0]->children[1];
    EXPECT_EQ(flags.display, Display::NumberHex);
    EXPECT_TRUE(flags.in_bit_group);
    EXPECT_EQ(flags.shift, 0u);  // big-endian: the second nibble is the low one
}

TEST(RestLeaves, WarnWhenNothingIsLeftForWhatFollowsAContainerWithoutLength) {
    // Blob takes the rest of the message, so Trailer never has bytes.
    Front f = front_end(rules("  <node name=\"Wrap\">\n"
                              "    <node name=\"Mask\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"Blob\" length=\"rest\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Trailer\" length=\"2byte\" displaytype=\"numberhex\"/>\n"));
    const std::string m = f.messages();
    EXPECT_TRUE(f.ok()) << m;
    EXPECT_TRUE(contains(m, "rules.xml:4: warning: leaf 'Blob' takes the rest of the message (no container around "
                            "it has a length), so 'Trailer' (line 6) finds no bytes after it")) << m;
    // A length on the container, room left with rest - N, or an alternative after it: no warning.
    for (const std::string& body :
         {std::string("  <node name=\"Wrap\" length=\"3byte\">\n"
                      "    <node name=\"Mask\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                      "    <node name=\"Blob\" length=\"rest\"/>\n"
                      "  </node>\n"
                      "  <node name=\"Trailer\" length=\"2byte\" displaytype=\"numberhex\"/>\n"),
          std::string("  <node name=\"Wrap\">\n"
                      "    <node name=\"Mask\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                      "    <node name=\"Blob\" length=\"rest - 2\"/>\n"
                      "  </node>\n"
                      "  <node name=\"Trailer\" length=\"2byte\" displaytype=\"numberhex\"/>\n"),
          std::string("  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                      "  <node name=\"Wrap\" if=\"../node[@name='Kind']\" in=\"1\">\n"
                      "    <node name=\"Blob\" length=\"rest\"/>\n"
                      "  </node>\n"
                      "  <node name=\"Other\" length=\"2byte\" otherwise=\"true\"/>\n")}) {
        Front g = front_end(rules(body));
        EXPECT_TRUE(g.ok()) << g.messages();
        EXPECT_FALSE(contains(g.messages(), "takes the rest")) << body << g.messages();
    }
}

TEST(RestLeaves, AGroupNestedDeeperThanItsDepthSaysToRaiseIt) {
    Front f = front_end(rules("  <group name=\"Diag\" depth=\"1\">\n"
                              "    <node name=\"Mask\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                              "    <node name=\"Inner\" if=\"../node[@name='Mask']\" in=\"1\"><use group=\"Diag\"/></node>\n"
                              "  </group>\n"
                              "  <node name=\"Diagnostics\"><use group=\"Diag\"/></node>\n"
                              "  <node name=\"Trailer\" length=\"2byte\" displaytype=\"numberhex\"/>\n",
                              "ethertype=\"0x88b5\""));
    const std::string m = f.messages();
    EXPECT_TRUE(contains(m, "warning: leaf 'Diag (nested deeper than 1 levels)' takes the rest of the message")) << m;
    EXPECT_TRUE(contains(m, "'Trailer' (line 7) finds no bytes after it: raise the group's depth")) << m;
}


TEST(Chains, WarnWhenADefaultAlsoDecodesBesideTheSiblingBeforeItsChain) {
    const std::string head = "  <node name=\"Tag\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                             "  <node name=\"Q\" length=\"1byte\" displaytype=\"numberdec\" if=\"../node[@name='Tag']\" in=\"2\"/>\n"
                             "  <node name=\"R\" length=\"1byte\" displaytype=\"numberdec\" if=\"../node[@name='Tag']\" in=\"3\"/>\n";
    // S is R's default, decoded after Q too; T, a second default, is never decoded: no claim on it.
    Front f = front_end(rules(head + "  <node name=\"S\" length=\"1byte\" otherwise=\"true\"/>\n"
                                     "  <node name=\"T\" length=\"1byte\" otherwise=\"true\"/>\n"));
    const std::string m = f.messages();
    EXPECT_TRUE(f.ok()) << m;
    EXPECT_TRUE(contains(m, "rules.xml:5: warning: otherwise=\"true\" on 'S' is the default of the chain that 'R' "
                            "(line 4) opens, so it is decoded also when 'Q' (line 3) is")) << m;
    EXPECT_FALSE(contains(m, "on 'T'")) << m;
    // One chain (otherwise on R), or no default (S an "else if" with conditions of its own): no warning.
    const std::string q = "  <node name=\"Tag\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                          "  <node name=\"Q\" length=\"1byte\" if=\"../node[@name='Tag']\" in=\"2\"/>\n";
    for (const std::string& tail :
         {std::string("  <node name=\"R\" length=\"1byte\" otherwise=\"true\" if=\"../node[@name='Tag']\" in=\"3\"/>\n"
                      "  <node name=\"S\" length=\"1byte\" otherwise=\"true\"/>\n"),
          std::string("  <node name=\"R\" length=\"1byte\" if=\"../node[@name='Tag']\" in=\"3\"/>\n"
                      "  <node name=\"S\" length=\"1byte\" otherwise=\"true\" if=\"../node[@name='Tag']\" in=\"5\"/>\n")}) {
        Front g = front_end(rules(q + tail));
        EXPECT_TRUE(g.ok()) << g.messages();
        EXPECT_FALSE(contains(g.messages(), "is the default of the chain")) << tail << g.messages();
    }
    // A bit field's otherwise after no bit alternative is an error, and only that.
    Front b = front_end(rules("  <node name=\"K\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"A\" length=\"4bit\" displaytype=\"numberhex\" if=\"../node[@name='K']\" in=\"0\"/>\n"
                              "  <node name=\"B\" length=\"4bit\" displaytype=\"numberhex\" if=\"../node[@name='K']\" in=\"1\"/>\n"
                              "  <node name=\"C\" length=\"4bit\" displaytype=\"numberhex\" otherwise=\"true\"/>\n"));
    EXPECT_FALSE(contains(b.messages(), "is the default of the chain")) << b.messages();
}

}  // namespace
}  // namespace dissgen::testing

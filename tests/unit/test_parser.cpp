// SPDX-License-Identifier: GPL-2.0-or-later
// Stage 1 (generator/parser.cpp): numbers, length forms, 'in' lists,
// arithmetic tails, XPath resolution relative to the node, line numbers.
#include <gtest/gtest.h>

#include <chrono>

#include "test_support.h"

namespace dissgen::testing {
namespace {

// A rule file around `body` (the nodes), on line 2 onwards.
struct Parsed {
    std::unique_ptr<Protocol> proto;
    Diagnostics diags;
    bool ok() const { return proto && !diags.has_errors(); }
    std::string messages() const { return diags.format("rules.xml"); }
};

Parsed parse(const std::string& xml) {
    Parsed p;
    p.proto = parse_rules(xml, p.diags);
    return p;
}

// ---- parse_number ---------------------------------------------------------

TEST(ParseNumber, DecimalAndHex) {
    uint64_t v = 0;
    EXPECT_TRUE(parse_number("31", v));
    EXPECT_EQ(v, 31u);
    EXPECT_TRUE(parse_number("0x1f", v));
    EXPECT_EQ(v, 31u);
    EXPECT_TRUE(parse_number("0X1F", v));
    EXPECT_EQ(v, 31u);
    EXPECT_TRUE(parse_number("0x88a4", v));
    EXPECT_EQ(v, 0x88a4u);
    EXPECT_TRUE(parse_number("0", v));
    EXPECT_EQ(v, 0u);
    EXPECT_TRUE(parse_number("0x0", v));
    EXPECT_EQ(v, 0u);
    EXPECT_TRUE(parse_number("007", v));
    EXPECT_EQ(v, 7u);  // leading zeros are decimal, not octal
}

TEST(ParseNumber, WhitespaceAround) {
    uint64_t v = 0;
    EXPECT_TRUE(parse_number("  42\t", v));
    EXPECT_EQ(v, 42u);
    EXPECT_TRUE(parse_number("\n0x0d ", v));
    EXPECT_EQ(v, 13u);
}

TEST(ParseNumber, SixtyFourBitLimits) {
    uint64_t v = 0;
    EXPECT_TRUE(parse_number("0xffffffffffffffff", v));
    EXPECT_EQ(v, UINT64_MAX);
    EXPECT_TRUE(parse_number("18446744073709551615", v));
    EXPECT_EQ(v, UINT64_MAX);
    EXPECT_FALSE(parse_number("18446744073709551616", v));
    EXPECT_FALSE(parse_number("0x10000000000000000", v));
    EXPECT_FALSE(parse_number("99999999999999999999", v));
}

TEST(ParseNumber, LeadingZerosDoNotCountAsDigits) {
    // found by tests/fuzz/xml_fuzz.py: '000000000000000000001' was "not a number from 0 to ..."
    uint64_t v = 0;
    EXPECT_TRUE(parse_number("0000000000000000000000000034997", v));
    EXPECT_EQ(v, 34997u);
    EXPECT_TRUE(parse_number("0x00000000000000000000ffffffffffffffff", v));
    EXPECT_EQ(v, UINT64_MAX);
    EXPECT_TRUE(parse_number("000000000000000000000", v));
    EXPECT_EQ(v, 0u);
    EXPECT_FALSE(parse_number("000000000000018446744073709551616", v));
    EXPECT_FALSE(parse_number("0x000010000000000000000", v));
}

TEST(ParseNumber, Rejects) {
    uint64_t v = 0;
    for (const char* bad : {"", " ", "0x", "-1", "+1", "1e3", "0x1g", "12abc", "abc", "1 2", "1.0", "0b101", "x10"})
        EXPECT_FALSE(parse_number(bad, v)) << "'" << bad << "'";
}

// ---- length forms --------------------------------------------------------------

TEST(Length, FixedBytesAndBits) {
    Parsed p = parse(rules("  <node name=\"a\" length=\"2byte\"/>\n"
                           "  <node name=\"b\" length=\"11bit\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"c\" length=\" 4byte \"/>\n"
                           "  <node name=\"d\" length=\"1048576byte\"/>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    const Node* a = find(*p.proto, "a");
    EXPECT_EQ(a->length_kind, LengthKind::Bytes);
    EXPECT_EQ(a->fixed_bits, 16u);
    const Node* b = find(*p.proto, "b");
    EXPECT_EQ(b->length_kind, LengthKind::Bits);
    EXPECT_EQ(b->fixed_bits, 11u);
    EXPECT_EQ(find(*p.proto, "c")->fixed_bits, 32u);
    EXPECT_EQ(find(*p.proto, "d")->fixed_bits, 8u << 20);
}

TEST(Length, AbsentEmptyAndRest) {
    Parsed p = parse(rules("  <node name=\"absent\"><node name=\"x\" length=\"1byte\"/></node>\n"
                           "  <node name=\"empty\" length=\"\"><node name=\"y\" length=\"1byte\"/></node>\n"
                           "  <node name=\"blank\" length=\"  \"><node name=\"z\" length=\"1byte\"/></node>\n"
                           "  <node name=\"tail\" length=\"rest\"/>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    EXPECT_EQ(find(*p.proto, "absent")->length_kind, LengthKind::Children);
    EXPECT_EQ(find(*p.proto, "empty")->length_kind, LengthKind::Children);
    EXPECT_EQ(find(*p.proto, "blank")->length_kind, LengthKind::Children);
    EXPECT_EQ(find(*p.proto, "tail")->length_kind, LengthKind::Rest);
}

TEST(Length, RestMinusTheBytesOfATrailer) {
    Parsed p = parse(rules("  <node name=\"a\" length=\"rest - 2\"/>\n"
                           "  <node name=\"b\" length=\"rest-1048576\"/>\n"
                           "  <node name=\"c\" length=\"rest - 00000004\"/>\n"
                           "  <node name=\"d\" length=\"rest - 0x10\"/>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    EXPECT_EQ(find(*p.proto, "a")->length_kind, LengthKind::Rest);
    EXPECT_EQ(find(*p.proto, "a")->rest_keep, 2u);
    EXPECT_EQ(find(*p.proto, "b")->rest_keep, 1048576u);
    EXPECT_EQ(find(*p.proto, "c")->rest_keep, 4u);
    EXPECT_EQ(find(*p.proto, "d")->rest_keep, 16u);
    for (const char* bad : {"rest - 0", "rest - 1048577", "rest - 99999999999999999999999", "rest -", "rest - -1",
                            "rest + 4", "rest 4", "rest - 4byte"}) {
        Parsed q = parse(rules(std::string("  <node name=\"x\" length=\"") + bad + "\"/>\n"));
        EXPECT_FALSE(q.ok()) << bad;
        EXPECT_TRUE(contains(q.messages(), "N from 1 to 1048576")) << bad << ": " << q.messages();
    }
}

TEST(Length, XPathWithoutArithmetic) {
    Parsed p = parse(rules("  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"Data\" length=\"../node[@name='Len']\"/>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    const Node* data = find(*p.proto, "Data");
    EXPECT_EQ(data->length_kind, LengthKind::Field);
    EXPECT_EQ(data->length_ref.xpath, "../node[@name='Len']");
    EXPECT_EQ(data->length_ref.op, 0);
    EXPECT_EQ(data->length_ref.operand, 0);
    EXPECT_EQ(data->length_ref.target, find(*p.proto, "Len"));
}

struct BadLength {
    const char* length;
    const char* message;
};

void PrintTo(const BadLength& b, std::ostream* os) { *os << "length=\"" << b.length << "\""; }

class LengthErrors : public ::testing::TestWithParam<BadLength> {};

TEST_P(LengthErrors, AreReportedOnTheNodeLine) {
    Parsed p = parse(rules("  <node name=\"a\" length=\"" + std::string(GetParam().length) + "\"/>\n"));
    EXPECT_FALSE(p.ok());
    EXPECT_NE(p.messages().find(std::string("rules.xml:2: error: ") + GetParam().message), std::string::npos)
        << p.messages();
}

INSTANTIATE_TEST_SUITE_P(
    Forms, LengthErrors,
    ::testing::Values(BadLength{"12bits", "bad length '12bits': expected 'Nbyte', 'Nbit', an XPath, 'rest' or nothing "
                                          "(did you mean '12bit'?)"},
                      BadLength{"10 byte", "bad length '10 byte'"},
                      BadLength{"10 byte", "bad length '10 byte': expected 'Nbyte', 'Nbit', an XPath, 'rest' or nothing (did you mean '10byte'?)"},
                      BadLength{"3BYTE", "bad length '3BYTE': expected 'Nbyte', 'Nbit', an XPath, 'rest' or nothing (did you mean '3byte'?)"},
                      BadLength{"0byte", "bad length '0byte': a fixed length must be from 1 to 1048576"},
                      BadLength{"0bit", "bad length '0bit'"},
                      BadLength{"1048577byte", "bad length '1048577byte'"},
                      BadLength{"99999999999999999999999bit", "bad length '99999999999999999999999bit'"},
                      BadLength{"12", "bad length '12'"},
                      BadLength{"1.5byte", "bad length '1.5byte'"},
                      BadLength{"abc!", "invalid XPath 'abc!' in 'length'"},
                      BadLength{"-3byte", "bad length '-3byte': a fixed length must be from 1 to 1048576"},
                      BadLength{"Rest", "XPath 'Rest' in 'length' selects no node"}),
    [](const ::testing::TestParamInfo<BadLength>& info) { return "case" + std::to_string(info.index); });

// ---- arithmetic tails -------------------------------------------------------

struct Tail {
    const char* text;
    char op;
    int64_t operand;
};

void PrintTo(const Tail& t, std::ostream* os) { *os << "\"" << t.text << "\""; }

class ArithmeticTail : public ::testing::TestWithParam<Tail> {};

TEST_P(ArithmeticTail, SplitsOffOneOperatorAndInteger) {
    const Tail& t = GetParam();
    Parsed p = parse(rules("  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"Data\" length=\"" + std::string(t.text) + "\"/>\n"
                           "  <node name=\"Item\" length=\"1byte\" count=\"" + std::string(t.text) + "\"/>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    const Node* len = find(*p.proto, "Len");
    for (const FieldRef* ref : {&find(*p.proto, "Data")->length_ref, &*find(*p.proto, "Item")->count}) {
        EXPECT_EQ(ref->xpath, "../node[@name='Len']");
        EXPECT_EQ(ref->op, t.op);
        EXPECT_EQ(ref->operand, t.operand);
        EXPECT_EQ(ref->target, len);
    }
}

INSTANTIATE_TEST_SUITE_P(Forms, ArithmeticTail,
                         ::testing::Values(Tail{"../node[@name='Len'] * 2", '*', 2},
                                           Tail{"../node[@name='Len'] + 4", '+', 4},
                                           Tail{"../node[@name='Len'] - 24", '-', 24},
                                           Tail{"../node[@name='Len']*2", '*', 2},
                                           Tail{"../node[@name='Len']-24", '-', 24},
                                           Tail{"  ../node[@name='Len']   +   0  ", '+', 0},
                                           Tail{"../node[@name='Len'] * 999999999", '*', 999999999},
                                           // leading zeros do not count towards the nine digits
                                           Tail{"../node[@name='Len'] * 0000000000000000000002", '*', 2},
                                           Tail{"../node[@name='Len'] + 0000000000", '+', 0}));

TEST(ArithmeticTailErrors, OperandTooLarge) {
    Parsed p = parse(rules("  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"Data\" length=\"../node[@name='Len'] * 1234567890\"/>\n"));
    EXPECT_FALSE(p.ok());
    EXPECT_NE(p.messages().find("rules.xml:3: error: number 1234567890 after '*' in 'length' is too large"),
              std::string::npos)
        << p.messages();
}

TEST(ArithmeticTailErrors, OperandTooLargeAfterLeadingZeros) {
    Parsed p = parse(rules("  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"Data\" length=\"../node[@name='Len'] * 01234567890\"/>\n"));
    EXPECT_FALSE(p.ok());
    EXPECT_NE(p.messages().find("rules.xml:3: error: number 01234567890 after '*' in 'length' is too large"),
              std::string::npos)
        << p.messages();
}

TEST(ArithmeticTailErrors, NotATail) {
    // An operator before the operator, or nothing before it: the whole text is the XPath.
    for (const char* text : {"../node[@name='Len'] - -2", "* 2", "../node[@name='Len'] 2"}) {
        Parsed p = parse(rules("  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                               "  <node name=\"Data\" length=\"" + std::string(text) + "\"/>\n"));
        EXPECT_FALSE(p.ok()) << text;
        EXPECT_NE(p.messages().find("XPath '" + std::string(text) + "' in 'length'"), std::string::npos)
            << text << "\n" << p.messages();
    }
}

TEST(ArithmeticTailErrors, OnlyLengthAndCountTakeArithmetic) {
    // if and repeat read a field as it is; the tail makes the XPath a number.
    Parsed p = parse(rules("  <node name=\"T\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"B\" length=\"1byte\" if=\"../node[@name='T'] + 1\" in=\"1\"/>\n"
                           "  <node name=\"R\" repeat=\"node[@name='M'] * 2\">\n"
                           "    <node name=\"M\" length=\"1byte\" displaytype=\"bool\"/>\n"
                           "  </node>\n"));
    EXPECT_FALSE(p.ok());
    EXPECT_NE(p.messages().find("rules.xml:3: error: XPath '../node[@name='T'] + 1' in 'if' gives a value"),
              std::string::npos)
        << p.messages();
    EXPECT_NE(p.messages().find("rules.xml:4: error: XPath 'node[@name='M'] * 2' in 'repeat' gives a value"),
              std::string::npos)
        << p.messages();
}

TEST(ArithmeticTailErrors, DivisionIsNotAnOperator) {
    Parsed p = parse(rules("  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"Data\" length=\"../node[@name='Len'] div 2\"/>\n"));
    EXPECT_FALSE(p.ok());
    EXPECT_NE(p.messages().find("rules.xml:3: error: XPath '../node[@name='Len'] div 2' in 'length' gives a value"),
              std::string::npos)
        << p.messages();
}

// ---- 'in' lists ------------------------------------------------------------------

std::vector<std::pair<uint64_t, uint64_t>> in_list(const std::string& in, std::string* messages = nullptr) {
    Parsed p = parse(rules("  <node name=\"T\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"B\" length=\"1byte\" if=\"../node[@name='T']\" in=\"" + in + "\"/>\n"));
    if (messages) *messages = p.messages();
    std::vector<std::pair<uint64_t, uint64_t>> out;
    if (!p.ok()) return out;
    const Node* b = find(*p.proto, "B");
    EXPECT_TRUE(b->has_in);
    for (const ValueRange& r : b->in_list) out.push_back({r.low, r.high});
    return out;
}

using Ranges = std::vector<std::pair<uint64_t, uint64_t>>;

TEST(InList, NumbersHexAndRanges) {
    EXPECT_EQ(in_list("1-9,0x0d,14"), (Ranges{{1, 9}, {13, 13}, {14, 14}}));
    EXPECT_EQ(in_list("1"), (Ranges{{1, 1}}));
    EXPECT_EQ(in_list("0"), (Ranges{{0, 0}}));
    EXPECT_EQ(in_list("0x0a-0x0c"), (Ranges{{10, 12}}));
    EXPECT_EQ(in_list(" 0 - 9 , 13 , 14-0xff "), (Ranges{{0, 9}, {13, 13}, {14, 255}}));
    EXPECT_EQ(in_list("5-5"), (Ranges{{5, 5}}));
    EXPECT_EQ(in_list("0-0xffffffffffffffff"), (Ranges{{0, UINT64_MAX}}));
    EXPECT_EQ(in_list("3,1"), (Ranges{{3, 3}, {1, 1}}));  // order as written
}

TEST(InList, Errors) {
    for (const char* bad : {"x", "1-9,x", "9-1", "5-", "-5", "1,,2", "1,2,", ",1", "1-2-3", "0x", "1 2"}) {
        std::string messages;
        EXPECT_TRUE(in_list(bad, &messages).empty()) << bad;
        EXPECT_NE(messages.find("rules.xml:3: error: bad 'in' list '" + std::string(bad) + "'"), std::string::npos)
            << bad << "\n" << messages;
    }
    std::string messages;
    in_list("", &messages);
    EXPECT_NE(messages.find("rules.xml:3: error: empty 'in' list"), std::string::npos) << messages;
}

TEST(InList, IfAndInGoTogether) {
    Parsed p = parse(rules("  <node name=\"T\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"A\" length=\"1byte\" if=\"../node[@name='T']\"/>\n"
                           "  <node name=\"B\" length=\"1byte\" in=\"1\"/>\n"));
    EXPECT_NE(p.messages().find("rules.xml:3: error: 'if' needs an 'in' list of values"), std::string::npos)
        << p.messages();
    EXPECT_NE(p.messages().find("rules.xml:4: error: 'in' needs an 'if' field to test"), std::string::npos)
        << p.messages();
}

// ---- XPath resolution ------------------------------------------------------------

TEST(XPath, ContextIsTheNodeItself) {
    Parsed p = parse(rules("  <node name=\"Header\">\n"
                           "    <node name=\"长度\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "    <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  </node>\n"
                           "  <node name=\"Body\">\n"
                           "    <node name=\"长度\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "    <node name=\"Sibling\" length=\"../node[@name='长度']\"/>\n"
                           "    <node name=\"Cousin\" length=\"../../node[@name='Header']/node[@name='长度']\"/>\n"
                           "    <node name=\"Anywhere\" length=\"//node[@name='Kind']\"/>\n"
                           "    <node name=\"Absolute\" length=\"/root/node[@name='Body']/node[1]\"/>\n"
                           "    <node name=\"Preceding\" length=\"preceding-sibling::node[5]\"/>\n"
                           "  </node>\n"
                           "  <node name=\"Item\" repeat=\"node[@name='Flags']/node[@name='M']\">\n"
                           "    <node name=\"Flags\" length=\"1byte\">\n"
                           "      <node name=\"M\" length=\"1bit\" displaytype=\"bool\"/>\n"
                           "      <node name=\"X\" length=\"7bit\" displaytype=\"numberhex\"/>\n"
                           "    </node>\n"
                           "  </node>\n"
                           "  <node name=\"Self\" length=\"1byte\" displaytype=\"bool\" repeat=\".\"/>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    const Protocol& proto = *p.proto;
    const Node* header_len = proto.nodes[0]->children[0].get();
    const Node* body_len = proto.nodes[1]->children[0].get();
    EXPECT_EQ(find(proto, "Sibling")->length_ref.target, body_len);
    EXPECT_EQ(find(proto, "Cousin")->length_ref.target, header_len);
    EXPECT_EQ(find(proto, "Anywhere")->length_ref.target, find(proto, "Kind"));
    EXPECT_EQ(find(proto, "Absolute")->length_ref.target, body_len);
    EXPECT_EQ(find(proto, "Preceding")->length_ref.target, body_len);
    EXPECT_EQ(find(proto, "Item")->repeat->target, find(proto, "M"));
    EXPECT_EQ(find(proto, "Self")->repeat->target, find(proto, "Self"));
}

TEST(XPath, DoubleSlashFromAnyNode) {
    Parsed p = parse(rules("  <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                           "  <node name=\"Deep\">\n"
                           "    <node name=\"Deeper\">\n"
                           "      <node name=\"Item\" length=\"1byte\" count=\"//node[@name='Count']\"/>\n"
                           "      <node name=\"Rel\" length=\"1byte\" count=\"../../../node[@name='Count']\"/>\n"
                           "    </node>\n"
                           "  </node>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    EXPECT_EQ(find(*p.proto, "Item")->count->target, find(*p.proto, "Count"));
    EXPECT_EQ(find(*p.proto, "Rel")->count->target, find(*p.proto, "Count"));
}

TEST(XPath, PdulengthIsRelativeToRoot) {
    Parsed p = parse(rules("  <hook table=\"tcp.port\" value=\"44818\"/>\n"
                           "  <node name=\"Command\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                           "  <node name=\"Length\" length=\"2byte\" displaytype=\"numberdec\"/>\n",
                           "pdulength=\"node[@name='Length']\" pdulengthadd=\"24\""));
    ASSERT_TRUE(p.ok()) << p.messages();
    ASSERT_TRUE(p.proto->pdulength.has_value());
    EXPECT_EQ(p.proto->pdulength->target, find(*p.proto, "Length"));
    EXPECT_EQ(p.proto->pdulengthadd, 24);
}

TEST(XPath, Errors) {
    struct Case {
        const char* attrs;
        const char* message;
    };
    const Case cases[] = {
        {"length=\"../node[@name='Len'\"", "invalid XPath '../node[@name='Len'' in 'length'"},
        {"length=\"1byte\" count=\"$n\"", "invalid XPath '$n' in 'count'"},
        {"length=\"../node[@name='Nope']\"", "XPath '../node[@name='Nope']' in 'length' selects no node"},
        {"length=\"node[@name='Len']\"", "XPath 'node[@name='Len']' in 'length' selects no node"},
        {"length=\"../node\"", "XPath '../node' in 'length' selects 3 nodes; it must select exactly one"},
        {"length=\"count(..)\"", "XPath 'count(..)' in 'length' gives a value, not a node; it must select one <node>"},
        {"length=\"../node[1]/@name\"", "XPath '../node[1]/@name' in 'length' selects something that is not a <node> element"},
        {"length=\"..\"", "XPath '..' in 'length' selects <root> on line 1, not a <node>"},
        {"length=\"../hook\"", "XPath '../hook' in 'length' selects <hook> on line 2, not a <node>"},
    };
    for (const Case& c : cases) {
        Parsed p = parse(rules("  <hook table=\"udp.port\" value=\"1\"/>\n"
                               "  <node name=\"Len\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                               "  <node name=\"X\" " + std::string(c.attrs) + "/>\n"
                               "  <node name=\"Y\" length=\"1byte\"/>\n"));
        EXPECT_FALSE(p.ok()) << c.attrs;
        EXPECT_NE(p.messages().find(std::string("rules.xml:4: error: ") + c.message), std::string::npos)
            << c.attrs << "\n" << p.messages();
    }
}

// ---- document structure, lines and attributes ------------------------------------

TEST(Structure, DocIndexIsPositionAmongAllNodes) {
    Parsed p = parse(rules("  <node name=\"a\"><node name=\"b\" length=\"1byte\"/><node name=\"c\">"
                           "<node name=\"d\" length=\"1byte\"/></node></node>\n"
                           "  <hook table=\"udp.port\" value=\"1\"/>\n"
                           "  <node name=\"e\" length=\"1byte\"/>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    int expected = 1;
    for (const char* name : {"a", "b", "c", "d", "e"}) EXPECT_EQ(find(*p.proto, name)->doc_index, expected++) << name;
    EXPECT_EQ(find(*p.proto, "d")->parent, find(*p.proto, "c"));
    EXPECT_EQ(find(*p.proto, "a")->parent, nullptr);
}

TEST(Structure, LinesAreWhereStartTagsBegin) {
    // The paper writes start tags over two lines; the element's line is the first.
    Parsed p = parse("<!-- line 1 -->\n"
                     "<root name=\"Test\" abbreviation=\"TST\"\n"
                     "      ethertype=\"0x88b5\">\n"
                     "  <node name=\"命令\" length=\"8bit\"\n"
                     "displaytype=\"enum\">\n"
                     "    <enum value=\"1\"\n"
                     "          name=\"one\"/>\n"
                     "  </node>\n"
                     "  <!-- <node name=\"commented out\" -->\n"
                     "  <node name=\"a > b\" description='x > y'\n"
                     "\n"
                     "        length=\"1byte\"/><node name=\"c\" length=\"1byte\"/>\n"
                     "</root>\n");
    ASSERT_TRUE(p.ok()) << p.messages();
    EXPECT_EQ(p.proto->line, 2);
    EXPECT_EQ(find(*p.proto, "命令")->line, 4);
    EXPECT_EQ(find(*p.proto, "命令")->enums.at(0).line, 6);
    EXPECT_EQ(find(*p.proto, "a > b")->line, 10);
    EXPECT_EQ(find(*p.proto, "c")->line, 12);
}

TEST(Structure, AttributesAsWritten) {
    Parsed p = parse(rules("  <node name=\"a\" length=\"1byte\" filter=\"aa\" description=\"help text\" byteorder=\"little\"/>\n"
                           "  <node name=\"b\" filter=\"\"><node name=\"c\" length=\"1byte\" displaytype=\"bool\"/></node>\n"
                           "  <node name=\"d\" summary=\"{c} !\"><node name=\"e\" length=\"1byte\"/></node>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    const Node* a = find(*p.proto, "a");
    EXPECT_EQ(a->filter, std::optional<std::string>("aa"));
    EXPECT_EQ(a->description, "help text");
    EXPECT_EQ(a->byteorder_given, std::optional<ByteOrder>(ByteOrder::Little));
    EXPECT_FALSE(a->display_given);
    EXPECT_EQ(find(*p.proto, "b")->filter, std::optional<std::string>(""));
    EXPECT_FALSE(find(*p.proto, "d")->filter.has_value());
    EXPECT_FALSE(find(*p.proto, "d")->byteorder_given.has_value());
    EXPECT_EQ(find(*p.proto, "d")->summary, std::optional<std::string>("{c} !"));
    EXPECT_TRUE(find(*p.proto, "c")->display_given);
    EXPECT_EQ(find(*p.proto, "c")->display, Display::Bool);
}

TEST(Structure, EveryDisplayType) {
    const std::pair<const char*, Display> all[] = {
        {"address", Display::Address}, {"numberhex", Display::NumberHex}, {"numberdec", Display::NumberDec},
        {"bool", Display::Bool},       {"origin", Display::Origin},       {"enum", Display::Enum},
        {"nondisplay", Display::NonDisplay}};
    for (const auto& [text, display] : all) {
        Parsed p = parse(rules("  <node name=\"a\" length=\"1byte\" displaytype=\"" + std::string(text) + "\"/>\n"));
        ASSERT_TRUE(p.ok()) << text << "\n" << p.messages();
        EXPECT_EQ(find(*p.proto, "a")->display, display) << text;
        EXPECT_STREQ(display_name(display), text);
    }
}

TEST(Structure, NoolIsNotBool) {
    Parsed p = parse(rules("  <node name=\"M\" length=\"1byte\" displaytype=\"nool\"/>\n"));
    EXPECT_FALSE(p.ok());
    EXPECT_NE(p.messages().find("rules.xml:2: error: unknown displaytype 'nool' (did you mean 'bool'?); valid: "
                                "address, numberhex, numberdec, bool, origin, enum, nondisplay"),
              std::string::npos)
        << p.messages();
}

TEST(Structure, RootAttributes) {
    Parsed p = parse("<root name=\"EtherCAT\" abbreviation=\"ECATR\" ethertype=\"0x88a4\" byteorder=\"little\">\n"
                     "  <hook table=\"udp.port\" value=\"34980\"/>\n"
                     "  <hook table=\"tcp.port\" value=\"0x10\"/>\n"
                     "</root>\n");
    ASSERT_TRUE(p.ok()) << p.messages();
    EXPECT_EQ(p.proto->name, "EtherCAT");
    EXPECT_EQ(p.proto->abbreviation, "ECATR");
    EXPECT_EQ(p.proto->filter, "ecatr");  // abbreviation lowercased
    EXPECT_FALSE(p.proto->filter_given);
    EXPECT_EQ(p.proto->ethertype, std::optional<uint64_t>(0x88a4));
    EXPECT_EQ(p.proto->byteorder, ByteOrder::Little);
    ASSERT_EQ(p.proto->hooks.size(), 2u);
    EXPECT_EQ(p.proto->hooks[0].table, "udp.port");
    EXPECT_EQ(p.proto->hooks[0].value, 34980u);
    EXPECT_EQ(p.proto->hooks[0].line, 2);
    EXPECT_EQ(p.proto->hooks[1].value, 16u);

    Parsed q = parse("<root name=\"X\" abbreviation=\"X-Y\" filter=\"xy\" ethertype=\"34980\"/>\n");
    ASSERT_TRUE(q.ok()) << q.messages();
    EXPECT_EQ(q.proto->filter, "xy");
    EXPECT_TRUE(q.proto->filter_given);
    EXPECT_EQ(q.proto->ethertype, std::optional<uint64_t>(34980));
    EXPECT_EQ(q.proto->byteorder, ByteOrder::Big);
}

TEST(Structure, EnumItems) {
    Parsed p = parse(rules("  <node name=\"Cmd\" length=\"1byte\" displaytype=\"enum\">\n"
                           "    <enum value=\"0x0a\" name=\"LRD 读数据\"/>\n"
                           "    <enum value=\"12\" name=\"LRW\"/>\n"
                           "  </node>\n"));
    ASSERT_TRUE(p.ok()) << p.messages();
    const Node* cmd = find(*p.proto, "Cmd");
    ASSERT_EQ(cmd->enums.size(), 2u);
    EXPECT_EQ(cmd->enums[0].value, 10u);
    EXPECT_EQ(cmd->enums[0].name, "LRD 读数据");
    EXPECT_EQ(cmd->enums[0].line, 3);
    EXPECT_EQ(cmd->enums[1].value, 12u);
    EXPECT_TRUE(cmd->is_leaf());  // enum items are not children
}

TEST(Structure, PaperEnumFormShowsTheWellFormedOne) {
    for (const char* item : {"<enum 0x0a=\"LRD 读数据\"/>", "<enum  0x0a = \"LRD\"/>", "<enum\n0x0a=\"LRD\"/>",
                             "<enum value=\"1\" name=\"x\" 0x0b=\"LWR\"/>", "<enum 10=\"LRD\"/>"}) {
        Parsed p = parse(rules("  <node name=\"Cmd\" length=\"1byte\" displaytype=\"enum\">\n    " + std::string(item) +
                               "\n  </node>\n"));
        EXPECT_EQ(p.proto, nullptr);
        EXPECT_NE(p.messages().find("rules.xml:3: error: XML is not well-formed: an attribute name cannot start with "
                                    "a digit; enum items are written <enum value=\"0x0a\" name=\"LRD 读数据\"/>"),
                  std::string::npos)
            << item << "\n" << p.messages();
    }
}

TEST(Structure, NotWellFormedGivesLibxmlMessageAndLine) {
    Parsed p = parse(rules("  <node name=\"a\" length=\"1byte\">\n"
                           "  </nod>\n"));
    EXPECT_EQ(p.proto, nullptr);
    EXPECT_NE(p.messages().find("rules.xml:3: error: XML is not well-formed: Opening and ending tag mismatch"),
              std::string::npos)
        << p.messages();
    Parsed empty = parse("");
    EXPECT_EQ(empty.proto, nullptr);
    EXPECT_NE(empty.messages().find("error: XML is not well-formed"), std::string::npos) << empty.messages();
}

TEST(Structure, DtdsAreRefusedButCommentsMayMentionThem) {
    Parsed p = parse("<!DOCTYPE root [<!ENTITY a \"b\">]>\n" + rules("  <node name=\"&a;\" length=\"1byte\"/>\n"));
    EXPECT_EQ(p.proto, nullptr);
    EXPECT_NE(p.messages().find("rules.xml:1: error: DTDs and entity declarations are not allowed in rule files"),
              std::string::npos)
        << p.messages();
    Parsed q = parse("<!-- no <!DOCTYPE or <!ENTITY here -->\n" + rules("  <node name=\"a\" length=\"1byte\"/>\n"));
    EXPECT_TRUE(q.ok()) << q.messages();
}

TEST(Structure, UnknownNamesSuggestTheClosest) {
    Parsed p = parse("<root name=\"T\" abbreviation=\"T\" ethertyp=\"1\">\n"
                     "  <hock table=\"udp.port\" value=\"1\"/>\n"
                     "  <node name=\"a\" lenght=\"1byte\"/>\n"
                     "  <node name=\"b\" length=\"1byte\" displaytype=\"enum\"><enum valeu=\"1\" name=\"x\"/></node>\n"
                     "  <node name=\"c\" length=\"1byte\"><Node name=\"d\" length=\"1byte\"/></node>\n"
                     "</root>\n");
    const std::string m = p.messages();
    EXPECT_NE(m.find("rules.xml:1: error: unknown attribute 'ethertyp' on <root>; did you mean 'ethertype'?"), std::string::npos) << m;
    EXPECT_NE(m.find("rules.xml:2: error: unknown element <hock> in <root>; did you mean <hook>?"), std::string::npos) << m;
    EXPECT_NE(m.find("rules.xml:3: error: unknown attribute 'lenght' on <node>; did you mean 'length'?"), std::string::npos) << m;
    EXPECT_NE(m.find("rules.xml:4: error: unknown attribute 'valeu' on <enum>; did you mean 'value'?"), std::string::npos) << m;
    EXPECT_NE(m.find("rules.xml:5: error: unknown element <Node> in <node>; did you mean <node>?"), std::string::npos) << m;
}

TEST(Structure, SuggestionsPreferNamesThatContainTheWord) {
    struct Case {
        const char* attribute;
        const char* suggestion;
    };
    for (const Case& c : {Case{"len", "length"}, Case{"type", "displaytype"}, Case{"display", "displaytype"},
                          Case{"desc", "description"}, Case{"order", "byteorder"}, Case{"repeated", "repeat"},
                          Case{"Filter", "filter"}, Case{"lenght", "length"}}) {
        Parsed p = parse(rules("  <node name=\"a\" length=\"1byte\" " + std::string(c.attribute) + "=\"x\"/>\n"));
        EXPECT_NE(p.messages().find("rules.xml:2: error: unknown attribute '" + std::string(c.attribute) +
                                    "' on <node>; did you mean '" + c.suggestion + "'?"),
                  std::string::npos)
            << p.messages();
    }
    Parsed far = parse(rules("  <node name=\"a\" length=\"1byte\" endian=\"little\"/>\n"));
    EXPECT_NE(far.messages().find("unknown attribute 'endian' on <node>; valid: name, length, displaytype, repeat, "
                                  "count, filter, byteorder, description, if, in, summary"),
              std::string::npos)
        << far.messages();
    Parsed display = parse(rules("  <node name=\"a\" length=\"1byte\" displaytype=\"hex\"/>\n"));
    EXPECT_NE(display.messages().find("unknown displaytype 'hex' (did you mean 'numberhex'?)"), std::string::npos)
        << display.messages();
}

TEST(Structure, FileLimits) {
    Diagnostics d;
    EXPECT_EQ(parse_rules(std::string(kMaxRuleFileBytes + 1, ' '), d), nullptr);
    EXPECT_NE(d.format("rules.xml").find("error: rule file is larger than 16 MiB"), std::string::npos);

    std::string deep;
    for (int i = 0; i <= kMaxNesting; ++i) deep += "<node name=\"n" + std::to_string(i) + "\">";
    deep += "<node name=\"leaf\" length=\"1byte\"/>";
    for (int i = 0; i <= kMaxNesting; ++i) deep += "</node>";
    Parsed p = parse(rules(deep + "\n"));
    EXPECT_FALSE(p.ok());
    EXPECT_NE(p.messages().find("error: nodes nested deeper than 64 levels"), std::string::npos) << p.messages();
}

TEST(Structure, LongValuesDoNotExhaustTheParser) {
    // std::regex recursed per character and overflowed the stack on these.
    const std::string many(200000, '1');
    for (const std::string& length : {many + "byte", many + " bytes", many, "../node[@name='" + many + "'] * 2",
                                      "../node[@name='" + many + "']"}) {
        Parsed p = parse(rules("  <node name=\"a\" length=\"" + length + "\"/>\n"));
        EXPECT_FALSE(p.ok());
        EXPECT_NE(p.messages().find("rules.xml:2: error: "), std::string::npos) << p.messages().substr(0, 200);
    }
    Parsed zeros = parse(rules("  <node name=\"a\" length=\"" + std::string(100, '0') + "2byte\"/>\n"));
    ASSERT_TRUE(zeros.ok()) << zeros.messages();
    EXPECT_EQ(zeros.proto->nodes[0]->fixed_bits, 16u);

    std::string broken = rules("  <node name=\"a\" length=\"1byte\">\n");  // never closed
    for (int i = 0; i < 10000; ++i) broken += "<enum a";
    Parsed p = parse(broken);
    EXPECT_EQ(p.proto, nullptr);
    EXPECT_NE(p.messages().find("error: XML is not well-formed"), std::string::npos);
    EXPECT_EQ(p.messages().find("attribute name cannot start with a digit"), std::string::npos);
}

TEST(Structure, LinesBeyond65535) {
    std::string xml = "<root name=\"T\" abbreviation=\"T\" ethertype=\"1\">\n";
    for (int i = 0; i < 70000; ++i) xml += "<!-- filler -->\n";
    xml += "<node name=\"a\"\n length=\"1byte\" displaytype=\"nool\"/>\n</root>\n";
    Parsed p = parse(xml);
    EXPECT_NE(p.messages().find("rules.xml:70002: error: unknown displaytype 'nool'"), std::string::npos)
        << p.messages();
}

TEST(Structure, MissingRuleFile) {
    Diagnostics d;
    EXPECT_EQ(parse_rule_file("/nonexistent/rules.xml", d), nullptr);
    EXPECT_TRUE(d.has_errors());
    EXPECT_EQ(d.format("x.xml"), "x.xml: error: cannot read the rule file: No such file or directory\n");
}

// A folder is refused before it is read; a device that never ends is read
// one byte past the size limit and refused as too large.
TEST(Structure, RuleFileThatIsNoFile) {
    Diagnostics folder, device;
    EXPECT_EQ(parse_rule_file("/tmp", folder), nullptr);
    EXPECT_EQ(folder.format("x.xml"), "x.xml: error: cannot read the rule file: it is a directory\n");
    EXPECT_EQ(parse_rule_file("/dev/zero", device), nullptr);
    EXPECT_EQ(device.format("x.xml"), "x.xml: error: rule file is larger than 16 MiB\n");
}

// Costly XPaths add up: each stays under the limit of one evaluation, but
// the file's budget ends them, on the line of the one that spent it.
TEST(Structure, ManyCostlyXPathsAreStopped) {
    std::string xml = "<root name=\"T\" abbreviation=\"T\" ethertype=\"1\">\n  <node name=\"Body\" length=\"50byte\">\n";
    for (int i = 0; i < 50; ++i) xml += "    <node name=\"F" + std::to_string(i) + "\" length=\"1byte\"/>\n";
    xml += "  </node>\n";
    for (int i = 0; i < 400; ++i)
        xml += "  <node name=\"O" + std::to_string(i) + "\" length=\"//node[//node[@name='none']]\"/>\n";
    xml += "</root>\n";
    const auto start = std::chrono::steady_clock::now();
    Parsed p = parse(xml);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_NE(p.messages().find("is where the file's XPaths take too long to evaluate (over 20000000 steps in all)"),
              std::string::npos)
        << p.messages().substr(0, 400);
    EXPECT_LT(seconds, 20.0);  // about 0.5 s; unbounded, minutes
}

// What libxml2 finds missing at the end it places one line past it; the
// diagnostic names a line of the file, and an unclosed comment where it opens.
TEST(Structure, ErrorsAtTheEndNameALineOfTheFile) {
    EXPECT_NE(parse("<root name=\"T\" abbreviation=\"T\" ethertype=\"1\">\n"
                    "<!-- never closed\n<node name=\"A\" length=\"1byte\"/>\n</root>\n")
                  .messages()
                  .find("rules.xml:2: error: XML is not well-formed: Comment not terminated"),
              std::string::npos);
    EXPECT_NE(parse("<root name=\"T\" abbreviation=\"T\" ethertype=\"1\">\n<node name=\"A\"/>\n")
                  .messages()
                  .find("rules.xml:2: error: XML is not well-formed: Premature end of data in tag root line 1"),
              std::string::npos);
    EXPECT_NE(parse("\n\n").messages().find("rules.xml:2: error: XML is not well-formed"), std::string::npos);
    // An encoding error libxml2 gives no line: the line of the bytes it names.
    const std::string eucjp = parse("<?xml version=\"1.0\" encoding=\"EUC-JP\"?>\n"
                                    "<root name=\"E\" abbreviation=\"E\" ethertype=\"1\">\n"
                                    "<node name=\"\xff\xfe\" length=\"1byte\"/>\n</root>\n").messages();
    EXPECT_NE(eucjp.find("rules.xml:3: error: XML is not well-formed: input conversion failed"), std::string::npos)
        << eucjp;
}

}  // namespace
}  // namespace dissgen::testing

namespace dissgen::testing {
namespace {

// A group's mistake found through each use is one diagnostic naming the uses'
// lines; through uses within uses, the others are counted, each once.
TEST(Diagnostics, OneMistakeThroughSeveralUsesIsToldOnce) {
    Diagnostics d;
    d.error(4, "bad path (in group 'G' used on line 7) here");
    d.error(4, "bad path (in group 'G' used on line 8) here");
    d.error(4, "bad path (in group 'G' used on line 8) here");
    d.error(4, "another mistake (in group 'G' used on line 7)");
    ASSERT_EQ(d.items().size(), 2u);
    EXPECT_EQ(d.items()[0].message, "bad path (in group 'G' used on lines 7 and 8) here");

    Diagnostics nested;
    const std::string a = "x (in group 'A' used on line 3, in group 'B' used on line 9)";
    const std::string b = "x (in group 'A' used on line 5, in group 'B' used on line 9)";
    for (const std::string& m : {a, b, b, b}) nested.warning(2, m);
    ASSERT_EQ(nested.items().size(), 1u);
    EXPECT_EQ(nested.items()[0].message, a + " (and through 1 more use of the groups)");
}

}  // namespace
}  // namespace dissgen::testing

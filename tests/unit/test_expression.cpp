// SPDX-License-Identifier: GPL-2.0-or-later
// Computed values: the value="..." expression parser, and the validator's
// name resolution and typing of expressions.
#include <gtest/gtest.h>

#include "emit_cpp.h"
#include "expression.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

// The tree in prefix form: "(+ 1 (* 2 3))", fields as {Name}, index as #.
std::string prefix(const Expr& e) {
    switch (e.op) {
    case ExprOp::Int: return std::to_string(e.integer);
    case ExprOp::Float: return std::to_string(e.real).substr(0, 4);
    case ExprOp::Field: return "{" + e.name + "}";
    case ExprOp::Index: return "#";
    case ExprOp::RequestField: return "request{" + e.name + "}";
    default: break;
    }
    std::string out = std::string("(") + expr_op_text(e.op);
    for (const Expr& a : e.args) out += " " + prefix(a);
    return out + ")";
}

std::string parsed(const std::string& text) {
    Expr e;
    std::string error;
    return parse_expression(text, e, error) ? prefix(e) : "error: " + error;
}

TEST(Expression, PrecedenceAsInC) {
    EXPECT_EQ(parsed("1 + 2 * 3"), "(+ 1 (* 2 3))");
    EXPECT_EQ(parsed("(1 + 2) * 3"), "(* (+ 1 2) 3)");
    EXPECT_EQ(parsed("10 - 4 - 3"), "(- (- 10 4) 3)");  // left to right
    EXPECT_EQ(parsed("1 << 2 + 3"), "(<< 1 (+ 2 3))");
    EXPECT_EQ(parsed("1 < 2 == 3 > 4"), "(== (< 1 2) (> 3 4))");
    EXPECT_EQ(parsed("1 | 2 ^ 3 & 4"), "(| 1 (^ 2 (& 3 4)))");
    EXPECT_EQ(parsed("1 || 2 && 3"), "(|| 1 (&& 2 3))");
    EXPECT_EQ(parsed("-{A} % 7"), "(% (- {A}) 7)");
    EXPECT_EQ(parsed("!~{A}"), "(! (~ {A}))");
    EXPECT_EQ(parsed("1 <= 2 >= 3 != 4"), "(!= (>= (<= 1 2) 3) 4)");
    EXPECT_EQ(parsed("8 >> 1 / 2"), "(>> 8 (/ 1 2))");
    // ?: below ||, right to left, any expression in each part
    EXPECT_EQ(parsed("{A} < 0x80 ? {A} : {B}"), "(?: (< {A} 128) {A} {B})");
    EXPECT_EQ(parsed("1 || 0 ? 2 : 3"), "(?: (|| 1 0) 2 3)");
    EXPECT_EQ(parsed("1 ? 2 : 3 ? 4 : 5"), "(?: 1 2 (?: 3 4 5))");
    EXPECT_EQ(parsed("1 ? 2 ? 3 : 4 : 5"), "(?: 1 (?: 2 3 4) 5)");
    EXPECT_EQ(parsed("(1 ? 2 : 3) + 4"), "(+ (?: 1 2 3) 4)");
}

TEST(Expression, Operands) {
    EXPECT_EQ(parsed("0x1F"), "31");
    EXPECT_EQ(parsed("9223372036854775807"), "9223372036854775807");
    EXPECT_EQ(parsed("0.25"), "0.25");
    EXPECT_EQ(parsed(".5"), "0.50");
    EXPECT_EQ(parsed("{Starting address} + index"), "(+ {Starting address} #)");
    EXPECT_EQ(parsed("  index*2  "), "(* # 2)");
}

TEST(Expression, MistakesSayWhere) {
    EXPECT_EQ(parsed(""), "error: expected a number, {field}, index, offset or '(' but the expression ends at character 1");
    EXPECT_EQ(parsed("1 +"), "error: expected a number, {field}, index, offset or '(' but the expression ends at character 4");
    EXPECT_EQ(parsed("(1"), "error: missing ')' at character 3");
    EXPECT_EQ(parsed("{A"), "error: missing '}' at character 1");
    EXPECT_EQ(parsed("{}"), "error: empty field name '{}' at character 1");
    EXPECT_EQ(parsed("1 2"), "error: unexpected '2' at character 3");
    EXPECT_EQ(parsed("0x"), "error: bad number '0x' at character 1");
    EXPECT_EQ(parsed("12ab"), "error: bad number '12a' at character 1");
    EXPECT_EQ(parsed("indexes"), "error: expected a number, {field}, index, offset or '(' but found 'i' at character 1");
    EXPECT_EQ(parsed("9223372036854775808"), "error: number '9223372036854775808' is above 9223372036854775807 at character 1");
    EXPECT_EQ(parsed("A + 1"), "error: expected a number, {field}, index, offset or '(' but found 'A' at character 1");
    EXPECT_EQ(parsed("1 ? 2"), "error: missing ':' of '?' at character 6");
    EXPECT_EQ(parsed("1 ? 2 : "), "error: expected a number, {field}, index, offset or '(' but the expression ends at character 9");
    EXPECT_EQ(parsed("1 : 2"), "error: unexpected ':' at character 3");
    // A number after the first character: the message quotes that number, not what follows it.
    EXPECT_EQ(parsed("{A} + 12ab - 3"), "error: bad number '12a' at character 7");
    EXPECT_EQ(parsed("2 * 9223372036854775808 + 1"),
              "error: number '9223372036854775808' is above 9223372036854775807 at character 5");
}

TEST(Expression, DeepNestingIsRefusedNotOverflowed) {
    EXPECT_EQ(parsed(std::string(100000, '(') + "1" + std::string(100000, ')')).rfind("error: expression nested too deeply", 0), 0u);
    EXPECT_EQ(parsed(std::string(100000, '-') + "1").rfind("error: expression nested too deeply", 0), 0u);
    std::string long_sum = "1";
    for (int i = 0; i < 1024; ++i) long_sum += "+1";
    EXPECT_EQ(parsed(long_sum).rfind("(+ (+", 0), 0u);  // long but flat: fine up to 1024 operators
    // Longer, its tree would be as deep as its operators are many: refused
    // before the validator and the emitters recurse down it.
    for (int i = 0; i < 20000; ++i) long_sum += "+1";
    EXPECT_EQ(parsed(long_sum).rfind("error: expression too long (more than 1024 operators deep)", 0), 0u);
}

const char* const kHead =
    "  <node name=\"Reference\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Raw\" length=\"2byte\" displaytype=\"int\"/>\n";

// The plugin numbers a computed value's operations with 16 bits: a file
// with more in all is refused on the node that goes past, not miscompiled.
TEST(Expression, MoreOperationsThanThePluginCanNumberAreRefused) {
    std::string chain = "{Count}";
    for (int i = 0; i < 1000; ++i) chain += " + {Count}";  // 2 001 operations
    std::string body = "  <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n";
    for (int i = 0; i < 32; ++i)
        body += "  <node name=\"V" + std::to_string(i) + "\" value=\"" + chain + "\"/>\n";
    EXPECT_TRUE(front_end(rules(body)).ok());  // 32 x 2 001 = 64 032 operations fit
    Front f = front_end(rules(body + "  <node name=\"Last\" value=\"" + chain + "\"/>\n"));
    EXPECT_NE(f.messages().find("rules.xml:35: error: the rule file is too large for the plugin's tables: more than "
                                "65535 operations in computed values in all"),
              std::string::npos)
        << f.messages().substr(0, 300);
}

TEST(Expression, RequestOperand) {
    EXPECT_EQ(parsed("request{Reference} + index"), "(+ request{Reference} #)");
    EXPECT_EQ(parsed("request{A}*{B}"), "(* request{A} {B})");
    EXPECT_EQ(parsed("request{A"), "error: missing '}' at character 8");
    EXPECT_EQ(parsed("request{}"), "error: empty field name '{}' at character 8");
    EXPECT_EQ(parsed("request"), "error: expected a number, {field}, index, offset or '(' but found 'r' at character 1");
}

// A response reads its request: the first request-only node of the name,
// one kept value per field however often it is read, the keys' offsets.
TEST(Computed, RequestFieldsAreKeptOnceAndTheKeysPlaced) {
    Front f = front_end(
        "<root name=\"Test\" abbreviation=\"TST\" byteorder=\"big\">\n"
        "  <hook table=\"udp.port\" value=\"47502\"/>\n"
        "  <pairing>\n"
        "    <key field=\"node[@name='Unit']\"/>\n"
        "    <key field=\"node[@name='Transaction']\"/>\n"
        "  </pairing>\n"
        "  <node name=\"Transaction\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
        "  <node name=\"Flags\" length=\"4bit\" displaytype=\"numberhex\"/>\n"
        "  <node name=\"Unit\" length=\"4bit\" displaytype=\"numberdec\"/>\n"
        "  <node name=\"Reference\" length=\"2byte\" displaytype=\"int\"/>\n"
        "  <node name=\"Ask\" direction=\"request\">\n"
        "    <node name=\"Reference\" filter=\"ref\" length=\"2byte\" displaytype=\"int\"/>\n"
        "  </node>\n"
        "  <node name=\"First\" value=\"request{Reference} + 1\" direction=\"response\"/>\n"
        "  <node name=\"Last\" value=\"request{Reference} + request{Transaction}\" direction=\"response\"/>\n"
        "</root>\n");
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* asked = f.proto->nodes[4]->children[0].get();
    ASSERT_EQ(f.proto->request_fields.size(), 2u);
    EXPECT_EQ(f.proto->request_fields[0], asked);  // the request-only one, not the earlier one
    EXPECT_EQ(f.proto->request_fields[1], f.proto->nodes[0].get());
    const Node& last = *f.proto->nodes[6];
    EXPECT_EQ(last.value->args[0].request_index, 0);
    EXPECT_EQ(last.value->args[1].request_index, 1);
    EXPECT_GE(asked->slot, 0);
    EXPECT_EQ(f.proto->pairing->keys[0].offset, 2u);  // Unit: its bit group's offset
    EXPECT_EQ(f.proto->pairing->keys[1].offset, 0u);
    const std::vector<ExprRow> rows = compile_expression(*last.value, false);
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0].code, "DG_OP_REQUEST_FIELD_SIGNED");  // an int field is sign-extended
    EXPECT_EQ(rows[0].bits, 16u);
    EXPECT_EQ(rows[1].code, "DG_OP_REQUEST_FIELD");
    EXPECT_EQ(rows[1].slot, 1);
    const std::string code = emit_cpp(*f.proto, "rules.xml");
    // the keys in the walk's order (the document's), each where it sits
    EXPECT_TRUE(contains(code, "/* Transaction, line 7 */ { 0, 2, 0, 0, 0 },\n    /* Unit, line 9 */ { 2, 1, 0, 0, 4 }")) << code;
    EXPECT_TRUE(contains(code, "request_context(&tst_request_context)")) << code;
    EXPECT_TRUE(contains(code, "dg_op_field(DG_OP_REQUEST_FIELD_SIGNED, 0, 16)")) << code;
}

// Two request layouts that both hold a Reference: the bare name is an error
// naming both; a path (containers' names, then the field's) reads one, also
// when the first in the file is the other, and a node named with '/' is
// still found by its name.
Front paired_layouts(const std::string& reader) {
    return front_end(
        "<root name=\"Test\" abbreviation=\"TST\" byteorder=\"big\">\n"
        "  <hook table=\"udp.port\" value=\"47502\"/>\n"
        "  <pairing><key field=\"node[@name='Transaction']\"/></pairing>\n"
        "  <node name=\"Transaction\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
        "  <node name=\"Read coils\" direction=\"request\">\n"
        "    <node name=\"Reference\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
        "  </node>\n"
        "  <node name=\"Read registers\" direction=\"request\">\n"
        "    <node name=\"Reference\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
        "    <node name=\"Read/Write\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
        "  </node>\n"
        "  <node name=\"Number\" value=\"" + reader + "\" direction=\"response\"/>\n"
        "</root>\n");
}

TEST(Computed, AmbiguousRequestNamesAreErrorsAndPathsChoose) {
    Front bare = paired_layouts("request{Reference}");
    EXPECT_FALSE(bare.ok());
    EXPECT_TRUE(contains(bare.messages(), "rules.xml:12: error: request{Reference} in the value of 'Number' is "
                                          "ambiguous: 2 fields a request decodes fit it: 'Read coils/Reference' "
                                          "(line 6), 'Read registers/Reference' (line 9); name one by its path, "
                                          "e.g. request{Read coils/Reference}"))
        << bare.messages();
    Front path = paired_layouts("request{Read registers/Reference}");
    ASSERT_TRUE(path.ok()) << path.messages();
    ASSERT_EQ(path.proto->request_fields.size(), 1u);
    EXPECT_EQ(path.proto->request_fields[0], path.proto->nodes[2]->children[0].get());
    Front slash = paired_layouts("request{Read/Write}");
    ASSERT_TRUE(slash.ok()) << slash.messages();
    EXPECT_EQ(slash.proto->request_fields[0], slash.proto->nodes[2]->children[1].get());
    Front wrong = paired_layouts("request{Read coil/Reference}");
    EXPECT_TRUE(contains(wrong.messages(), "no node has that path (did you mean request{Read coils/Reference}?)"))
        << wrong.messages();
}

TEST(Computed, ResolvesTheClosestEarlierFieldAndTypes) {
    Front f = front_end(rules(std::string(kHead) +
                              "  <node name=\"Temperature\" value=\"{Raw} * 0.1 - 40\"/>\n"
                              "  <node name=\"Registers\" count=\"../node[@name='Count']\">\n"
                              "    <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    <node name=\"Register\" value=\"{Reference} + index + {Count}\"/>\n"
                              "    <node name=\"Hot\" value=\"{Temperature} &gt; 50\" displaytype=\"bool\"/>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node& temperature = *f.proto->nodes[3];
    EXPECT_TRUE(temperature.value->is_float);
    EXPECT_EQ(temperature.display, Display::Float);  // the default for a decimal expression
    EXPECT_FALSE(temperature.is_numeric());           // not a length or a count
    const Node& registers = *f.proto->nodes[4];
    const Node& reg = *registers.children[1];
    EXPECT_EQ(reg.display, Display::NumberDec);
    EXPECT_FALSE(reg.value->is_float);
    // {Count} is the one inside the instance, the closest above
    EXPECT_EQ(reg.value->args[1].target, registers.children[0].get());
    EXPECT_EQ(reg.value->args[0].args[0].target, f.proto->nodes[0].get());
    EXPECT_GE(f.proto->nodes[0]->slot, 0);  // read at run time
    const Node& hot = *registers.children[2];
    EXPECT_FALSE(hot.value->is_float);  // a comparison gives 0 or 1
    EXPECT_TRUE(hot.value->args[0].is_float);
}

TEST(Computed, SkipsANameInsideARepeatDecodedSinceForTheOneItSees) {
    // the closest Tag is inside Inner, which does not hold the reader: the
    // Tag between the two repeats is the one the reader has a value of
    const std::string items = "  <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Item\" count=\"../node[@name='Count']\">\n"
                              "    <node name=\"Tag\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                              "  </node>\n";
    const std::string inner = "  <node name=\"Inner\" count=\"../node[@name='Count']\">\n"
                              "    <node name=\"Tag\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
                              "  </node>\n";
    Front f = front_end(rules(items + "  <node name=\"Tag\" length=\"1byte\" displaytype=\"numberhex\"/>\n" + inner +
                              "  <node name=\"Double tag\" value=\"{Tag} * 2\">\n"
                              "    <finding name=\"odd\" severity=\"note\" condition=\"{Tag} &gt; 1\" text=\"tag {Tag}\"/>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node& doubled = *f.proto->nodes[4];
    EXPECT_EQ(doubled.value->args[0].target, f.proto->nodes[2].get());
    EXPECT_EQ(doubled.findings[0].condition.args[0].target, f.proto->nodes[2].get());
    EXPECT_EQ(doubled.findings[0].text_pieces[1].leaf, f.proto->nodes[2].get());
    // with only Tags inside other repeats, the closest one is named in the error
    Front none = front_end(rules(items + inner + "  <node name=\"Double tag\" value=\"{Tag} * 2\"/>\n"));
    EXPECT_TRUE(contains(none.messages(), "rules.xml:9: error: {Tag} in the value of 'Double tag' is inside repeated node "
                                          "'Inner' (line 6), which does not contain 'Double tag'"))
        << none.messages();
}


TEST(Computed, SkipsANameInAnAlternativeToTheReaderAndWarnsWhenNoneIsLeft) {
    // Short's Count is closest, but Long is the other member of Short's
    // chain: only one is decoded, so Long reads the header's Count
    const std::string header = "  <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n";
    const std::string chain = "  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Short\" if=\"../node[@name='Kind']\" in=\"1\">\n"
                              "    <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  </node>\n"
                              "  <node name=\"Long\" otherwise=\"true\">\n"
                              "    <node name=\"Items\" value=\"{Count} * 2\"/>\n"
                              "  </node>\n";
    Front f = front_end(rules(header + chain));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(f.proto->nodes[3]->children[0]->value->args[0].target, f.proto->nodes[0].get());
    EXPECT_FALSE(contains(f.messages(), "warning")) << f.messages();
    // without the header's Count, the only one is never there: a warning on the reader's line
    Front alone = front_end(rules(chain));
    ASSERT_TRUE(alone.ok()) << alone.messages();
    EXPECT_TRUE(contains(alone.messages(), "rules.xml:7: warning: {Count} in the value of 'Items' is 'Count' (line 4), "
                                           "an alternative to 'Items': never decoded together with it"))
        << alone.messages();
    // two containers with the same chain: the second's reader keeps to its own copy (and
    // is warned), never the first container's Count
    const std::string wrapped = "  <node name=\"A\">\n" + chain + "  </node>\n";
    Front twice = front_end(rules(wrapped + std::string(wrapped).replace(wrapped.find("\"A\""), 3, "\"B\"")));
    ASSERT_TRUE(twice.ok()) << twice.messages();
    const Node& b = *twice.proto->nodes[1];
    EXPECT_EQ(b.children[2]->children[0]->value->args[0].target, b.children[1]->children[0].get());
    EXPECT_TRUE(contains(twice.messages(), "rules.xml:17: warning: {Count} in the value of 'Items' is 'Count' (line 14)"))
        << twice.messages();
    // siblings whose conditions on one field exclude each other are alternatives too, for a length as well
    Front sized = front_end(rules("  <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                                  "  <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\" "
                                  "if=\"../node[@name='Kind']\" in=\"1\"/>\n"
                                  "  <node name=\"Data\" length=\"../node[@name='Count']\" if=\"../node[@name='Kind']\" "
                                  "in=\"2\"/>\n"));
    EXPECT_TRUE(contains(sized.messages(), "rules.xml:4: warning: length field is 'Count' (line 3), an alternative to "
                                           "'Data'"))
        << sized.messages();
}
TEST(Computed, Mistakes) {
    Front f = front_end(rules(std::string(kHead) +
                              "  <node name=\"Registers\" count=\"../node[@name='Count']\">\n"
                              "    <node name=\"Value\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                              "  </node>\n"
                              "  <node name=\"T\" value=\"{Raw} * 0.5\"/>\n"
                              "  <node name=\"A\" value=\"{Refrence} + 1\"/>\n"
                              "  <node name=\"B\" value=\"index\"/>\n"
                              "  <node name=\"C\" value=\"{Value}\"/>\n"
                              "  <node name=\"D\" value=\"{T} % 2\"/>\n"
                              "  <node name=\"E\" length=\"1byte\" value=\"1\"/>\n"
                              "  <node name=\"F\" value=\"1\" displaytype=\"string\"/>\n"
                              "  <node name=\"G\" value=\"{Later}\"/>\n"
                              "  <node name=\"Later\" length=\"1byte\"/>\n"
                              "  <node name=\"H\" value=\"{Later}\"/>\n"
                              "  <node name=\"I\" value=\"1\"><node name=\"x\" length=\"1byte\"/></node>\n"));
    const std::string m = f.messages();
    EXPECT_TRUE(contains(m, "rules.xml:9: error: {Refrence} in the value of 'A': no node of that name comes before it (did you mean {Reference}?)")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:10: error: 'index' in the value of 'B': it is not inside a repeated node")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:11: error: {Value} in the value of 'C' is inside repeated node 'Registers' (line 5), which does not contain 'C'")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:12: error: operator '%' in the value of 'D' needs integers")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:13: error: computed value 'E' takes no bytes: drop its 'length'")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:14: error: computed value 'F' is shown as string; a computed value is shown as numberdec")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:15: error: {Later} in the value of 'G' is 'Later' (line 16), which comes after it; a value reads fields decoded before it")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:17: error: {Later} in the value of 'H' is 'Later' (line 16), which is not numeric")) << m;
    EXPECT_TRUE(contains(m, "rules.xml:18: error: computed value 'I' cannot have children")) << m;
    EXPECT_EQ(std::count(m.begin(), m.end(), '\n'), 9) << m;
}

TEST(Computed, IsANumericLeafForLengthsCountsAndConditions) {
    Front f = front_end(rules(std::string(kHead) +
                              "  <node name=\"Doubled\" value=\"{Count} * 2\"/>\n"
                              "  <node name=\"Data\" length=\"../node[@name='Doubled']\"/>\n"
                              "  <node name=\"More\" length=\"1byte\" if=\"../node[@name='Doubled']\" in=\"4\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_GE(f.proto->nodes[3]->slot, 0);
}

}  // namespace
}  // namespace dissgen::testing

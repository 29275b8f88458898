// SPDX-License-Identifier: GPL-2.0-or-later
// <finding>: expert infos the rule file raises (parser, validator, emitted code).
#include <gtest/gtest.h>

#include "emit_cpp.h"
#include "test_support.h"

using namespace dissgen;
using namespace dissgen::testing;

namespace {

const std::string kReply =
    "  <node name=\"Reply\">\n"
    "    <node name=\"Service\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
    "    <node name=\"Status\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "    <node name=\"Note\" length=\"2byte\" displaytype=\"origin\"/>\n";

std::string reply_with(const std::string& finding) { return rules(kReply + finding + "  </node>\n"); }

const std::string kGood =
    "    <finding name=\"error_status\" severity=\"note\" group=\"response_code\" condition=\"{Status} != 0\"\n"
    "             text=\"Service {Service} failed: {Status} ({Note})\"/>\n";

}  // namespace

TEST(FindingParser, ReadsEveryAttribute) {
    Front f = front_end(reply_with(kGood));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* reply = find(*f.proto, "Reply");
    ASSERT_EQ(reply->findings.size(), 1u);
    const Finding& x = reply->findings[0];
    EXPECT_EQ(x.name, "error_status");
    EXPECT_EQ(x.severity, "note");
    EXPECT_EQ(x.group, "response_code");
    EXPECT_EQ(x.condition_text, "{Status} != 0");
    EXPECT_EQ(x.line, 6);
    EXPECT_EQ(x.filter_name, "tst.finding.error_status");
}

TEST(FindingParser, GroupDefaultsToProtocol) {
    Front f = front_end(reply_with("<finding name=\"x\" severity=\"warn\" condition=\"{Status}\" text=\"t\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "Reply")->findings[0].group, "protocol");
}

TEST(FindingValidator, TextResolvesFieldsToSlotsAndLiterals) {
    Front f = front_end(reply_with(kGood));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Finding& x = find(*f.proto, "Reply")->findings[0];
    ASSERT_EQ(x.text_pieces.size(), 7u);  // "Service ", {Service}, " failed: ", {Status}, " (", {Note}, ")"
    EXPECT_EQ(x.text_pieces[0].text, "Service ");
    EXPECT_EQ(x.text_pieces[1].leaf, find(*f.proto, "Service"));
    EXPECT_EQ(x.text_pieces[3].leaf, find(*f.proto, "Status"));
    EXPECT_EQ(x.text_pieces[5].leaf, find(*f.proto, "Note"));
    EXPECT_EQ(x.text_pieces[6].leaf, nullptr);
    EXPECT_EQ(x.text_pieces[6].text, ")");
    // every field the finding reads keeps its value
    EXPECT_GE(find(*f.proto, "Service")->slot, 0);
    EXPECT_GE(find(*f.proto, "Status")->slot, 0);
    EXPECT_GE(find(*f.proto, "Note")->slot, 0);
}

struct BadFinding {
    const char* finding;
    const char* message;
};

class FindingErrors : public ::testing::TestWithParam<BadFinding> {};

TEST_P(FindingErrors, AreErrorsOnTheFindingsLine) {
    Front f = front_end(reply_with(std::string("    ") + GetParam().finding + "\n"));
    EXPECT_FALSE(f.ok());
    EXPECT_TRUE(contains(f.messages(), std::string("rules.xml:6: error: ") + GetParam().message)) << f.messages();
}

INSTANTIATE_TEST_SUITE_P(
    Findings, FindingErrors,
    ::testing::Values(
        BadFinding{"<finding name=\"x\" severity=\"warnig\" condition=\"{Status}\" text=\"t\"/>",
                   "unknown severity 'warnig' of finding 'x'; use chat, note, warning or error (did you mean 'warning'?)"},
        BadFinding{"<finding name=\"x\" severity=\"note\" group=\"malformd\" condition=\"{Status}\" text=\"t\"/>",
                   "unknown group 'malformd' of finding 'x'"},
        BadFinding{"<finding name=\"x\" severity=\"note\" condition=\"{Status} !=\" text=\"t\"/>",
                   "bad condition of finding 'x'"},
        BadFinding{"<finding name=\"x\" severity=\"note\" condition=\"{Stat} != 0\" text=\"t\"/>",
                   "{Stat} in the condition of finding 'x': no node of that name comes before it (did you mean {Status}?)"},
        BadFinding{"<finding name=\"x\" severity=\"note\" condition=\"{Note} != 0\" text=\"t\"/>",
                   "{Note} in the condition of finding 'x' is 'Note' (line 5), which is not numeric"},
        BadFinding{"<finding name=\"x\" severity=\"note\" condition=\"{Status}\" text=\"{Nothing}\"/>",
                   "{Nothing} in the text of finding 'x': no field of that name is decoded before it"},
        BadFinding{"<finding name=\"x\" severity=\"note\" condition=\"{Status}\" text=\"{Status\"/>",
                   "'{' without '}' in the text of finding 'x'"},
        BadFinding{"<finding name=\"Bad-Name\" severity=\"note\" condition=\"{Status}\" text=\"t\"/>",
                   "bad finding name 'Bad-Name'"},
        BadFinding{"<finding name=\"x\" severity=\"note\" text=\"t\"/>", "<finding> needs a 'condition' attribute"},
        BadFinding{"<finding name=\"x\" severity=\"note\" condition=\"{Status} * 0.5\" text=\"t\"/>",
                   "the condition of finding 'x' is a real number"},
        BadFinding{"<finding name=\"x\" severity=\"note\" condition=\"{Status}\" text=\"t\"><node name=\"n\"/></finding>",
                   "unknown element <node> in <finding>"}));

TEST(FindingValidator, DuplicateNameIsAnError) {
    Front f = front_end(reply_with("    <finding name=\"x\" severity=\"note\" condition=\"{Status}\" text=\"a\"/>\n"
                                   "    <finding name=\"x\" severity=\"note\" condition=\"{Service}\" text=\"b\"/>\n"));
    EXPECT_TRUE(contains(f.messages(), "rules.xml:7: error: duplicate finding name 'x' (also line 6)")) << f.messages();
}

TEST(FindingValidator, NameOfAFieldIsAnError) {
    Front f = front_end(rules("  <node name=\"Finding\">\n    <node name=\"X\" length=\"1byte\" displaytype=\"numberdec\">\n"
                              "      <finding name=\"x\" severity=\"note\" condition=\"{X}\" text=\"t\"/>\n"
                              "    </node>\n  </node>\n"));
    EXPECT_TRUE(contains(f.messages(), "rules.xml:4: error: finding 'x' is filtered as 'tst.finding.x', the name of 'X'"))
        << f.messages();
}

TEST(FindingValidator, ReadsNoFieldOfAnotherInstance) {
    Front f = front_end(rules("  <node name=\"Count\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Block\">\n"
                              "    <node name=\"Items\" count=\"../../node[@name='Count']\">\n"
                              "      <node name=\"Item\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    </node>\n"
                              "    <finding name=\"x\" severity=\"note\" condition=\"{Item} == 3\" text=\"t\"/>\n"
                              "  </node>\n"));
    EXPECT_TRUE(contains(f.messages(), "rules.xml:7: error: {Item} in the condition of finding 'x' is inside repeated node 'Items'"))
        << f.messages();
}

TEST(FindingEmit, RegistersOneExpertPerFindingAndChecksItAfterItsNode) {
    Front f = front_end(reply_with(kGood));
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, "static expert_field tst_finding_ei[1];")) << code;
    EXPECT_TRUE(contains(code, "{ &tst_finding_ei[0], { \"tst.finding.error_status\", PI_RESPONSE_CODE, PI_NOTE, "
                               "\"Service {Service} failed: {Status} ({Note})\", EXPFILL } }"))
        << code;
    EXPECT_TRUE(contains(code, "findings(tst_findings)")) << code;
    EXPECT_TRUE(contains(code, ".findings(0, 1)")) << code;
    // the condition's operations: Status, 0, !=
    EXPECT_TRUE(contains(code, "dg_op(DG_OP_NE)")) << code;
}

TEST(FindingEmit, FieldsListsEachFindingAsWiresharkRegistersIt) {
    Front f = front_end(reply_with(kGood));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_TRUE(contains(list_fields(*f.proto),
                         "tst.finding.error_status\tFT_NONE\tService {Service} failed: {Status} ({Note})\trules\n"))
        << list_fields(*f.proto);
}

// A <group> used twice copies its <finding>: one expert info registered and
// listed, raised by each use's own row.
TEST(FindingEmit, AGroupUsedTwiceRegistersItsFindingOnce) {
    Front f = front_end(rules("  <group name=\"Point\">\n"
                              "    <node name=\"X\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    <finding name=\"x_zero\" severity=\"warning\" condition=\"{X} == 0\" text=\"X is 0\"/>\n"
                              "  </group>\n"
                              "  <node name=\"From\"><use group=\"Point\"/></node>\n"
                              "  <node name=\"To\"><use group=\"Point\"/></node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, "static expert_field tst_finding_ei[1];")) << code;
    EXPECT_TRUE(contains(code, "/* x_zero, line 4 */ { &tst_finding_ei[0], 0, 3, 0, 1 }") &&
                contains(code, "/* x_zero, line 4 */ { &tst_finding_ei[0], 3, 3, 1, 1 }"))
        << code;
    const std::string fields = list_fields(*f.proto);
    EXPECT_EQ(fields.find("tst.finding.x_zero"), fields.rfind("tst.finding.x_zero")) << fields;
}

TEST(FindingEmit, NothingOfItWithoutFindings) {
    Front f = front_end(reply_with(""));
    ASSERT_TRUE(f.ok()) << f.messages();
    const std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_FALSE(contains(code, "finding")) << code;
}

// covers="XPATH": a computed value shown on another node's bytes (issue 40, item 4).
TEST(Covers, KeepsWhereItsNodeIsAndEmitsItsSlot) {
    Front f = front_end(rules("  <node name=\"Start\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Value\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
                              "  <node name=\"Number\" value=\"{Start} + 1\" covers=\"../node[@name='Value']\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* value = find(*f.proto, "Value");
    ASSERT_GE(value->slot, 0);  // its place is kept for the item
    EXPECT_EQ(find(*f.proto, "Number")->covers->target, value);
    const std::string code = emit_cpp(*f.proto, "t.xml");
    EXPECT_TRUE(contains(code, ".covers(" + std::to_string(value->slot) + ")")) << code;
}

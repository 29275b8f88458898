// SPDX-License-Identifier: GPL-2.0-or-later
// Rule files as data, one test per file (found at run time, so adding a file
// adds a test):
//   tests/rules_err/*.xml  one mistake each; the first line is
//                          <!-- expect: LINE: error: MESSAGE-SUBSTRING -->
//                          and the front end must fail with that diagnostic;
//                          a mistake that also stops other checks lists each
//                          further error on a line of its own, no more.
//   tests/rules_ok/*.xml   tricky but valid; no error. Leading lines
//                          <!-- expect: LINE: warning: SUBSTRING --> name
//                          warnings that must appear.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <sstream>

#include "emit_cpp.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

namespace fs = std::filesystem;

struct Expectation {
    int line = 0;
    std::string severity;  // "error" or "warning"
    std::string text;
};

// The expect comments at the top of a file, in order.
std::vector<Expectation> expectations(const std::string& content) {
    static const std::regex expect(R"(^<!--\s*expect:\s*(\d+):\s*(error|warning):\s*(.*?)\s*-->\s*$)");
    std::vector<Expectation> out;
    std::istringstream in(content);
    std::string line;
    while (std::getline(in, line)) {
        std::smatch m;
        if (!std::regex_match(line, m, expect)) break;
        out.push_back({std::stoi(m[1].str()), m[2].str(), m[3].str()});
    }
    return out;
}

std::vector<std::string> rule_files(const std::string& folder) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(source_path(folder), ec))
        if (entry.is_regular_file() && entry.path().extension() == ".xml") names.push_back(entry.path().filename());
    std::sort(names.begin(), names.end());
    return names;
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string stem = fs::path(info.param).stem().string();
    for (char& c : stem)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return stem;
}

// True when one diagnostic line is "rules.xml:LINE: SEVERITY: ..." and contains the text.
bool has_diagnostic(const std::string& messages, const Expectation& e) {
    const std::string prefix = "rules.xml:" + std::to_string(e.line) + ": " + e.severity + ": ";
    std::istringstream in(messages);
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(prefix, 0) == 0 && line.find(e.text, prefix.size()) != std::string::npos) return true;
    return false;
}

class RulesErr : public ::testing::TestWithParam<std::string> {};
class RulesOk : public ::testing::TestWithParam<std::string> {};

TEST_P(RulesErr, ReportsTheExpectedError) {
    const std::string path = source_path("tests/rules_err/" + GetParam());
    const std::string content = read_file(path);
    auto expected = expectations(content);
    ASSERT_FALSE(expected.empty()) << path << ": the first line must be <!-- expect: LINE: error: MESSAGE -->";
    ASSERT_EQ(expected.front().severity, "error") << path;

    Front f = front_end(content);
    EXPECT_FALSE(f.ok()) << path << " was accepted:\n" << f.messages();
    for (const Expectation& e : expected)
        EXPECT_TRUE(has_diagnostic(f.messages(), e))
            << path << ": expected rules.xml:" << e.line << ": " << e.severity << ": ..." << e.text
            << "...\ngot:\n" << f.messages();
    // one diagnostic a line, each in the FILE:LINE: form (not_utf8.xml: libxml2's
    // message goes on over a second line), and no error the file does not expect:
    // a check that also fires where it should not is a bug too
    std::istringstream lines(f.messages());
    size_t errors = 0;
    for (std::string line; std::getline(lines, line);) {
        EXPECT_EQ(line.rfind("rules.xml:", 0), 0u) << path << ": a line that is no diagnostic: " << line;
        if (line.find(": error: ") != std::string::npos) ++errors;
    }
    size_t expected_errors = static_cast<size_t>(
        std::count_if(expected.begin(), expected.end(), [](const Expectation& e) { return e.severity == "error"; }));
    EXPECT_EQ(errors, expected_errors) << path << ": every error needs its expect line; got:\n" << f.messages();
}

TEST_P(RulesOk, IsAcceptedAndGenerates) {
    const std::string path = source_path("tests/rules_ok/" + GetParam());
    const std::string content = read_file(path);
    Front f = front_end(content);
    ASSERT_TRUE(f.ok()) << path << ":\n" << f.messages();
    for (const Expectation& e : expectations(content)) {
        EXPECT_EQ(e.severity, "warning") << path << ": a valid file expects warnings only";
        EXPECT_TRUE(has_diagnostic(f.messages(), e))
            << path << ": expected rules.xml:" << e.line << ": " << e.severity << ": ..." << e.text
            << "...\ngot:\n" << f.messages();
    }
    // The later stages take every valid file.
    std::string code = emit_cpp(*f.proto, GetParam());
    EXPECT_NE(code.find("DG_DECLARE_PLUGIN(proto_register_" + f.proto->filter), std::string::npos);
    EXPECT_FALSE(list_fields(*f.proto).empty());
}

INSTANTIATE_TEST_SUITE_P(Files, RulesErr, ::testing::ValuesIn(rule_files("tests/rules_err")), test_name);
INSTANTIATE_TEST_SUITE_P(Files, RulesOk, ::testing::ValuesIn(rule_files("tests/rules_ok")), test_name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(RulesErr);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(RulesOk);

// One mistake a file: its error first; the errors it also causes (a check it
// stops, a rule it breaks as well) follow, each expected on a line of its own.
TEST(RuleFolders, EveryErrorFileExpectsItsErrors) {
    auto files = rule_files("tests/rules_err");
    EXPECT_GE(files.size(), 100u) << "tests/rules_err looks incomplete";
    size_t with_consequences = 0;
    for (const std::string& name : files) {
        auto e = expectations(read_file(source_path("tests/rules_err/" + name)));
        ASSERT_FALSE(e.empty()) << name;
        for (const Expectation& x : e) {
            EXPECT_EQ(x.severity, "error") << name;
            EXPECT_GT(x.line, 0) << name;
        }
        if (e.size() > 1) ++with_consequences;
    }
    // a cascade is the exception: most mistakes are reported once
    EXPECT_LT(with_consequences * 5, files.size()) << with_consequences << " of " << files.size();
}

TEST(RuleFolders, ShippedRulesAreValid) {
    size_t seen = 0;
    for (const std::string folder : {"rules", "tests/rules"}) {
        for (const std::string& name : rule_files(folder)) {
            Front f = front_end(read_file(source_path(folder + "/" + name)));
            EXPECT_TRUE(f.ok()) << folder << "/" << name << ":\n" << f.messages();
            ++seen;
        }
    }
    EXPECT_GE(seen, 2u);
}

}  // namespace
}  // namespace dissgen::testing

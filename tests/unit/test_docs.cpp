// SPDX-License-Identifier: GPL-2.0-or-later
// Every ```xml example in the user documentation is a rule file that must
// behave as the text says: valid, or (when its first line is
// <!-- expect: LINE: error: MESSAGE -->) rejected with that diagnostic.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <vector>

#include "emit_cpp.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

struct Example {
    std::string doc;
    int doc_line;
    std::string xml;
};

// The rule files a document shows: ```xml blocks, and here-documents of a
// shell block that write a rule file (`cat > query.xml <<'END'` ... `END`,
// whose body is a <root>).
std::vector<Example> examples_in(const std::string& doc) {
    std::vector<Example> out;
    std::istringstream in(read_file(source_path(doc)));
    static const std::regex heredoc(R"(^cat > \S+\.xml <<'(\w+)'$)");
    std::string line, xml, end_marker;
    int number = 0, start = 0;
    bool inside = false;
    while (std::getline(in, line)) {
        ++number;
        std::smatch m;
        if (!inside && line.rfind("```xml", 0) == 0) {
            inside = true;
            end_marker = "```";
            start = number + 1;
            xml.clear();
        } else if (!inside && std::regex_match(line, m, heredoc)) {
            inside = true;
            end_marker = m[1].str();
            start = number + 1;
            xml.clear();
        } else if (inside && line.rfind(end_marker, 0) == 0) {
            inside = false;
            if (end_marker == "```" || xml.rfind("<root", 0) == 0) out.push_back({doc, start, xml});
        } else if (inside) {
            xml += line + "\n";
        }
    }
    return out;
}

void check_examples(const std::string& doc, size_t at_least) {
    std::vector<Example> examples = examples_in(doc);
    EXPECT_GE(examples.size(), at_least) << doc;
    static const std::regex expect(R"(^<!-- expect: (\d+): error: (.*) -->)");
    for (const Example& e : examples) {
        SCOPED_TRACE(e.doc + ":" + std::to_string(e.doc_line));
        Front f = front_end(e.xml);
        std::smatch m;
        if (std::regex_search(e.xml, m, expect)) {
            EXPECT_FALSE(f.ok());
            std::string wanted = "rules.xml:" + m[1].str() + ": error: " + m[2].str();
            EXPECT_NE(f.messages().find(wanted), std::string::npos) << f.messages() << "\nwanted: " << wanted;
        } else {
            ASSERT_TRUE(f.ok()) << f.messages();
            EXPECT_FALSE(emit_cpp(*f.proto, "example.xml").empty());
        }
    }
}

TEST(Docs, ManualExamplesBehaveAsDocumented) { check_examples("docs/manual.md", 10); }

TEST(Docs, ReadmeExamplesBehaveAsDocumented) { check_examples("README.md", 1); }

// A merge left unresolved leaves both sides and its markers in the text.
TEST(Docs, NoMergeConflictMarkers) {
    std::vector<std::string> docs = {"README.md"};
    for (const auto& e : std::filesystem::directory_iterator(source_path("docs")))
        if (e.path().extension() == ".md") docs.push_back("docs/" + e.path().filename().string());
    ASSERT_GT(docs.size(), 2u);
    for (const std::string& doc : docs) {
        std::istringstream in(read_file(source_path(doc)));
        int number = 0;
        for (std::string line; std::getline(in, line);) {
            ++number;
            const bool marker = line.rfind("<<<<<<< ", 0) == 0 || line.rfind(">>>>>>> ", 0) == 0 || line == "=======";
            EXPECT_FALSE(marker) << doc << ":" << number << ": a merge conflict marker: " << line;
        }
    }
}

TEST(Docs, ManualBitGroupMasksAreTheOnesItStates) {
    auto examples = examples_in("docs/manual.md");
    const Example* bits = nullptr;
    for (const Example& e : examples)
        if (e.xml.find("abbreviation=\"BITS\"") != std::string::npos) bits = &e;
    ASSERT_NE(bits, nullptr);
    Front f = front_end(bits->xml);
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node& control = *f.proto->nodes[0];
    EXPECT_EQ(field_type(*control.children[0]).mask, 0x07ffu);  // Length
    EXPECT_EQ(field_type(*control.children[3]).mask, 0x8000u);  // More
    const Node& flags = *f.proto->nodes[1];
    EXPECT_EQ(field_type(*flags.children[0]).mask, 0xe0u);      // Version
    EXPECT_EQ(field_type(*flags.children[1]).mask, 0x1fu);      // Priority
    EXPECT_EQ(flags.children[1]->display, Display::NumberHex);
}

TEST(Docs, ManualNamingExampleGivesTheNamesItStates) {
    for (const Example& e : examples_in("docs/manual.md")) {
        if (e.xml.find("abbreviation=\"NAME\"") == std::string::npos) continue;
        Front f = front_end(e.xml);
        ASSERT_TRUE(f.ok()) << f.messages();
        std::string fields = list_fields(*f.proto);
        for (const char* name : {"name.working_counter_wkc\t", "name.cmd\t", "name.type\t"})
            EXPECT_NE(fields.find(name), std::string::npos) << fields;
        // The listing the manual shows is how `dissgen fields` begins.
        const std::string manual = read_file(source_path("docs/manual.md"));
        const std::string marker = "$ dissgen fields naming.xml\n";
        size_t at = manual.find(marker);
        ASSERT_NE(at, std::string::npos);
        at += marker.size();
        std::string shown = manual.substr(at, manual.find("...\n", at) - at);
        EXPECT_EQ(fields.substr(0, shown.size()), shown);
        return;
    }
    FAIL() << "naming example not found";
}

}  // namespace
}  // namespace dissgen::testing

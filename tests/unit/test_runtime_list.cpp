// SPDX-License-Identifier: GPL-2.0-or-later
// plugin_runtime/runtime.list, the one list of the runtime's files, the
// analyses and the options of plugin code: how it is read, that the copy
// built into dissgen is the file in the tree, that it names every file of
// plugin_runtime/ (what CMake installs and the mutation generator mutates)
// and only existing ones, and what `dissgen sources` prints from it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "runtime_list.h"

namespace dissgen::testing {
namespace {

namespace fs = std::filesystem;

const fs::path kRuntimeDir = fs::path(DISSGEN_SOURCE_DIR) / "plugin_runtime";

RuntimeList parsed(const std::string& text) {
    RuntimeList list;
    std::string error;
    EXPECT_TRUE(parse_runtime_list(text, list, error)) << error;
    return list;
}

std::string parse_error(const std::string& text) {
    RuntimeList list;
    std::string error;
    EXPECT_FALSE(parse_runtime_list(text, list, error));
    return error;
}

std::vector<std::string> every_file(const RuntimeList& list) {
    std::vector<std::string> files = list.sources;
    files.insert(files.end(), list.headers.begin(), list.headers.end());
    for (const Analysis& a : list.analyses) {
        files.insert(files.end(), a.runtime_sources.begin(), a.runtime_sources.end());
        files.insert(files.end(), a.runtime_headers.begin(), a.runtime_headers.end());
    }
    return files;
}

TEST(RuntimeList, RepeatedKindsAddUpAndLinesAfterAnAnalysisAreItsOwn) {
    RuntimeList list = parsed(
        "# comment\n"
        "flags -DA -fno-plt\n"
        "\n"
        "source a.cpp b.cpp\n"
        "source c.cpp\n"
        "header a.h\n"
        "analysis one dg_one\n"
        "  source one/x.cpp\n"
        "  header one/x.h\n"
        "analysis two dg_two\n"
        "flags -DB\n");
    EXPECT_EQ(list.flags, (std::vector<std::string>{"-DA", "-fno-plt", "-DB"}));
    EXPECT_EQ(list.sources, (std::vector<std::string>{"a.cpp", "b.cpp", "c.cpp"}));
    EXPECT_EQ(list.headers, (std::vector<std::string>{"a.h"}));
    ASSERT_EQ(list.analyses.size(), 2u);
    EXPECT_EQ(list.analyses[0].name, "one");
    EXPECT_EQ(list.analyses[0].symbol, "dg_one");
    EXPECT_EQ(list.analyses[0].runtime_sources, (std::vector<std::string>{"one/x.cpp"}));
    EXPECT_EQ(list.analyses[0].runtime_headers, (std::vector<std::string>{"one/x.h"}));
    EXPECT_TRUE(list.analyses[1].runtime_sources.empty());
}

TEST(RuntimeList, MistakesNameTheirLine) {
    EXPECT_EQ(parse_error("source a.cpp\nsources b.cpp\n"),
              "2: unknown entry 'sources' (flags, source, header, analysis)");
    EXPECT_EQ(parse_error("\n\nanalysis lonely\n"), "3: 'analysis' takes a name and its dg_analysis symbol");
    EXPECT_EQ(parse_error("header\n"), "1: 'header' lists nothing");
}

TEST(RuntimeList, BuiltInCopyIsTheFileInTheTree) {
    std::ifstream in(kRuntimeDir / "runtime.list");
    ASSERT_TRUE(in) << "cannot read " << (kRuntimeDir / "runtime.list");
    std::stringstream text;
    text << in.rdbuf();
    RuntimeList from_tree = parsed(text.str());
    const RuntimeList& built_in = runtime_list();
    EXPECT_EQ(every_file(built_in), every_file(from_tree));
    EXPECT_EQ(built_in.flags, from_tree.flags);
    ASSERT_EQ(built_in.analyses.size(), from_tree.analyses.size());
    for (size_t i = 0; i < built_in.analyses.size(); ++i) {
        EXPECT_EQ(built_in.analyses[i].name, from_tree.analyses[i].name);
        EXPECT_EQ(built_in.analyses[i].symbol, from_tree.analyses[i].symbol);
    }
}

// Every source and header of plugin_runtime/ is listed (else CMake would not
// install it and no mutant would test it), once, and every listed file exists.
TEST(RuntimeList, NamesEveryFileOfTheRuntimeOnce) {
    std::set<std::string> in_tree;
    for (const auto& entry : fs::recursive_directory_iterator(kRuntimeDir)) {
        std::string ext = entry.path().extension().string();
        if (ext == ".cpp" || ext == ".h") in_tree.insert(fs::relative(entry.path(), kRuntimeDir).generic_string());
    }
    std::vector<std::string> listed = every_file(runtime_list());
    std::set<std::string> listed_once(listed.begin(), listed.end());
    EXPECT_EQ(listed_once.size(), listed.size()) << "a file listed twice";
    EXPECT_EQ(listed_once, in_tree);
}

TEST(RuntimeList, SourcesTextHasTheGenericRuntimeAndTheAnalysesAsked) {
    RuntimeList list = parsed(
        "flags -DA -DB\nsource a.cpp\nheader a.h\n"
        "analysis one dg_one\nsource one/x.cpp\nheader one/x.h\n"
        "analysis two dg_two\nsource two/y.cpp\n");
    EXPECT_EQ(runtime_files_text(list, {}), "flags -DA -DB\nsource a.cpp\nheader a.h\n");
    EXPECT_EQ(runtime_files_text(list, {&list.analyses[1]}),
              "flags -DA -DB\nsource a.cpp\nsource two/y.cpp\nheader a.h\n");
    EXPECT_EQ(runtime_files_text(list, {&list.analyses[0], &list.analyses[1]}),
              "flags -DA -DB\nsource a.cpp\nsource one/x.cpp\nsource two/y.cpp\nheader a.h\nheader one/x.h\n");
}

}  // namespace
}  // namespace dissgen::testing

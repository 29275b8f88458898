// SPDX-License-Identifier: GPL-2.0-or-later
// Which packaged plugin in Wireshark's global folder a new plugin competes
// with (generator/packaged_plugins.cpp): the one built from a rule file whose
// protocol shares a name, never a file set aside or another protocol's.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "packaged_plugins.h"
#include "test_support.h"

namespace fs = std::filesystem;
using namespace dissgen;
using dissgen::testing::source_path;

namespace {

class PackagedPlugins : public ::testing::Test {
protected:
    void SetUp() override {
        ASSERT_FALSE(root.empty());
        fs::create_directories(root / "plugins");
        fs::create_directories(root / "rules");
        fs::copy_file(source_path("rules/enip.xml"), root / "rules" / "enip.xml");
        fs::copy_file(source_path("rules/profinet.xml"), root / "rules" / "profinet.xml");
    }

    void plugin(const std::string& name) { std::ofstream(root / "plugins" / name) << "ELF"; }
    PackagedPlugin lookup(const std::string& rules) {
        Diagnostics d;
        auto p = parse_rule_file(source_path(rules), d);
        EXPECT_TRUE(p) << d.format(rules);
        return packaged_plugin_for(*p, (root / "plugins").string(), (root / "rules").string());
    }

    dissgen::testing::TempDir tmp{"dissgen-packaged-test"};
    fs::path root = tmp.path();
};

TEST_F(PackagedPlugins, TheOneOfTheSameProtocol) {
    plugin("dissgen-packaged-profinet.so");
    plugin("dissgen-packaged-enip.so");
    PackagedPlugin found = lookup("rules/enip.xml");
    EXPECT_EQ(found.plugin, (root / "plugins" / "dissgen-packaged-enip.so").string());
    EXPECT_EQ(found.filter, "enipr");
}

TEST_F(PackagedPlugins, NoneForAnotherProtocolOrAFileSetAside) {
    plugin("dissgen-packaged-profinet.so");
    plugin("dissgen-packaged-enip.so.disabled");   // dpkg-divert's name for it
    plugin("dissgen-packaged-.so");
    plugin("dissgen_enip.so");                      // a per-user build's name
    EXPECT_EQ(lookup("rules/enip.xml").plugin, "");
    EXPECT_EQ(lookup("rules/powerlink.xml").plugin, "");
}

TEST_F(PackagedPlugins, NoneWithoutItsRuleFileOrFolder) {
    plugin("dissgen-packaged-enip.so");
    fs::remove(root / "rules" / "enip.xml");
    EXPECT_EQ(lookup("rules/enip.xml").plugin, "");
    fs::remove_all(root / "plugins");
    EXPECT_EQ(lookup("rules/enip.xml").plugin, "");
}

}  // namespace

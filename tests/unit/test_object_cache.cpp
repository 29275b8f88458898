// SPDX-License-Identifier: GPL-2.0-or-later
// The object cache of `dissgen install` (generator/object_cache.cpp): an object is
// reused exactly when nothing that decides it changed, whatever the temporary folder.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "object_cache.h"
#include "test_support.h"

namespace fs = std::filesystem;
using dissgen::CompileJob;
using dissgen::compile_objects;

namespace {

class ObjectCache : public ::testing::Test {
protected:
    void SetUp() override {
        ASSERT_FALSE(root.empty());
        fs::create_directories(root / "runtime");
        write("runtime/shared.h", "#define ANSWER 42\n");
        write("runtime/part.cpp", "#include \"shared.h\"\nint part() { return ANSWER; }\n");
    }

    void write(const std::string& rel, const std::string& text) { std::ofstream(root / rel) << text; }

    // A job as build_plugin.cpp makes one: the generated source in a fresh work folder.
    CompileJob job(const std::string& work, const std::string& generated) {
        fs::create_directories(root / work);
        write(work + "/gen.cpp", generated);
        return CompileJob{{"c++", "-O0", "-I" + (root / "runtime").string()},
                          {(root / work / "gen.cpp").string(), (root / "runtime/part.cpp").string()},
                          {(root / "runtime/shared.h").string()},
                          (root / "cache").string(),
                          (root / work).string(),
                          "Wireshark 4.0.0"};
    }

    static std::vector<std::string> compiled(const CompileJob& j) {
        std::vector<std::string> objects;
        std::string error = compile_objects(j, objects);
        EXPECT_EQ(error, "");
        for (const std::string& o : objects) EXPECT_TRUE(fs::exists(o)) << o;
        return objects;
    }

    dissgen::testing::TempDir tmp{"dissgen-cache-test"};
    fs::path root = tmp.path();
};

TEST_F(ObjectCache, SameInputsInAnotherWorkFolderReuseTheObjects) {
    std::vector<std::string> first = compiled(job("work1", "int gen() { return 1; }\n"));
    ASSERT_EQ(first.size(), 2u);
    EXPECT_EQ(fs::path(first[0]).parent_path(), root / "cache");
    auto written = fs::last_write_time(first[1]);
    std::vector<std::string> second = compiled(job("work2", "int gen() { return 1; }\n"));
    EXPECT_EQ(first, second);
    EXPECT_EQ(fs::last_write_time(second[1]), written);  // not compiled again
}

TEST_F(ObjectCache, AnEditedSourceHeaderOptionOrVersionMakesANewObject) {
    std::vector<std::string> base = compiled(job("w", "int gen() { return 1; }\n"));
    std::vector<std::string> edited = compiled(job("w", "int gen() { return 2; }\n"));
    EXPECT_NE(base[0], edited[0]);
    EXPECT_EQ(base[1], edited[1]);  // the runtime's unit did not change

    write("runtime/shared.h", "#define ANSWER 43\n");
    std::vector<std::string> header = compiled(job("w", "int gen() { return 1; }\n"));
    EXPECT_NE(header[0], base[0]);
    EXPECT_NE(header[1], base[1]);

    CompileJob optimised = job("w", "int gen() { return 1; }\n");
    optimised.compiler.push_back("-O2");
    EXPECT_NE(compiled(optimised)[1], header[1]);
    CompileJob other = job("w", "int gen() { return 1; }\n");
    other.salt = "Wireshark 4.2.0";
    EXPECT_NE(compiled(other)[1], header[1]);
}

TEST_F(ObjectCache, ACompileErrorIsReportedAndNothingIsKept) {
    CompileJob broken = job("w", "int gen() { return }\n");
    std::vector<std::string> objects;
    std::string error = compile_objects(broken, objects);
    EXPECT_NE(error.find("compiling the plugin failed"), std::string::npos) << error;
    EXPECT_NE(error.find("gen.cpp"), std::string::npos) << error;
    ASSERT_EQ(objects.size(), 2u);
    EXPECT_FALSE(fs::exists(objects[0]));
    for (const auto& entry : fs::directory_iterator(root / "cache"))
        EXPECT_EQ(entry.path().extension(), ".o") << entry.path();  // no partial object left
}

TEST_F(ObjectCache, WithoutAUsableCacheTheObjectsGoToTheWorkFolder) {
    CompileJob j = job("w", "int gen() { return 1; }\n");
    j.cache_dir = "";
    std::vector<std::string> objects = compiled(j);
    for (const std::string& o : objects) EXPECT_EQ(fs::path(o).parent_path(), root / "w");
    EXPECT_FALSE(fs::exists(root / "cache"));
}

}  // namespace

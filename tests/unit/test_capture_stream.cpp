// SPDX-License-Identifier: GPL-2.0-or-later
// How dissgen report reads a capture through tshark (generator/report/capture_stream.cpp),
// with a stand-in for tshark: its rows reach the caller, its failure is said with its
// message, and a tshark that cannot be started leaves no descriptor open behind it.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "report/capture_stream.h"
#include "test_support.h"

namespace fs = std::filesystem;
using namespace dissgen;

namespace {

std::set<int> open_descriptors() {
    std::set<int> fds;
    for (const auto& e : fs::directory_iterator("/proc/self/fd")) fds.insert(std::atoi(e.path().filename().c_str()));
    std::set<int> still;  // the directory's own descriptor is closed again by now
    for (int fd : fds)
        if (fcntl(fd, F_GETFD) != -1) still.insert(fd);
    return still;
}

class CaptureStreamTest : public ::testing::Test {
protected:
    void SetUp() override { ASSERT_FALSE(root.empty()); }

    // A stand-in for tshark: a shell script.
    std::string fake_tshark(const std::string& body) {
        fs::path p = root / "tshark";
        std::ofstream(p) << "#!/bin/sh\n" << body << "\n";
        chmod(p.c_str(), 0755);
        return p.string();
    }

    dissgen::testing::TempDir tmp{"dissgen-stream-test"};
    fs::path root = tmp.path();
};

TEST_F(CaptureStreamTest, RowsOfTheFieldsAskedFor) {
    CaptureStream s;
    s.tshark = fake_tshark("printf '1\\t0x01,0x02\\t\\n2\\t\\tlast\\nnot a row\\n'");
    s.fields = {"frame.number", "x.values", "x.text"};
    std::vector<std::string> others;
    s.on_other_line = [&](std::string_view l) { others.emplace_back(l); };
    std::vector<std::vector<std::string>> rows;
    std::string err = read_capture(s, {"c.pcap"}, [&](const FieldRow& r) {
        rows.emplace_back(r.begin(), r.end());
    });
    EXPECT_EQ(err, "");
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0], (std::vector<std::string>{"1", "0x01,0x02", ""}));
    EXPECT_EQ(rows[1], (std::vector<std::string>{"2", "", "last"}));
    EXPECT_EQ(others, std::vector<std::string>{"not a row"});
}

TEST_F(CaptureStreamTest, AFailureSaysTsharksMessage) {
    CaptureStream s;
    s.tshark = fake_tshark("echo 'tshark: The file \"c.pcap\" does not exist.' >&2\nexit 2");
    s.fields = {"frame.number"};
    std::string err = read_capture(s, {"c.pcap"}, [](const FieldRow&) {});
    EXPECT_EQ(err, s.tshark + " failed on c.pcap: tshark: The file \"c.pcap\" does not exist.");
}

// With room for one pipe only, the second fails: tshark cannot start, and the first
// pipe's two ends are closed again.
TEST_F(CaptureStreamTest, NoDescriptorLeftWhenTsharkCannotStart) {
    CaptureStream s;
    s.tshark = fake_tshark("exit 0");
    s.fields = {"frame.number"};
    const std::set<int> before = open_descriptors();
    int limit = 0;
    for (int free_below = 0; free_below < 2; ++limit)
        if (!before.count(limit)) ++free_below;
    rlimit saved;
    ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &saved), 0);
    rlimit tight = saved;
    tight.rlim_cur = static_cast<rlim_t>(limit);
    ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &tight), 0);
    std::string err = read_capture(s, {"c.pcap"}, [](const FieldRow&) {});
    ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &saved), 0);
    EXPECT_EQ(err.rfind("cannot start " + s.tshark + ": ", 0), 0u) << err;
    EXPECT_EQ(open_descriptors(), before);
}

}  // namespace

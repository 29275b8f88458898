// SPDX-License-Identifier: GPL-2.0-or-later
// dissgen report's model: tshark's text parsed exactly, figures by nearest
// rank, rows folded into cycles, returns, losses and slave states.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "report/report_html.h"
#include "report/timing_model.h"

using namespace dissgen;

namespace {

TEST(ReportParse, RelativeTimesToTheNanosecond) {
    int64_t ns = 0;
    ASSERT_TRUE(parse_seconds_ns("0.001000250", ns));
    EXPECT_EQ(ns, 1000250);
    ASSERT_TRUE(parse_seconds_ns("-0.000003000", ns));
    EXPECT_EQ(ns, -3000);
    ASSERT_TRUE(parse_seconds_ns("0.089000000", ns));  // a leading 0 is not octal
    EXPECT_EQ(ns, 89000000);
    ASSERT_TRUE(parse_seconds_ns("2.5", ns));
    EXPECT_EQ(ns, 2500000000);
    ASSERT_TRUE(parse_seconds_ns("12", ns));
    EXPECT_EQ(ns, 12000000000);
    EXPECT_FALSE(parse_seconds_ns("", ns));
    EXPECT_FALSE(parse_seconds_ns("0.00x", ns));
    EXPECT_FALSE(parse_seconds_ns("--1.0", ns));
}

TEST(ReportParse, NamesOfCommandsAndStates) {
    EXPECT_EQ(ethercat_command_name(12), "LRW");
    EXPECT_EQ(ethercat_command_name(14), "FRMW");
    EXPECT_EQ(ethercat_command_name(0), "NOP");
    EXPECT_EQ(ethercat_command_name(15), "cmd 0x0f");
    EXPECT_EQ(al_state_name(0x0008), "OP");
    EXPECT_EQ(al_state_name(0x0014), "SAFEOP");  // the error bit is not the state
    EXPECT_EQ(al_state_name(0x0003), "BOOT");
    EXPECT_EQ(al_state_name(0x0005), "0x5");
}

TEST(ReportSpread, NearestRankAndPopulationDeviation) {
    std::vector<int64_t> v;
    for (int64_t i = 1; i <= 200; ++i) v.push_back(i);
    Spread s = spread_of(v);
    EXPECT_EQ(s.count, 200u);
    EXPECT_EQ(s.min, 1);
    EXPECT_EQ(s.median, 100);  // the lower of the two middle values
    EXPECT_EQ(s.p99, 198);     // rank ceil(0.99 * 200) = 198
    EXPECT_EQ(s.max, 200);
    Spread one = spread_of({7});
    EXPECT_EQ(one.median, 7);
    EXPECT_EQ(one.p99, 7);
    EXPECT_DOUBLE_EQ(one.stddev, 0);
    EXPECT_EQ(spread_of({1, 2, 3}).median, 2);
    std::vector<int64_t> hundred;
    for (int64_t i = 1; i <= 100; ++i) hundred.push_back(i);
    EXPECT_EQ(spread_of(hundred).p99, 99);  // rank 99, not 100 (0.99 * 100 is not exact in binary)
    Spread pair = spread_of({-3, 3});
    EXPECT_EQ(pair.median, -3);
    EXPECT_DOUBLE_EQ(pair.stddev, 3);
    EXPECT_EQ(spread_of({}).count, 0u);
}

// Rows as tshark writes them for TimingModelBuilder::timing_fields().
struct Rows {
    std::vector<std::string> fields = TimingModelBuilder::timing_fields(
        {"frame.number", "frame.time_epoch", "ecatr.cycle", "ecatr.cycle.period", "ecatr.cycle.jitter",
         "ecatr.datagram.cmd", "ecatr.datagram.adp", "ecatr.datagram.ado", "ecatr.datagram.lad",
         "ecatr.datagram.len", "ecatr.datagram.wkc", "ecatr.esc.wkc_added", "ecatr.time", "ecatr.request_in",
         "ecatr.no_response_to", "ecatr.expert.wkc", "ecatr.slave.position", "ecatr.slave.name",
         "ecatr.datagram.reg.alstatus.status"});
    std::vector<std::vector<std::string>> text;
    void add(std::initializer_list<std::pair<const char*, std::string>> values) {
        std::vector<std::string> row(fields.size());
        for (auto& [name, value] : values)
            for (size_t i = 0; i < fields.size(); ++i)
                if (fields[i] == name) row[i] = value;
        text.push_back(row);
    }
    void feed(TimingModel& m) {
        TimingModelBuilder b(fields, m);
        for (auto& r : text) {
            FieldRow row(r.begin(), r.end());
            b.add(row);
        }
    }
};

TEST(ReportModel, CyclesReturnsLossesAndStates) {
    const std::string sep(1, kValueSeparator);
    Rows r;
    EXPECT_EQ(r.fields.size(), 19u);  // only the fields tshark knows are asked for
    r.add({{"frame.number", "1"}, {"frame.time_epoch", "100.000000000"}, {"ecatr.cycle", "1"},
           {"ecatr.datagram.cmd", "0x0c" + sep + "0x0e"}, {"ecatr.datagram.adp", "0x1001"},
           {"ecatr.datagram.ado", "0x0910"}, {"ecatr.datagram.lad", "0x00010000"},
           {"ecatr.datagram.len", "4" + sep + "8"}});
    r.add({{"frame.number", "2"}, {"frame.time_epoch", "100.000050000"}, {"ecatr.time", "0.000050000"},
           {"ecatr.request_in", "1"}, {"ecatr.expert.wkc", "1"}, {"ecatr.datagram.wkc", "3" + sep + "1"},
           {"ecatr.esc.wkc_added", "3" + sep + "0"}});
    r.add({{"frame.number", "3"}, {"frame.time_epoch", "100.001002000"}, {"ecatr.cycle", "1"},
           {"ecatr.cycle.period", "0.001002000"}, {"ecatr.cycle.jitter", "0.000002000"}});
    r.add({{"frame.number", "4"}, {"frame.time_epoch", "100.200000000"}, {"ecatr.no_response_to", "3"},
           {"ecatr.request_in", "9"}, {"ecatr.slave.position", "0" + sep + "1"},
           {"ecatr.slave.name", "EK1100" + sep + "EL1004"},
           {"ecatr.datagram.reg.alstatus.status", "0x0002" + sep + "0x0008"}});
    r.add({{"frame.number", "5"}, {"frame.time_epoch", "100.300000000"}, {"ecatr.request_in", "9"},
           {"ecatr.slave.position", "1"}, {"ecatr.datagram.reg.alstatus.status", "0x0008"}});
    TimingModel m;
    r.feed(m);
    EXPECT_EQ(m.frames, 5u);
    EXPECT_NEAR(m.duration, 0.3, 1e-9);
    ASSERT_EQ(m.cycles.size(), 1u);
    const Cycle& c = m.cycles.at(1);
    EXPECT_EQ(c.signature, "LRW 0x00010000 (4 bytes), FRMW 0x1001:0x0910 (8 bytes)");
    EXPECT_EQ(c.frames, 2u);
    ASSERT_EQ(c.period.size(), 1u);
    EXPECT_EQ(c.period[0].ns, 1002000);
    EXPECT_EQ(c.jitter[0].ns, 2000);
    ASSERT_EQ(c.round_trip.size(), 1u);
    EXPECT_EQ(c.round_trip[0].ns, 50000);
    EXPECT_EQ(c.wkc_errors, 1u);  // the FRMW's counter was not raised
    EXPECT_EQ(c.nominal, 1000000);
    EXPECT_EQ(c.returned, 1u);
    EXPECT_EQ(c.lost(), 0u);  // frame 3 may still be in flight: no later frame came back
    ASSERT_EQ(m.lost.size(), 1u);
    EXPECT_EQ(m.lost[0].frame, 3u);
    EXPECT_EQ(m.lost[0].cycle, 1u);
    ASSERT_EQ(m.slaves.size(), 2u);
    EXPECT_EQ(m.slaves.at(0).name, "EK1100");
    EXPECT_EQ(m.slaves.at(1).name, "EL1004");
    ASSERT_EQ(m.slaves.at(1).states.size(), 1u);  // OP twice: one state, no change
    EXPECT_EQ(m.slaves.at(1).states[0].second, 8u);
}

TEST(ReportModel, LostAreUnansweredBeforeTheLatestAnswered) {
    Cycle c;
    c.sent = {10, 20, 30, 40, 50};
    c.answered = {10, 40, 20};  // 30 lost; 50 in flight
    EXPECT_EQ(c.lost(), 1u);
    c.answered = {};
    EXPECT_EQ(c.lost(), 0u);
}

TEST(ReportModel, StatusesNotMatchingTheSlavesAreNotGuessed) {
    const std::string sep(1, kValueSeparator);
    Rows r;
    r.add({{"frame.number", "1"}, {"frame.time_epoch", "1.0"}, {"ecatr.request_in", "0"},
           {"ecatr.slave.position", "4"}, {"ecatr.datagram.reg.alstatus.status", "0x0002" + sep + "0x0004"}});
    TimingModel m;
    r.feed(m);
    EXPECT_TRUE(m.slaves.empty());
}

TEST(ReportChart, LongSeriesKeepEveryExtreme) {
    std::vector<TimedValue> series;
    for (int i = 0; i < 100000; ++i) series.push_back({i * 0.001, 1000000 + (i == 77777 ? 5000000 : i % 7)});
    std::string json = series_json(series, 100);
    size_t points = 0;
    for (size_t at = json.find("],["); at != std::string::npos; at = json.find("],[", at + 1)) ++points;
    EXPECT_LE(points, 101u);
    EXPECT_NE(json.find("6000.000]"), std::string::npos) << "the spike's maximum is drawn";
    std::string short_json = series_json({{0.5, 1500}, {1.0, -250}}, 100);
    EXPECT_EQ(short_json, "[[0.500000,[1.500,1.500,1.500]],[1.000000,[-0.250,-0.250,-0.250]]]");
}

// A curve longer than the report draws (4 000 points) becomes one point per time
// bucket: [first time of the bucket, [min, mean, max]] of exactly the values in it.
// Times in quarters over 3 000 s: 12 001 values, buckets 0.75 s wide with no rounding,
// three values each and the last value (at the end) in the last bucket.
TEST(ReportChart, DownsampledBucketsHoldTheMinMeanMaxOfTheirValues) {
    const size_t buckets = 4000;
    std::vector<TimedValue> series;
    uint32_t lcg = 12345;
    for (int i = 0; i <= 12000; ++i) {
        lcg = lcg * 1103515245u + 12345u;
        series.push_back({i * 0.25, static_cast<int64_t>(lcg >> 8) % 2000001 - 1000000});
    }
    struct Bucket {
        double t = -1;
        int64_t lo = 0, hi = 0;
        double sum = 0;
        size_t n = 0;
    };
    std::vector<Bucket> want(buckets);
    for (const TimedValue& v : series) {
        Bucket& b = want[std::min(static_cast<size_t>(v.t / 0.75), buckets - 1)];
        if (b.n == 0) b.t = v.t, b.lo = b.hi = v.ns;
        b.lo = std::min(b.lo, v.ns), b.hi = std::max(b.hi, v.ns), b.sum += static_cast<double>(v.ns), ++b.n;
    }
    ASSERT_EQ(want.back().n, 4u);
    std::string json = series_json(series, buckets);
    const char* at = json.c_str();
    ASSERT_EQ(*at++, '[');
    for (size_t i = 0; i < buckets; ++i) {
        double t, lo, mean, hi;
        int used = 0;
        ASSERT_EQ(std::sscanf(at, "[%lf,[%lf,%lf,%lf]]%n", &t, &lo, &mean, &hi, &used), 4) << "point " << i;
        at += used;
        ASSERT_EQ(*at, i + 1 < buckets ? ',' : ']') << "point " << i;
        ++at;
        const Bucket& b = want[i];
        EXPECT_DOUBLE_EQ(t, b.t) << "point " << i;
        EXPECT_NEAR(lo, static_cast<double>(b.lo) / 1000.0, 0.0005) << "point " << i;
        EXPECT_NEAR(hi, static_cast<double>(b.hi) / 1000.0, 0.0005) << "point " << i;
        EXPECT_NEAR(mean, b.sum / static_cast<double>(b.n) / 1000.0, 0.0005) << "point " << i;
        if (::testing::Test::HasFailure()) return;  // one bucket's report is enough
    }
    EXPECT_EQ(*at, '\0');
}

// The histogram's bins are whole nanoseconds, (max - min) / 80 + 1 wide,
// from the smallest value: at most 80 of them, whatever the values' sign.
TEST(ReportChart, HistogramBinsSpanTheValues) {
    std::string json = histogram_json({{0.0, 1000}, {0.1, 1010}, {0.2, 1011}, {0.3, 1800}});
    // 800 ns wide: 11 ns bins, 73 of them (the last from 1792 ns), then the closing one.
    EXPECT_EQ(json.rfind("[[1.000,2],[1.011,1],[1.022,0],", 0), 0u) << json;
    EXPECT_NE(json.find(",[1.792,1],[1.803,0]]"), std::string::npos) << json;
    size_t entries = 0;
    for (size_t at = json.find("],["); at != std::string::npos; at = json.find("],[", at + 1)) ++entries;
    EXPECT_EQ(entries + 1, 74u);
    std::string negative = histogram_json({{0.0, -500}, {0.1, 300}});
    EXPECT_EQ(negative.rfind("[[-0.500,1],[-0.489,0],", 0), 0u) << negative;
    EXPECT_EQ(histogram_json({}), "[]");
    EXPECT_EQ(histogram_json({{0.0, 7}}), "[[0.007,1],[0.008,0]]");
}

TEST(ReportPage, SelfContainedAndEscaped) {
    TimingModel m;
    m.capture = "/x/<evil>.pcap";
    m.has_cycle_fields = true;
    Cycle& c = m.cycles[1];
    c.number = 1;
    c.signature = "LRW 0x1 + </script>";
    c.frames = 3;
    c.period = {{0.001, 1000000}, {0.002, 1000000}};
    std::ostringstream out;
    std::string error = write_report_html(m, "test", out);
    if (error.find("dygraphs") != std::string::npos) GTEST_SKIP() << error;
    ASSERT_EQ(error, "");
    std::string page = out.str();
    EXPECT_EQ(page.find("<evil>"), std::string::npos);
    EXPECT_NE(page.find("&lt;evil&gt;.pcap"), std::string::npos);
    EXPECT_NE(page.find("\\u003c/script>"), std::string::npos) << "no </script> inside the data";
    EXPECT_NE(page.find("<td>1000.000</td>"), std::string::npos);
    EXPECT_EQ(page.find("src=\"http"), std::string::npos);
}

}  // namespace

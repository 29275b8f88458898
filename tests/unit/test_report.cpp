// SPDX-License-Identifier: GPL-2.0-or-later
// dissgen report's model: tshark's text parsed exactly, the cycles' figures
// taken from -z P,cycles as printed, rows folded into series, returns,
// losses and slave states, field names from the runtime's list.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "report/charts.h"
#include "report/ethercat/report_page.h"
#include "report/ethercat/timing_model.h"

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

TEST(ReportParse, NamesOfStates) {
    EXPECT_EQ(al_state_name(0x0008), "OP");
    EXPECT_EQ(al_state_name(0x0014), "SAFEOP");  // the error bit is not the state
    EXPECT_EQ(al_state_name(0x0003), "BOOT");
    EXPECT_EQ(al_state_name(0x0005), "0x5");
}

// Every field the report can ask for, as `tshark -G fields` would list them.
const std::vector<std::string> kKnown = {
    "frame.number",       "frame.time_epoch",      "ecatr.cycle",         "ecatr.cycle.period",
    "ecatr.cycle.jitter", "ecatr.time",            "ecatr.request_in",    "ecatr.no_response_to",
    "ecatr.expert.wkc",   "ecatr.slave.position",  "ecatr.slave.name",    "ecatr.datagram.reg.alstatus.status",
    "ecatr.esc.wkc_added", "ecatr.datagram.cmd",   "ecatr.datagram.adp",  "ecatr.datagram.ado",
    "other.time"};

// Rows as tshark writes them for TimingModelBuilder::fields().
struct Rows {
    std::vector<std::string> fields = TimingModelBuilder::fields("ecatr", kKnown);
    std::vector<std::vector<std::string>> text;
    std::vector<std::string> statistics;
    void add(std::initializer_list<std::pair<const char*, std::string>> values) {
        std::vector<std::string> row(fields.size());
        for (auto& [name, value] : values) {
            bool asked = false;
            for (size_t i = 0; i < fields.size(); ++i)
                if (fields[i] == name) row[i] = value, asked = true;
            EXPECT_TRUE(asked) << name << " is not asked for";
        }
        text.push_back(row);
    }
    void feed(TimingModel& m) {
        TimingModelBuilder b("ecatr", fields, m);
        for (auto& r : text) {
            FieldRow row(r.begin(), r.end());
            b.add(row);
        }
        for (auto& line : statistics) b.add_statistics_line(line);
    }
};

TEST(ReportFields, NamedFromTheRuntimeListUnderTheProtocol) {
    EXPECT_EQ(ethercat_protocol(kKnown), "ecatr");
    EXPECT_EQ(ethercat_protocol({"ecatr.time", "ecatr.cycle"}), "") << "no ethercat-esc analysis field";
    std::vector<std::string> renamed = {"ecx.esc.wkc_added", "ecx.time", "ecx.cycle"};
    EXPECT_EQ(ethercat_protocol(renamed), "ecx");
    EXPECT_EQ(TimingModelBuilder::fields("ecx", renamed), (std::vector<std::string>{"ecx.cycle", "ecx.time"}));
    std::vector<std::string> fields = TimingModelBuilder::fields("ecatr", kKnown);
    EXPECT_EQ(fields.size(), 15u);  // what tshark knows, without the ones the report does not read
    EXPECT_EQ(std::count(fields.begin(), fields.end(), "ecatr.esc.wkc_added"), 0);
    EXPECT_EQ(TimingModelBuilder::statistics_args("ecatr", kKnown), (std::vector<std::string>{"-z", "ecatr,cycles"}));
}

TEST(ReportModel, FiguresAreThePluginStatistics) {
    Rows r;
    r.add({{"frame.number", "1"}, {"frame.time_epoch", "100.000000000"}, {"ecatr.cycle", "1"}});
    r.add({{"frame.number", "3"}, {"frame.time_epoch", "100.001002000"}, {"ecatr.cycle", "1"},
           {"ecatr.cycle.period", "0.001002000"}, {"ecatr.cycle.jitter", "0.000002000"}});
    r.statistics = {"===================================================================",
                    "EtherCAT cycles (ecatr)",
                    "Cycle 1: LRW 0x00010000 (4 bytes), FRMW 0x1001:0x0910 (8 bytes)",
                    "  frames: 600",
                    "  nominal period (ns): 1000000",
                    "  period min/median/p99/max (ns): 995000 1000000 1005000 1005000",
                    "  jitter std dev (ns): 2160.2",
                    "  round trip: none",
                    "  frames returned: 599",
                    "  frames lost: 1",
                    "  working counter errors: 7",
                    "==================================================================="};
    TimingModel m;
    r.feed(m);
    ASSERT_EQ(m.cycles.size(), 1u);
    const Cycle& c = m.cycles.at(1);
    EXPECT_EQ(c.signature, "LRW 0x00010000 (4 bytes), FRMW 0x1001:0x0910 (8 bytes)");
    EXPECT_EQ(c.figures.frames, 600u) << "the plugin's count, not the two rows seen";
    EXPECT_EQ(c.figures.nominal, 1000000);
    EXPECT_EQ(c.figures.period.min, 995000);
    EXPECT_EQ(c.figures.period.p99, 1005000);
    EXPECT_DOUBLE_EQ(c.figures.jitter_sd, 2160.2);
    EXPECT_EQ(c.figures.round_trip.max, 0);
    EXPECT_EQ(c.figures.returned, 599u);
    EXPECT_EQ(c.figures.lost, 1u);
    EXPECT_EQ(c.figures.wkc_errors, 7u);
    ASSERT_EQ(c.period.size(), 1u);  // the chart's series, from the fields
    EXPECT_EQ(c.period[0].ns, 1002000);
    EXPECT_EQ(c.jitter[0].ns, 2000);
    EXPECT_TRUE(m.network.empty()) << "the cycles' lines are not network findings";
}

TEST(ReportModel, ReturnsLossesAndStates) {
    const std::string sep(1, kValueSeparator);
    Rows r;
    r.add({{"frame.number", "2"}, {"frame.time_epoch", "100.000050000"}, {"ecatr.time", "0.000050000"},
           {"ecatr.request_in", "1"}, {"ecatr.expert.wkc", "1"}});
    r.add({{"frame.number", "4"}, {"frame.time_epoch", "100.200000000"}, {"ecatr.no_response_to", "3"},
           {"ecatr.request_in", "9"}, {"ecatr.slave.position", "0" + sep + "1"},
           {"ecatr.slave.name", "EK1100" + sep + "EL1004"},
           {"ecatr.datagram.reg.alstatus.status", "0x0002" + sep + "0x0008"}});
    r.add({{"frame.number", "5"}, {"frame.time_epoch", "100.300000000"}, {"ecatr.request_in", "9"},
           {"ecatr.slave.position", "1"}, {"ecatr.datagram.reg.alstatus.status", "0x0008"}});
    TimingModel m;
    r.feed(m);
    EXPECT_EQ(m.frames, 3u);
    EXPECT_NEAR(m.duration, 0.29995, 1e-9);
    ASSERT_EQ(m.round_trip.size(), 1u);
    EXPECT_EQ(m.round_trip[0].ns, 50000);
    ASSERT_EQ(m.wkc_differs.size(), 1u);
    EXPECT_EQ(m.wkc_differs[0].frame, 1u);
    ASSERT_EQ(m.lost.size(), 1u);
    EXPECT_EQ(m.lost[0].frame, 3u);
    ASSERT_EQ(m.slaves.size(), 2u);
    EXPECT_EQ(m.slaves.at(0).name, "EK1100");
    EXPECT_EQ(m.slaves.at(1).name, "EL1004");
    ASSERT_EQ(m.slaves.at(1).states.size(), 1u);  // OP twice: one state, no change
    EXPECT_EQ(m.slaves.at(1).states[0].second, 8u);
}

// A capture started after the scan: no position known, the AL status read by
// FPRD of 0x0130 names the slave by its station address.
TEST(ReportModel, StatusesByStationWhenNoPositionIsKnown) {
    const std::string sep(1, kValueSeparator);
    Rows r;
    // LRW, FPRD 0x1001:0x0130, FPRD 0x1002:0x0130 (adp/ado only for the last two).
    auto reads = [&](const char* time, const char* second) {
        r.add({{"frame.number", "7"}, {"frame.time_epoch", time}, {"ecatr.request_in", "6"},
               {"ecatr.datagram.cmd", "0x0c" + sep + "0x04" + sep + "0x04"},
               {"ecatr.datagram.adp", "0x1001" + sep + "0x1002"}, {"ecatr.datagram.ado", "0x0130" + sep + "0x0130"},
               {"ecatr.datagram.reg.alstatus.status", "0x0008" + sep + second}});
    };
    reads("1.0", "0x0004");
    reads("2.0", "0x0008");
    // A BRD of 0x0130 is every slave's at once: not one slave's state.
    r.add({{"frame.number", "9"}, {"frame.time_epoch", "3.0"}, {"ecatr.request_in", "8"},
           {"ecatr.datagram.cmd", "0x07"}, {"ecatr.datagram.adp", "0x0000"}, {"ecatr.datagram.ado", "0x0130"},
           {"ecatr.datagram.reg.alstatus.status", "0x0002"}});
    TimingModel m;
    r.feed(m);
    EXPECT_TRUE(m.slaves.empty());
    ASSERT_EQ(m.stations.size(), 2u);
    EXPECT_EQ(m.stations.at(0x1001).states.size(), 1u);
    ASSERT_EQ(m.stations.at(0x1002).states.size(), 2u);
    EXPECT_EQ(m.stations.at(0x1002).states[0].second, 4u);
    EXPECT_EQ(m.stations.at(0x1002).states[1].second, 8u);
    EXPECT_EQ(m.stations.at(0x1001).states[0].second, 8u) << "the BRD's PREOP is nobody's";
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
    m.captures = {"/x/<evil>.pcap"};
    m.has_cycle_fields = true;
    Cycle& c = m.cycles[1];
    c.number = 1;
    c.signature = "LRW 0x1 + </script>";
    c.figures.frames = 3;
    c.figures.period.max = 1000000;
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

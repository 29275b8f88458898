// SPDX-License-Identifier: GPL-2.0-or-later
// dissgen report of any protocol with <cycles> or <pairing>: which installed
// protocols qualify, -z P,cycles taken as printed, rows folded into each
// cycle's series, the streams' losses and repeats, round trips; the page's
// table shows the statistic's figures as they are.
#include <gtest/gtest.h>

#include <sstream>

#include "report/any/cycles_model.h"
#include "report/any/cycles_page.h"

using namespace dissgen;

namespace {

// What `tshark -G fields` lists with the enip plugin (cycles and pairing),
// a pairing-only one, the EtherCAT one and one with a time but no pairing.
const std::vector<std::string> kKnown = {
    "frame.number",        "frame.time_epoch",       "enipr.cycle",        "enipr.cycle.period",
    "enipr.cycle.jitter",  "enipr.cycle.lost",       "enipr.cycle.duplicate", "enipr.expert.cycle_lost",
    "enipr.time",          "enipr.request_in",       "enipr.no_response_to", "enipr.expert.no_response",
    "rqc.time",            "rqc.request_in",         "rqc.no_response_to", "rqc.expert.no_response",
    "ecatr.time",          "ecatr.request_in",       "ecatr.no_response_to", "ecatr.expert.no_response",
    "ecatr.esc.wkc_added", "http.time",              "http.request_in",    "other.time"};

TEST(ReportCyclesProtocols, CyclesOrPairingButNotTheEtherCatOne) {
    EXPECT_EQ(cycles_protocols(kKnown, "ecatr"), (std::vector<std::string>{"enipr", "rqc"}));
    EXPECT_EQ(cycles_protocols(kKnown, ""), (std::vector<std::string>{"ecatr", "enipr", "rqc"}));
    EXPECT_EQ(cycles_protocols({"x.expert.cycle_lost"}, ""), (std::vector<std::string>{"x"})) << "cycles alone";
    EXPECT_TRUE(cycles_protocols({"other.time", "frame.time"}, "").empty()) << "a time without pairing";
    EXPECT_TRUE(cycles_protocols({"http.time", "http.request_in", "http.expert.no_response"}, "").empty())
        << "Wireshark's own pairing (no P.no_response_to)";
}

TEST(ReportCyclesProtocols, FieldsAndStatisticsOfWhatThePluginHas) {
    EXPECT_EQ(CyclesModelBuilder::fields("enipr", kKnown),
              (std::vector<std::string>{"frame.number", "frame.time_epoch", "enipr.cycle", "enipr.cycle.period",
                                        "enipr.cycle.jitter", "enipr.cycle.lost", "enipr.cycle.duplicate",
                                        "enipr.time", "enipr.no_response_to"}));
    EXPECT_EQ(CyclesModelBuilder::fields("rqc", kKnown),
              (std::vector<std::string>{"frame.number", "frame.time_epoch", "rqc.time", "rqc.no_response_to"}));
    EXPECT_EQ(CyclesModelBuilder::statistics_args("enipr", kKnown),
              (std::vector<std::string>{"-z", "enipr,cycles"}));
    EXPECT_TRUE(CyclesModelBuilder::statistics_args("rqc", kKnown).empty()) << "no <cycles>, no statistic";
}

// Rows as tshark writes them for CyclesModelBuilder::fields("enipr").
struct Rows {
    std::vector<std::string> fields = CyclesModelBuilder::fields("enipr", kKnown);
    std::vector<std::vector<std::string>> text;
    std::vector<std::string> statistics;
    void add(std::initializer_list<std::pair<const char*, std::string>> values) {
        std::vector<std::string> row(fields.size());
        for (auto& [name, value] : values)
            for (size_t i = 0; i < fields.size(); ++i)
                if (fields[i] == name) row[i] = value;
        text.push_back(row);
    }
    void feed(CyclesModel& m) {
        CyclesModelBuilder b("enipr", fields, m);
        for (auto& r : text) b.add(FieldRow(r.begin(), r.end()));
        for (auto& line : statistics) b.add_statistics_line(line);
    }
};

const std::vector<std::string> kStatistics = {
    "===================================================================",
    "EtherNet/IP cycles (enipr)",
    "Cycle 1: Connection ID 0x110001, sender 10.0.0.1:2222",
    "  first frame: 3",
    "  messages: 66",
    "  nominal period (ns): 10000000",
    "  period min/median/p99/max (ns): 9500001 10000002 10400003 10500004",
    "  jitter std dev (ns): 812.4",
    "  messages lost: 4",
    "  duplicates: 1",
    "Cycle 2: Connection ID 0x220002, sender 10.0.0.2:2222",
    "  first frame: 9",
    "  messages: 2",
    "  nominal period (ns): 4000000",
    "  period: none",
    "  jitter std dev (ns): 0.0",
    "==================================================================="};

TEST(ReportCyclesModel, FiguresAsTheStatisticPrintsThem) {
    Rows r;
    r.statistics = kStatistics;
    CyclesModel m;
    r.feed(m);
    ASSERT_EQ(m.cycles.size(), 2u);
    const StreamCycleFigures& a = m.cycles.at(1).figures;
    EXPECT_EQ(m.cycles.at(1).signature, "Connection ID 0x110001, sender 10.0.0.1:2222");
    EXPECT_EQ(a.first_frame, 3u);
    EXPECT_EQ(a.messages, 66u);
    EXPECT_EQ(a.nominal, 10000000);
    EXPECT_TRUE(a.has_period);
    EXPECT_EQ(a.period.min, 9500001);
    EXPECT_EQ(a.period.median, 10000002);
    EXPECT_EQ(a.period.p99, 10400003);
    EXPECT_EQ(a.period.max, 10500004);
    EXPECT_EQ(a.jitter_sd, "812.4") << "the text printed, not a number reformatted";
    EXPECT_TRUE(a.counted);
    EXPECT_TRUE(a.duplicates_counted);
    EXPECT_EQ(a.lost, 4u);
    EXPECT_EQ(a.duplicates, 1u);
    const StreamCycleFigures& b = m.cycles.at(2).figures;
    EXPECT_FALSE(b.has_period) << "period: none";
    EXPECT_FALSE(b.counted) << "a stream without a sequence count prints no losses";
    EXPECT_FALSE(b.duplicates_counted);
    EXPECT_EQ(b.jitter_sd, "0.0");
}

// lost="period": the statistic prints the messages lost and no duplicates,
// and the page leaves the duplicates cell empty rather than showing 0.
TEST(ReportCyclesModel, LossesByPeriodPrintNoDuplicates) {
    Rows r;
    r.statistics = {"===================================================================",
                    "Ethernet POWERLINK (rules) cycles (eplr)",
                    "Cycle 1: MessageType 0x4, Source 2",
                    "  first frame: 40",
                    "  messages: 31",
                    "  nominal period (ns): 400000",
                    "  period min/median/p99/max (ns): 398000 400000 402000 402000",
                    "  jitter std dev (ns): 1154.7",
                    "  messages lost: 1",
                    "==================================================================="};
    CyclesModel m;
    r.feed(m);
    ASSERT_EQ(m.cycles.size(), 1u);
    const StreamCycleFigures& f = m.cycles.at(1).figures;
    EXPECT_TRUE(f.counted);
    EXPECT_FALSE(f.duplicates_counted);
    EXPECT_EQ(f.lost, 1u);
}

TEST(ReportCyclesModel, SeriesLossesRepeatsAndRoundTrips) {
    Rows r;
    r.add({{"frame.number", "1"}, {"frame.time_epoch", "100.000000000"}, {"enipr.cycle.lost", "2"}});
    r.add({{"frame.number", "2"}, {"frame.time_epoch", "100.010000500"}, {"enipr.cycle", "1"},
           {"enipr.cycle.period", "0.010000500"}, {"enipr.cycle.jitter", "-0.000000250"}});
    r.add({{"frame.number", "3"}, {"frame.time_epoch", "100.010040000"}, {"enipr.cycle", "1"},
           {"enipr.cycle.duplicate", "2"}});
    r.add({{"frame.number", "4"}, {"frame.time_epoch", "100.020000000"}, {"enipr.cycle", "1"},
           {"enipr.cycle.lost", "3"}, {"enipr.time", "0.000250000"}, {"enipr.no_response_to", "1,2"}});
    CyclesModel m;
    r.feed(m);
    EXPECT_EQ(m.frames, 4u);
    EXPECT_NEAR(m.duration, 0.02, 1e-12);
    EXPECT_TRUE(m.has_cycles);
    EXPECT_TRUE(m.has_pairing);
    ASSERT_EQ(m.cycles.size(), 1u);
    const StreamCycle& c = m.cycles.at(1);
    ASSERT_EQ(c.period.size(), 1u);
    EXPECT_EQ(c.period[0].ns, 10000500);
    ASSERT_EQ(c.jitter.size(), 1u);
    EXPECT_EQ(c.jitter[0].ns, -250);
    ASSERT_EQ(m.lost.size(), 2u);
    EXPECT_EQ(m.lost[0].cycle, 0u) << "a loss before its stream is a cycle";
    EXPECT_EQ(m.lost[1].frame, 4u);
    EXPECT_EQ(m.lost[1].cycle, 1u);
    EXPECT_EQ(m.messages_lost(), 5u);
    ASSERT_EQ(m.duplicates.size(), 1u);
    EXPECT_EQ(m.duplicates[0].frame, 3u);
    ASSERT_EQ(m.round_trip.size(), 1u);
    EXPECT_EQ(m.round_trip[0].ns, 250000);
    ASSERT_EQ(m.no_response.size(), 2u);
    EXPECT_EQ(m.no_response[1].frame, 2u);
}

TEST(ReportCyclesModel, EveryResponseOfAFrameHasItsRoundTrip) {
    Rows r;  // one TCP segment holding two responses: P.time twice, as tshark joins them
    r.add({{"frame.number", "1"}, {"frame.time_epoch", "100.000000000"}});
    r.add({{"frame.number", "2"}, {"frame.time_epoch", "100.010000000"}, {"enipr.time", "0.009999000,0.000250000"}});
    CyclesModel m;
    r.feed(m);
    ASSERT_EQ(m.round_trip.size(), 2u) << "as -z P,tree and the fields count them";
    EXPECT_EQ(m.round_trip[0].ns, 9999000);
    EXPECT_EQ(m.round_trip[1].ns, 250000);
}

TEST(ReportCyclesModel, EveryMessageOfAFrameInItsCycle) {
    Rows r;  // TCP segments of two messages each, as tshark joins their values
    r.add({{"frame.number", "1"}, {"frame.time_epoch", "100.000000000"}, {"enipr.cycle", "1,2"},
           {"enipr.cycle.period", "0.010000000,0.004000000"}, {"enipr.cycle.jitter", "0.000000100,-0.000000200"}});
    r.add({{"frame.number", "2"}, {"frame.time_epoch", "100.010000000"}, {"enipr.cycle", "1,2"},
           {"enipr.cycle.period", "0.010000000,0.004000000"}, {"enipr.cycle.jitter", "0.000000300"},
           {"enipr.cycle.lost", "1"}});
    r.add({{"frame.number", "3"}, {"frame.time_epoch", "100.020000000"}, {"enipr.cycle", "2,2"},
           {"enipr.cycle.period", "0.004000000,0.000001000"}, {"enipr.cycle.lost", "2"}});
    // a message and its duplicate (no period), each after a loss
    r.add({{"frame.number", "4"}, {"frame.time_epoch", "100.030000000"}, {"enipr.cycle", "2,2"},
           {"enipr.cycle.period", "0.004000000"}, {"enipr.cycle.lost", "1,1"}, {"enipr.cycle.duplicate", "4"}});
    CyclesModel m;
    r.feed(m);
    ASSERT_EQ(m.cycles.size(), 2u);
    EXPECT_EQ(m.cycles.at(1).period.size(), 2u);
    ASSERT_EQ(m.cycles.at(2).period.size(), 5u) << "a duplicate's missing period drops no other";
    EXPECT_EQ(m.cycles.at(2).period[0].ns, 4000000);
    EXPECT_EQ(m.cycles.at(2).period[3].ns, 1000);
    EXPECT_EQ(m.cycles.at(2).period[4].ns, 4000000);
    ASSERT_EQ(m.cycles.at(1).jitter.size(), 1u) << "frame 2's one jitter belongs to one of two messages: not shown";
    EXPECT_EQ(m.cycles.at(1).jitter[0].ns, 100);
    EXPECT_EQ(m.cycles.at(2).jitter[0].ns, -200);
    ASSERT_EQ(m.lost.size(), 4u);
    EXPECT_EQ(m.lost[0].cycle, 0u) << "a loss in a frame of two cycles: which one is not known";
    EXPECT_EQ(m.lost[1].cycle, 2u);
    EXPECT_EQ(m.messages_lost(), 5u) << "every message's loss counts";
    ASSERT_EQ(m.duplicates.size(), 1u);
    EXPECT_EQ(m.duplicates[0].cycle, 2u);
}

TEST(ReportCyclesPage, TableAsPrintedChartsPerCycleEscaped) {
    Rows r;
    r.statistics = kStatistics;
    r.statistics[2] = "Cycle 1: Connection ID 0x1, </script><b>";
    r.add({{"frame.number", "1"}, {"frame.time_epoch", "100.000000000"}, {"enipr.cycle.lost", "2"}});
    CyclesModel m;
    m.captures = {"/x/io.pcap"};
    r.feed(m);
    std::ostringstream out;
    std::string error = write_cycles_report_html(m, "test", out);
    if (error.find("dygraphs") != std::string::npos) GTEST_SKIP() << error;
    ASSERT_EQ(error, "");
    const std::string page = out.str();
    EXPECT_NE(page.find("<td>9500001</td><td>10000002</td><td>10400003</td><td>10500004</td><td>812.4</td>"
                        "<td>4</td><td>1</td>"),
              std::string::npos);
    EXPECT_NE(page.find("<td>none</td><td>none</td><td>none</td><td>none</td><td>0.0</td><td></td><td></td>"),
              std::string::npos);
    for (const char* id : {"period-1", "jitter-1", "period-2", "jitter-2", "loss-events"})
        EXPECT_NE(page.find(std::string("id=\"") + id + "\""), std::string::npos) << id;
    EXPECT_NE(page.find("1 frames, 0.000 s; 2 cycles, 2 messages lost, 0 duplicates; 0 round trips"),
              std::string::npos);
    EXPECT_EQ(page.find("</script><b>"), std::string::npos);
    EXPECT_NE(page.find("No request and response paired"), std::string::npos) << "no round trip to draw";
    EXPECT_NE(page.find("io.pcap"), std::string::npos);
}

}  // namespace

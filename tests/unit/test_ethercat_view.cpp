// SPDX-License-Identifier: GPL-2.0-or-later
// The EtherCAT analysis reads the datagrams from the frame's dg_view (the
// values the walk decoded for <pairing><input>), not from the bytes:
// frame_datagrams() places them, without tshark.
#include <gtest/gtest.h>

#include <vector>

#include "ethercat/ethercat_bus.h"

namespace {

using namespace dg_ecat;

dg_view_value value(guint8 input, guint32 instance, guint64 v, gint32 offset, guint16 length) {
    dg_view_value x = {};
    x.value = v;
    x.offset = offset;
    x.length = length;
    x.input = input;
    x.instance = instance;
    return x;
}

// A frame as rules/ethercat.xml decodes it: FPRD 0x1001:0x0130 len 2, wkc 1,
// then LRW 0x00010000 len 4, wkc 3 (its address the logical one).
std::vector<dg_view_value> two_datagrams() {
    return {value(ESC_IN_FRAME_LENGTH, 0, 30, 0, 2),
            value(ESC_IN_COMMAND, 0, 0x04, 2, 1),  value(ESC_IN_INDEX, 0, 0x41, 3, 1),
            value(ESC_IN_ADP, 0, 0x1001, 4, 2),    value(ESC_IN_ADO, 0, 0x0130, 6, 2),
            value(ESC_IN_LENGTH, 0, 2, 8, 2),      value(ESC_IN_WKC, 0, 1, 14, 2),
            value(ESC_IN_COMMAND, 1, 0x0c, 16, 1), value(ESC_IN_INDEX, 1, 0x42, 17, 1),
            value(ESC_IN_LOGICAL, 1, 0x00010000, 18, 4), value(ESC_IN_LENGTH, 1, 4, 22, 2),
            value(ESC_IN_WKC, 1, 3, 30, 2)};
}

TEST(EthercatView, DatagramsComeFromTheWalksValues) {
    std::vector<dg_view_value> values = two_datagrams();
    dg_view view = {values.data(), (guint)values.size(), nullptr};
    datagram d[max_datagrams];
    guint header_length = 0;
    ASSERT_EQ(frame_datagrams(&view, &header_length, d, max_datagrams), 2u);
    EXPECT_EQ(header_length, 30u);
    EXPECT_EQ(d[0].cmd, 0x04);
    EXPECT_EQ(d[0].idx, 0x41);
    EXPECT_EQ(d[0].adp, 0x1001);
    EXPECT_EQ(d[0].ado, 0x0130);
    EXPECT_EQ(d[0].wkc, 1);
    EXPECT_EQ(d[0].offset, 2);
    EXPECT_EQ(d[0].address_offset, 4);
    EXPECT_EQ(data_offset(&d[0]), 12);   // the data ends where the working counter starts
    EXPECT_EQ(wkc_offset(&d[0]), 14);
    EXPECT_EQ(datagram_span(&d[0]), 14);
    // A logical address: ADP its low half, ADO its high half, as on the wire.
    EXPECT_EQ(d[1].cmd, 0x0c);
    EXPECT_EQ(d[1].adp, 0x0000);
    EXPECT_EQ(d[1].ado, 0x0001);
    EXPECT_EQ(d[1].address_offset, 18);
    EXPECT_EQ(data_offset(&d[1]), 26);
    EXPECT_EQ(datagram_span(&d[1]), 16);
}

// The walk stopped inside the second datagram (cut short): its working
// counter was not decoded, so only the first counts.
TEST(EthercatView, ADatagramWithoutItsWorkingCounterDoesNotCount) {
    std::vector<dg_view_value> values = two_datagrams();
    values.pop_back();
    dg_view view = {values.data(), (guint)values.size(), nullptr};
    datagram d[max_datagrams];
    guint header_length = 0;
    EXPECT_EQ(frame_datagrams(&view, &header_length, d, max_datagrams), 1u);
    EXPECT_EQ(d[0].wkc, 1);
}

// A working counter whose `length` bytes before it would start before the
// datagram's own command (rules that place it elsewhere): the datagrams end
// before it, so the analysis never reads data outside the datagram.
TEST(EthercatView, DataBeforeItsDatagramEndsTheDatagrams) {
    std::vector<dg_view_value> values = two_datagrams();
    values.back() = value(ESC_IN_WKC, 1, 3, 20, 2);  // 20 - 4 = 16, the second's command
    dg_view view = {values.data(), (guint)values.size(), nullptr};
    datagram d[max_datagrams];
    guint header_length = 0;
    EXPECT_EQ(frame_datagrams(&view, &header_length, d, max_datagrams), 1u);
}

TEST(EthercatView, AtMostMaxDatagramsAndNoneWithoutAView) {
    std::vector<dg_view_value> values = two_datagrams();
    dg_view view = {values.data(), (guint)values.size(), nullptr};
    datagram d[max_datagrams];
    guint header_length = 7;
    EXPECT_EQ(frame_datagrams(&view, &header_length, d, 1), 1u);
    EXPECT_EQ(frame_datagrams(NULL, &header_length, d, max_datagrams), 0u);
    EXPECT_EQ(header_length, 0u);
}

}  // namespace

// The plugin runtime's pure parts, called directly: integer reads and bit
// fields (dissgen_values.h), the text buffer and its number formatting
// (dissgen_text.h), value ranges, reference arithmetic and the conditions
// that select a node (dissgen_conditions.cpp). The walk over whole packets
// is tested with tshark (tests/integration/).
#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>
#include <string>
#include <vector>

#include "dissgen_label.h"
#include "dissgen_state.h"

namespace {

using namespace dg_rt;

// A tvb over `bytes` (tvb_new_real_data needs no epan initialisation).
struct Tvb {
    std::vector<guint8> bytes;
    tvbuff_t* tvb;
    explicit Tvb(std::vector<guint8> b) : bytes(std::move(b)) {
        tvb = tvb_new_real_data(bytes.data(), (guint)bytes.size(), (gint)bytes.size());
    }
    ~Tvb() { tvb_free(tvb); }
};

const std::vector<guint8> kEight = {0x81, 0x02, 0xa3, 0x04, 0xc5, 0x06, 0xe7, 0x08, 0xff};

guint64 big_endian(const std::vector<guint8>& b, guint offset, guint length) {
    guint64 v = 0;
    for (guint i = 0; i < length; i++) v = v << 8 | b[offset + i];
    return v;
}

guint64 little_endian(const std::vector<guint8>& b, guint offset, guint length) {
    guint64 v = 0;
    for (guint i = length; i-- > 0;) v = v << 8 | b[offset + i];
    return v;
}

TEST(RuntimeRead, EveryWidthInBothByteOrders) {
    Tvb t(kEight);
    for (guint offset : {0u, 1u}) {
        for (guint length = 1; length <= 8; length++) {
            EXPECT_EQ(read_uint(t.tvb, (gint)offset, length, ENC_BIG_ENDIAN), big_endian(kEight, offset, length))
                << "big-endian, " << length << " bytes at " << offset;
            EXPECT_EQ(read_uint(t.tvb, (gint)offset, length, ENC_LITTLE_ENDIAN),
                      little_endian(kEight, offset, length))
                << "little-endian, " << length << " bytes at " << offset;
        }
    }
}

TEST(RuntimeRead, LongerThanEightBytesReadsEight) {
    Tvb t(kEight);
    EXPECT_EQ(read_uint(t.tvb, 0, 9, ENC_BIG_ENDIAN), big_endian(kEight, 0, 8));
}

TEST(RuntimeRead, ByteOrderComesFromTheNode) {
    dg_node n{};
    EXPECT_EQ(encoding_of(&n), (guint)ENC_BIG_ENDIAN);
    n.flags = DG_LITTLE;
    EXPECT_EQ(encoding_of(&n), (guint)ENC_LITTLE_ENDIAN);
}

TEST(RuntimeBits, MaskOfEveryWidth) {
    guint64 expected = 0;
    for (guint bits = 0; bits <= 70; bits++) {
        EXPECT_EQ(bit_mask(bits), expected) << bits << " bits";
        expected = expected << 1 | 1;
    }
}

TEST(RuntimeBits, FieldsTakeTheirBitsOnly) {
    EXPECT_EQ(bit_field(0xabcd, 0, 4), 0xdu);
    EXPECT_EQ(bit_field(0xabcd, 4, 8), 0xbcu);
    EXPECT_EQ(bit_field(0xabcd, 12, 4), 0xau);
    EXPECT_EQ(bit_field(0xabcd, 15, 1), 1u);
    EXPECT_EQ(bit_field(0xabcd, 14, 1), 0u);
    EXPECT_EQ(bit_field(G_MAXUINT64, 0, 64), G_MAXUINT64);
    EXPECT_EQ(bit_field(G_GUINT64_CONSTANT(1) << 63, 63, 1), 1u);
    // Every width at every shift of a 16-bit group: the neighbours' bits stay out.
    for (guint shift = 0; shift < 16; shift++)
        for (guint bits = 1; shift + bits <= 16; bits++)
            EXPECT_EQ(bit_field(0xffff, shift, bits), (1u << bits) - 1) << shift << "+" << bits;
}

// --- text ------------------------------------------------------------------

std::string printed(const char* format, guint64 v, int width = -1) {
    char buf[64];
    if (width < 0)
        snprintf(buf, sizeof buf, format, v);
    else
        snprintf(buf, sizeof buf, format, width, v);
    return buf;
}

const guint64 kEdges[] = {0,
                          1,
                          9,
                          10,
                          15,
                          16,
                          255,
                          G_MAXUINT32,
                          G_GUINT64_CONSTANT(1) << 32,
                          G_GUINT64_CONSTANT(10000000000000000000),
                          G_MAXUINT64 - 1,
                          G_MAXUINT64};

TEST(RuntimeText, DecimalAsPrintf) {
    for (guint64 v : kEdges) {
        char buf[8];
        dg_text t;
        text_init(&t, NULL, buf, sizeof buf);
        append_dec(&t, v);
        EXPECT_EQ(std::string(t.data, t.len), printed("%" PRIu64, v));
        EXPECT_EQ(strlen(t.data), t.len) << "NUL-terminated";
    }
}

// The labels' appends (dissgen_label.h) write what printf would: "%d", "%+d", "%u".
TEST(RuntimeLabel, IntegersAsPrintf) {
    const gint64 signed_edges[] = {0, 1, -1, 9, -9, 10, -10, 255, -256, G_MAXINT32, G_MININT32,
                                   G_MAXINT64, G_MININT64, G_MININT64 + 1};
    for (gint64 v : signed_edges)
        for (int plus = 0; plus < 2; plus++) {
            dg_label l = {"", 0};
            dg_label_int(&l, v, plus);
            char want[32];
            std::snprintf(want, sizeof want, plus ? "%+" PRId64 : "%" PRId64, v);
            EXPECT_EQ(std::string(l.text, l.len), want);
        }
    for (guint64 v : kEdges) {
        dg_label l = {"", 0};
        dg_label_uint(&l, v);
        EXPECT_EQ(std::string(l.text), printed("%" PRIu64, v));
    }
}

TEST(RuntimeText, HexAsPrintfAtEveryWidth) {
    for (guint64 v : kEdges) {
        for (guint digits = 0; digits <= 16; digits++) {
            dg_text* t = text_new(NULL);
            append_hex(t, v, digits);
            EXPECT_EQ(std::string(t->data, t->len), printed("0x%0*" PRIx64, v, (int)digits)) << digits << " digits";
        }
    }
}

TEST(RuntimeText, HexWidthStopsAtSixteenDigits) {
    dg_text* t = text_new(NULL);
    append_hex(t, 1, 20);
    EXPECT_STREQ(t->data, "0x0000000000000001");
}

// A number as its field shows it, where no item does (cycle stream names, pairing notes):
// hex padded to the field's width, decimal, signed with the field's sign bit.
TEST(RuntimeText, NumbersAsTheirFieldShowsThem) {
    auto shown = [](int show, guint bits, guint64 v) {
        dg_node n{};
        n.show = show;
        n.bits = bits;
        dg_text* t = text_new(NULL);
        append_number(t, &n, v);
        return std::string(t->data, t->len);
    };
    EXPECT_EQ(shown(DG_SHOW_HEX, 16, 0xab), "0x00ab");
    EXPECT_EQ(shown(DG_SHOW_HEX, 12, 0xab), "0x0ab");
    EXPECT_EQ(shown(DG_SHOW_HEX, 1, 1), "0x1");
    EXPECT_EQ(shown(DG_SHOW_DEC, 16, 0xffff), "65535");
    EXPECT_EQ(shown(DG_SHOW_INT, 16, 0xffff), "-1");
    EXPECT_EQ(shown(DG_SHOW_INT, 16, 0x7fff), "32767");
    EXPECT_EQ(shown(DG_SHOW_INT, 8, 0x80), "-128");
    EXPECT_EQ(shown(DG_SHOW_INT, 4, 0x8), "-8");
    EXPECT_EQ(shown(DG_SHOW_INT, 64, G_MAXUINT64), "-1");
    EXPECT_EQ(shown(DG_SHOW_INT, 32, 0x80000000u), "-2147483648");
}

// A caller's buffer of 6 bytes, and 4 after it that no text may write.
struct GuardedBuffer {
    char buf[6] = {0};
    char after[4] = {'!', '!', '!', '!'};
};

TEST(RuntimeText, OutgrowsTheCallersBuffer) {
    GuardedBuffer stack;
    dg_text t;
    text_init(&t, NULL, stack.buf, sizeof stack.buf);
    append_str(&t, "Frame");
    EXPECT_EQ(t.data, stack.buf) << "fits: still the caller's buffer";
    EXPECT_LT(t.len, t.cap) << "room for the NUL";
    append_str(&t, ", ");
    EXPECT_LT(t.len, t.cap) << "room for the NUL";
    append_dec(&t, 12345);
    EXPECT_NE(t.data, stack.buf);
    EXPECT_STREQ(t.data, "Frame, 12345");
    EXPECT_EQ(t.len, 12u);
    EXPECT_EQ(std::string(stack.after, 4), "!!!!") << "nothing written past the caller's buffer";
    for (int i = 0; i < 100; i++) {
        text_append(&t, "abcdefghij", 10);
        ASSERT_LT(t.len, t.cap) << "room for the NUL";
    }
    EXPECT_EQ(t.len, 1012u);
    EXPECT_EQ(strlen(t.data), t.len);
}

TEST(RuntimeText, TheNulNeedsRoomToo) {
    GuardedBuffer stack;
    dg_text t;
    text_init(&t, NULL, stack.buf, sizeof stack.buf);
    append_str(&t, "Frame");
    append_str(&t, "!"); /* six bytes and the NUL: more than the buffer */
    EXPECT_NE(t.data, stack.buf);
    EXPECT_STREQ(t.data, "Frame!");
    EXPECT_LT(t.len, t.cap);
    EXPECT_EQ(std::string(stack.after, 4), "!!!!") << "no NUL written past the caller's buffer";
}

TEST(RuntimeText, TruncateOnlyShortens) {
    dg_text* t = text_new(NULL);
    append_str(t, "abcdef");
    text_truncate(t, 10);
    EXPECT_STREQ(t->data, "abcdef");
    text_truncate(t, 3);
    EXPECT_STREQ(t->data, "abc");
    EXPECT_EQ(t->len, 3u);
    text_truncate(t, 0);
    EXPECT_STREQ(t->data, "");
}

// --- ranges, references, time --------------------------------------------

const dg_range kRanges[] = {{1, 3}, {10, 10}, {G_MAXUINT64 - 1, G_MAXUINT64}};

TEST(RuntimeRanges, BothBoundsIncluded) {
    EXPECT_FALSE(in_ranges(kRanges, 0, 3, 0));
    EXPECT_TRUE(in_ranges(kRanges, 0, 3, 1));
    EXPECT_TRUE(in_ranges(kRanges, 0, 3, 3));
    EXPECT_FALSE(in_ranges(kRanges, 0, 3, 4));
    EXPECT_TRUE(in_ranges(kRanges, 0, 3, 10));
    EXPECT_FALSE(in_ranges(kRanges, 0, 3, 11));
    EXPECT_TRUE(in_ranges(kRanges, 0, 3, G_MAXUINT64));
}

TEST(RuntimeRanges, OnlyTheGivenRangesCount) {
    EXPECT_FALSE(in_ranges(kRanges, 0, 0, 1)) << "no ranges: nothing is in them";
    EXPECT_FALSE(in_ranges(kRanges, 1, 1, 2)) << "ranges[0] is not among them";
    EXPECT_TRUE(in_ranges(kRanges, 1, 1, 10));
    EXPECT_FALSE(in_ranges(kRanges, 0, 1, 10)) << "ranges[1] is not among them";
}

TEST(RuntimeRefs, Arithmetic) {
    dg_ref none = {0, 0, 0, 5}, plus = {0, '+', 0, 5}, minus = {0, '-', 0, 5}, times = {0, '*', 0, 5};
    EXPECT_EQ(ref_arith(7, &none), 7);
    EXPECT_EQ(ref_arith(7, &plus), 12);
    EXPECT_EQ(ref_arith(7, &minus), 2);
    EXPECT_EQ(ref_arith(3, &minus), -2);
    EXPECT_EQ(ref_arith(7, &times), 35);
}

TEST(RuntimeRefs, LargeValuesExactUpToTwoToThe62) {
    const gint64 limit = G_GINT64_CONSTANT(1) << 62;
    dg_ref none = {0, 0, 0, 0}, times = {0, '*', 0, 999999999}, minus = {0, '-', 0, 1};
    EXPECT_EQ(ref_arith(G_GUINT64_CONSTANT(4294967295), &none), G_GINT64_CONSTANT(4294967295))
        << "a 4-byte length is reported as the field holds it";
    EXPECT_EQ(ref_arith(G_GUINT64_CONSTANT(4294967295), &times), G_GINT64_CONSTANT(4294967295) * 999999999);
    EXPECT_EQ(ref_arith(G_GUINT64_CONSTANT(1) << 62, &none), limit);
    EXPECT_EQ(ref_arith((G_GUINT64_CONSTANT(1) << 62) + 1, &none), limit);
    EXPECT_EQ(ref_arith(G_MAXUINT64, &none), limit);
    EXPECT_EQ(ref_arith(G_MAXUINT64, &minus), limit - 1);
    EXPECT_EQ(ref_arith(G_MAXUINT64, &times), limit) << "saturated, no overflow";
}

// A signed field's (an int's, a computed value's) negative value stays negative, so that
// a length or count from it is reported negative; an unsigned one's top values clamp.
TEST(RuntimeRefs, SignedValuesStayNegative) {
    const gint64 limit = G_GINT64_CONSTANT(1) << 62;
    dg_ref signed_none = {0, 0, 1, 0}, signed_minus = {0, '-', 1, 8}, unsigned_none = {0, 0, 0, 0},
           signed_times = {0, '*', 1, 999999999};
    EXPECT_EQ(ref_arith((guint64)G_GINT64_CONSTANT(-3), &signed_none), -3);
    EXPECT_EQ(ref_arith(5, &signed_minus), -3);
    EXPECT_EQ(ref_arith((guint64)G_MININT64, &signed_none), -limit) << "no overflow";
    EXPECT_EQ(ref_arith((guint64)G_MININT64, &signed_times), -limit) << "saturated negative, no overflow";
    EXPECT_EQ(ref_arith((guint64)G_GINT64_CONSTANT(-3), &unsigned_none), limit);
    EXPECT_EQ(ref_arith(G_MAXUINT64 >> 1, &signed_none), limit) << "a large positive one still clamps";
}

TEST(RuntimeTime, UnitsBecomeSecondsAndNanoseconds) {
    dg_extra us{};
    us.units_per_second = 1000000;
    dg_node n{};
    nstime_t t = time_of(&n, G_GUINT64_CONSTANT(3000000123));
    EXPECT_EQ(t.secs, 3);
    EXPECT_EQ(t.nsecs, 123) << "nanoseconds without units_per_second";
    n.extra = &us;
    t = time_of(&n, 2500001);
    EXPECT_EQ(t.secs, 2);
    EXPECT_EQ(t.nsecs, 500001000);
}

// --- conditions ------------------------------------------------------------

// A protocol, its nodes and the state of a message, slots empty.
struct Message {
    dg_protocol p{};
    dg_node nodes[4]{};
    dg_when whens[2]{};
    dg_peek peeks[1]{};
    dg_slot slots[4]{};
    guint8 present[4]{};
    dg_conditions conditions{kRanges, whens};
    dg_state st{};

    Message() {
        p.conditions = &conditions;
        p.nodes = nodes;
        p.peeks = peeks;
        st.p = &p;
        st.slots = slots;
        st.present = present;
        for (dg_node& n : nodes) n.if_slot = n.repeat_slot = n.count.slot = n.slot = -1;
    }
    void set(gint16 slot, guint64 value) {
        slots[slot].value = value;
        present[slot] = TRUE;
    }
    gboolean selects(const dg_node& n, gboolean* chain_taken) { return selected(&st, &conditions, &n, 0, chain_taken); }
};

TEST(RuntimeConditions, UnconditionalNodesEndAChain) {
    Message m;
    gboolean chain = TRUE;
    EXPECT_TRUE(m.selects(m.nodes[0], &chain));
    EXPECT_FALSE(chain);
}

TEST(RuntimeConditions, IfNeedsTheFieldAndAValueInItsRanges) {
    Message m;
    dg_node& n = m.nodes[0];
    n.if_slot = 2;
    n.in_first = 0;
    n.in_count = 2; /* 1..3, 10 */
    gboolean chain = FALSE;
    EXPECT_FALSE(m.selects(n, &chain)) << "the field is not in the message";
    m.slots[2].value = 2;
    EXPECT_FALSE(m.selects(n, &chain)) << "a stale value of an absent field";
    m.set(2, 2);
    EXPECT_TRUE(m.selects(n, &chain));
    EXPECT_TRUE(chain) << "a conditional node taken";
    m.set(2, 4);
    EXPECT_FALSE(m.selects(n, &chain));
    EXPECT_FALSE(chain);
    m.set(0, 10);
    n.if_slot = 0;
    EXPECT_TRUE(m.selects(n, &chain)) << "slot 0 is a slot like any other";
}

TEST(RuntimeConditions, OtherwiseOnlyWhenNoEarlierMemberWasTaken) {
    Message m;
    dg_node& cond = m.nodes[0];
    dg_node& other = m.nodes[1];
    cond.if_slot = 0;
    cond.in_count = 1; /* 1..3 */
    other.alt = DG_ALT_OTHERWISE;
    gboolean chain = FALSE;
    m.set(0, 2);
    EXPECT_TRUE(m.selects(cond, &chain));
    EXPECT_FALSE(m.selects(other, &chain));
    m.set(0, 7);
    EXPECT_FALSE(m.selects(cond, &chain));
    EXPECT_TRUE(m.selects(other, &chain));
    EXPECT_TRUE(chain) << "an otherwise taken ends its chain for the next otherwise";
    EXPECT_FALSE(m.selects(other, &chain));
}

TEST(RuntimeConditions, IfHookTestsTheMatchedValue) {
    Message m;
    dg_node& n = m.nodes[0];
    n.hook_first = 1;
    n.hook_count = 1; /* 10 */
    gboolean chain = FALSE;
    m.st.hook_value = 10;
    EXPECT_TRUE(m.selects(n, &chain));
    m.st.hook_value = 3;
    EXPECT_FALSE(m.selects(n, &chain));
}

TEST(RuntimeConditions, DirectionMustMatchTheTransports) {
    Message m;
    dg_extra request{};
    request.direction = DG_DIR_REQUEST;
    request.reassemble_id = -1;
    request.offsets_slot = -1;
    dg_node& n = m.nodes[0];
    n.extra = &request;
    gboolean chain = FALSE;
    m.st.direction = DG_DIR_REQUEST;
    EXPECT_TRUE(m.selects(n, &chain));
    m.st.direction = DG_DIR_RESPONSE;
    EXPECT_FALSE(m.selects(n, &chain));
    request.direction = DG_DIR_ANY;
    EXPECT_TRUE(m.selects(n, &chain)) << "no direction: either";
}

TEST(RuntimeConditions, EveryWhenMustHold) {
    Message m;
    dg_node& n = m.nodes[0];
    m.whens[0] = {1, -1, 0, 1}; /* slot 1 in 1..3 */
    m.whens[1] = {2, -1, 1, 1}; /* slot 2 is 10 */
    n.when_first = 0;
    n.when_count = 2;
    gboolean chain = FALSE;
    m.set(1, 3);
    EXPECT_FALSE(m.selects(n, &chain)) << "slot 2 is not in the message";
    m.slots[2].value = 10;
    EXPECT_FALSE(m.selects(n, &chain)) << "a stale value of an absent field";
    m.set(2, 10);
    EXPECT_TRUE(m.selects(n, &chain));
    m.set(1, 0);
    EXPECT_FALSE(m.selects(n, &chain));
}

TEST(RuntimeConditions, AWhenOnAnAbsentFieldNeverHolds) {
    Message m;
    dg_range zero[] = {{0, 0}};
    m.conditions.ranges = zero;
    m.whens[0] = {1, -1, 0, 1}; /* slot 1 is 0 */
    dg_node& n = m.nodes[0];
    n.when_count = 1;
    gboolean chain = FALSE;
    EXPECT_FALSE(m.selects(n, &chain)) << "absent, not 0";
    m.set(1, 0);
    EXPECT_TRUE(m.selects(n, &chain));
}

TEST(RuntimeConditions, PeekReadsABitFieldAheadUpToTheEndOfItsList) {
    // bytes: 00 00 | group 0x0a50 (member: bits 4..11 = 0xa5)
    Tvb t({0x00, 0x00, 0x0a, 0x50});
    Message m;
    dg_node& target = m.nodes[3];
    target.length = 2;
    target.flags = DG_GROUP | DG_NUMERIC;
    target.shift = 4;
    target.bits = 8;
    m.peeks[0] = {3, 2, 0, 0, 0, 0}; /* node 3, 2 bytes after the node's start */
    m.whens[0] = {-1, 0, 0, 1};      /* peek 0 in ranges[0] */
    dg_range is_a5[] = {{0xa5, 0xa5}};
    m.conditions.ranges = is_a5;
    dg_node& n = m.nodes[0];
    n.when_count = 1;
    m.st.tvb = t.tvb;
    m.st.packet_end = 4;
    m.st.lists = 1;
    m.st.list_starts[0] = 0;
    m.st.list_ends[0] = 4;
    gboolean chain = FALSE;
    EXPECT_TRUE(m.selects(n, &chain)) << "the member's bits, shifted; its last byte is the list's last";
    m.st.list_ends[0] = 3;
    EXPECT_FALSE(m.selects(n, &chain)) << "its list ends before the leaf does";
}

TEST(RuntimeRefs, ValueOfAPresentField) {
    Message m;
    dg_ref ref = {1, '*', 0, 4};
    m.set(1, 6);
    gint64 v = -1;
    EXPECT_TRUE(ref_value(&m.st, &ref, &m.nodes[0], "length", NULL, 0, &v));
    EXPECT_EQ(v, 24);
}

}  // namespace

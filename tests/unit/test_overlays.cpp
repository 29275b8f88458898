// Overlays (overlay="XPATH"): a container decoding the bytes of an earlier
// node, through the parser, the validator, the emitter and the quiet walk.
// (Misuses: tests/rules_err/overlay_*.xml; behaviour with tshark:
// tests/integration/language/test_overlays.py.)
#include <gtest/gtest.h>

#include "emit_cpp.h"
#include "quiet.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

// A status word and its flags, a body of raw bytes and the record inside.
const char* kOverlays =
    "  <node name=\"Status\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
    "  <node name=\"Flags\" overlay=\"../node[@name='Status']\">\n"
    "    <node name=\"Ready\" length=\"1bit\" displaytype=\"bool\"/>\n"
    "    <node name=\"Rest\" length=\"15bit\" displaytype=\"numberdec\"/>\n"
    "  </node>\n"
    "  <node name=\"Length\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "  <node name=\"Body\" length=\"../node[@name='Length']\">\n"
    "    <node name=\"Raw\" length=\"rest\" displaytype=\"origin\"/>\n"
    "  </node>\n"
    "  <node name=\"Record\" overlay=\"../node[@name='Body']\">\n"
    "    <node name=\"Type\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
    "    <node name=\"Data\" length=\"rest\" displaytype=\"origin\"/>\n"
    "  </node>\n"
    "  <node name=\"Trailer\" length=\"2byte\" displaytype=\"numberhex\"/>\n";

TEST(Overlays, ParsedResolvedAndTheTargetsKeepWhereTheyAre) {
    Front f = front_end(rules(kOverlays));
    ASSERT_TRUE(f.ok()) << f.messages();
    const Node* flags = find(*f.proto, "Flags");
    ASSERT_TRUE(flags->is_overlay());
    EXPECT_EQ(flags->overlay->target, find(*f.proto, "Status"));
    EXPECT_EQ(find(*f.proto, "Record")->overlay->target, find(*f.proto, "Body"));
    // a leaf and a container target both get a slot: offset and length at run time
    EXPECT_GE(find(*f.proto, "Status")->slot, 0);
    EXPECT_GE(find(*f.proto, "Body")->slot, 0);
    EXPECT_FALSE(flags->is_repeated());
    EXPECT_FALSE(find(*f.proto, "Trailer")->is_overlay());
}

TEST(Overlays, EmittedAsTheTargetSlotInTheExtraRow) {
    Front f = front_end(rules(kOverlays));
    ASSERT_TRUE(f.ok()) << f.messages();
    std::string code = emit_cpp(*f.proto, "t.xml");
    const int status = find(*f.proto, "Status")->slot, body = find(*f.proto, "Body")->slot;
    EXPECT_TRUE(contains(code, "dg_node_extra().overlay(" + std::to_string(status) + "),")) << code;
    EXPECT_TRUE(contains(code, "dg_node_extra().overlay(" + std::to_string(body) + "),")) << code;
}

TEST(Overlays, ProtocolsWithoutOverlaysEmitNoOverlay) {
    Front f = front_end(rules("  <node name=\"Word\" length=\"2byte\" displaytype=\"numberhex\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_FALSE(contains(emit_cpp(*f.proto, "t.xml"), "overlay")) << emit_cpp(*f.proto, "t.xml");
}

TEST(Overlays, TakeNoBytesOfTheirContainer) {
    // A fixed-size container: the overlay inside adds nothing to its children's sum.
    Front f = front_end(rules(
        "  <node name=\"Header\" length=\"3byte\">\n"
        "    <node name=\"Word\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
        "    <node name=\"Bytes\" overlay=\"../node[@name='Word']\">\n"
        "      <node name=\"Low\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
        "      <node name=\"High\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
        "    </node>\n"
        "    <node name=\"Kind\" length=\"1byte\" displaytype=\"numberdec\" valid=\"1-3\"/>\n"
        "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    // the valid field after the overlay is at byte 2, as without it
    EXPECT_EQ(find(*f.proto, "Kind")->valid_offset, 2u);
}

TEST(Overlays, APeekAcrossAnOverlayCountsNoBytesForIt) {
    Front f = front_end(rules(
        "  <node name=\"Word\" length=\"2byte\" displaytype=\"numberhex\">\n"
        "    <when peek=\"../node[@name='Counter']\" in=\"1\"/>\n"
        "  </node>\n"
        "  <node name=\"Bytes\" overlay=\"../node[@name='Word']\">\n"
        "    <node name=\"Low\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
        "  </node>\n"
        "  <node name=\"Counter\" length=\"1byte\" displaytype=\"numberdec\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    EXPECT_EQ(find(*f.proto, "Word")->whens.front().offset, 2u);
}

TEST(Overlays, AValidFieldInsideAnOverlayIsNotAtAFixedOffset) {
    Front f = front_end(rules(
        "  <node name=\"Word\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
        "  <node name=\"Bytes\" overlay=\"../node[@name='Word']\">\n"
        "    <node name=\"Low\" length=\"1byte\" displaytype=\"numberhex\" valid=\"1\"/>\n"
        "  </node>\n"));
    EXPECT_FALSE(f.ok());
    EXPECT_TRUE(contains(f.messages(), "it is inside 'Bytes' (line 3), which is an overlay")) << f.messages();
}

TEST(Overlays, AreNeverSteppedOverInTheQuietWalk) {
    // Nobody reads Low: a plain container of it would be stepped over by its
    // size, which for an overlay would move the walk.
    Front f = front_end(rules(
        "  <node name=\"Word\" length=\"2byte\" displaytype=\"numberhex\"/>\n"
        "  <node name=\"Bytes\" overlay=\"../node[@name='Word']\">\n"
        "    <node name=\"Low\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
        "  </node>\n"
        "  <node name=\"Box\">\n"
        "    <node name=\"Inner\" overlay=\"../../node[@name='Word']\">\n"
        "      <node name=\"High\" length=\"1byte\" displaytype=\"numberhex\"/>\n"
        "    </node>\n"
        "  </node>\n"
        "  <node name=\"Trailer\" length=\"1byte\" displaytype=\"numberhex\"/>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    auto sizes = quiet_sizes(*f.proto, [](const Node&) { return false; });
    EXPECT_FALSE(sizes.count(find(*f.proto, "Bytes")));
    EXPECT_FALSE(sizes.count(find(*f.proto, "Box")));
    EXPECT_TRUE(sizes.count(find(*f.proto, "Trailer")));
    EXPECT_TRUE(sizes.count(find(*f.proto, "Low")));  // inside: its own bytes, as anywhere
}

}  // namespace
}  // namespace dissgen::testing

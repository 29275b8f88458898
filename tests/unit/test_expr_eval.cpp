// SPDX-License-Identifier: GPL-2.0-or-later
// Computed values end to end without tshark: a rule file's value="..." is
// parsed, checked and compiled by the generator, and the rows it would emit
// are evaluated by the runtime's evaluator (plugin_runtime/dissgen_expr.cpp)
// with field values given here.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>

#include "dissgen_expr.h"
#include "expression.h"
#include "test_support.h"

namespace dissgen::testing {
namespace {

guint8 code_of(const std::string& name) {
    static const std::map<std::string, guint8> codes = {
        {"DG_OP_INT", DG_OP_INT}, {"DG_OP_FLOAT", DG_OP_FLOAT}, {"DG_OP_FIELD", DG_OP_FIELD},
        {"DG_OP_FIELD_SIGNED", DG_OP_FIELD_SIGNED}, {"DG_OP_FIELD_FLOAT", DG_OP_FIELD_FLOAT},
        {"DG_OP_INDEX", DG_OP_INDEX}, {"DG_OP_OFFSET", DG_OP_OFFSET}, {"DG_OP_LEARNED", DG_OP_LEARNED}, {"DG_OP_TO_FLOAT", DG_OP_TO_FLOAT}, {"DG_OP_NEG", DG_OP_NEG},
        {"DG_OP_NOT", DG_OP_NOT}, {"DG_OP_BITNOT", DG_OP_BITNOT}, {"DG_OP_FNEG", DG_OP_FNEG},
        {"DG_OP_FNOT", DG_OP_FNOT}, {"DG_OP_DEFINED", DG_OP_DEFINED}, {"DG_OP_MUL", DG_OP_MUL}, {"DG_OP_DIV", DG_OP_DIV}, {"DG_OP_MOD", DG_OP_MOD},
        {"DG_OP_ADD", DG_OP_ADD}, {"DG_OP_SUB", DG_OP_SUB}, {"DG_OP_SHL", DG_OP_SHL}, {"DG_OP_SHR", DG_OP_SHR},
        {"DG_OP_LT", DG_OP_LT}, {"DG_OP_LE", DG_OP_LE}, {"DG_OP_GT", DG_OP_GT}, {"DG_OP_GE", DG_OP_GE},
        {"DG_OP_EQ", DG_OP_EQ}, {"DG_OP_NE", DG_OP_NE}, {"DG_OP_BITAND", DG_OP_BITAND},
        {"DG_OP_BITXOR", DG_OP_BITXOR}, {"DG_OP_BITOR", DG_OP_BITOR}, {"DG_OP_AND", DG_OP_AND},
        {"DG_OP_OR", DG_OP_OR}, {"DG_OP_FMUL", DG_OP_FMUL}, {"DG_OP_FDIV", DG_OP_FDIV},
        {"DG_OP_FADD", DG_OP_FADD}, {"DG_OP_FSUB", DG_OP_FSUB}, {"DG_OP_FLT", DG_OP_FLT},
        {"DG_OP_FLE", DG_OP_FLE}, {"DG_OP_FGT", DG_OP_FGT}, {"DG_OP_FGE", DG_OP_FGE}, {"DG_OP_FEQ", DG_OP_FEQ},
        {"DG_OP_FNE", DG_OP_FNE}, {"DG_OP_FAND", DG_OP_FAND}, {"DG_OP_FOR", DG_OP_FOR},
        {"DG_OP_SELECT", DG_OP_SELECT}};
    auto it = codes.find(name);
    if (it == codes.end()) ADD_FAILURE() << "no runtime code for " << name;
    return it == codes.end() ? 0 : it->second;
}

// Field values by slot; a slot missing from the map was not decoded.
using Slots = std::map<gint16, guint64>;

gboolean read_slot(const void* context, gint16 slot, guint64* value) {
    const Slots& slots = *static_cast<const Slots*>(context);
    auto it = slots.find(slot);
    if (it == slots.end()) return FALSE;
    *value = it->second;
    return TRUE;
}

// Rule file fields: A (2 bytes), S (1-byte int), C (1 byte); then the value under test.
struct Evaluated {
    dg_expr_value v{};
    std::string error;
};

// expr as an XML attribute value.
std::string escaped(const std::string& expr) {
    std::string out;
    for (char c : expr) out += c == '&' ? "&amp;" : c == '<' ? "&lt;" : std::string(1, c);
    return out;
}

// `offset`: the computed value sits at byte 21 of its message.
gboolean offset_21(const void*, guint64* value) {
    *value = 21;
    return TRUE;
}

Evaluated evaluate(const std::string& expr, const Slots& by_name, guint32 index = 0, const std::string& display = "") {
    Front f = front_end(rules("  <node name=\"A\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"S\" length=\"1byte\" displaytype=\"int\"/>\n"
                              "  <node name=\"C\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"F\" value=\"{A} * 0.5\"/>\n"
                              "  <node name=\"R\" count=\"../node[@name='C']\">\n"
                              "    <node name=\"V\" value=\"" + escaped(expr) + "\"" +
                              (display.empty() ? "" : " displaytype=\"" + display + "\"") + "/>\n"
                              "  </node>\n"));
    Evaluated out;
    if (!f.ok()) {
        out.error = f.messages();
        return out;
    }
    const Node& v = *f.proto->nodes[4]->children[0];
    std::vector<dg_expr_op> ops;
    for (const ExprRow& r : compile_expression(*v.value, v.display == Display::Float))
        ops.push_back({code_of(r.code), static_cast<guint8>(r.bits), static_cast<gint16>(r.slot), r.integer, r.real});
    // Slots of the fields by name (A, S, C, F: the evaluator reads them by slot).
    Slots slots;
    for (const auto& [name, value] : by_name) {
        const char* names[] = {"A", "S", "C", "F"};
        const Node* n = find(*f.proto, names[name]);
        if (n->slot >= 0) slots[static_cast<gint16>(n->slot)] = value;
    }
    const dg_expr_readers readers = {read_slot, nullptr, nullptr, offset_21};
    out.v = dg_expr_eval(ops.data(), static_cast<guint>(ops.size()), &readers, &slots, index);
    return out;
}

enum { A, S, C, F };

// How a float computed value keeps its value in a slot: the double's bits.
guint64 bits_of(double d) {
    guint64 bits;
    std::memcpy(&bits, &d, sizeof bits);
    return bits;
}

const Slots kFields = {{A, 1000}, {S, 0xfe}, {C, 3}, {F, bits_of(500.0)}};

gint64 integer(const std::string& expr, const Slots& fields = kFields, guint32 index = 0) {
    Evaluated e = evaluate(expr, fields, index);
    EXPECT_EQ(e.error, "") << expr;
    EXPECT_TRUE(e.v.defined) << expr;
    EXPECT_FALSE(e.v.is_float) << expr;
    return e.v.integer;
}

double real(const std::string& expr, const Slots& fields = kFields) {
    Evaluated e = evaluate(expr, fields);
    EXPECT_EQ(e.error, "") << expr;
    EXPECT_TRUE(e.v.defined) << expr;
    EXPECT_TRUE(e.v.is_float) << expr;
    return e.v.real;
}

bool undefined(const std::string& expr, const Slots& fields = kFields) {
    Evaluated e = evaluate(expr, fields);
    EXPECT_EQ(e.error, "") << expr;
    return !e.v.defined;
}

TEST(ComputedEval, TheDeepestExpressionTheParserTakesFitsTheStack) {
    // Each operator of rising precedence and each parenthesis leaves an operand waiting.
    const std::string ladder = "1 || 1 && 1 | 1 ^ 1 & 1 == 1 < 1 << 1 + 1 * (";
    std::string deepest;
    for (int i = 0; i < 5; ++i) deepest += ladder;
    const std::string inner = "1 || 1 && 1 | 1 ^ 1 & 1 == 1 < 1 << 1 + 1";
    Evaluated e = evaluate(deepest + inner + ")))))", kFields);
    ASSERT_EQ(e.error, "");
    EXPECT_TRUE(e.v.defined);
    EXPECT_EQ(e.v.integer, 1);
    // one operand more waiting: refused by the parser, not left to the evaluator
    EXPECT_NE(evaluate(deepest + inner + " * 1)))))", kFields).error, "");
}

TEST(ComputedEval, TheLongestConditionalChainTheParserTakesFitsTheStack) {
    // 0 ? 0 : 0 ? 0 : ... 7: each level leaves its condition and first value waiting.
    std::string accepted;
    for (std::string chain = "7";; chain = "0 ? 0 : " + chain) {
        Evaluated e = evaluate(chain, kFields);
        if (!e.error.empty()) break;
        accepted = chain;
        ASSERT_TRUE(e.v.defined) << chain;
        EXPECT_EQ(e.v.integer, 7);
    }
    EXPECT_GT(accepted.size(), 8 * 20u);  // some 30 levels, not a handful
}

TEST(ComputedEval, IntegerArithmeticAsInC) {
    EXPECT_EQ(integer("{A} + index + 1", {{A, 40000}, {C, 5}}, 3), 40004);
    // where the value sits, as the walk's reader gives it (here 21): alignment padding
    EXPECT_EQ(integer("offset"), 21);
    EXPECT_EQ(integer("(4 - offset % 4) % 4 + index", kFields, 2), 5);
    EXPECT_NE(evaluate("offsets", kFields).error.find("expected a number, {field}, index, offset or '('"),
              std::string::npos);
    EXPECT_EQ(integer("{S}"), -2);                 // an int field is signed
    EXPECT_EQ(integer("{C} - 5"), -2);
    EXPECT_EQ(integer("7 / 2"), 3);
    EXPECT_EQ(integer("-7 / 2"), -3);             // truncates toward zero
    EXPECT_EQ(integer("-7 % 3"), -1);
    EXPECT_EQ(integer("1 << 4 | 3"), 19);
    EXPECT_EQ(integer("0xff & ~0x0f ^ 1"), 0xf1);
    EXPECT_EQ(integer("{A} >> 3"), 125);
    EXPECT_EQ(integer("1 << 64"), 0);
    EXPECT_EQ(integer("-1 >> 60"), 15);           // the bit pattern shifts
    EXPECT_EQ(integer("9223372036854775807 + 1"), INT64_MIN);  // wraps
    EXPECT_EQ(integer("(-9223372036854775807 - 1) / -1"), INT64_MIN);  // wraps, no trap
    EXPECT_EQ(integer("(-9223372036854775807 - 1) % -1"), 0);
}

TEST(ComputedEval, ComparisonsAndLogicGiveZeroOrOne) {
    EXPECT_EQ(integer("{C} == 3"), 1);
    EXPECT_EQ(integer("{C} != 3"), 0);
    EXPECT_EQ(integer("{S} < 0"), 1);
    EXPECT_EQ(integer("{C} <= 2 || {C} >= 3"), 1);
    EXPECT_EQ(integer("{C} > 2 && 5"), 1);
    EXPECT_EQ(integer("!{C}"), 0);
    EXPECT_EQ(integer("!!{C}"), 1);
    EXPECT_EQ(integer("{F} > 499.5"), 1);  // on reals, still 0 or 1
}

TEST(ComputedEval, UndefinedWhenAFieldIsMissingOrIntegerDivisionByZero) {
    EXPECT_TRUE(undefined("{A} / ({C} - 3)"));
    EXPECT_TRUE(undefined("{A} % 0"));
    EXPECT_TRUE(undefined("{A} + 1", {{C, 3}}));
    // the left side decides, as in C
    EXPECT_EQ(integer("{C} != 3 && {A} / ({C} - 3) > 1"), 0);
    EXPECT_EQ(integer("{C} == 3 || {A} / 0"), 1);
    EXPECT_EQ(integer("{C} == 3 || {A} > 1", {{C, 3}}), 1);
    EXPECT_TRUE(undefined("{C} == 4 || {A} > 1", {{C, 3}}));
    EXPECT_TRUE(undefined("{A} > 1 || {C} == 3", {{C, 3}}));  // an undefined left decides nothing
}

TEST(ComputedEval, ConditionalChoosesAndOnlyTheChosenValueMustBeDefined) {
    EXPECT_EQ(integer("{C} == 3 ? {A} : 7"), 1000);
    EXPECT_EQ(integer("{C} == 4 ? {A} : 7"), 7);
    EXPECT_EQ(integer("{S} < 0 ? -{S} : {S}"), 2);
    EXPECT_EQ(integer("{C} ? 1 : 2 + 3"), 1);             // ?: below every binary operator
    EXPECT_EQ(integer("0 ? 1 : {C} == 3 ? 2 : 3"), 2);    // right to left
    // a BER-style length: short form, else the long form's bytes
    EXPECT_EQ(integer("{C} < 0x80 ? {C} : {A}", {{C, 3}}), 3);   // A not decoded, not chosen
    EXPECT_EQ(integer("{C} == 3 ? 1 : {A} / 0"), 1);
    EXPECT_TRUE(undefined("{C} == 3 ? {A} : 1", {{C, 3}}));      // the chosen one undefined
    EXPECT_TRUE(undefined("{A} ? 1 : 2", {{C, 3}}));             // an undefined condition
    EXPECT_EQ(integer("{F} > 1.5 ? 1 : 0"), 1);                   // a comparison of reals, integer values
    EXPECT_EQ(integer("{F} ? 1 : 2"), 1);                         // a real condition: not 0.0
    EXPECT_EQ(integer("{F} - 500 ? 1 : 2"), 2);                   // 0.0: the other value
    EXPECT_EQ(integer("{F} * 0.0 ? 1 : 2", {{F, bits_of(-0.0)}}), 2);
    EXPECT_DOUBLE_EQ(real("{C} == 3 ? 1 : 0.5"), 1.0);           // one real value: both real
    EXPECT_DOUBLE_EQ(real("{C} == 3 ? 0.5 : {A}"), 0.5);
    EXPECT_DOUBLE_EQ(real("({C} == 4 ? 0.5 : {A}) / 3"), 1000.0 / 3);
}

TEST(ComputedEval, DefinedAsksWhetherAFieldWasDecoded) {
    EXPECT_EQ(integer("defined({A})"), 1);
    EXPECT_EQ(integer("defined({A})", {{C, 3}}), 0);  // A not decoded: 0, itself defined
    EXPECT_EQ(integer("defined( {F} )"), 1);          // a float value's, an integer answer
    EXPECT_EQ(integer("!defined({A}) + 2 * defined({C})", {{C, 3}}), 3);
    EXPECT_EQ(integer("defined({A}) && {A} > 999"), 1);
    EXPECT_EQ(integer("defined({A}) && {A} / 0", {{C, 3}}), 0);  // the left side decides
    EXPECT_DOUBLE_EQ(real("defined({A}) * 0.5"), 0.5);
    // a field only: a number, index or expression is an error, and so is a missing '('
    EXPECT_NE(evaluate("defined(3)", kFields).error.find("asks about one field, {Name}, request{Name} or learned{Name}: a number, "
                                                         "index or offset is always defined"), std::string::npos);
    EXPECT_NE(evaluate("defined({A} + 1)", kFields).error.find("ask about that field"), std::string::npos);
    EXPECT_NE(evaluate("defined {A}", kFields).error.find("expected '(' after 'defined'"), std::string::npos);
}

TEST(ComputedEval, RealsWhenADecimalTakesPart) {
    EXPECT_DOUBLE_EQ(real("{S} * 0.1 - 40"), -40.2);
    EXPECT_DOUBLE_EQ(real("{F} + 1"), 501.0);     // a float computed value read back
    EXPECT_DOUBLE_EQ(real("({A} + 1) / 2.0"), 500.5);
    EXPECT_DOUBLE_EQ(real("{A} / 3 * 1.0"), 333.0);  // the integer division comes first
    EXPECT_DOUBLE_EQ(real("-{F}"), -500.0);
    EXPECT_TRUE(std::isinf(real("1.0 / 0")));      // IEEE: not undefined
    Evaluated shown_as_float = evaluate("{C} * 2", {{A, 1}, {C, 3}}, 0, "float");
    EXPECT_TRUE(shown_as_float.v.is_float);
    EXPECT_DOUBLE_EQ(shown_as_float.v.real, 6.0);
}

// A request's kept value, read by request{X}: the runtime op the generator emits for a
// field of the request (DG_OP_REQUEST_FIELD*), over a reader that has it or not.
dg_expr_value request_operand(guint8 code, guint8 bits, const Slots& request) {
    const dg_expr_op op{code, bits, 0, 0, 0.0};
    const dg_expr_readers readers = {read_slot, read_slot, nullptr, nullptr};
    return dg_expr_eval(&op, 1, &readers, &request, 0);
}

TEST(ComputedEval, RequestFieldsSignedLikeTheMessagesOwn) {
    // A 16-bit int of the request holding 0xfffe is -2, as {X} of a field of the message is.
    dg_expr_value v = request_operand(DG_OP_REQUEST_FIELD_SIGNED, 16, {{0, 0xfffe}});
    ASSERT_TRUE(v.defined);
    EXPECT_EQ(v.integer, -2);
    EXPECT_EQ(request_operand(DG_OP_REQUEST_FIELD_SIGNED, 8, {{0, 0x7f}}).integer, 127);
    EXPECT_EQ(request_operand(DG_OP_REQUEST_FIELD, 16, {{0, 0xfffe}}).integer, 65534);  // unsigned stays so
}

TEST(ComputedEval, RequestFieldTheRequestLacksIsUndefinedNotZero) {
    // The reader has no value (the request's instance lacks the field): undefined, never 0.
    EXPECT_FALSE(request_operand(DG_OP_REQUEST_FIELD_SIGNED, 16, {}).defined);
    EXPECT_FALSE(request_operand(DG_OP_REQUEST_FIELD, 16, {}).defined);
}

// learned{X}: the runtime op over a reader that knows a value for the <learn>'s row or not.
TEST(ComputedEval, LearnedValuesReadByTheirRowAndUndefinedWhenNotLearned) {
    Front f = front_end(rules("  <node name=\"A\" length=\"2byte\" displaytype=\"numberdec\"/>\n"
                              "  <node name=\"Scaled\" value=\"{A} * learned{Scale} + learned{Offset}\"/>\n"
                              "  <node name=\"Known\" value=\"defined(learned{Scale})\"/>\n"
                              "  <node name=\"Setup\">\n"
                              "    <node name=\"B\" length=\"1byte\" displaytype=\"numberdec\"/>\n"
                              "    <learn name=\"Offset\" value=\"{B} - 10\"/>\n"
                              "    <learn name=\"Scale\" value=\"{B}\"/>\n"
                              "  </node>\n"));
    ASSERT_TRUE(f.ok()) << f.messages();
    auto ops_of = [&](const char* name) {
        const Node* n = find(*f.proto, name);
        std::vector<dg_expr_op> ops;
        for (const ExprRow& r : compile_expression(*n->value, false))
            ops.push_back({code_of(r.code), static_cast<guint8>(r.bits), static_cast<gint16>(r.slot), r.integer, r.real});
        return ops;
    };
    // the rows by document order: Offset 0, Scale 1; learned values by row, as read_slot reads slots
    Slots learned = {{0, static_cast<guint64>(-3)}, {1, 7}};
    Slots fields;
    fields[static_cast<gint16>(find(*f.proto, "A")->slot)] = 5;
    struct Context {
        const Slots* fields;
        const Slots* learned;
    } context{&fields, &learned};
    const dg_expr_readers readers = {
        [](const void* c, gint16 slot, guint64* v) { return read_slot(static_cast<const Context*>(c)->fields, slot, v); },
        nullptr,
        [](const void* c, gint16 row, guint64* v) { return read_slot(static_cast<const Context*>(c)->learned, row, v); },
        nullptr};
    std::vector<dg_expr_op> scaled = ops_of("Scaled"), known = ops_of("Known");
    dg_expr_value v = dg_expr_eval(scaled.data(), static_cast<guint>(scaled.size()), &readers, &context, 0);
    ASSERT_TRUE(v.defined);
    EXPECT_EQ(v.integer, 5 * 7 - 3);  // a learned value is a signed 64-bit integer
    EXPECT_EQ(dg_expr_eval(known.data(), static_cast<guint>(known.size()), &readers, &context, 0).integer, 1);
    learned.erase(1);  // Scale not learned: undefined, and defined() says 0
    EXPECT_FALSE(dg_expr_eval(scaled.data(), static_cast<guint>(scaled.size()), &readers, &context, 0).defined);
    EXPECT_EQ(dg_expr_eval(known.data(), static_cast<guint>(known.size()), &readers, &context, 0).integer, 0);
    const dg_expr_readers without = {readers.field, nullptr, nullptr};  // no reader: undefined
    learned[1] = 7;
    EXPECT_FALSE(dg_expr_eval(scaled.data(), static_cast<guint>(scaled.size()), &without, &context, 0).defined);
}

}  // namespace
}  // namespace dissgen::testing

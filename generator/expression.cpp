// SPDX-License-Identifier: GPL-2.0-or-later
// A precedence-climbing parser for value="..." expressions (see expression.h).
#include "expression.h"

#include "model.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>

namespace dissgen {

namespace {

struct BinaryOp {
    const char* text;
    ExprOp op;
    int precedence;  // higher binds tighter
};

// Longest spellings first, so that "<<" is not read as "<".
const BinaryOp kBinary[] = {
    {"||", ExprOp::Or, 1},  {"&&", ExprOp::And, 2},   {"<<", ExprOp::Shl, 9},   {">>", ExprOp::Shr, 9},
    {"<=", ExprOp::Le, 8},  {">=", ExprOp::Ge, 8},    {"==", ExprOp::Eq, 7},    {"!=", ExprOp::Ne, 7},
    {"|", ExprOp::BitOr, 3}, {"^", ExprOp::BitXor, 4}, {"&", ExprOp::BitAnd, 5}, {"<", ExprOp::Lt, 8},
    {">", ExprOp::Gt, 8},   {"+", ExprOp::Add, 10},   {"-", ExprOp::Sub, 10},   {"*", ExprOp::Mul, 11},
    {"/", ExprOp::Div, 11}, {"%", ExprOp::Mod, 11},
};

// Deep nesting is refused before it can exhaust the stack.
constexpr int kMaxDepth = 64;
// A chain (a + b + c ...) is read in a loop, but its tree deepens by one per
// operator, and the validator and the emitters recurse over the tree.
constexpr int kMaxChain = 1024;

class ExprParser {
public:
    explicit ExprParser(const std::string& text) : s_(text) {}

    bool parse(Expr& out, std::string& error) {
        int height = 0;
        bool ok = conditional(out, 0, height);
        skip_space();
        if (ok && pos_ < s_.size()) ok = fail("unexpected '" + s_.substr(pos_, 1) + "'");
        if (ok && s_.find_first_not_of(" \t\r\n") == std::string::npos) ok = fail("empty expression");
        if (!ok) error = error_;
        return ok;
    }

private:
    const std::string& s_;
    size_t pos_ = 0;
    std::string error_;

    bool fail(const std::string& what) {
        if (error_.empty()) error_ = what + " at character " + std::to_string(pos_ + 1);
        return false;
    }

    void skip_space() {
        while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
    }

    const BinaryOp* peek_binary() {
        skip_space();
        for (const BinaryOp& b : kBinary)
            if (s_.compare(pos_, std::char_traits<char>::length(b.text), b.text) == 0) return &b;
        return nullptr;
    }

    // c ? a : b, below every binary operator, right to left (a ? b : c ? d : e
    // is a ? b : (c ? d : e)). While the runtime evaluates `b`, `c` and `a`
    // wait on its stack: `b` is read two levels deeper, so that the nesting
    // limit still bounds the stack (DG_EXPR_STACK).
    bool conditional(Expr& out, int depth, int& height) {
        if (!binary(out, 1, depth, height)) return false;
        skip_space();
        if (pos_ >= s_.size() || s_[pos_] != '?') return true;
        ++pos_;
        Expr then_value, else_value;
        int then_height = 0, else_height = 0;
        if (!conditional(then_value, depth + 1, then_height)) return false;
        skip_space();
        if (pos_ >= s_.size() || s_[pos_] != ':') return fail("missing ':' of '?'");
        ++pos_;
        if (!conditional(else_value, depth + 2, else_height)) return false;
        height = std::max({height, then_height, else_height}) + 1;
        if (height > kMaxChain)
            return fail("expression too long (more than " + std::to_string(kMaxChain) + " operators deep)");
        Expr joined;
        joined.op = ExprOp::Conditional;
        joined.args.push_back(std::move(out));
        joined.args.push_back(std::move(then_value));
        joined.args.push_back(std::move(else_value));
        out = std::move(joined);
        return true;
    }

    // Operands joined by operators of at least `min_precedence`, left to right.
    // `height`: the levels of operators in the tree read.
    bool binary(Expr& out, int min_precedence, int depth, int& height) {
        if (!unary(out, depth, height)) return false;
        for (const BinaryOp* b = peek_binary(); b && b->precedence >= min_precedence; b = peek_binary()) {
            pos_ += std::char_traits<char>::length(b->text);
            Expr rhs;
            int rhs_height = 0;
            if (!binary(rhs, b->precedence + 1, depth + 1, rhs_height)) return false;
            height = std::max(height, rhs_height) + 1;
            if (height > kMaxChain)
                return fail("expression too long (more than " + std::to_string(kMaxChain) + " operators deep)");
            Expr joined;
            joined.op = b->op;
            joined.args.push_back(std::move(out));
            joined.args.push_back(std::move(rhs));
            out = std::move(joined);
        }
        return true;
    }

    bool unary(Expr& out, int depth, int& height) {
        if (depth > kMaxDepth) return fail("expression nested too deeply");
        skip_space();
        const char c = pos_ < s_.size() ? s_[pos_] : '\0';
        if (c == '-' || c == '!' || c == '~') {
            ++pos_;
            Expr operand;
            if (!unary(operand, depth + 1, height)) return false;
            ++height;
            out.op = c == '-' ? ExprOp::Neg : c == '!' ? ExprOp::Not : ExprOp::BitNot;
            out.args.push_back(std::move(operand));
            return true;
        }
        if (s_.compare(pos_, 7, "defined") == 0) return defined(out, depth, height);
        if (c == '(') {
            ++pos_;
            if (!conditional(out, depth + 1, height)) return false;
            skip_space();
            if (pos_ >= s_.size() || s_[pos_] != ')') return fail("missing ')'");
            ++pos_;
            return true;
        }
        height = 0;
        return operand(out);
    }

    // defined(X): whatever X is here; the validator allows a field only.
    bool defined(Expr& out, int depth, int& height) {
        pos_ += 7;
        skip_space();
        if (pos_ >= s_.size() || s_[pos_] != '(') return fail("expected '(' after 'defined'");
        ++pos_;
        Expr inner;
        if (!conditional(inner, depth + 1, height)) return false;
        skip_space();
        if (pos_ >= s_.size() || s_[pos_] != ')') return fail("missing ')'");
        ++pos_;
        ++height;
        out.op = ExprOp::Defined;
        out.args.push_back(std::move(inner));
        return true;
    }

    bool operand(Expr& out) {
        const char c = pos_ < s_.size() ? s_[pos_] : '\0';
        if (c == '{') {
            size_t end = s_.find('}', pos_ + 1);
            if (end == std::string::npos) return fail("missing '}'");
            out.op = ExprOp::Field;
            out.name = s_.substr(pos_ + 1, end - pos_ - 1);
            if (out.name.empty()) return fail("empty field name '{}'");
            pos_ = end + 1;
            return true;
        }
        if (s_.compare(pos_, 8, "request{") == 0) {
            pos_ += 7;  // past "request": the field is read from its brace
            if (!operand(out)) return false;
            out.op = ExprOp::RequestField;
            return true;
        }
        if (s_.compare(pos_, 8, "learned{") == 0) {
            pos_ += 7;  // past "learned": the name is read from its brace
            if (!operand(out)) return false;
            out.op = ExprOp::Learned;
            return true;
        }
        if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number(out);
        if (s_.compare(pos_, 5, "index") == 0 &&
            (pos_ + 5 >= s_.size() || !std::isalnum(static_cast<unsigned char>(s_[pos_ + 5])))) {
            out.op = ExprOp::Index;
            pos_ += 5;
            return true;
        }
        if (s_.compare(pos_, 6, "offset") == 0 &&
            (pos_ + 6 >= s_.size() || !std::isalnum(static_cast<unsigned char>(s_[pos_ + 6])))) {
            out.op = ExprOp::Offset;
            pos_ += 6;
            return true;
        }
        if (c == '\0') return fail("expected a number, {field}, index, offset or '(' but the expression ends");
        return fail("expected a number, {field}, index, offset or '(' but found '" + s_.substr(pos_, 1) + "'");
    }

    bool number(Expr& out) {
        const size_t start = pos_;
        const bool hex = s_.compare(pos_, 2, "0x") == 0 || s_.compare(pos_, 2, "0X") == 0;
        size_t end = hex ? pos_ + 2 : pos_;
        bool point = false;
        while (end < s_.size() && (hex ? std::isxdigit(static_cast<unsigned char>(s_[end]))
                                       : std::isdigit(static_cast<unsigned char>(s_[end])) || s_[end] == '.')) {
            if (s_[end] == '.') {
                if (point) break;
                point = true;
            }
            ++end;
        }
        const std::string digits = s_.substr(start, end - start);
        if (end < s_.size() && std::isalnum(static_cast<unsigned char>(s_[end])))
            return fail("bad number '" + digits + s_[end] + "'");
        if (digits == "." || (hex && digits.size() == 2)) return fail("bad number '" + digits + "'");
        errno = 0;
        if (point) {
            out.op = ExprOp::Float;
            out.real = std::strtod(digits.c_str(), nullptr);
            if (errno == ERANGE) return fail("number '" + digits + "' is out of range");
        } else {
            out.op = ExprOp::Int;
            unsigned long long v = std::strtoull(digits.c_str(), nullptr, hex ? 16 : 10);
            if (errno == ERANGE || v > static_cast<unsigned long long>(INT64_MAX))
                return fail("number '" + digits + "' is above 9223372036854775807");
            out.integer = static_cast<int64_t>(v);
        }
        pos_ = end;
        return true;
    }
};

}  // namespace

bool parse_expression(const std::string& text, Expr& out, std::string& error) {
    out = Expr();
    return ExprParser(text).parse(out, error);
}

const char* expr_op_text(ExprOp op) {
    for (const BinaryOp& b : kBinary)
        if (b.op == op) return b.text;
    switch (op) {
    case ExprOp::Neg: return "-";
    case ExprOp::Not: return "!";
    case ExprOp::BitNot: return "~";
    case ExprOp::Defined: return "defined";
    case ExprOp::Conditional: return "?:";
    default: return "";
    }
}

bool expr_op_needs_integers(ExprOp op) {
    switch (op) {
    case ExprOp::Mod: case ExprOp::Shl: case ExprOp::Shr: case ExprOp::BitAnd:
    case ExprOp::BitXor: case ExprOp::BitOr: case ExprOp::BitNot:
        return true;
    default:
        return false;
    }
}

uint64_t expr_mask(const Expr& e) {
    if (e.op != ExprOp::BitAnd || e.is_float) return ~uint64_t{0};
    for (const Expr& a : e.args)
        if (a.op == ExprOp::Int && a.integer >= 0) return static_cast<uint64_t>(a.integer);
    return ~uint64_t{0};
}

unsigned expr_value_bits(const Expr& e) {
    const uint64_t mask = expr_mask(e);
    for (unsigned bits : {8u, 16u, 32u})
        if (mask >> bits == 0) return bits;
    return 64;
}

namespace {

const char* integer_code(ExprOp op) {
    switch (op) {
    case ExprOp::Neg: return "DG_OP_NEG";
    case ExprOp::Not: return "DG_OP_NOT";
    case ExprOp::BitNot: return "DG_OP_BITNOT";
    case ExprOp::Defined: return "DG_OP_DEFINED";
    case ExprOp::Mul: return "DG_OP_MUL";
    case ExprOp::Div: return "DG_OP_DIV";
    case ExprOp::Mod: return "DG_OP_MOD";
    case ExprOp::Add: return "DG_OP_ADD";
    case ExprOp::Sub: return "DG_OP_SUB";
    case ExprOp::Shl: return "DG_OP_SHL";
    case ExprOp::Shr: return "DG_OP_SHR";
    case ExprOp::Lt: return "DG_OP_LT";
    case ExprOp::Le: return "DG_OP_LE";
    case ExprOp::Gt: return "DG_OP_GT";
    case ExprOp::Ge: return "DG_OP_GE";
    case ExprOp::Eq: return "DG_OP_EQ";
    case ExprOp::Ne: return "DG_OP_NE";
    case ExprOp::BitAnd: return "DG_OP_BITAND";
    case ExprOp::BitXor: return "DG_OP_BITXOR";
    case ExprOp::BitOr: return "DG_OP_BITOR";
    case ExprOp::And: return "DG_OP_AND";
    default: return "DG_OP_OR";
    }
}

// The double variant of an operator that has one (the others need integers).
std::string float_code(ExprOp op) {
    const std::string code = integer_code(op);
    return "DG_OP_F" + code.substr(6);
}

void compile_into(const Expr& e, bool as_float, std::vector<ExprRow>& out) {
    ExprRow row;
    switch (e.op) {
    case ExprOp::Int:
        if (as_float) {
            row.code = "DG_OP_FLOAT";
            row.real = static_cast<double>(e.integer);
        } else {
            row.code = "DG_OP_INT";
            row.integer = e.integer;
        }
        out.push_back(row);
        return;
    case ExprOp::Float:
        row.code = "DG_OP_FLOAT";
        row.real = e.real;
        out.push_back(row);
        return;
    case ExprOp::Index:
        out.push_back({"DG_OP_INDEX"});
        if (as_float) out.push_back({"DG_OP_TO_FLOAT"});
        return;
    case ExprOp::Offset:
        out.push_back({"DG_OP_OFFSET"});
        if (as_float) out.push_back({"DG_OP_TO_FLOAT"});
        return;
    case ExprOp::Defined:  // of a value of any type, giving an integer
        compile_into(e.args[0], e.args[0].is_float, out);
        out.push_back({"DG_OP_DEFINED"});
        if (as_float) out.push_back({"DG_OP_TO_FLOAT"});
        return;
    case ExprOp::Learned:  // an integer
        row.code = "DG_OP_LEARNED";
        row.slot = e.learn_index;
        out.push_back(row);
        if (as_float) out.push_back({"DG_OP_TO_FLOAT"});
        return;
    case ExprOp::Field:
    case ExprOp::RequestField: {
        const std::string prefix = e.op == ExprOp::Field ? "DG_OP_FIELD" : "DG_OP_REQUEST_FIELD";
        row.slot = e.op == ExprOp::Field ? e.target->slot : e.request_index;
        if (e.is_float) {
            row.code = prefix + "_FLOAT";
        } else if (e.target->display == Display::Int) {
            row.code = prefix + "_SIGNED";
            row.bits = e.target->bits;
        } else {
            row.code = prefix;
        }
        out.push_back(row);
        if (as_float && !e.is_float) out.push_back({"DG_OP_TO_FLOAT"});
        return;
    }
    case ExprOp::Conditional:  // the condition in its own type; the chosen value as wanted
        compile_into(e.args[0], e.args[0].is_float, out);
        compile_into(e.args[1], as_float || e.is_float, out);
        compile_into(e.args[2], as_float || e.is_float, out);
        out.push_back({"DG_OP_SELECT"});
        return;
    default:
        break;
    }
    // The operands work in double when one of them is a double.
    bool operands_float = false;
    for (const Expr& a : e.args) operands_float = operands_float || a.is_float;
    for (const Expr& a : e.args) compile_into(a, operands_float, out);
    out.push_back({operands_float ? float_code(e.op) : integer_code(e.op)});
    // Comparisons and logic give an integer even on doubles.
    if (as_float && !e.is_float) out.push_back({"DG_OP_TO_FLOAT"});
}

}  // namespace

std::vector<ExprRow> compile_expression(const Expr& e, bool as_float) {
    std::vector<ExprRow> out;
    compile_into(e, as_float, out);
    return out;
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
// Computed values: the expression of a node's value="..." attribute, parsed
// into a tree here and checked by the validator (names resolved, types).
//
//   value="{Starting address} + index + 1"
//   value="{Raw temperature} * 0.1 - 40"
//
// Operands: integers (decimal, 0x hex), decimals with a point (1.5),
// {Name} (the value of an earlier numeric field), index (the instance number
// of the innermost repeated node, from 0), request{Name} (the value of a
// field of the paired request message, in a protocol with <pairing>),
// learned{Name} (the value a <learn> of that name learned in an earlier
// message under this message's keys), defined({Name}) / defined(request{Name})
// / defined(learned{Name}) (1 when that value is defined: the field was
// decoded, the request was captured, a value was learned; else 0).
// Operators as in C, with C's
// precedence: unary - ! ~; * / %; + -; << >>; < <= > >=; == !=; &; ^; |;
// &&; ||; c ? a : b (right to left); and parentheses.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dissgen {

struct Node;

enum class ExprOp {
    Int, Float, Field, Index, RequestField,    // operands
    Offset,                                    // offset: where a computed value sits in its message
    Learned,                                   // learned{Name}: a <learn>'s value from earlier messages
    Neg, Not, BitNot, Defined,                 // unary; Defined: defined(X), 1 when X is, else 0
    Mul, Div, Mod, Add, Sub, Shl, Shr,         // binary, arithmetic
    Lt, Le, Gt, Ge, Eq, Ne,                    // binary, comparisons (0 or 1)
    BitAnd, BitXor, BitOr, And, Or,            // binary, logic
    Conditional,                               // c ? a : b: args c, a, b
};

struct Expr {
    ExprOp op = ExprOp::Int;
    int64_t integer = 0;            // Int
    double real = 0;                // Float
    std::string name;               // Field, RequestField, Learned: the name between the braces
    Node* target = nullptr;         // Field, RequestField: resolved by the validator
    int request_index = -1;         // RequestField: its place among the values a request keeps
    int learn_index = -1;           // Learned: the <learn>'s row (Learn::index)
    std::vector<Expr> args;         // one (unary), two (binary) or three (conditional) operands
    bool is_float = false;          // derived by the validator: evaluated in double
};

// One operation of a compiled expression, as the runtime's dg_expr_op
// (plugin_runtime/dissgen_expr.h) holds it: `code` is its DG_OP_ name.
struct ExprRow {
    std::string code;
    unsigned bits = 0;   // DG_OP_FIELD_SIGNED, DG_OP_REQUEST_FIELD_SIGNED
    int slot = -1;       // DG_OP_FIELD*; DG_OP_REQUEST_FIELD*: the index into the request's kept values;
                         // DG_OP_LEARNED*: the <learn>'s row
    int64_t integer = 0; // DG_OP_INT
    double real = 0;     // DG_OP_FLOAT
};

// A checked expression (targets resolved and slotted, types derived) in
// postfix order; `as_float`: the result is wanted as a double.
std::vector<ExprRow> compile_expression(const Expr& e, bool as_float);

// Parses `text`; on a mistake returns false and sets `error` to a message
// that says where ("... at character 7").
bool parse_expression(const std::string& text, Expr& out, std::string& error);

// The operator's spelling ("+", "<<", ...), "" for operands.
const char* expr_op_text(ExprOp op);

// Integer-only operators: % << >> & ^ | ~ (a float operand is an error).
bool expr_op_needs_integers(ExprOp op);

// The width of a value `e` computes: when its last operator is `&` with a
// constant on either side, 8, 16 or 32 bits, the least that holds the constant
// (0xFFFF: 16, 0xFFFFFF: 32); else 64.
unsigned expr_value_bits(const Expr& e);
// The constant of an expression whose last operator is '&' with a constant on
// either side (the values it can take are at most that); all ones otherwise.
uint64_t expr_mask(const Expr& e);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
/* Computed values (value="..." in the rules): an expression compiled by
 * dissgen into operations in postfix order, evaluated here on a small stack.
 *
 * Pure: no packet, no tree. The walk hands in how to read a slot's value, how
 * to read a value the paired request kept (request{Name}) and one learned
 * from earlier messages (learned{Name}), and the current instance index
 * (dissgen_walk's computed leaves).
 *
 * Integers are 64-bit two's complement and wrap; a shift by 64 or more gives
 * 0 (>> shifts the bit pattern, as for unsigned values). A value is
 * undefined when a field it reads was not decoded in this message, or it
 * divides an integer by zero; && and || give a defined answer when their
 * left side decides, as in C, so "{n} != 0 && {x} / {n} > 2" is safe; so
 * does c ? a : b, defined when c and the value it chooses are.
 * defined(X) asks: 1 when X is defined, 0 when not, never undefined.
 */
#pragma once

#include <glib.h>

enum dg_expr_code {
    /* operands */
    DG_OP_INT,          /* integer */
    DG_OP_FLOAT,        /* real */
    DG_OP_FIELD,        /* slot's value, unsigned */
    DG_OP_FIELD_SIGNED, /* slot's value, sign-extended from `bits` */
    DG_OP_FIELD_FLOAT,  /* slot's value holds a double's bits (a float computed value) */
    /* request{Name}: as the three above, `slot` the index of the value the
     * paired request kept */
    DG_OP_REQUEST_FIELD, DG_OP_REQUEST_FIELD_SIGNED, DG_OP_REQUEST_FIELD_FLOAT,
    DG_OP_LEARNED,      /* learned{Name}: an integer, `slot` the <learn>'s row */
    DG_OP_INDEX,        /* the instance number of the innermost repeat */
    DG_OP_OFFSET,       /* where the computed value sits: bytes from its message's start */
    DG_OP_TO_FLOAT,     /* the integer on top becomes a double */
    /* unary, on integers (F: on doubles) */
    DG_OP_NEG, DG_OP_NOT, DG_OP_BITNOT, DG_OP_FNEG, DG_OP_FNOT,
    DG_OP_DEFINED,      /* 1 when the value on top is defined, else 0: itself always defined */
    /* binary, on integers */
    DG_OP_MUL, DG_OP_DIV, DG_OP_MOD, DG_OP_ADD, DG_OP_SUB, DG_OP_SHL, DG_OP_SHR,
    DG_OP_LT, DG_OP_LE, DG_OP_GT, DG_OP_GE, DG_OP_EQ, DG_OP_NE,
    DG_OP_BITAND, DG_OP_BITXOR, DG_OP_BITOR, DG_OP_AND, DG_OP_OR,
    /* binary, on doubles (comparisons and logic give integers 0 or 1) */
    DG_OP_FMUL, DG_OP_FDIV, DG_OP_FADD, DG_OP_FSUB,
    DG_OP_FLT, DG_OP_FLE, DG_OP_FGT, DG_OP_FGE, DG_OP_FEQ, DG_OP_FNE, DG_OP_FAND, DG_OP_FOR,
    /* c ? a : b on the top three (c, a, b); a and b of one type, c of either */
    DG_OP_SELECT
};

typedef struct dg_expr_op {
    guint8 code;    /* dg_expr_code */
    guint8 bits;    /* DG_OP_*FIELD_SIGNED: the field's width */
    gint16 slot;    /* DG_OP_FIELD*: where the field's value is kept; DG_OP_REQUEST_FIELD*: its index;
                     * DG_OP_LEARNED: the <learn>'s row */
    gint64 integer; /* DG_OP_INT */
    gdouble real;   /* DG_OP_FLOAT */
} dg_expr_op;

/* The deepest stack an expression may need. The parser's nesting limit
 * (64 levels: each pending operand is one) keeps every accepted expression
 * within it, the operand read at the deepest level included
 * (tests/unit/test_expr_eval.cpp); a deeper one would be undefined. */
#define DG_EXPR_STACK 65

/* A slot's value, or FALSE when the field was not decoded in this message. */
typedef gboolean (*dg_slot_reader)(const void *context, gint16 slot, guint64 *value);

typedef struct dg_expr_value {
    gboolean defined;
    gboolean is_float;
    gint64 integer;
    gdouble real;
} dg_expr_value;

/* Where the value being computed sits in its message (DG_OP_OFFSET), or FALSE. */
typedef gboolean (*dg_offset_reader)(const void *context, guint64 *value);

/* How an expression reads what is not in its operations: the message's
 * fields, the paired request's kept values (DG_OP_REQUEST_FIELD*), what
 * earlier messages taught (DG_OP_LEARNED) and its place in the message
 * (DG_OP_OFFSET); a NULL reader: those are undefined. */
typedef struct dg_expr_readers {
    dg_slot_reader field, request, learned;
    dg_offset_reader offset;
} dg_expr_readers;

/* Evaluates ops[0 .. count); the result's is_float tells which member holds it. */
dg_expr_value dg_expr_eval(const dg_expr_op *ops, guint count, const dg_expr_readers *readers, const void *context,
                           guint32 index);

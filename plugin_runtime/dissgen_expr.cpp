// SPDX-License-Identifier: GPL-2.0-or-later
/* The evaluator of computed values (see dissgen_expr.h). */
#include "dissgen_expr.h"

#include <string.h>

namespace {

dg_expr_value integer_value(gint64 v) { return {TRUE, FALSE, v, 0}; }
dg_expr_value real_value(gdouble v) { return {TRUE, TRUE, 0, v}; }
dg_expr_value undefined_value() { return {FALSE, FALSE, 0, 0}; }

/* Arithmetic on the unsigned bit pattern: wraps instead of overflowing. */
gint64 wrap(guint64 v) { return (gint64)v; }

dg_expr_value operand(const dg_expr_op *op, const dg_expr_readers *readers, const void *context, guint32 index) {
    guint64 raw;
    switch (op->code) {
    case DG_OP_INT: return integer_value(op->integer);
    case DG_OP_FLOAT: return real_value(op->real);
    case DG_OP_INDEX: return integer_value(index);
    case DG_OP_OFFSET:
        if (!readers->offset || !readers->offset(context, &raw)) return undefined_value();
        return integer_value(wrap(raw));
    case DG_OP_LEARNED:
        if (!readers->learned || !readers->learned(context, op->slot, &raw)) return undefined_value();
        return integer_value(wrap(raw));
    default: break;
    }
    const gboolean from_request = op->code >= DG_OP_REQUEST_FIELD;
    const dg_slot_reader reader = from_request ? readers->request : readers->field;
    if (!reader || !reader(context, op->slot, &raw)) return undefined_value();
    const guint8 kind = from_request ? op->code - (DG_OP_REQUEST_FIELD - DG_OP_FIELD) : op->code;
    if (kind == DG_OP_FIELD_FLOAT) {
        gdouble d;
        memcpy(&d, &raw, sizeof d);
        return real_value(d);
    }
    if (kind == DG_OP_FIELD_SIGNED && op->bits > 0 && op->bits < 64) {
        const guint64 sign = G_GUINT64_CONSTANT(1) << (op->bits - 1);
        raw = (raw ^ sign) - sign;
    }
    return integer_value(wrap(raw));
}

dg_expr_value unary(guint8 code, dg_expr_value a) {
    if (code == DG_OP_DEFINED) return integer_value(a.defined);
    if (!a.defined) return a;
    switch (code) {
    case DG_OP_TO_FLOAT: return real_value((gdouble)a.integer);
    case DG_OP_NEG: return integer_value(wrap(0 - (guint64)a.integer));
    case DG_OP_NOT: return integer_value(a.integer == 0);
    case DG_OP_BITNOT: return integer_value(~a.integer);
    case DG_OP_FNEG: return real_value(-a.real);
    default: return integer_value(a.real == 0); /* DG_OP_FNOT */
    }
}

/* && and ||: the left side alone may decide, even when the right is undefined. */
dg_expr_value logic(gboolean is_and, gboolean left_true, gboolean left_defined, dg_expr_value b, gboolean right_true) {
    if (left_defined && left_true != is_and) return integer_value(left_true);
    if (!left_defined || !b.defined) return undefined_value();
    return integer_value(right_true);
}

dg_expr_value shift(guint8 code, gint64 a, gint64 b) {
    if (b < 0 || b >= 64) return integer_value(0);
    return integer_value(code == DG_OP_SHL ? wrap((guint64)a << b) : wrap((guint64)a >> b));
}

dg_expr_value integer_binary(guint8 code, dg_expr_value a, dg_expr_value b) {
    if (code == DG_OP_AND || code == DG_OP_OR)
        return logic(code == DG_OP_AND, a.integer != 0, a.defined, b, b.integer != 0);
    if (!a.defined || !b.defined) return undefined_value();
    const gint64 x = a.integer, y = b.integer;
    switch (code) {
    case DG_OP_MUL: return integer_value(wrap((guint64)x * (guint64)y));
    case DG_OP_DIV:
    case DG_OP_MOD:
        if (y == 0) return undefined_value();
        if (y == -1) return integer_value(code == DG_OP_DIV ? wrap(0 - (guint64)x) : 0); /* INT64_MIN / -1 wraps */
        return integer_value(code == DG_OP_DIV ? x / y : x % y);
    case DG_OP_ADD: return integer_value(wrap((guint64)x + (guint64)y));
    case DG_OP_SUB: return integer_value(wrap((guint64)x - (guint64)y));
    case DG_OP_SHL:
    case DG_OP_SHR: return shift(code, x, y);
    case DG_OP_LT: return integer_value(x < y);
    case DG_OP_LE: return integer_value(x <= y);
    case DG_OP_GT: return integer_value(x > y);
    case DG_OP_GE: return integer_value(x >= y);
    case DG_OP_EQ: return integer_value(x == y);
    case DG_OP_NE: return integer_value(x != y);
    case DG_OP_BITAND: return integer_value(x & y);
    case DG_OP_BITXOR: return integer_value(x ^ y);
    default: return integer_value(x | y); /* DG_OP_BITOR */
    }
}

dg_expr_value real_binary(guint8 code, dg_expr_value a, dg_expr_value b) {
    if (code == DG_OP_FAND || code == DG_OP_FOR)
        return logic(code == DG_OP_FAND, a.real != 0, a.defined, b, b.real != 0);
    if (!a.defined || !b.defined) return undefined_value();
    const gdouble x = a.real, y = b.real;
    switch (code) {
    case DG_OP_FMUL: return real_value(x * y);
    case DG_OP_FDIV: return real_value(x / y);
    case DG_OP_FADD: return real_value(x + y);
    case DG_OP_FSUB: return real_value(x - y);
    case DG_OP_FLT: return integer_value(x < y);
    case DG_OP_FLE: return integer_value(x <= y);
    case DG_OP_FGT: return integer_value(x > y);
    case DG_OP_FGE: return integer_value(x >= y);
    case DG_OP_FEQ: return integer_value(x == y);
    default: return integer_value(x != y); /* DG_OP_FNE */
    }
}

/* c ? a : b: the value c chooses, whether or not the other is defined. */
dg_expr_value select(dg_expr_value c, dg_expr_value a, dg_expr_value b) {
    if (!c.defined) return undefined_value();
    return (c.is_float ? c.real != 0 : c.integer != 0) ? a : b;
}

}  // namespace

dg_expr_value dg_expr_eval(const dg_expr_op *ops, guint count, const dg_expr_readers *readers, const void *context,
                           guint32 index) {
    dg_expr_value stack[DG_EXPR_STACK];
    guint depth = 0;
    for (guint k = 0; k < count; ++k) {
        const guint8 code = ops[k].code;
        if (code <= DG_OP_OFFSET) {
            if (depth == DG_EXPR_STACK) return undefined_value();
            stack[depth++] = operand(&ops[k], readers, context, index);
        } else if (code <= DG_OP_DEFINED) {
            if (depth < 1) return undefined_value();
            stack[depth - 1] = unary(code, stack[depth - 1]);
        } else if (code == DG_OP_SELECT) {
            if (depth < 3) return undefined_value();
            depth -= 2;
            stack[depth - 1] = select(stack[depth - 1], stack[depth], stack[depth + 1]);
        } else {
            if (depth < 2) return undefined_value();
            --depth;
            stack[depth - 1] = code < DG_OP_FMUL ? integer_binary(code, stack[depth - 1], stack[depth])
                                                 : real_binary(code, stack[depth - 1], stack[depth]);
        }
    }
    return depth == 1 ? stack[0] : undefined_value();
}

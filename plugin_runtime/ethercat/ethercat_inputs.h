/* What the ethercat-esc analysis reads from each EtherCAT frame: the rule
 * file binds every input to one of its fields (<pairing><input name="..."
 * field="..."/>), the generator checks that each is bound (and, per
 * datagram, inside the repeated datagram), and the walk fills the frame's
 * dg_view with them in this order. The one list both sides read: the
 * generator includes it (generator/analyses.cpp) as the runtime does.
 *
 * X(id, name, per_instance): per_instance 1 is one value per datagram (the
 * instances of one repeated node), 0 one per frame. Plain C: no includes. */
#pragma once

#define DG_ESC_INPUTS(X)                       \
    X(ESC_IN_FRAME_LENGTH, "frame length", 0)  \
    X(ESC_IN_COMMAND, "command", 1)            \
    X(ESC_IN_INDEX, "index", 1)                \
    X(ESC_IN_ADP, "slave address", 1)          \
    X(ESC_IN_ADO, "offset address", 1)         \
    X(ESC_IN_LOGICAL, "logical address", 1)    \
    X(ESC_IN_LENGTH, "length", 1)              \
    X(ESC_IN_WKC, "working counter", 1)

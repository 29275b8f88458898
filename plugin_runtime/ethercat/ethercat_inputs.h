/* What the ethercat-esc analysis reads from each EtherCAT frame: the rule
 * file binds every input to one of its fields (<pairing><input name="..."
 * field="..."/>), the generator checks that each is bound (and, per
 * datagram, inside the repeated datagram), and the walk fills the frame's
 * dg_view with them in this order. The one list both sides read: the
 * generator includes it (generator/analyses.cpp) as the runtime does.
 *
 * X(id, name, kind): DG_INPUT_PER_MESSAGE is one number per frame,
 * DG_INPUT_PER_INSTANCE one per datagram (the instances of one repeated
 * node), DG_INPUT_BYTES_PER_INSTANCE where a datagram's bytes of a field are
 * (any leaf with bytes: the view gives their offset and length); with
 * DG_INPUT_OPTIONAL a rule file may leave the input unbound. DG_INPUT_ADDRESS
 * is not a value of each frame but where a register sits in the rule file's
 * register map (a child of the window on the datagram's ADO: its at=,
 * stride= and instances=), handed to the analysis once (dg_pairing.places):
 * the bus model reads the registers there, so their addresses are stated
 * once, in the rules; how many bytes it reads and what they mean (the SII
 * interface, an FMMU's layout) is the slave controller's, and stays here in
 * the runtime. Unbound, the model learns nothing from that register. The SDO inputs
 * are the CoE mailbox's initiate download request (as the master writes it)
 * and initiate upload response (as it reads it back), from which the bus model
 * learns the PDO assignment and mapping; without them it learns none (the ESI
 * file's default PDOs stay). Plain C: no includes. */
#pragma once

/* The analysis times the rule file's <cycles> itself, by each frame's return
 * (dg_analysis.times_cycles; the generator lists its names, not the generic
 * cycle analysis's). */
#define DG_ESC_TIMES_CYCLES 1

/* the kinds are bits: one per instance, bytes, optional, a register's address */
#define DG_INPUT_PER_MESSAGE 0
#define DG_INPUT_PER_INSTANCE 1
#define DG_INPUT_BYTES 2
#define DG_INPUT_OPTIONAL 4
#define DG_INPUT_ADDRESS 8
#define DG_INPUT_BYTES_PER_INSTANCE (DG_INPUT_PER_INSTANCE | DG_INPUT_BYTES)
#define DG_SDO_INPUT (DG_INPUT_PER_INSTANCE | DG_INPUT_OPTIONAL)
#define DG_SDO_BYTES_INPUT (DG_INPUT_BYTES_PER_INSTANCE | DG_INPUT_OPTIONAL)
#define DG_REGISTER_INPUT (DG_INPUT_ADDRESS | DG_INPUT_OPTIONAL)

#define DG_ESC_INPUTS(X)                                                             \
    X(ESC_IN_FRAME_LENGTH, "frame length", DG_INPUT_PER_MESSAGE)                     \
    X(ESC_IN_COMMAND, "command", DG_INPUT_PER_INSTANCE)                              \
    X(ESC_IN_INDEX, "index", DG_INPUT_PER_INSTANCE)                                  \
    X(ESC_IN_ADP, "slave address", DG_INPUT_PER_INSTANCE)                            \
    X(ESC_IN_ADO, "offset address", DG_INPUT_PER_INSTANCE)                           \
    X(ESC_IN_LOGICAL, "logical address", DG_INPUT_PER_INSTANCE)                      \
    X(ESC_IN_LENGTH, "length", DG_INPUT_PER_INSTANCE)                                \
    X(ESC_IN_WKC, "working counter", DG_INPUT_PER_INSTANCE)                          \
    X(ESC_IN_DOWNLOAD_SIZE_INDICATED, "sdo download size indicated", DG_SDO_INPUT)   \
    X(ESC_IN_DOWNLOAD_UNUSED_BYTES, "sdo download unused bytes", DG_SDO_INPUT)       \
    X(ESC_IN_DOWNLOAD_COMPLETE_ACCESS, "sdo download complete access", DG_SDO_INPUT) \
    X(ESC_IN_DOWNLOAD_INDEX, "sdo download index", DG_SDO_INPUT)                     \
    X(ESC_IN_DOWNLOAD_SUBINDEX, "sdo download subindex", DG_SDO_INPUT)               \
    X(ESC_IN_DOWNLOAD_EXPEDITED, "sdo download expedited data", DG_SDO_BYTES_INPUT)  \
    X(ESC_IN_DOWNLOAD_SIZE, "sdo download size", DG_SDO_INPUT)                       \
    X(ESC_IN_DOWNLOAD_DATA, "sdo download data", DG_SDO_BYTES_INPUT)                 \
    X(ESC_IN_UPLOAD_SIZE_INDICATED, "sdo upload size indicated", DG_SDO_INPUT)       \
    X(ESC_IN_UPLOAD_UNUSED_BYTES, "sdo upload unused bytes", DG_SDO_INPUT)           \
    X(ESC_IN_UPLOAD_COMPLETE_ACCESS, "sdo upload complete access", DG_SDO_INPUT)     \
    X(ESC_IN_UPLOAD_INDEX, "sdo upload index", DG_SDO_INPUT)                         \
    X(ESC_IN_UPLOAD_SUBINDEX, "sdo upload subindex", DG_SDO_INPUT)                   \
    X(ESC_IN_UPLOAD_EXPEDITED, "sdo upload expedited data", DG_SDO_BYTES_INPUT)      \
    X(ESC_IN_UPLOAD_SIZE, "sdo upload size", DG_SDO_INPUT)                           \
    X(ESC_IN_UPLOAD_DATA, "sdo upload data", DG_SDO_BYTES_INPUT)                     \
    X(ESC_REG_STATION, "station address register", DG_REGISTER_INPUT)               \
    X(ESC_REG_ALIAS, "station alias register", DG_REGISTER_INPUT)                   \
    X(ESC_REG_AL_STATUS, "al status register", DG_REGISTER_INPUT)                   \
    X(ESC_REG_SII_CONTROL, "sii control register", DG_REGISTER_INPUT)               \
    X(ESC_REG_SII_ADDRESS, "sii address register", DG_REGISTER_INPUT)               \
    X(ESC_REG_SII_DATA, "sii data register", DG_REGISTER_INPUT)                     \
    X(ESC_REG_FMMU, "fmmu registers", DG_REGISTER_INPUT)                            \
    X(ESC_REG_SYNCMANAGER, "syncmanager registers", DG_REGISTER_INPUT)              \
    X(ESC_REG_SYSTEM_TIME, "system time register", DG_REGISTER_INPUT)

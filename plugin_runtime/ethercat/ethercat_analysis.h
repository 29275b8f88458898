/* EtherCAT's analyses as one dissgen pairing analysis: what the slave
 * controllers (ESC) do to a frame on its way round the segment, the bus
 * model and the cycles. Rule files enable it with
 * <pairing analysis="ethercat-esc">; ethercat_analysis.cpp says how.
 */
#pragma once

#include "dissgen_pairing.h"

/* C linkage: generated code declares it so (extern "C") where its rules name it. */
extern "C" {

extern const dg_analysis dg_ethercat_esc;

}

/* What an EtherCAT slave controller (ESC) does to a frame on its way round
 * the segment, as a dissgen pairing analysis: rule files enable it
 * with <pairing analysis="ethercat-esc">. See ethercat_esc.cpp for the rules.
 */
#pragma once

#include "dissgen_pairing.h"

#ifdef __cplusplus
extern "C" {
#endif

extern const dg_analysis dg_ethercat_esc;

#ifdef __cplusplus
}
#endif

/* What an EtherCAT slave controller (ESC) does to a frame on its way round
 * the segment, as a dissgen pairing analysis: rule files enable it
 * with <pairing analysis="ethercat-esc">. See ethercat_esc.cpp for the rules.
 */
#pragma once

#include "dissgen_pairing.h"

/* C linkage: generated code declares it so (extern "C") where its rules name it. */
extern "C" {

extern const dg_analysis dg_ethercat_esc;

}

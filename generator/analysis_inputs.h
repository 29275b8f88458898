// SPDX-License-Identifier: GPL-2.0-or-later
// What a pairing's analysis reads from each message: <pairing analysis="...">
// binds each input the analysis lists (analyses.h) to a field with
// <input name="..." field="XPATH"/>, the way <key> names the key fields. The
// walk then fills a view of those fields for the analysis (dissgen_pairing.h,
// dg_view) instead of the analysis decoding the bytes again. A register
// input instead names a child of a window (a register of a register map):
// the analysis gets where it is once (dg_pairing.places), not a value per
// message, so the rules state its address and the analysis does not.
#pragma once

#include "diagnostics.h"
#include "model.h"

namespace dissgen {

// Checks the inputs against the analysis' list (every one bound once, to a
// numeric leaf; per-instance ones inside one repeated node, the others
// outside any; register inputs to children of one window), marks each bound
// leaf (Node::analysis_input) and numbers each input (AnalysisInput::index).
void check_analysis_inputs(Protocol& proto, Diagnostics& diags);

}  // namespace dissgen

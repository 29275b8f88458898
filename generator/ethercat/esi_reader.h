// ESI front end: EtherCAT Slave Information files (XML) -> Catalogue.
// Reads what vendors ship: decimal, #x and 0x numbers, any encoding libxml2
// knows (ISO-8859-1, UTF-8 with or without BOM or declaration), localised
// names, CDATA, Fixed/Mandatory as 1 or true, modular devices and module
// files (root EtherCATModule). No DTD, entities or network access.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "diagnostics.h"
#include "esi_model.h"

namespace dissgen {

// Adds the devices and modules of one ESI file (its text) to `into`. `file`
// is recorded in the model. Returns false, and adds nothing, on any error.
bool read_esi(const std::string& text, const std::string& file, Catalogue& into, Diagnostics& diags);

// Each path is an ESI file or a folder of *.xml files (read in name order).
// Diagnostics go to `err` as FILE:LINE: error: MESSAGE. On success the
// devices are sorted by vendor, product code and revision (an identity given
// twice is kept once, the first read). Returns false on any error.
bool load_catalogue(const std::vector<std::string>& paths, Catalogue& out, std::ostream& err);

// `dissgen esi`: one line per device revision,
// "0xVVVVVVVV 0xPPPPPPPP 0xRRRRRRRR NAME", sorted.
std::string list_catalogue(const Catalogue& cat);

}  // namespace dissgen

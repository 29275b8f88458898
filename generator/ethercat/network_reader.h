// Network front end: the designed bus, from either
//   a design:  <network><slave type="EK1100"/><slave vendor="2" product="0x07d43052"/>...</network>
//              (types resolved against the ESI catalogue), or
//   an ENI file (root EtherCATConfig, as TwinCAT exports it): slaves with
//              identities, names, station addresses, process data with bit
//              offsets, and the cyclic commands with expected working counters.
#pragma once

#include <string>

#include "diagnostics.h"
#include "esi_model.h"

namespace dissgen {

// Reads the design or ENI in `text` into `net`. Returns false after adding
// errors to `diags`.
bool read_network(const std::string& text, const std::string& file, const Catalogue& cat, Network& net,
                  Diagnostics& diags);

// The default process data of a device: the PDOs its ESI file assigns to a
// SyncManager (attribute Sm), outputs and inputs each packed in file order.
void default_process_data(const EsiDevice& dev, NetSlave& slave);

}  // namespace dissgen

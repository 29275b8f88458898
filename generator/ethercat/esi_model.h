// What dissgen keeps of ESI files (EtherCAT Slave Information) and of a
// network design or ENI file: plain data, every item with the file and line
// it came from. The ESI reader and the network reader fill it in; the
// catalogue emitter turns it into the plugin's static tables.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dissgen {

// One entry of a PDO: an object of the slave's object dictionary mapped into
// the process data. Index 0 is padding (no name, no object).
struct EsiEntry {
    uint16_t index = 0;
    uint8_t subindex = 0;
    uint16_t bit_length = 0;
    std::string name;
    std::string data_type;  // "BOOL", "UINT", "BIT2", "ARRAY [0..1] OF BYTE", ... ("" for padding)
    int line = 0;
    bool is_padding() const { return index == 0; }
};

// A process data object. TxPdo: slave to master (inputs); RxPdo: outputs.
struct EsiPdo {
    bool tx = false;
    uint16_t index = 0;
    std::string name;
    int sm = -1;            // SyncManager of the default assignment; -1: not assigned by default
    bool fixed = false;     // the mapping cannot be changed
    bool mandatory = false; // must be assigned
    std::vector<uint16_t> excludes;  // PDOs that cannot be assigned together with this one
    std::vector<EsiEntry> entries;
    int line = 0;
};

// A SyncManager as an ESI <Sm> or an ENI <SmN> describes it.
struct SyncManager {
    int index = 0;            // SM number (position among the device's <Sm>, N of <SmN>)
    uint16_t start = 0;       // StartAddress in the slave's memory
    uint16_t size = 0;        // DefaultSize, 0 when not given
    uint8_t control = 0;      // ControlByte
    bool enable = false;
    std::string type;         // "Outputs", "Inputs", "MBoxOut", "MBoxIn", ...
    int line = 0;
};

// One <Device> element: one revision of one product.
struct EsiDevice {
    uint32_t vendor = 0, product = 0, revision = 0;
    std::string type;  // <Type> text, e.g. "EL1004": what a design names
    std::string name;  // <Name>, English (LcId 1033) when given, else the first
    std::vector<SyncManager> sms;
    std::vector<EsiPdo> pdos;
    std::string file;
    int line = 0;
};

// One <Module> of a modular device (Slots/Modules; module files have the root EtherCATModule).
struct EsiModule {
    uint32_t vendor = 0;
    uint32_t ident = 0;  // ModuleIdent
    std::string type, name;
    std::vector<EsiPdo> pdos;
    std::string file;
    int line = 0;
};

struct Catalogue {
    std::vector<EsiDevice> devices;  // sorted by vendor, product, revision once loaded
    std::vector<EsiModule> modules;
};

// A PDO entry of one slave of a network, placed in that slave's process data.
struct NetEntry {
    bool output = false;        // RxPdo entry (master to slave)
    uint16_t pdo_index = 0;
    std::string pdo_name;
    EsiEntry entry;
    uint32_t bit_offset = 0;    // from the start of the slave's inputs or outputs
    int64_t logical_bit = -1;   // in the logical process image (ENI), -1 when the master decides at run time
};

// One slave of the designed network, by bus position.
struct NetSlave {
    int position = 0;            // 0-based, bus order
    uint16_t station = 0;        // configured station address, 0 when not given
    uint32_t vendor = 0, product = 0, revision = 0;
    bool revision_given = false; // the design fixes the revision too
    std::string type;            // model (<Type> of its ESI device), "" when unknown
    std::string name;            // instance name (ENI) or the model's name
    int device = -1;             // index into Catalogue::devices, -1 when not in the catalogue
    std::vector<SyncManager> sms;
    std::vector<NetEntry> entries;
    uint32_t input_bits = 0, output_bits = 0;
    int64_t input_logical_bit = -1, output_logical_bit = -1;  // ENI <Recv>/<Send> BitStart
    int line = 0;
};

// A datagram the master sends every cycle (ENI <Cyclic><Frame><Cmd>).
struct NetCommand {
    int frame = 0;                // 0-based frame of the cycle
    uint8_t cmd = 0;              // EtherCAT command number (LRW = 12, ...)
    uint16_t adp = 0, ado = 0;    // position/station and register, for non-logical commands
    uint32_t logical_address = 0; // for LRD/LWR/LRW
    uint16_t length = 0;
    int expected_wkc = -1;        // <Cnt>, -1 when not given
    int line = 0;
};

struct Network {
    std::string file;
    bool from_eni = false;
    std::vector<NetSlave> slaves;
    std::vector<NetCommand> cyclic;
};

}  // namespace dissgen

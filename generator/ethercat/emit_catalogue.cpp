#include "emit_catalogue.h"

#include <cctype>
#include <cstdio>
#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "network_reader.h"
#include "../../plugin_runtime/dissgen_names.h"
#include "../../plugin_runtime/ethercat/ethercat_commands.h"

namespace dissgen {

namespace {

std::string hexn(uint64_t v, int digits) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%0*llx", digits, static_cast<unsigned long long>(v));
    return buf;
}

// A filter-name segment: lower-case letters, digits and '_' ("Channel 1" -> "channel_1").
std::string segment(const std::string& text) {
    std::string out;
    for (unsigned char c : text) {
        if (c < 0x80 && std::isalnum(c)) out += static_cast<char>(std::tolower(c));
        else if (!out.empty() && out.back() != '_') out += '_';
    }
    while (!out.empty() && out.back() == '_') out.pop_back();
    return out;
}

}  // namespace

// How an entry of an ESI data type is registered with Wireshark.
FieldType pdo_field_type(const std::string& data_type, unsigned bits) {
    static const std::map<std::string, FieldType> kTypes = {
        {"BOOL", {"FT_BOOLEAN", "BASE_NONE"}}, {"BIT", {"FT_BOOLEAN", "BASE_NONE"}},
        {"SINT", {"FT_INT8", "BASE_DEC"}},     {"INT", {"FT_INT16", "BASE_DEC"}},
        {"DINT", {"FT_INT32", "BASE_DEC"}},    {"LINT", {"FT_INT64", "BASE_DEC"}},
        {"USINT", {"FT_UINT8", "BASE_DEC"}},   {"UINT", {"FT_UINT16", "BASE_DEC"}},
        {"UDINT", {"FT_UINT32", "BASE_DEC"}},  {"ULINT", {"FT_UINT64", "BASE_DEC"}},
        {"BYTE", {"FT_UINT8", "BASE_HEX"}},    {"WORD", {"FT_UINT16", "BASE_HEX"}},
        {"DWORD", {"FT_UINT32", "BASE_HEX"}},  {"LWORD", {"FT_UINT64", "BASE_HEX"}},
        {"REAL", {"FT_FLOAT", "BASE_NONE"}},   {"LREAL", {"FT_DOUBLE", "BASE_NONE"}},
    };
    auto it = kTypes.find(data_type);
    if (it != kTypes.end()) return it->second;
    // BITn: an unsigned number of n bits (BIT1 is a flag).
    if (data_type.size() > 3 && data_type.compare(0, 3, "BIT") == 0 &&
        data_type.find_first_not_of("0123456789", 3) == std::string::npos) {
        if (bits == 1) return {"FT_BOOLEAN", "BASE_NONE"};
        if (bits <= 8) return {"FT_UINT8", "BASE_DEC"};
        if (bits <= 16) return {"FT_UINT16", "BASE_DEC"};
        if (bits <= 32) return {"FT_UINT32", "BASE_DEC"};
    }
    return {"FT_BYTES", "BASE_NONE"};  // arrays, strings, vendor types: the bytes
}

namespace {

struct Field {
    std::string ident;   // C name of the hf variable
    std::string filter;  // display-filter name
    std::string label;   // display name
    std::string blurb;
    FieldType type;
};

// Everything emit_bus and list_bus_fields need, worked out once.
struct BusLayout {
    std::vector<int> devices;                    // catalogue indices embedded, in order
    std::map<int, int> device_row;               // catalogue index -> row
    std::vector<NetEntry> entries;
    std::vector<std::string> entry_owner;        // comment per entry
    std::vector<int> entry_field;                // into fields, -1 none
    std::vector<std::pair<uint32_t, uint32_t>> device_entries;  // per row: first, count
    std::vector<std::pair<uint32_t, uint32_t>> slave_entries;   // per slave
    struct Pdo {
        uint16_t index;
        bool output, assigned;
        uint32_t first, count;  // into maps
    };
    struct Ranges {
        uint32_t pdo_first = 0, pdo_count = 0, object_first = 0, object_count = 0;
    };
    std::vector<Pdo> pdos;                       // the devices' PDOs (revisions that map alike share them)
    std::vector<EsiEntry> maps;                  // the PDOs' mappings: index, subindex, bit length
    std::vector<Ranges> device_pdos;             // per row
    std::vector<Field> fields;
};

// Every PDO of a device with its mapping (the default ones first, in packing order); and the objects
// only its PDOs outside the default assignment map, as entries without a
// field (their names and types). Both shared between the revisions (and
// models) that have the same, so that a catalogue of thousands of PDOs stays
// small: no pointers in the mappings.
struct PdoTables {
    std::map<std::string, BusLayout::Ranges> devices;  // a device's PDOs and objects, by content
    std::map<std::string, std::pair<uint32_t, uint32_t>> maps;  // a mapping, by content
};

std::string entry_key(const EsiEntry& en) {
    return std::to_string(en.index) + ":" + std::to_string(en.subindex) + ":" + std::to_string(en.bit_length) + ":" +
           en.name + ":" + en.data_type + "\n";
}

void add_device_pdos(BusLayout& l, const EsiDevice& dev, uint32_t first, uint32_t count, PdoTables& t) {
    std::string key = dev.type + "\n";
    for (const EsiPdo& p : dev.pdos) {
        key += std::to_string(p.index) + (p.tx ? "t" : "r") + (p.sm >= 0 ? "a" : "") + p.name + "\n";
        for (const EsiEntry& en : p.entries) key += entry_key(en);
    }
    auto known = t.devices.find(key);
    if (known != t.devices.end()) {
        l.device_pdos.push_back(known->second);
        return;
    }
    BusLayout::Ranges r;
    r.pdo_first = static_cast<uint32_t>(l.pdos.size());
    std::set<std::pair<uint16_t, uint8_t>> in_defaults;
    for (uint32_t i = first; i < first + count; ++i)
        in_defaults.insert({l.entries[i].entry.index, l.entries[i].entry.subindex});
    std::set<std::string> objects;
    r.object_first = static_cast<uint32_t>(l.entries.size());
    // The default assignment first, in the order its process data is packed
    // (SyncManager order, then file order), then the other PDOs in file order.
    std::vector<const EsiPdo*> order;
    for (const EsiPdo& p : dev.pdos) order.push_back(&p);
    std::stable_sort(order.begin(), order.end(), [](const EsiPdo* a, const EsiPdo* b) {
        return (a->sm < 0 ? 1000 : a->sm) < (b->sm < 0 ? 1000 : b->sm);
    });
    for (const EsiPdo* pp : order) {
        const EsiPdo& p = *pp;
        std::string map_key;
        for (const EsiEntry& en : p.entries) map_key += entry_key(en);
        auto m = t.maps.find(map_key);
        if (m == t.maps.end()) {
            m = t.maps.emplace(map_key, std::make_pair(static_cast<uint32_t>(l.maps.size()),
                                                       static_cast<uint32_t>(p.entries.size()))).first;
            l.maps.insert(l.maps.end(), p.entries.begin(), p.entries.end());
        }
        l.pdos.push_back({p.index, !p.tx, p.sm >= 0, m->second.first, m->second.second});
        for (const EsiEntry& en : p.entries) {
            if (en.is_padding() || in_defaults.count({en.index, en.subindex}) || !objects.insert(entry_key(en)).second)
                continue;
            NetEntry e;
            e.output = !p.tx;
            e.pdo_index = p.index;
            e.pdo_name = p.name;
            e.entry = en;
            l.entries.push_back(e);
            l.entry_owner.push_back(dev.type + " (objects of PDOs not assigned by default)");
            l.entry_field.push_back(-1);
        }
    }
    r.pdo_count = static_cast<uint32_t>(l.pdos.size()) - r.pdo_first;
    r.object_count = static_cast<uint32_t>(l.entries.size()) - r.object_first;
    t.devices.emplace(key, r);
    l.device_pdos.push_back(r);
}

// What names a PDO entry: "PDO.Entry", the entry alone in a PDO without a name, the PDO
// alone for an entry without one (the dissector shows the object beside it).
std::string entry_name(const NetEntry& e) {
    if (e.pdo_name.empty() || e.entry.name.empty()) return e.pdo_name + e.entry.name;
    return e.pdo_name + "." + e.entry.name;
}

// A field's label: its owner and the entry's name; an entry without a name adds its object as
// the dissector shows it ("EL9999 Status 0x60ab:11", "EL9999 0x7000:01").
std::string field_label(const std::string& owner, const NetEntry& e) {
    std::string label = owner + " " + entry_name(e);
    if (e.entry.name.empty())
        label += (e.pdo_name.empty() ? "" : " ") + hexn(e.entry.index, 4) + ":" + hexn(e.entry.subindex, 2).substr(2);
    return label;
}

BusLayout make_bus_layout(const Catalogue& cat, const BusOptions& opt, const std::string& filter) {
    BusLayout l;
    const Network* net = opt.network;
    std::set<int> used;
    if (net)
        for (const NetSlave& s : net->slaves)
            if (s.device >= 0) used.insert(s.device);
    for (size_t i = 0; i < cat.devices.size(); ++i) {
        if (opt.compact && !used.count(static_cast<int>(i))) continue;
        l.device_row[static_cast<int>(i)] = static_cast<int>(l.devices.size());
        l.devices.push_back(static_cast<int>(i));
    }

    std::set<std::string> filters, idents;
    std::map<std::string, int> field_of;  // owner-qualified key -> field, shared by slaves of one model
    auto field_for = [&](const std::string& owner, const NetEntry& e) -> int {
        if (e.entry.is_padding()) return -1;
        std::string key = owner + "\n" + std::to_string(e.output) + "\n" + std::to_string(e.pdo_index) + "\n" +
                          std::to_string(e.entry.index) + ":" + std::to_string(e.entry.subindex) + "\n" +
                          e.entry.name + "\n" + e.entry.data_type + "\n" + std::to_string(e.entry.bit_length);
        auto it = field_of.find(key);
        if (it != field_of.end()) return it->second;
        std::string base = filter + "." + DG_BUS_PDO_PREFIX + segment(owner);
        std::string pdo = segment(e.pdo_name), name = segment(e.entry.name);
        if (!pdo.empty()) base += "." + pdo;
        base += "." + (name.empty() ? "entry_" + hexn(e.entry.index, 4).substr(2) + "_" +
                                          std::to_string(e.entry.subindex)
                                    : name);
        std::string f = base;
        for (int k = 2; !filters.insert(f).second; ++k) f = base + "_" + std::to_string(k);
        Field fld;
        fld.filter = f;
        fld.ident = "hf_";
        for (char c : f) fld.ident += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
        for (int k = 2; !idents.insert(fld.ident).second; ++k) fld.ident += "_" + std::to_string(k);
        fld.label = field_label(owner, e);
        fld.blurb = std::string(e.output ? "Output" : "Input") + " of PDO " + hexn(e.pdo_index, 4) + ", object " +
                    hexn(e.entry.index, 4) + ":" + hexn(e.entry.subindex, 2) + ", " +
                    (e.entry.data_type.empty() ? "" : e.entry.data_type + ", ") + std::to_string(e.entry.bit_length) +
                    " bit";
        fld.type = pdo_field_type(e.entry.data_type, e.entry.bit_length);
        l.fields.push_back(fld);
        return field_of[key] = static_cast<int>(l.fields.size()) - 1;
    };

    // Models a design uses get fields, the rest of the catalogue is data only;
    // without a network every model does: the run time names the process data
    // of the slaves the capture identifies by their model's defaults.
    std::set<int> design_models;
    if (net && !net->from_eni)
        for (const NetSlave& s : net->slaves)
            if (s.device >= 0) design_models.insert(s.device);
    if (!net) design_models.insert(l.devices.begin(), l.devices.end());
    PdoTables pdo_tables;
    for (int d : l.devices) {
        const EsiDevice& dev = cat.devices[d];
        NetSlave defaults;
        default_process_data(dev, defaults);
        uint32_t first = static_cast<uint32_t>(l.entries.size());
        for (const NetEntry& e : defaults.entries) {
            l.entries.push_back(e);
            l.entry_owner.push_back(dev.type);
            l.entry_field.push_back(design_models.count(d) ? field_for(dev.type, e) : -1);
        }
        l.device_entries.push_back({first, static_cast<uint32_t>(defaults.entries.size())});
        add_device_pdos(l, dev, first, static_cast<uint32_t>(defaults.entries.size()), pdo_tables);
    }
    if (net) {
        for (const NetSlave& s : net->slaves) {
            if (!net->from_eni) {  // a design slave has its model's default process data
                auto row = s.device >= 0 ? l.device_row.find(s.device) : l.device_row.end();
                l.slave_entries.push_back(row == l.device_row.end() ? std::make_pair(0u, 0u)
                                                                    : l.device_entries[row->second]);
                continue;
            }
            std::string owner = s.name.empty() ? "slave" + std::to_string(s.position) : s.name;
            uint32_t first = static_cast<uint32_t>(l.entries.size());
            for (const NetEntry& e : s.entries) {
                l.entries.push_back(e);
                l.entry_owner.push_back(owner);
                l.entry_field.push_back(field_for(owner, e));
            }
            l.slave_entries.push_back({first, static_cast<uint32_t>(s.entries.size())});
        }
    }
    return l;
}

// The one row of a table without any (C++ has no empty arrays; the count says 0).
constexpr const char* kEmptyRow = "    {}\n";

std::string command_name(uint8_t cmd) {
    const char* name = dg_ecat_commands::command_name_of(cmd);
    return name ? name : "command " + std::to_string(cmd);
}

}  // namespace

EmbeddedTables emit_bus(const Catalogue& cat, const BusOptions& opt, const std::string& filter) {
    BusLayout l = make_bus_layout(cat, opt, filter);
    const Network* net = opt.network;
    EmbeddedTables t;
    t.includes = "#include \"ethercat/ethercat_design.h\"\n";
    std::ostringstream d;
    for (const Field& f : l.fields) d << "static int " << f.ident << " = -1;\n";
    t.declarations = d.str();

    std::ostringstream o;
    o << "/* PDO entries: object index, subindex, output, bit length, PDO, bit offset in the slave's inputs or\n"
      << " * outputs, bit in the logical process image (-1: set at run time), name, data type, field. */\n"
      << "static const dg_pdo_entry " << filter << "_pdo_entries[] = {\n";
    std::string last_owner;
    for (size_t i = 0; i < l.entries.size(); ++i) {
        const NetEntry& e = l.entries[i];
        if (i == 0 || l.entry_owner[i] != last_owner)
            o << "    /* " << i << ": " << l.entry_owner[i] << " */\n";
        last_owner = l.entry_owner[i];
        std::string name = entry_name(e);
        o << "    { " << hexn(e.entry.index, 4) << ", " << static_cast<unsigned>(e.entry.subindex) << ", "
          << (e.output ? 1 : 0) << ", " << e.entry.bit_length << ", " << hexn(e.pdo_index, 4) << ", " << e.bit_offset
          << ", " << e.logical_bit << ", " << c_string(e.entry.is_padding() ? "(padding)" : name) << ", "
          << c_string(e.entry.data_type) << ", "
          << (l.entry_field[i] < 0 ? "NULL" : "&" + l.fields[l.entry_field[i]].ident) << " },\n";
    }
    if (l.entries.empty()) o << kEmptyRow;
    o << "};\n\n";

    o << "/* The devices' PDOs: index, output, assigned by default, mapping (first, count). */\n"
      << "static const dg_pdo " << filter << "_pdos[] = {\n";
    for (const BusLayout::Pdo& p : l.pdos)
        o << "    { " << hexn(p.index, 4) << ", " << (p.output ? 1 : 0) << ", " << (p.assigned ? 1 : 0) << ", " << p.first
          << ", " << p.count << " },\n";
    if (l.pdos.empty()) o << kEmptyRow;
    o << "};\n\n";
    o << "/* The PDOs' mappings: object index, bit length, subindex. */\n"
      << "static const dg_map_entry " << filter << "_maps[] = {\n";
    for (size_t i = 0; i < l.maps.size(); i += 4) {
        o << "   ";
        for (size_t k = i; k < l.maps.size() && k < i + 4; ++k)
            o << " { " << hexn(l.maps[k].index, 4) << ", " << l.maps[k].bit_length << ", "
              << static_cast<unsigned>(l.maps[k].subindex) << " },";
        o << "\n";
    }
    if (l.maps.empty()) o << kEmptyRow;
    o << "};\n\n";

    o << "/* Device catalogue" << (opt.compact ? " (compact: the models of the network only)" : "")
      << ": vendor, product code, revision, type, name,\n"
      << " * default process data (first entry, count), PDOs (first, count), objects of other PDOs (first, count). */\n"
      << "static const dg_device " << filter << "_devices[] = {\n";
    for (size_t row = 0; row < l.devices.size(); ++row) {
        const EsiDevice& dev = cat.devices[l.devices[row]];
        o << "    /* " << std::filesystem::path(dev.file).filename().string() << ":" << dev.line << " */\n"
          << "    { " << hexn(dev.vendor, 8) << ", " << hexn(dev.product, 8) << ", " << hexn(dev.revision, 8) << ", "
          << c_string(dev.type) << ", " << c_string(dev.name) << ", " << l.device_entries[row].first << ", "
          << l.device_entries[row].second << ", " << l.device_pdos[row].pdo_first << ", "
          << l.device_pdos[row].pdo_count << ", " << l.device_pdos[row].object_first << ", "
          << l.device_pdos[row].object_count << " },\n";
    }
    if (l.devices.empty()) o << kEmptyRow;
    o << "};\n\n";

    size_t slave_count = net ? net->slaves.size() : 0, cyclic_count = net ? net->cyclic.size() : 0;
    size_t sm_count = 0;
    std::vector<size_t> sm_first;
    if (net) {
        o << "/* SyncManagers of the network's slaves: number, control byte, start address, default length,\n"
          << " * enabled, type. */\n"
          << "static const dg_sync_manager " << filter << "_sync_managers[] = {\n";
        for (const NetSlave& s : net->slaves) {
            sm_first.push_back(sm_count);
            if (!s.sms.empty()) o << "    /* " << sm_count << ": position " << s.position << " */\n";
            for (const SyncManager& sm : s.sms)
                o << "    { " << sm.index << ", " << hexn(sm.control, 2) << ", " << hexn(sm.start, 4) << ", " << sm.size
                  << ", " << (sm.enable ? 1 : 0) << ", " << c_string(sm.type) << " },\n";
            sm_count += s.sms.size();
        }
        if (!sm_count) o << kEmptyRow;
        o << "};\n\n";
        o << "/* The network of " << std::filesystem::path(net->file).filename().string()
          << " in bus order: position, station address, vendor, product code,\n"
          << " * revision, revision checked, device, name, process data (first entry, count), SyncManagers (first,\n"
          << " * count), input and output bits, their first bit in the logical process image (-1: set at run time). */\n"
          << "static const dg_slave " << filter << "_slaves[] = {\n";
        for (size_t i = 0; i < net->slaves.size(); ++i) {
            const NetSlave& s = net->slaves[i];
            auto row = l.device_row.find(s.device);
            o << "    /* " << (s.type.empty() ? "model without ESI file" : s.type) << ", "
              << std::filesystem::path(net->file).filename().string() << ":" << s.line << " */\n";
            o << "    { " << s.position << ", " << hexn(s.station, 4) << ", " << hexn(s.vendor, 8) << ", "
              << hexn(s.product, 8) << ", " << hexn(s.revision, 8) << ", " << (s.revision_given ? 1 : 0) << ", "
              << (row == l.device_row.end() ? -1 : row->second) << ", " << c_string(s.name) << ", "
              << l.slave_entries[i].first << ", " << l.slave_entries[i].second << ", " << sm_first[i] << ", "
              << s.sms.size() << ", " << s.input_bits << ", "
              << s.output_bits << ", " << s.input_logical_bit << ", " << s.output_logical_bit << " },\n";
        }
        o << "};\n\n";
        if (cyclic_count) {
            o << "/* Cyclic datagrams: frame, command, ADP, ADO, logical address, length, expected working counter. */\n"
              << "static const dg_cyclic_cmd " << filter << "_cyclic[] = {\n";
            for (const NetCommand& c : net->cyclic)
                o << "    { " << c.frame << ", " << static_cast<unsigned>(c.cmd) << " /* " << command_name(c.cmd)
                  << " */, " << hexn(c.adp, 4) << ", " << hexn(c.ado, 4) << ", " << hexn(c.logical_address, 8)
                  << ", " << c.length << ", " << c.expected_wkc << " },\n";
            o << "};\n\n";
        }
    }
    t.analysis_data = filter + "_bus";
    o << "/* Referenced by the run-time slave model; kept in the plugin even while unused. */\n"
      << "extern G_GNUC_INTERNAL const dg_bus " << t.analysis_data << ";\n"
      << "const dg_bus " << t.analysis_data << " = {\n"
      << "    " << filter << "_devices, " << l.devices.size() << ", " << filter << "_pdo_entries, " << l.entries.size()
      << ", " << filter << "_pdos, " << l.pdos.size() << ", " << filter << "_maps, " << l.maps.size()
      << ",\n    " << (net ? filter + "_slaves" : "NULL") << ", " << slave_count << ", "
      << (net ? filter + "_sync_managers" : "NULL") << ", " << sm_count << ",\n    "
      << (cyclic_count ? filter + "_cyclic" : "NULL") << ", " << cyclic_count << "\n};\n\n";
    t.tables = o.str();

    for (const Field& f : l.fields)
        t.hf_entries.push_back("{ &" + f.ident + ",\n          { " + c_string(f.label) + ", " + c_string(f.filter) + ", " +
                               f.type.type + ", " + f.type.display + ", NULL, 0x0,\n            " + c_string(f.blurb) +
                               ", HFILL } }");
    return t;
}

std::string list_bus_fields(const Catalogue& cat, const BusOptions& opt, const std::string& filter) {
    std::string out;
    for (const Field& f : make_bus_layout(cat, opt, filter).fields)
        out += f.filter + "\t" + f.type.type + "\t" + f.label + "\t" + kEsiSource + "\n";
    return out;
}

}  // namespace dissgen

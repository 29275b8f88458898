#include "network_reader.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "text_util.h"
#include "xml_input.h"

namespace dissgen {

namespace {

const std::vector<std::string> kSlaveAttributes = {"type", "vendor", "product", "revision", "name", "station"};

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
}

std::string hex32(uint32_t v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%08x", v);
    return buf;
}

void link_to_catalogue(const Catalogue& cat, NetSlave& s) {
    for (size_t i = 0; i < cat.devices.size(); ++i) {
        const EsiDevice& d = cat.devices[i];
        if (d.vendor != s.vendor || d.product != s.product) continue;
        if (s.revision_given ? d.revision != s.revision : false) continue;
        s.device = static_cast<int>(i);  // sorted: the last match is the newest revision
    }
}

class DesignReader {
public:
    DesignReader(const Catalogue& cat, Diagnostics& diags) : cat_(cat), diags_(diags) {}
    bool read(const xmlNode* root, Network& net);

private:
    bool number_attr(const xmlNode* el, const char* name, uint64_t max, uint64_t& value, bool& given);
    bool resolve_type(const xmlNode* el, const std::string& type, NetSlave& s);

    const Catalogue& cat_;
    Diagnostics& diags_;
};

bool DesignReader::number_attr(const xmlNode* el, const char* name, uint64_t max, uint64_t& value, bool& given) {
    auto text = xml_attr(el, name);
    given = text.has_value();
    if (!given) return true;
    if (!parse_esi_number(*text, value) || value > max) {
        diags_.error(xml_line(el), std::string(name) + "=\"" + *text + "\" is not a number up to " +
                                       (max > 0xffff ? "0xffffffff" : "0xffff"));
        return false;
    }
    return true;
}

// Exact <Type> first, then ignoring case, then the device's name. Among the
// revisions of the product found, the one given, else the newest.
bool DesignReader::resolve_type(const xmlNode* el, const std::string& type, NetSlave& s) {
    std::vector<size_t> hits;
    for (int pass = 0; pass < 3 && hits.empty(); ++pass) {
        for (size_t i = 0; i < cat_.devices.size(); ++i) {
            const EsiDevice& d = cat_.devices[i];
            bool match = pass == 0 ? d.type == type : pass == 1 ? lower(d.type) == lower(type) : lower(d.name) == lower(type);
            if (match) hits.push_back(i);
        }
    }
    if (hits.empty()) {
        std::vector<std::string> types;
        for (const EsiDevice& d : cat_.devices) types.push_back(d.type);
        std::string near = closest_match(type, types);
        if (cat_.devices.empty())
            diags_.error(xml_line(el), "slave type '" + type + "' needs the ESI file that describes it (--esi)");
        else
            diags_.error(xml_line(el), "unknown slave type '" + type + "': no device of that type in the ESI files" +
                                           (near.empty() ? "" : " (did you mean '" + near + "'?)"));
        return false;
    }
    const EsiDevice& first = cat_.devices[hits.front()];
    for (size_t i : hits) {
        const EsiDevice& d = cat_.devices[i];
        if (d.vendor != first.vendor || d.product != first.product) {
            diags_.error(xml_line(el), "slave type '" + type + "' names more than one product (" + hex32(first.product) +
                                           ", " + hex32(d.product) + "): give vendor=\"...\" product=\"...\" instead");
            return false;
        }
    }
    int found = -1;
    for (size_t i : hits)  // sorted by revision: the last one is the newest
        if (!s.revision_given || cat_.devices[i].revision == s.revision) found = static_cast<int>(i);
    if (found < 0) {
        diags_.error(xml_line(el), "no revision " + hex32(s.revision) + " of slave type '" + type + "' in the ESI files");
        return false;
    }
    const EsiDevice& d = cat_.devices[found];
    s.device = found;
    s.type = d.type;
    s.vendor = d.vendor;
    s.product = d.product;
    s.revision = d.revision;
    return true;
}

// Text that is not only whitespace: a design's elements hold none.
static bool stray_text(const xmlNode* c) {
    if (c->type != XML_TEXT_NODE && c->type != XML_CDATA_SECTION_NODE) return false;
    for (const xmlChar* p = c->content; p && *p; ++p)
        if (!std::isspace(*p)) return true;
    return false;
}

bool DesignReader::read(const xmlNode* root, Network& net) {
    bool ok = true;
    for (const xmlAttr* a = root->properties; a; a = a->next) {
        diags_.error(xml_line(root), "unknown attribute '" + std::string(reinterpret_cast<const char*>(a->name)) +
                                         "' on <network>: it takes none, only <slave> elements");
        ok = false;
    }
    for (const xmlNode* c = root->children; c; c = c->next) {
        if (stray_text(c)) {
            diags_.error(xml_line(c), "<network> holds <slave> elements only, not text");
            ok = false;
        }
        if (c->type != XML_ELEMENT_NODE) continue;
        if (xml_name(c) != "slave") {
            diags_.error(xml_line(c), "<network> holds <slave> elements in bus order, not <" + xml_name(c) + ">");
            ok = false;
            continue;
        }
        for (const xmlAttr* a = c->properties; a; a = a->next) {
            std::string n = reinterpret_cast<const char*>(a->name);
            if (std::find(kSlaveAttributes.begin(), kSlaveAttributes.end(), n) != kSlaveAttributes.end()) continue;
            diags_.error(xml_line(c),
                         unknown_attribute(n, "slave", closest_match(n, kSlaveAttributes), kSlaveAttributes));
            ok = false;
        }
        for (const xmlNode* inner = c->children; inner; inner = inner->next) {
            if (inner->type == XML_ELEMENT_NODE || stray_text(inner)) {
                const std::string what = inner->type == XML_ELEMENT_NODE ? "<" + xml_name(inner) + ">" : "text";
                diags_.error(xml_line(inner), "<slave> holds nothing: a slave is described by its attributes, not by " +
                                                  what);
                ok = false;
                break;
            }
        }
        NetSlave s;
        s.position = static_cast<int>(net.slaves.size());
        s.line = xml_line(c);
        uint64_t v = 0;
        bool given = false;
        if (!number_attr(c, "revision", 0xffffffff, v, s.revision_given)) ok = false;
        s.revision = static_cast<uint32_t>(v);
        if (!number_attr(c, "station", 0xffff, v, given)) ok = false;
        s.station = given ? static_cast<uint16_t>(v) : 0;
        auto type = xml_attr(c, "type");
        bool has_vendor = false, has_product = false;
        uint64_t vendor = 0, product = 0;
        if (!number_attr(c, "vendor", 0xffffffff, vendor, has_vendor)) ok = false;
        if (!number_attr(c, "product", 0xffffffff, product, has_product)) ok = false;
        if (type && (has_vendor || has_product)) {
            diags_.error(s.line, "<slave> gives either type=\"...\" or vendor=\"...\" product=\"...\", not both");
            ok = false;
        } else if (type) {
            s.type = *type;
            if (!resolve_type(c, *type, s)) ok = false;
        } else if (has_vendor && has_product) {
            s.vendor = static_cast<uint32_t>(vendor);
            s.product = static_cast<uint32_t>(product);
            link_to_catalogue(cat_, s);
            if (s.device >= 0) {
                s.type = cat_.devices[s.device].type;
                if (!s.revision_given) s.revision = cat_.devices[s.device].revision;
            }
        } else {
            diags_.error(s.line, "<slave> needs type=\"EK1100\" (a <Type> of the ESI files) or vendor=\"...\" "
                                 "and product=\"...\"");
            ok = false;
        }
        if (s.device >= 0) {
            s.name = cat_.devices[s.device].name;
            s.sms = cat_.devices[s.device].sms;
            default_process_data(cat_.devices[s.device], s);
        }
        if (auto name = xml_attr(c, "name")) s.name = *name;
        net.slaves.push_back(std::move(s));
    }
    if (ok && net.slaves.empty()) {
        diags_.error(xml_line(root), "<network> lists no <slave>");
        ok = false;
    }
    return ok;
}

// --- ENI -------------------------------------------------------------------

class EniReader {
public:
    EniReader(const Catalogue& cat, Diagnostics& diags) : cat_(cat), diags_(diags) {}
    bool read(const xmlNode* root, Network& net);

private:
    bool number(const xmlNode* parent, const char* name, uint64_t max, uint64_t& value, bool required = true);
    bool read_slave(const xmlNode* el, NetSlave& s);
    bool read_process_data(const xmlNode* pd, NetSlave& s);
    bool read_cyclic(const xmlNode* cyclic, Network& net);

    const Catalogue& cat_;
    Diagnostics& diags_;
};

bool EniReader::number(const xmlNode* parent, const char* name, uint64_t max, uint64_t& value, bool required) {
    const xmlNode* el = xml_child(parent, name);
    if (!el) {
        if (required) diags_.error(xml_line(parent), "<" + xml_name(parent) + "> has no <" + name + ">");
        return !required;
    }
    std::string text = xml_text(el);
    if (!parse_esi_number(text, value) || value > max) {
        diags_.error(xml_line(el), "<" + std::string(name) + "> is not a number in range: '" + text + "'");
        return false;
    }
    return true;
}

// The PDOs assigned to the slave's SyncManagers (<SmN><Pdo>), entries packed
// from the <Send> (outputs) and <Recv> (inputs) bit start in assignment order.
bool EniReader::read_process_data(const xmlNode* pd, NetSlave& s) {
    bool ok = true;
    uint64_t v = 0;
    for (const char* dir : {"Send", "Recv"}) {
        const xmlNode* area = xml_child(pd, dir);
        if (!area) continue;
        uint64_t start = 0, length = 0;
        ok = number(area, "BitStart", 0xffffffffu, start) && number(area, "BitLength", 0xffffffffu, length) && ok;
        if (dir[0] == 'S') {
            s.output_logical_bit = static_cast<int64_t>(start);
            s.output_bits = static_cast<uint32_t>(length);
        } else {
            s.input_logical_bit = static_cast<int64_t>(start);
            s.input_bits = static_cast<uint32_t>(length);
        }
    }
    std::vector<std::pair<bool, uint16_t>> assigned;  // (output, PDO index) in SyncManager order
    for (const xmlNode* c = pd->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        std::string n = xml_name(c);
        if (n.size() < 3 || n.compare(0, 2, "Sm") != 0 || !std::isdigit(static_cast<unsigned char>(n[2]))) continue;
        bool output = xml_text(xml_child(c, "Type")) == "Outputs";
        SyncManager sm;
        sm.index = std::atoi(n.c_str() + 2);
        sm.line = xml_line(c);
        sm.type = xml_text(xml_child(c, "Type"));
        uint64_t start = 0, size = 0, control = 0, enable = 0;
        ok = number(c, "StartAddress", 0xffff, start, false) && number(c, "DefaultSize", 0xffff, size, false) &&
             number(c, "ControlByte", 0xff, control, false) && number(c, "Enable", 0xff, enable, false) && ok;
        sm.start = static_cast<uint16_t>(start);
        sm.size = static_cast<uint16_t>(size);
        sm.control = static_cast<uint8_t>(control);
        sm.enable = enable != 0;
        s.sms.push_back(sm);
        for (const xmlNode* p : xml_children(c, "Pdo")) {
            if (parse_esi_number(xml_text(p), v) && v <= 0xffff) assigned.push_back({output, static_cast<uint16_t>(v)});
            else {
                diags_.error(xml_line(p), "<Pdo> is not a PDO index: '" + xml_text(p) + "'");
                ok = false;
            }
        }
    }
    std::map<std::pair<bool, uint16_t>, const xmlNode*> pdos;
    for (const xmlNode* c = pd->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE || (xml_name(c) != "TxPdo" && xml_name(c) != "RxPdo")) continue;
        if (!number(c, "Index", 0xffff, v)) {
            ok = false;
            continue;
        }
        pdos[{xml_name(c) == "RxPdo", static_cast<uint16_t>(v)}] = c;
    }
    uint32_t offset[2] = {0, 0};
    for (const auto& [output, index] : assigned) {
        auto it = pdos.find({output, index});
        if (it == pdos.end()) continue;  // assigned but not described: nothing to name
        const xmlNode* pdo = it->second;
        for (const xmlNode* en : xml_children(pdo, "Entry")) {
            NetEntry e;
            e.output = output;
            e.pdo_index = index;
            e.pdo_name = xml_text(xml_child(pdo, "Name"));
            e.entry.line = xml_line(en);
            uint64_t idx = 0, sub = 0, bits = 0;
            ok = number(en, "Index", 0xffff, idx, false) && number(en, "SubIndex", 0xff, sub, false) &&
                 number(en, "BitLen", 0xffff, bits) && ok;
            e.entry.index = static_cast<uint16_t>(idx);
            e.entry.subindex = static_cast<uint8_t>(sub);
            e.entry.bit_length = static_cast<uint16_t>(bits);
            e.entry.name = xml_text(xml_child(en, "Name"));
            e.entry.data_type = xml_text(xml_child(en, "DataType"));
            e.bit_offset = offset[output];
            int64_t base = output ? s.output_logical_bit : s.input_logical_bit;
            if (base >= 0) e.logical_bit = base + offset[output];
            offset[output] += e.entry.bit_length;
            s.entries.push_back(std::move(e));
        }
    }
    return ok;
}

bool EniReader::read_slave(const xmlNode* el, NetSlave& s) {
    s.line = xml_line(el);
    const xmlNode* info = xml_child(el, "Info");
    if (!info) {
        diags_.error(s.line, "<Slave> has no <Info>");
        return false;
    }
    uint64_t v = 0;
    bool ok = true;
    s.name = xml_text(xml_child(info, "Name"));
    if (number(info, "PhysAddr", 0xffff, v)) s.station = static_cast<uint16_t>(v);
    else ok = false;
    if (number(info, "VendorId", 0xffffffff, v)) s.vendor = static_cast<uint32_t>(v);
    else ok = false;
    if (number(info, "ProductCode", 0xffffffff, v)) s.product = static_cast<uint32_t>(v);
    else ok = false;
    v = 0;
    if (number(info, "RevisionNo", 0xffffffff, v, false)) s.revision = static_cast<uint32_t>(v);
    else ok = false;
    s.revision_given = xml_child(info, "RevisionNo") != nullptr;
    link_to_catalogue(cat_, s);
    if (s.device >= 0) s.type = cat_.devices[s.device].type;
    if (const xmlNode* pd = xml_child(el, "ProcessData")) ok = read_process_data(pd, s) && ok;
    return ok;
}

bool EniReader::read_cyclic(const xmlNode* cyclic, Network& net) {
    bool ok = true;
    int frame = 0;
    for (const xmlNode* f : xml_children(cyclic, "Frame")) {
        for (const xmlNode* c : xml_children(f, "Cmd")) {
            NetCommand cmd;
            cmd.frame = frame;
            cmd.line = xml_line(c);
            uint64_t v = 0;
            if (number(c, "Cmd", 0xff, v)) cmd.cmd = static_cast<uint8_t>(v);
            else ok = false;
            if (xml_child(c, "Addr")) {
                if (number(c, "Addr", 0xffffffff, v)) cmd.logical_address = static_cast<uint32_t>(v);
                else ok = false;
            } else {
                uint64_t adp = 0, ado = 0;
                ok = number(c, "Adp", 0xffff, adp) && number(c, "Ado", 0xffff, ado) && ok;
                cmd.adp = static_cast<uint16_t>(adp);
                cmd.ado = static_cast<uint16_t>(ado);
            }
            if (number(c, "DataLength", 0xffff, v)) cmd.length = static_cast<uint16_t>(v);
            else ok = false;
            if (xml_child(c, "Cnt")) {
                if (number(c, "Cnt", 0xffff, v)) cmd.expected_wkc = static_cast<int>(v);
                else ok = false;
            }
            net.cyclic.push_back(cmd);
        }
        ++frame;
    }
    return ok;
}

bool EniReader::read(const xmlNode* root, Network& net) {
    net.from_eni = true;
    const xmlNode* config = xml_child(root, "Config");
    if (!config) {
        diags_.error(xml_line(root), "<EtherCATConfig> has no <Config>");
        return false;
    }
    bool ok = true;
    for (const xmlNode* el : xml_children(config, "Slave")) {
        NetSlave s;
        s.position = static_cast<int>(net.slaves.size());
        ok = read_slave(el, s) && ok;
        net.slaves.push_back(std::move(s));
    }
    for (const xmlNode* cyclic : xml_children(config, "Cyclic")) ok = read_cyclic(cyclic, net) && ok;
    if (ok && net.slaves.empty()) {
        diags_.error(xml_line(config), "the ENI file configures no <Slave>");
        ok = false;
    }
    return ok;
}

}  // namespace

void default_process_data(const EsiDevice& dev, NetSlave& s) {
    uint32_t offset[2] = {0, 0};
    // Outputs and inputs each in SyncManager order, PDOs of one SyncManager in file order.
    std::vector<const EsiPdo*> assigned;
    for (const EsiPdo& p : dev.pdos)
        if (p.sm >= 0) assigned.push_back(&p);
    std::stable_sort(assigned.begin(), assigned.end(), [](const EsiPdo* a, const EsiPdo* b) { return a->sm < b->sm; });
    for (const EsiPdo* p : assigned) {
        bool output = !p->tx;
        for (const EsiEntry& en : p->entries) {
            NetEntry e;
            e.output = output;
            e.pdo_index = p->index;
            e.pdo_name = p->name;
            e.entry = en;
            e.bit_offset = offset[output];
            offset[output] += en.bit_length;
            s.entries.push_back(std::move(e));
        }
    }
    s.output_bits = offset[1];
    s.input_bits = offset[0];
}

bool read_network(const std::string& text, const std::string& file, const Catalogue& cat, Network& net,
                  Diagnostics& diags) {
    net = Network{};
    net.file = file;
    XmlDocPtr doc = read_untrusted_xml(text, "network files", diags);
    if (!doc) return false;
    const xmlNode* root = xmlDocGetRootElement(doc.get());
    std::string name = root ? xml_name(root) : "";
    if (name == "network") return DesignReader(cat, diags).read(root, net);
    if (name == "EtherCATConfig") return EniReader(cat, diags).read(root, net);
    diags.error(root ? xml_line(root) : 1, "a network file is a design (<network>) or an ENI file "
                                           "(<EtherCATConfig>), not <" + name + ">");
    return false;
}

}  // namespace dissgen

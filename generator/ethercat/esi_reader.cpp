#include "esi_reader.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>
#include <tuple>

#include "xml_input.h"

namespace fs = std::filesystem;

namespace dissgen {

namespace {

class EsiReader {
public:
    EsiReader(const std::string& file, Diagnostics& diags) : file_(file), diags_(diags) {}

    bool read(const xmlNode* root, Catalogue& into);

private:
    // A number in element `name` of `parent`; an error when missing (and required) or malformed.
    bool number_of(const xmlNode* parent, const char* name, uint64_t& value, bool required, uint64_t max);
    bool number_text(const xmlNode* where, const std::string& what, const std::string& text, uint64_t& value,
                     uint64_t max);
    bool flag(const xmlNode* el, const char* attr, bool& value);
    std::string localised_name(const xmlNode* parent);
    bool read_pdos(const xmlNode* owner, std::vector<EsiPdo>& pdos);
    bool read_pdo(const xmlNode* el, EsiPdo& pdo);
    bool read_device(const xmlNode* el, uint32_t vendor, EsiDevice& dev);
    bool read_sync_manager(const xmlNode* el, int index, SyncManager& sm);
    bool read_module(const xmlNode* el, uint32_t vendor, EsiModule& mod);

    std::string file_;
    Diagnostics& diags_;
};

bool EsiReader::number_text(const xmlNode* where, const std::string& what, const std::string& text,
                            uint64_t& value, uint64_t max) {
    if (!parse_esi_number(text, value)) {
        diags_.error(xml_line(where), what + " is not a number: '" + text +
                                          "' (ESI numbers are decimal, #x hex or 0x hex)");
        return false;
    }
    if (value > max) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%#llx", static_cast<unsigned long long>(max));
        diags_.error(xml_line(where), what + " " + text + " is larger than " + buf);
        return false;
    }
    return true;
}

bool EsiReader::number_of(const xmlNode* parent, const char* name, uint64_t& value, bool required, uint64_t max) {
    const xmlNode* el = xml_child(parent, name);
    if (!el) {
        if (required) diags_.error(xml_line(parent), "<" + xml_name(parent) + "> has no <" + name + ">");
        return !required;
    }
    return number_text(el, "<" + std::string(name) + ">", xml_text(el), value, max);
}

bool EsiReader::flag(const xmlNode* el, const char* attr, bool& value) {
    auto v = xml_attr(el, attr);
    if (!v) return true;
    if (*v == "1" || *v == "true") value = true;
    else if (*v == "0" || *v == "false") value = false;
    else {
        diags_.error(xml_line(el), std::string(attr) + "=\"" + *v + "\" is not a boolean (1, 0, true or false)");
        return false;
    }
    return true;
}

// English (LcId 1033) when there is one, else the first <Name>.
std::string EsiReader::localised_name(const xmlNode* parent) {
    auto names = xml_children(parent, "Name");
    for (const xmlNode* n : names) {
        auto lcid = xml_attr(n, "LcId");
        uint64_t id = 0;
        if (lcid && parse_esi_number(*lcid, id) && id == 1033) return xml_text(n);
    }
    return names.empty() ? "" : xml_text(names.front());
}

bool EsiReader::read_pdo(const xmlNode* el, EsiPdo& pdo) {
    pdo.tx = xml_name(el) == "TxPdo";
    pdo.line = xml_line(el);
    bool ok = flag(el, "Fixed", pdo.fixed) && flag(el, "Mandatory", pdo.mandatory);
    if (auto sm = xml_attr(el, "Sm")) {
        uint64_t v = 0;
        if (number_text(el, "Sm", *sm, v, 31)) pdo.sm = static_cast<int>(v);
        else ok = false;
    }
    uint64_t v = 0;
    if (number_of(el, "Index", v, true, 0xffff)) pdo.index = static_cast<uint16_t>(v);
    else ok = false;
    pdo.name = localised_name(el);
    for (const xmlNode* ex : xml_children(el, "Exclude")) {
        if (number_text(ex, "<Exclude>", xml_text(ex), v, 0xffff)) pdo.excludes.push_back(static_cast<uint16_t>(v));
        else ok = false;
    }
    for (const xmlNode* en : xml_children(el, "Entry")) {
        EsiEntry e;
        e.line = xml_line(en);
        if (number_of(en, "Index", v, true, 0xffff)) e.index = static_cast<uint16_t>(v);
        else ok = false;
        v = 0;
        if (number_of(en, "SubIndex", v, false, 0xff)) e.subindex = static_cast<uint8_t>(v);
        else ok = false;
        if (number_of(en, "BitLen", v, true, 0xffff)) e.bit_length = static_cast<uint16_t>(v);
        else ok = false;
        e.name = localised_name(en);
        e.data_type = xml_text(xml_child(en, "DataType"));
        if (!e.is_padding() && xml_child(en, "SubIndex") == nullptr) {
            diags_.error(e.line, "<Entry> of object " + xml_text(xml_child(en, "Index")) + " has no <SubIndex>");
            ok = false;
        }
        pdo.entries.push_back(std::move(e));
    }
    return ok;
}

bool EsiReader::read_pdos(const xmlNode* owner, std::vector<EsiPdo>& pdos) {
    bool ok = true;
    for (const xmlNode* c = owner->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        std::string n = xml_name(c);
        if (n != "TxPdo" && n != "RxPdo") continue;
        EsiPdo pdo;
        ok = read_pdo(c, pdo) && ok;
        pdos.push_back(std::move(pdo));
    }
    return ok;
}

bool EsiReader::read_sync_manager(const xmlNode* el, int index, SyncManager& sm) {
    sm.index = index;
    sm.line = xml_line(el);
    sm.type = xml_text(el);
    bool ok = true;
    uint64_t v = 0;
    struct Attr {
        const char* name;
        uint64_t max;
    };
    for (const Attr& a : {Attr{"StartAddress", 0xffff}, Attr{"DefaultSize", 0xffff}, Attr{"ControlByte", 0xff},
                          Attr{"Enable", 0xff}}) {
        auto text = xml_attr(el, a.name);
        if (!text) continue;
        if (!number_text(el, a.name, *text, v, a.max)) {
            ok = false;
            continue;
        }
        if (a.name[0] == 'S') sm.start = static_cast<uint16_t>(v);
        else if (a.name[0] == 'D') sm.size = static_cast<uint16_t>(v);
        else if (a.name[0] == 'C') sm.control = static_cast<uint8_t>(v);
        else sm.enable = v != 0;
    }
    return ok;
}

bool EsiReader::read_device(const xmlNode* el, uint32_t vendor, EsiDevice& dev) {
    dev.vendor = vendor;
    dev.file = file_;
    dev.line = xml_line(el);
    const xmlNode* type = xml_child(el, "Type");
    if (!type) {
        diags_.error(dev.line, "<Device> has no <Type> (product code and revision)");
        return false;
    }
    dev.type = xml_text(type);
    bool ok = true;
    uint64_t v = 0;
    auto product = xml_attr(type, "ProductCode");
    if (!product) {
        diags_.error(xml_line(type), "<Type> of device '" + dev.type + "' has no ProductCode");
        ok = false;
    } else if (number_text(type, "ProductCode", *product, v, 0xffffffff)) {
        dev.product = static_cast<uint32_t>(v);
    } else {
        ok = false;
    }
    if (auto rev = xml_attr(type, "RevisionNo")) {
        if (number_text(type, "RevisionNo", *rev, v, 0xffffffff)) dev.revision = static_cast<uint32_t>(v);
        else ok = false;
    }
    dev.name = localised_name(el);
    if (dev.name.empty()) dev.name = dev.type;
    for (const xmlNode* sm : xml_children(el, "Sm")) {
        dev.sms.emplace_back();
        ok = read_sync_manager(sm, static_cast<int>(dev.sms.size()) - 1, dev.sms.back()) && ok;
    }
    return read_pdos(el, dev.pdos) && ok;
}

bool EsiReader::read_module(const xmlNode* el, uint32_t vendor, EsiModule& mod) {
    mod.vendor = vendor;
    mod.file = file_;
    mod.line = xml_line(el);
    const xmlNode* type = xml_child(el, "Type");
    bool ok = true;
    if (type) {
        mod.type = xml_text(type);
        uint64_t v = 0;
        if (auto ident = xml_attr(type, "ModuleIdent")) {
            if (number_text(type, "ModuleIdent", *ident, v, 0xffffffff)) mod.ident = static_cast<uint32_t>(v);
            else ok = false;
        }
    } else {
        diags_.error(mod.line, "<Module> has no <Type>");
        ok = false;
    }
    mod.name = localised_name(el);
    if (mod.name.empty()) mod.name = mod.type;
    return read_pdos(el, mod.pdos) && ok;
}

bool EsiReader::read(const xmlNode* root, Catalogue& into) {
    const std::string root_name = xml_name(root);
    if (root_name != "EtherCATInfo" && root_name != "EtherCATModule") {
        diags_.error(xml_line(root), "the document element of an ESI file is <EtherCATInfo> (or <EtherCATModule> "
                                     "for module files), not <" + root_name + ">");
        return false;
    }
    const xmlNode* vendor_el = xml_child(root, "Vendor");
    if (!vendor_el) {
        diags_.error(xml_line(root), "<" + root_name + "> has no <Vendor>");
        return false;
    }
    uint64_t vendor = 0;
    if (!number_of(vendor_el, "Id", vendor, true, 0xffffffff)) return false;

    Catalogue found;
    bool ok = true;
    const xmlNode* descriptions = root_name == "EtherCATInfo" ? xml_child(root, "Descriptions") : root;
    if (root_name == "EtherCATInfo" && !descriptions) {
        diags_.error(xml_line(root), "<EtherCATInfo> has no <Descriptions>");
        return false;
    }
    for (const xmlNode* devices : xml_children(descriptions, "Devices")) {
        for (const xmlNode* d : xml_children(devices, "Device")) {
            EsiDevice dev;
            ok = read_device(d, static_cast<uint32_t>(vendor), dev) && ok;
            found.devices.push_back(std::move(dev));
        }
    }
    for (const xmlNode* modules : xml_children(descriptions, "Modules")) {
        for (const xmlNode* m : xml_children(modules, "Module")) {
            EsiModule mod;
            ok = read_module(m, static_cast<uint32_t>(vendor), mod) && ok;
            found.modules.push_back(std::move(mod));
        }
    }
    if (!ok) return false;
    for (auto& d : found.devices) into.devices.push_back(std::move(d));
    for (auto& m : found.modules) into.modules.push_back(std::move(m));
    return true;
}

std::vector<std::string> esi_files_of(const std::string& path, std::ostream& err, bool& ok) {
    std::error_code ec;
    if (!fs::is_directory(path, ec)) return {path};
    std::vector<std::string> files;
    for (fs::directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec)) {
        std::string ext = it->path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
        if (ext == ".xml" && it->is_regular_file()) files.push_back(it->path().string());
    }
    if (ec) {
        err << path << ": error: cannot read the folder: " << ec.message() << "\n";
        ok = false;
    } else if (files.empty()) {
        err << path << ": error: the folder holds no *.xml ESI files\n";
        ok = false;
    }
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace

bool read_esi(const std::string& text, const std::string& file, Catalogue& into, Diagnostics& diags) {
    XmlDocPtr doc = read_untrusted_xml(text, "ESI files", diags);
    if (!doc) return false;
    const xmlNode* root = xmlDocGetRootElement(doc.get());
    if (!root) {
        diags.error(1, "the file has no document element");
        return false;
    }
    return EsiReader(file, diags).read(root, into);
}

bool load_catalogue(const std::vector<std::string>& paths, Catalogue& out, std::ostream& err) {
    bool ok = true;
    Catalogue all;
    for (const std::string& path : paths) {
        for (const std::string& file : esi_files_of(path, err, ok)) {
            std::string text, why;
            Diagnostics diags;
            if (!read_whole_file(file, text, why)) diags.error(0, "cannot read the ESI file: " + why);
            else read_esi(text, file, all, diags);
            err << diags.format(file);
            ok = ok && !diags.has_errors();
        }
    }
    if (!ok) return false;
    std::stable_sort(all.devices.begin(), all.devices.end(), [](const EsiDevice& a, const EsiDevice& b) {
        return std::tie(a.vendor, a.product, a.revision) < std::tie(b.vendor, b.product, b.revision);
    });
    auto same = [](const EsiDevice& a, const EsiDevice& b) {
        return a.vendor == b.vendor && a.product == b.product && a.revision == b.revision;
    };
    all.devices.erase(std::unique(all.devices.begin(), all.devices.end(), same), all.devices.end());
    std::stable_sort(all.modules.begin(), all.modules.end(), [](const EsiModule& a, const EsiModule& b) {
        return std::tie(a.vendor, a.ident) < std::tie(b.vendor, b.ident);
    });
    out = std::move(all);
    return true;
}

std::string list_catalogue(const Catalogue& cat) {
    std::string out;
    char buf[40];
    for (const EsiDevice& d : cat.devices) {
        std::snprintf(buf, sizeof buf, "0x%08x 0x%08x 0x%08x ", d.vendor, d.product, d.revision);
        out += buf + d.name + "\n";
    }
    return out;
}

}  // namespace dissgen

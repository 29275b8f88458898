#include "xml_input.h"

#include <libxml/parser.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "parser.h"

namespace dissgen {

namespace {

struct FirstError {
    bool seen = false;
    int line = 0;
    std::string message;
};

void keep_first_error(void* user, xmlErrorPtr e) {
    auto* first = static_cast<FirstError*>(user);
    if (first->seen || !e || e->level < XML_ERR_ERROR) return;
    first->seen = true;
    first->line = e->line;
    std::string m = e->message ? e->message : "cannot parse";
    m = m.substr(0, m.find('\n'));
    while (!m.empty() && std::isspace(static_cast<unsigned char>(m.back()))) m.pop_back();
    first->message = m;
}

// Line of the first DOCTYPE or ENTITY declaration outside comments; 0 when none.
int declaration_line(const std::string& text) {
    size_t i = 0;
    int line = 1;
    while (i < text.size()) {
        if (text.compare(i, 4, "<!--") == 0) {
            size_t end = text.find("-->", i + 4);
            size_t stop = end == std::string::npos ? text.size() : end + 3;
            line += static_cast<int>(std::count(text.begin() + i, text.begin() + stop, '\n'));
            i = stop;
            continue;
        }
        if (text.compare(i, 9, "<!DOCTYPE") == 0 || text.compare(i, 8, "<!ENTITY") == 0) return line;
        if (text[i++] == '\n') ++line;
    }
    return 0;
}

}  // namespace

XmlDocPtr read_untrusted_xml(const std::string& text, const std::string& kind, Diagnostics& diags) {
    if (text.size() > kMaxInputXmlBytes) {
        diags.error(0, "the file is larger than " + std::to_string(kMaxInputXmlBytes >> 20) + " MiB");
        return nullptr;
    }
    // A DTD opens the door to entity expansion and external entities; none of
    // these files needs one.
    if (int line = declaration_line(text)) {
        diags.error(line, "DTDs and entity declarations are not allowed in " + kind);
        return nullptr;
    }
    FirstError first;
    xmlSetStructuredErrorFunc(&first, keep_first_error);
    xmlParserCtxtPtr ctxt = xmlNewParserCtxt();
    xmlDoc* doc = ctxt ? xmlCtxtReadMemory(ctxt, text.data(), static_cast<int>(text.size()), "input.xml", nullptr,
                                           XML_PARSE_NONET | XML_PARSE_BIG_LINES)
                       : nullptr;
    xmlSetStructuredErrorFunc(nullptr, nullptr);
    xmlFreeParserCtxt(ctxt);
    XmlDocPtr owned(doc);
    if (!doc || first.seen) {
        diags.error(xml_error_line(first.seen ? first.line : 1, first.message, text),
                    "XML is not well-formed: " + (first.seen ? first.message : std::string("cannot parse")));
        return nullptr;
    }
    return owned;
}

bool read_whole_file(const std::string& path, std::string& text, std::string& why, size_t max_bytes) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec) {
        why = ec.message();
        return false;
    }
    if (std::filesystem::is_directory(status)) {
        why = "it is a directory";
        return false;
    }
    if (!std::filesystem::is_regular_file(status)) {
        why = "it is not a regular file";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        why = "cannot open it";
        return false;
    }
    text.assign(max_bytes + 1, '\0');
    in.read(&text[0], static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<size_t>(in.gcount()));
    if (in.bad()) {
        why = "read error";
        return false;
    }
    return true;
}

int xml_error_line(int reported, const std::string& message, const std::string& text) {
    if (message.find("Comment not terminated") != std::string::npos) {
        size_t open = text.rfind("<!--");
        if (open != std::string::npos && text.find("-->", open + 4) == std::string::npos)
            return 1 + static_cast<int>(std::count(text.begin(), text.begin() + open, '\n'));
    }
    int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
    if (!text.empty() && text.back() != '\n') ++lines;
    return std::clamp(reported, 1, std::max(lines, 1));
}

int xml_line(const xmlNode* el) { return static_cast<int>(xmlGetLineNo(el)); }

std::string xml_name(const xmlNode* el) { return reinterpret_cast<const char*>(el->name); }

std::vector<const xmlNode*> xml_children(const xmlNode* el, const char* name) {
    std::vector<const xmlNode*> out;
    for (const xmlNode* c = el ? el->children : nullptr; c; c = c->next)
        if (c->type == XML_ELEMENT_NODE && (!name || xmlStrEqual(c->name, BAD_CAST name))) out.push_back(c);
    return out;
}

const xmlNode* xml_child(const xmlNode* el, const char* name) {
    for (const xmlNode* c = el ? el->children : nullptr; c; c = c->next)
        if (c->type == XML_ELEMENT_NODE && xmlStrEqual(c->name, BAD_CAST name)) return c;
    return nullptr;
}

std::string xml_text(const xmlNode* el) {
    if (!el) return "";
    xmlChar* raw = xmlNodeGetContent(el);
    std::string out;
    bool space = false;
    for (const xmlChar* p = raw; p && *p; ++p) {
        if (std::isspace(*p)) {
            space = !out.empty();
        } else {
            if (space) out += ' ';
            space = false;
            out += static_cast<char>(*p);
        }
    }
    xmlFree(raw);
    return out;
}

std::optional<std::string> xml_attr(const xmlNode* el, const char* name) {
    xmlChar* v = xmlGetProp(el, BAD_CAST name);
    if (!v) return std::nullopt;
    std::string out = reinterpret_cast<const char*>(v);
    xmlFree(v);
    return out;
}

bool parse_esi_number(const std::string& text, uint64_t& value) {
    size_t at = text.find_first_not_of(" \t\r\n");
    if (at != std::string::npos && text.compare(at, 2, "#x") == 0) return parse_number("0x" + text.substr(at + 2), value);
    if (at != std::string::npos && text.compare(at, 2, "#X") == 0) return parse_number("0X" + text.substr(at + 2), value);
    return parse_number(text, value);
}

}  // namespace dissgen

#include "xml_input.h"

#include <libxml/parser.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
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
    if (std::filesystem::is_directory(path, ec)) {
        why = "it is a directory";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        why = std::filesystem::exists(path, ec) ? "cannot open it" : "No such file or directory";
        return false;
    }
    // In pieces, and no further than one byte past the limit: a pipe or
    // /dev/stdin is read as a file is, and /dev/zero ends as too large.
    text.clear();
    char piece[65536];
    while (text.size() <= max_bytes && in.read(piece, sizeof piece).gcount() > 0)
        text.append(piece, static_cast<size_t>(in.gcount()));
    if (text.size() > max_bytes) text.resize(max_bytes + 1);
    if (in.bad()) {
        why = "read error";
        return false;
    }
    return true;
}

namespace {

// The line (from 1) of the byte at `pos` in text.
int line_at(const std::string& text, size_t pos) {
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

// The line of the bytes an encoding error names ("... input error, bytes
// 0xA4 0xA2 0xA4 0xEA"), 0 when they are not named or not found.
int line_of_named_bytes(const std::string& message, const std::string& text) {
    size_t at = message.find("bytes 0x");
    if (at == std::string::npos) return 0;
    std::string bytes;
    for (at += 6; at + 4 <= message.size() && message.compare(at, 2, "0x") == 0; at += 5) {
        const std::string digits = message.substr(at + 2, 2);
        char* end = nullptr;
        long v = std::strtol(digits.c_str(), &end, 16);
        if (end != digits.c_str() + digits.size()) break;
        bytes += static_cast<char>(v);
    }
    size_t found = bytes.empty() ? std::string::npos : text.find(bytes);
    return found == std::string::npos ? 0 : line_at(text, found);
}

}  // namespace

int xml_error_line(int reported, const std::string& message, const std::string& text) {
    if (reported <= 0)
        if (int line = line_of_named_bytes(message, text)) return line;
    if (message.find("Comment not terminated") != std::string::npos) {
        size_t open = text.rfind("<!--");
        if (open != std::string::npos && text.find("-->", open + 4) == std::string::npos)
            return line_at(text, open);
    }
    int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
    if (!text.empty() && text.back() != '\n') ++lines;
    return std::clamp(reported, 1, std::max(lines, 1));
}

int xml_line(const xmlNode* el) {
    // a rule file's line above 65534 is kept in psvi (parser.cpp, use_start_lines)
    if (el->type == XML_ELEMENT_NODE && el->line == 65535 && el->psvi)
        return static_cast<int>(reinterpret_cast<ptrdiff_t>(el->psvi));
    return static_cast<int>(xmlGetLineNo(el));
}

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

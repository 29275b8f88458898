// Reading untrusted XML input files other than rule files (ESI files, network
// designs, ENI files) with libxml2: no DTD, no entities, no network; the
// first well-formedness error becomes one diagnostic with its line. Small
// DOM helpers for walking the elements of such files.
#pragma once

#include <libxml/tree.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "diagnostics.h"

namespace dissgen {

// Larger than any real ESI file (the biggest vendor files are a few MiB).
constexpr size_t kMaxInputXmlBytes = 64u << 20;

struct XmlDocFree {
    void operator()(xmlDoc* d) const { xmlFreeDoc(d); }
};
using XmlDocPtr = std::unique_ptr<xmlDoc, XmlDocFree>;

// Parses `text`; `kind` names the files in messages ("ESI files"). Returns
// nullptr after adding an error to `diags`.
XmlDocPtr read_untrusted_xml(const std::string& text, const std::string& kind, Diagnostics& diags);

// Whole file into `text`, at most max_bytes + 1 bytes of it (the caller's size
// check then refuses it), so that a device such as /dev/zero is not read
// without end; pipes are read as files are. False when it cannot be read,
// with `why` ("it is a directory").
bool read_whole_file(const std::string& path, std::string& text, std::string& why,
                     size_t max_bytes = kMaxInputXmlBytes);

// The line to report for libxml2's error at `reported` in text: libxml2 counts
// one line past the end for what it finds missing there, and 0 for what it
// cannot place; an unclosed comment is reported where it opens.
int xml_error_line(int reported, const std::string& message, const std::string& text);

int xml_line(const xmlNode* el);
std::string xml_name(const xmlNode* el);
// Element children, all or those named `name`.
std::vector<const xmlNode*> xml_children(const xmlNode* el, const char* name = nullptr);
const xmlNode* xml_child(const xmlNode* el, const char* name);
// Text content (CDATA included), whitespace trimmed and inner runs collapsed.
std::string xml_text(const xmlNode* el);
std::optional<std::string> xml_attr(const xmlNode* el, const char* name);

// A number as ESI and ENI files write them: decimal, "#x1A00" or "0x1A00".
bool parse_esi_number(const std::string& text, uint64_t& value);

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "parser.h"

#include "analyses.h"

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xpath.h>
#include <libxml/xpathInternals.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <fstream>
#include <map>
#include <sstream>

#include "node_groups.h"
#include "text_util.h"
#include "xml_input.h"

namespace dissgen {

namespace {

// The digits without their leading zeros ("0002" -> "2", "000" -> "0"): a
// number's size is what remains.
std::string significant_digits(const std::string& digits) {
    return digits.substr(std::min(digits.find_first_not_of('0'), digits.size() - 1));
}

const std::vector<std::string> kRootAttributes = {"name",   "abbreviation", "ethertype", "filter",
                                                  "byteorder", "pdulength", "pdulengthadd", "padding"};
const std::vector<std::string> kNodeAttributes = {"name",   "length",    "displaytype", "repeat",
                                                  "count",  "filter",    "byteorder",   "description",
                                                  "if",     "in",        "summary",     "ifhook",
                                                  // text, time, hand-off and reassembly
                                                  "encoding", "unit", "direction", "dissector", "reassemble-id",
                                                  "reassemble-offset", "reassemble-seq", "reassemble-last",
                                                  "reassemble-more",
                                                  // alternatives and register windows
                                                  "otherwise", "base", "at", "stride", "instances",
                                                  "malformed",
                                                  // offset tables
                                                  "offsets", "from",
                                                  // two views of the same bytes
                                                  "overlay",
                                                  // computed values
                                                  "value", "covers",
                                                  // whose message it is
                                                  "valid"};
const std::vector<std::string> kEnumAttributes = {"value", "name"};
const std::vector<std::string> kHookAttributes = {"table", "value"};
const std::vector<std::string> kHeuristicAttributes = {"table", "enabled"};
const std::vector<std::string> kWhenAttributes = {"field", "peek", "in"};
const std::vector<std::string> kFindingAttributes = {"name", "severity", "group", "condition", "text"};
const std::vector<std::string> kLearnAttributes = {"name", "value", "if", "sender", "conversation"};
const std::vector<std::string> kLearnKeyAttributes = {"value", "lookup", "span", "id"};
const std::vector<std::string> kPairingAttributes = {"timeout", "analysis", "order"};
const std::vector<std::string> kKeyAttributes = {"field"};
const std::vector<std::string> kInputAttributes = {"name", "field"};
const std::vector<std::string> kCyclesAttributes = {"window", "sender", "lost", "requests", "maxlost"};
const std::vector<std::string> kCycleFieldAttributes = {"field"};
const std::vector<std::string> kSequenceAttributes = {"field", "bits", "step", "wrap"};
const std::vector<std::string> kCycleTestAttributes = {"field", "in"};
const std::vector<std::string> kDisplayNames = {"address", "numberhex", "numberdec", "bool",
                                                "origin",  "enum",      "nondisplay",
                                                // typed values shown as text
                                                "string",  "stringz",   "ipv4",      "int",
                                                "float",   "time",
                                                // absolute dates and times, GUIDs
                                                "datetime", "guid",
                                                // addresses of fixed size
                                                "ipv6", "mac", "eui64",
                                                // object identifiers
                                                "oid",
                                                // base-128 numbers of varying length
                                                "varint"};

int line_of(const xmlNode* el) { return xml_line(el); }  // lines above 65534: use_start_lines

std::string element_name(const xmlNode* el) { return reinterpret_cast<const char*>(el->name); }

// The valid name to suggest for an unknown one: one that begins with it or
// contains it ("len" -> length, "type" -> displaytype), one it begins with
// ("boolean" -> bool), else the closest by edit distance ("" if none is close).
std::string suggest(const std::string& word, const std::vector<std::string>& valid) {
    std::string w = word;
    std::transform(w.begin(), w.end(), w.begin(), [](unsigned char c) { return std::tolower(c); });
    if (w.size() >= 3) {
        for (const std::string& v : valid)
            if (v.rfind(w, 0) == 0) return v;
        for (const std::string& v : valid)
            if (v.find(w) != std::string::npos) return v;
        for (const std::string& v : valid)
            if (v.size() >= 3 && w.rfind(v, 0) == 0) return v;
    }
    return closest_match(word, valid);
}

// Collects libxml2's messages instead of letting it print them.
struct XmlErrorSink {
    int line = 0;
    std::string message;
    bool seen = false;
};

void collect_xml_error(void* user, xmlErrorPtr error) {
    auto* sink = static_cast<XmlErrorSink*>(user);
    if (sink->seen || error == nullptr || error->level < XML_ERR_ERROR) return;
    sink->seen = true;
    sink->line = error->line;
    // one line: libxml2 may go on over a second ("...indicate encoding !\nBytes: 0xC3 ...")
    const std::string m = error->message ? error->message : "unknown XML error";
    sink->message = trim(m.substr(0, m.find('\n')));
}

void ignore_xml_error(void*, xmlErrorPtr) {}

// Finds the line of `needle` in text outside comments, 0 if absent.
int line_of_text(const std::string& text, const std::string& needle) {
    size_t at = 0;
    while ((at = text.find(needle, at)) != std::string::npos) {
        size_t open = text.rfind("<!--", at);
        size_t close = open == std::string::npos ? std::string::npos : text.find("-->", open);
        if (open == std::string::npos || close < at)
            return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
        at = close;  // past this comment (npos: it never ends)
    }
    return 0;
}

// The line where each start tag begins, in document order. libxml2 numbers
// an element by the line where its start tag ends, which is not the element's
// line when the tag is written over several lines (as the paper does).
std::vector<int> start_tag_lines(const std::string& text) {
    std::vector<int> lines;
    int line = 1;
    size_t i = 0;
    const size_t n = text.size();
    auto skip_past = [&](const char* end) {
        size_t at = text.find(end, i);
        size_t stop = at == std::string::npos ? n : at + std::char_traits<char>::length(end);
        line += static_cast<int>(std::count(text.begin() + i, text.begin() + stop, '\n'));
        i = stop;
    };
    while (i < n) {
        if (text[i] != '<') {
            if (text[i++] == '\n') ++line;
        } else if (text.compare(i, 4, "<!--") == 0) {
            skip_past("-->");
        } else if (text.compare(i, 9, "<![CDATA[") == 0) {
            skip_past("]]>");
        } else if (text.compare(i, 2, "<?") == 0) {
            skip_past("?>");
        } else if (text.compare(i, 2, "</") == 0 || text.compare(i, 2, "<!") == 0) {
            skip_past(">");
        } else {
            lines.push_back(line);
            char quote = 0;  // attribute values may hold '>'
            for (++i; i < n; ++i) {
                char c = text[i];
                if (c == '\n') ++line;
                if (quote) {
                    if (c == quote) quote = 0;
                } else if (c == '"' || c == '\'') {
                    quote = c;
                } else if (c == '>') {
                    ++i;
                    break;
                }
            }
        }
    }
    return lines;
}

// Hand-written matchers instead of std::regex: libstdc++'s regex recurses
// once per character and overflows the stack on long attribute values.
bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }
bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

// "12byte" / "11bit": the digits and the unit ("" when `text` is not of that form).
// `loose` also takes space before the unit, any case and a plural 's' ("10 Bytes").
bool split_fixed_length(const std::string& text, bool loose, std::string& digits, std::string& unit) {
    size_t i = 0;
    while (i < text.size() && is_digit(text[i])) ++i;
    if (i == 0) return false;
    digits = text.substr(0, i);
    if (loose)
        while (i < text.size() && is_space(text[i])) ++i;
    unit = text.substr(i);
    if (loose) {
        std::transform(unit.begin(), unit.end(), unit.begin(), [](unsigned char c) { return std::tolower(c); });
        if (!unit.empty() && unit.back() == 's') unit.pop_back();
    }
    return unit == "byte" || unit == "bit";
}

// "XPATH * 2": splits off the operator and the integer at the end. The XPath
// must not end in an operator or be empty.
bool split_arithmetic(const std::string& text, std::string& path, char& op, std::string& number) {
    size_t end = text.size();
    while (end > 0 && is_digit(text[end - 1])) --end;
    if (end == text.size()) return false;
    number = text.substr(end);
    while (end > 0 && is_space(text[end - 1])) --end;
    if (end == 0 || std::string("+-*").find(text[end - 1]) == std::string::npos) return false;
    op = text[end - 1];
    --end;
    while (end > 0 && is_space(text[end - 1])) --end;
    if (end == 0 || std::string("+-*").find(text[end - 1]) != std::string::npos) return false;
    path = text.substr(0, end);
    return true;
}

// The offset of the first "<enum" whose tag has an attribute name starting
// with a digit (the paper's <enum 0x0a="LRD"/>), npos if none.
size_t find_paper_enum(const std::string& text) {
    size_t close = 0;
    for (size_t at = text.find("<enum"); at != std::string::npos; at = text.find("<enum", std::max(at + 1, close))) {
        // a later "<enum" before `close` sees a part of what this one saw
        size_t body = at + 5;
        if (body >= text.size() || !is_space(text[body])) continue;
        close = std::min(text.find('>', body), text.size());
        for (size_t j = body + 1; j < close; ++j) {
            if (!is_space(text[j - 1]) || !is_digit(text[j])) continue;
            size_t k = j;
            while (k < close && std::isalnum(static_cast<unsigned char>(text[k]))) ++k;
            while (k < close && is_space(text[k])) ++k;
            if (k < close && text[k] == '=') return at;
        }
    }
    return std::string::npos;
}

void collect_elements(xmlNode* el, std::vector<xmlNode*>& out) {
    for (; el; el = el->next) {
        if (el->type != XML_ELEMENT_NODE) continue;
        out.push_back(el);
        collect_elements(el->children, out);
    }
}

// Numbers every element by the line its start tag begins on.
void use_start_lines(xmlDoc* doc, const std::string& text) {
    std::vector<xmlNode*> elements;
    collect_elements(xmlDocGetRootElement(doc), elements);
    std::vector<int> lines = start_tag_lines(text);
    if (lines.size() != elements.size()) return;  // keep libxml2's numbers
    for (size_t k = 0; k < elements.size(); ++k) {
        if (lines[k] < 65535) {
            elements[k]->line = static_cast<unsigned short>(lines[k]);
        } else {  // too big for the field: line_of reads it from psvi, unused otherwise
            elements[k]->line = 65535;
            elements[k]->psvi = reinterpret_cast<void*>(static_cast<ptrdiff_t>(lines[k]));
        }
    }
}

// libxml2 steps one XPath evaluation, and all of a file's, may take: the
// shipped rule files take under 40000 in all, and 20 million take a second.
constexpr unsigned long kXPathStepLimit = 5000000;
constexpr unsigned long kXPathFileStepLimit = 20000000;

class Parser {
public:
    Parser(xmlDoc* doc, Diagnostics& diags, const GroupUses& uses) : doc_(doc), diags_(diags), uses_(uses) {}

    std::unique_ptr<Protocol> parse_root(xmlNode* root);

private:
    struct PendingRef {
        FieldRef* ref;
        xmlNode* context;
        int line;
        std::string attribute;
    };

    std::map<std::string, std::string> attributes(xmlNode* el, const std::vector<std::string>& allowed);
    std::unique_ptr<Node> parse_node(xmlNode* el, Node* parent, int depth);
    void parse_enum(xmlNode* el, Node& node);
    void parse_hook(xmlNode* el, Protocol& proto);
    void parse_heuristic(xmlNode* el, Protocol& proto);
    void parse_text_direction_handoff_attributes(std::map<std::string, std::string>& attrs, int line, Node& node);
    void defer_reassembly_refs(Node& node, xmlNode* el);
    bool parse_enum_range(const std::string& text, EnumItem& item);
    void parse_when(xmlNode* el, Node& node, xmlNode* node_el);
    void parse_finding(xmlNode* el, Node& node);
    void parse_learn(xmlNode* el, Node& node);
    bool parse_expression_attribute(const std::string& text, int line, const std::string& what, Expr& out);
    void parse_layout_attributes(std::map<std::string, std::string>& attrs, Node& node);
    void parse_pairing(xmlNode* el, Protocol& proto);
    void parse_cycles(xmlNode* el, Protocol& proto);
    bool parse_cycle_field(xmlNode* el, const std::vector<std::string>& allowed, CycleField& out,
                           std::map<std::string, std::string>& attrs);
    void parse_length(const std::string& text, int line, Node& node, xmlNode* el);
    void parse_rest_minus(const std::string& raw, const std::string& tail, int line, Node& node);
    void parse_display(const std::string& text, int line, Node& node);
    void parse_in_list(const std::string& text, int line, Node& node);
    void parse_value(const std::string& text, int line, Node& node);
    bool parse_value_list(const std::string& text, int line, const std::string& attribute,
                          std::vector<ValueRange>& out);
    bool parse_byteorder(const std::string& text, int line, ByteOrder& out);
    void parse_yes_no(std::map<std::string, std::string>& attrs, const char* name, int line, const std::string& of,
                      const std::string& yes_means, bool& out);
    FieldRef make_ref(const std::string& text, int line, const std::string& attribute, bool arithmetic);
    void defer(FieldRef& ref, xmlNode* context, int line, const std::string& attribute);
    std::string nothing_selected_hint(const PendingRef& p);
    std::string name_hint(const std::string& wanted) const;
    std::string remembered_suggestion(const std::string& word, const std::vector<std::string>& valid);
    void unexpected_child(xmlNode* child, const std::string& parent, const std::vector<std::string>& allowed);
    void resolve_all();
    Node* resolve(const PendingRef& p);

    xmlDoc* doc_;
    Diagnostics& diags_;
    const GroupUses& uses_;  // where copies of groups stand, for messages about them
    std::map<const xmlNode*, Node*> by_xml_;
    // name_hint of each name an XPath that selected nothing looked for: every
    // copy of a failing path in a <group> gets the same
    std::map<std::string, std::string> name_hints_;
    // suggest's answer for each misspelt word with its list of valid words
    // (the key joins them): each copy of a <group> repeats its mistakes
    std::map<std::string, std::string> suggestions_;
    std::vector<PendingRef> pending_;
    int next_doc_index_ = 1;
    bool xpath_limit_hit_ = false;
    unsigned long xpath_steps_left_ = kXPathFileStepLimit;
};

std::map<std::string, std::string> Parser::attributes(xmlNode* el,
                                                      const std::vector<std::string>& allowed) {
    std::map<std::string, std::string> out;
    for (xmlAttr* a = el->properties; a; a = a->next) {
        std::string name = reinterpret_cast<const char*>(a->name);
        if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
            diags_.error(line_of(el),
                         unknown_attribute(name, element_name(el), remembered_suggestion(name, allowed), allowed));
            continue;
        }
        xmlChar* value = xmlNodeListGetString(doc_, a->children, 1);
        out[name] = value ? reinterpret_cast<const char*>(value) : "";
        xmlFree(value);
    }
    return out;
}

std::string Parser::remembered_suggestion(const std::string& word, const std::vector<std::string>& valid) {
    std::string key = word;
    for (const std::string& v : valid) key += '\0' + v;
    auto [known, added] = suggestions_.try_emplace(std::move(key));
    if (added) known->second = suggest(word, valid);
    return known->second;
}

void Parser::unexpected_child(xmlNode* child, const std::string& parent,
                              const std::vector<std::string>& allowed) {
    if (child->type == XML_TEXT_NODE || child->type == XML_CDATA_SECTION_NODE) {
        xmlChar* content = xmlNodeGetContent(child);
        std::string raw = content ? reinterpret_cast<const char*>(content) : "";
        xmlFree(content);
        std::string text = trim(raw);
        // libxml2 numbers a text node by the line where it ends.
        size_t first = raw.find(text);
        int line = line_of(child) - static_cast<int>(std::count(raw.begin() + first, raw.end(), '\n'));
        if (!text.empty())
            diags_.error(std::max(line, 1), "unexpected text '" + text.substr(0, 40) + "' in <" + parent + ">");
        return;
    }
    if (child->type != XML_ELEMENT_NODE) return;  // comments, processing instructions
    std::string name = element_name(child);
    std::string msg = "unknown element <" + name + "> in <" + parent + ">";
    std::string near = remembered_suggestion(name, allowed);
    static const std::vector<std::string> kNodeOnly = {"enum", "when", "finding", "learn"};
    if (allowed.empty())
        msg += "; <" + parent + "> has no child elements";
    else if (parent == "root" && std::find(kNodeOnly.begin(), kNodeOnly.end(), name) != kNodeOnly.end())
        msg += "; <" + name + "> goes inside a <node>, whose fields it reads";
    else if (!near.empty())
        msg += "; did you mean <" + near + ">?";
    else
        msg += "; expected <" + join(allowed, "> or <") + ">";
    diags_.error(line_of(child), msg);
}

// A yes/no attribute `name`, when given, into `out`; else `FILE:LINE: error:
// bad NAME 'VALUE'OF: expected yes (YES_MEANS) or no`.
void Parser::parse_yes_no(std::map<std::string, std::string>& attrs, const char* name, int line, const std::string& of,
                          const std::string& yes_means, bool& out) {
    if (!attrs.count(name)) return;
    const std::string v = trim(attrs[name]);
    if (v == "yes" || v == "no")
        out = v == "yes";
    else
        diags_.error(line, std::string("bad ") + name + " '" + attrs[name] + "'" + of + ": expected yes (" + yes_means +
                               ") or no");
}

bool Parser::parse_byteorder(const std::string& text, int line, ByteOrder& out) {
    if (text == "big") out = ByteOrder::Big;
    else if (text == "little") out = ByteOrder::Little;
    else {
        diags_.error(line, "bad byteorder '" + text + "': expected 'big' or 'little'");
        return false;
    }
    return true;
}

std::unique_ptr<Protocol> Parser::parse_root(xmlNode* root) {
    auto proto = std::make_unique<Protocol>();
    proto->line = line_of(root);
    auto attrs = attributes(root, kRootAttributes);
    proto->name = attrs["name"];
    proto->abbreviation = attrs["abbreviation"];
    if (proto->name.empty()) diags_.error(proto->line, "<root> needs a 'name' attribute");
    if (proto->abbreviation.empty()) diags_.error(proto->line, "<root> needs an 'abbreviation' attribute");
    if (attrs.count("filter")) {
        proto->filter = attrs["filter"];
        proto->filter_given = true;
    } else {
        for (char c : proto->abbreviation)
            proto->filter += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    if (attrs.count("ethertype")) {
        uint64_t v;
        if (!parse_number(attrs["ethertype"], v) || v > 0xffff)
            diags_.error(proto->line, "bad ethertype '" + attrs["ethertype"] +
                                          "': expected a number from 0 to 0xffff, hex (0x88a4) or decimal");
        else
            proto->ethertype = v;
    }
    if (attrs.count("byteorder")) parse_byteorder(attrs["byteorder"], proto->line, proto->byteorder);
    if (attrs.count("pdulength")) {
        proto->pdulength = make_ref(attrs["pdulength"], proto->line, "pdulength", false);
    }
    if (attrs.count("pdulengthadd")) {
        const std::string& t = trim(attrs["pdulengthadd"]);
        char* end = nullptr;
        long long v = std::strtoll(t.c_str(), &end, 0);
        if (t.empty() || *end != '\0' || v < -65536 || v > 65536)
            diags_.error(proto->line, "bad pdulengthadd '" + attrs["pdulengthadd"] + "': expected an integer");
        else
            proto->pdulengthadd = v;
        if (!attrs.count("pdulength"))
            diags_.error(proto->line, "'pdulengthadd' needs a 'pdulength' field");
    }

    if (attrs.count("padding")) {
        const std::string padding = trim(attrs["padding"]);
        if (padding == "none")
            proto->no_padding = true;
        else if (padding != "zeros")
            diags_.error(proto->line, "bad padding '" + attrs["padding"] +
                                          "': expected 'zeros' (zero bytes a length leaves over are padding, the "
                                          "default) or 'none' (the protocol never pads: they are not decoded either)");
    }
    for (xmlNode* c = root->children; c; c = c->next) {
        if (c->type == XML_ELEMENT_NODE && element_name(c) == "node")
            proto->nodes.push_back(parse_node(c, nullptr, 1));
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "hook")
            parse_hook(c, *proto);
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "pairing")
            parse_pairing(c, *proto);
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "heuristic")
            parse_heuristic(c, *proto);
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "cycles")
            parse_cycles(c, *proto);
        else
            unexpected_child(c, "root", {"node", "hook", "pairing", "heuristic", "cycles", "group", "use"});
    }
    if (proto->pdulength) defer(*proto->pdulength, root, proto->line, "pdulength");
    resolve_all();
    return proto;
}

void Parser::parse_hook(xmlNode* el, Protocol& proto) {
    Hook hook;
    hook.line = line_of(el);
    auto attrs = attributes(el, kHookAttributes);
    hook.table = trim(attrs["table"]);
    if (hook.table.empty()) diags_.error(hook.line, "<hook> needs a 'table' attribute (e.g. udp.port)");
    if (!attrs.count("value"))
        diags_.error(hook.line, "<hook> needs a 'value' attribute");
    else if (!parse_number(attrs["value"], hook.value) || hook.value > 0xffffffffu)
        diags_.error(hook.line, "bad hook value '" + attrs["value"] + "': expected a 32-bit number");
    for (xmlNode* c = el->children; c; c = c->next) unexpected_child(c, "hook", {});
    proto.hooks.push_back(hook);
}

// <heuristic table="udp" enabled="false"/>: one per heuristic list.
void Parser::parse_heuristic(xmlNode* el, Protocol& proto) {
    Heuristic h;
    h.line = line_of(el);
    auto attrs = attributes(el, kHeuristicAttributes);
    h.table = trim(attrs["table"]);
    if (h.table.empty()) diags_.error(h.line, "<heuristic> needs a 'table' attribute (a heuristic list such as udp)");
    if (attrs.count("enabled")) {
        const std::string e = trim(attrs["enabled"]);
        if (e == "true" || e == "false") h.enabled = e == "true";
        else diags_.error(h.line, "bad enabled '" + attrs["enabled"] + "' on <heuristic>: expected 'true' or 'false'");
    }
    for (xmlNode* c = el->children; c; c = c->next) unexpected_child(c, "heuristic", {});
    for (const Heuristic& other : proto.heuristics)
        if (!h.table.empty() && other.table == h.table) {
            diags_.error(h.line, "duplicate <heuristic table=\"" + h.table + "\"> (the first is on line " +
                                     std::to_string(other.line) + "): one per heuristic list");
            return;
        }
    proto.heuristics.push_back(h);
}

// Request/response pairing: <pairing timeout="0.1" analysis="ethercat-esc"><key field="XPATH"/>...
// [<request field="XPATH" in="LIST"/>]</pairing>
void Parser::parse_pairing(xmlNode* el, Protocol& proto) {
    int line = line_of(el);
    if (proto.pairing) {
        diags_.error(line, "only one <pairing> per protocol (the first is on line " +
                               std::to_string(proto.pairing->line) + "); list all key fields in it");
        return;
    }
    proto.pairing = std::make_unique<Pairing>();
    Pairing& pairing = *proto.pairing;
    pairing.line = line;
    auto attrs = attributes(el, kPairingAttributes);
    if (attrs.count("timeout")) {
        const std::string t = trim(attrs["timeout"]);
        char* end = nullptr;
        double v = t.empty() ? 0 : std::strtod(t.c_str(), &end);
        if (t.empty() || *end != '\0' || !(v > 0) || v > 3600)
            diags_.error(line, "bad timeout '" + attrs["timeout"] +
                                   "': expected seconds, more than 0 and at most 3600 (e.g. 0.1)");
        else
            pairing.timeout = v;
    }
    if (attrs.count("order")) {
        const std::string order = trim(attrs["order"]);
        if (order == "any")
            pairing.ordered = false;
        else if (order != "request")
            diags_.error(line, "bad order '" + attrs["order"] +
                                   "': expected request (responses come back in the order of their requests, the "
                                   "default) or any");
    }
    if (attrs.count("analysis")) {
        pairing.analysis = trim(attrs["analysis"]);
        std::vector<std::string> known;
        for (const Analysis& a : analyses()) known.push_back(a.name);
        if (!find_analysis(pairing.analysis))
            diags_.error(line, "unknown analysis '" + attrs["analysis"] + "'; valid: " + join(known, ", "));
    }
    std::vector<xmlNode*> key_elements, input_elements;
    for (xmlNode* c = el->children; c; c = c->next) {
        if (c->type == XML_ELEMENT_NODE && element_name(c) == "key") {
            key_elements.push_back(c);
        } else if (c->type == XML_ELEMENT_NODE && element_name(c) == "input") {
            input_elements.push_back(c);
        } else if (c->type == XML_ELEMENT_NODE &&
                   (element_name(c) == "request" || element_name(c) == "unanswered")) {
            const std::string what = element_name(c);
            std::optional<CycleField>& slot = what == "request" ? pairing.request : pairing.unanswered;
            CycleField f;
            std::map<std::string, std::string> rattrs;
            if (slot)
                diags_.error(line_of(c), "only one <" + what + "> in <pairing> (the first is on line " +
                                             std::to_string(slot->line) + "): list its values in 'in'");
            else if (parse_cycle_field(c, kCycleTestAttributes, f, rattrs))
                slot = f;
        } else {
            unexpected_child(c, "pairing", {"key", "input", "request", "unanswered"});
        }
    }
    // What the analysis reads: checked against its list by analysis_inputs.cpp.
    for (xmlNode* c : input_elements) {
        AnalysisInput input;
        input.line = line_of(c);
        auto iattrs = attributes(c, kInputAttributes);
        input.name = trim(iattrs["name"]);
        if (input.name.empty() || !iattrs.count("field") || trim(iattrs["field"]).empty())
            diags_.error(input.line, "<input> needs 'name' (what the analysis reads) and 'field' (an XPath to a "
                                     "numeric field, from <root>)");
        else
            input.field = make_ref(iattrs["field"], input.line, "field", false);
        for (xmlNode* k = c->children; k; k = k->next) unexpected_child(k, "input", {});
        pairing.inputs.push_back(input);
    }
    // All keys first, then their references: defer() keeps pointers into the vector.
    for (xmlNode* c : key_elements) {
        PairingKey key;
        key.line = line_of(c);
        auto kattrs = attributes(c, kKeyAttributes);
        if (!kattrs.count("field") || trim(kattrs["field"]).empty())
            diags_.error(key.line, "<key> needs a 'field' attribute: an XPath to a numeric field, from <root>");
        else
            key.field = make_ref(kattrs["field"], key.line, "field", false);
        for (xmlNode* k = c->children; k; k = k->next) unexpected_child(k, "key", {});
        pairing.keys.push_back(key);
    }
    if (pairing.keys.empty())
        diags_.error(line, "<pairing> needs at least one <key field=\"XPATH\"/>: the fields a response repeats "
                           "from its request");
    for (size_t i = 0; i < pairing.keys.size(); ++i)
        defer(pairing.keys[i].field, el->parent, pairing.keys[i].line, "field");
    for (AnalysisInput& input : pairing.inputs)
        defer(input.field, el->parent, input.line, "field");
    if (pairing.request) defer(pairing.request->field, el->parent, pairing.request->line, "field");
    if (pairing.unanswered) defer(pairing.unanswered->field, el->parent, pairing.unanswered->line, "field");
}

// Periodic traffic: <cycles window="8" sender="yes" lost="sequence|period" requests="yes" maxlost="N"><signature field="XPATH"/>...
// [<sequence field="XPATH" bits="N"/>] [<only field="XPATH" in="LIST"/>]... [<never .../>]...</cycles>
void Parser::parse_cycles(xmlNode* el, Protocol& proto) {
    int line = line_of(el);
    if (proto.cycles) {
        diags_.error(line, "only one <cycles> per protocol (the first is on line " + std::to_string(proto.cycles->line) +
                               "); list every signature field in it");
        return;
    }
    proto.cycles = std::make_unique<Cycles>();
    Cycles& cycles = *proto.cycles;
    cycles.line = line;
    auto attrs = attributes(el, kCyclesAttributes);
    if (attrs.count("window")) {
        uint64_t w = 0;
        if (!parse_number(attrs["window"], w) || w < 1 || w > 64)
            diags_.error(line, "bad window '" + attrs["window"] +
                                   "': expected the number of regular periods in a row that make a cycle, 1 to 64 "
                                   "(1: every stream is a cycle from its second message)");
        else
            cycles.window = static_cast<unsigned>(w);
    }
    if (attrs.count("sender")) {
        const std::string sender = trim(attrs["sender"]);
        if (sender == "yes" || sender == "connection" || sender == "no") {
            cycles.by_sender = sender != "no";
            cycles.by_connection = sender == "connection";
        } else {
            diags_.error(line, "bad sender '" + attrs["sender"] +
                                   "': expected yes (the sender's address and port are part of the signature), "
                                   "connection (the receiver's too: each side of each connection its own stream) "
                                   "or no");
        }
    }
    parse_yes_no(attrs, "requests", line, "", "only the <pairing>'s requests are timed, with their round trips",
                 cycles.requests_only);
    if (attrs.count("lost")) {
        const std::string v = trim(attrs["lost"]);
        if (v == "period")
            cycles.lost_by_period = true;
        else if (v == "sequence")
            cycles.lost_line = line;
        else
            diags_.error(line, "bad lost '" + attrs["lost"] +
                                   "': expected sequence (the <sequence> count tells the messages lost) or period (a "
                                   "cycle's period of about n nominal periods means n - 1 messages lost)");
    }
    if (attrs.count("maxlost")) {
        uint64_t n = 0;
        if (!parse_number(attrs["maxlost"], n) || n < 1 || n > kMostLostInAGap)
            diags_.error(line, "bad maxlost '" + attrs["maxlost"] +
                                   "': expected the most messages counted lost in one gap, 1 to " +
                                   std::to_string(kMostLostInAGap) + " (a bigger gap is a restart: nothing lost)");
        else
            cycles.max_lost = n;
    }
    for (xmlNode* c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) {
            unexpected_child(c, "cycles", {"signature", "sequence", "only", "never"});
            continue;
        }
        const std::string name = element_name(c);
        CycleField f;
        std::map<std::string, std::string> sattrs;
        if (name == "signature") {
            if (parse_cycle_field(c, kCycleFieldAttributes, f, sattrs)) cycles.signature.push_back(f);
        } else if (name == "sequence") {
            if (cycles.sequence) {
                diags_.error(line_of(c), "only one <sequence> in <cycles> (the first is on line " +
                                             std::to_string(cycles.sequence->line) + ")");
                continue;
            }
            if (parse_cycle_field(c, kSequenceAttributes, f, sattrs)) cycles.sequence = f;
            if (sattrs.count("bits")) {
                uint64_t b = 0;
                if (!parse_number(sattrs["bits"], b) || b < 1 || b > 64)
                    diags_.error(line_of(c), "bad bits '" + sattrs["bits"] +
                                                 "': expected the sequence count's width, 1 to 64");
                else
                    cycles.sequence_bits = static_cast<unsigned>(b);
            }
            if (sattrs.count("step")) {
                uint64_t n = 0;
                if (sattrs["step"] == "learned")
                    cycles.sequence_step = 0;
                else if (!parse_number(sattrs["step"], n) || n < 1)
                    diags_.error(line_of(c), "bad step '" + sattrs["step"] +
                                                 "': expected how much the count advances per message (a number "
                                                 "from 1) or 'learned'");
                else
                    cycles.sequence_step = n;
            }
            if (sattrs.count("wrap")) {
                uint64_t n = 0;
                if (sattrs.count("bits"))
                    diags_.error(line_of(c), "bits= and wrap= both say where the count wraps: keep one (wrap=\"N\": "
                                             "it runs 0 to N - 1; bits=\"B\": 0 to 2^B - 1)");
                else if (!parse_number(sattrs["wrap"], n) || n < 2)
                    diags_.error(line_of(c), "bad wrap '" + sattrs["wrap"] +
                                                 "': expected how many values the count takes before it wraps to 0 "
                                                 "(a number from 2)");
                else
                    cycles.sequence_wrap = n;
            }
        } else if (name == "only" || name == "never") {
            if (parse_cycle_field(c, kCycleTestAttributes, f, sattrs))
                (name == "only" ? cycles.only : cycles.never).push_back(f);
        } else {
            unexpected_child(c, "cycles", {"signature", "sequence", "only", "never"});
        }
    }
    if (cycles.signature.empty())
        diags_.error(line, "<cycles> needs at least one <signature field=\"XPATH\"/>: the fields whose values tell "
                           "one stream of messages from another");
    if (cycles.only.size() > 32) diags_.error(cycles.only[32].line, "at most 32 <only> tests in <cycles>");
    // All fields first, then their references: defer() keeps pointers into the vectors.
    for (CycleField& f : cycles.signature) defer(f.field, el->parent, f.line, "field");
    if (cycles.sequence) defer(cycles.sequence->field, el->parent, cycles.sequence->line, "field");
    for (CycleField& f : cycles.only) defer(f.field, el->parent, f.line, "field");
    for (CycleField& f : cycles.never) defer(f.field, el->parent, f.line, "field");
}

// One field of <cycles>: its 'field' XPath and, for <only>/<never>, its 'in' list.
bool Parser::parse_cycle_field(xmlNode* el, const std::vector<std::string>& allowed, CycleField& out,
                               std::map<std::string, std::string>& attrs) {
    out.line = line_of(el);
    const std::string what = "<" + element_name(el) + ">";
    attrs = attributes(el, allowed);
    for (xmlNode* k = el->children; k; k = k->next) unexpected_child(k, element_name(el), {});
    if (!attrs.count("field") || trim(attrs["field"]).empty()) {
        diags_.error(out.line, what + " needs a 'field' attribute: an XPath to a numeric field, from <root>");
        return false;
    }
    out.field = make_ref(attrs["field"], out.line, "field", false);
    if (attrs.count("in") && !parse_value_list(attrs["in"], out.line, "in", out.in_list)) return false;
    return true;
}

std::unique_ptr<Node> Parser::parse_node(xmlNode* el, Node* parent, int depth) {
    auto node = std::make_unique<Node>();
    node->line = line_of(el);
    if (!uses_.empty()) node->group_use = group_uses_of(uses_, el);
    node->parent = parent;
    node->doc_index = next_doc_index_++;
    by_xml_[el] = node.get();
    auto attrs = attributes(el, kNodeAttributes);

    node->name = attrs["name"];
    if (trim(node->name).empty()) diags_.error(node->line, "<node> needs a non-empty 'name' attribute");
    if (depth > kMaxNesting) {
        diags_.error(node->line, "nodes nested deeper than " + std::to_string(kMaxNesting) + " levels");
        return node;
    }
    if (attrs.count("filter")) node->filter = attrs["filter"];
    if (attrs.count("description")) node->description = attrs["description"];
    if (attrs.count("summary")) node->summary = attrs["summary"];
    if (attrs.count("byteorder")) {
        ByteOrder order;
        if (parse_byteorder(attrs["byteorder"], node->line, order)) node->byteorder_given = order;
    }
    if (attrs.count("displaytype")) parse_display(attrs["displaytype"], node->line, *node);
    if (attrs.count("repeat") && trim(attrs["repeat"]) == "rest") node->repeat_rest = true;
    else if (attrs.count("repeat")) node->repeat = make_ref(attrs["repeat"], node->line, "repeat", false);
    if (attrs.count("count")) node->count = make_ref(attrs["count"], node->line, "count", true);
    if (attrs.count("if")) node->if_field = make_ref(attrs["if"], node->line, "if", false);
    if (attrs.count("in")) parse_in_list(attrs["in"], node->line, *node);
    if (node->if_field && !node->has_in) diags_.error(node->line, "'if' needs an 'in' list of values");
    if (node->has_in && !node->if_field) diags_.error(node->line, "'in' needs an 'if' field to test");
    if (attrs.count("ifhook")) {
        node->has_hook = true;
        parse_value_list(attrs["ifhook"], node->line, "ifhook", node->hook_list);
    }
    if (attrs.count("valid")) {
        node->has_valid = true;
        parse_value_list(attrs["valid"], node->line, "valid", node->valid_list);
    }
    parse_length(attrs.count("length") ? attrs["length"] : "", node->line, *node, el);
    if (attrs.count("value")) parse_value(attrs["value"], node->line, *node);
    if (attrs.count("covers")) node->covers = make_ref(attrs["covers"], node->line, "covers", false);
    parse_text_direction_handoff_attributes(attrs, node->line, *node);
    parse_layout_attributes(attrs, *node);

    for (xmlNode* c = el->children; c; c = c->next) {
        if (c->type == XML_ELEMENT_NODE && element_name(c) == "node")
            node->children.push_back(parse_node(c, node.get(), depth + 1));
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "enum")
            parse_enum(c, *node);
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "when")
            parse_when(c, *node, el);
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "finding")
            parse_finding(c, *node);
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "learn")
            parse_learn(c, *node);
        else
            unexpected_child(c, "node", {"node", "enum", "when", "finding", "learn", "use"});
    }
    for (When& w : node->whens) defer(w.ref, el, w.line, w.peek ? "peek" : "field");
    if (node->base) defer(*node->base, el, node->line, "base");
    if (node->offsets) defer(*node->offsets, el, node->line, "offsets");
    if (node->from) defer(*node->from, el, node->line, "from");
    if (node->overlay) defer(*node->overlay, el, node->line, "overlay");
    if (node->covers) defer(*node->covers, el, node->line, "covers");
    if (node->repeat) defer(*node->repeat, el, node->line, "repeat");
    if (node->count) defer(*node->count, el, node->line, "count");
    if (node->if_field) defer(*node->if_field, el, node->line, "if");
    if (node->length_kind == LengthKind::Field) defer(node->length_ref, el, node->line, "length");
    defer_reassembly_refs(*node, el);
    return node;
}

void Parser::parse_enum(xmlNode* el, Node& node) {
    EnumItem item;
    item.line = line_of(el);
    auto attrs = attributes(el, kEnumAttributes);
    if (!attrs.count("value") || !attrs.count("name")) {
        diags_.error(item.line, "enum items are written <enum value=\"0x0a\" name=\"LRD 读数据\"/>");
        return;
    }
    if (!parse_number(attrs["value"], item.value) && !parse_enum_range(attrs["value"], item)) {
        diags_.error(item.line, "bad enum value '" + attrs["value"] +
                                    "': expected hex (0x0a) or decimal, or a range such as 0x11-0x1f");
        return;
    }
    if (!item.is_range) item.high = item.value;  // a single value is the range [value, value]
    item.name = attrs["name"];
    for (xmlNode* c = el->children; c; c = c->next) unexpected_child(c, "enum", {});
    node.enums.push_back(item);
}

// <when field="XPATH" in="LIST"/> or <when peek="XPATH" in="LIST"/>.
// The XPath is evaluated from the node, as 'if' is.
void Parser::parse_when(xmlNode* el, Node& node, xmlNode*) {
    When w;
    w.line = line_of(el);
    auto attrs = attributes(el, kWhenAttributes);
    for (xmlNode* c = el->children; c; c = c->next) unexpected_child(c, "when", {});
    bool field = attrs.count("field") > 0, peek = attrs.count("peek") > 0;
    if (field == peek) {
        diags_.error(w.line, field ? "<when> has both 'field' and 'peek'; use one of them"
                                   : "<when> needs a 'field' (an earlier field) or a 'peek' (a later one) attribute");
        return;
    }
    if (!attrs.count("in")) {
        diags_.error(w.line, "<when> needs an 'in' list of values");
        return;
    }
    w.peek = peek;
    w.ref = make_ref(attrs[peek ? "peek" : "field"], w.line, peek ? "peek" : "field", false);
    if (!parse_value_list(attrs["in"], w.line, "in", w.in_list)) return;
    node.whens.push_back(std::move(w));
}

// <finding name="..." severity="..." [group="..."] condition="EXPR" text="..."/>;
// the validator checks the words and the names the condition and text read.
void Parser::parse_finding(xmlNode* el, Node& node) {
    Finding f;
    f.line = line_of(el);
    auto attrs = attributes(el, kFindingAttributes);
    for (xmlNode* c = el->children; c; c = c->next) unexpected_child(c, "finding", {});
    for (const char* required : {"name", "severity", "condition", "text"})
        if (!attrs.count(required)) {
            diags_.error(f.line, std::string("<finding> needs a '") + required + "' attribute");
            return;
        }
    f.name = attrs["name"];
    f.severity = trim(attrs["severity"]);
    f.group = attrs.count("group") ? trim(attrs["group"]) : "protocol";
    f.condition_text = attrs["condition"];
    std::string error;
    if (!parse_expression(f.condition_text, f.condition, error)) {
        diags_.error(f.line, "bad condition of finding '" + f.name + "' '" + excerpt(f.condition_text) + "': " + error);
        return;
    }
    f.text = attrs["text"];
    node.findings.push_back(std::move(f));
}

// An expression in an attribute; false (reported) when it does not parse.
bool Parser::parse_expression_attribute(const std::string& text, int line, const std::string& what, Expr& out) {
    std::string error;
    if (parse_expression(text, out, error)) return true;
    diags_.error(line, "bad " + what + " '" + excerpt(text) + "': " + error);
    return false;
}

// <learn name="..." value="EXPR" [if="EXPR"] [sender="yes|no"] [conversation="yes|no"]> <key value="EXPR"
// [lookup="EXPR"]/>... </learn>; the validator resolves the names.
void Parser::parse_learn(xmlNode* el, Node& node) {
    Learn l;
    l.line = line_of(el);
    auto attrs = attributes(el, kLearnAttributes);
    for (const char* required : {"name", "value"})
        if (!attrs.count(required)) {
            diags_.error(l.line, std::string("<learn> needs a '") + required + "' attribute");
            return;
        }
    l.name = attrs["name"];
    const std::string what = "learn '" + l.name + "'";
    l.value_text = attrs["value"];
    bool ok = parse_expression_attribute(l.value_text, l.line, "value of " + what, l.value);
    if (attrs.count("if")) {
        l.condition_text = attrs["if"];
        l.condition.emplace();
        ok = parse_expression_attribute(l.condition_text, l.line, "if of " + what, *l.condition) && ok;
    }
    parse_yes_no(attrs, "sender", l.line, " of " + what, "the sender's address and port are a key too", l.sender);
    parse_yes_no(attrs, "conversation", l.line, " of " + what,
                 "both ends' addresses and ports are a key too, whichever sent the message", l.conversation);
    if (l.sender && l.conversation) {
        diags_.error(l.line, what + " has both sender=\"yes\" and conversation=\"yes\": a value is either each "
                                    "sender's (sender) or shared by both ends of a conversation (conversation)");
        ok = false;
    }
    for (xmlNode* c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE || element_name(c) != "key") {
            unexpected_child(c, "learn", {"key"});
            continue;
        }
        LearnKey k;
        k.line = line_of(c);
        auto key_attrs = attributes(c, kLearnKeyAttributes);
        for (xmlNode* g = c->children; g; g = g->next) unexpected_child(g, "key", {});
        if (!key_attrs.count("value")) {
            diags_.error(k.line, "<key> of " + what + " needs a 'value' attribute: the expression the key is");
            ok = false;
            continue;
        }
        k.value_text = key_attrs["value"];
        ok = parse_expression_attribute(k.value_text, k.line, "key of " + what, k.value) && ok;
        if (key_attrs.count("lookup")) {
            k.lookup_text = key_attrs["lookup"];
            k.lookup.emplace();
            ok = parse_expression_attribute(k.lookup_text, k.line, "lookup of " + what, *k.lookup) && ok;
        }
        if (key_attrs.count("span")) {
            k.span_text = key_attrs["span"];
            k.span.emplace();
            ok = parse_expression_attribute(k.span_text, k.line, "span of " + what, *k.span) && ok;
        }
        if (key_attrs.count("id")) {
            k.id_text = key_attrs["id"];
            k.id.emplace();
            ok = parse_expression_attribute(k.id_text, k.line, "id of " + what, *k.id) && ok;
        }
        l.keys.push_back(std::move(k));
    }
    if (ok) node.learns.push_back(std::move(l));
}

// Alternatives and register windows: otherwise="true", base="XPATH [op N]", at="ADDR", stride="N", instances="M".
void Parser::parse_layout_attributes(std::map<std::string, std::string>& attrs, Node& node) {
    if (attrs.count("otherwise")) {
        if (trim(attrs["otherwise"]) == "true")
            node.otherwise = true;
        else
            diags_.error(node.line, "bad otherwise '" + attrs["otherwise"] + "': the only value is 'true'");
    }
    if (attrs.count("malformed")) {
        const std::string v = trim(attrs["malformed"]);
        if (v == "skip")
            node.skip_malformed = true;
        else if (v != "stop")
            diags_.error(node.line, "bad malformed '" + attrs["malformed"] +
                                        "': 'stop' (the default: decoding of the message stops there) or 'skip' "
                                        "(the rest of this container is skipped, decoding goes on after it)");
    }
    if (attrs.count("base")) node.base = make_ref(attrs["base"], node.line, "base", true);
    if (attrs.count("offsets")) node.offsets = make_ref(attrs["offsets"], node.line, "offsets", false);
    if (attrs.count("from")) node.from = make_ref(attrs["from"], node.line, "from", false);
    if (attrs.count("overlay")) node.overlay = make_ref(attrs["overlay"], node.line, "overlay", false);
    auto number = [&](const char* name, uint64_t max, std::optional<uint64_t>& out) {
        if (!attrs.count(name)) return;
        uint64_t v = 0;
        if (!parse_number(attrs[name], v) || v > max) {
            diags_.error(node.line, "bad " + std::string(name) + " '" + attrs[name] +
                                        "': expected a number from " + (std::string(name) == "at" ? "0" : "1") +
                                        " to " + std::to_string(max) + ", hex (0x0600) or decimal");
            return;
        }
        if (v == 0 && std::string(name) != "at") {
            diags_.error(node.line, "bad " + std::string(name) + " '" + attrs[name] + "': it must be at least 1");
            return;
        }
        out = v;
    };
    number("at", 0xffffffffffffull, node.at);
    number("stride", 0xffffffffull, node.stride);
    number("instances", 65535, node.instances);
}

void Parser::parse_display(const std::string& text, int line, Node& node) {
    static const Display kValues[] = {Display::Address, Display::NumberHex, Display::NumberDec,
                                      Display::Bool,    Display::Origin,    Display::Enum,
                                      Display::NonDisplay,
                                      Display::String,  Display::StringZ,   Display::IPv4,
                                      Display::Int,     Display::Float,     Display::Time,
                                      Display::DateTime, Display::Guid,
                                      Display::IPv6,    Display::Mac,       Display::Eui64,
                                      Display::Oid,     Display::Varint};
    for (size_t i = 0; i < kDisplayNames.size(); ++i) {
        if (text == kDisplayNames[i]) {
            node.display = kValues[i];
            node.display_given = true;
            return;
        }
    }
    std::string msg = "unknown displaytype '" + text + "'";
    std::string near = text.empty() ? "" : remembered_suggestion(text, kDisplayNames);
    if (!near.empty()) msg += " (did you mean '" + near + "'?)";
    diags_.error(line, msg + "; valid: " + join(kDisplayNames, ", "));
}

void Parser::parse_length(const std::string& raw, int line, Node& node, xmlNode*) {
    std::string text = trim(raw);
    std::string digits, unit;
    if (text.empty()) {
        node.length_kind = LengthKind::Children;
    } else if (text == "rest") {
        node.length_kind = LengthKind::Rest;
    } else if (text.compare(0, 4, "rest") == 0) {
        parse_rest_minus(raw, text.substr(4), line, node);
    } else if (split_fixed_length(text, false, digits, unit)) {
        digits = significant_digits(digits);
        uint64_t n = digits.size() > 12 ? UINT64_MAX : std::stoull(digits);
        bool bytes = unit == "byte";
        if (n == 0 || n > (1u << 20)) {
            diags_.error(line, "bad length '" + raw + "': a fixed length must be from 1 to 1048576");
            return;
        }
        node.length_kind = bytes ? LengthKind::Bytes : LengthKind::Bits;
        node.fixed_bits = bytes ? n * 8 : n;
    } else if (text[0] == '-' && split_fixed_length(trim(text.substr(1)), true, digits, unit)) {
        diags_.error(line, "bad length '" + raw + "': a fixed length must be from 1 to 1048576");
    } else if (std::isdigit(static_cast<unsigned char>(text[0]))) {
        std::string msg = "bad length '" + raw + "': expected 'Nbyte', 'Nbit', an XPath, 'rest' or nothing";
        if (split_fixed_length(text, true, digits, unit)) msg += " (did you mean '" + digits + unit + "'?)";
        diags_.error(line, msg);
    } else {
        node.length_kind = LengthKind::Field;
        node.length_ref = make_ref(text, line, "length", true);
    }
}

// "rest - N": to the end but the last N bytes, which a trailer after the
// node takes (PROFINET's cycle counter and status bytes end the frame).
void Parser::parse_rest_minus(const std::string& raw, const std::string& tail, int line, Node& node) {
    std::string t = trim(tail);
    uint64_t n = 0;
    bool number = t.size() > 1 && t[0] == '-' && parse_number(trim(t.substr(1)), n);
    if (!number || n == 0 || n > (1u << 20)) {
        diags_.error(line, "bad length '" + raw + "': after 'rest' only '- N' may follow, N from 1 to 1048576 "
                           "(the bytes left to what follows the node)");
        return;
    }
    node.length_kind = LengthKind::Rest;
    node.rest_keep = static_cast<uint32_t>(n);
}

void Parser::parse_value(const std::string& text, int line, Node& node) {
    Expr expr;
    std::string error;
    if (!parse_expression(text, expr, error)) {
        diags_.error(line, "bad value expression '" + excerpt(text) + "': " + error);
        return;
    }
    node.value = std::move(expr);
    node.value_text = text;
}

void Parser::parse_in_list(const std::string& text, int line, Node& node) {
    node.has_in = true;
    parse_value_list(text, line, "in", node.in_list);
}

// Whether an item of a value list starts with a minus sign ("-1", "2, -5").
static bool has_negative_item(const std::string& text) {
    std::stringstream ss(text);
    for (std::string item; std::getline(ss, item, ',');)
        if (trim(item).rfind('-', 0) == 0) return true;
    return false;
}

// "1-9,0x0d,14": numbers and ranges, for 'in', 'ifhook' and 'valid'.
bool Parser::parse_value_list(const std::string& text, int line, const std::string& attribute,
                              std::vector<ValueRange>& out) {
    const std::string bad = "bad '" + attribute + "' list '" + text +
                            "': expected numbers and ranges such as \"1-9,0x0d,14\"" +
                            (has_negative_item(text)
                                 ? "; a negative value of an int field is written as its bits (-1 of 2 bytes: 0xffff)"
                                 : "");
    std::stringstream ss(text);
    std::string item;
    bool any = false;
    while (std::getline(ss, item, ',')) {
        item = trim(item);
        ValueRange r;
        size_t dash = item.find('-');
        bool ok = dash == std::string::npos
                      ? parse_number(item, r.low)
                      : parse_number(item.substr(0, dash), r.low) && parse_number(item.substr(dash + 1), r.high);
        if (dash == std::string::npos) r.high = r.low;
        r.text = item;
        if (!ok || r.high < r.low) {
            diags_.error(line, bad);
            return false;
        }
        out.push_back(r);
        any = true;
    }
    if (!any) {
        diags_.error(line, "empty '" + attribute + "' list; expected numbers and ranges such as \"1-9,0x0d,14\"");
        return false;
    }
    if (trim(text).back() == ',') {  // getline drops the empty last item
        diags_.error(line, bad);
        return false;
    }
    return true;
}

FieldRef Parser::make_ref(const std::string& text, int line, const std::string& attribute, bool arithmetic) {
    FieldRef ref;
    ref.xpath = trim(text);
    std::string path, number;
    char op = 0;
    if (arithmetic && split_arithmetic(ref.xpath, path, op, number)) {
        ref.op = op;
        ref.xpath = path;
        // Leading zeros do not make a number large ("* 0002" is 2).
        const std::string digits = significant_digits(number);
        if (digits.size() > 9) {
            diags_.error(line, "number " + number + " after '" + ref.op + "' in '" + attribute +
                                   "' is too large: at most 999999999");
            return ref;
        }
        ref.operand = std::stoll(digits);
    }
    if (ref.xpath.empty()) diags_.error(line, "empty XPath in '" + attribute + "'");
    return ref;
}

void Parser::defer(FieldRef& ref, xmlNode* context, int line, const std::string& attribute) {
    if (!ref.xpath.empty()) pending_.push_back({&ref, context, line, attribute});
}

// The attributes of typed values and hand-off: encoding, unit, direction,
// dissector and the reassemble-* fields.
void Parser::parse_text_direction_handoff_attributes(std::map<std::string, std::string>& attrs, int line, Node& node) {
    if (attrs.count("encoding")) {
        node.encoding = trim(attrs["encoding"]);
        node.encoding_given = true;
        if (node.encoding == "latin-1") node.encoding = "iso-8859-1"; // one name per encoding in the model
        if (node.encoding != "ascii" && node.encoding != "utf-8" && node.encoding != "iso-8859-1")
            diags_.error(line, "bad encoding '" + attrs["encoding"] +
                                   "': expected 'ascii', 'utf-8' or 'iso-8859-1' (also 'latin-1')");
    }
    if (attrs.count("unit")) {
        node.unit = trim(attrs["unit"]);
        node.unit_given = true;
    }
    if (attrs.count("direction")) {
        const std::string d = trim(attrs["direction"]);
        if (d == "request") node.direction = Direction::Request;
        else if (d == "response") node.direction = Direction::Response;
        else diags_.error(line, "bad direction '" + attrs["direction"] + "': expected 'request' or 'response'");
    }
    if (attrs.count("dissector")) {
        node.dissector = trim(attrs["dissector"]);
        bool ok = !node.dissector->empty();
        for (unsigned char c : *node.dissector)
            ok = ok && c > 0x20 && c < 0x7f && c != '"' && c != '\\';
        if (!ok)
            diags_.error(line, "bad dissector name '" + attrs["dissector"] +
                                   "': expected a Wireshark dissector name such as eth_withoutfcs");
    }
    struct { const char* attribute; std::optional<FieldRef>* ref; bool arithmetic; } refs[] = {
        {"reassemble-id", &node.reassemble_id, false},     {"reassemble-offset", &node.reassemble_offset, true},
        {"reassemble-seq", &node.reassemble_seq, false},   {"reassemble-last", &node.reassemble_last, false},
        {"reassemble-more", &node.reassemble_more, false},
    };
    for (auto& r : refs)
        if (attrs.count(r.attribute)) *r.ref = make_ref(attrs[r.attribute], line, r.attribute, r.arithmetic);
}

// Resolves the reassemble-* XPaths once the whole file is parsed, as the
// other field references are.
void Parser::defer_reassembly_refs(Node& node, xmlNode* el) {
    struct { const char* attribute; std::optional<FieldRef>* ref; } refs[] = {
        {"reassemble-id", &node.reassemble_id},     {"reassemble-offset", &node.reassemble_offset},
        {"reassemble-seq", &node.reassemble_seq},   {"reassemble-last", &node.reassemble_last},
        {"reassemble-more", &node.reassemble_more},
    };
    for (auto& r : refs)
        if (*r.ref) defer(**r.ref, el, node.line, r.attribute);
}

// "0x0011-0x001f" or "17-31": an enum item for a range of values.
bool Parser::parse_enum_range(const std::string& text, EnumItem& item) {
    size_t dash = text.find('-');
    if (dash == std::string::npos || dash == 0) return false;
    uint64_t low = 0, high = 0;
    if (!parse_number(text.substr(0, dash), low) || !parse_number(text.substr(dash + 1), high) || high < low)
        return false;
    item.value = low;
    item.high = high;
    item.is_range = true;
    return true;
}

void Parser::resolve_all() {
    for (const PendingRef& p : pending_) {
        p.ref->target = resolve(p);
        // One path past the limit is reported; evaluating the others could
        // cost as much each, and the file is refused already.
        if (xpath_limit_hit_) break;
    }
}

// X of each "@name='X'" (or "@name = \"X\"") of an XPath, in order.
// A plain scan: std::regex recurses per character on long values.
std::vector<std::string> names_in_xpath(const std::string& xpath) {
    std::vector<std::string> names;
    for (size_t at = xpath.find("@name"); at != std::string::npos; at = xpath.find("@name", at + 1)) {
        size_t i = xpath.find_first_not_of(" \t", at + 5);
        if (i == std::string::npos || xpath[i] != '=') continue;
        i = xpath.find_first_not_of(" \t", i + 1);
        if (i == std::string::npos || (xpath[i] != '\'' && xpath[i] != '"')) continue;
        size_t end = xpath.find(xpath[i], i + 1);
        if (end != std::string::npos) names.push_back(xpath.substr(i + 1, end - i - 1));
    }
    return names;
}

// The start of name_hint() for a name no node has.
const std::string kNoNodeNamed = "; no node is named '";

// Where an XPath that selected nothing was evaluated from, and, when it
// names a node (@name='X'), whether any node has that name: the two usual
// mistakes are a wrong step ('..' one level too few) and a misspelt name.
std::string Parser::nothing_selected_hint(const PendingRef& p) {
    std::string from = "<" + element_name(p.context) + ">";
    if (auto it = by_xml_.find(p.context); it != by_xml_.end()) from = "node '" + it->second->name + "'";
    std::string hint = " (evaluated from " + from + " on line " + std::to_string(line_of(p.context)) + ")";
    const std::vector<std::string> names = names_in_xpath(p.ref->xpath);
    if (names.empty()) return hint;
    // The first name no node has (misspelt), else where the path's first name is.
    const std::string* first_hint = nullptr;
    for (const std::string& wanted : names) {
        auto [known, added] = name_hints_.try_emplace(wanted);
        if (added) known->second = name_hint(wanted);
        if (!first_hint) first_hint = &known->second;
        if (known->second.rfind(kNoNodeNamed, 0) == 0) return hint + known->second;
    }
    return hint + *first_hint;
}

// Whether a node is named `wanted`, and where first, or the name most like it.
std::string Parser::name_hint(const std::string& wanted) const {
    std::map<std::string, int> first_line;  // each name, in order, with its first line
    for (const auto& [xml, node] : by_xml_) {
        auto [at, added] = first_line.emplace(node->name, node->line);
        if (!added) at->second = std::min(at->second, node->line);
    }
    if (auto named = first_line.find(wanted); named != first_line.end())
        return "; node '" + wanted + "' is on line " + std::to_string(named->second) + ": check the path's steps from there";
    std::vector<std::string> names;
    for (const auto& [name, line] : first_line) names.push_back(name);
    std::string near = closest_match(wanted, names);
    return kNoNodeNamed + wanted + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)");
}

Node* Parser::resolve(const PendingRef& p) {
    const std::string where = "XPath '" + excerpt(p.ref->xpath, 120) + "' in '" + p.attribute + "'" +
                              group_use_context(uses_, p.context);
    xmlXPathContextPtr ctx = xmlXPathNewContext(doc_);
    ctx->node = p.context;
    ctx->error = ignore_xml_error;
    Node* result = nullptr;
    xmlSetStructuredErrorFunc(nullptr, ignore_xml_error);
    xmlXPathCompExprPtr comp = xmlXPathCtxtCompile(ctx, BAD_CAST p.ref->xpath.c_str());
    // A path's cost can grow exponentially with its nesting ("//node[//node[...]]"),
    // and many costly paths add up: libxml2 stops an evaluation after its
    // share of the file's budget, far more than real references take.
    ctx->opLimit = std::min(kXPathStepLimit, xpath_steps_left_);
    xmlXPathObjectPtr obj = comp ? xmlXPathCompiledEval(comp, ctx) : nullptr;
    xmlSetStructuredErrorFunc(nullptr, nullptr);
    xpath_steps_left_ -= std::min(xpath_steps_left_, ctx->opCount);
    if (comp && !obj && ctx->opCount >= ctx->opLimit) {
        xpath_limit_hit_ = true;
        diags_.error(p.line, where + (ctx->opLimit < kXPathStepLimit
                                          ? " is where the file's XPaths take too long to evaluate (over " +
                                                std::to_string(kXPathFileStepLimit) + " steps in all)"
                                          : " takes too long to evaluate (over " + std::to_string(kXPathStepLimit) +
                                                " steps)") +
                                 "; select the node by a simpler path, such as ../node[@name='X']");
    } else if (!comp || !obj) {
        diags_.error(p.line, "invalid " + where +
                                 (p.attribute == "length"
                                      ? "; a length is 'Nbyte', 'Nbit', an XPath, 'rest' or nothing"
                                      : ""));
    } else if (obj->type != XPATH_NODESET) {
        // "X * 2 + 1": the last '+ 1' was split off, the rest is arithmetic XPath evaluates
        const bool arithmetic = obj->type == XPATH_NUMBER && p.ref->op;
        diags_.error(p.line, where + " gives a value, not a node; it must select one <node>" +
                                 (arithmetic ? " (one '+', '-' or '*' and a whole number may follow the path; for "
                                               "more, compute it in a computed value, <node name=\"Size\" "
                                               "value=\"{N} * 2 + 1\"/>, and select that)"
                                             : ""));
    } else {
        int count = obj->nodesetval ? obj->nodesetval->nodeNr : 0;
        if (count == 0) {
            diags_.error(p.line, where + " selects no node" + nothing_selected_hint(p));
        } else if (count > 1) {
            diags_.error(p.line, where + " selects " + std::to_string(count) +
                                     " nodes; it must select exactly one");
        } else {
            xmlNode* target = obj->nodesetval->nodeTab[0];
            auto found = by_xml_.find(target);
            if (found != by_xml_.end()) {
                result = found->second;
            } else if (target->type == XML_ELEMENT_NODE) {
                diags_.error(p.line, where + " selects <" + element_name(target) + "> on line " +
                                         std::to_string(line_of(target)) + ", not a <node>");
            } else {
                diags_.error(p.line, where + " selects something that is not a <node> element");
            }
        }
    }
    xmlXPathFreeObject(obj);
    xmlXPathFreeCompExpr(comp);
    xmlXPathFreeContext(ctx);
    return result;
}

}  // namespace

bool parse_number(const std::string& raw, uint64_t& value) {
    std::string text = trim(raw);
    if (text.empty()) return false;
    bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
    std::string digits = hex ? text.substr(2) : text;
    if (digits.empty()) return false;
    digits = significant_digits(digits);
    if (digits.size() > (hex ? 16u : 20u)) return false;
    for (char c : digits)
        if (!(hex ? std::isxdigit(static_cast<unsigned char>(c)) : std::isdigit(static_cast<unsigned char>(c))))
            return false;
    errno = 0;
    value = std::strtoull(digits.c_str(), nullptr, hex ? 16 : 10);
    return errno == 0;
}

std::unique_ptr<Protocol> parse_rules(const std::string& text, Diagnostics& diags) {
    if (text.size() > kMaxRuleFileBytes) {
        diags.error(0, "rule file is larger than " + std::to_string(kMaxRuleFileBytes >> 20) + " MiB");
        return nullptr;
    }
    // A DTD is the door to entity expansion ("billion laughs") and external
    // entities; rule files never need one.
    for (const char* needle : {"<!DOCTYPE", "<!ENTITY"}) {
        if (int line = line_of_text(text, needle)) {
            diags.error(line, "DTDs and entity declarations are not allowed in rule files");
            return nullptr;
        }
    }

    XmlErrorSink sink;
    xmlSetStructuredErrorFunc(&sink, collect_xml_error);
    xmlParserCtxtPtr ctxt = xmlNewParserCtxt();
    xmlDoc* doc = ctxt ? xmlCtxtReadMemory(ctxt, text.data(), static_cast<int>(text.size()), "rules.xml",
                                           nullptr, XML_PARSE_NONET | XML_PARSE_BIG_LINES)
                       : nullptr;
    xmlSetStructuredErrorFunc(nullptr, nullptr);
    xmlFreeParserCtxt(ctxt);

    if (!doc || sink.seen) {
        // The paper writes enum items as attributes named by their value
        // (<enum 0x0a="LRD"/>), which no XML parser accepts: point at the
        // element and show the form this language uses instead.
        size_t paper_enum = find_paper_enum(text);
        if (paper_enum != std::string::npos) {
            int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + paper_enum, '\n'));
            diags.error(line, "XML is not well-formed: an attribute name cannot start with a digit; "
                              "enum items are written <enum value=\"0x0a\" name=\"LRD 读数据\"/>, one element per item");
        } else {
            diags.error(xml_error_line(sink.line, sink.message, text),
                        "XML is not well-formed: " + (sink.seen ? sink.message : "cannot parse"));
        }
        xmlFreeDoc(doc);
        return nullptr;
    }

    use_start_lines(doc, text);
    xmlNode* root = xmlDocGetRootElement(doc);
    std::unique_ptr<Protocol> proto;
    if (!root || element_name(root) != "root") {
        diags.error(root ? line_of(root) : 0,
                    "unknown element <" + (root ? element_name(root) : "") +
                        "> as the document element; the document element must be <root>");
    } else if (GroupUses uses; expand_node_groups(root, diags, uses)) {
        proto = Parser(doc, diags, uses).parse_root(root);
    }
    xmlFreeDoc(doc);
    return proto;
}

std::unique_ptr<Protocol> parse_rule_file(const std::string& path, Diagnostics& diags) {
    std::string text, why;
    if (!read_whole_file(path, text, why, kMaxRuleFileBytes)) {
        diags.error(0, "cannot read the rule file: " + why);
        return nullptr;
    }
    return parse_rules(text, diags);
}

}  // namespace dissgen

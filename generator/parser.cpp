#include "parser.h"

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xpath.h>
#include <libxml/xpathInternals.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "text_util.h"

namespace dissgen {

namespace {

const std::vector<std::string> kRootAttributes = {"name",   "abbreviation", "ethertype", "filter",
                                                  "byteorder", "pdulength", "pdulengthadd"};
const std::vector<std::string> kNodeAttributes = {"name",   "length",    "displaytype", "repeat",
                                                  "count",  "filter",    "byteorder",   "description",
                                                  "if",     "in",        "summary"};
const std::vector<std::string> kEnumAttributes = {"value", "name"};
const std::vector<std::string> kHookAttributes = {"table", "value"};
const std::vector<std::string> kDisplayNames = {"address", "numberhex", "numberdec", "bool",
                                                "origin",  "enum",      "nondisplay"};

int line_of(const xmlNode* el) { return static_cast<int>(xmlGetLineNo(el)); }

std::string element_name(const xmlNode* el) { return reinterpret_cast<const char*>(el->name); }

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
    sink->message = error->message ? trim(error->message) : "unknown XML error";
}

void ignore_xml_error(void*, xmlErrorPtr) {}

// Finds the line of `needle` in text, 0 if absent.
int line_of_text(const std::string& text, const std::string& needle) {
    size_t at = text.find(needle);
    if (at == std::string::npos) return 0;
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

class Parser {
public:
    Parser(xmlDoc* doc, Diagnostics& diags) : doc_(doc), diags_(diags) {}

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
    void parse_length(const std::string& text, int line, Node& node, xmlNode* el);
    void parse_display(const std::string& text, int line, Node& node);
    void parse_in_list(const std::string& text, int line, Node& node);
    bool parse_byteorder(const std::string& text, int line, ByteOrder& out);
    FieldRef make_ref(const std::string& text, int line, const std::string& attribute, bool arithmetic);
    void defer(FieldRef& ref, xmlNode* context, int line, const std::string& attribute);
    void unexpected_child(xmlNode* child, const std::string& parent, const std::vector<std::string>& allowed);
    void resolve_all();
    Node* resolve(const PendingRef& p);

    xmlDoc* doc_;
    Diagnostics& diags_;
    std::map<const xmlNode*, Node*> by_xml_;
    std::vector<PendingRef> pending_;
    int next_doc_index_ = 1;
};

std::map<std::string, std::string> Parser::attributes(xmlNode* el,
                                                      const std::vector<std::string>& allowed) {
    std::map<std::string, std::string> out;
    for (xmlAttr* a = el->properties; a; a = a->next) {
        std::string name = reinterpret_cast<const char*>(a->name);
        if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
            std::string msg = "unknown attribute '" + name + "' on <" + element_name(el) + ">";
            std::string near = closest_match(name, allowed);
            msg += near.empty() ? "; valid: " + join(allowed, ", ") : "; did you mean '" + near + "'?";
            diags_.error(line_of(el), msg);
            continue;
        }
        xmlChar* value = xmlNodeListGetString(doc_, a->children, 1);
        out[name] = value ? reinterpret_cast<const char*>(value) : "";
        xmlFree(value);
    }
    return out;
}

void Parser::unexpected_child(xmlNode* child, const std::string& parent,
                              const std::vector<std::string>& allowed) {
    if (child->type == XML_TEXT_NODE || child->type == XML_CDATA_SECTION_NODE) {
        xmlChar* content = xmlNodeGetContent(child);
        std::string text = content ? trim(reinterpret_cast<const char*>(content)) : "";
        xmlFree(content);
        if (!text.empty())
            diags_.error(line_of(child), "unexpected text '" + text.substr(0, 40) + "' in <" + parent + ">");
        return;
    }
    if (child->type != XML_ELEMENT_NODE) return;  // comments, processing instructions
    std::string name = element_name(child);
    std::string msg = "unknown element <" + name + "> in <" + parent + ">";
    std::string near = closest_match(name, allowed);
    if (allowed.empty())
        msg += "; <" + parent + "> has no child elements";
    else if (!near.empty())
        msg += "; did you mean <" + near + ">?";
    else
        msg += "; expected <" + join(allowed, "> or <") + ">";
    diags_.error(line_of(child), msg);
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

    for (xmlNode* c = root->children; c; c = c->next) {
        if (c->type == XML_ELEMENT_NODE && element_name(c) == "node")
            proto->nodes.push_back(parse_node(c, nullptr, 1));
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "hook")
            parse_hook(c, *proto);
        else
            unexpected_child(c, "root", {"node", "hook"});
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

std::unique_ptr<Node> Parser::parse_node(xmlNode* el, Node* parent, int depth) {
    auto node = std::make_unique<Node>();
    node->line = line_of(el);
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
    if (attrs.count("repeat")) node->repeat = make_ref(attrs["repeat"], node->line, "repeat", false);
    if (attrs.count("count")) node->count = make_ref(attrs["count"], node->line, "count", true);
    if (attrs.count("if")) node->if_field = make_ref(attrs["if"], node->line, "if", false);
    if (attrs.count("in")) parse_in_list(attrs["in"], node->line, *node);
    if (node->if_field && !node->has_in) diags_.error(node->line, "'if' needs an 'in' list of values");
    if (node->has_in && !node->if_field) diags_.error(node->line, "'in' needs an 'if' field to test");
    parse_length(attrs.count("length") ? attrs["length"] : "", node->line, *node, el);

    for (xmlNode* c = el->children; c; c = c->next) {
        if (c->type == XML_ELEMENT_NODE && element_name(c) == "node")
            node->children.push_back(parse_node(c, node.get(), depth + 1));
        else if (c->type == XML_ELEMENT_NODE && element_name(c) == "enum")
            parse_enum(c, *node);
        else
            unexpected_child(c, "node", {"node", "enum"});
    }
    if (node->repeat) defer(*node->repeat, el, node->line, "repeat");
    if (node->count) defer(*node->count, el, node->line, "count");
    if (node->if_field) defer(*node->if_field, el, node->line, "if");
    if (node->length_kind == LengthKind::Field) defer(node->length_ref, el, node->line, "length");
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
    if (!parse_number(attrs["value"], item.value)) {
        diags_.error(item.line, "bad enum value '" + attrs["value"] + "': expected hex (0x0a) or decimal");
        return;
    }
    item.name = attrs["name"];
    for (xmlNode* c = el->children; c; c = c->next) unexpected_child(c, "enum", {});
    node.enums.push_back(item);
}

void Parser::parse_display(const std::string& text, int line, Node& node) {
    static const Display kValues[] = {Display::Address, Display::NumberHex, Display::NumberDec,
                                      Display::Bool,    Display::Origin,    Display::Enum,
                                      Display::NonDisplay};
    for (size_t i = 0; i < kDisplayNames.size(); ++i) {
        if (text == kDisplayNames[i]) {
            node.display = kValues[i];
            node.display_given = true;
            return;
        }
    }
    std::string msg = "unknown displaytype '" + text + "'";
    std::string near = closest_match(text, kDisplayNames);
    if (!near.empty()) msg += " (did you mean '" + near + "'?)";
    diags_.error(line, msg + "; valid: " + join(kDisplayNames, ", "));
}

void Parser::parse_length(const std::string& raw, int line, Node& node, xmlNode*) {
    std::string text = trim(raw);
    static const std::regex fixed(R"(^([0-9]+)(byte|bit)$)");
    std::smatch m;
    if (text.empty()) {
        node.length_kind = LengthKind::Children;
    } else if (text == "rest") {
        node.length_kind = LengthKind::Rest;
    } else if (std::regex_match(text, m, fixed)) {
        uint64_t n = std::stoull(m[1].str().substr(0, 12));
        bool bytes = m[2] == "byte";
        if (n == 0 || n > (1u << 20)) {
            diags_.error(line, "bad length '" + raw + "': a fixed length must be from 1 to 1048576");
            return;
        }
        node.length_kind = bytes ? LengthKind::Bytes : LengthKind::Bits;
        node.fixed_bits = bytes ? n * 8 : n;
    } else if (std::isdigit(static_cast<unsigned char>(text[0]))) {
        static const std::regex loose(R"(^([0-9]+)\s*(byte|bit)s?$)", std::regex::icase);
        std::string msg = "bad length '" + raw + "': expected 'Nbyte', 'Nbit', an XPath, 'rest' or nothing";
        if (std::regex_match(text, m, loose)) {
            std::string unit = m[2].str();
            std::transform(unit.begin(), unit.end(), unit.begin(), ::tolower);
            msg += " (did you mean '" + m[1].str() + unit + "'?)";
        }
        diags_.error(line, msg);
    } else {
        node.length_kind = LengthKind::Field;
        node.length_ref = make_ref(text, line, "length", true);
    }
}

void Parser::parse_in_list(const std::string& text, int line, Node& node) {
    node.has_in = true;
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
        if (!ok || r.high < r.low) {
            diags_.error(line, "bad 'in' list '" + text + "': expected numbers and ranges such as \"1-9,0x0d,14\"");
            return;
        }
        node.in_list.push_back(r);
        any = true;
    }
    if (!any) diags_.error(line, "empty 'in' list; expected numbers and ranges such as \"1-9,0x0d,14\"");
}

FieldRef Parser::make_ref(const std::string& text, int line, const std::string& attribute, bool arithmetic) {
    FieldRef ref;
    ref.xpath = trim(text);
    static const std::regex tail(R"(^(.*[^-+*\s])\s*([-+*])\s*([0-9]+)$)");
    std::smatch m;
    if (arithmetic && std::regex_match(ref.xpath, m, tail)) {
        ref.op = m[2].str()[0];
        ref.operand = std::stoll(m[3].str().substr(0, 9));
        ref.xpath = m[1].str();
    }
    if (ref.xpath.empty()) diags_.error(line, "empty XPath in '" + attribute + "'");
    return ref;
}

void Parser::defer(FieldRef& ref, xmlNode* context, int line, const std::string& attribute) {
    if (!ref.xpath.empty()) pending_.push_back({&ref, context, line, attribute});
}

void Parser::resolve_all() {
    for (const PendingRef& p : pending_) p.ref->target = resolve(p);
}

Node* Parser::resolve(const PendingRef& p) {
    const std::string where = "XPath '" + p.ref->xpath + "' in '" + p.attribute + "'";
    xmlXPathContextPtr ctx = xmlXPathNewContext(doc_);
    ctx->node = p.context;
    ctx->error = ignore_xml_error;
    Node* result = nullptr;
    xmlSetStructuredErrorFunc(nullptr, ignore_xml_error);
    xmlXPathCompExprPtr comp = xmlXPathCtxtCompile(ctx, BAD_CAST p.ref->xpath.c_str());
    xmlXPathObjectPtr obj = comp ? xmlXPathCompiledEval(comp, ctx) : nullptr;
    xmlSetStructuredErrorFunc(nullptr, nullptr);
    if (!comp || !obj) {
        diags_.error(p.line, "invalid " + where);
    } else if (obj->type != XPATH_NODESET) {
        diags_.error(p.line, where + " gives a value, not a node; it must select one <node>");
    } else {
        int count = obj->nodesetval ? obj->nodesetval->nodeNr : 0;
        if (count == 0) {
            diags_.error(p.line, where + " selects no node");
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
    const std::string digits = hex ? text.substr(2) : text;
    if (digits.empty() || digits.size() > (hex ? 16u : 20u)) return false;
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
        static const std::regex paper_enum(R"(<enum\s[^>]*?\s[0-9][0-9A-Za-z]*\s*=)");
        std::smatch m;
        if (std::regex_search(text, m, paper_enum)) {
            int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + m.position(0), '\n'));
            diags.error(line, "XML is not well-formed: an attribute name cannot start with a digit; "
                              "enum items are written <enum value=\"0x0a\" name=\"LRD 读数据\"/>, one element per item");
        } else {
            diags.error(sink.line, "XML is not well-formed: " + (sink.seen ? sink.message : "cannot parse"));
        }
        xmlFreeDoc(doc);
        return nullptr;
    }

    xmlNode* root = xmlDocGetRootElement(doc);
    std::unique_ptr<Protocol> proto;
    if (!root || element_name(root) != "root") {
        diags.error(root ? line_of(root) : 0,
                    "the document element must be <root>, not <" + (root ? element_name(root) : "") + ">");
    } else {
        proto = Parser(doc, diags).parse_root(root);
    }
    xmlFreeDoc(doc);
    return proto;
}

std::unique_ptr<Protocol> parse_rule_file(const std::string& path, Diagnostics& diags) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        diags.error(0, "cannot read the rule file");
        return nullptr;
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    return parse_rules(ss.str(), diags);
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "node_groups.h"

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "parser.h"
#include "text_util.h"
#include "xml_input.h"

namespace dissgen {

namespace {

bool is_element(const xmlNode* n, const char* name) {
    return n->type == XML_ELEMENT_NODE && xmlStrEqual(n->name, BAD_CAST name);
}

struct Group {
    std::string name;
    xmlNode* element;
    int depth = 1;        // levels of itself it may be nested in, itself included
    bool depth_given = false;
    bool used = false;
};

// The copy's lines are the group's: libxml2 copies an element's line but
// not a text's, nor what use_start_lines keeps in psvi for lines above 65534.
void copy_lines(const xmlNode* from, xmlNode* to) {
    for (; from && to; from = from->next, to = to->next) {
        to->line = from->line;
        if (from->type == XML_ELEMENT_NODE) {
            to->psvi = from->psvi;
            copy_lines(from->children, to->children);
        }
    }
}

// What a copy of a list of siblings adds: its elements, and the bytes of
// their attribute values and text.
struct Weight {
    size_t elements = 0;
    size_t text_bytes = 0;
};

void weigh(const xmlNode* n, Weight& w) {
    for (; n; n = n->next) {
        if (n->content) w.text_bytes += static_cast<size_t>(xmlStrlen(n->content));
        if (n->type != XML_ELEMENT_NODE) continue;
        w.elements += 1;
        for (const xmlAttr* a = n->properties; a; a = a->next)
            for (const xmlNode* v = a->children; v; v = v->next)
                if (v->content) w.text_bytes += static_cast<size_t>(xmlStrlen(v->content));
        weigh(n->children, w);
    }
}

class Expander {
public:
    Expander(Diagnostics& diags, GroupUses& uses) : diags_(diags), uses_(uses) {}

    bool run(xmlNode* root) {
        collect_groups(root);
        misplaced_groups(root->children);
        expand_children(root);
        for (Group& g : groups_) {
            if (!g.used && !failed_)
                diags_.warning(xml_line(g.element), "group '" + g.name + "' is never used (a <use group=\"" +
                                                        g.name + "\"/> puts its nodes in place)");
            xmlUnlinkNode(g.element);
            xmlFreeNode(g.element);
        }
        return !failed_;
    }

private:
    void error(const xmlNode* at, const std::string& message) {
        diags_.error(xml_line(at), message);
        failed_ = true;
    }

    bool check_attributes(const xmlNode* el, const std::vector<std::string>& allowed) {
        bool ok = true;
        for (const xmlAttr* a = el->properties; a; a = a->next) {
            const std::string name = reinterpret_cast<const char*>(a->name);
            if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
            error(el, unknown_attribute(name, xml_name(el), closest_match(name, allowed), allowed));
            ok = false;
        }
        return ok;
    }

    void collect_groups(xmlNode* root) {
        for (xmlNode* c = root->children; c; c = c->next) {
            if (!is_element(c, "group")) continue;
            check_attributes(c, {"name", "depth"});
            Group g;
            g.element = c;
            g.name = trim(xml_attr(c, "name").value_or(""));
            if (g.name.empty()) {
                error(c, "<group> needs a 'name' attribute: what <use group=\"...\"/> calls it");
                continue;
            }
            if (const Group* before = find(g.name)) {
                error(c, "group '" + g.name + "' is already defined at line " +
                             std::to_string(xml_line(before->element)));
                continue;
            }
            if (auto depth = xml_attr(c, "depth")) {
                const std::string t = trim(*depth);
                const bool digits = !t.empty() && t.size() <= 2 &&
                                    std::all_of(t.begin(), t.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
                const int n = digits ? std::stoi(t) : 0;
                if (n < 1 || n > kMaxGroupDepth) {
                    error(c, "bad depth '" + *depth + "' on group '" + g.name + "': expected how many levels of "
                             "itself it may be nested in, from 1 to " + std::to_string(kMaxGroupDepth));
                    continue;
                }
                g.depth = n;
                g.depth_given = true;
            }
            if (xml_children(c, "node").empty() && xml_children(c, "use").empty()) {
                error(c, "group '" + g.name + "' holds no <node>: a group is the nodes its uses stand for");
                continue;
            }
            index_[g.name] = groups_.size();
            groups_.push_back(g);
        }
    }

    // A <group> anywhere but directly in <root> is a mistake the parser
    // would only call an unknown element.
    void misplaced_groups(xmlNode* n) {
        for (; n; n = n->next) {
            if (n->type != XML_ELEMENT_NODE) continue;
            if (is_element(n, "group") && !is_element(n->parent, "root"))
                error(n, "<group> belongs directly in <root>: it defines nodes for <use group=\"...\"/>, it is "
                         "not a place in the message");
            misplaced_groups(n->children);
        }
    }

    Group* find(const std::string& name) {
        auto it = index_.find(name);
        return it == index_.end() ? nullptr : &groups_[it->second];
    }

    // Where a use may stand: where a <node> may.
    static bool holds_nodes(const xmlNode* parent) {
        return is_element(parent, "root") || is_element(parent, "node") || is_element(parent, "group");
    }

    void expand_children(xmlNode* parent) {
        xmlNode* c = parent->children;
        while (c && !failed_) {
            xmlNode* next = c->next;
            if (is_element(c, "group") && is_element(parent, "root")) {
                // a definition: expanded where it is used
            } else if (is_element(c, "use") && holds_nodes(parent)) {
                replace_use(c);
            } else if (c->type == XML_ELEMENT_NODE) {
                expand_children(c);
            }
            c = next;
        }
    }

    // The chain of groups from the outermost to `g`, for a message.
    std::string chain_to(const Group& g) const {
        std::vector<std::string> names;
        for (const Group* s : stack_) names.push_back(s->name);
        names.push_back(g.name);
        return join(names, " -> ");
    }

    // Nested deeper than its group's depth: the rest of the container is
    // shown as bytes, one leaf named after the group, filter name "deeper"
    // ("deeper_2", ... for the stand-ins after it in the same container).
    void stand_in_for_deeper(xmlNode* use, const Group& g) {
        int before = 0;
        for (const xmlNode* s = use->prev; s; s = s->prev) before += stand_ins_.count(s) != 0;
        const std::string suffix = before ? "_" + std::to_string(before + 1) : "";
        xmlNode* leaf = xmlNewDocNode(use->doc, nullptr, BAD_CAST "node", nullptr);
        const std::string name = g.name + " (nested deeper than " + std::to_string(g.depth) + " levels)" +
                                 (before ? " " + std::to_string(before + 1) : "");
        xmlNewProp(leaf, BAD_CAST "name", BAD_CAST name.c_str());
        xmlNewProp(leaf, BAD_CAST "filter", BAD_CAST("deeper" + suffix).c_str());
        xmlNewProp(leaf, BAD_CAST "length", BAD_CAST "rest");
        xmlNewProp(leaf, BAD_CAST "displaytype", BAD_CAST "origin");
        leaf->line = use->line;
        leaf->psvi = use->psvi;
        xmlReplaceNode(use, leaf);
        xmlFreeNode(use);
        stand_ins_.insert(leaf);
    }

    void replace_use(xmlNode* use) {
        if (!check_attributes(use, {"group"})) return;
        for (const xmlNode* k = use->children; k; k = k->next)
            if (k->type == XML_ELEMENT_NODE) return error(use, "<use> holds nothing: it stands for its group's nodes");
        const std::string name = trim(xml_attr(use, "group").value_or(""));
        if (name.empty()) return error(use, "<use> needs a 'group' attribute: the name of a <group> in <root>");
        Group* g = find(name);
        if (!g) {
            std::vector<std::string> names;
            for (const Group& x : groups_) names.push_back(x.name);
            const std::string near = closest_match(name, names);
            return error(use, "no group named '" + name + "'" +
                                  (near.empty() ? names.empty() ? std::string(" (this file defines none)")
                                                                : "; groups: " + join(names, ", ")
                                                : " (did you mean '" + near + "'?)"));
        }
        g->used = true;
        if (stack_.size() >= static_cast<size_t>(kMaxNesting))
            return error(use, "uses of groups nested deeper than " + std::to_string(kMaxNesting) +
                                  " levels (a use inside group '" + stack_.back()->name + "', itself used inside "
                                  "group '" + stack_.front()->name + "' ...): nodes cannot nest that deep");
        const int nested = static_cast<int>(std::count(stack_.begin(), stack_.end(), g));
        if (nested >= g->depth) {
            if (!g->depth_given)
                return error(use, "group '" + g->name + "' is used inside itself (" + chain_to(*g) +
                                      "): say how many levels of itself it may be nested in with depth=\"N\" "
                                      "on its <group> (line " + std::to_string(xml_line(g->element)) + ")");
            return stand_in_for_deeper(use, *g);
        }
        weigh(g->element->children, added_);
        if (added_.elements > kMaxGroupElements)
            return error(use, "the uses of groups add more than " + std::to_string(kMaxGroupElements) +
                                  " elements to the file (" + chain_to(*g) + "): nest fewer levels");
        if (added_.text_bytes > kMaxGroupTextBytes)
            return error(use, "the uses of groups add more than " + std::to_string(kMaxGroupTextBytes >> 20) +
                                  " MiB of attribute values, text and comments to the file (" + chain_to(*g) +
                                  "): use a group with long values fewer times");
        xmlNode* copy = xmlDocCopyNodeList(use->doc, g->element->children);
        copy_lines(g->element->children, copy);
        // Expand the copy's own uses while it hangs under the group's name,
        // then put its nodes where the use was.
        xmlNode* holder = xmlNewDocNode(use->doc, nullptr, BAD_CAST "group", nullptr);
        xmlAddChildList(holder, copy);
        stack_.push_back(g);
        expand_children(holder);
        stack_.pop_back();
        const GroupUse here{g->name, xml_line(use)};
        while (xmlNode* n = holder->children) {
            xmlUnlinkNode(n);
            if (n->type == XML_ELEMENT_NODE) uses_[n] = here;
            xmlAddPrevSibling(use, n);
        }
        xmlFreeNode(holder);
        xmlUnlinkNode(use);
        xmlFreeNode(use);
    }

    Diagnostics& diags_;
    GroupUses& uses_;
    std::vector<Group> groups_;
    std::map<std::string, size_t> index_;  // name -> groups_
    std::set<const xmlNode*> stand_ins_;
    std::vector<const Group*> stack_;
    Weight added_;
    bool failed_ = false;
};

}  // namespace

bool expand_node_groups(xmlNode* root, Diagnostics& diags, GroupUses& uses) {
    return Expander(diags, uses).run(root);
}

std::string group_uses_of(const GroupUses& uses, const xmlNode* el) {
    std::string out;
    for (; el; el = el->parent) {
        auto it = uses.find(el);
        if (it == uses.end()) continue;
        out += (out.empty() ? "in group '" : ", in group '") + it->second.group + "' used on line " +
               std::to_string(it->second.line);
    }
    return out;
}

std::string group_use_context(const GroupUses& uses, const xmlNode* el) {
    const std::string in = group_uses_of(uses, el);
    return in.empty() ? in : " (" + in + ")";
}

}  // namespace dissgen

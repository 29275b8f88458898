// SPDX-License-Identifier: GPL-2.0-or-later
#include "analysis_inputs.h"

#include "analyses.h"
#include "text_util.h"

#include <map>

namespace dissgen {
namespace {

// The nearest repeated node above n (n itself included), or nullptr.
const Node* repeated_owner(const Node* n) {
    for (; n; n = n->parent)
        if (n->is_repeated()) return n;
    return nullptr;
}

std::string line_text(int line) { return " (line " + std::to_string(line) + ")"; }

// An input that says where a register is: a child of a window (at=), all
// of them of one window, whose base is the address the analysis reads from.
bool check_address_input(const AnalysisInput& input, const Node*& window, int& window_line, Diagnostics& diags) {
    const Node* t = input.field.target;
    const std::string what = "input '" + input.name + "' ";
    const std::string field = "field '" + t->name + "'" + line_text(t->line);
    if (!t->at) {
        diags.error(input.line, what + "is where a register sits in a register map, and " + field +
                                    " is not a child of a window: name a node with at=\"ADDRESS\" inside a "
                                    "container with base=\"...\"");
        return false;
    }
    if (!window) {
        window = t->parent;
        window_line = input.line;
    } else if (t->parent != window) {
        diags.error(input.line, what + "must be in the same window as the register inputs before it: " + field +
                                    " is in '" + t->parent->name + "', the input on line " +
                                    std::to_string(window_line) + " in '" + window->name + "'");
        return false;
    }
    return true;
}

// One bound input: the leaf it names fits what the analysis reads there.
// `unit` is the repeated node of the first per-instance input (and its line).
bool check_input(const AnalysisInput& input, const AnalysisInputSpec& spec, const Node*& unit, int& unit_line,
                 Diagnostics& diags) {
    const Node* t = input.field.target;
    if (!t) return false;  // the parser reported the XPath
    const std::string what = "input '" + input.name + "' ";
    const std::string field = "field '" + t->name + "'" + line_text(t->line);
    if (spec.bytes) {
        if (!t->is_leaf() || t->is_computed()) {
            diags.error(input.line, what + "reads where bytes are, and " + field + " is " +
                                        (t->is_computed() ? "a computed value, which has none" : "a container") +
                                        ": name a leaf with bytes");
            return false;
        }
    } else if (!t->is_numeric()) {
        diags.error(input.line, what + "reads a number, and " + field +
                                    " is not numeric: name a leaf of 1-64 bits shown as a number, bool, enum or "
                                    "nondisplay");
        return false;
    }
    const Node* owner = repeated_owner(t);
    if (!spec.per_instance) {
        if (owner) {
            diags.error(input.line, what + "is one value per message, and " + field + " is inside repeated node '" +
                                        owner->name + "': name a field outside any repeated node");
            return false;
        }
        return true;
    }
    if (!owner) {
        diags.error(input.line, what + "is one value per instance of a repeated node (one per datagram), and " +
                                    field + " is not inside a repeated node");
        return false;
    }
    if (!unit) {
        unit = owner;
        unit_line = input.line;
        if (const Node* outer = repeated_owner(owner->parent)) {
            // The view numbers instances within one run of the repeat: a repeat
            // inside another would give several datagrams the same number.
            diags.error(input.line, what + "is one value per instance of a repeated node, and " + field + " is in '" +
                                        owner->name + "', which is itself inside repeated node '" + outer->name +
                                        "': the instances must be one list per message");
            return false;
        }
    } else if (owner != unit) {
        diags.error(input.line, what + "must be in the same repeated node as the inputs before it: " + field +
                                    " is in '" + owner->name + "', the input on line " + std::to_string(unit_line) +
                                    " in '" + unit->name + "'");
        return false;
    }
    return true;
}

}  // namespace

void check_analysis_inputs(Protocol& proto, Diagnostics& diags) {
    if (!proto.pairing) return;
    Pairing& pairing = *proto.pairing;
    const Analysis* analysis = find_analysis(pairing.analysis);
    if (!analysis) {
        // Without an analysis nobody reads them (an unknown one is reported by the parser).
        if (pairing.analysis.empty())
            for (const AnalysisInput& input : pairing.inputs)
                diags.error(input.line, "<input> names what the pairing's analysis reads, and this <pairing> has "
                                        "no analysis: add analysis=\"...\" or remove the input");
        return;
    }
    std::vector<std::string> names;
    for (const AnalysisInputSpec& spec : analysis->inputs) names.push_back(spec.name);
    std::map<std::string, int> bound;  // input name -> its line
    const Node* unit = nullptr;
    int unit_line = 0;
    const Node* window = nullptr;  // of the register inputs
    int window_line = 0;
    std::map<const Node*, std::string> fields;  // bound fields -> their input's name
    for (AnalysisInput& input : pairing.inputs) {
        size_t index = 0;
        while (index < names.size() && names[index] != input.name) ++index;
        if (index == names.size()) {
            if (!input.name.empty())
                diags.error(input.line, "unknown input '" + input.name + "' of the " + analysis->name +
                                            " analysis; valid: " + join(names, ", "));
            continue;
        }
        auto [it, inserted] = bound.emplace(input.name, input.line);
        if (!inserted) {
            diags.error(input.line, "input '" + input.name + "' is already bound" + line_text(it->second) +
                                        ": name each input once");
            continue;
        }
        const AnalysisInputSpec& spec = analysis->inputs[index];
        if (spec.address) {
            if (!input.field.target || !check_address_input(input, window, window_line, diags)) continue;
        } else if (!check_input(input, spec, unit, unit_line, diags)) {
            continue;
        }
        Node* t = input.field.target;
        auto [named, first] = fields.emplace(t, input.name);
        if (!first) {
            diags.error(input.line,
                        "field '" + t->name + "' is already input '" + named->second + "': one field per input");
            continue;
        }
        input.index = static_cast<int>(index);
        if (spec.address) continue;  // read where the register map puts it, not by the walk
        t->analysis_input = static_cast<int>(index);
        t->analysis_input_per_instance = spec.per_instance;
    }
    for (const AnalysisInputSpec& spec : analysis->inputs) {
        const std::string& name = spec.name;
        if (!spec.optional && !bound.count(name))
            diags.error(pairing.line, "the " + analysis->name + " analysis reads input '" + name +
                                          "' from each message: add <input name=\"" + name +
                                          "\" field=\"XPATH\"/> to <pairing>");
    }
}

}  // namespace dissgen

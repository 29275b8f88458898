// SPDX-License-Identifier: GPL-2.0-or-later
// Node groups: <group name="X"> at the top of a rule file holds nodes that
// several places share; <use group="X"/> stands for a copy of them. The
// front end replaces every use by its copy in the XML tree before the
// parser reads it, so every path, name and filter inside a copy is resolved
// where the copy stands, and a diagnostic about it names the group's line.
#pragma once

#include <libxml/tree.h>

#include <map>
#include <string>

#include "diagnostics.h"

namespace dissgen {

// A group may nest in itself (a value that holds values of its own kind)
// this many levels at most.
constexpr int kMaxGroupDepth = 16;
// Elements all uses together may add: copies of copies grow fast (the
// shipped rule files add under 800; a file of 20000 takes seconds with
// sanitizers on).
constexpr size_t kMaxGroupElements = 20000;
// Bytes of attribute values and text they may add: a few copies of a long
// comment or value weigh as much as many of a short one.
constexpr size_t kMaxGroupTextBytes = 8 * 1024 * 1024;

// Where a copy came from: each element a use put in place, with the group's
// name and the use's line (for diagnostics that depend on where it stands).
struct GroupUse {
    std::string group;
    int line = 0;
};
using GroupUses = std::map<const xmlNode*, GroupUse>;

// Replaces the uses under `root` by copies of their groups and removes the
// groups; records the copies in `uses`. False (after errors in `diags`) when
// a use or group is wrong.
bool expand_node_groups(xmlNode* root, Diagnostics& diags, GroupUses& uses);

// "in group 'X' used on line N, ..." for an element inside copies, from the
// innermost use out; "" elsewhere.
std::string group_uses_of(const GroupUses& uses, const xmlNode* el);
// The same in parentheses after a space, or "".
std::string group_use_context(const GroupUses& uses, const xmlNode* el);

}  // namespace dissgen

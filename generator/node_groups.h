// SPDX-License-Identifier: GPL-2.0-or-later
// Node groups: <group name="X"> at the top of a rule file holds nodes that
// several places share; <use group="X"/> stands for a copy of them. The
// front end replaces every use by its copy in the XML tree before the
// parser reads it, so every path, name and filter inside a copy is resolved
// where the copy stands, and a diagnostic about it names the group's line.
#pragma once

#include <libxml/tree.h>

#include "diagnostics.h"

namespace dissgen {

// A group may nest in itself (a value that holds values of its own kind)
// this many levels at most.
constexpr int kMaxGroupDepth = 16;
// Elements all uses together may add: copies of copies grow fast.
constexpr size_t kMaxGroupElements = 100000;

// Replaces the uses under `root` by copies of their groups and removes the
// groups. False (after errors in `diags`) when a use or group is wrong.
bool expand_node_groups(xmlNode* root, Diagnostics& diags);

}  // namespace dissgen

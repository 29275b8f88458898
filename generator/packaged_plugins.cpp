// SPDX-License-Identifier: GPL-2.0-or-later
#include "packaged_plugins.h"

#include <filesystem>

#include "diagnostics.h"
#include "parser.h"

namespace fs = std::filesystem;

namespace dissgen {

namespace {

const std::string kPrefix = "dissgen-packaged-", kSuffix = ".so";

// STEM of dissgen-packaged-STEM.so; "" for any other file name.
std::string packaged_stem(const std::string& file) {
    if (file.size() <= kPrefix.size() + kSuffix.size() || file.rfind(kPrefix, 0) != 0 ||
        file.compare(file.size() - kSuffix.size(), kSuffix.size(), kSuffix) != 0)
        return "";
    return file.substr(kPrefix.size(), file.size() - kPrefix.size() - kSuffix.size());
}

}  // namespace

PackagedPlugin packaged_plugin_for(const Protocol& p, const std::string& system_dir, const std::string& rules_dir) {
    std::error_code ec;
    for (fs::directory_iterator it(system_dir, ec), end; !ec && it != end; it.increment(ec)) {
        std::string stem = packaged_stem(it->path().filename().string());
        if (stem.empty()) continue;
        fs::path rules = fs::path(rules_dir) / (stem + ".xml");
        Diagnostics ignored;
        std::error_code exists_ec;
        auto other = fs::exists(rules, exists_ec) ? parse_rule_file(rules.string(), ignored) : nullptr;
        if (other && (other->filter == p.filter || other->abbreviation == p.abbreviation || other->name == p.name))
            return {it->path().string(), other->filter};
    }
    return {};
}

}  // namespace dissgen

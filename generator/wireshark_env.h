// SPDX-License-Identifier: GPL-2.0-or-later
// What the generator needs to know about the installed Wireshark: its
// version (headers and tshark), its plugin folders, and its protocol names.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace dissgen {

// Runs a command (argv[0] looked up in PATH), returns its exit status and
// captures stdout (and stderr when `merge_stderr`).
int run_command(const std::vector<std::string>& argv, std::string* output, bool merge_stderr = false);

// "4.0" from `pkg-config --modversion wireshark` (the headers plugins are built against).
std::optional<std::string> headers_version();

// "4.0" from `tshark --version` (the Wireshark that will load the plugin).
std::optional<std::string> tshark_version();

// HOME/.local/lib/wireshark/plugins/X.Y/epan (HOME: $HOME when empty)
std::string user_plugin_dir(const std::string& major_minor, const std::string& home = "");

// `pkg-config --variable=plugindir wireshark`/epan
std::optional<std::string> system_plugin_dir();

struct InstalledProtocol {
    std::string name, short_name, filter;
};

// The protocols of the installed tshark (`tshark -G protocols`); empty when
// tshark is not available.
std::vector<InstalledProtocol> installed_protocols();

// Whether the installed protocol `filter` is a dissgen plugin's: it has the
// runtime's own expert infos (`tshark -G fields`).
bool installed_by_dissgen(const std::string& filter);

}  // namespace dissgen

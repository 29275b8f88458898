// SPDX-License-Identifier: GPL-2.0-or-later
#include "wireshark_env.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <regex>
#include <sstream>

#include "text_util.h"

namespace dissgen {

int run_command(const std::vector<std::string>& argv, std::string* output, bool merge_stderr) {
    // The argument vector is built before fork(): the child of a threaded dissgen
    // (object_cache.cpp compiles in parallel) must not allocate before exec.
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    int pipefd[2];
    if (pipe2(pipefd, O_CLOEXEC) != 0) return -1;
    pid_t pid = fork();
    if (pid < 0) {
        close(pipefd[0]);
        close(pipefd[1]);
        return -1;
    }
    if (pid == 0) {
        dup2(pipefd[1], STDOUT_FILENO);
        if (merge_stderr) {
            dup2(pipefd[1], STDERR_FILENO);
        } else if (int devnull = open("/dev/null", O_WRONLY); devnull >= 0) {
            dup2(devnull, STDERR_FILENO);  // tshark's start-up chatter is not ours to show
            close(devnull);
        }
        close(pipefd[0]);
        close(pipefd[1]);
        execvp(args[0], args.data());
        _exit(127);
    }
    close(pipefd[1]);
    std::string out;
    char buf[4096];
    ssize_t n;
    while ((n = read(pipefd[0], buf, sizeof buf)) > 0) out.append(buf, static_cast<size_t>(n));
    close(pipefd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (output) *output = out;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static std::optional<std::string> major_minor(const std::string& text) {
    static const std::regex version(R"((\d+)\.(\d+)\.\d+)");
    std::smatch m;
    if (!std::regex_search(text, m, version)) return std::nullopt;
    return m[1].str() + "." + m[2].str();
}

std::optional<std::string> headers_version() {
    std::string out;
    if (run_command({"pkg-config", "--modversion", "wireshark"}, &out) != 0) return std::nullopt;
    return major_minor(out);
}

std::optional<std::string> tshark_version() {
    std::string out;
    if (run_command({"tshark", "--version"}, &out) != 0) return std::nullopt;
    return major_minor(out);
}

std::string user_plugin_dir(const std::string& version, const std::string& home) {
    const char* env = std::getenv("HOME");
    return (home.empty() ? std::string(env ? env : ".") : home) + "/.local/lib/wireshark/plugins/" + version + "/epan";
}

std::optional<std::string> system_plugin_dir() {
    std::string out;
    if (run_command({"pkg-config", "--variable=plugindir", "wireshark"}, &out) != 0) return std::nullopt;
    out = trim(out);
    if (out.empty()) return std::nullopt;
    return out + "/epan";
}

std::vector<InstalledProtocol> installed_protocols() {
    std::string out;
    std::vector<InstalledProtocol> protocols;
    if (run_command({"tshark", "-G", "protocols"}, &out) != 0) return protocols;
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream fields(line);
        InstalledProtocol p;
        if (std::getline(fields, p.name, '\t') && std::getline(fields, p.short_name, '\t') &&
            std::getline(fields, p.filter, '\t'))
            protocols.push_back(p);
    }
    return protocols;
}

bool installed_by_dissgen(const std::string& filter) {
    std::string out;
    if (run_command({"tshark", "-G", "fields"}, &out) != 0) return false;
    return out.find("\t" + filter + ".expert.truncated\t") != std::string::npos;
}

}  // namespace dissgen

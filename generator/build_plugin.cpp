// SPDX-License-Identifier: GPL-2.0-or-later
#include "build_plugin.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "object_cache.h"
#include "runtime_list.h"
#include "text_util.h"
#include "wireshark_env.h"

namespace fs = std::filesystem;

namespace dissgen {

namespace {

std::vector<std::string> split_words(const std::string& s) {
    std::istringstream in(s);
    std::vector<std::string> words;
    std::string w;
    while (in >> w) words.push_back(w);
    return words;
}

// The generic runtime's sources (runtime.list) are compiled into every plugin;
// an analysis's own come from the request (BuildRequest::analysis_sources).
bool has_runtime(const fs::path& dir) {
    std::error_code ec;
    for (const std::string& source : runtime_list().sources)
        if (!fs::exists(dir / source, ec)) return false;
    return fs::exists(dir / "dissgen_runtime.h", ec);
}

// Every header of the runtime and its analyses: what a cached object may have included.
std::vector<std::string> runtime_headers(const std::string& runtime_dir) {
    std::vector<std::string> headers;
    std::error_code ec;
    for (fs::recursive_directory_iterator it(runtime_dir, ec), end; !ec && it != end; it.increment(ec))
        if (it->path().extension() == ".h") headers.push_back(it->path().string());
    std::sort(headers.begin(), headers.end());
    return headers;
}

}  // namespace

std::string plugin_basename(const std::string& rule_path) {
    std::string stem = fs::path(rule_path).stem().string();
    for (char& c : stem)
        if (!(std::isalnum(static_cast<unsigned char>(c)) && static_cast<unsigned char>(c) < 0x80) && c != '-') c = '_';
    return "dissgen_" + stem;
}

std::string share_dir(const std::string& argv0) {
    std::error_code ec;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) exe = fs::absolute(argv0, ec);
    return (exe.parent_path().parent_path() / "share" / "dissgen").string();
}

// DIR/<the build folder's name>, which tshark (run as nobody under root) may write its
// counts into; "" when it cannot be made.
static std::string coverage_notes_dir(const std::string& folder, const fs::path& build_dir) {
    fs::path notes = fs::path(folder) / build_dir.filename();
    std::error_code ec;
    fs::create_directories(notes, ec);
    if (ec || chmod(notes.c_str(), 0777) != 0) return "";
    return notes.string();
}

std::string find_runtime_dir(const std::string& argv0) {
    if (const char* env = std::getenv("DISSGEN_RUNTIME_DIR"); env && has_runtime(env)) return env;
    fs::path installed = fs::path(share_dir(argv0)) / "runtime";
    return has_runtime(installed) ? installed.string() : "";
}

std::string make_temp_folder(const std::string& prefix, std::string& tried) {
    std::vector<std::string> parents;
    if (const char* tmp = std::getenv("TMPDIR"); tmp && *tmp) parents.push_back(tmp);
    parents.push_back("/tmp");
    if (const char* cache = std::getenv("XDG_CACHE_HOME"); cache && *cache) parents.push_back(cache);
    else if (const char* home = std::getenv("HOME"); home && *home) parents.push_back(std::string(home) + "/.cache");
    for (const std::string& parent : parents) {
        std::error_code ec;
        fs::create_directories(parent, ec);
        std::string tmpl = parent + "/" + prefix + "-XXXXXX";
        std::vector<char> buf(tmpl.begin(), tmpl.end());
        buf.push_back('\0');
        if (const char* made = mkdtemp(buf.data())) return made;
        tried += (tried.empty() ? "" : ", ") + parent + " (" + std::strerror(errno) + ")";
    }
    return "";
}

std::string build_and_install(const BuildRequest& req, std::string& installed_path) {
    std::string tried;
    const std::string work = make_temp_folder("dissgen-build", tried);
    if (work.empty()) return "cannot create a temporary build folder in " + tried;
    setenv("TMPDIR", work.c_str(), 1);  // the compiler's own temporary files too, where this user can write
    fs::path dir(work);
    struct Cleanup {
        fs::path d;
        ~Cleanup() {
            std::error_code ec;
            fs::remove_all(d, ec);
        }
    } cleanup{dir};

    for (const std::string& extra : req.analysis_sources) {
        std::error_code ec;
        if (!fs::exists(fs::path(req.runtime_dir) / extra, ec))
            return "the plugin runtime in " + req.runtime_dir + " lacks " + extra + ", which these rules use";
    }

    const char* coverage = std::getenv("DISSGEN_COVERAGE_DIR");
    if (coverage && !*coverage) coverage = nullptr;
    // Under coverage the notes are named by the source: a plugin stem may be a runtime
    // file's (handoff.xml makes dissgen_handoff, as dissgen_handoff.cpp).
    fs::path source = dir / (req.stem + (coverage ? ".generated.cpp" : ".cpp"));
    std::ofstream(source) << req.generated_source;
    fs::path output = dir / (req.stem + ".so");

    std::string cflags, libs;
    if (run_command({"pkg-config", "--cflags", "wireshark"}, &cflags) != 0 ||
        run_command({"pkg-config", "--libs", "wireshark"}, &libs) != 0)
        return "pkg-config cannot find Wireshark's development files: install libwireshark-dev";

    const char* cxx = std::getenv("CXX");
    std::vector<std::string> cmd = {cxx && *cxx ? cxx : "c++", "-std=c++17", "-O2", "-fPIC", "-shared"};
    const RuntimeList& runtime = runtime_list();
    cmd.insert(cmd.end(), runtime.flags.begin(), runtime.flags.end());
    cmd.push_back("-I" + req.runtime_dir);
    for (const std::string& w : split_words(cflags)) cmd.push_back(w);
    // Extra flags, e.g. -fsanitize=address,undefined for the sanitizer test runs.
    if (const char* extra = std::getenv("DISSGEN_CXXFLAGS"))
        for (const std::string& w : split_words(extra)) cmd.push_back(w);
    // gcov coverage for the mutation check's map (tests/mutation/coverage_map.py): each
    // plugin's notes and counts in a folder of its own, since every plugin has the
    // runtime's file names and one rule file may make several plugins.
    if (coverage) {
        std::string notes = coverage_notes_dir(coverage, dir);
        if (notes.empty()) return std::string("cannot create a coverage folder in ") + coverage;
        cmd.insert(cmd.end(), {"--coverage", "-dumpdir", notes + "/"});
    }
    std::vector<std::string> sources = {source.string()};
    for (const std::string& runtime_source : runtime.sources) sources.push_back(req.runtime_dir + "/" + runtime_source);
    for (const std::string& extra : req.analysis_sources) sources.push_back(req.runtime_dir + "/" + extra);
    std::vector<std::string> link_inputs = sources;
    // The coverage notes name each plugin's folder: compiled in one go, nothing cached.
    if (!coverage) {
        // The Wireshark and GLib headers the objects are compiled against, by version.
        std::string versions;
        run_command({"pkg-config", "--modversion", "wireshark", "glib-2.0"}, &versions);
        CompileJob job{cmd, sources, runtime_headers(req.runtime_dir), default_cache_dir(), dir.string(),
                       "Wireshark, GLib " + trim(versions)};
        if (std::string error = compile_objects(job, link_inputs); !error.empty()) return error;
    }
    cmd.insert(cmd.end(), link_inputs.begin(), link_inputs.end());
    cmd.push_back("-o");
    cmd.push_back(output.string());
    cmd.push_back("-Wl,--no-undefined");
    for (const std::string& w : split_words(libs)) cmd.push_back(w);

    std::string log;
    int status = run_command(cmd, &log, true);
    if (status != 0) return "compiling the plugin failed (" + cmd[0] + " exit " + std::to_string(status) + "):\n" + log;

    std::error_code ec;
    fs::create_directories(req.target_dir, ec);
    if (ec) return "cannot create " + req.target_dir + ": " + ec.message();
    // Copy beside the target, then rename: a running Wireshark never sees a half-written file.
    fs::path target = fs::path(req.target_dir) / (req.stem + ".so");
    fs::path staging = fs::path(req.target_dir) / ("." + req.stem + ".so.tmp");
    fs::copy_file(output, staging, fs::copy_options::overwrite_existing, ec);
    if (ec) return "cannot write " + staging.string() + ": " + ec.message();
    chmod(staging.c_str(), 0644);
    fs::rename(staging, target, ec);
    if (ec) return "cannot install " + target.string() + ": " + ec.message();
    installed_path = target.string();
    return "";
}

}  // namespace dissgen

// SPDX-License-Identifier: GPL-2.0-or-later
#include "object_cache.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <sstream>
#include <string_view>
#include <system_error>
#include <thread>

#include "wireshark_env.h"

namespace fs = std::filesystem;

namespace dissgen {

namespace {

// The key's version: bump it when what an object depends on changes beyond what the key reads.
constexpr const char* kCacheFormat = "dissgen object cache 1";

// 128 bits from two unrelated 64-bit hashes (FNV-1a and libstdc++'s); a key, not a defence.
class Key {
public:
    void add(std::string_view text) {
        for (unsigned char c : text) fnv_ = (fnv_ ^ c) * 0x100000001b3ULL;
        fnv_ = (fnv_ ^ 0xff) * 0x100000001b3ULL;  // the end of a piece: "ab"+"c" differs from "a"+"bc"
        other_ = other_ * 31 + std::hash<std::string_view>{}(text);
    }
    std::string hex() const {
        char buf[33];
        snprintf(buf, sizeof buf, "%016llx%016llx", static_cast<unsigned long long>(fnv_),
                 static_cast<unsigned long long>(other_));
        return buf;
    }

private:
    std::uint64_t fnv_ = 0xcbf29ce484222325ULL;
    std::uint64_t other_ = 0;
};

bool read_file(const std::string& path, std::string& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    std::ostringstream s;
    s << in.rdbuf();
    out = s.str();
    return true;
}

// What every object of this job depends on besides its own source: the compiler (by what
// it says it is), its options, and the headers. Paths inside the build's temporary folder
// are named relative to it (the folder is new each time; -ffile-prefix-map keeps it out
// of __FILE__ and debug information).
std::string job_key(const CompileJob& job, std::string& error) {
    Key key;
    key.add(kCacheFormat);
    std::string version;
    if (run_command({job.compiler[0], "--version"}, &version) != 0) {
        error = "cannot run the compiler " + job.compiler[0];
        return "";
    }
    key.add(version);
    key.add(job.salt);
    // What the compiler reads from its environment beyond its options.
    for (const char* name : {"CPATH", "CPLUS_INCLUDE_PATH", "C_INCLUDE_PATH", "GCC_EXEC_PREFIX", "COMPILER_PATH",
                             "SOURCE_DATE_EPOCH"}) {
        const char* value = std::getenv(name);
        key.add(std::string(name) + "=" + (value ? value : "(unset)"));
    }
    for (std::string word : job.compiler) {
        for (size_t at; !job.work_dir.empty() && (at = word.find(job.work_dir)) != std::string::npos;)
            word.replace(at, job.work_dir.size(), "<work>");
        key.add(word);
    }
    for (const std::string& header : job.headers) {
        std::string text;
        key.add(header);
        key.add(read_file(header, text) ? text : "(missing)");
    }
    return key.hex();
}

std::string object_name(const std::string& job_key, const std::string& source, const std::string& text,
                        const std::string& work_dir) {
    Key key;
    key.add(job_key);
    std::string where = source.rfind(work_dir, 0) == 0 ? "<work>" + source.substr(work_dir.size()) : source;
    key.add(where);
    key.add(text);
    return key.hex();
}

bool usable_dir(const std::string& dir) {
    if (dir.empty()) return false;
    std::error_code ec;
    // root (sudo with the user's HOME kept) must not leave root-owned folders in another
    // user's home: no cache where the nearest existing folder is someone else's.
    if (geteuid() == 0) {
        fs::path existing = fs::absolute(dir, ec);
        while (!existing.empty() && !fs::exists(existing, ec) && existing != existing.parent_path())
            existing = existing.parent_path();
        struct stat st;
        if (stat(existing.c_str(), &st) != 0 || st.st_uid != 0) return false;
    }
    fs::create_directories(dir, ec);
    return !ec && access(dir.c_str(), W_OK | X_OK) == 0;
}

}  // namespace

std::string default_cache_dir() {
    if (const char* dir = std::getenv("DISSGEN_CACHE_DIR")) return dir;
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/dissgen";
    if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/dissgen";
    return "";
}

std::string compile_objects(const CompileJob& job, std::vector<std::string>& objects) {
    const bool cached = usable_dir(job.cache_dir);
    const std::string store = cached ? job.cache_dir : job.work_dir;
    std::vector<std::string> compiler = job.compiler;
    compiler.push_back("-ffile-prefix-map=" + job.work_dir + "/=");
    std::string error;
    std::string common = job_key(CompileJob{compiler, {}, job.headers, "", job.work_dir, job.salt}, error);
    if (!error.empty()) return error;

    struct Unit {
        std::string source, object;
    };
    std::vector<Unit> missing;
    objects.clear();
    for (const std::string& source : job.sources) {
        std::string text;
        if (!read_file(source, text)) return "cannot read " + source;
        std::string object = store + "/" + object_name(common, source, text, job.work_dir) + ".o";
        std::error_code ec;
        if (!cached || !fs::exists(object, ec)) missing.push_back({source, object});
        objects.push_back(object);
    }

    // Each object is written beside its name and renamed into place: another dissgen
    // compiling the same unit at the same time, or one interrupted, never leaves half an object.
    std::atomic<size_t> next{0};
    std::mutex failed_lock;
    std::string failed;
    auto worker = [&]() {
        for (size_t i; (i = next++) < missing.size();) {
            const Unit& unit = missing[i];
            std::string partial = unit.object + ".part" + std::to_string(getpid()) + "-" + std::to_string(i);
            std::vector<std::string> cmd = compiler;
            cmd.insert(cmd.end(), {"-c", unit.source, "-o", partial});
            std::string log;
            int status = run_command(cmd, &log, true);
            std::error_code ec;
            if (status == 0) fs::rename(partial, unit.object, ec);
            if (status != 0 || ec) {
                fs::remove(partial, ec);
                std::lock_guard<std::mutex> hold(failed_lock);
                if (failed.empty())
                    failed = "compiling the plugin failed (" + cmd[0] + " exit " + std::to_string(status) +
                             ", " + unit.source + "):\n" + log;
            }
        }
    };
    size_t threads = std::min<size_t>(missing.size(), std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) {
        try {
            pool.emplace_back(worker);
        } catch (const std::system_error&) {
            break;  // no more threads: the ones started (and this one) do the rest
        }
    }
    worker();
    for (std::thread& t : pool) t.join();
    return failed;
}

}  // namespace dissgen

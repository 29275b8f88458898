// SPDX-License-Identifier: GPL-2.0-or-later
#include "capture_stream.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>

namespace dissgen {

namespace {

struct Child {
    pid_t pid = -1;
    int out = -1;  // tshark's stdout
    int err = -1;  // tshark's stderr
};

// fork + exec without a shell: arguments pass through untouched. `in`: the
// child's stdin when not -1 (closed here once the child has it).
Child spawn(const std::vector<std::string>& argv, const CaptureStream& stream, int in = -1) {
    int out[2], err[2];
    if (pipe(out) != 0) return {};
    if (pipe(err) != 0) {
        close(out[0]);
        close(out[1]);
        return {};
    }
    pid_t pid = fork();
    if (pid == 0) {
        if (in >= 0) dup2(in, 0), close(in);
        dup2(out[1], 1);
        dup2(err[1], 2);
        close(out[0]);
        close(out[1]);
        close(err[0]);
        close(err[1]);
        for (const auto& [name, value] : stream.environment) setenv(name.c_str(), value.c_str(), 1);
        std::vector<char*> args;
        for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        execvp(args[0], args.data());
        std::fprintf(stderr, "cannot run %s: %s\n", args[0], std::strerror(errno));
        _exit(127);
    }
    close(out[1]);
    close(err[1]);
    if (in >= 0) close(in);
    if (pid < 0) {
        close(out[0]);
        close(err[0]);
        return {};
    }
    // tshark's stderr is small (warnings); read it after stdout, without
    // letting a full pipe block tshark meanwhile.
    fcntl(err[0], F_SETFL, fcntl(err[0], F_GETFL) | O_NONBLOCK);
    return {pid, out[0], err[0]};
}

void drain(int fd, std::string& into) {
    char buf[4096];
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) > 0) into.append(buf, static_cast<size_t>(n));
}

// Progress on stderr: one updated line on a terminal, else a line every 10 s.
class Progress {
public:
    explicit Progress(const std::string& what) : what_(what), tty_(isatty(2)) {}
    void frame() {
        if (++frames_ % 4096) return;
        auto now = std::chrono::steady_clock::now();
        auto every = std::chrono::seconds(tty_ ? 1 : 10);
        if (now - last_ < every) return;
        last_ = now;
        std::cerr << (tty_ ? "\r" : "") << "dissgen: " << what_ << ": " << frames_ << " frames read, "
                  << seconds() << " s" << (tty_ ? "" : "\n") << std::flush;
    }
    void done() const {
        if (tty_ && frames_ >= 4096) std::cerr << "\r\033[K" << std::flush;
    }
    unsigned long frames() const { return frames_; }

private:
    long seconds() const {
        return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - start_).count();
    }
    std::string what_;
    bool tty_;
    unsigned long frames_ = 0;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_ = start_;
};

void split_row(std::string_view line, FieldRow& row) {
    row.clear();
    size_t start = 0;
    for (;;) {
        size_t tab = line.find('\t', start);
        row.push_back(line.substr(start, tab == std::string_view::npos ? std::string_view::npos : tab - start));
        if (tab == std::string_view::npos) break;
        start = tab + 1;
    }
}

}  // namespace

std::vector<std::string_view> split_values(std::string_view joined) {
    std::vector<std::string_view> values;
    if (joined.empty()) return values;
    size_t start = 0;
    for (;;) {
        size_t sep = joined.find(kValueSeparator, start);
        values.push_back(joined.substr(start, sep == std::string_view::npos ? std::string_view::npos : sep - start));
        if (sep == std::string_view::npos) break;
        start = sep + 1;
    }
    return values;
}

bool has_field(const std::vector<std::string>& known, const std::string& name) {
    return std::find(known.begin(), known.end(), name) != known.end();
}

FieldColumns::FieldColumns(const std::vector<std::string>& fields) {
    for (size_t i = 0; i < fields.size(); ++i) columns_[fields[i]] = i;
}

std::string_view FieldColumns::get(const FieldRow& row, const std::string& field) const {
    auto it = columns_.find(field);
    return it == columns_.end() || it->second >= row.size() ? std::string_view() : row[it->second];
}

std::vector<std::string> known_fields(const CaptureStream& stream) {
    std::vector<std::string> argv{stream.tshark, "-G", "fields"};
    std::string out;
    std::vector<std::string> names;
    Child child = spawn(argv, stream);
    if (child.pid < 0) return names;
    FILE* in = fdopen(child.out, "r");
    std::string err;
    char* line = nullptr;
    size_t cap = 0;
    ssize_t len;
    while ((len = getline(&line, &cap, in)) > 0) {
        // F<TAB>Label<TAB>abbrev<TAB>...
        std::string_view l(line, static_cast<size_t>(len));
        if (l.size() < 2 || l[0] != 'F' || l[1] != '\t') continue;
        size_t a = l.find('\t', 2);
        if (a == std::string_view::npos) continue;
        size_t b = l.find('\t', a + 1);
        names.emplace_back(l.substr(a + 1, b == std::string_view::npos ? std::string_view::npos : b - a - 1));
        drain(child.err, err);
    }
    free(line);
    fclose(in);
    drain(child.err, err);
    close(child.err);
    int status = 0;
    waitpid(child.pid, &status, 0);
    return names;
}

namespace {

// mergecap writing `captures` one after the other to a pipe, which is the
// returned child's `out`.
Child concatenate(const CaptureStream& stream, const std::vector<std::string>& captures) {
    std::vector<std::string> argv{stream.mergecap, "-a", "-w", "-"};
    argv.insert(argv.end(), captures.begin(), captures.end());
    return spawn(argv, stream);
}

// What a child wrote to stderr, once it is done, trimmed.
std::string rest_of_stderr(int fd, std::string err) {
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    drain(fd, err);
    close(fd);
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    return err;
}

std::string joined(const std::vector<std::string>& captures) {
    std::string names;
    for (const std::string& c : captures) names += (names.empty() ? "" : " + ") + c;
    return names;
}

}  // namespace

std::string read_capture(const CaptureStream& stream, const std::vector<std::string>& captures,
                         const std::function<void(const FieldRow&)>& on_row) {
    Child merger;
    if (captures.size() > 1 && (merger = concatenate(stream, captures)).pid < 0)
        return "cannot start " + stream.mergecap + ": " + std::strerror(errno);
    const std::string capture = captures.size() == 1 ? captures[0] : "-";
    // One custom column per field, unresolved ("0x0130", not its name), every occurrence.
    std::string columns;
    for (size_t i = 0; i < stream.fields.size(); ++i)
        columns += (i ? "," : "") + std::string("\"f") + std::to_string(i) + "\",\"%Cus:" + stream.fields[i] + ":0:U\"";
    std::vector<std::string> argv{stream.tshark, "-n", "-r", capture, "-T", "tabs", "-o", "gui.column.format:" + columns};
    argv.insert(argv.end(), stream.extra_args.begin(), stream.extra_args.end());
    Child child = spawn(argv, stream, merger.out);
    if (child.pid < 0) {
        const std::string why = std::strerror(errno);
        if (merger.pid > 0) {  // nobody will read what it joins
            kill(merger.pid, SIGTERM);
            waitpid(merger.pid, nullptr, 0);
        }
        return "cannot start " + stream.tshark + ": " + why;
    }
    FILE* in = fdopen(child.out, "r");
    Progress progress("decoding " + joined(captures));
    std::string err;
    FieldRow row;
    char* line = nullptr;
    size_t cap = 0;
    ssize_t len;
    while ((len = getline(&line, &cap, in)) > 0) {
        std::string_view l(line, static_cast<size_t>(len));
        if (!l.empty() && l.back() == '\n') l.remove_suffix(1);
        split_row(l, row);
        if (row.size() == stream.fields.size()) {
            on_row(row);
            progress.frame();
        } else if (stream.on_other_line) {
            stream.on_other_line(l);
        }
        if (err.size() < 65536) drain(child.err, err);
    }
    free(line);
    fclose(in);
    progress.done();
    err = rest_of_stderr(child.err, err);
    int status = 0, merged = 0;
    waitpid(child.pid, &status, 0);
    std::string merge_err;
    if (merger.pid > 0) {
        merge_err = rest_of_stderr(merger.err, "");
        waitpid(merger.pid, &merged, 0);
    }
    bool merge_ok = merger.pid <= 0 || (WIFEXITED(merged) && WEXITSTATUS(merged) == 0);
    const bool tshark_ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (tshark_ok && merge_ok) return "";
    // tshark stopping early (a bad option, a plugin error) kills mergecap with
    // SIGPIPE on its next write: then tshark's message is the one that matters.
    const bool merger_cut_off = WIFSIGNALED(merged) && WTERMSIG(merged) == SIGPIPE;
    if (!merge_ok && (tshark_ok || !merger_cut_off))
        return stream.mergecap + " could not join " + joined(captures) + (merge_err.empty() ? "" : ": " + merge_err);
    return stream.tshark + " failed on " + joined(captures) + (err.empty() ? "" : ": " + err);
}

}  // namespace dissgen

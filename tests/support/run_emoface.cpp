#include "support/run_emoface.h"

#include "support/scratch_dir.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace emoface::testing {

namespace {

namespace fs = std::filesystem;

std::string name_of(const std::string& entry) { return entry.substr(0, entry.find('=')); }

// The child's environment, built before fork (setenv after fork is not safe
// in a test that has threads).
std::vector<std::string> child_environment(const RunOptions& options) {
    std::vector<std::string> env;
    std::string asan = "detect_leaks=0";
    for (char** e = environ; *e; ++e) {
        const std::string entry = *e;
        const std::string name = name_of(entry);
        bool drop = false;
        for (const std::string& u : options.unset_env) drop = drop || u == name;
        for (const auto& kv : options.set_env) drop = drop || kv.first == name;
        if (name == "ASAN_OPTIONS") {
            asan = entry.substr(entry.find('=') + 1) + ":detect_leaks=0";
            drop = true;
        }
        if (!drop) env.push_back(entry);
    }
    for (const auto& kv : options.set_env) env.push_back(kv.first + "=" + kv.second);
    env.push_back("ASAN_OPTIONS=" + asan);
    return env;
}

std::vector<char*> pointers(std::vector<std::string>& strings) {
    std::vector<char*> p;
    for (std::string& s : strings) p.push_back(s.data());
    p.push_back(nullptr);
    return p;
}

}  // namespace

RunOptions without_display() {
    RunOptions o;
    o.unset_env = {"DISPLAY", "WAYLAND_DISPLAY"};
    return o;
}

RunOptions on_display(const std::string& display) {
    RunOptions o;
    o.set_env = {{"DISPLAY", display}};
    return o;
}

std::vector<std::string> args_with(std::vector<std::string> first, const std::vector<std::string>& rest) {
    first.insert(first.end(), rest.begin(), rest.end());
    return first;
}

EmofaceProcess::EmofaceProcess(const std::vector<std::string>& args, const RunOptions& options)
{
    std::string pattern = (fs::temp_directory_path() / "emoface_run_XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("run_emoface: mkdtemp failed");
    dir_ = pattern;
    const std::string out = dir_ + "/stdout", err = dir_ + "/stderr";

    std::vector<std::string> argv{EMOFACE_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<std::string> env = child_environment(options);
    std::vector<char*> argv_p = pointers(argv), env_p = pointers(env);
    const std::string& working_dir = options.working_dir;

    pid_ = ::fork();
    if (pid_ == 0) {
        const int in_fd = ::open("/dev/null", O_RDONLY);
        const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (in_fd < 0 || out_fd < 0 || err_fd < 0) ::_exit(127);
        if (!working_dir.empty() && ::chdir(working_dir.c_str()) != 0) ::_exit(127);
        ::dup2(in_fd, 0);
        ::dup2(out_fd, 1);
        ::dup2(err_fd, 2);
        ::execve(argv_p[0], argv_p.data(), env_p.data());
        ::_exit(127);
    }
    if (pid_ < 0) throw std::runtime_error("run_emoface: fork failed");
}

EmofaceProcess::~EmofaceProcess() {
    if (pid_ > 0) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
    }
    std::error_code ec;
    fs::remove_all(dir_, ec);
}

std::string EmofaceProcess::err_so_far() const { return read_file(dir_ + "/stderr"); }

CommandResult EmofaceProcess::wait(double seconds) {
    if (pid_ <= 0) throw std::logic_error("EmofaceProcess::wait(): expected a running process, got one already waited for");
    CommandResult r;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(long(seconds * 1000));
    int status = 0;
    while (::waitpid(pid_, &status, WNOHANG) == 0) {
        if (std::chrono::steady_clock::now() > deadline) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, &status, 0);
            r.timed_out = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    pid_ = -1;
    r.exit_code = !r.timed_out && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_file(dir_ + "/stdout");
    r.err = read_file(dir_ + "/stderr");
    return r;
}

CommandResult run_emoface(const std::vector<std::string>& args, const RunOptions& options) {
    return EmofaceProcess(args, options).wait(options.timeout_seconds);
}

}  // namespace emoface::testing

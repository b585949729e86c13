// Child processes of external systems (external_run.h).
#include "eval/orchestration/external_run.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

extern char** environ;  // NOLINT(readability-redundant-declaration): POSIX, not declared by every libc header

namespace rovo {
namespace {

using Clock = std::chrono::steady_clock;

// This process's environment with `overrides` set.
std::vector<std::string> ChildEnvironment(const std::vector<std::pair<std::string, std::string>>& overrides) {
  std::map<std::string, std::string> env;
  for (char** e = environ; e && *e; ++e) {
    const std::string entry(*e);
    const size_t eq = entry.find('=');
    if (eq != std::string::npos) env[entry.substr(0, eq)] = entry.substr(eq + 1);
  }
  for (const auto& [key, value] : overrides) env[key] = value;
  std::vector<std::string> out;
  out.reserve(env.size());
  for (const auto& [key, value] : env) out.push_back(key + "=" + value);
  return out;
}

std::vector<char*> Pointers(std::vector<std::string>& strings) {
  std::vector<char*> out;
  out.reserve(strings.size() + 1);
  for (std::string& s : strings) out.push_back(s.data());
  out.push_back(nullptr);
  return out;
}

// posix_spawn with its own process group, default signal handling and the output files.
pid_t Spawn(const ChildSpec& spec, std::string* error) {
  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attr;
  posix_spawn_file_actions_init(&actions);
  posix_spawnattr_init(&attr);
  if (!spec.cwd.empty()) posix_spawn_file_actions_addchdir_np(&actions, spec.cwd.c_str());
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, spec.stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, spec.stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  sigset_t defaults, empty;
  sigfillset(&defaults);
  sigdelset(&defaults, SIGKILL);
  sigdelset(&defaults, SIGSTOP);
  sigemptyset(&empty);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setsigmask(&attr, &empty);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  std::vector<std::string> argv = spec.argv;
  std::vector<std::string> envp = ChildEnvironment(spec.env);
  std::vector<char*> argv_ptrs = Pointers(argv), env_ptrs = Pointers(envp);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv_ptrs[0], &actions, &attr, argv_ptrs.data(), env_ptrs.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) {
    *error = spec.argv[0] + ": " + std::strerror(rc);
    return -1;
  }
  return pid;
}

// Resident memory of the child's process group in kB: the sum over its processes now, and the
// largest high-water mark of one of them (VmHWM: from its exec on; wait4's ru_maxrss would count the
// memory of this process, which the child's mm inherited at spawn).
void SampleGroupMemory(pid_t group, double* peak_kb) {
  std::error_code ec;
  double sum_kb = 0.0;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    const size_t paren = line.rfind(')');
    if (paren == std::string::npos) continue;
    std::istringstream fields(line.substr(paren + 2));
    std::string state;
    long ppid = 0, pgrp = 0;
    if (!(fields >> state >> ppid >> pgrp) || pgrp != group) continue;
    std::ifstream status(entry.path() / "status");
    for (std::string l; std::getline(status, l);) {
      double kb = 0.0;
      if (l.rfind("VmRSS:", 0) == 0 && std::sscanf(l.c_str() + 6, "%lf", &kb) == 1) sum_kb += kb;
      if (l.rfind("VmHWM:", 0) == 0 && std::sscanf(l.c_str() + 6, "%lf", &kb) == 1) *peak_kb = std::max(*peak_kb, kb);
    }
  }
  *peak_kb = std::max(*peak_kb, sum_kb);
}

// Waits for `pid`, killing its group at the deadline; fills the status and resource use.
void WaitWithTimeout(pid_t pid, const ChildSpec& spec, Clock::time_point start, ChildResult* result) {
  const auto deadline =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(spec.timeout_s));
  Clock::time_point kill_at = Clock::time_point::max();
  int status = 0;
  rusage usage{};
  double peak_kb = 0.0;
  while (true) {
    SampleGroupMemory(pid, &peak_kb);
    const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return;
    const auto now = Clock::now();
    if (!result->timed_out && now >= deadline) {
      result->timed_out = true;
      ::kill(-pid, SIGTERM);
      kill_at = now + std::chrono::seconds(2);
    }
    if (now >= kill_at) {
      ::kill(-pid, SIGKILL);
      kill_at = Clock::time_point::max();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(-pid, SIGKILL);  // what the child left running in its group
  result->wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (WIFEXITED(status)) result->exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) result->signal = WTERMSIG(status);
  result->user_cpu_s = Seconds(usage.ru_utime);
  result->system_cpu_s = Seconds(usage.ru_stime);
  result->peak_rss_mb = peak_kb / 1024.0;
}

}  // namespace

ChildResult RunChild(const ChildSpec& spec) {
  ChildResult result;
  if (spec.argv.empty()) {
    result.start_error = "empty command";
    return result;
  }
  const auto start = Clock::now();
  const pid_t pid = Spawn(spec, &result.start_error);
  if (pid < 0) return result;
  result.started = true;
  WaitWithTimeout(pid, spec, start, &result);
  return result;
}

std::string FileTail(const std::string& path, size_t max_bytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return "";
  const std::streamoff size = in.tellg();
  const std::streamoff from =
      size > static_cast<std::streamoff>(max_bytes) ? size - static_cast<std::streamoff>(max_bytes) : 0;
  in.seekg(from);
  std::string text(static_cast<size_t>(size - from), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (from > 0) {
    const size_t newline = text.find('\n');
    if (newline != std::string::npos && newline < 200) text = text.substr(newline + 1);
  }
  return text;
}

std::string ShellQuoteWords(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) {
    if (!out.empty()) out += ' ';
    const bool plain = !w.empty() && w.find_first_not_of(
                                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                         "_-./=:,+@%") == std::string::npos;
    if (plain) {
      out += w;
      continue;
    }
    out += '\'';
    for (char c : w) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    out += '\'';
  }
  return out;
}

}  // namespace rovo

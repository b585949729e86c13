#pragma once
// Running another system's command as a child process: posix_spawn in its own process group, stdout
// and stderr to files, a timeout that kills the whole group, the child's CPU time from wait4 and its
// memory from /proc.

#include <sys/time.h>

#include <string>
#include <utility>
#include <vector>

namespace rovo {

// A struct timeval (getrusage's and wait4's CPU times) in seconds.
inline double Seconds(const timeval& t) {
  return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
}

struct ChildSpec {
  std::vector<std::string> argv;                         // argv[0]: the program's path
  std::vector<std::pair<std::string, std::string>> env;  // set on top of this process's environment
  std::string stdout_path, stderr_path;                  // absolute; truncated, written by the child
  std::string cwd;                                       // the child's working folder ("" = this one's)
  double timeout_s = 600.0;
};

struct ChildResult {
  bool started = false;
  std::string start_error;  // why posix_spawn failed
  int exit_code = -1;       // when it exited
  int signal = 0;           // when a signal ended it (SIGKILL after a timeout)
  bool timed_out = false;
  double wall_s = 0.0;
  double user_cpu_s = 0.0;  // the child and the descendants it waited for (wait4)
  double system_cpu_s = 0.0;
  double peak_rss_mb = 0.0;  // resident memory of the child's process group at its peak (sampled
                             // every 20 ms from /proc: the sum over the group, or one process's VmHWM)
};

// Runs the child to its end or the timeout (SIGTERM to the group, SIGKILL 2 s later); kills what is
// left of the group when the child ends. Never throws for the child's failures.
ChildResult RunChild(const ChildSpec& spec);

// The last `max_bytes` of a file (from a line start when one is near), "" when it cannot be read.
std::string FileTail(const std::string& path, size_t max_bytes);

// Words joined as a POSIX shell would read them back (single quotes where needed).
std::string ShellQuoteWords(const std::vector<std::string>& words);

}  // namespace rovo

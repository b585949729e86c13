#pragma once
// Shell helpers of the Blender integration tests: commands run with their output appended to a log
// file, whose tail goes into a failure message.

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace rovo::testing {

inline std::string Quote(const std::string& s) { return "'" + s + "'"; }

// Runs a shell command, output appended to `log`; returns the exit status.
inline int RunShell(const std::string& command, const std::string& log) {
  std::ofstream(log, std::ios::app) << "\n$ " << command << "\n";
  const int status = std::system((command + " >> " + Quote(log) + " 2>&1").c_str());
  return status == -1 ? -1 : WEXITSTATUS(status);
}

// The last `max_chars` characters of a file.
inline std::string Tail(const std::string& path, size_t max_chars = 4000) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string s = ss.str();
  return s.size() > max_chars ? s.substr(s.size() - max_chars) : s;
}

}  // namespace rovo::testing

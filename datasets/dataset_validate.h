#pragma once
// The dataset validator (`rovo dataset validate`): every problem of a dataset folder at once.

#include <string>
#include <vector>

namespace rovo {

// One problem: the file, the place in it, and what is wrong.
struct ValidationIssue {
  std::string file;   // path of the offending file
  std::string field;  // JSON pointer, line number or image property
  std::string message;
};
// Checks every field and file; returns all problems (empty when valid).
std::vector<ValidationIssue> ValidateDataset(const std::string& dir);

}  // namespace rovo

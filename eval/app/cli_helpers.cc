// Small parsing helpers shared by the commands (commands.h).
#include <stdexcept>
#include <string>

#include "eval/app/commands.h"

namespace rovo {

void ParseFrameRange(const std::string& text, int* begin, int* end) {
  if (text.empty()) return;
  const size_t colon = text.find(':');
  if (colon == std::string::npos) throw std::invalid_argument("--frames '" + text + "': expected A:B");
  try {
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    *begin = a.empty() ? 0 : std::stoi(a);
    *end = b.empty() ? -1 : std::stoi(b);
  } catch (const std::exception&) {
    throw std::invalid_argument("--frames '" + text + "': expected integers A:B");
  }
}

}  // namespace rovo

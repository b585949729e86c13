#include "eval/plots.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "datasets/io.h"
#include "rovo/version.h"

namespace rovo {
namespace fs = std::filesystem;

namespace {

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

std::string ExecutableDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

std::string FindPython() {
  if (::access("/usr/bin/python3", X_OK) == 0) return "/usr/bin/python3";
  return "";
}

std::string HtmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// **bold** and `code` inside already escaped text.
std::string Inline(const std::string& escaped) {
  std::string out;
  bool bold = false, code = false;
  for (size_t i = 0; i < escaped.size(); ++i) {
    if (!code && escaped.compare(i, 2, "**") == 0) {
      out += bold ? "</b>" : "<b>";
      bold = !bold;
      ++i;
    } else if (escaped[i] == '`') {
      out += code ? "</code>" : "<code>";
      code = !code;
    } else {
      out += escaped[i];
    }
  }
  if (bold) out += "</b>";
  if (code) out += "</code>";
  return out;
}

std::vector<std::string> SplitRow(const std::string& line) {
  std::vector<std::string> cells;
  std::string s = line;
  if (!s.empty() && s.front() == '|') s.erase(0, 1);
  if (!s.empty() && s.back() == '|') s.pop_back();
  std::stringstream in(s);
  std::string cell;
  while (std::getline(in, cell, '|')) {
    const size_t b = cell.find_first_not_of(' ');
    const size_t e = cell.find_last_not_of(' ');
    cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
  }
  return cells;
}

}  // namespace

std::string FindPlotScript(const std::string& name) {
  std::vector<fs::path> candidates = {fs::path(ROVO_SOURCE_DIR) / "eval" / "plots" / name};
  const std::string exe_dir = ExecutableDir();
  if (!exe_dir.empty()) {
    candidates.push_back(fs::path(exe_dir) / "plots" / name);
    candidates.push_back(fs::path(exe_dir) / ".." / "eval" / "plots" / name);
    candidates.push_back(fs::path(exe_dir) / ".." / "share" / "rovo" / "plots" / name);
  }
  for (const fs::path& p : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) return p.lexically_normal().string();
  }
  return "";
}

bool RunPlotScript(const std::string& name, const std::string& folder, bool quiet) {
  const std::string script = FindPlotScript(name);
  const std::string python = FindPython();
  auto warn = [&](const std::string& message) {
    if (!quiet) std::fprintf(stderr, "rovo: warning: %s; no plots in %s\n", message.c_str(), folder.c_str());
    return false;
  };
  if (script.empty()) {
    return warn("eval/plots/" + name + " not found (looked in " + std::string(ROVO_SOURCE_DIR) + " and next to rovo)");
  }
  if (python.empty()) return warn("/usr/bin/python3 not found");
  const std::string command =
      ShellQuote(python) + " " + ShellQuote(script) + " " + ShellQuote(folder) + (quiet ? " >/dev/null 2>&1" : " >&2");
  const int status = std::system(command.c_str());
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const int code = (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
    return warn(code == 3 ? std::string("python3 has no matplotlib (apt-get install python3-matplotlib)")
                          : "plot script failed (exit status " + std::to_string(code) + ")");
  }
  return true;
}

std::vector<std::string> RunReportPlots(const std::string& report_dir, bool quiet) {
  RunPlotScript("plot_report.py", report_dir, quiet);
  std::vector<std::string> pngs;
  std::error_code ec;
  const fs::path plots_dir = fs::path(report_dir) / "plots";
  if (fs::is_directory(plots_dir, ec)) {
    for (const auto& entry : fs::directory_iterator(plots_dir, ec)) {
      if (entry.path().extension() == ".png") pngs.push_back(entry.path().string());
    }
  }
  std::sort(pngs.begin(), pngs.end());
  return pngs;
}

std::string Base64Encode(const std::string& bytes) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (static_cast<uint8_t>(bytes[i]) << 16) | (static_cast<uint8_t>(bytes[i + 1]) << 8) |
                       static_cast<uint8_t>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  const size_t rest = bytes.size() - i;
  if (rest == 1) {
    const uint32_t v = static_cast<uint8_t>(bytes[i]) << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (rest == 2) {
    const uint32_t v = (static_cast<uint8_t>(bytes[i]) << 16) | (static_cast<uint8_t>(bytes[i + 1]) << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::string MarkdownToHtml(const std::string& markdown) {
  std::string html;
  std::istringstream in(markdown);
  std::string line;
  bool in_table = false, table_header_done = false, in_paragraph = false;
  auto close_blocks = [&] {
    if (in_table) html += "</tbody></table>\n";
    if (in_paragraph) html += "</p>\n";
    in_table = in_paragraph = false;
  };
  while (std::getline(in, line)) {
    if (!line.empty() && line.front() == '|') {
      if (in_paragraph) {
        html += "</p>\n";
        in_paragraph = false;
      }
      const std::vector<std::string> cells = SplitRow(line);
      if (!in_table) {
        html += "<table><thead><tr>";
        for (const std::string& c : cells) html += "<th>" + Inline(HtmlEscape(c)) + "</th>";
        html += "</tr></thead><tbody>\n";
        in_table = true;
        table_header_done = false;
        continue;
      }
      const bool separator =
          std::all_of(line.begin(), line.end(), [](char c) { return c == '|' || c == '-' || c == ':' || c == ' '; });
      if (separator && !table_header_done) {
        table_header_done = true;
        continue;
      }
      html += "<tr>";
      for (const std::string& c : cells) html += "<td>" + Inline(HtmlEscape(c)) + "</td>";
      html += "</tr>\n";
      continue;
    }
    if (line.empty()) {
      close_blocks();
      continue;
    }
    if (line.rfind("## ", 0) == 0 || line.rfind("# ", 0) == 0) {
      close_blocks();
      const bool h1 = line[1] == ' ';
      const std::string tag = h1 ? "h1" : "h2";
      html += "<" + tag + ">" + Inline(HtmlEscape(line.substr(h1 ? 2 : 3))) + "</" + tag + ">\n";
      continue;
    }
    if (in_table) {
      html += "</tbody></table>\n";
      in_table = false;
    }
    if (!in_paragraph) {
      html += "<p>";
      in_paragraph = true;
    } else {
      html += "\n";
    }
    html += Inline(HtmlEscape(line));
  }
  close_blocks();
  return html;
}

void WriteHtmlReport(const std::string& path, const std::string& title, const std::string& markdown,
                     const std::vector<std::string>& pngs) {
  std::string html = "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" + HtmlEscape(title) +
                     "</title>\n<style>body{font-family:sans-serif;margin:24px;background:#fff;color:#111}"
                     "table{border-collapse:collapse;margin:12px 0;font-size:13px}"
                     "th,td{border:1px solid #999;padding:4px 8px;text-align:right}th{background:#e8eef6}"
                     "td:first-child,th:first-child{text-align:left}figure{display:inline-block;margin:8px}"
                     "img{max-width:100%;border:1px solid #ccc}figcaption{font-size:12px;color:#444}</style>\n"
                     "</head><body>\n<h1>" +
                     HtmlEscape(title) + "</h1>\n<p>rovo " ROVO_VERSION "</p>\n";
  html += MarkdownToHtml(markdown);
  if (pngs.empty()) {
    html += "<p><i>No plots (python3 with matplotlib was not available or failed).</i></p>\n";
  }
  for (const std::string& png : pngs) {
    // Caption "<report folder>/<file>": plots live in <report>/plots/.
    const fs::path png_path(png);
    const std::string name =
        png_path.parent_path().parent_path().filename().string() + "/" + png_path.filename().string();
    html += "<figure><img alt=\"" + HtmlEscape(name) + "\" src=\"data:image/png;base64," + Base64Encode(ReadFile(png)) +
            "\"><figcaption>" + HtmlEscape(name) + "</figcaption></figure>\n";
  }
  html += "</body></html>\n";
  WriteFileAtomic(path, html);
}

}  // namespace rovo

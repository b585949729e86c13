#pragma once
// Plots (eval/plots/*.py, run with /usr/bin/python3 + matplotlib, Agg backend) and the
// self-contained report.html (Markdown table rendered to HTML, PNGs embedded as base64).

#include <string>
#include <vector>

namespace rovo {

// Path of eval/plots/<name>: looked up in ROVO_SOURCE_DIR (rovo/version.h), then next to the
// running executable (<exe dir>/plots, <exe dir>/../eval/plots, <exe dir>/../share/rovo/plots).
// Empty when not found.
std::string FindPlotScript(const std::string& name);

// Runs eval/plots/<name> on `folder` (the script's one argument). Prints a warning (unless quiet)
// and returns false when python3, matplotlib or the script is missing or the script fails.
bool RunPlotScript(const std::string& name, const std::string& folder, bool quiet);

// Runs plot_report.py on an eval report folder (report.h layout); the script writes
// <report_dir>/plots/*.png. Returns the PNGs written, sorted. When python3, matplotlib or the
// script is missing, prints a warning (unless quiet) and returns what exists: the report goes on
// without plots.
std::vector<std::string> RunReportPlots(const std::string& report_dir, bool quiet);

// Standard base64 (RFC 4648) of bytes.
std::string Base64Encode(const std::string& bytes);

// Minimal Markdown to HTML for our reports: "# "/"## " headings, pipe tables, paragraphs,
// **bold** and `code`. Text is HTML-escaped.
std::string MarkdownToHtml(const std::string& markdown);

// One self-contained HTML page: title, the Markdown body, and each PNG embedded as a data URI with
// "<report folder>/<file name>" as caption. Written atomically.
void WriteHtmlReport(const std::string& path, const std::string& title, const std::string& markdown,
                     const std::vector<std::string>& pngs);

}  // namespace rovo

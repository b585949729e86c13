#include <gtest/gtest.h>

#include "eval/plots.h"

namespace rovo {
namespace {

TEST(Base64, MatchesRfc4648Vectors) {
  EXPECT_EQ(Base64Encode(""), "");
  EXPECT_EQ(Base64Encode("f"), "Zg==");
  EXPECT_EQ(Base64Encode("fo"), "Zm8=");
  EXPECT_EQ(Base64Encode("foo"), "Zm9v");
  EXPECT_EQ(Base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64Encode(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(MarkdownToHtml, TablesHeadingsAndEscaping) {
  const std::string html = MarkdownToHtml("# Title\n\n| a | b<c |\n|---|---|\n| 1 | **2** |\n\nText `x&y`.\n");
  EXPECT_NE(html.find("<h1>Title</h1>"), std::string::npos) << html;
  EXPECT_NE(html.find("<th>b&lt;c</th>"), std::string::npos) << html;
  EXPECT_NE(html.find("<td><b>2</b></td>"), std::string::npos) << html;
  EXPECT_EQ(html.find("---"), std::string::npos) << html;
  EXPECT_NE(html.find("<p>Text <code>x&amp;y</code>.</p>"), std::string::npos) << html;
}

TEST(FindPlotScript, FindsTheReportScriptInTheSourceTree) {
  const std::string script = FindPlotScript("plot_report.py");
  EXPECT_NE(script.find("eval/plots/plot_report.py"), std::string::npos) << script;
  EXPECT_EQ(FindPlotScript("no_such_script.py"), "");
}

}  // namespace
}  // namespace rovo

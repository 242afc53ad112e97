#include "report/report_page.hpp"

#include <cctype>
#include <fstream>
#include <sstream>

#include "common/error.hpp"

namespace hybridctl::report {
namespace {

namespace fs = std::filesystem;

std::string read_script(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path.string() + ": cannot read three.js, which the report inlines: install Debian's libjs-three "
                     "(scripts/setup does)");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Text placed inside <script>: a "</script" in it would end the element early. In the
// strings and JSON where it can occur, "<\/" means the same.
std::string script_safe(std::string text) {
  for (std::size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at + 2)) {
    std::string next = text.substr(at + 2, 6);
    for (char& c : next) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (next == "script") text.replace(at, 2, "<\\/");
  }
  return text;
}

// Replaces the first `marker` at or after `from` and returns where the inserted text ends,
// so what was inlined is never searched for the next marker.
std::size_t replace_once(std::string& page, std::size_t from, std::string_view marker, const std::string& with) {
  const std::size_t at = page.find(marker, from);
  if (at == std::string::npos) throw std::logic_error("report.html lacks " + std::string(marker) + " in its order");
  page.replace(at, marker.size(), with);
  return at + with.size();
}

std::string html_text(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

}  // namespace

std::string report_page(const nlohmann::json& document, const fs::path& three_js_directory) {
  const std::string three = read_script(three_js_directory / "three.min.js");
  const std::string orbit = read_script(three_js_directory / "examples/js/controls/OrbitControls.js");
  std::string page(page_asset("report.html"));
  const std::string part = document.value("part", std::string("part"));
  // The markers stand in report.html in this order.
  std::size_t at = replace_once(page, 0, "@TITLE@", html_text("hybridctl report: " + fs::path(part).filename().string()));
  at = replace_once(page, at, "/*@STYLE@*/", std::string(page_asset("report.css")));
  at = replace_once(page, at, "@DATA@", script_safe(document.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)));
  at = replace_once(page, at, "/*@THREE@*/", script_safe(three) + "\n" + script_safe(orbit));
  replace_once(page, at, "/*@SCRIPT@*/", script_safe(std::string(page_asset("report.js"))));
  return page;
}

}  // namespace hybridctl::report

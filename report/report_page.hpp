#pragma once
// The report page: report/page/report.html with its styles, three.js, the page's script
// and the data document inlined.

#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace hybridctl::report {

// A file of report/page/ compiled into the program (embed_page.cmake).
std::string_view page_asset(std::string_view name);

// The whole page. Throws hybridctl::InputError when three.js is not in `three_js_directory`
// (Debian's libjs-three).
std::string report_page(const nlohmann::json& document, const std::filesystem::path& three_js_directory);

}  // namespace hybridctl::report

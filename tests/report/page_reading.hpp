#pragma once
// What the report tests share: a folder of their own for the plans they make, and reading
// what the report wrote (files, the page's embedded data, its base64 fields, how much of
// a snapshot is drawn).

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace hybridctl::report {

namespace fs = std::filesystem;

// The test program's own folder for the plans it makes (its pid in the name).
inline const fs::path& test_root() {
  static const fs::path root = fs::temp_directory_path() / ("hybridctl-report-test-" + std::to_string(::getpid()));
  return root;
}

// The plans made for the tests go when the program ends.
class RemoveTestPlans : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(test_root(), ec);
  }
};
inline const auto* const kRemoveTestPlans = ::testing::AddGlobalTestEnvironment(new RemoveTestPlans);

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline nlohmann::json page_data(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"report-data\">";
  const std::size_t from = page.find(open) + open.size();
  return nlohmann::json::parse(page.substr(from, page.find("</script>", from) - from));
}

// The share of a PNG's pixels that are not the page's background: the snapshot shows something.
inline double drawn_share(const fs::path& png_path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  EXPECT_TRUE(png_image_begin_read_from_file(&image, png_path.c_str())) << png_path;
  image.format = PNG_FORMAT_RGB;
  std::vector<unsigned char> rgb(PNG_IMAGE_SIZE(image));
  EXPECT_TRUE(png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr));
  std::size_t drawn = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
    if (std::abs(rgb[i] - 245) > 12 || std::abs(rgb[i + 1] - 247) > 12 || std::abs(rgb[i + 2] - 250) > 12) ++drawn;
  return double(drawn) / double(rgb.size() / 3);
}

// Little-endian values of a base64 field of the page (report_mesh.hpp's base64).
template <class T>
std::vector<T> decoded(const std::string& text) {
  static const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> bytes;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | std::uint32_t(digits.find(c));
    if ((count += 6) >= 8) bytes.push_back(static_cast<unsigned char>(bits >> (count -= 8)));
  }
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  EXPECT_EQ(bytes.size(), out.size() * sizeof(T)) << "not a whole number of values";
  return out;
}

}  // namespace hybridctl::report

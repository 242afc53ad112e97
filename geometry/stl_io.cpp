// STL reading and writing. Binary is recognised by its size (84 + 50 n bytes), which
// is reliable where the leading "solid" is not: many binary exporters start their
// header with that word.

#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "geometry/mesh.hpp"

namespace hybridctl::geometry {
namespace {

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kBinaryPrefix = 84;
constexpr std::size_t kFacetBytes = 50;

std::uint32_t read_u32(const char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;  // STL is little-endian, as is every host we build for
}

float read_f32(const char* p) {
  float v;
  std::memcpy(&v, p, 4);
  return v;
}

bool starts_with_solid(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\r' || bytes[i] == '\n')) ++i;
  return bytes.substr(i, 5) == "solid";
}

std::string describe(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

TriangleMesh parse_binary(std::string_view bytes, const std::string& name) {
  const std::uint32_t count = read_u32(bytes.data() + kHeaderBytes);
  TriangleMesh mesh;
  mesh.triangles.reserve(count);
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* facet = bytes.data() + kBinaryPrefix + std::size_t(t) * kFacetBytes;
    Triangle tri;
    for (int v = 0; v < 3; ++v) {
      const char* p = facet + 12 + v * 12;  // skip the normal, which we recompute
      const float x = read_f32(p), y = read_f32(p + 4), z = read_f32(p + 8);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        throw InputError(name + ": byte " + std::to_string(p - bytes.data()) + ": triangle " +
                         std::to_string(t + 1) + " vertex " + std::to_string(v + 1) +
                         " has a non-finite coordinate (" + describe(x) + ", " + describe(y) +
                         ", " + describe(z) + "), expected finite numbers in mm");
      }
      tri[v] = {x, y, z};
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

// A tokenizer for ASCII STL that knows where each token starts.
class AsciiReader {
 public:
  AsciiReader(std::string_view text, const std::string& name) : text_(text), name_(name) {}

  bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }

  std::string_view next_word(const char* expected) {
    skip_space();
    token_line_ = line_;
    token_column_ = column_;
    if (pos_ >= text_.size()) fail(std::string("unexpected end of file (truncated?), expected ") + expected);
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) advance();
    return text_.substr(start, pos_ - start);
  }

  void expect(std::string_view keyword) {
    const std::string_view word = next_word(std::string(keyword).c_str());
    if (word != keyword) {
      fail("expected '" + std::string(keyword) + "', got '" + printable(word) + "'");
    }
  }

  double number(const char* what) {
    const std::string_view word = next_word(what);
    double v = 0;
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
    if (ec != std::errc() || end != word.data() + word.size()) {
      fail(std::string("expected ") + what + ", got '" + printable(word) + "'");
    }
    if (!std::isfinite(v)) fail(std::string("non-finite ") + what + " '" + printable(word) + "', expected a finite number");
    return v;
  }

  // Skips the rest of the current line (the solid's name, say).
  void skip_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n') advance();
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(name_ + ":" + std::to_string(token_line_) + ":" + std::to_string(token_column_) +
                     ": " + message);
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
  static std::string printable(std::string_view w) {
    std::string out;
    for (char c : w.substr(0, 40)) out += (c >= 32 && c < 127) ? c : '?';
    if (w.size() > 40) out += "...";
    return out;
  }
  void advance() {
    if (text_[pos_] == '\n') {
      ++line_;
      column_ = 1;
    } else {
      ++column_;
    }
    ++pos_;
  }
  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) advance();
  }

  std::string_view text_;
  const std::string& name_;
  std::size_t pos_ = 0;
  int line_ = 1, column_ = 1;
  int token_line_ = 1, token_column_ = 1;
};

TriangleMesh parse_ascii(std::string_view text, const std::string& name) {
  AsciiReader in(text, name);
  in.expect("solid");
  in.skip_line();
  TriangleMesh mesh;
  while (true) {
    const std::string_view word = in.next_word("'facet' or 'endsolid'");
    if (word == "endsolid") break;
    if (word != "facet") in.fail("expected 'facet' or 'endsolid', got '" + std::string(word.substr(0, 40)) + "'");
    in.expect("normal");
    for (int i = 0; i < 3; ++i) in.number("a normal component");
    in.expect("outer");
    in.expect("loop");
    Triangle tri;
    for (int v = 0; v < 3; ++v) {
      in.expect("vertex");
      tri[v].x = in.number("a vertex coordinate in mm");
      tri[v].y = in.number("a vertex coordinate in mm");
      tri[v].z = in.number("a vertex coordinate in mm");
    }
    in.expect("endloop");
    in.expect("endfacet");
    mesh.triangles.push_back(tri);
  }
  if (mesh.triangles.empty()) in.fail("the solid has no facets, expected at least one triangle");
  return mesh;
}

}  // namespace

StlFormat detect_stl_format(std::string_view bytes) {
  if (bytes.size() >= kBinaryPrefix) {
    const std::uint64_t count = read_u32(bytes.data() + kHeaderBytes);
    if (kBinaryPrefix + count * kFacetBytes == bytes.size()) return StlFormat::Binary;
  }
  // A binary header may start with "solid" too; binary facets are never free of NULs.
  const bool text = bytes.substr(0, 4096).find('\0') == std::string_view::npos;
  return starts_with_solid(bytes) && text ? StlFormat::Ascii : StlFormat::Binary;
}

TriangleMesh parse_stl(std::string_view bytes, const std::string& name) {
  if (bytes.empty()) throw InputError(name + ": empty file, expected a binary or ASCII STL");
  if (detect_stl_format(bytes) == StlFormat::Ascii) return parse_ascii(bytes, name);
  if (bytes.size() < kBinaryPrefix) {
    throw InputError(name + ": truncated: " + std::to_string(bytes.size()) +
                     " bytes, a binary STL needs at least 84 (80-byte header and triangle count); "
                     "not an ASCII STL either (does not start with 'solid')");
  }
  const std::uint64_t count = read_u32(bytes.data() + kHeaderBytes);
  const std::uint64_t expected = kBinaryPrefix + count * kFacetBytes;
  if (expected != bytes.size()) {
    const bool truncated = bytes.size() < expected;
    throw InputError(name + ": " + (truncated ? "truncated" : "size mismatch") +
                     ": the binary STL header announces " + std::to_string(count) +
                     " triangles, which need " + std::to_string(expected) + " bytes, but the file has " +
                     std::to_string(bytes.size()) + " bytes" +
                     (starts_with_solid(bytes) ? "" : "; not an ASCII STL either (does not start with 'solid')"));
  }
  if (count == 0) throw InputError(name + ": the binary STL holds no triangles, expected at least one");
  return parse_binary(bytes, name);
}

TriangleMesh read_stl(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  if (!in || std::filesystem::is_directory(path, ec)) {
    throw InputError(path.string() + ": cannot read: " +
                     (std::filesystem::exists(path, ec) ? "not a readable file" : "no such file"));
  }
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_stl(bytes, path.string());
}

void write_stl(const TriangleMesh& mesh, const std::filesystem::path& path) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    char header[kHeaderBytes] = {};
    std::snprintf(header, sizeof header, "binary STL written by hybridctl");
    out.write(header, sizeof header);
    const std::uint32_t count = std::uint32_t(mesh.triangles.size());
    out.write(reinterpret_cast<const char*>(&count), 4);
    for (const Triangle& t : mesh.triangles) {
      const Vec3 u{t[1].x - t[0].x, t[1].y - t[0].y, t[1].z - t[0].z};
      const Vec3 v{t[2].x - t[0].x, t[2].y - t[0].y, t[2].z - t[0].z};
      Vec3 n{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
      const double len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
      if (len > 0) n = {n.x / len, n.y / len, n.z / len};
      float record[12] = {float(n.x), float(n.y), float(n.z)};
      for (int i = 0; i < 3; ++i) {
        record[3 + 3 * i] = float(t[i].x);
        record[4 + 3 * i] = float(t[i].y);
        record[5 + 3 * i] = float(t[i].z);
      }
      out.write(reinterpret_cast<const char*>(record), sizeof record);
      const std::uint16_t attributes = 0;
      out.write(reinterpret_cast<const char*>(&attributes), 2);
    }
    if (!out.flush()) throw InputError(path.string() + ": cannot write: output error");
  }
  file.commit();
}

}  // namespace hybridctl::geometry

#include "geometry/png_slices.hpp"

#include <png.h>

#include <cstdio>
#include <memory>

#include "common/atomic_file.hpp"
#include "common/error.hpp"

namespace hybridctl::geometry {
namespace {

void write_gray_png(const std::filesystem::path& path, int width, int height, const std::vector<std::uint8_t>& pixels) {
  AtomicFile file(path);
  std::unique_ptr<FILE, int (*)(FILE*)> out(std::fopen(file.temp_path().c_str(), "wb"), &std::fclose);
  if (!out) throw InputError(path.string() + ": cannot write");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw InputError(path.string() + ": cannot write: out of memory");
  }
  if (setjmp(png_jmpbuf(png))) {  // libpng reports its errors by longjmp
    png_destroy_write_struct(&png, &info);
    throw InputError(path.string() + ": cannot write: PNG encoding failed");
  }
  png_init_io(png, out.get());
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int r = 0; r < height; ++r) png_write_row(png, pixels.data() + std::size_t(r) * std::size_t(width));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(out.get()) != 0) throw InputError(path.string() + ": cannot write: output error");
  out.reset();
  file.commit();
}

}  // namespace

std::vector<std::filesystem::path> write_png_slices(const Solid& solid, const std::filesystem::path& directory,
                                                    int min_width) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) throw InputError(directory.string() + ": cannot create directory: " + ec.message());
  std::vector<std::filesystem::path> written;
  const IndexBox box = solid.bounding_box();
  if (box.empty()) return written;
  const int nx = box.hi.x - box.lo.x, ny = box.hi.y - box.lo.y;
  const int scale = std::max(1, (min_width + nx - 1) / nx);
  const int width = nx * scale, height = ny * scale;
  std::vector<std::uint8_t> pixels(std::size_t(width) * std::size_t(height));
  for (int z = box.lo.z; z < box.hi.z; ++z) {
    for (int row = 0; row < height; ++row) {
      const int y = box.hi.y - 1 - row / scale;  // +Y up in the image
      for (int col = 0; col < width; ++col) {
        const int x = box.lo.x + col / scale;
        pixels[std::size_t(row) * std::size_t(width) + std::size_t(col)] = solid.contains({x, y, z}) ? 255 : 0;
      }
    }
    char name[32];
    std::snprintf(name, sizeof name, "z%04d.png", z - box.lo.z);
    written.push_back(directory / name);
    write_gray_png(written.back(), width, height, pixels);
  }
  return written;
}

}  // namespace hybridctl::geometry

#pragma once
// PNG snapshots of the report's main views, drawn on the CPU (no browser, no GPU): a
// small z-buffer rasteriser with flat Lambert shading and an orthographic camera from the
// page's default direction, supersampled 2x. For mail and tickets, and for the README.

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "geometry/solid.hpp"
#include "report/report_mesh.hpp"

namespace hybridctl::report {

using Colour = std::array<float, 3>;  // linear 0..1

struct SnapshotMesh {
  const IndexedMesh* mesh = nullptr;
  Colour colour{0.7f, 0.7f, 0.7f};
  bool x_ray = false;  // drawn over everything else, 70 % opaque: what must be seen even inside
  const std::vector<Colour>* triangle_colours = nullptr;  // one per triangle, instead of `colour`
};

struct SnapshotLines {
  const std::vector<float>* points = nullptr;  // two vertices (x, y, z) per segment
  std::vector<Colour> colours;                 // one per segment
  int width = 1;                               // pixels of the supersampled canvas (2 per pixel of the image)
};

struct SnapshotTile {
  std::vector<SnapshotMesh> meshes;
  std::vector<SnapshotLines> lines;
};

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, top row first
};

// Tiles side by side (columns x rows, left to right, top to bottom), each framing `bounds`
// from the same direction, each `tile_width` x `tile_height` pixels.
Image render_tiles(const std::vector<SnapshotTile>& tiles, const geometry::Box3& bounds, int columns,
                   int tile_width, int tile_height);

// Writes an 8-bit RGB PNG (temporary file, then rename).
void write_png(const Image& image, const std::filesystem::path& path);

}  // namespace hybridctl::report

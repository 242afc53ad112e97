#include "report/snapshot.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/atomic_file.hpp"
#include "common/error.hpp"

namespace hybridctl::report {
namespace {

using geometry::Vec3;

constexpr int kSupersample = 2;
const Colour kBackground{0.96f, 0.97f, 0.98f};  // the page's viewport background

Vec3 sub(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Vec3 normalised(Vec3 a) {
  const double n = std::sqrt(dot(a, a));
  return n > 0 ? Vec3{a.x / n, a.y / n, a.z / n} : a;
}

// An orthographic camera looking at the box from the page's default direction (report.js,
// kViewDirection), fitted to the box with a margin.
class Camera {
 public:
  Camera(const geometry::Box3& box, int width, int height) {
    centre_ = {(box.min.x + box.max.x) / 2, (box.min.y + box.max.y) / 2, (box.min.z + box.max.z) / 2};
    const Vec3 eye = normalised({1.0, -1.6, 1.1});  // from where the camera looks
    forward_ = {-eye.x, -eye.y, -eye.z};
    right_ = normalised(cross(forward_, {0, 0, 1}));
    up_ = cross(right_, forward_);
    double half_w = 1e-9, half_h = 1e-9;
    for (int c = 0; c < 8; ++c) {
      const Vec3 p{c & 1 ? box.max.x : box.min.x, c & 2 ? box.max.y : box.min.y, c & 4 ? box.max.z : box.min.z};
      half_w = std::max(half_w, std::abs(dot(sub(p, centre_), right_)));
      half_h = std::max(half_h, std::abs(dot(sub(p, centre_), up_)));
    }
    scale_ = 0.9 * std::min(width / (2 * half_w), height / (2 * half_h));
    cx_ = width / 2.0;
    cy_ = height / 2.0;
  }
  // Pixel x, y (y down) and depth (larger is farther).
  Vec3 project(Vec3 p) const {
    const Vec3 d = sub(p, centre_);
    return {cx_ + dot(d, right_) * scale_, cy_ - dot(d, up_) * scale_, dot(d, forward_)};
  }
  const Vec3& forward() const { return forward_; }

 private:
  Vec3 centre_, forward_, right_, up_;
  double scale_ = 1, cx_ = 0, cy_ = 0;
};

struct Canvas {
  int width, height;
  std::vector<Colour> colour;
  std::vector<float> depth;
  std::vector<float> alpha;  // x-ray layer coverage
  Canvas(int w, int h)
      : width(w), height(h), colour(std::size_t(w) * h, kBackground),
        depth(std::size_t(w) * h, std::numeric_limits<float>::infinity()), alpha(std::size_t(w) * h, 0) {}
  void clear_depth() { std::fill(depth.begin(), depth.end(), std::numeric_limits<float>::infinity()); }
};

void fill_triangle(Canvas& canvas, const Vec3 (&p)[3], const Colour& c, std::vector<Colour>* layer) {
  const double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
  if (std::abs(area) < 1e-12) return;
  const int x0 = std::max(0, int(std::floor(std::min({p[0].x, p[1].x, p[2].x}))));
  const int x1 = std::min(canvas.width - 1, int(std::ceil(std::max({p[0].x, p[1].x, p[2].x}))));
  const int y0 = std::max(0, int(std::floor(std::min({p[0].y, p[1].y, p[2].y}))));
  const int y1 = std::min(canvas.height - 1, int(std::ceil(std::max({p[0].y, p[1].y, p[2].y}))));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5, py = y + 0.5;
      const double w0 = ((p[1].x - px) * (p[2].y - py) - (p[2].x - px) * (p[1].y - py)) / area;
      const double w1 = ((p[2].x - px) * (p[0].y - py) - (p[0].x - px) * (p[2].y - py)) / area;
      const double w2 = 1 - w0 - w1;
      if (w0 < 0 || w1 < 0 || w2 < 0) continue;
      const float z = float(w0 * p[0].z + w1 * p[1].z + w2 * p[2].z);
      const std::size_t i = std::size_t(y) * canvas.width + x;
      if (z >= canvas.depth[i]) continue;
      canvas.depth[i] = z;
      (layer ? (*layer)[i] : canvas.colour[i]) = c;
      if (layer) canvas.alpha[i] = 1;
    }
}

void draw_mesh(Canvas& canvas, const Camera& camera, const SnapshotMesh& m, std::vector<Colour>* layer) {
  const std::vector<float>& pos = m.mesh->positions;
  const Vec3 light = normalised({0.35, -0.45, 0.82});
  for (std::size_t t = 0; t + 2 < m.mesh->indices.size(); t += 3) {
    Vec3 world[3], screen[3];
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = std::size_t(m.mesh->indices[t + k]) * 3;
      world[k] = {pos[v], pos[v + 1], pos[v + 2]};
      screen[k] = camera.project(world[k]);
    }
    const Vec3 n = normalised(cross(sub(world[1], world[0]), sub(world[2], world[0])));
    // Lit from above and behind the viewer; faces turned away are lit as if turned to it.
    const float shade = float(0.42 + 0.58 * std::abs(dot(n, light)));
    const float facing = float(0.85 + 0.15 * std::abs(dot(n, camera.forward())));
    const Colour& base = m.triangle_colours && t / 3 < m.triangle_colours->size() ? (*m.triangle_colours)[t / 3] : m.colour;
    const Colour c{base[0] * shade * facing, base[1] * shade * facing, base[2] * shade * facing};
    fill_triangle(canvas, screen, c, layer);
  }
}

void draw_lines(Canvas& canvas, const Camera& camera, const SnapshotLines& lines) {
  const std::vector<float>& p = *lines.points;
  for (std::size_t s = 0; s * 6 + 5 < p.size(); ++s) {
    const Vec3 a = camera.project({p[s * 6], p[s * 6 + 1], p[s * 6 + 2]});
    const Vec3 b = camera.project({p[s * 6 + 3], p[s * 6 + 4], p[s * 6 + 5]});
    const int steps = std::max(1, int(std::ceil(std::max(std::abs(b.x - a.x), std::abs(b.y - a.y)))));
    const Colour& c = lines.colours[std::min(s, lines.colours.size() - 1)];
    for (int i = 0; i <= steps; ++i) {
      const double t = double(i) / steps;
      const int x0 = int(a.x + (b.x - a.x) * t) - (lines.width - 1) / 2, y0 = int(a.y + (b.y - a.y) * t) - (lines.width - 1) / 2;
      const float z = float(a.z + (b.z - a.z) * t) - 0.5f;  // lines on a surface stay in front of it
      for (int y = y0; y < y0 + lines.width; ++y)
        for (int x = x0; x < x0 + lines.width; ++x) {
          if (x < 0 || y < 0 || x >= canvas.width || y >= canvas.height) continue;
          const std::size_t k = std::size_t(y) * canvas.width + x;
          if (z >= canvas.depth[k]) continue;
          canvas.depth[k] = z;
          canvas.colour[k] = c;
        }
    }
  }
}

Canvas render_tile(const SnapshotTile& tile, const geometry::Box3& bounds, int width, int height) {
  Canvas canvas(width, height);
  const Camera camera(bounds, width, height);
  for (const SnapshotMesh& m : tile.meshes)
    if (m.mesh && !m.x_ray) draw_mesh(canvas, camera, m, nullptr);
  for (const SnapshotLines& l : tile.lines)
    if (l.points && !l.colours.empty()) draw_lines(canvas, camera, l);
  std::vector<Colour> layer(canvas.colour.size());
  canvas.clear_depth();
  for (const SnapshotMesh& m : tile.meshes)
    if (m.mesh && m.x_ray) draw_mesh(canvas, camera, m, &layer);
  for (std::size_t i = 0; i < layer.size(); ++i)
    if (canvas.alpha[i] > 0)
      for (int k = 0; k < 3; ++k) canvas.colour[i][k] = 0.3f * canvas.colour[i][k] + 0.7f * layer[i][k];
  return canvas;
}

}  // namespace

Image render_tiles(const std::vector<SnapshotTile>& tiles, const geometry::Box3& bounds, int columns, int tile_width,
                   int tile_height) {
  columns = std::max(1, std::min(columns, int(tiles.size())));
  const int rows = int((tiles.size() + columns - 1) / columns);
  Image image{columns * tile_width, std::max(1, rows) * tile_height, {}};
  image.rgb.assign(std::size_t(image.width) * image.height * 3, 255);
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const Canvas canvas = render_tile(tiles[t], bounds, tile_width * kSupersample, tile_height * kSupersample);
    const int ox = int(t % columns) * tile_width, oy = int(t / columns) * tile_height;
    for (int y = 0; y < tile_height; ++y)
      for (int x = 0; x < tile_width; ++x) {
        Colour sum{0, 0, 0};
        for (int sy = 0; sy < kSupersample; ++sy)
          for (int sx = 0; sx < kSupersample; ++sx) {
            const Colour& c = canvas.colour[std::size_t(y * kSupersample + sy) * canvas.width + x * kSupersample + sx];
            for (int k = 0; k < 3; ++k) sum[k] += c[k];
          }
        std::uint8_t* out = &image.rgb[(std::size_t(oy + y) * image.width + ox + x) * 3];
        for (int k = 0; k < 3; ++k)
          out[k] = std::uint8_t(std::clamp(sum[k] / (kSupersample * kSupersample), 0.0f, 1.0f) * 255.0f + 0.5f);
      }
  }
  return image;
}

void write_png(const Image& image, const std::filesystem::path& path) {
  AtomicFile file(path);
  FILE* out = std::fopen(file.temp_path().c_str(), "wb");
  if (!out) throw InputError(path.string() + ": cannot write");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(out);
    throw InputError(path.string() + ": cannot write the PNG");
  }
  png_init_io(png, out);
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(&image.rgb[std::size_t(y) * image.width * 3]));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(out) != 0) throw InputError(path.string() + ": cannot write");
  file.commit();
}

}  // namespace hybridctl::report

#pragma once
// Drop-cutter against the design's triangles (docs/toolpaths.md, "Surface finishing"): the
// lowest height at which a flat, ball or bull-nose cutter held over a point touches a
// triangle mesh coming down its axis, exactly (no sampling of the surface).
//
//   const DropCutter drop(design, cutter_shape(tool));
//   const double z = drop.tip_height({x, y});   // the tool tip's height, work frame
//
// The cutter's lower surface is convex and of revolution: at distance d from the axis it
// stands f(d) above the tip (flat 0; ball R - sqrt(R^2 - d^2); bull 0 out to R - r, then a
// torus of tube r). A triangle is met at a vertex, on an edge or inside its face:
//   vertex  tip = v.z - f(d), d the vertex's distance from the axis;
//   face    the face's plane touches the cutter where the surface's slope equals the
//           plane's (closed form per shape); kept when that point lies inside the triangle;
//   edge    along the edge, v.z(t) - f(d(t)) is concave in t (a convex increasing f of a
//           convex distance), so its maximum over the part of the edge under the cutter is
//           found by golden-section search to 1e-10 of the edge.
// Everything is in the work frame (tool axis +Z), in mm; only the cutting part is modelled
// (flutes long enough, shank and holder are the caller's to keep clear).

#include <memory>
#include <vector>

#include "config/machine.hpp"
#include "geometry/mesh.hpp"
#include "toolpaths/wall_finish.hpp"

namespace hybridctl::toolpaths {

// radius R and corner radius r: flat r = 0, ball r = R, bull 0 < r < R.
struct CutterShape {
  double radius = 0;
  double corner_radius = 0;
  // f(d): the lower surface's height above the tip at distance d <= radius from the axis.
  double height_at(double d) const;
};

// The cutting part of `tool` (its type, diameter and corner radius).
CutterShape cutter_shape(const config::CuttingTool& tool);

class DropCutter {
 public:
  DropCutter(std::shared_ptr<const std::vector<geometry::Triangle>> mesh, CutterShape shape);

  // The lowest tip height at `p` at which the cutter touches no triangle's interior:
  // where it first meets the mesh coming down; -infinity when nothing lies under it.
  double tip_height(Point2 p) const;
  const CutterShape& shape() const { return shape_; }

 private:
  std::shared_ptr<const std::vector<geometry::Triangle>> mesh_;
  CutterShape shape_;
  // Triangles by the square cells (side cell_ mm) that their XY bounding boxes overlap.
  double cell_ = 1, x0_ = 0, y0_ = 0;
  int nx_ = 0, ny_ = 0;
  std::vector<std::vector<int>> buckets_;
  mutable std::vector<unsigned> seen_;
  mutable unsigned stamp_ = 0;
};

// The step-over (mm) between raster rows of `shape` whose scallops stand at most
// `scallop` mm on a flat face: 2 sqrt(2 r h - h^2) for the corner radius r (a flat
// cutter: its diameter).
double scallop_step_over(const CutterShape& shape, double scallop);

}  // namespace hybridctl::toolpaths

#include "toolpaths/arc_fit.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace hybridctl::toolpaths {
namespace {

using geometry::Vec3;

// Fine-tuning constants.
constexpr double kSameHeight = 1e-9;     // mm: a move ending this close to the run's height is planar
constexpr double kShortestChord = 1e-6;  // mm: a shorter move ends a run (no direction to fit)
constexpr int kRefineSteps = 4;          // Gauss-Newton steps of the centre along the bisector
constexpr double kSweepSlack = 1e-9;     // radians: a sweep of exactly max_sweep_deg, summed in chords, is within

struct P2 {
  double x = 0, y = 0;
};
P2 operator-(P2 a, P2 b) { return {a.x - b.x, a.y - b.y}; }
P2 operator+(P2 a, P2 b) { return {a.x + b.x, a.y + b.y}; }
P2 operator*(double s, P2 a) { return {s * a.x, s * a.y}; }
double dot(P2 a, P2 b) { return a.x * b.x + a.y * b.y; }
double cross(P2 a, P2 b) { return a.x * b.y - a.y * b.x; }
double norm(P2 a) { return std::hypot(a.x, a.y); }
P2 xy(const Vec3& v) { return {v.x, v.y}; }

// Distance from `c` to the segment a-b.
double distance_to_segment(P2 c, P2 a, P2 b) {
  const P2 ab = b - a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(dot(c - a, ab) / len2, 0.0, 1.0) : 0.0;
  return norm(a + t * ab - c);
}

struct ArcFit {
  P2 centre;
  double radius = 0;
  double sweep = 0;    // radians, counter-clockwise > 0
  double outward = 0;  // mm: how far the arc stands out of the chords (away from its centre), at most
  double inward = 0;   // mm: how far a chord's point lies outside the arc (the arc passing inside it), at most
};

// The circles through the first and last of `points` have their centres on the ends'
// perpendicular bisector: centre(t) = mid + t * normal, radius(t) = hypot(half, t).
class Bisector {
 public:
  Bisector(P2 first, P2 last) : mid_(0.5 * (first + last)) {
    const P2 chord = last - first;
    half_ = 0.5 * norm(chord);
    normal_ = {-chord.y / (2 * half_), chord.x / (2 * half_)};
  }
  P2 centre(double t) const { return mid_ + t * normal_; }
  double radius(double t) const { return std::hypot(half_, t); }
  double along(P2 centre) const { return dot(centre - mid_, normal_); }
  P2 normal() const { return normal_; }

 private:
  P2 mid_, normal_;
  double half_ = 0;
};

// The circle through a, b and c, as a point on the bisector of a and c; none when the
// three are (nearly) in line.
std::optional<double> three_point_centre(const Bisector& bisector, P2 a, P2 b, P2 c) {
  const P2 ab = b - a, ac = c - a;
  const double d = 2 * cross(ab, ac);
  if (std::abs(d) <= 1e-15 * norm(ab) * norm(ac)) return std::nullopt;
  const double ab2 = dot(ab, ab), ac2 = dot(ac, ac);
  const P2 centre = a + P2{(ac.y * ab2 - ab.y * ac2) / d, (ab.x * ac2 - ac.x * ab2) / d};
  return bisector.along(centre);
}

// Least squares of the radial misfit of the inner points and the chords' middles, by
// Gauss-Newton along the bisector from `t`.
double refine(const Bisector& bisector, const std::vector<P2>& points, std::size_t k, double t) {
  for (int step = 0; step < kRefineSteps; ++step) {
    const P2 c = bisector.centre(t);
    const double r = bisector.radius(t);
    double num = 0, den = 0;
    const auto add = [&](P2 q) {
      const P2 d = q - c;
      const double len = norm(d);
      if (len == 0) return;
      const double f = len - r;
      const double df = -dot(d, bisector.normal()) / len - t / r;
      num += f * df;
      den += df * df;
    };
    for (std::size_t j = 0; j < k; ++j) {
      if (j > 0) add(points[j]);
      add(0.5 * (points[j] + points[j + 1]));
    }
    if (!(den > 0)) break;
    t -= num / den;
  }
  return t;
}

// The arc of centre bisector.centre(t) from points[0] to points[k], judged against the
// chords between: none when it does not hold to the rules (arc_fit.hpp).
std::optional<ArcFit> judge(const Bisector& bisector, double t, const std::vector<P2>& points, std::size_t k,
                            const ArcFitOptions& options) {
  if (!std::isfinite(t)) return std::nullopt;
  ArcFit fit;
  fit.centre = bisector.centre(t);
  fit.radius = bisector.radius(t);
  if (fit.radius < options.min_radius || fit.radius > options.max_radius) return std::nullopt;
  const double max_sweep = options.max_sweep_deg * std::numbers::pi / 180;
  for (std::size_t j = 0; j < k; ++j) {
    const P2 a = points[j] - fit.centre, b = points[j + 1] - fit.centre;
    const double step = std::atan2(cross(a, b), dot(a, b));
    if (step == 0 || (j > 0 && (step > 0) != (fit.sweep > 0))) return std::nullopt;  // turns back
    fit.sweep += step;
    if (std::abs(fit.sweep) > max_sweep + kSweepSlack) return std::nullopt;
    // The chord's points lie between its nearest point to the centre and its farther end.
    const double nearest = distance_to_segment(fit.centre, points[j], points[j + 1]);
    const double farthest = std::max(norm(a), norm(b));
    fit.outward = std::max(fit.outward, fit.radius - nearest);
    fit.inward = std::max(fit.inward, farthest - fit.radius);
    if (fit.outward > options.chord_tolerance || fit.inward > options.inward_tolerance) return std::nullopt;
  }
  return fit;
}

// The best arc from points[0] to points[k] within the rules, if any.
std::optional<ArcFit> fit_prefix(const std::vector<P2>& points, std::size_t k, const ArcFitOptions& options) {
  if (norm(points[k] - points[0]) < kShortestChord) return std::nullopt;  // closed: a full turn
  const Bisector bisector(points[0], points[k]);
  const std::optional<double> t = three_point_centre(bisector, points[0], points[k / 2], points[k]);
  if (!t) return std::nullopt;
  // The circle the points lie on, when they do (a polygon offset's round join: its
  // vertices are on the arc, its chords inside it); else the least-squares one.
  if (std::optional<ArcFit> through = judge(bisector, *t, points, k, options)) return through;
  return judge(bisector, refine(bisector, points, k, *t), points, k, options);
}

void require_workable(const ArcFitOptions& o) {
  if (!(o.chord_tolerance > 0)) throw std::invalid_argument("arc fitting: the chord tolerance must be positive");
  if (!(o.inward_tolerance >= 0 && o.inward_tolerance <= o.chord_tolerance))
    throw std::invalid_argument("arc fitting: expected 0 <= inward_tolerance <= chord_tolerance");
  if (o.min_chords < 2) throw std::invalid_argument("arc fitting: an arc replaces at least 2 moves");
  if (!(o.max_sweep_deg > 0 && o.max_sweep_deg < 360))
    throw std::invalid_argument("arc fitting: the largest sweep must be in (0, 360) degrees");
  if (!(o.min_radius > 0 && o.min_radius <= o.max_radius))
    throw std::invalid_argument("arc fitting: expected 0 < min_radius <= max_radius");
}

}  // namespace

std::vector<PathMove> fit_arcs(const Vec3& start, const std::vector<PathMove>& moves, const ArcFitOptions& options,
                               ArcFitStats* stats) {
  require_workable(options);
  const std::size_t min_chords = std::size_t(options.min_chords);
  std::vector<PathMove> out;
  out.reserve(moves.size());
  std::vector<P2> points;
  Vec3 at = start;
  std::size_t i = 0;
  while (i < moves.size()) {
    const PathMove& first = moves[i];
    // Extend the run one move at a time while its prefix still fits an arc.
    points.assign(1, xy(at));
    std::optional<ArcFit> best;
    std::size_t best_k = 0;
    for (std::size_t k = 1; i + k - 1 < moves.size(); ++k) {
      const PathMove& m = moves[i + k - 1];
      const bool joins = m.kind == MoveKind::Feed && std::abs(m.to.z - at.z) <= kSameHeight &&
                         (k == 1 || (m.comment.empty() && m.feed == first.feed && m.spindle == first.spindle &&
                                     m.process_on == first.process_on)) &&
                         norm(xy(m.to) - points.back()) >= kShortestChord;
      if (!joins) break;
      points.push_back(xy(m.to));
      if (k < min_chords) continue;
      std::optional<ArcFit> fit = fit_prefix(points, k, options);
      if (!fit) break;
      best = fit;
      best_k = k;
    }
    if (!best) {
      out.push_back(first);
      at = first.to;
      ++i;
      continue;
    }
    PathMove arc;
    arc.kind = best->sweep > 0 ? MoveKind::ArcCcw : MoveKind::ArcCw;
    arc.to = moves[i + best_k - 1].to;
    arc.centre = {best->centre.x, best->centre.y, at.z};
    arc.feed = first.feed;
    arc.spindle = first.spindle;
    arc.process_on = first.process_on;
    arc.comment = first.comment;
    out.push_back(std::move(arc));
    if (stats) {
      ++stats->arcs;
      stats->moves_replaced += best_k;
    }
    at = moves[i + best_k - 1].to;
    i += best_k;
  }
  return out;
}

Toolpath fit_arcs(Toolpath path, const ArcFitOptions& options, ArcFitStats* stats) {
  path.moves = fit_arcs(path.start, path.moves, options, stats);
  return path;
}

}  // namespace hybridctl::toolpaths

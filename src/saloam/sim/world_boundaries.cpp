// Hedges and fences (see world_builder.hpp): along the back of the
// sidewalk wherever no building stands, and along the plots' property lines;
// each placed as a run of short pieces, with shrubs or a hedge behind some
// fences.

#include <algorithm>
#include <cmath>

#include "saloam/core/semantic_classes.hpp"
#include "saloam/sim/world_builder.hpp"

namespace saloam {

using namespace world_building;

// Hedges and fences along the back of the sidewalk wherever no building
// stands there: streets in KITTI are lined with them.
void WorldBuilder::place_boundaries() {
  for (int side = -1; side <= 1; side += 2) {
    Rng rng(hash3(seed_, kSaltFences, static_cast<std::uint64_t>(side + 5)));
    walk(rng.uniform(0, 10), [&](const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double s) -> double {
      return boundary_run(p, dir, s, side, rng);
    });
  }
}

double WorldBuilder::boundary_run(const Eigen::Vector2d& p, const Eigen::Vector2d& dir, double s, int side, Rng& rng) {
  const Eigen::Vector2d left(-dir.y(), dir.x());
  const Eigen::Vector2d probe = p + side * left * 7.0;
  const bool rural = w_->zone_at(probe.x(), probe.y()).sidewalk == 0;
  const double length = rng.uniform(6, 30);
  const double pick = rng.uniform();
  if (pick < (rural ? 0.03 : 0.04)) return length;  // open
  // Country roads: wide belts of shrubs along the field edges.
  const double half_w = rural ? rng.uniform(0.6, 1.8) : rng.uniform(0.35, 0.8);
  // Street side of the hedge or fence just behind the sidewalk, or
  // behind a country road's shoulder (rect_free keeps objects
  // kRoadsideMargin off a road without sidewalk).
  const double gap = line_gap(rural) + rng.uniform(0.0, rural ? 0.4 : 0.15);
  const bool hedge = pick < (rural ? 0.85 : 0.5);
  const double hedge_height = rng.uniform(1.4, rural ? 4.0 : 2.8);
  const FenceStyle fence = fence_style(rng.uniform(1.0, 2.2), 0.3, rng);
  const bool planted = !hedge && rng.chance(rural ? 0.6 : 0.85);
  const double depth = hedge ? half_w : kFenceCheckHalfWidth;
  const std::vector<RunPiece> placed = along_street(s, side, length, gap + depth, [&](const RunPiece& piece) {
    return hedge ? add_hedge_piece(piece.c, piece.axis, piece.half_length, half_w, hedge_height, rng)
                 : add_fence_piece(piece.c, piece.axis, piece.half_length, fence);
  });
  if (placed.empty()) return 2.0;
  if (planted) {
    for (const RunPiece& piece : placed) planting_behind(piece.c, piece.axis, piece.away, piece.half_length, rng);
  }
  return length + (rng.chance(0.75) ? 0.0 : rng.uniform(1, 4));
}

bool WorldBuilder::add_hedge(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, double half_width,
                             double height, Rng& rng) {
  return in_pieces(c, axis, half_length, [&](const Eigen::Vector2d& pc, double half) {
           return add_hedge_piece(pc, axis, half, half_width, height, rng);
         }) > 0;
}

bool WorldBuilder::add_hedge_piece(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, double half_width,
                                   double height, Rng& rng) {
  if (!rect_free(c, axis, half_length, half_width, kLineClearance, false)) return false;
  const double g = ground(c);
  Primitive h = box(cls::kVegetation, c, axis, half_length, half_width, g - 0.1, g + height, rng.uniform(0.38, 0.5));
  h.mean_free_path = 0.3f;
  w_->add_object(h);
  mark_rect(c, axis, half_length, half_width);
  return true;
}

WorldBuilder::FenceStyle WorldBuilder::fence_style(double height, double chain_link, Rng& rng) {
  FenceStyle f;
  f.chain_link = rng.chance(chain_link);
  f.height = height;
  f.remission = rng.uniform(0.2, 0.5);
  return f;
}

bool WorldBuilder::add_fence(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, double height,
                             double chain_link, Rng& rng) {
  const FenceStyle style = fence_style(height, chain_link, rng);
  return in_pieces(c, axis, half_length, [&](const Eigen::Vector2d& pc, double half) {
           return add_fence_piece(pc, axis, half, style);
         }) > 0;
}

bool WorldBuilder::add_fence_piece(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, double half_length, const FenceStyle& style) {
  if (!rect_free(c, axis, half_length, kFenceCheckHalfWidth, kLineClearance, false)) return false;
  const double g = ground(c);
  Primitive f = box(cls::kFence, c, axis, half_length, 0.04, g, g + style.height, style.remission);
  if (style.chain_link) {
    f.half_y = 0.2f;
    f.mean_free_path = 1.0f;
  }
  w_->add_object(f);
  mark_rect(c, axis, half_length, kFenceCheckHalfWidth);
  return true;
}

void WorldBuilder::planting_behind(const Eigen::Vector2d& c, const Eigen::Vector2d& axis, const Eigen::Vector2d& away,
                                   double half_length, Rng& rng) {
  if (rng.chance(0.45)) {
    const double hw = rng.uniform(0.4, 0.9);
    add_hedge(c + away * (0.45 + hw), axis, half_length, hw, rng.uniform(1.2, 2.8), rng);
    return;
  }
  for (double u = -half_length + 0.8; u < half_length - 0.5; u += rng.uniform(1.5, 3.5)) {
    const double r = rng.uniform(0.6, 1.6);
    const Eigen::Vector2d b = c + u * axis + away * (0.4 + r);
    if (!rect_free(b, {1, 0}, r, r, 0.1, false)) continue;
    add_bush(b, r, rng);
    mark_rect(b, {1, 0}, r, r);
  }
}

}  // namespace saloam

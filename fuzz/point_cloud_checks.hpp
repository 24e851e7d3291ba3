#pragma once
// The contract of every point cloud reader (PCD, PLY, PointCloud2): a cloud
// of finite points whose optional fields have one entry per point.

#include <cmath>

#include "fuzz_support.hpp"
#include "saloam/io/point_fields.hpp"

namespace saloam::fuzz {

inline void check_decoded_cloud(const DecodedCloud& d) {
  const LabelledCloud& c = d.cloud;
  SALOAM_FUZZ_CHECK(!c.empty());
  SALOAM_FUZZ_CHECK(c.size() <= d.points_in_file);
  SALOAM_FUZZ_CHECK(c.remission.size() == c.size() && c.label.size() == c.size() && c.instance.size() == c.size());
  SALOAM_FUZZ_CHECK(c.ring.empty() || c.ring.size() == c.size());
  SALOAM_FUZZ_CHECK(c.time.empty() || c.time.size() == c.size());
  SALOAM_FUZZ_CHECK(d.fields.starts_with("x y z"));
  for (std::size_t i = 0; i < c.size(); ++i) {
    SALOAM_FUZZ_CHECK(c.points[i].allFinite());
    SALOAM_FUZZ_CHECK(std::isfinite(c.remission[i]));
    if (!c.time.empty()) SALOAM_FUZZ_CHECK(std::isfinite(c.time[i]));
  }
}

}  // namespace saloam::fuzz

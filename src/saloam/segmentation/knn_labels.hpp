#pragma once
// From pixel classes back to point classes: RangeNet++'s k-nearest-neighbour
// clean-up (Milioto et al., IROS 2019, Sec. III-D). A range image shows one
// point per pixel; the others behind it (and every point near a boundary,
// where the network's coarse output bleeds across objects) take the majority
// class of the k pixels in a window around their own whose ranges are
// nearest to theirs. A point's own pixel counts with distance 0; ranges
// farther than `cutoff` do not vote; each window position's range difference
// is scaled by 1 - g, g a Gaussian of the pixel offset (RangeNet++'s
// inverse Gaussian weighting, which prefers near pixels among equal ranges).
// Beyond RangeNet++: the window wraps around in azimuth (column 0 and the
// last column are neighbours), and a point without any vote keeps its
// pixel's class.

#include <cstdint>
#include <vector>

#include "saloam/segmentation/range_projection.hpp"

namespace saloam {

struct KnnOptions {
  int k = 5;             ///< neighbours that vote (RangeNet++: 5)
  int window = 5;        ///< odd side of the search window [pixels] (RangeNet++: 5)
  double cutoff = 1.0;   ///< [m] largest range difference that votes (RangeNet++: 1.0)
  double sigma = 1.0;    ///< [pixels] of the Gaussian weighting (RangeNet++: 1.0)
};

/// Class of every point of the projected scan. `pixel_class` holds one class
/// per pixel of `image` (any value for pixels without a point); `classes` is
/// the number of classes; class 0 (unlabeled) never wins a vote. Points
/// without a pixel get class 0.
std::vector<std::int16_t> point_classes(const RangeImage& image, const std::vector<std::int16_t>& pixel_class,
                                        const std::vector<float>& point_range, int classes,
                                        const KnnOptions& options);

/// Range of every point (the distances the vote compares with the image's).
std::vector<float> point_ranges(const LabelledCloud& cloud);

}  // namespace saloam

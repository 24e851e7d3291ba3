#include "saloam/sim/label_noise.hpp"

#include <array>
#include <cmath>

#include "saloam/core/error.hpp"

namespace saloam {
namespace {

// Learning class ids (SemanticKITTI order).
enum L : std::uint8_t {
  kCar = 1, kBicycle, kMotorcycle, kTruck, kOtherVehicle, kPerson, kBicyclist, kMotorcyclist, kRoad, kParking,
  kSidewalk, kOtherGround, kBuilding, kFence, kVegetation, kTrunk, kTerrain, kPole, kTrafficSign
};

struct Confusion {
  double rate;                    // chance that a blob of this class is mislabelled
  std::array<std::uint8_t, 3> to; // what it is mistaken for (first = most likely)
};

// Rates loosely follow where RangeNet++ is weak: parking, other-ground,
// trucks, other vehicles, fences, trunks, poles and signs.
Confusion confusion_of(std::uint8_t c) {
  switch (c) {
    case kCar: return {0.04, {kTruck, kOtherVehicle, kCar}};
    case kTruck: return {0.5, {kCar, kOtherVehicle, kBuilding}};
    case kOtherVehicle: return {0.4, {kCar, kTruck, kBuilding}};
    case kPerson: return {0.15, {kBicyclist, kPole, kVegetation}};
    case kRoad: return {0.03, {kParking, kSidewalk, kRoad}};
    case kParking: return {0.35, {kRoad, kSidewalk, kTerrain}};
    case kSidewalk: return {0.12, {kRoad, kParking, kTerrain}};
    case kOtherGround: return {0.5, {kSidewalk, kTerrain, kRoad}};
    case kBuilding: return {0.06, {kFence, kVegetation, kBuilding}};
    case kFence: return {0.3, {kBuilding, kVegetation, kTerrain}};
    case kVegetation: return {0.06, {kTerrain, kTrunk, kBuilding}};
    case kTrunk: return {0.3, {kVegetation, kPole, kTrunk}};
    case kTerrain: return {0.12, {kVegetation, kSidewalk, kTerrain}};
    case kPole: return {0.2, {kTrunk, kTrafficSign, kBuilding}};
    case kTrafficSign: return {0.2, {kPole, kBuilding, kPole}};
    default: return {0.3, {kBuilding, kFence, kBuilding}};
  }
}

/// Ground-truth learning class per range-image cell (kNoReturn where none).
class ClassImage {
 public:
  static constexpr std::uint8_t kNoReturn = 0xFF;
  ClassImage(int beams, int columns)
      : beams_(beams), columns_(columns),
        cells_(static_cast<std::size_t>(beams) * static_cast<std::size_t>(columns), kNoReturn) {}
  [[nodiscard]] int beams() const { return beams_; }
  [[nodiscard]] int columns() const { return columns_; }
  [[nodiscard]] std::uint8_t at(int ring, int column) const { return cells_[cell(ring, column)]; }
  void set(int ring, int column, std::uint8_t c) { cells_[cell(ring, column)] = c; }

 private:
  [[nodiscard]] std::size_t cell(int ring, int column) const {
    return static_cast<std::size_t>(ring) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(column);
  }
  int beams_, columns_;
  std::vector<std::uint8_t> cells_;
};

/// Each point's learning class, also written into `image`; unlabelled
/// structure counts as building (the network calls it something solid).
std::vector<std::uint8_t> true_classes(const SimulatedScan& scan, ClassImage& image) {
  std::vector<std::uint8_t> truth(scan.cloud.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    std::uint8_t c = to_learning_class(scan.cloud.label[i]);
    if (c == 0) c = kBuilding;  // other-structure etc.
    truth[i] = c;
    image.set(scan.ring[i], scan.column[i], c);
  }
  return truth;
}

/// 1. Blurry class boundaries: range-image networks smear labels across
/// edges; a point takes a neighbour's other class the more likely the more of
/// its neighbourhood (adjacent rings, +-boundary_columns) has other classes.
void blur_boundaries(const SimulatedScan& scan, const ClassImage& image, const std::vector<std::uint8_t>& truth,
                     const LabelNoiseOptions& options, Rng& rng, std::vector<std::uint8_t>& out) {
  const int beams = image.beams(), columns = image.columns();
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const int r = scan.ring[i], c = scan.column[i];
    std::array<std::uint8_t, 16> other{};
    int n_other = 0, n_seen = 0;
    for (int rr = std::max(r - 1, 0); rr <= std::min(r + 1, beams - 1); ++rr) {
      for (int dc = -options.boundary_columns; dc <= options.boundary_columns; ++dc) {
        if (rr == r && dc == 0) continue;
        int cc = c + dc;  // wraps around the turn
        if (cc < 0) cc += columns;
        if (cc >= columns) cc -= columns;
        const std::uint8_t k = image.at(rr, cc);
        if (k == ClassImage::kNoReturn) continue;
        ++n_seen;
        if (k != truth[i] && n_other < 16) other[static_cast<std::size_t>(n_other++)] = k;
      }
    }
    const double u = rng.uniform(), v = rng.uniform();
    const double share = static_cast<double>(n_other) / static_cast<double>(n_seen);
    if (n_other > 0 && u < options.boundary_flip * share) out[i] = other[static_cast<std::size_t>(v * n_other)];
  }
}

/// 2. Correlated confusions between similar classes, blob by blob: every
/// point of one class in one block of the range image shares the outcome
/// (drawn from the block's own seed; remembered while the points, stored
/// ring by ring, stay in the same block and class).
void confuse_blobs(const SimulatedScan& scan, const std::vector<std::uint8_t>& truth, std::uint64_t seed,
                   const LabelNoiseOptions& options, std::vector<std::uint8_t>& out) {
  struct Blob {
    int block_ring = -1, block_column = -1;
    std::uint8_t truth = 0;
    std::uint8_t label = 0;  // what its points are called; 0 = their true class
  } blob;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const int block_ring = scan.ring[i] / options.block_rings, block_column = scan.column[i] / options.block_columns;
    if (block_ring != blob.block_ring || block_column != blob.block_column || truth[i] != blob.truth) {
      blob = {block_ring, block_column, truth[i], 0};
      Rng draw(hash_combine(seed, hash3(static_cast<std::uint64_t>(block_ring), static_cast<std::uint64_t>(block_column), truth[i])));
      const Confusion conf = confusion_of(truth[i]);
      if (draw.uniform() < conf.rate * options.confusion_scale) {
        const double pick = draw.uniform();
        blob.label = conf.to[pick < 0.6 ? 0 : (pick < 0.85 ? 1 : 2)];
      }
    }
    if (blob.label != 0) out[i] = blob.label;
  }
}

/// 3. A few plainly wrong labels, drawn from the common classes (networks
/// do not hallucinate rare ones like signs out of nothing).
void add_wrong_labels(const LabelNoiseOptions& options, Rng& rng, std::vector<std::uint8_t>& out) {
  constexpr std::array<std::uint8_t, 7> kCommon{kRoad, kSidewalk, kBuilding, kVegetation, kTerrain, kCar, kFence};
  for (auto& label : out) {
    const double u = rng.uniform(), v = rng.uniform();
    if (u < options.random_label) label = kCommon[static_cast<std::size_t>(v * kCommon.size())];
  }
}

}  // namespace

std::vector<std::uint16_t> emulate_segmentation(const SimulatedScan& scan, int beams, int columns, std::uint64_t seed,
                                                const LabelNoiseOptions& options) {
  const std::size_t n = scan.cloud.size();
  if (scan.ring.size() != n || scan.column.size() != n) throw ConfigError("scan without range-image indices");
  if (beams <= 0 || columns <= 0 || options.boundary_columns < 0 || options.boundary_columns >= columns ||
      options.block_rings <= 0 || options.block_columns <= 0) {
    throw ConfigError("label noise: range image or neighbourhood sizes out of range");
  }
  ClassImage image(beams, columns);
  const std::vector<std::uint8_t> truth = true_classes(scan, image);
  std::vector<std::uint8_t> out(truth);
  Rng rng(hash_combine(seed, 0x1abe1ull));
  blur_boundaries(scan, image, truth, options, rng, out);
  confuse_blobs(scan, truth, seed, options, out);
  add_wrong_labels(options, rng, out);
  std::vector<std::uint16_t> labels(n);
  for (std::size_t i = 0; i < n; ++i) labels[i] = from_learning_class(out[i]);
  return labels;
}

}  // namespace saloam

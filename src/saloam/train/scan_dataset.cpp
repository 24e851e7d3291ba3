#include "saloam/train/scan_dataset.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <mutex>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/core/files.hpp"
#include "saloam/core/output_file.hpp"
#include "saloam/core/frame_range.hpp"
#include "saloam/core/hash.hpp"
#include "saloam/core/progress.hpp"
#include "saloam/core/semantic_classes.hpp"
#include "saloam/io/sequence.hpp"
#include "saloam/io/sequence_source.hpp"
#include "saloam/segmentation/segmenter.hpp"

namespace saloam {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;
constexpr char kCacheMagic[] = "saloam-scans-1";

// ---- building ----

/// Builds scans[k] = make(k) in parallel with a progress bar.
template <class Make>
std::vector<TrainingScan> build_all(std::size_t count, const std::string& label, bool show_progress, Make&& make) {
  std::vector<TrainingScan> scans(count);
  ProgressBar progress(count, label, show_progress);
  std::mutex mutex;
  tbb::parallel_for(std::size_t{0}, count, [&](std::size_t k) {
    if (stop_requested()) return;
    scans[k] = make(k);
    const std::lock_guard lock(mutex);
    progress.advance();
  });
  progress.finish();
  return scans;
}

TrainingScan labelled_scan(const LabelledCloud& cloud, const FeatureConfig& rings) {
  const PointRings found = point_rings(cloud, rings);
  return compact_scan(cloud, found.ring, found.beams);
}

std::vector<TrainingScan> simulated_scans(const SourceSpec& spec, const FeatureConfig& rings, bool show_progress) {
  const SimulatedSequence sequence(simulation_options(spec));
  return build_all(sequence.size(), "scans of " + spec.name(), show_progress,
                   [&](std::size_t k) { return labelled_scan(sequence.render(k).cloud, rings); });
}

std::vector<TrainingScan> folder_scans(const SourceSpec& spec, const FeatureConfig& rings, bool show_progress) {
  SequenceOptions options;
  if (!spec.labels.empty()) options.labels_dir = spec.labels;
  const SequenceReader reader(spec.path, options);
  if (!reader.has_labels()) throw InputError(spec.path, "no labels (labels/ or the recipe's labels: folder)");
  const auto [first, end] = FrameRange::parse(spec.frames, "frames").clip(reader.size(), "frames");
  std::vector<std::size_t> frames;
  for (std::size_t i = first; i < end; i += spec.frame_step) frames.push_back(i);
  // Remission in 0..1 as every run reads it (io/intensity_scale.hpp): one
  // range for the folder, from its first scan.
  const IntensityScale scale = sequence_intensity_scale(reader);
  if (scale.divisor != 1.0F) spdlog::info("{}: {}", spec.name(), scale.note());
  return build_all(frames.size(), "scans of " + spec.name(), show_progress, [&](std::size_t k) {
    LabelledCloud cloud = reader.load_scan(frames[k]);
    scale.apply(cloud);
    return labelled_scan(cloud, rings);
  });
}

// ---- cache: magic, key, scans; written to a temporary name and renamed ----

template <class T>
void write_vector(std::ostream& out, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  out.write(reinterpret_cast<const char*>(&n), sizeof n);
  out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
}

// A vector as write_vector() wrote it; false when the stream ends or fails
// first, or it claims more than `max_size` elements or more bytes than are left.
template <class T>
bool read_vector(std::istream& in, std::vector<T>& v, std::uint64_t max_size, std::uint64_t& bytes_left) {
  std::uint64_t n = 0;
  if (bytes_left < sizeof n || !in.read(reinterpret_cast<char*>(&n), sizeof n) || n > max_size) return false;
  bytes_left -= sizeof n;
  if (n * sizeof(T) > bytes_left) return false;
  bytes_left -= n * sizeof(T);
  v.resize(n);
  return static_cast<bool>(in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T))));
}

std::string cache_key(const SourceSpec& spec, const FeatureConfig& rings) {
  nlohmann::json key{{"source", spec.to_json()},
                     {"ring_rows", 2},  // version of point_rings(): rows of missing rings
                     {"rings", {rings.num_beams, rings.ring_from_point_order, rings.sweep_start_azimuth_deg,
                                rings.sweep_clockwise, rings.sweep_duration}}};
  // Folders' remission is brought to 0..1 since version 1 (0..255 files were clipped before).
  if (spec.kind == SourceSpec::Kind::kFolder) key["intensity_scale"] = 1;
  return key.dump();
}

// The cached scans when `file` holds them for `key`; nullopt when there is
// none, it is stale, or it is damaged (a warning: it is then rebuilt). Every
// read is checked, and no length is trusted beyond the file's size.
std::optional<std::vector<TrainingScan>> read_cache(const fs::path& file, const std::string& key) {
  if (!path_taken(file)) return std::nullopt;
  require_file(file, "scan cache");  // a folder or a FIFO in its place is an error, never waited on
  std::error_code error;
  std::uint64_t bytes_left = fs::file_size(file, error);
  std::ifstream in(file, std::ios::binary);
  if (error || !in) throw InputError(file, "cannot read the scan cache");
  const auto damaged = [&file]() -> std::optional<std::vector<TrainingScan>> {
    spdlog::warn("{}: damaged or cut scan cache; rebuilding it", plain_error_text(file.string()));
    return std::nullopt;
  };
  std::vector<char> magic, stored_key;
  if (!read_vector(in, magic, 64, bytes_left) || std::string(magic.begin(), magic.end()) != kCacheMagic) return damaged();
  if (!read_vector(in, stored_key, 1 << 20, bytes_left)) return damaged();
  if (std::string(stored_key.begin(), stored_key.end()) != key) return std::nullopt;  // stale
  std::uint64_t count = 0;
  if (bytes_left < sizeof count || !in.read(reinterpret_cast<char*>(&count), sizeof count) || count > 10'000'000)
    return damaged();
  bytes_left -= sizeof count;
  std::vector<TrainingScan> scans;
  constexpr std::uint64_t kMaxPoints = 10'000'000;
  for (std::uint64_t k = 0; k < count; ++k) {
    TrainingScan s;
    std::vector<std::int32_t> beams;
    if (!read_vector(in, beams, 1, bytes_left) || beams.size() != 1 || !read_vector(in, s.xyz, kMaxPoints, bytes_left) ||
        !read_vector(in, s.remission, kMaxPoints, bytes_left) || !read_vector(in, s.target, kMaxPoints, bytes_left) ||
        !read_vector(in, s.ring, kMaxPoints, bytes_left))
      return damaged();
    s.beams = beams[0];
    const std::size_t n = s.xyz.size();
    if (s.remission.size() != n || s.target.size() != n || s.ring.size() != n) return damaged();
    scans.push_back(std::move(s));
  }
  if (bytes_left != 0) return damaged();
  return scans;
}

void write_cache(const fs::path& file, const std::string& key, const std::vector<TrainingScan>& scans) {
  AtomicFile cache(file);
  {
    std::ostream& out = cache.stream();
    write_vector(out, std::vector<char>(kCacheMagic, kCacheMagic + sizeof kCacheMagic - 1));
    write_vector(out, std::vector<char>(key.begin(), key.end()));
    const std::uint64_t count = scans.size();
    out.write(reinterpret_cast<const char*>(&count), sizeof count);
    for (const auto& s : scans) {
      write_vector(out, std::vector<std::int32_t>{s.beams});
      write_vector(out, s.xyz);
      write_vector(out, s.remission);
      write_vector(out, s.target);
      write_vector(out, s.ring);
    }
  }
  cache.commit();
}

// ---- augmentation ----

struct Augmented {
  LabelledCloud cloud;
  std::vector<std::int16_t> ring;
  std::vector<std::uint8_t> target;
};

Eigen::Matrix3f tilt_and_yaw(const ScanAugmentOptions& a, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> tilt(-a.max_tilt_deg * kPi / 180, a.max_tilt_deg * kPi / 180);
  std::uniform_real_distribution<double> yaw(0.0, a.rotate ? 2 * kPi : 0.0);
  const double roll = tilt(rng), pitch = tilt(rng), heading = yaw(rng);
  return (Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix()
      .cast<float>();
}

/// Occluded azimuth sectors: (start, width) in radians and the first ring hidden.
struct Occluder {
  double start, width;
  int first_ring;
};

std::vector<Occluder> draw_occluders(const ScanAugmentOptions& a, int beams, std::mt19937_64& rng) {
  std::vector<Occluder> out;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  if (unit(rng) >= a.occlusion) return out;
  const int count = 1 + static_cast<int>(unit(rng) * 3.0);
  for (int i = 0; i < count; ++i)
    out.push_back({unit(rng) * 2 * kPi, (5.0 + 35.0 * unit(rng)) * kPi / 180,
                   static_cast<int>(unit(rng) * beams)});
  return out;
}

bool occluded(const std::vector<Occluder>& occluders, double azimuth, int ring) {
  for (const auto& o : occluders) {
    const double offset = std::fmod(azimuth - o.start + 4 * kPi, 2 * kPi);
    if (ring >= o.first_ring && offset < o.width) return true;
  }
  return false;
}

/// The remission transform r -> a r^g + b + noise, or a constant.
struct RemissionMap {
  bool constant = false;
  float gain = 1, gamma = 1, offset = 0, noise = 0;
};

RemissionMap draw_remission(const ScanAugmentOptions& a, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  RemissionMap m;
  m.constant = unit(rng) < a.remission_constant;
  m.gamma = static_cast<float>(std::exp((2 * unit(rng) - 1) * std::log(a.remission_gamma)));
  m.gain = static_cast<float>(1 + a.remission_gain * (2 * unit(rng) - 1));
  m.offset = static_cast<float>(a.remission_offset * (2 * unit(rng) - 1));
  m.noise = static_cast<float>(a.remission_noise * unit(rng));
  return m;
}

Augmented augment(const TrainingScan& scan, const ScanAugmentOptions& a, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  const Eigen::Matrix3f rotation = tilt_and_yaw(a, rng);
  const bool flip = unit(rng) < a.flip;
  const auto height = static_cast<float>(a.max_height_shift * (2 * unit(rng) - 1));
  const auto range_noise = static_cast<float>(a.max_range_noise * unit(rng));
  const double point_dropout = a.max_point_dropout * unit(rng);
  const double ring_dropout = a.max_ring_dropout * unit(rng);
  std::vector<std::uint8_t> ring_lost(static_cast<std::size_t>(std::max(scan.beams, 1)));
  for (auto& lost : ring_lost) lost = unit(rng) < ring_dropout;
  const auto occluders = draw_occluders(a, scan.beams, rng);
  const RemissionMap remission = draw_remission(a, rng);

  Augmented out;
  out.cloud.reserve(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const int ring = scan.ring[i] == kNoRing ? -1 : scan.ring[i];
    if (ring >= 0 && ring_lost[static_cast<std::size_t>(ring)]) continue;
    if (hash_to_unit(hash_combine(seed, i)) < point_dropout) continue;
    Eigen::Vector3f p(scan.xyz[i][0], scan.xyz[i][1], scan.xyz[i][2]);
    p *= kScanPositionStep;
    if (!occluders.empty() && occluded(occluders, std::atan2(p.y(), p.x()), ring)) continue;
    const float r = p.norm();
    if (r > 0.0f && range_noise > 0.0f) p *= (r + range_noise * normal(rng)) / r;
    if (flip) p.y() = -p.y();
    p = rotation * p;
    p.z() += height;
    float rem = remission.constant ? 0.0f
                                   : remission.gain * std::pow(scan.remission[i] / 255.0f, remission.gamma) +
                                         remission.offset + remission.noise * normal(rng);
    out.cloud.push_back(p, std::clamp(rem, 0.0f, 1.0f));
    out.ring.push_back(static_cast<std::int16_t>(ring));
    out.target.push_back(scan.target[i]);
  }
  return out;
}

/// LaserMix: the rings cut into `bands` bands of equal height; `a` keeps
/// its points in the even bands (and those without a ring) and takes the
/// partner's in the odd ones.
void mix_ring_bands(Augmented& a, const Augmented& partner, int beams, int bands) {
  const auto band = [&](std::int16_t ring) { return ring * bands / std::max(beams, 1); };
  Augmented mixed;
  mixed.cloud.reserve(a.cloud.size());
  const auto keep = [&](const Augmented& from, std::size_t i) {
    mixed.cloud.push_back(from.cloud.points[i], from.cloud.remission[i]);
    mixed.ring.push_back(from.ring[i]);
    mixed.target.push_back(from.target[i]);
  };
  for (std::size_t i = 0; i < a.cloud.size(); ++i)
    if (a.ring[i] < 0 || band(a.ring[i]) % 2 == 0) keep(a, i);
  for (std::size_t i = 0; i < partner.cloud.size(); ++i)
    if (partner.ring[i] >= 0 && band(partner.ring[i]) % 2 == 1) keep(partner, i);
  a = std::move(mixed);
}

}  // namespace

TrainingScan compact_scan(const LabelledCloud& cloud, const std::vector<std::int16_t>& ring, int beams) {
  TrainingScan scan;
  scan.beams = beams;
  const float limit = 32767 * kScanPositionStep;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() >= limit) continue;
    scan.xyz.push_back({static_cast<std::int16_t>(std::lround(p.x() / kScanPositionStep)),
                        static_cast<std::int16_t>(std::lround(p.y() / kScanPositionStep)),
                        static_cast<std::int16_t>(std::lround(p.z() / kScanPositionStep))});
    scan.remission.push_back(static_cast<std::uint8_t>(std::lround(std::clamp(cloud.remission[i], 0.0f, 1.0f) * 255)));
    scan.target.push_back(to_learning_class(cloud.label[i]));
    scan.ring.push_back(ring[i] >= 0 && ring[i] < kNoRing ? static_cast<std::uint8_t>(ring[i]) : kNoRing);
  }
  return scan;
}

TrainingScanSet build_training_scans(const SourceSpec& spec, const FeatureConfig& rings,
                                 const std::optional<fs::path>& cache_dir, bool show_progress) {
  if (spec.kind == SourceSpec::Kind::kSimulated && spec.noisy_labels)
    throw InputError(spec.path, "segmentation trains on ground truth: set `labels: gt` (" + spec.name() + ")");
  TrainingScanSet sequence{spec.name(), {}, spec.weight};
  const std::string key = cache_key(spec, rings);
  const fs::path cache = cache_dir ? *cache_dir / (spec.name() + ".scans") : fs::path();
  if (cache_dir)
    if (auto cached = read_cache(cache, key)) {
      sequence.scans = std::move(*cached);
      return sequence;
    }
  sequence.scans = spec.kind == SourceSpec::Kind::kSimulated ? simulated_scans(spec, rings, show_progress)
                                                             : folder_scans(spec, rings, show_progress);
  if (cache_dir && !stop_requested()) write_cache(cache, key, sequence.scans);
  return sequence;
}

std::array<std::uint64_t, kNumLearningClasses> class_counts(const std::vector<TrainingScanSet>& sequences) {
  std::array<std::uint64_t, kNumLearningClasses> counts{};
  for (const auto& s : sequences) {
    std::array<std::uint64_t, kNumLearningClasses> set_counts{};
    for (const auto& scan : s.scans)
      for (const auto t : scan.target) ++set_counts[t < kNumLearningClasses ? t : 0];
    for (int c = 0; c < kNumLearningClasses; ++c)
      counts[c] += static_cast<std::uint64_t>(std::llround(static_cast<double>(set_counts[c]) * s.weight));
  }
  return counts;
}

LabelledCloud scan_cloud(const TrainingScan& scan) {
  LabelledCloud cloud;
  cloud.reserve(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i)
    cloud.push_back(Eigen::Vector3f(scan.xyz[i][0], scan.xyz[i][1], scan.xyz[i][2]) * kScanPositionStep,
                    scan.remission[i] / 255.0f);
  return cloud;
}

std::vector<std::int16_t> training_scan_rings(const TrainingScan& scan) {
  std::vector<std::int16_t> ring(scan.size());
  std::transform(scan.ring.begin(), scan.ring.end(), ring.begin(),
                 [](std::uint8_t r) { return r == kNoRing ? std::int16_t{-1} : static_cast<std::int16_t>(r); });
  return ring;
}

void fit_channel_statistics(const std::vector<TrainingScanSet>& sequences, ProjectionSpec& spec, std::size_t step) {
  const std::size_t channels = spec.channels.size();
  ProjectionSpec raw = spec;
  raw.means.assign(channels, 0.0f);
  raw.stds.assign(channels, 1.0f);
  std::vector<double> sum(channels), sum_sq(channels);
  double count = 0;
  std::size_t k = 0;
  for (const auto& s : sequences)
    for (const auto& scan : s.scans) {
      if (k++ % std::max<std::size_t>(step, 1) != 0) continue;
      const RangeImage image = project_scan(scan_cloud(scan), training_scan_rings(scan), scan.beams, raw);
      for (std::size_t px = 0; px < image.pixels(); ++px) {
        if (image.shown[px] < 0) continue;
        count += 1;
        for (std::size_t c = 0; c < channels; ++c) {
          const double v = image.data[c * image.pixels() + px];
          sum[c] += v;
          sum_sq[c] += v * v;
        }
      }
    }
  if (count < 2) throw ConfigError("no training scan has a point: cannot fit the channel statistics");
  for (std::size_t c = 0; c < channels; ++c) {
    // The mask is 1 on every pixel measured here: it keeps 0 / 1, so that it
    // tells the network which pixels have a point.
    if (spec.channels[c] == ImageChannel::kMask) {
      spec.means[c] = 0.0f;
      spec.stds[c] = 1.0f;
      continue;
    }
    const double mean = sum[c] / count;
    const double variance = std::max(sum_sq[c] / count - mean * mean, 0.0);
    spec.means[c] = static_cast<float>(mean);
    spec.stds[c] = static_cast<float>(std::max(std::sqrt(variance), 1e-3));
  }
}

TrainingSample make_training_sample(const TrainingScan& scan, const ProjectionSpec& spec,
                                    const ScanAugmentOptions& augment_options, std::uint64_t seed, int crop_columns,
                                    const TrainingScan* partner) {
  Augmented a = augment(scan, augment_options, seed);
  if (partner != nullptr && partner->beams == scan.beams &&
      hash_to_unit(hash_combine(seed, 0x313full)) < augment_options.mix) {
    const int bands = 2 + static_cast<int>(hash_combine(seed, 0xba5dull) % 5);
    mix_ring_bands(a, augment(*partner, augment_options, hash_combine(seed, 0x9a27ull)), scan.beams, bands);
  }
  const RangeImage image = project_scan(a.cloud, a.ring, scan.beams, spec);
  const int cols = crop_columns > 0 && crop_columns < image.cols ? crop_columns : image.cols;
  const int first = cols == image.cols ? 0 : static_cast<int>(hash_combine(seed, 0x5eedull) % static_cast<std::uint64_t>(image.cols));
  TrainingSample sample;
  sample.rows = image.rows;
  sample.cols = cols;
  sample.image.resize(static_cast<std::size_t>(image.channels) * image.rows * cols);
  sample.target.assign(static_cast<std::size_t>(image.rows) * cols, 0);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < cols; ++x) {
      const auto src = static_cast<std::size_t>(y * image.cols + (first + x) % image.cols);
      const auto dst = static_cast<std::size_t>(y * cols + x);
      for (int c = 0; c < image.channels; ++c)
        sample.image[static_cast<std::size_t>(c) * sample.target.size() + dst] =
            image.data[static_cast<std::size_t>(c) * image.pixels() + src];
      if (image.shown[src] >= 0) sample.target[dst] = a.target[static_cast<std::size_t>(image.shown[src])];
    }
  return sample;
}

void set_augment_option(ScanAugmentOptions& augment, std::string_view name, std::string_view value) {
  bool found = false;
  const std::string text(value);
  visit_fields(augment, [&](std::string_view field, auto& member, std::string_view, auto... range) {
    if (field != name) return;
    found = true;
    using T = std::decay_t<decltype(member)>;
    if constexpr (std::is_same_v<T, bool>) {
      if (text != "true" && text != "false")
        throw ConfigError(fmt::format("--augment {}: expected true or false, not '{}'", name, text));
      member = text == "true";
    } else {
      static_assert(sizeof...(range) == 1);
      const Range r = (range, ...);
      std::size_t used = 0;
      double x = 0;
      try {
        x = std::stod(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != text.size() || !(x >= r.lo && x <= r.hi))
        throw ConfigError(fmt::format("--augment {}: expected a number in [{:g}, {:g}], not '{}'", name, r.lo, r.hi, text));
      member = x;
    }
  });
  if (!found) {
    std::vector<std::string> names;
    visit_fields(augment, [&](std::string_view field, auto&&...) { names.emplace_back(field); });
    throw ConfigError(fmt::format("--augment: unknown augmentation '{}' ({})", name, fmt::join(names, ", ")));
  }
}

}  // namespace saloam

#pragma once
// Point records with named, typed fields, as PCD, PLY and ROS PointCloud2
// describe them: what those three readers share. A record is `stride` bytes;
// each field has a name, a scalar type, a byte offset and an element count.
// Which fields become which part of a LabelledCloud:
//   x, y, z                        the point [m] (required; any numeric type)
//   intensity, else remission      LabelledCloud::remission, as stored (KITTI
//                                  scans hold 0..1, Velodyne drivers 0..255;
//                                  the sources bring it to 0..1, see
//                                  intensity_scale.hpp)
//   ring                           LabelledCloud::ring (beam index)
//   time, t, timestamp, offset_time LabelledCloud::time, see PointTimeUnits
//   label, instance                class and instance ids (low 16 bits)
// Other fields are skipped. Every point goes through io/point_checks.hpp:
// points with non-finite or out-of-range coordinates or rings are dropped
// (organised clouds mark missing returns with NaN), times clamped into the
// sweep, each counted and warned once per file.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "saloam/core/types.hpp"
#include "saloam/io/point_checks.hpp"

namespace saloam {

enum class ScalarType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kInt64, kUint64, kFloat32, kFloat64 };

[[nodiscard]] std::size_t scalar_size(ScalarType type);
[[nodiscard]] bool is_floating(ScalarType type);
/// "float32", "uint16", ...
[[nodiscard]] std::string_view scalar_name(ScalarType type);

struct PointField {
  std::string name;
  ScalarType type = ScalarType::kFloat32;
  std::size_t offset = 0;  ///< bytes from the record's start
  std::size_t count = 1;   ///< elements (only the first is read)
};

/// Reads one scalar at `p` as a double.
[[nodiscard]] double read_scalar(const std::byte* p, ScalarType type, bool big_endian);
/// Writes `value` at `p` (little-endian unless `big_endian`), converted to `type`.
void write_scalar(std::byte* p, ScalarType type, double value, bool big_endian);

/// How per-point time fields are read: integer fields are nanoseconds,
/// floating ones seconds (Velodyne's `time` float s, Ouster's `t` uint32 ns,
/// Livox's `offset_time` uint32 ns, Hesai's `timestamp` double s). Values
/// beyond kAbsoluteTimeThreshold seconds are absolute (since the epoch) and
/// are taken relative to the scan's timestamp, or to the earliest point when
/// the scan has none; smaller values are already relative to the sweep start,
/// which is the scan's timestamp.
inline constexpr double kAbsoluteTimeThreshold = 1e5;

/// A point cloud file's content: the cloud and what was found in it.
struct DecodedCloud {
  LabelledCloud cloud;
  std::string fields;                   ///< the fields taken, as named in the file ("x y z intensity ring t")
  std::size_t points_in_file = 0;       ///< before dropping non-finite points
  std::optional<double> time_reference; ///< absolute per-point times were made relative to this [s]
  /// The type of the field taken for the remission; none when the file has
  /// no intensity field (what intensity_scale.hpp decides the range by).
  std::optional<ScalarType> intensity_type;
  PointCheckCounts checks;              ///< what the point checks dropped or clamped
};

/// The record the writers (PCD, PLY scans, PointCloud2) write for a cloud,
/// packed: x y z intensity (float32), then ring (uint16) when the cloud has
/// rings and time (float32, [s] relative to the scan) when it has times.
struct ScanRecordLayout {
  std::vector<PointField> fields;
  std::size_t stride = 0;  ///< bytes of one record
  [[nodiscard]] static ScanRecordLayout of(const LabelledCloud& cloud);
  /// The value of field `field` (an index into `fields`) for point `i` of `cloud`.
  [[nodiscard]] static double value(const LabelledCloud& cloud, std::size_t i, std::size_t field);
};

/// Which fields of a record layout a LabelledCloud takes (indices into the
/// field list), found by name as above.
struct FieldRoles {
  std::size_t x = 0, y = 0, z = 0;
  std::optional<std::size_t> intensity, ring, time, label, instance;
  /// The roles of `fields`; InputError naming `file` when x, y or z is missing.
  static FieldRoles find(const std::vector<PointField>& fields, const std::filesystem::path& file);
  /// "x y z intensity ring time" as found (the names in the file).
  [[nodiscard]] std::string describe(const std::vector<PointField>& fields) const;
};

/// Collects points one record at a time and makes the cloud: drops points
/// with non-finite coordinates, converts times to seconds relative to the
/// scan (see kAbsoluteTimeThreshold).
class CloudAssembler {
 public:
  CloudAssembler(const std::vector<PointField>& fields, const FieldRoles& roles, std::size_t expected_points);

  /// One record in binary form (`record` holds at least the layout's bytes).
  void add_binary(const std::byte* record, bool big_endian);
  /// One record as one value per field (the first element of each), in field order.
  void add_values(std::span<const double> values);

  /// The cloud; `scan_stamp` is the scan's timestamp when the source has one
  /// (absolute per-point times are made relative to it). `file` names the
  /// input when no finite point is left (InputError).
  LabelledCloud finish(std::optional<double> scan_stamp, const std::filesystem::path& file);
  /// The absolute time the per-point times were taken relative to, when they
  /// were absolute (after finish()).
  [[nodiscard]] std::optional<double> absolute_reference() const { return absolute_reference_; }
  /// What the point checks dropped (so far) and clamped (after finish()).
  [[nodiscard]] const PointCheckCounts& checks() const { return checks_; }
  /// finish() with what a file's reader reports: the fields taken and the
  /// number of records in the file.
  DecodedCloud decoded(std::size_t points_in_file, std::optional<double> scan_stamp, const std::filesystem::path& file);

 private:
  void add(double x, double y, double z, double intensity, double ring, double time, double label, double instance);

  const std::vector<PointField>& fields_;
  FieldRoles roles_;
  double time_scale_ = 1.0;  ///< to seconds
  LabelledCloud cloud_;
  std::vector<double> raw_times_;
  PointCheckCounts checks_;
  std::size_t points_seen_ = 0;
  std::optional<double> absolute_reference_;
};


/// Parses a decimal number as written in ASCII PCD and PLY ("nan", "inf" accepted).
[[nodiscard]] std::optional<double> parse_number(std::string_view token);

}  // namespace saloam

#include "saloam/sources/pcap_source.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "saloam/core/error.hpp"
#include "saloam/sensors/ouster_frame.hpp"
#include "saloam/sensors/ouster_imu.hpp"
#include "saloam/sensors/packet_frames.hpp"
#include "saloam/sensors/velodyne_frame.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

constexpr double kNs = 1e-9;

/// Ouster lidar packets by frame id (sensors/ouster_frame.hpp).
class OusterDecoder final : public CaptureDecoder {
 public:
  OusterDecoder(const fs::path& metadata_file, OusterMetadata metadata)
      : metadata_file_(metadata_file), metadata_(std::move(metadata)), assembler_(metadata_), framer_(metadata_) {}

  void index(const UdpDatagram& d, std::vector<CaptureFrame>& done) override {
    if (!is_lidar(d)) return;
    ++lidar_packets_;
    if (!assembler_.format().check(d.payload).empty()) {
      assembler_.add(d.payload, scans_);  // counted as a bad packet
      return;
    }
    // Where the packets of each open frame lie (one entry per frame being filled).
    const std::uint32_t id = assembler_.format().frame_id(d.payload);
    const auto it = spans_.find(id);
    const bool fresh = it == spans_.end();
    if (fresh) {
      spans_.emplace(id, Span{d.offset, d.offset, d.time});
    } else {
      it->second.last = d.offset;
    }
    const std::size_t dropped = assembler_.dropped_packets();
    assembler_.add(d.payload, scans_);
    if (fresh && assembler_.dropped_packets() > dropped) spans_.erase(id);  // a late packet opens no frame
    take_indexed(done);
  }

  void index_end(std::vector<CaptureFrame>& done) override {
    if (auto last = assembler_.finish()) scans_.push_back(std::move(*last));
    take_indexed(done);
  }

  LabelledCloud read(PcapReader& reader, const CaptureFrame& frame) override {
    // The frame's own packets, through the frame assembly a live source uses too.
    framer_.restart();
    std::vector<PacketFrame> frames;
    UdpDatagram d;
    while (reader.next(d) && d.offset <= frame.last_offset) {
      if (framer_.is_lidar(d.payload, d.dst_port) && framer_.format().check(d.payload).empty() &&
          framer_.format().frame_id(d.payload) == frame.tag) {
        framer_.add(d.payload, d.dst_port, frames);
      }
    }
    framer_.finish(frames);
    return frames.empty() ? LabelledCloud{} : std::move(frames.front().cloud);
  }

  [[nodiscard]] std::vector<std::string> notes() const override {
    const OusterMetadata& m = metadata_;
    std::vector<std::string> out{
        fmt::format("sensor: Ouster {}{}, firmware {}, mode {}, profile {}", m.prod_line.empty() ? "?" : m.prod_line,
                    m.serial.empty() ? "" : fmt::format(" (serial {})", m.serial),
                    m.firmware.empty() ? "?" : m.firmware, m.lidar_mode, ouster_profile_name(m.profile)),
        fmt::format("metadata: {} ({} layout)", metadata_file_.string(), m.nested_layout ? "nested" : "flat"),
        fmt::format("columns: {} per frame ({} per packet, window {}..{}), {} beams", m.columns_per_frame,
                    m.columns_per_packet, m.column_window.first, m.column_window.second, m.pixels_per_column),
        fmt::format("packets: {} lidar packets, {} of the wrong size, {} late (dropped); {} of {} frames missing "
                    "columns ({} columns in all)",
                    lidar_packets_, assembler_.bad_packets(), assembler_.dropped_packets(), incomplete_frames_,
                    frames_, missing_columns_),
        "points: first returns (RANGE, REFLECTIVITY), time from each column's timestamp"};
    if (m.profile == OusterProfile::kRng19Rfl8Sig16Nir16Dual || m.profile == OusterProfile::kRng15Rfl8Nir8Dual ||
        m.profile == OusterProfile::kFusaRng15Rfl8Nir8Dual) {
      out.emplace_back("second returns of the dual-return profile are left out");
    }
    return out;
  }

  [[nodiscard]] std::string point_fields() const override { return framer_.point_fields(); }
  [[nodiscard]] std::string intensity_field() const override { return framer_.intensity_field(); }

 private:
  struct Span {
    std::int64_t first = 0, last = 0;
    double capture_time = 0.0;
  };

  [[nodiscard]] bool is_lidar(const UdpDatagram& d) const {
    return d.dst_port == metadata_.udp_port_lidar || d.payload.size() == assembler_.format().packet_size();
  }

  /// Frames the assembler finished, as index entries (frames without a valid column are left out).
  void take_indexed(std::vector<CaptureFrame>& done) {
    for (const auto& scan : scans_) {
      const auto span = spans_.find(scan.frame_id);
      const auto t0 = scan.first_valid_timestamp();
      if (span == spans_.end()) continue;
      if (!t0) {  // no valid column: no frame
        spans_.erase(span);
        continue;
      }
      ++frames_;
      const std::size_t expected = window_columns();
      if (scan.valid_columns < expected) {
        ++incomplete_frames_;
        missing_columns_ += expected - scan.valid_columns;
      }
      done.push_back({span->second.first, span->second.last, static_cast<double>(*t0) * kNs,
                      span->second.capture_time, scan.frame_id});
      spans_.erase(span);
    }
    scans_.clear();
  }

  [[nodiscard]] std::size_t window_columns() const {
    const auto [first, last] = metadata_.column_window;
    return first <= last ? last - first + 1 : metadata_.columns_per_frame - first + last + 1;
  }

  fs::path metadata_file_;
  OusterMetadata metadata_;
  OusterFrameAssembler assembler_;  ///< the index pass's
  OusterPacketFramer framer_;       ///< reading a frame again
  std::vector<OusterScan> scans_;
  std::map<std::uint32_t, Span> spans_;
  std::size_t lidar_packets_ = 0;
  std::size_t frames_ = 0;
  std::size_t incomplete_frames_ = 0;
  std::size_t missing_columns_ = 0;
};


/// Velodyne data packets cut into sweeps (sensors/velodyne_frame.hpp).
class VelodyneCaptureDecoder final : public CaptureDecoder {
 public:
  explicit VelodyneCaptureDecoder(const VelodyneDecoder& decoder) : assembler_(decoder), framer_(decoder) {}

  void index(const UdpDatagram& d, std::vector<CaptureFrame>& done) override {
    if (d.payload.size() != kVelodynePacketBytes) return;
    ++packets_;
    if (!mode_ && check_velodyne_packet(d.payload).empty()) mode_ = velodyne_tail(d.payload).byte_1204;
    const std::size_t begun = assembler_.frames_begun();
    frames_.clear();
    assembler_.add(d.payload, frames_);
    for (auto& frame : frames_) close_frame(frame, d.offset, done);
    if (assembler_.frames_begun() > begun) {
      starts_.push_back({d.offset, d.offset, 0.0, d.time, assembler_.last_start_block()});
    }
    last_offset_ = d.offset;
  }

  void index_end(std::vector<CaptureFrame>& done) override {
    if (auto last = assembler_.finish()) close_frame(*last, last_offset_, done);
  }

  LabelledCloud read(PcapReader& reader, const CaptureFrame& frame) override {
    // From the block where the frame began, through the frame assembly a live source uses too.
    framer_.restart();
    std::vector<PacketFrame> frames;
    UdpDatagram d;
    bool first = true;
    while (frames.empty() && reader.next(d) && d.offset <= frame.last_offset) {
      if (d.payload.size() != kVelodynePacketBytes) continue;
      framer_.add_from_block(d.payload, first ? frame.tag : 0, frames);
      first = false;
    }
    if (frames.empty()) framer_.finish(frames);
    return frames.empty() ? LabelledCloud{} : std::move(frames.front().cloud);
  }

  [[nodiscard]] std::vector<std::string> notes() const override {
    const VelodyneDecoder& decoder = assembler_.decoder();
    std::string mode = "single return";
    if (decoder.model() != VelodyneModel::kHdl64e && mode_) {
      mode = *mode_ == 0x39 ? "dual return (last returns kept)" : *mode_ == 0x38 ? "last return" : "strongest return";
    }
    return {fmt::format("sensor: Velodyne {}, {}", velodyne_model_name(decoder.model()), mode),
            fmt::format("calibration: {}", decoder.calibration().source),
            fmt::format("packets: {} data packets, {} malformed, about {} missing (gaps in their timestamps)", packets_,
                        assembler_.bad_packets(), assembler_.missing_packets()),
            "frames: cut where the azimuth passes 180 deg (behind the sensor); the first and last may be partial "
            "sweeps; points timed by the model's firing sequence"};
  }

  [[nodiscard]] std::string point_fields() const override { return framer_.point_fields(); }
  [[nodiscard]] std::string intensity_field() const override { return framer_.intensity_field(); }

 private:
  /// Pairs a finished frame with where it began.
  void close_frame(const VelodyneFrame& frame, std::int64_t last_offset, std::vector<CaptureFrame>& done) {
    if (starts_.empty()) return;
    CaptureFrame entry = starts_.front();
    starts_.erase(starts_.begin());
    if (frame.cloud.empty()) return;
    entry.last_offset = last_offset;
    entry.time = frame.time;
    done.push_back(entry);
  }

  VelodyneFrameAssembler assembler_;  ///< the index pass's
  VelodynePacketFramer framer_;       ///< reading a frame again
  std::vector<VelodyneFrame> frames_;
  std::vector<CaptureFrame> starts_;
  std::int64_t last_offset_ = 0;
  std::size_t packets_ = 0;
  std::optional<std::uint8_t> mode_;
};

bool is_json(const fs::path& file) { return file.extension() == ".json"; }

bool has_velodyne_packets(PcapReader& reader) {
  UdpDatagram d;
  for (int i = 0; i < 1000 && reader.next(d); ++i) {
    if (d.payload.size() == kVelodynePacketBytes) return true;
  }
  return false;
}

/// The longest NAME.json beside `capture` whose NAME begins the capture's name (digests left out).
std::optional<fs::path> json_beside(const fs::path& capture) {
  const std::string stem = capture.stem().string();
  std::optional<fs::path> best;
  std::error_code ec;
  const fs::path folder = capture.has_parent_path() ? capture.parent_path() : fs::path(".");
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const fs::path& p = entry.path();
    const std::string name = p.stem().string();
    if (!is_json(p) || name.ends_with("_digest") || !stem.starts_with(name)) continue;
    if (!best || name.size() > best->stem().string().size()) best = p;
  }
  return best;
}

/// The model of the first Velodyne data packet among the capture's first datagrams.
std::optional<VelodyneModel> velodyne_model(PcapReader& reader, const std::optional<fs::path>& calibration) {
  UdpDatagram d;
  for (int i = 0; i < 1000 && reader.next(d); ++i) {
    if (d.payload.size() != kVelodynePacketBytes || !check_velodyne_packet(d.payload).empty()) continue;
    if (auto model = velodyne_model_of(d.payload)) return model;
    if (calibration) return std::nullopt;  // told by the calibration's laser count
  }
  return std::nullopt;
}

std::unique_ptr<CaptureDecoder> velodyne_decoder(const fs::path& capture, std::optional<VelodyneModel> model,
                                                 const std::optional<fs::path>& calibration_file) {
  std::optional<VelodyneCalibration> calibration;
  if (calibration_file) calibration = read_velodyne_calibration(*calibration_file);
  if (!model && calibration) {
    for (auto m : {VelodyneModel::kVlp16, VelodyneModel::kHdl32e, VelodyneModel::kHdl64e}) {
      if (velodyne_lasers(m) == calibration->lasers.size()) model = m;
    }
  }
  if (!model) {
    throw InputError(capture, "Velodyne packets of no model saloam reads (VLP-16, HDL-32E, HDL-64E: product id 0x22, "
                              "0x21, or lower blocks 0xDDFF)");
  }
  if (!calibration) calibration = nominal_velodyne_calibration(*model);
  if (!calibration) {
    throw InputError(capture, fmt::format("a {} capture needs the sensor's calibration: --metadata CALIB.yaml "
                                          "(velodyne_pointcloud's format) or NAME.yaml beside NAME.pcap",
                                          velodyne_model_name(*model)));
  }
  if (calibration->lasers.size() != velodyne_lasers(*model)) {
    throw InputError(*calibration_file, fmt::format("calibration of {} lasers for a {} ({} lasers)",
                                                    calibration->lasers.size(), velodyne_model_name(*model),
                                                    velodyne_lasers(*model)));
  }
  return std::make_unique<VelodyneCaptureDecoder>(VelodyneDecoder(*model, std::move(*calibration)));
}

}  // namespace

std::optional<fs::path> find_capture_metadata(const fs::path& capture, const std::optional<fs::path>& given) {
  if (given) return given;
  std::error_code ec;
  for (const char* ext : {".json", ".yaml", ".yml"}) {
    fs::path beside = capture;
    beside.replace_extension(ext);
    if (fs::is_regular_file(beside, ec)) return beside;
  }
  return json_beside(capture);
}

PcapSource::PcapSource(fs::path capture, const SourceOptions& options)
    : capture_(std::move(capture)), reader_(std::make_unique<PcapReader>(capture_)) {
  if (options.labels && !options.ignore_labels) {
    throw InputError(*options.labels, "labels cannot be paired with the points of a packet capture (which come in "
                                      "no stored order): label it with --segment");
  }
  const auto metadata = find_capture_metadata(capture_, options.metadata);
  if (metadata && is_json(*metadata)) {
    decoder_ = std::make_unique<OusterDecoder>(*metadata, read_ouster_metadata(*metadata));
  } else {
    const bool velodyne = has_velodyne_packets(*reader_);
    if (!velodyne) {
      throw InputError(capture_, "no Velodyne data packets (1206 bytes) in the capture's first 1000 datagrams, and "
                                 "no Ouster metadata: an Ouster capture needs the sensor's metadata JSON "
                                 "(--metadata FILE, or NAME.json beside NAME.pcap)");
    }
    reader_ = std::make_unique<PcapReader>(capture_);
    const auto model = velodyne_model(*reader_, metadata);
    reader_ = std::make_unique<PcapReader>(capture_);
    decoder_ = velodyne_decoder(capture_, model, metadata);
  }
  intensity_ = choose_intensity_scale(options.intensity_scale, ScalarType::kUint8, {});
  if (!options.intensity_scale) intensity_.how = decoder_->intensity_field();
  info_.name = capture_.string();
  info_.format = "pcap";
  info_.rereadable = true;
  index_capture();
  info_.point_fields = decoder_->point_fields();
  auto notes = decoder_->notes();
  notes.push_back(intensity_.note());
  notes.emplace_back("extrinsics: none (a packet capture runs in the LiDAR frame)");
  info_.notes.insert(info_.notes.begin(), notes.begin(), notes.end());
  if (metadata && is_json(*metadata)) read_imu(*metadata);
}

// The Ouster's own IMU (sensors/ouster_imu.hpp): its stream described in the
// notes, and up from its accelerometer when it was still at the start.
void PcapSource::read_imu(const fs::path& metadata) {
  const OusterImuCalibration calibration = read_ouster_imu_calibration(metadata);
  const std::vector<ImuSample> samples = read_ouster_imu(capture_, calibration.udp_port_imu);
  if (samples.empty()) {
    info_.notes.push_back(fmt::format("IMU: no packets on port {}", calibration.udp_port_imu));
    return;
  }
  ImuStreamReport report = describe_imu_stream(samples, fmt::format("on port {}", calibration.udp_port_imu),
                                               calibration.imu_to_lidar_rotation(), "lidar");
  info_.notes.insert(info_.notes.end(), report.notes.begin(), report.notes.end());
  info_.imu_up = report.up;
}

PcapSource::~PcapSource() = default;

void PcapSource::index_capture() {
  UdpDatagram d;
  while (reader_->next(d)) decoder_->index(d, frames_);
  decoder_->index_end(frames_);
  if (frames_.empty()) {
    const auto notes = decoder_->notes();
    throw InputError(capture_, fmt::format("no complete frame in the capture ({})", fmt::join(notes, "; ")));
  }
  const bool sensor_times = std::adjacent_find(frames_.begin(), frames_.end(), [](const auto& a, const auto& b) {
                              return b.time <= a.time;
                            }) == frames_.end();
  for (const auto& f : frames_) info_.times.push_back(sensor_times ? f.time : f.capture_time);
  if (!sensor_times) {
    info_.notes.emplace_back("times: the capture's (the sensor's clock did not increase from frame to frame)");
  }
  // Capture times of equal stamps (microseconds) must still increase.
  for (std::size_t i = 1; i < info_.times.size(); ++i) {
    if (info_.times[i] <= info_.times[i - 1]) {
      throw InputError(capture_, fmt::format("frame {} is not later than frame {}", i, i - 1));
    }
  }
}

LabelledCloud PcapSource::scan(std::size_t i) {
  if (i >= frames_.size()) throw std::out_of_range(fmt::format("frame {} of {}", i, frames_.size()));
  reader_->seek(frames_[i].first_offset);
  LabelledCloud cloud = decoder_->read(*reader_, frames_[i]);
  intensity_.apply(cloud);
  return cloud;
}

}  // namespace saloam

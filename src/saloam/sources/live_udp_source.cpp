#include "saloam/sources/live_udp_source.hpp"

#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "saloam/core/cancellation.hpp"
#include "saloam/core/error.hpp"
#include "saloam/sensors/ouster_metadata.hpp"

namespace fs = std::filesystem;

namespace saloam {
namespace {

/// How often the receiver looks at the clock and the stop flag when no packet comes.
constexpr std::chrono::milliseconds kPollTick{50};
/// Datagrams taken at most between two looks at the stop flag (a few frames' worth).
constexpr std::size_t kDrainLimit = 1000;

std::optional<VelodyneModel> velodyne_model_named(const std::string& sensor) {
  if (sensor == "vlp16") return VelodyneModel::kVlp16;
  if (sensor == "hdl32e") return VelodyneModel::kHdl32e;
  if (sensor == "hdl64e") return VelodyneModel::kHdl64e;
  return std::nullopt;
}

std::unique_ptr<PacketFramer> ouster_framer(const fs::path& metadata, std::vector<std::string>& notes) {
  const OusterMetadata m = read_ouster_metadata(metadata);
  notes.push_back(fmt::format("sensor: Ouster {}, mode {}, profile {} (metadata {}); lidar packets to port {}",
                              m.prod_line.empty() ? "?" : m.prod_line, m.lidar_mode, ouster_profile_name(m.profile),
                              metadata.string(), m.udp_port_lidar));
  return std::make_unique<OusterPacketFramer>(m);
}

std::unique_ptr<PacketFramer> velodyne_framer(const std::string& url, VelodyneModel model,
                                              const std::optional<fs::path>& calibration_file,
                                              std::vector<std::string>& notes) {
  std::optional<VelodyneCalibration> calibration =
      calibration_file ? read_velodyne_calibration(*calibration_file) : nominal_velodyne_calibration(model);
  if (!calibration) {
    throw InputError(url, fmt::format("a {} needs its calibration: --metadata CALIB.yaml (velodyne_pointcloud's "
                                      "format)",
                                      velodyne_model_name(model)));
  }
  if (calibration->lasers.size() != velodyne_lasers(model)) {
    throw InputError(*calibration_file, fmt::format("calibration of {} lasers for a {} ({} lasers)",
                                                    calibration->lasers.size(), velodyne_model_name(model),
                                                    velodyne_lasers(model)));
  }
  notes.push_back(fmt::format("sensor: Velodyne {}; calibration: {}", velodyne_model_name(model), calibration->source));
  return std::make_unique<VelodynePacketFramer>(VelodyneDecoder(model, std::move(*calibration)));
}

std::string idle_text(double seconds) { return fmt::format("no packet for {:g} s (--idle-timeout)", seconds); }

}  // namespace

std::unique_ptr<PacketFramer> live_packet_framer(const std::string& url, const SourceOptions& options,
                                                 std::vector<std::string>& notes) {
  const std::string& sensor = options.live.sensor;
  if (options.metadata && options.metadata->extension() == ".json") return ouster_framer(*options.metadata, notes);
  if (const auto model = velodyne_model_named(sensor)) return velodyne_framer(url, *model, options.metadata, notes);
  if (sensor.starts_with("os")) {
    throw InputError(url, fmt::format("an Ouster sensor's packets ({}) need its metadata: --metadata META.json (the "
                                      "sensor serves it at http://SENSOR/api/v1/sensor/metadata)",
                                      sensor));
  }
  if (sensor.empty() || sensor == "auto" || sensor == "none") {
    throw InputError(url, "a live source needs the sensor whose packets arrive: --sensor vlp16, hdl32e or hdl64e "
                          "(Velodyne), or an Ouster's --metadata META.json");
  }
  throw InputError(url, fmt::format("--sensor {}: live packets are read from Velodyne VLP-16, HDL-32E, HDL-64E "
                                    "(--sensor vlp16, hdl32e, hdl64e) and Ouster sensors (--metadata META.json)",
                                    sensor));
}

LiveUdpSource::LiveUdpSource(const std::string& url, const SourceOptions& options)
    : receiver_(parse_udp_url(url), options.live.receive_buffer_bytes),
      options_(options.live),
      queue_(options.live.queue_frames) {
  if (options.labels && !options.ignore_labels) {
    throw InputError(*options.labels, "labels cannot be paired with live packets: label them with --segment");
  }
  std::vector<std::string> notes;
  framer_ = live_packet_framer(url, options, notes);
  intensity_ = choose_intensity_scale(options.intensity_scale, ScalarType::kUint8, {});
  if (!options.intensity_scale) intensity_.how = framer_->intensity_field();
  describe(std::move(notes));
  spdlog::info("listening on {} (receive buffer {:.1f} MiB, as the kernel reports it)", info_.name,
               receiver_.buffer_bytes() / 1048576.0);
  if (receiver_.buffer_bytes() < options.live.receive_buffer_bytes) {
    spdlog::warn("{}: the kernel granted a receive buffer of {:.1f} MiB, not the {:.0f} MiB asked (net.core.rmem_max "
                 "caps it; raise it with `sysctl -w net.core.rmem_max={}`, or run as root): packets that arrive while "
                 "the receiver is busy may be lost (frames then dropped as incomplete)",
                 info_.name, receiver_.buffer_bytes() / 1048576.0, options.live.receive_buffer_bytes / 1048576.0,
                 options.live.receive_buffer_bytes);
  }
  thread_ = std::thread([this] { receive_loop(); });
}

void LiveUdpSource::describe(std::vector<std::string> notes) {
  info_.name = receiver_.address().url();
  info_.format = "udp";
  info_.live = true;
  info_.rereadable = false;
  info_.point_fields = framer_->point_fields();
  info_.notes = std::move(notes);
  info_.notes.push_back(fmt::format("listening: {}, receive buffer {:.1f} MiB (as the kernel reports it), idle "
                                    "timeout {}, queue of {} frames (the oldest dropped when the run falls behind)",
                                    info_.name, receiver_.buffer_bytes() / 1048576.0,
                                    options_.idle_timeout_s > 0 ? fmt::format("{:g} s", options_.idle_timeout_s)
                                                                : std::string("none"),
                                    options_.queue_frames));
  info_.notes.push_back(intensity_.note());
  info_.notes.emplace_back("extrinsics: none (a live source runs in the LiDAR frame)");
}

LiveUdpSource::~LiveUdpSource() { close_stream(); }

void LiveUdpSource::close_stream() {
  closing_ = true;
  if (thread_.joinable()) thread_.join();
}

LabelledCloud LiveUdpSource::scan(std::size_t i) {
  throw std::logic_error(fmt::format("{}: a live source serves frames through next_frame(), not scan({})", info_.name, i));
}

std::optional<SourceFrame> LiveUdpSource::next_frame(std::size_t i) {
  {
    const std::lock_guard lock(run_mutex_);
    if (i != served_) {
      throw std::logic_error(fmt::format("{}: a live source serves its frames once, in order (asked for {}, next is {})",
                                         info_.name, i, served_));
    }
    note_latency(std::chrono::steady_clock::now());  // the run asks again: the last frame's pose is written
  }
  std::optional<QueuedFrame> queued = queue_.pop();
  if (!queued) return std::nullopt;
  const std::lock_guard lock(run_mutex_);
  ++served_;
  last_completed_ = queued->completed;
  return std::move(queued->frame);
}

void LiveUdpSource::note_latency(std::chrono::steady_clock::time_point now) {
  if (!last_completed_) return;
  latency_ms_.push_back(std::chrono::duration<double, std::milli>(now - *last_completed_).count());
  last_completed_.reset();
}

std::optional<StreamStats> LiveUdpSource::stream_stats() const {
  StreamStats s;
  s.address = info_.name;
  {
    const std::lock_guard lock(stats_mutex_);
    s.packets = packets_;
    s.packet_counts = framer_->packet_counts();
    s.frames_made = frames_made_;
    s.frames_out_of_order = out_of_order_;
    s.frames_incomplete = incomplete_;
  }
  s.frames_unread = queue_.queued();
  s.frames_dropped = queue_.dropped();
  s.ended_by = queue_.ended_by();
  const std::lock_guard lock(run_mutex_);
  s.frames_served = served_;
  s.latency_ms = latency_ms_;
  return s;
}

void LiveUdpSource::receive_loop() {
  std::vector<PacketFrame> made;
  auto last_packet = std::chrono::steady_clock::now();
  const std::chrono::duration<double> idle(options_.idle_timeout_s);
  try {
    for (;;) {
      if (stop_requested()) return end_stream("Ctrl-C", true);
      if (closing_) return end_stream("the run (frame limit)", true);
      if (receiver_.wait(kPollTick) && drain(made)) {
        last_packet = std::chrono::steady_clock::now();
      } else if (options_.idle_timeout_s > 0 && std::chrono::steady_clock::now() - last_packet > idle) {
        return end_stream(idle_text(options_.idle_timeout_s), false);
      }
    }
  } catch (const std::exception& e) {
    spdlog::error("{}: {}", info_.name, e.what());
    end_stream(fmt::format("an error: {}", e.what()), true);
  }
}

bool LiveUdpSource::drain(std::vector<PacketFrame>& made) {
  std::vector<std::uint8_t> payload;
  std::size_t taken = 0;
  const std::uint16_t port = receiver_.address().port;
  while (taken < kDrainLimit && receiver_.receive(payload)) {
    ++taken;
    {
      const std::lock_guard lock(stats_mutex_);  // the framer's counts are read by stream_stats()
      ++packets_;
      framer_->add(payload, port, made);
    }
    queue(made);  // at once: the run may be waiting for it
  }
  return taken > 0;
}

void LiveUdpSource::queue(std::vector<PacketFrame>& made) {
  const auto now = std::chrono::steady_clock::now();
  for (PacketFrame& frame : made) {
    {
      const std::lock_guard lock(stats_mutex_);
      ++frames_made_;
      if (frame.missing_packets > 0) {  // never a partial frame: dropped whole
        ++incomplete_;
        continue;
      }
      if (last_time_ && frame.time <= *last_time_) {
        ++out_of_order_;
        continue;
      }
      last_time_ = frame.time;
    }
    intensity_.apply(frame.cloud);
    queue_.push({SourceFrame{std::move(frame.cloud), frame.time}, now});
  }
  made.clear();
}

void LiveUdpSource::end_stream(const std::string& reason, bool interrupted) {
  if (!interrupted) {
    std::vector<PacketFrame> last;
    {
      const std::lock_guard lock(stats_mutex_);
      framer_->finish(last);
    }
    queue(last);
  }
  queue_.end(reason);
}

}  // namespace saloam

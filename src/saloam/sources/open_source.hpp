#pragma once
// The one place where a command opens the frames it runs on: the reader for
// a path, then the stages every frame goes through before a run sees it.
//   readers  every layout of source_options.hpp, each a FrameSource that
//            fills SourceInfo (times, labels?, Tr?, reference poses, folder,
//            format, point fields, intensity range, notes) and serves
//            remission in 0..1 (io/intensity_scale.hpp):
//              semantickitti  SequenceFolderSource (io/sequence_source.hpp)
//              kitti-raw      KittiRawDrive        (sources/kitti_raw_drive.hpp)
//              pcd, ply       PointCloudFolder     (sources/point_cloud_folder.hpp)
//              rosbag         RosbagSource         (sources/rosbag_source.hpp)
//              rosbag2, mcap  Ros2BagSource        (sources/ros2_bag_source.hpp)
//              pcap           PcapSource           (sources/pcap_source.hpp)
//              udp://         LiveUdpSource        (sources/live_udp_source.hpp: live)
//   stages   the sensor's laser count on the ring field (SensorRingsSource),
//            the frame range (--frames A:B, FrameRangeSource), then the
//            segmentation (--segment: labels from a network, SegmentedSource)
// A new reader is one more case in open_reader() (and in detect_scan_format
// when a path can say what it is); a new stage wraps the source in
// add_stages(), in the order frames should pass it, with its option in
// SourceOptions. The simulator is no path: the demo builds its
// SimulatedSource itself and hands it to add_stages().
//
// Frames: a source with Tr (calib.txt) gives KITTI camera-frame reference
// poses and runs write camera-frame poses; a source without (no calib.txt,
// --no-calib, KITTI raw drives, bags) runs in the LiDAR frame, and the run
// says so once (runs/output_folder.hpp).

#include <filesystem>
#include <memory>

#include "saloam/io/frame_source.hpp"
#include "saloam/sources/source_options.hpp"

namespace saloam {

/// The format of `path` by what it holds: a file starting with the bag magic
/// "#ROSBAG V2.0" or named *.bag: rosbag; starting with the MCAP magic or
/// named *.mcap: mcap; an SQLite file or *.db3: rosbag2; a file starting
/// with a pcap or pcapng magic number, or named *.pcap / *.pcapng: pcap; a
/// .pcd or .ply file: that format; a folder with velodyne/: semantickitti;
/// with metadata.yaml: rosbag2; with velodyne_points/data:
/// kitti-raw; with .pcd or .ply files: that format. InputError naming the
/// path and listing what was looked for when nothing matches (or both .pcd
/// and .ply files lie in one folder).
ScanFormat detect_scan_format(const std::filesystem::path& path);

/// The reader for `path` as `options.format` (detected when kAuto), or for
/// a `udp://[ADDRESS]:PORT` the live source (sources/live_udp_source.hpp), with
/// options.topic, labels, ignore_labels and ignore_calib (labels are not
/// read when the segmentation stage makes them). InputError naming
/// the file for a missing path, a layout that is not that format, a corrupt
/// file or (for a bag) a build without rosbag_storage.
std::unique_ptr<FrameSource> open_reader(const std::filesystem::path& path, const SourceOptions& options);

/// `source` behind the stages `options` asks for: the frame range
/// (ConfigError when it holds no frame), then the segmentation (InputError
/// when its model cannot be opened).
std::unique_ptr<FrameSource> add_stages(std::unique_ptr<FrameSource> source, const SourceOptions& options);

/// add_stages(open_reader(path, options), options).
std::unique_ptr<FrameSource> open_source(const std::filesystem::path& path, const SourceOptions& options);

}  // namespace saloam

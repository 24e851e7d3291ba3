// `saloam convert SRC --out DEST --to LAYOUT`: a scan source written in
// another layout (sources/sequence_writer.hpp says what each keeps), e.g. a
// KITTI folder as a KITTI raw drive or a folder of PCD files. The input is
// never overwritten: DEST must be new (or an empty folder).

#include <iostream>
#include <map>

#include <fmt/format.h>

#include "command.hpp"
#include "saloam/core/error.hpp"
#include "saloam/sources/sequence_writer.hpp"

namespace saloam::cli {
namespace {

struct ConvertArgs {
  SourceArgs source;
  std::string out;
  std::string to;
  std::string encoding;
  std::string bag_topic = "/points";
  bool no_labels = false;
  ConfigOptions config;
};

const std::map<std::string, PcdEncoding> kPcdEncodings{
    {"ascii", PcdEncoding::kAscii}, {"binary", PcdEncoding::kBinary}, {"binary_compressed", PcdEncoding::kBinaryCompressed}};
const std::map<std::string, McapCompression> kMcapEncodings{
    {"zstd", McapCompression::kZstd}, {"lz4", McapCompression::kLz4}, {"none", McapCompression::kNone}};
const std::map<std::string, PlyEncoding> kPlyEncodings{{"ascii", PlyEncoding::kAscii},
                                                       {"binary_little_endian", PlyEncoding::kBinaryLittleEndian},
                                                       {"binary_big_endian", PlyEncoding::kBinaryBigEndian}};

template <class T>
T encoding_of(const std::map<std::string, T>& known, const std::string& name, const std::string& layout) {
  const auto it = known.find(name);
  if (it != known.end()) return it->second;
  std::string names;
  for (const auto& [n, e] : known) names += (names.empty() ? "" : ", ") + n;
  throw ConfigError(fmt::format("--encoding {}: not a {} encoding ({})", name, layout, names));
}

SequenceWriteOptions write_options(const ConvertArgs& args) {
  SequenceWriteOptions o;
  const auto format = scan_format_from_name(args.to);
  if (!format || *format == ScanFormat::kAuto) throw ConfigError(fmt::format("--to {}: name a layout", args.to));
  o.format = *format;
  if (!args.encoding.empty()) {
    if (o.format == ScanFormat::kPcd) o.pcd = encoding_of(kPcdEncodings, args.encoding, "PCD");
    else if (o.format == ScanFormat::kPly) o.ply = encoding_of(kPlyEncodings, args.encoding, "PLY");
    else if (o.format == ScanFormat::kMcap) o.mcap_compression = encoding_of(kMcapEncodings, args.encoding, "MCAP");
    else throw ConfigError(fmt::format("--encoding: only for --to pcd, ply or mcap, not {}", args.to));
  }
  o.topic = args.bag_topic;
  return o;
}

int run_convert(const ConvertArgs& args) {
  PathRules rules;
  args.source.add_inputs(rules).output("--out", args.out, OutputUse::kFolder).check();
  const SequenceWriteOptions options = write_options(args);  // before anything is read
  SaloamConfig config = args.config.resolve();
  const auto source = args.source.open(args.no_labels, config);
  write_scan_sequence(*source, args.out, options);
  std::cout << fmt::format("wrote {} frames of {} ({}) as {} into {}\n", source->size(), source->info().name,
                           source->info().format, args.to, args.out);
  return 0;
}

const CommandRegistration kRegistration{Command{
    "convert", "Write a scan source in another layout (SemanticKITTI, KITTI raw, PCD, PLY, ROS 1 and 2 bags, MCAP)", 16,
    [](CLI::App& app) {
      auto args = std::make_shared<ConvertArgs>();
      args->source.add_with_no_calib_to(app);
      app.add_option("--out", args->out, "The new folder (or .bag / .mcap file); must not exist or be an empty folder")
          ->required();
      app.add_option("--to", args->to, "Layout to write: semantickitti, kitti-raw, pcd, ply, rosbag, rosbag2, mcap")
          ->required()
          ->check(CLI::IsMember({"semantickitti", "kitti-raw", "pcd", "ply", "rosbag", "rosbag2", "mcap"}));
      app.add_option("--encoding", args->encoding,
                     "PCD: ascii, binary (default), binary_compressed; PLY: ascii, binary_little_endian (default), "
                     "binary_big_endian; MCAP chunks: zstd (default), lz4, none");
      app.add_option("--bag-topic", args->bag_topic, "Topic of the written bag's PointCloud2 messages")
          ->capture_default_str();
      app.add_flag("--no-labels", args->no_labels, "Leave the labels out");
      args->config.add_to(app);
      return [args] { return run_convert(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli

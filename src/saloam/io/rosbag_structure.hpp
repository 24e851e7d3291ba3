#pragma once
// The record structure of a ROS 1 bag (format 2.0), checked before Debian's
// rosbag_storage reads it: rosbag trusts the lengths and positions a bag
// states (a corrupt length makes it allocate up to 4 GB, a position in the
// middle of a record makes it read data as a length), so every one is
// checked here against the file first. The format (ROS wiki, Bags/Format/2.0):
//   "#ROSBAG V2.0\n", then records: uint32 header_len, header, uint32
//   data_len, data; a header is fields (uint32 field_len, "name=value"),
//   `op` (uint8) saying the record's kind:
//     0x03 bag header   index_pos (uint64), conn_count, chunk_count (uint32)
//     0x05 chunk        compression ("none", "bz2", "lz4"), size (uint32,
//                       uncompressed); data: records (connections, messages)
//     0x04 index data   ver, conn, count; data: count x (uint64 time, uint32 offset in the chunk)
//     0x07 connection   conn, topic; data: the connection header's fields
//     0x06 chunk info   ver, chunk_pos (uint64), start_time, end_time, count
//     0x02 message data conn, time
// All integers little-endian.

#include <cstdint>
#include <filesystem>
#include <istream>

namespace saloam {

/// Walks every record of the bag in `in` (`size` bytes, magic included) and
/// throws InputError naming `file` at the first length that runs past its
/// record or the file, a header field without '=', an unknown op, a bag
/// header that is not first or whose index_pos is not a record, a chunk info
/// whose chunk_pos is not a chunk, an uncompressed chunk whose size is not
/// its data's or whose records do not fill it, a compressed chunk claiming
/// more than 100 times its data plus 64 MiB, or an index entry pointing past
/// its chunk. Reads only headers; data are skipped (uncompressed chunks
/// walked). Compressed chunks' content is left to rosbag.
void check_rosbag_structure(std::istream& in, std::uint64_t size, const std::filesystem::path& file);
/// check_rosbag_structure of a file.
void check_rosbag_structure(const std::filesystem::path& file);

}  // namespace saloam

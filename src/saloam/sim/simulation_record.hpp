#pragma once
// What a simulated sequence on disk records of how it was made
// (simulation.yaml beside its scans), so that a later run that reuses it
// (`demo --reuse`) can tell whether it is the sequence it asks for; and the
// folder a simulation is written into, which never holds anything but
// saloam simulate's own earlier output.

#include <filesystem>
#include <string>
#include <vector>

#include "saloam/core/output_folder.hpp"
#include "saloam/sim/simulator.hpp"

namespace saloam {

/// How `options` make a sequence, one "key: value" line each (YAML): equal
/// records, equal sequences.
std::string simulation_record(const SimulationOptions& options);
/// Writes `folder`/simulation.yaml.
void write_simulation_record(const std::filesystem::path& folder, const SimulationOptions& options);
/// The settings in which the sequence in `folder` differs from `options`,
/// as "key: KEPT, asked for ASKED"; InputError when it has no record.
std::vector<std::string> simulation_differences(const std::filesystem::path& folder, const SimulationOptions& options);

/// The files of a sequence folder besides its scans.
inline const std::vector<std::string> kSequenceFiles{"poses.txt", "poses_sensor.txt", "times.txt", "calib.txt",
                                                    "simulation.yaml"};

/// The output folder of a simulation (core/output_folder.hpp): an earlier
/// simulation there is removed first, every scan of it. InputError when
/// `out_dir` holds a sequence or results that saloam simulate did not write:
/// they are never overwritten.
OutputFolder open_sequence_output(const std::filesystem::path& out_dir);

}  // namespace saloam

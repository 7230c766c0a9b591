#pragma once
// machine_boxes.csv of a harvester recording: per scan, the boxes (body frame) that enclose the
// machine's cabin and moving crane parts over that scan, as joint encoders would give them on a
// real machine; the odometry crops its scans with them. See docs/simulator.md.

#include <filesystem>
#include <fstream>
#include <string>

#include "taiga/sim/machine.hpp"

namespace taiga::sim::detail {

/// Boxes grow by this much beyond the machine's surfaces: more than 6 sigma of the simulated range
/// noise at the crane's distances, so that every return from the machine lies inside.
inline constexpr double kMachineBoxMargin_m = 0.10;

class MachineBoxesWriter {
 public:
  /// Creates the file and writes its header; std::runtime_error when it cannot.
  MachineBoxesWriter(const std::filesystem::path& path, const HarvesterMachine& machine);
  /// One row per box for the scan stamped `stamp_s` (as in the bag) whose columns fire over
  /// motion times [t0_s, t1_s].
  void writeScan(double stamp_s, double t0_s, double t1_s);

 private:
  std::filesystem::path path_;
  const HarvesterMachine& machine_;
  std::ofstream out_;
};

/// The cabin box as YAML comment lines for rig.yaml (the configuration has no crop-box field).
std::string cabinBoxRigComment();

}  // namespace taiga::sim::detail

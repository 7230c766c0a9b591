#pragma once
// Trajectory files in the formats that evo and most tools read.
//
// TUM:   one pose per line, "t x y z qx qy qz qw" (s, m, unit quaternion with w last),
//        separated by spaces; lines starting with '#' and blank lines are ignored.
// KITTI: one pose per line, the 12 numbers of the 3x4 matrix [R | t] in row-major order, no time.
//        Times are the line index (0, 1, 2, ...) unless a times file (one time per line, as in
//        the KITTI odometry benchmark's times.txt) is given.
//
// Readers check every line and throw InputError("FILE:LINE: what is wrong") on malformed input.
// Writers print every number with the shortest representation that reads back to the same
// double, so a written trajectory reads back bit for bit.

#include <filesystem>
#include <optional>

#include "taiga/core/trajectory.hpp"

namespace taiga::io {

enum class TrajectoryFormat { kTum, kKitti };

Trajectory readTum(const std::filesystem::path& path);
void writeTum(const std::filesystem::path& path, const Trajectory& trajectory);

Trajectory readKitti(const std::filesystem::path& path,
                     const std::optional<std::filesystem::path>& times_path = std::nullopt);
void writeKitti(const std::filesystem::path& path, const Trajectory& trajectory);

/// TUM when the first pose line has 8 values, KITTI when it has 12; InputError otherwise.
TrajectoryFormat detectTrajectoryFormat(const std::filesystem::path& path);
/// Reads either format, detected from the content.
Trajectory readTrajectory(const std::filesystem::path& path);

}  // namespace taiga::io

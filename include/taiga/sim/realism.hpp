#pragma once
// Realism presets of the simulator: errors of the rig that the rig.yaml a user would write does
// not state (IMU noise beyond its datasheet, biases that wander, scale and axis errors, clipping,
// extrinsics off the drawing, a lidar-IMU time offset and clock drift, noisier weak returns, lost
// packets, a forest swaying in the wind). Every value and its source: docs/simulator.md,
// "Realism". `ideal` changes nothing: today's recordings, bit for bit.

#include <string>
#include <vector>

#include "taiga/sim/scenario.hpp"

namespace taiga::sim {

/// `ideal`, `typical`, `harsh`.
std::vector<std::string> realismNames();

/// Sets the error fields of `scenario` (imu, lidar, rig, forest wind) to the preset's values and
/// scenario.realism to its name; other fields are untouched. InputError naming `--realism` and
/// the valid names for another name.
void applyRealism(const std::string& preset, Scenario& scenario);

}  // namespace taiga::sim

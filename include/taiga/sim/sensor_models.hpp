#pragma once
// Lidar heads built into taiga, so that `taiga simulate` gives the same sensor wherever it runs
// (no file looked up at run time). Values are the nominal design of each product as its
// datasheet and firmware manual state it, not one unit's factory calibration.

#include <string>
#include <vector>

#include "taiga/sim/lidar.hpp"

namespace taiga::sim {

/// Names of the built-in models (`lidar.model`).
std::vector<std::string> sensorModelNames();

/// The full beam table and frames of a built-in model; InputError naming `lidar.model` and the
/// valid names for another name.
LidarGeometry sensorModel(const std::string& name);

}  // namespace taiga::sim

#pragma once
// Some IMU drivers publish acceleration in standard gravities instead of m/s^2. Over the first
// second of a recording the median magnitude of the specific force is close to 1 g whatever the
// motion of a hand-held or vehicle rig, which tells the unit.

#include <memory>
#include <span>
#include <string>

#include "taiga/core/rig_config.hpp"
#include "taiga/core/sensor_samples.hpp"
#include "taiga/io/recording.hpp"

namespace taiga::io {

inline constexpr double kStandardGravity_mps2 = 9.80665;

struct AccelerationUnitDecision {
  double scale_to_mps2 = 1.0;  ///< multiply raw acceleration by this
  bool detected = false;       ///< true when decided from the data (unit `auto`)
  bool warn = false;           ///< true when the user should look: converted from g, or unsure
  std::string explanation;     ///< what was decided and why, for the log and `taiga info`
};

/// Decides the unit from the configured one, or from the data when it is kAuto: a median
/// magnitude in [0.5, 2] means g, in [5, 20] means m/s^2; anything else keeps m/s^2 and says the
/// unit could not be told.
AccelerationUnitDecision decideAccelerationUnit(AccelerationUnit configured,
                                                std::span<const ImuSample> first_samples);

/// Wraps a stream of raw IMU samples: reads its first second (at most 400 samples), decides the
/// acceleration unit, logs the decision (a warning when it converted or could not tell) and
/// delivers every sample in m/s^2. `source` names the recording in the log.
std::unique_ptr<StreamSource> withAccelerationUnit(std::unique_ptr<StreamSource> raw_imu, AccelerationUnit configured,
                                                   std::string source);

}  // namespace taiga::io

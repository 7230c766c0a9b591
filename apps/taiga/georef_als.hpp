#pragma once
// taiga georef --als: a run's map registered to airborne laser scanning (docs/georeferencing.md,
// "ALS"); the registration is taiga::georef::registerToAls, this reads and writes the files.

#include <optional>
#include <string>
#include <vector>

namespace taiga::app {

struct AlsGeorefOptions {
  std::vector<std::string> als;  ///< LAS tiles, or directories of them
  std::string run;               ///< a run directory of `taiga run`
  std::string out;
  std::optional<int> epsg;
  std::string guess;  ///< "E,N,YAW_DEG": the map origin's easting, northing and heading
  std::optional<double> search_m, search_deg;
};

int runAlsGeoref(const AlsGeorefOptions& options);

}  // namespace taiga::app

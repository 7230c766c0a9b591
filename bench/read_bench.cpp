// Reading a recording, as `taiga run`'s reader thread does it (issue 26: the reader took about
// a fifth of the demo run's CPU): every event through io::Recording, timed as a whole, with
// the scans' share. The first run computes a checksum (not timed) that covers every decoded channel
// of every scan (positions, times, intensities, rings, columns) and the IMU readings: a faster
// reader must not change it.
//
//   read_bench RECORDING [CONFIG] [RUNS=3]     e.g. read_bench SIM/recording.bag SIM/rig.yaml
#include <fmt/format.h>

#include <cstdlib>
#include <string>
#include <variant>
#include <vector>

#include "bench_common.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"

using namespace taiga;
using bench::Clock;
using bench::median;
using bench::msSince;

int main(int argc, char** argv) {
  if (argc < 2) {
    fmt::print(stderr, "usage: read_bench RECORDING [CONFIG] [RUNS=3]\n");
    return 2;
  }
  SystemConfig config;
  if (argc > 2) io::readConfigYaml(argv[2], config);
  const int runs = 1 + (argc > 3 ? std::atoi(argv[3]) : 3);  // the first one for the checksum
  std::vector<double> total_ms;
  std::size_t scans = 0, points = 0, imu = 0;
  std::uint64_t hash = bench::kFnvOffset;
  for (int run = 0; run < runs; ++run) {
    const auto start = Clock::now();
    io::Recording recording = io::openRecording(argv[1], config.recording, config.rig);
    scans = points = imu = 0;
    while (auto event = recording.next()) {
      if (const auto* scan = std::get_if<io::Scan>(&*event)) {
        const PointCloud& c = scan->cloud_in_lidar;
        ++scans;
        points += c.size();
        if (run > 0) continue;
        hash = bench::fnv1a(c.positions, hash);
        hash = bench::fnv1a(c.times_s, hash);
        hash = bench::fnv1a(c.intensities, hash);
        hash = bench::fnv1a(c.rings, hash);
        hash = bench::fnv1a(c.columns, hash);
      } else if (const auto* sample = std::get_if<ImuSample>(&*event)) {
        ++imu;
        if (run > 0) continue;
        hash = bench::fnv1a(&sample->t_s, sizeof(double), hash);
        hash = bench::fnv1a(sample->acceleration_imu_mps2.data(), 3 * sizeof(double), hash);
        hash = bench::fnv1a(sample->angular_velocity_imu_radps.data(), 3 * sizeof(double), hash);
      }
    }
    if (run > 0) total_ms.push_back(msSince(start));
  }
  fmt::print("{} scans ({:.0f} points each), {} IMU readings\n", scans,
             scans ? static_cast<double>(points) / static_cast<double>(scans) : 0.0, imu);
  fmt::print("read in {:.1f} ms (median of {} runs), {:.2f} ms per scan\n", median(total_ms),
             runs - 1, scans ? median(total_ms) / static_cast<double>(scans) : 0.0);
  fmt::print("checksum {:016x}\n", hash);
  return 0;
}

// Simulator speed (issue 4): seconds of data simulated per second of wall time for the full
// OS0-128 (128 x 1024 at 10 Hz, 4 sub-rays) at 1 and 2 TBB threads, and the CPU time per scan.
//
// The scene is generated once (its build time is reported apart: it does not grow with the
// duration). Then, per thread count and run:
//   "scans":  LidarSimulator::simulateScan for every scan of the duration, nothing written
//             (the ray casting and the lidar model);
//   "whole":  writeSimulation into a temporary directory (scans + IMU + GNSS + the LZ4 bag and
//             the side files), i.e. what `taiga simulate` does after building the scene.
// Wall time (steady clock) and CPU time of the process (getrusage, user + system) are taken
// around each; the table gives medians over the runs. The machine is shared: the wall-time ratio
// depends on what else runs, while CPU-seconds per data-second is what real time needs on an idle
// machine (<= 1 at one thread, <= 2 at two threads with perfect scaling).
//
//   sim_bench [RUNS] [DURATION_S] [SCENARIO] [SEED] [SUB_RAYS] [REALISM,REALISM...]
//     (defaults 3, 10, mixed, 1, the scenario's 4; the beam table is built in)
//
// With a list of realism presets (e.g. `ideal,typical`), it compares them instead: per run, the
// whole simulation at 2 threads for each preset in turn (interleaved, so that the machine's load
// falls on all alike), and the median wall and CPU time of each as a ratio to the first.
#include <sys/resource.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "taiga/sim/realism.hpp"
#include "taiga/sim/simulator.hpp"

namespace {

double cpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& tv) { return tv.tv_sec + 1e-6 * tv.tv_usec; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct Timing {
  double wall_s = 0.0;
  double cpu_s = 0.0;
};

template <typename F>
Timing timed(F&& f) {
  const double wall0 = wallSeconds(), cpu0 = cpuSeconds();
  f();
  return {wallSeconds() - wall0, cpuSeconds() - cpu0};
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    out.push_back(list.substr(start, comma - start));
    start = comma + 1;
  }
  return out;
}

int compareRealism(const std::vector<std::string>& presets, int runs, double duration_s,
                   const std::string& scenario_name, std::uint64_t seed) {
  std::vector<std::unique_ptr<taiga::sim::Simulation>> simulations;
  for (const std::string& preset : presets) {
    taiga::sim::Scenario scenario = taiga::sim::scenarioByName(scenario_name);
    taiga::sim::applyRealism(preset, scenario);
    simulations.push_back(std::make_unique<taiga::sim::Simulation>(scenario, duration_s, seed));
  }
  const double data_s =
      static_cast<double>(simulations[0]->scanCount()) * simulations[0]->lidar().scanPeriod_s();
  const std::filesystem::path out_dir =
      std::filesystem::temp_directory_path() / ("taiga_sim_bench_" + std::to_string(getpid()));
  std::vector<std::vector<double>> wall(presets.size()), cpu(presets.size());
  tbb::task_arena arena(2);
  for (int run = 0; run < runs; ++run) {
    for (std::size_t i = 0; i < presets.size(); ++i) {
      const Timing t =
          timed([&] { arena.execute([&] { taiga::sim::writeSimulation(*simulations[i], out_dir); }); });
      wall[i].push_back(t.wall_s);
      cpu[i].push_back(t.cpu_s);
    }
  }
  std::filesystem::remove_all(out_dir);
  std::printf(
      "scenario %s, seed %llu, %.1f s of data, whole simulation at 2 threads, %d runs\n\n"
      "| realism | wall s (median) | data s / wall s | CPU s / data s | wall ratio | CPU ratio |\n"
      "|---|---|---|---|---|---|\n",
              scenario_name.c_str(), static_cast<unsigned long long>(seed), data_s, runs);
  for (std::size_t i = 0; i < presets.size(); ++i) {
    const double w = median(wall[i]), c = median(cpu[i]);
    std::printf("| %s | %.2f | %.2f | %.2f | %.3f | %.3f |\n", presets[i].c_str(), w, data_s / w,
                c / data_s, w / median(wall[0]), c / median(cpu[0]));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 3;
  const double duration_s = argc > 2 ? std::atof(argv[2]) : 10.0;
  const std::string scenario_name = argc > 3 ? argv[3] : "mixed";
  const std::uint64_t seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 1;
  if (runs < 1 || duration_s <= 0.0) {
    std::fprintf(stderr,
                 "usage: sim_bench [RUNS>=1] [DURATION_S>0] [SCENARIO] [SEED] [SUB_RAYS]\n");
    return 2;
  }

  if (argc > 6) return compareRealism(split(argv[6]), runs, duration_s, scenario_name, seed);
  taiga::sim::Scenario scenario = taiga::sim::scenarioByName(scenario_name);
  if (argc > 5) scenario.lidar.sub_rays = std::atoi(argv[5]);
  std::unique_ptr<taiga::sim::Simulation> simulation;
  const Timing build = timed([&] {
    simulation = std::make_unique<taiga::sim::Simulation>(scenario, duration_s, seed);
  });
  const auto& lidar = simulation->lidar();
  const std::size_t scans = simulation->scanCount();
  const double data_s = static_cast<double>(scans) * lidar.scanPeriod_s();
  const taiga::sim::SceneStats stats = simulation->scene().stats();
  std::printf(
      "scenario %s, seed %llu: %.2f ha, %zu triangles, %zu curve segments; scene built in %.2f s "
      "wall, %.2f s CPU\n"
      "lidar %d x %d, %d sub-rays; %zu scans = %.1f s of data; %d runs per row\n\n",
      scenario_name.c_str(), static_cast<unsigned long long>(seed), stats.area_ha,
      stats.triangles, stats.curve_segments, build.wall_s, build.cpu_s, lidar.rows(),
      lidar.columns(), scenario.lidar.sub_rays, scans, data_s, runs);

  const std::filesystem::path out_dir =
      std::filesystem::temp_directory_path() / ("taiga_sim_bench_" + std::to_string(getpid()));
  std::printf(
      "| part | threads | wall s (median) | data s / wall s | CPU s / scan | CPU s / data s |\n"
      "|---|---|---|---|---|---|\n");
  for (const int threads : {1, 2}) {
    tbb::task_arena arena(threads);
    for (const bool whole : {false, true}) {
      std::vector<double> wall, cpu;
      for (int run = 0; run < runs; ++run) {
        std::size_t points = 0;
        const Timing t = timed([&] {
          arena.execute([&] {
            if (whole) {
              points = taiga::sim::writeSimulation(*simulation, out_dir).points;
            } else {
              for (std::size_t k = 0; k < scans; ++k) {
                const double t_start = static_cast<double>(k) * lidar.scanPeriod_s();
                points += lidar.simulateScan(simulation->scene(), simulation->motion(), k, t_start)
                              .cloud_in_lidar.size();
              }
            }
          });
        });
        if (points == 0) {
          std::fprintf(stderr, "no points simulated: the benchmark measures nothing\n");
          return 1;
        }
        wall.push_back(t.wall_s);
        cpu.push_back(t.cpu_s);
      }
      const double wall_med = median(wall), cpu_med = median(cpu);
      std::printf("| %s | %d | %.2f | %.2f | %.3f | %.2f |\n", whole ? "whole" : "scans", threads,
                  wall_med, data_s / wall_med, cpu_med / static_cast<double>(scans),
                  cpu_med / data_s);
      std::fflush(stdout);
    }
  }
  std::filesystem::remove_all(out_dir);
  return 0;
}

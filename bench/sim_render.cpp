// Pictures of a simulated forest for docs/simulator.md (issue 4): orthographic views of the scene
// ray-cast through Embree (Scene::castRay), the ground-truth trajectory and one simulated scan.
// scripts/render_sim_figures.py turns the files into the PNGs in docs/images.
//
//   sim_render OUT_DIR [DURATION_S] [SCENARIO] [SEED] [SCAN]
//     (defaults 60, mixed, 1, 100; run from the repository root: the simulator reads
//      ../shared/data/ouster)
//
// Writes into OUT_DIR (NumPy .npy, row 0 = north / top of the picture):
//   top_height.npy, top_shade.npy, top_material.npy   view straight down, 0.15 m pixels: height
//                                                     of the first surface (m, world z), cosine of
//                                                     its normal with a light from the north-west,
//                                                     Material (uint8); NaN / 255 where nothing
//   side_depth.npy, side_shade.npy, side_material.npy view northwards into a slab 12 m deep
//                                                     centred on the plot (0.05 m pixels): distance
//                                                     into the slab, shade, material
//   views.json                                        extents of the views (world x, y, z in m)
//   trajectory.csv                                    t, x, y, z of T_world_body every 0.05 s
//   scan.csv                                          scan SCAN: x, y, z (world, each point at its
//                                                     own firing time's true pose), intensity,
//                                                     ring
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "taiga/sim/simulator.hpp"

namespace {

using taiga::sim::Scene;

/// A 2D array in NumPy's .npy format (version 1.0, C order, little-endian).
template <typename T>
void writeNpy(const std::filesystem::path& path, const std::vector<T>& data, int rows, int cols,
              const char* descr) {
  std::string header =
      fmt::format("{{'descr': '{}', 'fortran_order': False, 'shape': ({}, {}), }}", descr, rows,
                  cols);
  const std::size_t preamble = 10;  // magic (6) + version (2) + header length (2)
  header.append(64 - (preamble + header.size() + 1) % 64, ' ');
  header.push_back('\n');
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const auto length = static_cast<std::uint16_t>(header.size());
  const char length_le[2] = {static_cast<char>(length & 0xff), static_cast<char>(length >> 8)};
  out.write(length_le, 2);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(reinterpret_cast<const char*>(data.data()),
            static_cast<std::streamsize>(data.size() * sizeof(T)));
  if (!out) throw std::runtime_error(fmt::format("{}: cannot write", path.string()));
}

struct View {
  std::vector<float> value, shade;
  std::vector<std::uint8_t> material;
  int rows = 0, cols = 0;
};

/// Orthographic view: pixel (r, c) casts from origin(r, c) along `direction` over (0, depth_m).
/// `value` is the hit's world z (top view) or its range (side view).
template <typename OriginFn>
View castView(const Scene& scene, int rows, int cols, const Eigen::Vector3d& direction,
              double depth_m, bool value_is_height, OriginFn origin) {
  View v;
  v.rows = rows, v.cols = cols;
  const std::size_t n = static_cast<std::size_t>(rows) * cols;
  v.value.assign(n, std::numeric_limits<float>::quiet_NaN());
  v.shade.assign(n, 0.0f);
  v.material.assign(n, 255);
  const Eigen::Vector3d light = Eigen::Vector3d(-1.0, 1.0, 1.5).normalized();  // from the NW
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector3d o = origin(r, c);
      const auto hit = scene.castRay(o, direction, 0.0, depth_m);
      if (!hit) continue;
      const std::size_t i = static_cast<std::size_t>(r) * cols + c;
      v.value[i] = static_cast<float>(value_is_height ? (o + hit->range_m * direction).z()
                                                      : hit->range_m);
      v.shade[i] = static_cast<float>(std::max(0.0, hit->normal_world.dot(light)));
      v.material[i] = static_cast<std::uint8_t>(hit->material);
    }
  }
  return v;
}

void writeView(const std::filesystem::path& dir, const std::string& name, const View& v,
               const char* value_name) {
  writeNpy(dir / (name + "_" + value_name + ".npy"), v.value, v.rows, v.cols, "<f4");
  writeNpy(dir / (name + "_shade.npy"), v.shade, v.rows, v.cols, "<f4");
  writeNpy(dir / (name + "_material.npy"), v.material, v.rows, v.cols, "|u1");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: sim_render OUT_DIR [DURATION_S] [SCENARIO] [SEED] [SCAN]\n");
    return 2;
  }
  const std::filesystem::path out_dir = argv[1];
  const double duration_s = argc > 2 ? std::atof(argv[2]) : 60.0;
  const std::string scenario_name = argc > 3 ? argv[3] : "mixed";
  const std::uint64_t seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 1;
  const std::size_t scan_index = argc > 5 ? std::strtoull(argv[5], nullptr, 10) : 100;
  std::filesystem::create_directories(out_dir);

  const taiga::sim::Simulation simulation(taiga::sim::scenarioByName(scenario_name), duration_s,
                                          seed);
  if (scan_index >= simulation.scanCount()) {
    std::fprintf(stderr, "SCAN %zu: the recording has %zu scans\n", scan_index,
                 simulation.scanCount());
    return 2;
  }
  const Scene& scene = simulation.scene();
  const auto& motion = simulation.motion();
  const taiga::sim::SceneLayout& layout = scene.layout();
  const double half = layout.half_size_m;
  const Eigen::Vector2d center = layout.center_world;
  const double x0 = center.x() - half, y1 = center.y() + half;

  // Top view: straight down from well above the highest tree.
  const double top_pixel_m = 0.15;
  const int top_n = static_cast<int>(std::ceil(2.0 * half / top_pixel_m));
  const double z_top = 80.0;
  const View top = castView(
      scene, top_n, top_n, Eigen::Vector3d(0, 0, -1), 200.0, true, [&](int r, int c) {
        return Eigen::Vector3d(x0 + (c + 0.5) * top_pixel_m, y1 - (r + 0.5) * top_pixel_m, z_top);
      });
  writeView(out_dir, "top", top, "height");

  // Side view: northwards into a slab 12 m deep through the plot centre.
  const double side_pixel_m = 0.05, slab_m = 12.0, z_min = -8.0, z_max = 32.0;
  const int side_cols = static_cast<int>(std::ceil(2.0 * half / side_pixel_m));
  const int side_rows = static_cast<int>(std::ceil((z_max - z_min) / side_pixel_m));
  const double y_slab = center.y() - 0.5 * slab_m;
  const View side = castView(
      scene, side_rows, side_cols, Eigen::Vector3d(0, 1, 0), slab_m, false, [&](int r, int c) {
        return Eigen::Vector3d(x0 + (c + 0.5) * side_pixel_m, y_slab,
                               z_max - (r + 0.5) * side_pixel_m);
      });
  writeView(out_dir, "side", side, "depth");

  std::ofstream views(out_dir / "views.json");
  views << fmt::format(
      "{{\"scenario\": \"{}\", \"seed\": {}, \"duration_s\": {},\n"
      " \"top\": {{\"x_min\": {}, \"x_max\": {}, \"y_min\": {}, \"y_max\": {}, \"pixel_m\": {}}},\n"
      " \"side\": {{\"x_min\": {}, \"x_max\": {}, \"z_min\": {}, \"z_max\": {}, \"pixel_m\": {}, "
      "\"y_from\": {}, \"y_to\": {}}},\n"
      " \"scan\": {}, \"trees\": {}}}\n",
      scenario_name, seed, duration_s, x0, x0 + top_n * top_pixel_m, y1 - top_n * top_pixel_m, y1,
      top_pixel_m, x0, x0 + side_cols * side_pixel_m, z_max - side_rows * side_pixel_m, z_max,
      side_pixel_m, y_slab, y_slab + slab_m, scan_index, scene.trees().size());

  std::ofstream trajectory(out_dir / "trajectory.csv");
  trajectory << "t_s,x_m,y_m,z_m\n";
  for (double t = 0.0; t <= duration_s + 1e-9; t += 0.05) {
    const Eigen::Vector3d p = motion.at(t).T_world_body.translation();
    trajectory << fmt::format("{:.3f},{:.4f},{:.4f},{:.4f}\n", t, p.x(), p.y(), p.z());
  }

  const auto& lidar = simulation.lidar();
  const double t_start = static_cast<double>(scan_index) * lidar.scanPeriod_s();
  const taiga::io::Scan scan = lidar.simulateScan(scene, motion, scan_index, t_start);
  const auto T_body_lidar = lidar.T_body_lidar();
  std::ofstream points(out_dir / "scan.csv");
  points << "x_m,y_m,z_m,intensity,ring\n";
  const taiga::PointCloud& cloud = scan.cloud_in_lidar;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p_world =
        motion.at(cloud.times_s[i]).T_world_body * (T_body_lidar * cloud.positions[i]);
    points << fmt::format("{:.3f},{:.3f},{:.3f},{:.1f},{}\n", p_world.x(), p_world.y(),
                          p_world.z(), cloud.intensities[i], cloud.rings[i]);
  }
  if (!views || !trajectory || !points) {
    std::fprintf(stderr, "%s: cannot write\n", out_dir.c_str());
    return 1;
  }
  std::printf("wrote %s: top %dx%d, side %dx%d, %zu trajectory samples, scan %zu with %zu points\n",
              out_dir.c_str(), top_n, top_n, side_rows, side_cols,
              static_cast<std::size_t>(duration_s / 0.05) + 1, scan_index, cloud.size());
  return 0;
}

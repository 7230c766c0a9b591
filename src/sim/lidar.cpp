#include "taiga/sim/lidar.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <numbers>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/ouster/sensor_info.hpp"
#include "taiga/sim/machine.hpp"
#include "ring_on_curve.hpp"
#include "taiga/sim/random.hpp"
#include "taiga/sim/sensor_models.hpp"

namespace taiga::sim {
namespace {
constexpr double kPi = std::numbers::pi;
constexpr int kMaxSubRays = 8;
/// Columns per lidar UDP packet (Ouster: 16), the unit of packet loss.
constexpr int kColumnsPerPacket = 16;
/// Range of a ray that hit nothing.
constexpr double kNoHit = std::numeric_limits<double>::infinity();
/// Reflectivity of the target that reaches max_range_m at normal incidence.
constexpr double kReferenceReflectivity = 0.8;
/// Beyond this margin past the detection limit of the brightest material a hit cannot change a
/// return (a mixed range averages echoes less than 1 m apart), m.
constexpr double kMixingMargin_m = 1.0;
/// The ring rays start this far in front of the nearest centre hit among the pixel and its two
/// azimuth neighbours, m.
constexpr double kRingLead_m = 0.5;

/// One pixel's outcome before compaction.
struct Pixel {
  bool valid = false;
  Eigen::Vector3f p_sensor = Eigen::Vector3f::Zero();
  float intensity = 0.0f;
};

/// The highest reflectivity of any scene material.
double maxReflectivity() {
  double best = 0.0;
  for (const Material m : {Material::kGround, Material::kBark, Material::kBranch,
                           Material::kFoliage, Material::kRock, Material::kDeadWood,
                           Material::kMachine})
    best = std::max(best, reflectivity(m));
  return best;
}

struct SubHit {
  double range_m;
  double weight;
  double reflectivity_eff;  ///< reflectivity * cos(incidence)
};
}  // namespace

LidarGeometry loadLidarGeometry(const LidarParams& params) {
  if (params.beams < 0)
    throw InputError(fmt::format("lidar.beams: expected 0 (all) or more, found {}", params.beams));
  if (params.columns < 16)
    throw InputError(fmt::format("lidar.columns: expected at least 16, found {}", params.columns));
  LidarGeometry full;
  if (params.metadata_json.empty()) {
    full = sensorModel(params.model);
  } else {
    if (!std::filesystem::exists(params.metadata_json))
      throw InputError(fmt::format("lidar.metadata_json: {}: no such file", params.metadata_json));
    const io::ouster::SensorInfo info = io::ouster::readSensorInfo(params.metadata_json);
    full.beam_altitude_deg = info.beam_altitude_angles_deg;
    full.beam_azimuth_deg = info.beam_azimuth_angles_deg;
    full.beam_azimuth_deg.resize(full.beam_altitude_deg.size(), 0.0);
    full.lidar_origin_to_beam_origin_m = info.lidar_origin_to_beam_origin_mm / 1000.0;
    full.beam_origin_z_m = info.T_lidar_beam.translation().z();
    full.T_sensor_lidar = info.T_sensor_lidar;
    full.T_sensor_imu = info.T_sensor_imu;
    full.source = params.metadata_json;
  }
  const auto n = static_cast<int>(full.beam_altitude_deg.size());
  if (params.beams == 0) return full;
  if (params.beams > n)
    throw InputError(fmt::format("lidar.beams: {} has {} beams, {} were asked for", full.source,
                                 n, params.beams));
  // Evenly subsample: a 128-beam table gives a 64- or 32-beam head of the same field of view.
  LidarGeometry g = full;
  g.beam_altitude_deg.clear();
  g.beam_azimuth_deg.clear();
  for (int i = 0; i < params.beams; ++i) {
    const int row = params.beams == 1
                        ? n / 2
                        : static_cast<int>(std::lround(i * (n - 1.0) / (params.beams - 1.0)));
    g.beam_altitude_deg.push_back(full.beam_altitude_deg[row]);
    g.beam_azimuth_deg.push_back(full.beam_azimuth_deg[row]);
  }
  return g;
}

LidarSimulator::LidarSimulator(LidarParams params, LidarGeometry geometry, std::uint64_t seed)
    : params_(std::move(params)), geometry_(std::move(geometry)), seed_(streamSeed(seed, "lidar")) {
  params_.sub_rays = std::clamp(params_.sub_rays, 1, kMaxSubRays);
  // The beam directions in the lidar frame are the same in every scan: computed once here
  // (the sines and cosines per pixel and pass cost a few per cent of a scan).
  const int rows = this->rows(), cols = params_.columns;
  directions_lidar_.resize(static_cast<std::size_t>(rows) * cols);
  for (int col = 0; col < cols; ++col) {
    const double theta_e = 2.0 * kPi * (1.0 - static_cast<double>(col) / cols);
    for (int row = 0; row < rows; ++row) {
      const double az = theta_e - geometry_.beam_azimuth_deg[row] * kRadPerDeg;
      const double alt = geometry_.beam_altitude_deg[row] * kRadPerDeg;
      directions_lidar_[static_cast<std::size_t>(col) * rows + row] = Eigen::Vector3d(
          std::cos(az) * std::cos(alt), std::sin(az) * std::cos(alt), std::sin(alt));
    }
  }
}

io::Scan LidarSimulator::simulateScan(const Scene& scene, const WalkingMotion& motion,
                                      std::uint64_t index, double t_start_s,
                                      double time_offset_s) const {
  const int rows = this->rows(), cols = params_.columns;
  const double dt_column = scanPeriod_s() / cols;
  const lie::SE3 T_body_sensor = T_body_lidar();
  std::vector<Pixel> pixels(static_cast<std::size_t>(rows) * cols);

  // Sub-ray pattern: the centre and a ring at 3/4 of the half divergence, weights of a Gaussian
  // footprint.
  const int k_rays = params_.sub_rays;
  const double ring_rad = 0.75 * 0.5 * params_.beam_divergence_deg * kRadPerDeg;
  const double center_weight = k_rays == 1 ? 1.0 : 0.4;
  const double ring_weight = k_rays == 1 ? 0.0 : 0.6 / (k_rays - 1);

  // Rays end where nothing could be detected any more: the range limit of the brightest material
  // at normal incidence with the whole footprint on it (the detection rule below), plus the
  // mixing margin. A hit beyond would be dropped anyway; as the far echo of an edge it could only
  // outweigh a detectable near one, which a real receiver would not do for an echo too weak to
  // detect. (The ray used to run on to 1.2 x max_range_m: about 8 % slower, sim_bench.)
  const double t_max_m =
      params_.max_range_m * std::sqrt(maxReflectivity() / kReferenceReflectivity) +
      kMixingMargin_m;

  // Pass 1: the centre ray of every pixel, each column from the true pose at its firing time.
  struct Column {
    Eigen::Matrix3d R_world_lidar;
    Eigen::Vector3d origin_lidar, origin_world;
    std::optional<MachineSnapshot> machine;  ///< the harvester's cabin and crane, if any
  };
  const HarvesterMachine* machine = motion.machine();
  std::vector<Column> columns(cols);
  std::vector<SubHit> centers(pixels.size(), SubHit{kNoHit, 0.0, 0.0});
  std::vector<std::uint8_t> solid(pixels.size(), 0);
  std::vector<std::int32_t> segment(pixels.size(), -1);  ///< curve segment of the centre hit
  // Wind: the sway gain of each centre hit (0: does not move), only when there is wind.
  const Wind& wind_field = scene.wind();
  const bool wind = !wind_field.calm();
  std::vector<float> sway_gain(wind ? pixels.size() : 0, 0.0f);
  auto direction = [&](int col, int row) -> const Eigen::Vector3d& {
    return directions_lidar_[static_cast<std::size_t>(col) * rows + row];
  };
  tbb::parallel_for(
      tbb::blocked_range<int>(0, cols, 16), [&](const tbb::blocked_range<int>& range) {
        std::vector<Eigen::Vector3d> dirs(rows);
        std::vector<std::optional<RayHit>> column_hits;
        for (int col = range.begin(); col != range.end(); ++col) {
          const double t = t_start_s + col * dt_column;
          const lie::SE3 T_world_body = motion.at(t).T_world_body;
          const lie::SE3 T_world_lidar = T_world_body * T_body_sensor * geometry_.T_sensor_lidar;
          const double theta_e = 2.0 * kPi * (1.0 - static_cast<double>(col) / cols);
          Column& c = columns[col];
          c.R_world_lidar = T_world_lidar.rotation().matrix();
          c.origin_lidar =
              Eigen::Vector3d(geometry_.lidar_origin_to_beam_origin_m * std::cos(theta_e),
                              geometry_.lidar_origin_to_beam_origin_m * std::sin(theta_e),
                              geometry_.beam_origin_z_m);
          c.origin_world = T_world_lidar * c.origin_lidar;
          for (int row = 0; row < rows; ++row) dirs[row] = c.R_world_lidar * direction(col, row);
          scene.castRays(c.origin_world, dirs, t_max_m,
                         column_hits);  // packets of 16
          if (machine) {  // the machine's own body: nearest hit wins
            c.machine = machine->snapshot(t, T_world_body);
            c.machine->occlude(c.origin_world, dirs, t_max_m, column_hits);
          }
          for (int row = 0; row < rows; ++row) {
            const auto& hit = column_hits[row];
            if (!hit) continue;
            const double cos_inc = std::max(0.05, std::abs(hit->normal_world.dot(dirs[row])));
            const std::size_t pixel = static_cast<std::size_t>(col) * rows + row;
            centers[pixel] = {hit->range_m, 1.0, reflectivity(hit->material) * cos_inc};
            solid[pixel] = hit->material != Material::kFoliage ? 1 : 0;
            segment[pixel] = hit->curve_segment;
            if (wind && Wind::sways(hit->material)) {
              const Eigen::Vector3d p = c.origin_world + hit->range_m * dirs[row];
              sway_gain[pixel] = static_cast<float>(Wind::gain(
                  hit->material, p.z() - scene.terrain().smoothHeight(p.x(), p.y())));
            }
          }
        }
      });

  // Pass 2: where the centre ranges of neighbouring pixels jump (an edge), the beam footprint
  // may straddle several surfaces: cast the sub-rays of the ring and mix. Elsewhere the footprint
  // lies on one surface and the centre ray stands for it.
  auto rangeAt = [&](int col, int row) {
    return centers[static_cast<std::size_t>((col + cols) % cols) * rows + row].range_m;
  };
  // Only the azimuth neighbours are compared: they are one footprint apart (0.35 deg at 1024
  // columns), while the rows are about two footprints apart (0.7 deg), too far to tell. Only
  // edges whose nearer side is solid (stems, branches, rocks, logs, the ground) get sub-rays:
  // foliage is clutter at the footprint's scale anyway, and sub-rays there would triple the cost.
  auto solidAt = [&](int col, int row) {
    return solid[static_cast<std::size_t>((col + cols) % cols) * rows + row] != 0;
  };
  auto segmentAt = [&](int col, int row) {
    return segment[static_cast<std::size_t>((col + cols) % cols) * rows + row];
  };
  // Half-angle tangent of the ring: a ring ray is tan_ring * t off the centre ray at range t.
  const double tan_ring = std::tan(ring_rad);
  // The ring of pixel (col, row): a range jump to an azimuth neighbour flags a possible edge.
  // When the nearer side of every jump is a curve (stem, branch, twig: most edges in a forest),
  // the cones settle each ring ray exactly and cheaply (ring_on_curve.hpp): a ray that stays on
  // the cone its own centre ray hit, or misses the nearer curve a neighbour's centre ray hit,
  // sees what the centre ray saw and is not cast. The neighbours are a column (0.35 deg) apart
  // and the ring only 0.13 deg off the centre, so most flagged rays are settled.
  struct RingPlan {
    bool edge = false;      ///< some azimuth neighbour's range jumps and its near side is solid
    bool cast_all = false;  ///< a near side is not a curve (ground, rock): no shortcut
    int n_curves = 0;
    std::array<std::int32_t, 2> curve{};  ///< near-side curve segments
    std::array<bool, 2> own{};            ///< the pixel's own centre ray hit it
  };
  auto planRing = [&](int col, int row) {
    RingPlan plan;
    const double r = rangeAt(col, row);
    for (const int nb : {col - 1, col + 1}) {
      const double q = rangeAt(nb, row);
      if (q == r) continue;
      const bool near_is_self = r < q;
      if (!(near_is_self ? solidAt(col, row) : solidAt(nb, row))) continue;
      if (!(q == kNoHit || r == kNoHit || std::abs(q - r) > 0.15 + 0.01 * std::min(r, q)))
        continue;
      plan.edge = true;
      const std::int32_t near_segment = near_is_self ? segmentAt(col, row) : segmentAt(nb, row);
      if (near_segment < 0) {
        plan.cast_all = true;
        break;
      }
      plan.curve[plan.n_curves] = near_segment;
      plan.own[plan.n_curves] = near_is_self;
      ++plan.n_curves;
    }
    return plan;
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, cols, 16), [&](const tbb::blocked_range<int>&
                                                                  range) {
    std::array<SubHit, kMaxSubRays> hits{};
    std::vector<int> ring_rows;
    /// Per ring row, k_rays - 1 slots: the index of the ray in ring_dirs, or -1 for a ray that
    /// sees what the centre ray saw.
    std::vector<int> ring_slots;
    std::vector<Eigen::Vector3d> ring_dirs;
    std::vector<double> ring_t_min;
    std::vector<std::optional<RayHit>> ring_hits;
    std::array<Eigen::Vector3d, kMaxSubRays> pixel_dirs;
    for (int col = range.begin(); col != range.end(); ++col) {
      const Column& c = columns[col];
      // The ring rays of every pixel of the column that needs them, cast together in packets
      // of 16 (Embree rtcIntersect16).
      ring_rows.clear();
      ring_slots.clear();
      ring_dirs.clear();
      ring_t_min.clear();
      if (k_rays > 1) {
        for (int row = 0; row < rows; ++row) {
          const RingPlan plan = planRing(col, row);
          if (!plan.edge) continue;
          const std::uint64_t pixel_id = static_cast<std::uint64_t>(col) * rows + row;
          const Eigen::Vector3d d_world = c.R_world_lidar * direction(col, row);
          const Eigen::Vector3d e1 =
              d_world
                  .cross(std::abs(d_world.z()) < 0.9 ? Eigen::Vector3d::UnitZ()
                                                     : Eigen::Vector3d::UnitX())
                  .normalized();
          const Eigen::Vector3d e2 = d_world.cross(e1);
          const double spin = 2.0 * kPi * hashUniform(seed_, index, pixel_id, 101);
          const std::int32_t own_segment = segment[pixel_id];
          std::array<bool, kMaxSubRays> cast{};
          bool any = false;
          for (int k = 1; k < k_rays; ++k) {
            const double a = spin + 2.0 * kPi * (k - 1) / (k_rays - 1);
            pixel_dirs[k] =
                (d_world + tan_ring * (std::cos(a) * e1 + std::sin(a) * e2)).normalized();
            cast[k] = plan.cast_all;
            for (int i = 0; i < plan.n_curves && !cast[k]; ++i) {
              cast[k] = plan.own[i] ? !detail::rayStaysOnCurve(scene, plan.curve[i],
                                                               c.origin_world, pixel_dirs[k])
                                    : !detail::rayMissesCurve(scene, plan.curve[i],
                                                              c.origin_world, pixel_dirs[k]);
            }
            // A ray that misses the nearer curve sees what its centre saw only if it stays on
            // that surface too: the centre's own curve may end between the two centre rays,
            // behind the nearer one (a stem's edge behind a twig).
            if (!cast[k] && own_segment >= 0)
              cast[k] = !detail::rayStaysOnCurve(scene, own_segment, c.origin_world, pixel_dirs[k]);
            any = any || cast[k];
          }
          if (!any) continue;  // the whole footprint sees what the centre ray saw
          ring_rows.push_back(row);
          // The ring looks for the surfaces the centre rays around it found: it starts just in
          // front of the nearest of them (a thin object in front of all three centre rays is
          // missed, as it is by a pixel that is not at an edge). About 9 % faster (sim_bench).
          double nearest_m = rangeAt(col, row);
          for (const int nb : {col - 1, col + 1}) nearest_m = std::min(nearest_m, rangeAt(nb, row));
          const double ring_t_min_m = std::max(0.0, nearest_m - kRingLead_m);
          for (int k = 1; k < k_rays; ++k) {
            if (!cast[k]) {
              ring_slots.push_back(-1);
              continue;
            }
            ring_slots.push_back(static_cast<int>(ring_dirs.size()));
            ring_dirs.push_back(pixel_dirs[k]);
            ring_t_min.push_back(ring_t_min_m);
          }
        }
        if (!ring_dirs.empty()) {
          scene.castRays(c.origin_world, ring_dirs, t_max_m, ring_hits, &ring_t_min);
          if (c.machine) c.machine->occlude(c.origin_world, ring_dirs, t_max_m, ring_hits);
        }
      }
      std::size_t next_ring = 0;
      for (int row = 0; row < rows; ++row) {
        const std::uint64_t pixel_id = static_cast<std::uint64_t>(col) * rows + row;
        const Eigen::Vector3d d_lidar = direction(col, row);
        const SubHit& center = centers[pixel_id];
        int n_hits = 0;
        if (next_ring < ring_rows.size() && ring_rows[next_ring] == row) {
          if (center.range_m != kNoHit)
            hits[n_hits++] = {center.range_m, center_weight, center.reflectivity_eff};
          for (int k = 1; k < k_rays; ++k) {
            const int ray = ring_slots[next_ring * static_cast<std::size_t>(k_rays - 1) + (k - 1)];
            if (ray < 0) {  // settled: sees the centre's surface
              if (center.range_m != kNoHit)
                hits[n_hits++] = {center.range_m, ring_weight, center.reflectivity_eff};
              continue;
            }
            const auto& hit = ring_hits[static_cast<std::size_t>(ray)];
            if (!hit) continue;
            const double cos_inc = std::max(
                0.05, std::abs(hit->normal_world.dot(ring_dirs[static_cast<std::size_t>(ray)])));
            hits[n_hits++] = {hit->range_m, ring_weight, reflectivity(hit->material) * cos_inc};
          }
          ++next_ring;
        } else if (center.range_m != kNoHit) {
          hits[n_hits++] = center;  // weight 1: the whole footprint on one surface
        }
        if (n_hits == 0) continue;
        for (int i = 1; i < n_hits; ++i) {  // insertion sort by range (a handful of entries)
          for (int j = i; j > 0 && hits[j].range_m < hits[j - 1].range_m; --j)
            std::swap(hits[j], hits[j - 1]);
        }
        // Cluster the sub-ray returns by range: the nearest cluster and the one behind it.
        auto cluster = [&](int first, double& w, double& r_mean, double& refl_mean) {
          int i = first;
          w = 0.0, r_mean = 0.0, refl_mean = 0.0;
          while (i < n_hits && hits[i].range_m < hits[first].range_m + 0.2) {
            w += hits[i].weight;
            r_mean += hits[i].weight * hits[i].range_m;
            refl_mean += hits[i].weight * hits[i].reflectivity_eff;
            ++i;
          }
          r_mean /= w, refl_mean /= w;
          return i;
        };
        double w_near, r_near, refl_near;
        const int next = cluster(0, w_near, r_near, refl_near);
        double r = r_near, weight = w_near, refl = refl_near;
        if (w_near < 0.5 && next < n_hits) {
          double w_far, r_far, refl_far;
          cluster(next, w_far, r_far, refl_far);
          if (r_far - r_near < 1.0) {  // one pulse with two overlapping echoes: a mixed range
            r = (w_near * r_near + w_far * r_far) / (w_near + w_far);
            weight = w_near + w_far;
            refl = (w_near * refl_near + w_far * refl_far) / weight;
          } else if (w_far > w_near) {  // the stronger, farther echo wins
            r = r_far, weight = w_far, refl = refl_far;
          }
        }
        // Detection: the energy returned decides the maximum range, with a soft edge.
        const double energy = refl * weight;
        const double r_max = params_.max_range_m * std::sqrt(energy / kReferenceReflectivity);
        if (r < params_.min_range_m || r > r_max) continue;
        if (params_.noise) {
          const double edge = std::clamp((r - 0.8 * r_max) / (0.2 * r_max), 0.0, 1.0);
          if (hashUniform(seed_, index, pixel_id, 102) <
              std::max(params_.dropout_probability, edge))
            continue;
          double sigma_m = params_.range_noise_m + params_.range_noise_per_m * r;
          if (params_.range_noise_at_limit_m > 0.0)  // weak returns: SNR falls as (r / r_max)^2
            sigma_m += params_.range_noise_at_limit_m * (r / r_max) * (r / r_max);
          r += sigma_m * hashNormal(seed_, index, pixel_id, 103);
        }
        Pixel& px = pixels[pixel_id];
        px.valid = true;
        Eigen::Vector3d p_lidar = c.origin_lidar + r * d_lidar;
        if (wind && sway_gain[pixel_id] > 0.0f) {  // the surface has moved with the wind
          const Eigen::Vector3d p_world = c.origin_world + c.R_world_lidar * (r * d_lidar);
          const double t = t_start_s + col * dt_column;
          p_lidar += c.R_world_lidar.transpose() *
                     (sway_gain[pixel_id] * wind_field.displacement_m(p_world, t));
        }
        px.p_sensor = (geometry_.T_sensor_lidar * p_lidar).cast<float>();
        px.intensity = static_cast<float>(100.0 * refl);  // reflectivity x cos(incidence), percent
      }
    }
  });

  // Lost UDP packets: a whole packet's columns are missing from the frame.
  if (params_.noise && params_.packet_loss_probability > 0.0) {
    for (int first = 0; first < cols; first += kColumnsPerPacket) {
      if (hashUniform(seed_, index, static_cast<std::uint64_t>(first), 104) >=
          params_.packet_loss_probability)
        continue;
      const int end = std::min(cols, first + kColumnsPerPacket);
      for (std::size_t i = static_cast<std::size_t>(first) * rows;
           i < static_cast<std::size_t>(end) * rows; ++i)
        pixels[i].valid = false;
    }
  }

  io::Scan scan;
  scan.index = index;
  scan.t_start_s = t_start_s + time_offset_s;
  scan.t_end_s = t_start_s + (cols - 1) * dt_column + time_offset_s;
  PointCloud& cloud = scan.cloud_in_lidar;
  std::size_t valid = 0;
  for (const Pixel& px : pixels) valid += px.valid ? 1 : 0;
  cloud.reserve(valid);
  for (int col = 0; col < cols; ++col) {
    const double t = t_start_s + col * dt_column + time_offset_s;
    for (int row = 0; row < rows; ++row) {
      const Pixel& px = pixels[static_cast<std::size_t>(col) * rows + row];
      if (!px.valid) continue;
      cloud.positions.push_back(px.p_sensor.cast<double>());
      cloud.times_s.push_back(t);
      cloud.intensities.push_back(px.intensity);
      cloud.rings.push_back(static_cast<std::uint16_t>(row));
      cloud.columns.push_back(static_cast<std::uint16_t>(col));
    }
  }
  return scan;
}

}  // namespace taiga::sim

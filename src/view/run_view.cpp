#include "taiga/view/run_view.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "taiga/core/errors.hpp"
#include "taiga/eval/health_split.hpp"
#include "taiga/eval/timing.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/trees/tree_files.hpp"
#include "taiga/view/web_assets.hpp"

namespace taiga::view {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

/// At most this many trajectory poses and scans go to the page (evenly thinned): enough for a
/// line and a chart, small enough to load at once.
constexpr std::size_t kMaxSeries = 20000;

std::size_t stride(std::size_t n) { return n / kMaxSeries + 1; }

json position(const Eigen::Vector3d& p_map, const Eigen::Vector3d& origin) {
  const Eigen::Vector3d p = p_map - origin;
  return {p.x(), p.y(), p.z()};
}

json trajectoryJson(const fs::path& path, const Eigen::Vector3d& origin) {
  json out = json::array();
  if (!fs::exists(path)) return out;
  const Trajectory trajectory = io::readTum(path);
  for (std::size_t i = 0; i < trajectory.size(); i += stride(trajectory.size())) {
    json row = position(trajectory[i].pose.translation(), origin);
    row.insert(row.begin(), trajectory[i].t_s);
    out.push_back(row);
  }
  return out;
}

/// loops.csv's accepted closures as pairs of keyframe positions (keyframes.tum, row = id).
json loopsJson(const fs::path& loops_csv, const Trajectory& keyframes,
               const Eigen::Vector3d& origin) {
  json out = json::array();
  std::ifstream in(loops_csv);
  std::string line;
  if (!std::getline(in, line)) return out;
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string field; fields.size() < 10 && std::getline(row, field, ',');)
      fields.push_back(field);
    if (fields.size() < 10 || fields[9] != "1") continue;
    std::size_t current = 0, candidate = 0;
    std::from_chars(fields[1].data(), fields[1].data() + fields[1].size(), current);
    std::from_chars(fields[2].data(), fields[2].data() + fields[2].size(), candidate);
    if (current >= keyframes.size() || candidate >= keyframes.size()) continue;
    out.push_back({position(keyframes[current].pose.translation(), origin),
                   position(keyframes[candidate].pose.translation(), origin)});
  }
  return out;
}

json noScans() { return {{"t_s", json::array()}, {"ms", json::array()}, {"status", json::array()}}; }

/// Per scan: time, total processing time (timing.csv) and status (scans.csv).
json scansJson(const fs::path& dir) {
  json out = noScans();
  if (!fs::exists(dir / "timing.csv")) return out;
  const eval::TimingTable timing = eval::readTimingCsv(dir / "timing.csv");
  std::vector<eval::ScanStatusAt> statuses;
  if (fs::exists(dir / "scans.csv")) statuses = eval::readScanStatuses(dir / "scans.csv");
  const std::size_t n = timing.t_s.size();
  for (std::size_t i = 0; i < n; i += stride(n)) {
    out["t_s"].push_back(timing.t_s[i]);
    out["ms"].push_back(timing.values_ms[timing.total_column][i]);
    out["status"].push_back(statuses.size() == n ? statuses[i].status : "");
  }
  return out;
}

/// trees.csv (`taiga trees`, or `mapping.trees` in a run): [x, y, ground z, DBH, height] per
/// stem at breast height; NaN fields (a file without heights) as null.
json treesJson(const fs::path& path, const Eigen::Vector3d& origin) {
  json out = json::array();
  if (!fs::exists(path)) return out;
  for (const trees::TreeRecord& t : trees::readTreesCsv(path)) {
    const Eigen::Vector3d p = Eigen::Vector3d(t.bh_xy_m.x(), t.bh_xy_m.y(), t.ground_z_m) - origin;
    const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    out.push_back({p.x(), p.y(), number(p.z()), t.dbh_m, number(t.height_m)});
  }
  return out;
}

json summaryJson(const fs::path& path) {
  if (!fs::exists(path)) return json::object();
  std::ifstream in(path);
  const json summary = json::parse(in, nullptr, false);
  if (!summary.is_object()) return json::object();
  json out = json::object();
  for (const char* key : {"health", "time_per_scan_ms", "realtime_factor", "keyframes",
                          "loop_closures", "path_length_m", "duration_s", "georef"})
    if (summary.contains(key)) out[key] = summary[key];
  return out;
}

/// A cloud file has no side files: they are read from a run directory only (never from the
/// working directory).
json infoJson(const fs::path& input, bool run_dir, const LodTree& tree) {
  const Eigen::Vector3d& origin = tree.origin();
  json info = {{"mode", "run"},
               {"name", (run_dir ? input : input.filename()).string()},
               {"origin", {origin.x(), origin.y(), origin.z()}},
               {"points", tree.pointCount()},
               {"trajectory", json::array()},
               {"keyframes", json::array()},
               {"loops", json::array()},
               {"scans", noScans()},
               {"trees", json::array()},
               {"summary", json::object()}};
  if (!run_dir) return info;
  info["scans"] = scansJson(input);
  info["trajectory"] = trajectoryJson(input / "trajectory.tum", origin);
  info["trees"] = treesJson(input / "trees.csv", origin);
  if (fs::exists(input / "keyframes.tum")) {
    const Trajectory keyframes = io::readTum(input / "keyframes.tum");
    for (const StampedPose& k : keyframes.poses())
      info["keyframes"].push_back(position(k.pose.translation(), origin));
    info["loops"] = loopsJson(input / "loops.csv", keyframes, origin);
  }
  info["summary"] = summaryJson(input / "summary.json");
  return info;
}

json nodesJson(const LodTree& tree) {
  json nodes = json::array();
  for (const LodNode& node : tree.nodes()) {
    json children = json::array();
    for (int child : node.children)
      if (child >= 0) children.push_back(child);
    nodes.push_back({{"min", {node.min_m.x(), node.min_m.y(), node.min_m.z()}},
                     {"max", {node.max_m.x(), node.max_m.y(), node.max_m.z()}},
                     {"depth", node.depth},
                     {"parent", node.parent},
                     {"children", children},
                     {"points", node.count}});
  }
  return nodes;
}

std::string withoutQuery(const std::string& resource) {
  return resource.substr(0, resource.find('?'));
}

/// The page and its scripts, or nullopt when `path` is not one.
std::optional<stream::HttpResponse> assetResponse(const std::string& path) {
  const WebAsset* asset = findWebAsset(path == "/index.html" ? "/" : path);
  if (!asset) return std::nullopt;
  return stream::HttpResponse{200, std::string(asset->content_type), std::string(asset->bytes)};
}

/// The cloud's points for the tree; a LAS file a million points at a time, so a large map is
/// never held in double precision with all its channels.
LodPoints readPoints(const fs::path& path) {
  LodPoints points;
  if (io::lowercaseExtension(path) != ".las") {
    points.append(io::readAnyCloudFile(path));
    return points;
  }
  io::LasReader reader(path);
  constexpr std::uint64_t kChunk = 1u << 20;
  points.xyzi.reserve(4 * reader.pointCount());
  for (std::uint64_t first = 0; first < reader.pointCount(); first += kChunk) {
    PointCloud chunk;
    reader.read(first, kChunk, chunk);
    points.append(chunk);
  }
  return points;
}

stream::HttpResponse notFound(const std::string& path) {
  return {404, "text/plain", fmt::format("{}: not found\n", path)};
}

}  // namespace

RunView RunView::load(const fs::path& input, const LodOptions& options) {
  const bool run_dir = fs::is_directory(input);
  const fs::path map_path = run_dir ? input / "map.las" : input;
  if (run_dir && !fs::exists(map_path))
    throw InputError(fmt::format(
        "{}: a directory without map.las (give a run directory of `taiga run`, or a LAS/PLY/PCD "
        "file)",
        input.string()));
  if (!fs::exists(map_path)) throw InputError(fmt::format("{}: no such file", input.string()));
  RunView view;
  view.tree_ = LodTree::build(readPoints(map_path), options);
  if (view.tree_.pointCount() == 0)
    throw InputError(fmt::format("{}: no finite point to show", map_path.string()));
  try {
    view.info_json_ = infoJson(input, run_dir, view.tree_).dump();
  } catch (const InputError& e) {  // a broken side file: say which, the map is still shown
    throw InputError(fmt::format("{} (in {})", e.what(), input.string()));
  }
  view.nodes_json_ = nodesJson(view.tree_).dump();
  return view;
}

stream::HttpResponse RunView::get(const std::string& resource) const {
  const std::string path = withoutQuery(resource);
  if (auto asset = assetResponse(path)) return *asset;
  if (path == "/api/info") return {200, "application/json", info_json_};
  if (path == "/api/nodes") return {200, "application/json", nodes_json_};
  constexpr std::string_view kNode = "/api/node/";
  if (path.starts_with(kNode)) {
    std::size_t id = 0;
    const char* first = path.data() + kNode.size();
    const char* last = path.data() + path.size();
    const auto [end, error] = std::from_chars(first, last, id);
    if (error != std::errc() || end != last || id >= tree_.nodes().size()) return notFound(path);
    const std::span<const float> xyzi = tree_.points(tree_.nodes()[id]);
    return {200, "application/octet-stream",
            std::string(reinterpret_cast<const char*>(xyzi.data()), xyzi.size_bytes())};
  }
  return notFound(path);
}

stream::HttpResponse liveViewResponse(const std::string& resource) {
  const std::string path = withoutQuery(resource);
  if (auto asset = assetResponse(path)) return *asset;
  if (path == "/api/info") return {200, "application/json", R"({"mode":"live"})"};
  return notFound(path);
}

}  // namespace taiga::view

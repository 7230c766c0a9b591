#pragma once
// What the viewer's page is served (docs/viewer.md): the page itself and, for a finished run, its
// data over HTTP. `taiga view` serves a RunView; `taiga run --view` serves liveViewResponse on
// its Foxglove WebSocket port, and the page takes the run's data from the channels there.
//
// HTTP API (JSON unless said; coordinates in the map frame relative to `origin`, in metres):
//   /api/info     mode ("run" or "live"), name, origin, point count, the trajectory (t, x, y, z),
//                 keyframe positions, accepted loop closures (two positions each), per-scan time
//                 and status, the trees of trees.csv, and summary.json's health and time per scan
//   /api/nodes    the level-of-detail octree (lod_tree.hpp): per node its cube, depth, parent,
//                 children and point count
//   /api/node/N   node N's points: float32 little-endian x, y, z, intensity per point

#include <filesystem>
#include <string>

#include "taiga/stream/foxglove_server.hpp"
#include "taiga/view/lod_tree.hpp"

namespace taiga::view {

class RunView {
 public:
  /// A run directory of `taiga run` (its map.las, and the trajectory, keyframes, loops and scan
  /// logs when they are there) or a LAS/PLY/PCD file. InputError naming the file that cannot be
  /// read.
  static RunView load(const std::filesystem::path& input, const LodOptions& options = {});

  /// The answer to a GET of `resource` (path and query).
  stream::HttpResponse get(const std::string& resource) const;

  const LodTree& tree() const { return tree_; }

 private:
  LodTree tree_;
  std::string info_json_, nodes_json_;
};

/// The page and `/api/info` = {"mode": "live"}: what `taiga run --view` serves over HTTP.
stream::HttpResponse liveViewResponse(const std::string& resource);

}  // namespace taiga::view

#pragma once
// Re-attaching a map segment (docs/mapping.md, "Relocalization"). When the odometry was lost for
// long it gives its local map up and starts a new segment, placed by dead reckoning: after
// seconds without the lidar that guess can be metres and degrees off, and a loop closure's local
// registration from it may settle in a wrong basin of a forest that looks alike everywhere. So
// the keyframes of a segment not yet attached are registered against the attached map with a
// search wide enough for that guess:
//
//   candidate: the attached keyframe nearest to the current one's dead-reckoned pose, within
//              loop_max_search_radius_m;
//   search:    a correlative search (registration/correlative_search.hpp) of the current
//              keyframe's registration cloud over +-relocalization_search_deg of heading and
//              +-relocalization_search_m of horizontal position in the candidate's submap (its
//              attached neighbours); its best distinct starts refined by NDT, coarse to fine;
//   accept:    the best refinement by overlap (share of the points above the ground within
//              voxel_size_m of the submap: ground lies near other ground at almost any pose)
//              converged, with an overlap of at least kMinOverlap, clearly better than
//              every distinct rival (a forest has look-alike places: a near tie is refused, and
//              the next keyframe tries again). Not the fitness, as loops do: the keyframe may
//              stand metres from the submap's keyframes and see what they did not.
//
// An accepted attempt is a relative pose between the candidate and the current keyframe, added
// to the graph like a loop; the bridge between the segments carries no weight
// (PoseGraph::addKeyframe), so the graph moves the whole segment onto the map.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "taiga/core/mapping_config.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/pose_graph.hpp"
#include "taiga/mapping/stem_constellation.hpp"

namespace taiga::mapping {

struct RelocalizationAttempt {
  std::size_t current = 0;
  std::size_t candidate = 0;
  bool accepted = false;
  std::string note;            ///< why it was refused
  double overlap = 0.0;        ///< of the best refinement
  double rival_overlap = 0.0;  ///< of the best distinct rival (0: none)
  double fitness_m2 = 0.0;
  double correction_m = 0.0;    ///< how far it moves the current keyframe from dead reckoning
  double correction_deg = 0.0;  ///< and how far it turns it
  double search_ms = 0.0;       ///< wall time of the search and the refinements
  RelativePose link;            ///< from = candidate, to = current
};

/// Whether a keyframe belongs to the attached map.
using Attached = std::function<bool(std::size_t keyframe)>;

/// The attached keyframe nearest to `current` (graph poses) within loop_max_search_radius_m.
std::optional<std::size_t> findRelocalizationCandidate(const PoseGraph& graph, std::size_t current,
                                                       const Attached& attached,
                                                       const MappingConfig& config);

/// A keyframe's stems in its body frame (scanStemMarks, cached by the caller).
using KeyframeStemMarks = std::function<const std::vector<StemMark>&(std::size_t keyframe)>;

/// Searches for `current` in the candidate's submap and, with `stems_of`, wherever its stems match
/// the map's (see above); judges the result.
RelocalizationAttempt relocalize(const PoseGraph& graph, const KeyframeStore& store,
                                 std::size_t current, std::size_t candidate,
                                 const Attached& attached, const MappingConfig& config,
                                 const OdometryConfig& odometry,
                                 const KeyframeStemMarks& stems_of = {});

}  // namespace taiga::mapping

#pragma once
// Per-scan boxes around moving parts of the rig (a harvester's boom), in the body frame, from a
// CSV side file (`taiga run --moving-boxes FILE`; the simulator writes machine_boxes.csv):
//
//   scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz
//   1700000012.3,1,2.10,-0.40,0.95,1.80,0.25,0.30,0.98,0.0,0.0,0.199
//
// One row per box: the scan's stamp (s, on the lidar clock: the start time of the scan the box
// belongs to, which is the header stamp of the Ouster driver's clouds), an id (not used), the centre (m), the half extents (m) and
// the orientation (unit quaternion, w first) of the box in the body frame. Lines starting with
// '#' and blank lines are ignored.

#include <filesystem>

#include "taiga/core/box.hpp"

namespace taiga::io {

/// Throws InputError("FILE:LINE: ...") naming the column on malformed input.
MovingBoxes readMovingBoxes(const std::filesystem::path& path);

}  // namespace taiga::io

#include "machine_boxes_output.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace taiga::sim::detail {

MachineBoxesWriter::MachineBoxesWriter(const std::filesystem::path& path,
                                       const HarvesterMachine& machine)
    : path_(path), machine_(machine), out_(path) {
  out_ << "scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz\n";
  if (!out_) throw std::runtime_error(fmt::format("{}: cannot write", path_.string()));
}

void MachineBoxesWriter::writeScan(double stamp_s, double t0_s, double t1_s) {
  const auto boxes = machine_.enclosingBoxesInBody(t0_s, t1_s, kMachineBoxMargin_m);
  // The stamp exactly as the bag stores it: whole seconds and the nearest nanosecond.
  auto sec = static_cast<std::int64_t>(std::floor(stamp_s));
  auto nsec = std::llround((stamp_s - std::floor(stamp_s)) * 1e9);
  if (nsec >= 1000000000) nsec -= 1000000000, ++sec;
  for (std::size_t id = 0; id < boxes.size(); ++id) {
    const OrientedBox& b = boxes[id];
    const Eigen::Quaterniond& q = b.orientation;
    out_ << fmt::format("{}.{:09d},{},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.8f},{:.8f},{:.8f},{:.8f}\n",
                        sec, nsec, id, b.center.x(), b.center.y(), b.center.z(), b.half_extents.x(),
                        b.half_extents.y(), b.half_extents.z(), q.w(), q.x(), q.y(), q.z());
  }
  if (!out_) throw std::runtime_error(fmt::format("{}: cannot write", path_.string()));
}

std::string cabinBoxRigComment() {
  const OrientedBox cabin = HarvesterMachine::cabinInBody();
  const Eigen::Vector3d lo = cabin.center - cabin.half_extents, hi = cabin.center + cabin.half_extents;
  return fmt::format(
      "# Harvester: the cabin is a fixed box in the body frame (m), returns from it are the machine:\n"
      "#   min ({:.2f}, {:.2f}, {:.2f}) max ({:.2f}, {:.2f}, {:.2f}); grown by {:.2f} m it is\n"
      "#   rig.self_boxes_body below and box_id 0 of machine_boxes.csv, which also holds the moving\n"
      "#   crane's boxes per scan (taiga run --moving-boxes machine_boxes.csv).\n",
      lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z(), kMachineBoxMargin_m);
}

}  // namespace taiga::sim::detail

#include "taiga/eval/alignment.hpp"

#include <fmt/format.h>

#include <cassert>

#include "taiga/core/errors.hpp"
#include "taiga/lie/umeyama.hpp"

namespace taiga::eval {

std::string_view alignmentName(Alignment alignment) {
  switch (alignment) {
    case Alignment::kSe3:
      return "se3";
    case Alignment::kSim3:
      return "sim3";
    case Alignment::kOrigin:
      return "origin";
    case Alignment::kNone:
      return "none";
  }
  return "none";
}

Alignment parseAlignment(std::string_view name) {
  for (const Alignment a :
       {Alignment::kSe3, Alignment::kSim3, Alignment::kOrigin, Alignment::kNone})
    if (alignmentName(a) == name) return a;
  throw InputError(fmt::format("alignment '{}' is not one of se3, sim3, origin, none", name));
}

AlignmentTransform umeyama(const std::vector<Eigen::Vector3d>& source,
                           const std::vector<Eigen::Vector3d>& target, bool with_scale) {
  assert(source.size() == target.size());
  const std::size_t n = source.size();
  if (n == 0) throw InputError("cannot align: no associated poses");
  const int rank = lie::crossCovarianceRank(source, target);
  if (rank < 2)
    throw InputError(fmt::format(
        "cannot align ({} pose pairs): the positions lie on a line or a point (covariance rank "
        "{} < 2), so the rotation is not determined; use --align origin or --align none",
        n, rank));
  const lie::Similarity similarity = lie::umeyama(source, target, with_scale);
  return {similarity.T_target_source, similarity.scale};
}

AlignmentTransform computeAlignment(const std::vector<StampedPose>& est,
                                    const std::vector<StampedPose>& ref, Alignment alignment) {
  assert(est.size() == ref.size() && !est.empty());
  switch (alignment) {
    case Alignment::kSe3:
    case Alignment::kSim3: {
      std::vector<Eigen::Vector3d> source, target;
      source.reserve(est.size());
      target.reserve(ref.size());
      for (std::size_t i = 0; i < est.size(); ++i) {
        source.push_back(est[i].pose.translation());
        target.push_back(ref[i].pose.translation());
      }
      return umeyama(source, target, alignment == Alignment::kSim3);
    }
    case Alignment::kOrigin:
      return {ref.front().pose * est.front().pose.inverse(), 1.0};
    case Alignment::kNone:
      break;
  }
  return {};
}

AlignmentTransform alignWithOrientations(const std::vector<StampedPose>& est,
                                         const std::vector<StampedPose>& ref, double lever_m) {
  assert(est.size() == ref.size() && !est.empty());
  Eigen::Vector3d x_mean = Eigen::Vector3d::Zero(), y_mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < est.size(); ++i) {
    x_mean += est[i].pose.translation();
    y_mean += ref[i].pose.translation();
  }
  x_mean /= static_cast<double>(est.size());
  y_mean /= static_cast<double>(ref.size());
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < est.size(); ++i) {
    M += (ref[i].pose.translation() - y_mean) * (est[i].pose.translation() - x_mean).transpose();
    M += lever_m * lever_m * ref[i].pose.rotation().matrix() *
         est[i].pose.rotation().matrix().transpose();
  }
  const Eigen::Matrix3d R = lie::kabschRotation(M);
  return {lie::SE3(lie::SO3::fromMatrix(R), y_mean - R * x_mean), 1.0};
}

std::vector<StampedPose> applyAlignment(const std::vector<StampedPose>& poses,
                                        const AlignmentTransform& transform) {
  std::vector<StampedPose> aligned;
  aligned.reserve(poses.size());
  for (const StampedPose& p : poses) {
    const lie::SE3 scaled(p.pose.rotation(), transform.scale * p.pose.translation());
    aligned.push_back({p.t_s, transform.T_ref_est * scaled});
  }
  return aligned;
}

}  // namespace taiga::eval

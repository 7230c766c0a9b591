#include "taiga/eval/alignment.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <cassert>
#include <limits>

#include "taiga/core/errors.hpp"

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
  Eigen::Vector3d mean_x = Eigen::Vector3d::Zero(), mean_y = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mean_x += source[i];
    mean_y += target[i];
  }
  const double count = static_cast<double>(n);
  mean_x /= count;
  mean_y /= count;
  double sigma_x = 0.0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d dx = source[i] - mean_x;
    sigma_x += dx.squaredNorm();
    covariance += (target[i] - mean_y) * dx.transpose();
  }
  sigma_x /= count;
  covariance /= count;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  int rank = 0;
  for (int i = 0; i < 3; ++i) rank += d[i] > std::numeric_limits<double>::epsilon() ? 1 : 0;
  if (rank < 2)
    throw InputError(fmt::format(
        "cannot align ({} pose pairs): the positions lie on a line or a point (covariance rank "
        "{} < 2), so the rotation is not determined; use --align origin or --align none",
        n, rank));
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (U.determinant() * V.determinant() < 0.0) S(2, 2) = -1.0;
  const Eigen::Matrix3d R = U * S * V.transpose();
  const double scale = with_scale ? (d.asDiagonal() * S).trace() / sigma_x : 1.0;
  const Eigen::Vector3d t = mean_y - scale * R * mean_x;
  return {lie::SE3(lie::SO3::fromMatrix(R), t), scale};
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

#include "taiga/lie/umeyama.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cassert>
#include <cmath>
#include <limits>

namespace taiga::lie {
namespace {

/// The points as the columns of a 3 x n matrix, the form Eigen::umeyama takes.
Eigen::Matrix3Xd columns(std::span<const Vector3> points) {
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) m.col(static_cast<Eigen::Index>(i)) = points[i];
  return m;
}

}  // namespace

int crossCovarianceRank(std::span<const Vector3> source, std::span<const Vector3> target) {
  assert(source.size() == target.size());
  if (source.empty()) return 0;
  const Eigen::Matrix3Xd x = columns(source), y = columns(target);
  const Eigen::Matrix3Xd dx = x.colwise() - x.rowwise().mean();
  const Eigen::Matrix3Xd dy = y.colwise() - y.rowwise().mean();
  const Matrix3 covariance = dy * dx.transpose() / static_cast<double>(source.size());
  const Vector3 d = Eigen::JacobiSVD<Matrix3>(covariance).singularValues();
  return static_cast<int>((d.array() > std::numeric_limits<double>::epsilon()).count());
}

Matrix3 kabschRotation(const Matrix3& M) {
  const Eigen::JacobiSVD<Matrix3> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3 D = Matrix3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

Similarity umeyama(std::span<const Vector3> source, std::span<const Vector3> target,
                   bool with_scale) {
  assert(source.size() == target.size() && !source.empty());
  const Eigen::Matrix4d T = Eigen::umeyama(columns(source), columns(target), with_scale);
  // Eigen returns c R in the rotation block; its Frobenius norm is sqrt(3) c.
  const Matrix3 cR = T.topLeftCorner<3, 3>();
  const double scale = with_scale ? cR.norm() / std::sqrt(3.0) : 1.0;
  return {SE3(SO3::fromMatrix(cR / scale), T.topRightCorner<3, 1>()), scale};
}

}  // namespace taiga::lie

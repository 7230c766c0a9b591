#include "taiga/io/trajectory_io.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "numeric_text.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

using detail::formatExact;
using detail::NumericTextReader;

constexpr std::size_t kTumValues = 8;
constexpr std::size_t kKittiValues = 12;

// Quaternions in files are rounded to the digits written; anything further from unit length is
// not a rotation (wrong column order, a zero quaternion, or a different format).
constexpr double kQuaternionNormTolerance = 1e-2;
// KITTI rotation matrices are printed with 6-9 significant digits.
constexpr double kRotationOrthonormalityTolerance = 1e-3;

// Appends with the line number in the error, instead of the pose index Trajectory would name.
void appendChecked(NumericTextReader& reader, Trajectory& trajectory, double t_s,
                   const lie::SE3& pose) {
  if (!trajectory.empty() && !(t_s > trajectory.back().t_s)) {
    reader.fail(
        fmt::format("time {} is not after the previous pose's time {}; poses must be in "
                    "strictly increasing time order",
                    formatExact(t_s), formatExact(trajectory.back().t_s)));
  }
  trajectory.append(t_s, pose);
}

void requireValueCount(NumericTextReader& reader, const std::vector<double>& values,
                       std::size_t expected, const char* layout) {
  if (values.size() != expected) {
    reader.fail(fmt::format("expected {} values ({}), found {}", expected, layout, values.size()));
  }
}

std::FILE* openForWriting(const std::filesystem::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file)
    throw InputError(
        fmt::format("{}: cannot open for writing: {}", path.string(), std::strerror(errno)));
  return file;
}

void closeWritten(std::FILE* file, const std::filesystem::path& path) {
  const bool failed = std::ferror(file) != 0;
  if (std::fclose(file) != 0 || failed) {
    throw writeFailed(path);
  }
}

}  // namespace

Trajectory readTum(const std::filesystem::path& path) {
  NumericTextReader reader(path);
  Trajectory trajectory;
  std::vector<double> v;
  while (reader.next(v)) {
    requireValueCount(reader, v, kTumValues, "t x y z qx qy qz qw");
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
      reader.fail(
          fmt::format("quaternion (qx qy qz qw) = ({} {} {} {}) has norm {:.6f}; expected a "
                      "unit quaternion with w last",
                      v[4], v[5], v[6], v[7], q.norm()));
    }
    appendChecked(reader, trajectory, v[0], lie::SE3(q, Eigen::Vector3d(v[1], v[2], v[3])));
  }
  if (trajectory.empty())
    reader.failFile("contains no poses (expected lines of 't x y z qx qy qz qw')");
  return trajectory;
}

Trajectory readKitti(const std::filesystem::path& path,
                     const std::optional<std::filesystem::path>& times_path) {
  std::vector<double> times_s;
  std::optional<NumericTextReader> times_reader;
  if (times_path) times_reader.emplace(*times_path);

  NumericTextReader reader(path);
  Trajectory trajectory;
  std::vector<double> v, t;
  while (reader.next(v)) {
    requireValueCount(reader, v, kKittiValues, "r11 r12 r13 tx r21 r22 r23 ty r31 r32 r33 tz");
    Eigen::Matrix3d R;
    R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (error > kRotationOrthonormalityTolerance || R.determinant() < 0.0) {
      reader.fail(
          fmt::format("the 3x3 block is not a rotation matrix (|R^T R - I| = {:.2g}, det = "
                      "{:.4f})",
                      error, R.determinant()));
    }
    double t_s = static_cast<double>(trajectory.size());
    if (times_reader) {
      if (!times_reader->next(t)) {
        times_reader->failFile(fmt::format("has fewer times than {} has poses", path.string()));
      }
      if (t.size() != 1)
        times_reader->fail(fmt::format("expected 1 value (time), found {}", t.size()));
      t_s = t[0];
    }
    appendChecked(reader, trajectory, t_s,
                  lie::SE3(lie::SO3::fromMatrix(R), Eigen::Vector3d(v[3], v[7], v[11])));
  }
  if (times_reader && times_reader->next(t)) {
    times_reader->fail(
        fmt::format("more times than {} has poses ({})", path.string(), trajectory.size()));
  }
  if (trajectory.empty()) reader.failFile("contains no poses (expected lines of 12 values)");
  return trajectory;
}

void writeTum(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::FILE* file = openForWriting(path);
  fmt::print(file, "# t x y z qx qy qz qw\n");
  for (const StampedPose& p : trajectory) {
    const Eigen::Vector3d& t = p.pose.translation();
    const Eigen::Quaterniond& q = p.pose.rotation().quaternion();
    fmt::print(file, "{} {} {} {} {} {} {} {}\n", formatExact(p.t_s), formatExact(t.x()),
               formatExact(t.y()), formatExact(t.z()), formatExact(q.x()), formatExact(q.y()),
               formatExact(q.z()), formatExact(q.w()));
  }
  closeWritten(file, path);
}

void writeKitti(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::FILE* file = openForWriting(path);
  for (const StampedPose& p : trajectory) {
    const Eigen::Matrix4d T = p.pose.matrix();
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 4; ++col) {
        fmt::print(file, "{}{}", formatExact(T(row, col)), row == 2 && col == 3 ? "\n" : " ");
      }
    }
  }
  closeWritten(file, path);
}

TrajectoryFormat detectTrajectoryFormat(const std::filesystem::path& path) {
  NumericTextReader reader(path);
  std::vector<double> v;
  if (!reader.next(v)) reader.failFile("contains no poses");
  if (v.size() == kTumValues) return TrajectoryFormat::kTum;
  if (v.size() == kKittiValues) return TrajectoryFormat::kKitti;
  reader.fail(
      fmt::format("found {} values; expected 8 (TUM: t x y z qx qy qz qw) or 12 (KITTI: "
                  "3x4 matrix, row-major)",
                  v.size()));
}

Trajectory readTrajectory(const std::filesystem::path& path) {
  return detectTrajectoryFormat(path) == TrajectoryFormat::kTum ? readTum(path) : readKitti(path);
}

}  // namespace taiga::io

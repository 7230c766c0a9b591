#include "taiga/mapping/keyframe_store.hpp"

#include <fmt/format.h>

#include "taiga/core/errors.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/mapping/keyframe_file.hpp"
#include "taiga/preprocess/voxel_filter.hpp"

namespace taiga::mapping {
namespace {

constexpr const char* kPosesFile = "poses.tum";

std::shared_ptr<const PointCloud> registrationCopy(const PointCloud& cloud_in_body,
                                                   double voxel_m) {
  if (voxel_m <= 0.0) return std::make_shared<const PointCloud>();
  const PointCloud filtered = preprocess::voxelFilter(cloud_in_body, voxel_m);
  // Registration needs positions only. A fresh vector of the exact size: the filter's own keeps
  // the capacity it grew to (up to twice its size), and a copy stays in RAM per keyframe.
  auto positions_only = std::make_shared<PointCloud>();
  positions_only->positions.assign(filtered.positions.begin(), filtered.positions.end());
  return positions_only;
}

}  // namespace

struct KeyframeStore::Impl {
  std::filesystem::path dir;
  KeyframeStoreOptions options;
  mutable std::mutex mutex;
  std::vector<KeyframeInfo> infos;
  std::vector<std::shared_ptr<const PointCloud>> registration_clouds;

  const KeyframeInfo& at(std::uint64_t id) const {
    if (id >= infos.size())
      throw OutOfRangeError(fmt::format("keyframe {} is not in the store {} ({} keyframes)", id,
                                        dir.string(), infos.size()));
    return infos[id];
  }
};

KeyframeStore::KeyframeStore(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
KeyframeStore::KeyframeStore(KeyframeStore&&) noexcept = default;
KeyframeStore& KeyframeStore::operator=(KeyframeStore&&) noexcept = default;
KeyframeStore::~KeyframeStore() = default;

KeyframeStore KeyframeStore::create(const std::filesystem::path& dir,
                                    KeyframeStoreOptions options) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw InputError(
        fmt::format("{}: cannot create the keyframe directory: {}", dir.string(), ec.message()));
  // Files of an earlier run in the same directory would be taken for this run's by open().
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".tkf" || entry.path().filename() == kPosesFile)
      std::filesystem::remove(entry.path());
  }
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  impl->options = options;
  return KeyframeStore(std::move(impl));
}

KeyframeStore KeyframeStore::open(const std::filesystem::path& dir, KeyframeStoreOptions options) {
  const std::filesystem::path poses_path = dir / kPosesFile;
  if (!std::filesystem::exists(poses_path))
    throw InputError(fmt::format("{}: missing: not a keyframe directory of taiga run",
                                 poses_path.string()));
  const Trajectory poses = io::readTum(poses_path);
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  impl->options = options;
  KeyframeStore store(std::move(impl));
  for (std::size_t id = 0; id < poses.size(); ++id) {
    const std::filesystem::path path = store.keyframePath(id);
    if (!std::filesystem::exists(path))
      throw InputError(fmt::format("{}: missing ({} lists {} keyframes)", path.string(),
                                   poses_path.string(), poses.size()));
    KeyframeInfo info;
    info.id = id;
    info.T_world_body = poses[id].pose;
    std::shared_ptr<const PointCloud> registration;
    const KeyframeFileHeader header = readKeyframeHeader(path);
    if (header.id != id || header.t_s != poses[id].t_s) {
      throw InputError(fmt::format(
          "{}: keyframe {} at t = {} s, but {} lists keyframe {} at t = {} s", path.string(),
          header.id, header.t_s, poses_path.string(), id, poses[id].t_s));
    }
    info.t_s = header.t_s;
    info.point_count = header.point_count;
    if (options.registration_voxel_m > 0.0) {
      registration =
          registrationCopy(readKeyframeFile(path).cloud_in_body, options.registration_voxel_m);
    } else {
      registration = std::make_shared<const PointCloud>();
    }
    store.impl_->infos.push_back(info);
    store.impl_->registration_clouds.push_back(std::move(registration));
  }
  return store;
}

std::uint64_t KeyframeStore::add(double t_s, const lie::SE3& T_world_body,
                                 const PointCloud& cloud_in_body) {
  std::uint64_t id = 0;
  {
    const std::lock_guard lock(impl_->mutex);
    id = impl_->infos.size();
    if (!impl_->infos.empty() && !(t_s > impl_->infos.back().t_s))
      throw std::invalid_argument(fmt::format("KeyframeStore::add: time {} is not after {}", t_s,
                                              impl_->infos.back().t_s));
  }
  // The slow parts (file, voxel filter) outside the lock: readers of other keyframes go on.
  writeKeyframeFile(keyframePath(id), id, t_s, cloud_in_body);
  KeyframeInfo info{.id = id, .t_s = t_s, .T_world_body = T_world_body,
                    .point_count = cloud_in_body.size()};
  std::shared_ptr<const PointCloud> registration =
      registrationCopy(cloud_in_body, impl_->options.registration_voxel_m);
  const std::lock_guard lock(impl_->mutex);
  impl_->infos.push_back(info);
  impl_->registration_clouds.push_back(std::move(registration));
  return id;
}

std::size_t KeyframeStore::size() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->infos.size();
}

const std::filesystem::path& KeyframeStore::directory() const { return impl_->dir; }

std::filesystem::path KeyframeStore::keyframePath(std::uint64_t id) const {
  return impl_->dir / fmt::format("{:06d}.tkf", id);
}

PointCloud KeyframeStore::load(std::uint64_t id) const {
  const KeyframeInfo info = this->info(id);
  KeyframeFileContent content = readKeyframeFile(keyframePath(id));
  if (content.header.id != id || content.header.point_count != info.point_count) {
    throw InputError(fmt::format("{}: holds keyframe {} with {} points, expected keyframe {} with {}",
                                 keyframePath(id).string(), content.header.id,
                                 content.header.point_count, id, info.point_count));
  }
  return std::move(content.cloud_in_body);
}

std::shared_ptr<const PointCloud> KeyframeStore::registrationCloud(std::uint64_t id) const {
  const std::lock_guard lock(impl_->mutex);
  impl_->at(id);
  return impl_->registration_clouds[id];
}

KeyframeInfo KeyframeStore::info(std::uint64_t id) const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->at(id);
}

lie::SE3 KeyframeStore::pose(std::uint64_t id) const { return info(id).T_world_body; }

std::vector<lie::SE3> KeyframeStore::poses() const {
  const std::lock_guard lock(impl_->mutex);
  std::vector<lie::SE3> out;
  out.reserve(impl_->infos.size());
  for (const KeyframeInfo& info : impl_->infos) out.push_back(info.T_world_body);
  return out;
}

Trajectory KeyframeStore::trajectory() const {
  const std::lock_guard lock(impl_->mutex);
  Trajectory out;
  for (const KeyframeInfo& info : impl_->infos) out.append(info.t_s, info.T_world_body);
  return out;
}

void KeyframeStore::setPoses(const std::vector<lie::SE3>& poses_T_world_body) {
  const std::lock_guard lock(impl_->mutex);
  if (poses_T_world_body.size() != impl_->infos.size())
    throw std::invalid_argument(fmt::format("KeyframeStore::setPoses: {} poses for {} keyframes",
                                            poses_T_world_body.size(), impl_->infos.size()));
  for (std::size_t k = 0; k < poses_T_world_body.size(); ++k)
    impl_->infos[k].T_world_body = poses_T_world_body[k];
}

void KeyframeStore::writePoses() const {
  const std::filesystem::path path = impl_->dir / kPosesFile;
  const std::filesystem::path temporary = impl_->dir / (std::string(kPosesFile) + ".tmp");
  io::writeTum(temporary, trajectory());
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) throw InputError(fmt::format("{}: cannot write: {}", path.string(), ec.message()));
}

}  // namespace taiga::mapping

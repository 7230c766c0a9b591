#include "taiga/mapping/keyframe_store.hpp"

#include <fmt/format.h>

#include <list>
#include <unordered_map>

#include "taiga/core/errors.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/mapping/keyframe_file.hpp"
#include "taiga/preprocess/voxel_filter.hpp"

namespace taiga::mapping {
namespace {

constexpr const char* kPosesFile = "poses.tum";

// Registration needs positions only. A fresh vector of the exact size: the filter's own keeps
// the capacity it grew to (up to twice its size), and up to registration_cache_keyframes copies
// stay in RAM.
std::shared_ptr<const PointCloud> positionsOnly(const std::vector<Eigen::Vector3d>& positions) {
  auto copy = std::make_shared<PointCloud>();
  copy->positions.assign(positions.begin(), positions.end());
  return copy;
}

std::shared_ptr<const PointCloud> registrationCopy(const PointCloud& cloud_in_body,
                                                   const KeyframeStoreOptions& options) {
  if (options.registration_voxel_m <= 0.0) return std::make_shared<const PointCloud>();
  return positionsOnly(preprocess::voxelFilter(cloud_in_body, options.registration_voxel_m,
                                               options.registration_voxel_point)
                           .positions);
}

// The registration copies kept in RAM: at most `capacity`, the least recently used evicted, so
// memory stays bounded however many keyframes the store holds. Not thread-safe by itself.
class RegistrationCache {
 public:
  explicit RegistrationCache(std::size_t capacity) : capacity_(capacity) {}

  /// The cached copy of keyframe `id` (now the most recently used), or null.
  std::shared_ptr<const PointCloud> find(std::uint64_t id) {
    const auto found = entries_.find(id);
    if (found == entries_.end()) return nullptr;
    ids_most_recent_first_.splice(ids_most_recent_first_.begin(), ids_most_recent_first_,
                                  found->second.position);
    return found->second.copy;
  }

  /// Caches `copy` as the most recently used, evicting the least recently used beyond capacity,
  /// and returns the cached copy (the one already there when another thread cached it first).
  /// Callers holding an evicted copy keep it alive (shared ownership).
  std::shared_ptr<const PointCloud> insert(std::uint64_t id,
                                           std::shared_ptr<const PointCloud> copy) {
    if (capacity_ == 0) return copy;
    if (std::shared_ptr<const PointCloud> cached = find(id)) return cached;
    ids_most_recent_first_.push_front(id);
    entries_.emplace(id, Entry{copy, ids_most_recent_first_.begin()});
    while (entries_.size() > capacity_) {
      entries_.erase(ids_most_recent_first_.back());
      ids_most_recent_first_.pop_back();
    }
    return copy;
  }

  std::size_t size() const { return entries_.size(); }

 private:
  struct Entry {
    std::shared_ptr<const PointCloud> copy;
    std::list<std::uint64_t>::iterator position;  // in ids_most_recent_first_
  };
  std::size_t capacity_;
  std::list<std::uint64_t> ids_most_recent_first_;
  std::unordered_map<std::uint64_t, Entry> entries_;
};

}  // namespace

struct KeyframeStore::Impl {
  explicit Impl(const std::filesystem::path& directory, const KeyframeStoreOptions& store_options)
      : dir(directory),
        options(store_options),
        registration_cache(store_options.registration_cache_keyframes) {}

  std::filesystem::path dir;
  KeyframeStoreOptions options;
  mutable std::mutex mutex;  // guards infos
  std::vector<KeyframeInfo> infos;
  // Its own lock, never held together with `mutex`: a cache miss reads a file without either.
  mutable std::mutex cache_mutex;  // guards registration_cache and the counters
  mutable RegistrationCache registration_cache;
  mutable std::uint64_t registration_cache_hits = 0;
  mutable std::uint64_t registration_copies_rebuilt = 0;

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
  return KeyframeStore(std::make_unique<Impl>(dir, options));
}

KeyframeStore KeyframeStore::open(const std::filesystem::path& dir, KeyframeStoreOptions options) {
  const std::filesystem::path poses_path = dir / kPosesFile;
  if (!std::filesystem::exists(poses_path))
    throw InputError(
        fmt::format("{}: missing: not a keyframe directory of taiga run", poses_path.string()));
  const Trajectory poses = io::readTum(poses_path);
  // Only the headers: the registration copies are rebuilt from the files when first asked for.
  KeyframeStore store(std::make_unique<Impl>(dir, options));
  for (std::size_t id = 0; id < poses.size(); ++id) {
    const std::filesystem::path path = store.keyframePath(id);
    if (!std::filesystem::exists(path))
      throw InputError(fmt::format("{}: missing ({} lists {} keyframes)", path.string(),
                                   poses_path.string(), poses.size()));
    KeyframeInfo info;
    info.id = id;
    info.T_map_body = poses[id].pose;
    const KeyframeFileHeader header = readKeyframeHeader(path);
    if (header.id != id || header.t_s != poses[id].t_s) {
      throw InputError(fmt::format(
          "{}: keyframe {} at t = {} s, but {} lists keyframe {} at t = {} s", path.string(),
          header.id, header.t_s, poses_path.string(), id, poses[id].t_s));
    }
    info.t_s = header.t_s;
    info.point_count = header.point_count;
    store.impl_->infos.push_back(info);
  }
  return store;
}

std::uint64_t KeyframeStore::add(double t_s, const lie::SE3& T_odom_body,
                                 const PointCloud& cloud_in_body,
                                 const std::vector<Eigen::Vector3d>* registration_positions) {
  std::uint64_t id = 0;
  {
    const std::lock_guard lock(impl_->mutex);
    id = impl_->infos.size();
    if (!impl_->infos.empty() && !(t_s > impl_->infos.back().t_s))
      throw std::invalid_argument(
          fmt::format("KeyframeStore::add: time {} is not after {}", t_s, impl_->infos.back().t_s));
  }
  // The slow parts (file, voxel filter) outside the lock: readers of other keyframes go on.
  writeKeyframeFile(keyframePath(id), id, t_s, cloud_in_body);
  KeyframeInfo info{
      .id = id, .t_s = t_s, .T_map_body = T_odom_body, .point_count = cloud_in_body.size()};
  if (impl_->options.registration_voxel_m > 0.0) {
    // The newest keyframe is the one loop closure asks for next: cache its copy now, from the
    // scan at hand (or the caller's filtering of it), rather than read the file back.
    std::shared_ptr<const PointCloud> registration =
        registration_positions != nullptr ? positionsOnly(*registration_positions)
                                          : registrationCopy(cloud_in_body, impl_->options);
    const std::lock_guard cache_lock(impl_->cache_mutex);
    impl_->registration_cache.insert(id, std::move(registration));
  }
  const std::lock_guard lock(impl_->mutex);
  impl_->infos.push_back(info);
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
    throw InputError(
        fmt::format("{}: holds keyframe {} with {} points, expected keyframe {} with {}",
                    keyframePath(id).string(), content.header.id, content.header.point_count, id,
                    info.point_count));
  }
  return std::move(content.cloud_in_body);
}

std::shared_ptr<const PointCloud> KeyframeStore::registrationCloud(std::uint64_t id) const {
  info(id);  // OutOfRangeError for an unknown id
  if (impl_->options.registration_voxel_m <= 0.0) return std::make_shared<const PointCloud>();
  {
    const std::lock_guard cache_lock(impl_->cache_mutex);
    if (std::shared_ptr<const PointCloud> cached = impl_->registration_cache.find(id)) {
      ++impl_->registration_cache_hits;
      return cached;
    }
  }
  // Rebuilt outside the lock, so that readers of cached keyframes go on. The file holds the scan
  // add() filtered, bit for bit, and the filter is deterministic: the same copy as add() made.
  // Two threads missing the same keyframe both rebuild it; either result is the same.
  std::shared_ptr<const PointCloud> rebuilt = registrationCopy(load(id), impl_->options);
  const std::lock_guard cache_lock(impl_->cache_mutex);
  ++impl_->registration_copies_rebuilt;
  return impl_->registration_cache.insert(id, std::move(rebuilt));
}

RegistrationCacheStatistics KeyframeStore::registrationCacheStatistics() const {
  const std::lock_guard cache_lock(impl_->cache_mutex);
  return {.cached_keyframes = impl_->registration_cache.size(),
          .hits = impl_->registration_cache_hits,
          .rebuilt = impl_->registration_copies_rebuilt};
}

KeyframeInfo KeyframeStore::info(std::uint64_t id) const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->at(id);
}

lie::SE3 KeyframeStore::pose(std::uint64_t id) const { return info(id).T_map_body; }

std::vector<lie::SE3> KeyframeStore::poses() const {
  const std::lock_guard lock(impl_->mutex);
  std::vector<lie::SE3> out;
  out.reserve(impl_->infos.size());
  for (const KeyframeInfo& info : impl_->infos) out.push_back(info.T_map_body);
  return out;
}

Trajectory KeyframeStore::trajectory() const {
  const std::lock_guard lock(impl_->mutex);
  Trajectory out;
  for (const KeyframeInfo& info : impl_->infos) out.append(info.t_s, info.T_map_body);
  return out;
}

void KeyframeStore::setPoses(const std::vector<lie::SE3>& poses_T_map_body) {
  const std::lock_guard lock(impl_->mutex);
  if (poses_T_map_body.size() != impl_->infos.size())
    throw std::invalid_argument(fmt::format("KeyframeStore::setPoses: {} poses for {} keyframes",
                                            poses_T_map_body.size(), impl_->infos.size()));
  for (std::size_t k = 0; k < poses_T_map_body.size(); ++k)
    impl_->infos[k].T_map_body = poses_T_map_body[k];
}

void KeyframeStore::writePoses() const { writePoses(trajectory()); }

void KeyframeStore::writePoses(const Trajectory& poses_T_map_body) const {
  if (poses_T_map_body.size() > size())
    throw std::invalid_argument(fmt::format("KeyframeStore::writePoses: {} poses for {} keyframes",
                                            poses_T_map_body.size(), size()));
  const std::filesystem::path path = impl_->dir / kPosesFile;
  const std::filesystem::path temporary = impl_->dir / (std::string(kPosesFile) + ".tmp");
  io::writeTum(temporary, poses_T_map_body);
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) throw InputError(fmt::format("{}: cannot write: {}", path.string(), ec.message()));
}

}  // namespace taiga::mapping

#include "taiga/core/point_cloud.hpp"

#include <algorithm>
#include <cassert>
#include <stdexcept>

namespace taiga {
namespace {

template <class T>
bool channelFits(const std::vector<T>& channel, std::size_t n) {
  return channel.empty() || channel.size() == n;
}

template <class T>
void appendChannel(std::vector<T>& into, const std::vector<T>& from) {
  into.insert(into.end(), from.begin(), from.end());
}

template <class T>
void selectChannel(const std::vector<T>& from, std::span<const std::size_t> indices,
                   std::vector<T>& into) {
  if (from.empty()) return;
  into.reserve(indices.size());
  for (std::size_t i : indices) into.push_back(from[i]);
}

template <class T>
void keepChannel(std::vector<T>& channel, std::span<const std::uint8_t> keep) {
  if (channel.empty()) return;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < channel.size(); ++i)
    if (keep[i]) channel[kept++] = channel[i];
  channel.resize(kept);
}

}  // namespace

bool PointCloud::isConsistent() const {
  const std::size_t n = positions.size();
  return channelFits(times_s, n) && channelFits(intensities, n) && channelFits(rings, n) &&
         channelFits(columns, n);
}

void PointCloud::clear() {
  positions.clear();
  times_s.clear();
  intensities.clear();
  rings.clear();
  columns.clear();
}

void PointCloud::reserve(std::size_t n) {
  positions.reserve(n);
  times_s.reserve(n);
  intensities.reserve(n);
  rings.reserve(n);
  columns.reserve(n);
}

void PointCloud::append(const PointCloud& other) {
  if (empty()) {
    *this = other;
    return;
  }
  if (hasTimes() != other.hasTimes() || hasIntensities() != other.hasIntensities() ||
      hasRings() != other.hasRings() || hasColumns() != other.hasColumns()) {
    throw std::invalid_argument("PointCloud::append: the clouds carry different channels");
  }
  appendChannel(positions, other.positions);
  appendChannel(times_s, other.times_s);
  appendChannel(intensities, other.intensities);
  appendChannel(rings, other.rings);
  appendChannel(columns, other.columns);
}

PointCloud PointCloud::select(std::span<const std::size_t> indices) const {
  assert(isConsistent());
  PointCloud out;
  selectChannel(positions, indices, out.positions);
  selectChannel(times_s, indices, out.times_s);
  selectChannel(intensities, indices, out.intensities);
  selectChannel(rings, indices, out.rings);
  selectChannel(columns, indices, out.columns);
  return out;
}

void PointCloud::keepWhere(std::span<const std::uint8_t> keep) {
  assert(isConsistent() && keep.size() == size());
  keepChannel(positions, keep);
  keepChannel(times_s, keep);
  keepChannel(intensities, keep);
  keepChannel(rings, keep);
  keepChannel(columns, keep);
}

std::pair<double, double> PointCloud::timeSpan() const {
  assert(hasTimes() && !empty());
  const auto [min_it, max_it] = std::minmax_element(times_s.begin(), times_s.end());
  return {*min_it, *max_it};
}

}  // namespace taiga

#include "taiga/pipeline/imu_buffer.hpp"

#include <algorithm>

#include "taiga/imu/readings.hpp"

namespace taiga::pipeline {
namespace {

/// Index of the reading in force at t: the latest at or before t, or the first one.
template <class Container>
std::size_t inForce(const Container& samples, double t_s) {
  const auto after = std::upper_bound(samples.begin(), samples.end(), t_s,
                                      [](double t, const ImuSample& s) { return t < s.t_s; });
  return after == samples.begin() ? 0 : static_cast<std::size_t>(after - samples.begin()) - 1;
}

}  // namespace

bool ImuBuffer::add(const ImuSample& sample) {
  if (!samples_.empty() && sample.t_s <= samples_.back().t_s) return false;
  samples_.push_back(sample);
  return true;
}

std::vector<ImuSample> ImuBuffer::between(double t_from_s, double t_to_s) const {
  std::vector<ImuSample> out;
  if (samples_.empty()) return out;
  for (std::size_t i = inForce(samples_, t_from_s);
       i < samples_.size() && samples_[i].t_s <= t_to_s; ++i)
    out.push_back(samples_[i]);
  if (out.empty()) out.push_back(samples_[inForce(samples_, t_from_s)]);
  return out;
}

std::vector<ImuSample> ImuBuffer::signalOver(double t_from_s, double t_to_s) const {
  std::vector<ImuSample> out = between(t_from_s, t_to_s);
  const auto after = std::upper_bound(samples_.begin(), samples_.end(), t_to_s,
                                      [](double t, const ImuSample& s) { return t < s.t_s; });
  if (after != samples_.end() && (out.empty() || after->t_s > out.back().t_s))
    out.push_back(*after);
  return out;
}

imu::Preintegrator ImuBuffer::preintegrate(double t_from_s, double t_to_s,
                                           const imu::ImuBias& bias_hat,
                                           const imu::ImuNoise& noise) const {
  return imu::preintegrateReadings(samples_, t_from_s, t_to_s, bias_hat, noise);
}

double ImuBuffer::longestGap(double t_from_s, double t_to_s) const {
  double previous_s = t_from_s, longest_s = 0.0;
  for (std::size_t i = inForce(samples_, t_from_s); i < samples_.size(); ++i) {
    const double t_s = std::clamp(samples_[i].t_s, t_from_s, t_to_s);
    longest_s = std::max(longest_s, t_s - previous_s);
    previous_s = std::max(previous_s, t_s);
    if (samples_[i].t_s >= t_to_s) return longest_s;
  }
  return std::max(longest_s, t_to_s - previous_s);
}

void ImuBuffer::dropBefore(double t_s) {
  const std::size_t keep_from = inForce(samples_, t_s);
  samples_.erase(samples_.begin(), samples_.begin() + static_cast<std::ptrdiff_t>(keep_from));
}

}  // namespace taiga::pipeline

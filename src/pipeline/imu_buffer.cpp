#include "taiga/pipeline/imu_buffer.hpp"

#include <algorithm>

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

imu::Preintegrator ImuBuffer::preintegrate(double t_from_s, double t_to_s,
                                           const imu::ImuBias& bias_hat,
                                           const imu::ImuNoise& noise) const {
  imu::Preintegrator pre(bias_hat, noise);
  if (samples_.empty() || t_to_s <= t_from_s) return pre;
  double t = t_from_s;
  for (std::size_t i = inForce(samples_, t_from_s); i < samples_.size() && t < t_to_s; ++i) {
    const double t_next = i + 1 < samples_.size() ? std::min(samples_[i + 1].t_s, t_to_s) : t_to_s;
    if (t_next > t) {
      pre.integrate(samples_[i].acceleration_imu_mps2, samples_[i].angular_velocity_imu_radps,
                    t_next - t);
      t = t_next;
    }
  }
  return pre;
}

void ImuBuffer::dropBefore(double t_s) {
  const std::size_t keep_from = inForce(samples_, t_s);
  samples_.erase(samples_.begin(), samples_.begin() + static_cast<std::ptrdiff_t>(keep_from));
}

}  // namespace taiga::pipeline

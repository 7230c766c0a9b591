#include "taiga/io/imu_units.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <deque>
#include <vector>

#include "taiga/core/log.hpp"

namespace taiga::io {

AccelerationUnitDecision decideAccelerationUnit(AccelerationUnit configured,
                                                std::span<const ImuSample> first_samples) {
  if (configured == AccelerationUnit::kMetersPerSecond2) return {1.0, false, false, "acceleration in m/s^2 (configured)"};
  if (configured == AccelerationUnit::kStandardGravity) {
    return {kStandardGravity_mps2, false, false, "acceleration in g (configured), converted to m/s^2"};
  }
  if (first_samples.empty()) return {1.0, false, false, "no IMU samples; acceleration assumed in m/s^2"};
  std::vector<double> norms;
  for (const ImuSample& s : first_samples) norms.push_back(s.acceleration_imu_mps2.norm());
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
  const double median = norms[norms.size() / 2];
  if (median >= 0.5 && median <= 2.0) {
    return {kStandardGravity_mps2, true, true,
            fmt::format("acceleration is in g (median magnitude {:.3f} over the first {} samples), converted to "
                        "m/s^2; set rig.imu_acceleration_unit to silence this",
                        median, norms.size())};
  }
  if (median >= 5.0 && median <= 20.0) {
    return {1.0, true, false, fmt::format("acceleration in m/s^2 (median magnitude {:.3f})", median)};
  }
  return {1.0, true, true,
          fmt::format("cannot tell the acceleration unit (median magnitude {:.3f} is neither about 1 g nor 9.8 "
                      "m/s^2); assuming m/s^2: set rig.imu_acceleration_unit",
                      median)};
}

namespace {

class ScaledImuStream final : public StreamSource {
 public:
  ScaledImuStream(std::unique_ptr<StreamSource> raw, AccelerationUnit configured, std::string source)
      : raw_(std::move(raw)), configured_(configured), source_(std::move(source)) {}

  std::string name() const override { return raw_->name(); }
  std::vector<std::string> details() const override {
    std::vector<std::string> out = raw_->details();
    if (decision_) out.push_back(decision_->explanation);
    return out;
  }

  std::optional<RecordingEvent> next() override {
    if (!decision_) decide();
    std::optional<RecordingEvent> event;
    if (!buffered_.empty()) {
      event = std::move(buffered_.front());
      buffered_.pop_front();
    } else {
      event = raw_->next();
    }
    if (event) {
      if (auto* imu = std::get_if<ImuSample>(&*event)) imu->acceleration_imu_mps2 *= decision_->scale_to_mps2;
    }
    return event;
  }

 private:
  static constexpr double kWindow_s = 1.0;
  static constexpr std::size_t kMaxSamples = 400;

  void decide() {
    std::vector<ImuSample> first;
    while (first.size() < kMaxSamples && (first.empty() || first.back().t_s - first.front().t_s < kWindow_s)) {
      std::optional<RecordingEvent> event = raw_->next();
      if (!event) break;
      if (const auto* imu = std::get_if<ImuSample>(&*event)) first.push_back(*imu);
      buffered_.push_back(std::move(*event));
    }
    decision_ = decideAccelerationUnit(configured_, first);
    logger().log(decision_->warn ? spdlog::level::warn : spdlog::level::info, "{}: {}: {}", source_, name(),
                 decision_->explanation);
  }

  std::unique_ptr<StreamSource> raw_;
  AccelerationUnit configured_;
  std::string source_;
  std::optional<AccelerationUnitDecision> decision_;
  std::deque<RecordingEvent> buffered_;
};

}  // namespace

std::unique_ptr<StreamSource> withAccelerationUnit(std::unique_ptr<StreamSource> raw_imu, AccelerationUnit configured,
                                                   std::string source) {
  return std::make_unique<ScaledImuStream>(std::move(raw_imu), configured, std::move(source));
}

}  // namespace taiga::io

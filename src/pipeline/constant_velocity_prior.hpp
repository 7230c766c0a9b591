#pragma once
// Lidar-only odometry's motion model (motion_prior.hpp): each scan is predicted and deskewed with
// the constant twist of the last two poses; the state is the registered pose, or the prediction
// when the registration was rejected. The odom frame is the first scan's body frame (not
// levelled). The prediction may be off by decimetres, so registration then runs coarse to fine
// (OdometryConfig::ndtResolutionsM()). Internal to the pipeline.

#include <optional>
#include <string>

#include "motion_prior.hpp"

namespace taiga::pipeline {

class ConstantVelocityPrior final : public MotionPrior {
 public:
  void addImu(const ImuSample&) override {}
  bool start(const io::Scan&, std::optional<FirstScan>&) override { return true; }
  std::optional<double> stateTime() const override {
    return last_ ? std::optional(last_->t_s) : std::nullopt;
  }
  MotionPrediction predict(const io::Scan& scan) override;
  std::optional<JumpBound> jumpBound() const override { return std::nullopt; }
  MotionUpdate update(const std::optional<backend::PoseMeasurement>& lidar) override;
  bool levelled() const override { return true; }
  const std::string& initializationNote() const override { return note_; }

 private:
  /// A pose and the body-frame twist per second that predicts the next.
  struct Twist {
    double t_s = 0.0;
    lie::SE3 T_odom_body;
    lie::Vector6 twist_per_s = lie::Vector6::Zero();
  };
  std::optional<Twist> last_;  ///< none before the first scan: it is at rest at the origin
  Twist predicted_;            ///< the scan last predicted (its end time and pose)
  std::string note_;
};

}  // namespace taiga::pipeline

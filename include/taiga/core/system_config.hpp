#pragma once
// The whole configuration of a taiga run: one section per module. Sections are added here as the
// modules that own them land.

#include "taiga/core/calibration_config.hpp"
#include "taiga/core/compute_config.hpp"
#include "taiga/core/config.hpp"
#include "taiga/core/georef_config.hpp"
#include "taiga/core/live_config.hpp"
#include "taiga/core/mapping_config.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/core/recording_config.hpp"
#include "taiga/core/rig_config.hpp"

namespace taiga {

struct SystemConfig final : ConfigSection {
  RigConfig rig;
  RecordingConfig recording;
  OdometryConfig odometry;
  MappingConfig mapping;
  GeorefConfig georef;
  CalibrationConfig calibration;
  LiveConfig live;
  ComputeConfig compute;

  void visit(ConfigVisitor& v) override {
    v.section("rig", rig, "sensor rig: extrinsics, clock offset and units");
    v.section("recording", recording, "which streams to read and how to interpret them");
    v.section("odometry", odometry,
              "lidar-inertial odometry: preprocessing, registration, keyframes, IMU noise");
    v.section("mapping", mapping, "keyframe graph and loop closures");
    v.section("georef", georef, "georeferencing with GNSS: post-fit method, output CRS, gating");
    v.section("calibration", calibration,
              "self-calibration of the lidar-IMU time offset and extrinsic rotation");
    v.section("live", live, "taiga run --live: the sensor's UDP packets, and what a live run does");
    v.section("compute", compute, "how much of the machine a run may use");
  }
};

}  // namespace taiga

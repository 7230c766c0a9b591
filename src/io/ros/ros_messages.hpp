#pragma once
// ROS1 message types usable from C++20. Internal to the io module.
//
// ROS1's generated messages take their container types from `Allocator::rebind`, which
// std::allocator lost in C++20. The messages are templates on the allocator, so an allocator that
// still provides rebind makes them compile unchanged; serialization and rosbag treat them as the
// ordinary message types (same MD5 sums and definitions).

#include <memory>

namespace taiga::io::detail {

template <class T>
struct RosAllocator : std::allocator<T> {
  using value_type = T;
  RosAllocator() = default;
  template <class U>
  RosAllocator(const RosAllocator<U>&) noexcept {}
  template <class U>
  struct rebind {
    using other = RosAllocator<U>;
  };
};

template <class T, class U>
bool operator==(const RosAllocator<T>&, const RosAllocator<U>&) {
  return true;
}

}  // namespace taiga::io::detail

#include <sensor_msgs/Imu.h>
#include <sensor_msgs/NavSatFix.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/String.h>

namespace taiga::io::detail {

using RosHeader = std_msgs::Header_<RosAllocator<void>>;
using RosPointField = sensor_msgs::PointField_<RosAllocator<void>>;
using RosPointCloud2 = sensor_msgs::PointCloud2_<RosAllocator<void>>;
using RosImu = sensor_msgs::Imu_<RosAllocator<void>>;
using RosNavSatFix = sensor_msgs::NavSatFix_<RosAllocator<void>>;
using RosString = std_msgs::String_<RosAllocator<void>>;

}  // namespace taiga::io::detail

# ROS1 bags without a ROS installation, from Debian's librosbag-storage-dev and message packages.
# Debian's rosbag_storage headers pull in ROS 2's pluginlib, hence the extra include directories.
# Defines the interface target taiga_rosbag_storage.
set(taiga_rosbag_libraries rosbag_storage roscpp_serialization rostime cpp_common class_loader
    console_bridge rcutils rcpputils ament_index_cpp)
add_library(taiga_rosbag_storage INTERFACE)
foreach(library ${taiga_rosbag_libraries})
  find_library(taiga_rosbag_${library} NAMES ${library} REQUIRED)
  target_link_libraries(taiga_rosbag_storage INTERFACE ${taiga_rosbag_${library}})
endforeach()
foreach(directory pluginlib class_loader rcpputils rcutils ament_index_cpp)
  if(NOT EXISTS /usr/include/${directory})
    message(FATAL_ERROR "/usr/include/${directory} is missing: run scripts/setup.sh")
  endif()
  target_include_directories(taiga_rosbag_storage SYSTEM INTERFACE /usr/include/${directory})
endforeach()

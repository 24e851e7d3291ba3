# Debian's ROS 1 bag library (librosbag-storage-dev), found by its files:
# its own rosbag_storageConfig.cmake pulls in pluginlib's ament CMake, which
# runs Python's ament_package at configure time (and fails under a Python
# without it). Defines SALOAM_HAVE_ROSBAG and the imported target
# saloam_rosbag_storage (rosbag_storage with what its headers and symbols need:
# roscpp_serialization, rostime, cpp_common, console_bridge, Boost headers,
# and the ROS 2 style include folders of pluginlib and class_loader).
option(SALOAM_ROSBAG "Read ROS 1 bags when rosbag_storage is installed (OFF: build as without it)" ON)
if(NOT SALOAM_ROSBAG)
  set(SALOAM_HAVE_ROSBAG OFF)
  message(STATUS "SALOAM_ROSBAG=OFF: ROS 1 bags are left out")
  return()
endif()
find_path(SALOAM_ROSBAG_INCLUDE_DIR rosbag/bag.h)
find_path(SALOAM_PLUGINLIB_INCLUDE_DIR pluginlib/class_loader.hpp PATH_SUFFIXES pluginlib)
find_path(SALOAM_CLASS_LOADER_INCLUDE_DIR class_loader/class_loader.hpp PATH_SUFFIXES class_loader)
find_path(SALOAM_RCUTILS_INCLUDE_DIR rcutils/types.h PATH_SUFFIXES rcutils)
find_path(SALOAM_RCPPUTILS_INCLUDE_DIR rcpputils/shared_library.hpp PATH_SUFFIXES rcpputils)
find_path(SALOAM_AMENT_INDEX_INCLUDE_DIR ament_index_cpp/get_resource.hpp PATH_SUFFIXES ament_index_cpp)
find_library(SALOAM_ROSBAG_STORAGE_LIB rosbag_storage)
find_library(SALOAM_ROSCPP_SERIALIZATION_LIB roscpp_serialization)
find_library(SALOAM_ROSTIME_LIB rostime)
find_library(SALOAM_CPP_COMMON_LIB cpp_common)
find_library(SALOAM_CONSOLE_BRIDGE_LIB console_bridge)
set(_saloam_rosbag_parts SALOAM_ROSBAG_INCLUDE_DIR SALOAM_PLUGINLIB_INCLUDE_DIR SALOAM_CLASS_LOADER_INCLUDE_DIR
    SALOAM_RCUTILS_INCLUDE_DIR SALOAM_RCPPUTILS_INCLUDE_DIR SALOAM_AMENT_INDEX_INCLUDE_DIR SALOAM_ROSBAG_STORAGE_LIB
    SALOAM_ROSCPP_SERIALIZATION_LIB SALOAM_ROSTIME_LIB SALOAM_CPP_COMMON_LIB SALOAM_CONSOLE_BRIDGE_LIB)
set(SALOAM_HAVE_ROSBAG ON)
foreach(part ${_saloam_rosbag_parts})
  if(NOT ${part})
    set(SALOAM_HAVE_ROSBAG OFF)
  endif()
endforeach()
if(SALOAM_HAVE_ROSBAG AND NOT TARGET saloam_rosbag_storage)
  add_library(saloam_rosbag_storage INTERFACE IMPORTED)
  # SYSTEM: the ROS headers' own warnings are not ours.
  set_target_properties(saloam_rosbag_storage PROPERTIES
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES
      "${SALOAM_ROSBAG_INCLUDE_DIR};${SALOAM_PLUGINLIB_INCLUDE_DIR};${SALOAM_CLASS_LOADER_INCLUDE_DIR};${SALOAM_RCUTILS_INCLUDE_DIR};${SALOAM_RCPPUTILS_INCLUDE_DIR};${SALOAM_AMENT_INDEX_INCLUDE_DIR}"
    INTERFACE_INCLUDE_DIRECTORIES
      "${SALOAM_ROSBAG_INCLUDE_DIR};${SALOAM_PLUGINLIB_INCLUDE_DIR};${SALOAM_CLASS_LOADER_INCLUDE_DIR};${SALOAM_RCUTILS_INCLUDE_DIR};${SALOAM_RCPPUTILS_INCLUDE_DIR};${SALOAM_AMENT_INDEX_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES
      "${SALOAM_ROSBAG_STORAGE_LIB};${SALOAM_ROSCPP_SERIALIZATION_LIB};${SALOAM_ROSTIME_LIB};${SALOAM_CPP_COMMON_LIB};${SALOAM_CONSOLE_BRIDGE_LIB}")
  message(STATUS "rosbag_storage found: ROS 1 bags are read (--format rosbag)")
elseif(NOT SALOAM_HAVE_ROSBAG)
  message(STATUS "rosbag_storage not found: ROS 1 bags are left out (install librosbag-storage-dev)")
endif()

if(NOT TARGET orocos-kdl)
  find_package(Eigen3 REQUIRED NO_MODULE)
  find_library(_mlaunch_orocos_kdl_library orocos-kdl REQUIRED)
  add_library(orocos-kdl INTERFACE IMPORTED GLOBAL)
  set_target_properties(orocos-kdl PROPERTIES
    INTERFACE_LINK_LIBRARIES "${_mlaunch_orocos_kdl_library}"
    INTERFACE_INCLUDE_DIRECTORIES "${EIGEN3_INCLUDE_DIR};${EIGEN3_INCLUDE_DIRS}")
endif()

# Debian's libtinyxml2-dev has a CMake config defining tinyxml2::tinyxml2, which urdf links.
find_package(tinyxml2 CONFIG QUIET)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(TinyXML2 REQUIRED_VARS tinyxml2_DIR)
if(TinyXML2_FOUND AND NOT TARGET TinyXML2::TinyXML2)
  add_library(TinyXML2::TinyXML2 INTERFACE IMPORTED)
  set_target_properties(TinyXML2::TinyXML2 PROPERTIES INTERFACE_LINK_LIBRARIES tinyxml2::tinyxml2)
endif()
set(TinyXML2_LIBRARIES tinyxml2::tinyxml2)

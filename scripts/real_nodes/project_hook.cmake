# Injected with CMAKE_PROJECT_INCLUDE into every package of the real-node build (build.py).
# 1. The interface build's hook: drop include folders of the wheels' build machine.
include("${CMAKE_CURRENT_LIST_DIR}/../../interfaces/drop_missing_includes.cmake")
# 2. Two bad link items in the ros-jazzy-* wheels' CMake exports: fastrtps links
#    /usr/lib64/libtinyxml2.so (a path of the machine that built the wheel) and tracetools a bare
#    `lttng-ust` (a library not installed here, and not needed: tracing is compiled out of the
#    wheels). Once the project's CMakeLists has run, drop from every imported target the link
#    items that are absolute paths that do not exist and bare names no library answers to.
function(_mlaunch_drop_missing_links)
  get_directory_property(_targets DIRECTORY "${CMAKE_SOURCE_DIR}" IMPORTED_TARGETS)
  foreach(_target IN LISTS _targets)
    get_target_property(_items ${_target} INTERFACE_LINK_LIBRARIES)
    if(NOT _items)
      continue()
    endif()
    set(_kept)
    foreach(_item IN LISTS _items)
      if(_item MATCHES "^\\$<|::|^-" OR TARGET "${_item}")
        list(APPEND _kept "${_item}")
      elseif(IS_ABSOLUTE "${_item}")
        if(EXISTS "${_item}")
          list(APPEND _kept "${_item}")
        endif()
      else()
        find_library(_mlaunch_lib_${_item} NAMES "${_item}")
        if(_mlaunch_lib_${_item})
          list(APPEND _kept "${_item}")
        endif()
      endif()
    endforeach()
    set_target_properties(${_target} PROPERTIES INTERFACE_LINK_LIBRARIES "${_kept}")
  endforeach()
endfunction()
cmake_language(DEFER DIRECTORY "${CMAKE_SOURCE_DIR}" CALL _mlaunch_drop_missing_links)

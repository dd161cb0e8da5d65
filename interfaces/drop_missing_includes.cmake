# Injected with CMAKE_PROJECT_INCLUDE. The ros-jazzy-* message wheels export CMake targets whose
# INTERFACE_INCLUDE_DIRECTORIES still name their build container's Python headers
# (/opt/python/cp311-cp311/include/python3.11); CMake refuses to generate with a target that names
# a missing directory. Once the project's CMakeLists has run, drop such entries from every
# imported target (generator expressions are kept: they are evaluated later).
function(_mlaunch_drop_missing_includes)
  get_directory_property(_targets DIRECTORY "${CMAKE_SOURCE_DIR}" IMPORTED_TARGETS)
  foreach(_target IN LISTS _targets)
    get_target_property(_dirs ${_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(NOT _dirs)
      continue()
    endif()
    set(_kept)
    foreach(_dir IN LISTS _dirs)
      if(_dir MATCHES "^\\$<" OR EXISTS "${_dir}")
        list(APPEND _kept "${_dir}")
      endif()
    endforeach()
    set_target_properties(${_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_kept}")
  endforeach()
endfunction()
cmake_language(DEFER DIRECTORY "${CMAKE_SOURCE_DIR}" CALL _mlaunch_drop_missing_includes)

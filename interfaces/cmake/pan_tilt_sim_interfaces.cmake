# Shared by the packages under interfaces/: each one calls
#   pan_tilt_sim_interfaces_generate(<files...> DEPENDENCIES <pkgs...>)
# where an upstream package calls rosidl_generate_interfaces(${PROJECT_NAME} ...),
# after find_package(rosidl_default_generators) and its dependencies.
#
# scripts/build_interfaces.py configures these packages against the ROS 2
# Jazzy wheels from PyPI, which need two things a ROS install does not:
#
# * The wheels export <pkg>::<pkg>__rosidl_generator_py targets whose include
#   directories name the wheel builder's Python (/opt/python/cp311-cp311/...),
#   absent here, and CMake refuses an imported target with a missing include
#   directory.  At the end of the configure step each such directory is
#   replaced by this interpreter's headers or NumPy's.
# * PAN_TILT_SIM_INTERFACES_GENERATORS=python (what the build script passes)
#   runs only the generators whose output rclpy over rmw_fastrtps_cpp loads:
#   the type descriptions (RIHS01 hashes), the C structs, the Fast DDS C type
#   support (serialisation), the C introspection type support (Fast DDS
#   builds its type object from it: without it creating a publisher fails
#   with "failed to register type object"), the C type support that
#   dispatches to those two, and the Python bindings.  No C++ headers or
#   type supports: nothing in the venv compiles against them or loads them.
#   "default" runs every generator rosidl_default_generators registered, as
#   upstream does.

set(PAN_TILT_SIM_INTERFACES_GENERATORS "default" CACHE STRING
  "python: only what rclpy with rmw_fastrtps_cpp needs; default: all of rosidl_default_generators")

set(_PAN_TILT_SIM_INTERFACES_PYTHON_GENERATORS
  rosidl_generator_type_description
  rosidl_generator_c
  rosidl_typesupport_fastrtps_c
  rosidl_typesupport_introspection_c
  rosidl_typesupport_c
  rosidl_generator_py
)

function(_pan_tilt_sim_interfaces_fix_python_includes)
  find_package(Python3 REQUIRED COMPONENTS Interpreter Development.Module NumPy)
  get_property(_targets DIRECTORY "${CMAKE_SOURCE_DIR}" PROPERTY IMPORTED_TARGETS)
  foreach(_target IN LISTS _targets)
    get_target_property(_dirs ${_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(NOT _dirs)
      continue()
    endif()
    set(_fixed "")
    set(_changed FALSE)
    foreach(_dir IN LISTS _dirs)
      if(NOT EXISTS "${_dir}" AND _dir MATCHES "/include/python3\\.[0-9]+$")
        list(APPEND _fixed ${Python3_INCLUDE_DIRS})
        set(_changed TRUE)
      elseif(NOT EXISTS "${_dir}" AND _dir MATCHES "/numpy/(_core|core)/include$")
        list(APPEND _fixed ${Python3_NumPy_INCLUDE_DIRS})
        set(_changed TRUE)
      else()
        list(APPEND _fixed "${_dir}")
      endif()
    endforeach()
    if(_changed)
      list(REMOVE_DUPLICATES _fixed)
      set_target_properties(${_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_fixed}")
    endif()
  endforeach()
endfunction()

macro(pan_tilt_sim_interfaces_generate)
  if(PAN_TILT_SIM_INTERFACES_GENERATORS STREQUAL "python")
    set(_pts_kept "")
    foreach(_pts_extension IN LISTS AMENT_EXTENSIONS_rosidl_generate_idl_interfaces)
      string(REGEX REPLACE ":.*$" "" _pts_pkg "${_pts_extension}")
      if(_pts_pkg IN_LIST _PAN_TILT_SIM_INTERFACES_PYTHON_GENERATORS)
        list(APPEND _pts_kept "${_pts_extension}")
      endif()
    endforeach()
    set(AMENT_EXTENSIONS_rosidl_generate_idl_interfaces ${_pts_kept})
    message(STATUS "pan_tilt_sim interfaces: generators ${_pts_kept}")
  elseif(NOT PAN_TILT_SIM_INTERFACES_GENERATORS STREQUAL "default")
    message(FATAL_ERROR "PAN_TILT_SIM_INTERFACES_GENERATORS is python or default, "
      "not '${PAN_TILT_SIM_INTERFACES_GENERATORS}'")
  endif()
  cmake_language(DEFER DIRECTORY "${CMAKE_SOURCE_DIR}"
    CALL _pan_tilt_sim_interfaces_fix_python_includes)
  rosidl_generate_interfaces(${PROJECT_NAME} ${ARGN})
endmacro()

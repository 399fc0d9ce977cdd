# FindMuJoCo: the MuJoCo C library, from the pinned `mujoco` wheel or a release folder.
#
# Search order:
#   1. -DMUJOCO_ROOT=DIR: a MuJoCo release folder (DIR/include/mujoco/mujoco.h and
#      DIR/lib/libmujoco.so.*), for people who do not use Python.
#   2. The Python package `mujoco` of MUJOCO_PYTHON (default: the repository's .venv/bin/python,
#      made by scripts/install-deps.sh, else python3 on PATH): its folder holds
#      libmujoco.so.<version> (no unversioned link) and include/mujoco/.
#
# Defines the IMPORTED target mujoco::mujoco (full path of the versioned library, its SONAME, the
# include folder above mujoco/), MuJoCo_VERSION (from mjVERSION_HEADER), MuJoCo_LIBRARY_DIR (for
# rpaths) and MuJoCo_PLUGIN_DIR (the wheel's plugin folder, empty for a release folder).
include(FindPackageHandleStandardArgs)

set(MUJOCO_ROOT "" CACHE PATH "MuJoCo release folder (include/ and lib/); empty = the Python wheel")
set(_mj_default_python "${PROJECT_SOURCE_DIR}/.venv/bin/python")
if(NOT EXISTS "${_mj_default_python}")
  set(_mj_default_python "python3")
endif()
set(MUJOCO_PYTHON "${_mj_default_python}" CACHE STRING "Python whose `mujoco` package to build against")

set(_mj_include "")
set(_mj_libdir "")
set(MuJoCo_PLUGIN_DIR "")
if(MUJOCO_ROOT)
  set(_mj_include "${MUJOCO_ROOT}/include")
  set(_mj_libdir "${MUJOCO_ROOT}/lib")
else()
  execute_process(
    COMMAND "${MUJOCO_PYTHON}" -c
            "import os, mujoco; print(os.path.dirname(mujoco.__file__)); print(mujoco.PLUGINS_DIR)"
    OUTPUT_VARIABLE _mj_out ERROR_VARIABLE _mj_err RESULT_VARIABLE _mj_rc
    OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(_mj_rc EQUAL 0)
    string(REPLACE "\n" ";" _mj_lines "${_mj_out}")
    list(GET _mj_lines 0 _mj_pkg)
    list(GET _mj_lines 1 MuJoCo_PLUGIN_DIR)
    set(_mj_include "${_mj_pkg}/include")
    set(_mj_libdir "${_mj_pkg}")
  else()
    message(STATUS "FindMuJoCo: '${MUJOCO_PYTHON}' has no mujoco package "
                   "(run scripts/install-deps.sh, or pass -DMUJOCO_ROOT=DIR)")
  endif()
endif()

find_path(MuJoCo_INCLUDE_DIR mujoco/mujoco.h PATHS "${_mj_include}" NO_DEFAULT_PATH)
set(MuJoCo_LIBRARY "")
if(_mj_libdir)
  file(GLOB _mj_candidates "${_mj_libdir}/libmujoco.so.*")
  list(SORT _mj_candidates)
  if(_mj_candidates)
    list(GET _mj_candidates -1 MuJoCo_LIBRARY)
  elseif(EXISTS "${_mj_libdir}/libmujoco.so")
    set(MuJoCo_LIBRARY "${_mj_libdir}/libmujoco.so")
  endif()
endif()

if(MuJoCo_INCLUDE_DIR)
  file(STRINGS "${MuJoCo_INCLUDE_DIR}/mujoco/mujoco.h" _mj_ver REGEX "#define mjVERSION_HEADER")
  string(REGEX MATCH "[0-9]+" _mj_num "${_mj_ver}")
  math(EXPR _mj_major "${_mj_num} / 1000000")
  math(EXPR _mj_minor "(${_mj_num} / 1000) % 1000")
  math(EXPR _mj_patch "${_mj_num} % 1000")
  set(MuJoCo_VERSION "${_mj_major}.${_mj_minor}.${_mj_patch}")
endif()

find_package_handle_standard_args(MuJoCo
  REQUIRED_VARS MuJoCo_LIBRARY MuJoCo_INCLUDE_DIR
  VERSION_VAR MuJoCo_VERSION)

if(MuJoCo_FOUND AND NOT TARGET mujoco::mujoco)
  get_filename_component(MuJoCo_LIBRARY_DIR "${MuJoCo_LIBRARY}" DIRECTORY)
  get_filename_component(_mj_soname "${MuJoCo_LIBRARY}" NAME)
  add_library(mujoco::mujoco SHARED IMPORTED)
  set_target_properties(mujoco::mujoco PROPERTIES
    IMPORTED_LOCATION "${MuJoCo_LIBRARY}"
    IMPORTED_SONAME "${_mj_soname}"
    INTERFACE_INCLUDE_DIRECTORIES "${MuJoCo_INCLUDE_DIR}")
endif()
mark_as_advanced(MuJoCo_INCLUDE_DIR MuJoCo_LIBRARY)

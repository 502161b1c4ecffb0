# Precompiled headers: the third-party headers (Eigen, GoogleTest) parsed once per build, not once
# per translation unit. Measured 2026-12-02 (release build, 127 unity TUs on 2 cores): a TU that
# includes GoogleTest and Eigen spends 2.5 s parsing them with GCC at -O3, 0.9 s when it loads
# them precompiled; 57 of the 127 TUs took under 3 s in all, so most of their time was those headers.
#
# Three donors, one per set of compile flags that changes what a header means (exceptions/RTTI,
# optimisation, target features; clang refuses a PCH built with others, GCC ignores it):
#   mmlfw_pch_embedded  firmware/ and hal/ libraries (mmlfw_embedded_target: -fno-exceptions -fno-rtti)
#   mmlfw_pch_test      every target that links GoogleTest (tests, the test main)
#   mmlfw_pch_host      the rest of the project's C++ targets (sim/ tools and libraries, benchmarks)
# Only the third-party headers are precompiled, so a missing #include of our own headers still
# fails the build, and -DMMLFW_PCH=OFF builds without them (the code must compile either way).
option(MMLFW_PCH "Share precompiled Eigen/GoogleTest headers across targets (toolchain/pch.cmake)" ON)

set(MMLFW_PCH_EIGEN <Eigen/Core> <Eigen/Geometry> <Eigen/LU> <Eigen/Cholesky> <Eigen/Eigenvalues>)

# The donors are created once (toolchain/project.cmake includes this file before any target).
function(mmlfw_pch_donors)
  if(NOT MMLFW_PCH)
    return()
  endif()
  set(_anchor ${PROJECT_SOURCE_DIR}/toolchain/pch/anchor.cpp)
  add_library(mmlfw_pch_embedded STATIC EXCLUDE_FROM_ALL ${_anchor})
  target_compile_options(mmlfw_pch_embedded PRIVATE ${MMLFW_EMBEDDED_FLAGS})
  target_link_libraries(mmlfw_pch_embedded PUBLIC eigen3)
  target_precompile_headers(mmlfw_pch_embedded PRIVATE ${MMLFW_PCH_EIGEN})

  add_library(mmlfw_pch_host STATIC EXCLUDE_FROM_ALL ${_anchor})
  target_link_libraries(mmlfw_pch_host PUBLIC eigen3)
  target_precompile_headers(mmlfw_pch_host PRIVATE ${MMLFW_PCH_EIGEN})

  add_library(mmlfw_pch_test STATIC EXCLUDE_FROM_ALL ${_anchor})
  target_link_libraries(mmlfw_pch_test PUBLIC eigen3 gtest)
  target_precompile_headers(mmlfw_pch_test PRIVATE <gtest/gtest.h> ${MMLFW_PCH_EIGEN})
  foreach(_donor mmlfw_pch_embedded mmlfw_pch_host mmlfw_pch_test)
    set_target_properties(${_donor} PROPERTIES UNITY_BUILD OFF)
  endforeach()
endfunction()

# mmlfw_pch_targets(DIR): every C++ target defined under DIR (recursively) reuses its donor's
# header. Called once from the top-level CMakeLists.txt after every subdirectory is added. Left out:
# targets whose own compile options are more than warnings (fw_pransam's -O2: a PCH must be built
# with the same optimisation) and directories outside the source tree (GoogleTest's own build).
function(mmlfw_pch_targets dir)
  if(NOT MMLFW_PCH)
    return()
  endif()
  # The project-wide options (add_compile_options: -ffp-contract=off, the sanitizers) are the donors' too.
  get_property(_global DIRECTORY ${PROJECT_SOURCE_DIR} PROPERTY COMPILE_OPTIONS)
  get_property(_targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  foreach(_t IN LISTS _targets)
    get_target_property(_type ${_t} TYPE)
    if(NOT _type MATCHES "^(STATIC_LIBRARY|SHARED_LIBRARY|OBJECT_LIBRARY|EXECUTABLE)$" OR _t MATCHES "^mmlfw_pch_")
      continue()
    endif()
    get_target_property(_reuse ${_t} PRECOMPILE_HEADERS_REUSE_FROM)
    get_target_property(_own ${_t} PRECOMPILE_HEADERS)
    if(_reuse OR _own)
      continue()
    endif()
    get_target_property(_options ${_t} COMPILE_OPTIONS)
    if(NOT _options)
      set(_options "")
    endif()
    set(_extra ${_options})
    list(REMOVE_ITEM _extra ${MMLFW_EMBEDDED_FLAGS} ${_global})
    list(FILTER _extra EXCLUDE REGEX "^-W")
    if(_extra)
      continue()
    endif()
    # Every firmware/hal target (mmlfw_embedded_target, and mmlfw's own executable) has -fno-exceptions.
    get_target_property(_libs ${_t} LINK_LIBRARIES)
    if("-fno-exceptions" IN_LIST _options)
      set(_donor mmlfw_pch_embedded)
    elseif(_libs AND ("gtest" IN_LIST _libs OR "gtest_main" IN_LIST _libs OR "mmlfw_test_main" IN_LIST _libs))
      set(_donor mmlfw_pch_test)
    else()
      set(_donor mmlfw_pch_host)
    endif()
    # The precompiled Eigen comes with its include path and the definitions it was built with
    # (GCC ignores a PCH without them): a target that did not use Eigen now merely could.
    target_include_directories(${_t} SYSTEM PRIVATE ${EIGEN3_INCLUDE_DIR})
    target_compile_definitions(${_t} PRIVATE EIGEN_NO_MALLOC EIGEN_DONT_PARALLELIZE)
    target_precompile_headers(${_t} REUSE_FROM ${_donor})
  endforeach()
  get_property(_subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(_d IN LISTS _subdirs)
    cmake_path(IS_PREFIX PROJECT_SOURCE_DIR "${_d}" NORMALIZE _inside)
    if(_inside)
      mmlfw_pch_targets(${_d})
    endif()
  endforeach()
endfunction()

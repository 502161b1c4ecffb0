# Project-wide options and the one place where firmware/hal compile flags live.
option(MMLFW_BUILD_HOST_TOOLS "Build sim/ host tools (off for cross builds)" ON)
option(MMLFW_BUILD_BENCHMARKS "Build benchmarks (Google Benchmark / harness)" ON)
set(MMLFW_SANITIZE "" CACHE STRING "Sanitizers: '', 'address' (ASan+UBSan), 'thread' or 'fuzzer' (libFuzzer + ASan/UBSan)")

# Eigen is header-only; for cross builds the host copy under /usr/include/eigen3 is the same.
find_path(EIGEN3_INCLUDE_DIR NAMES Eigen/Core PATHS /usr/include/eigen3 NO_CMAKE_FIND_ROOT_PATH)
if(NOT EIGEN3_INCLUDE_DIR)
  message(FATAL_ERROR "Eigen3 not found (install libeigen3-dev: scripts/setup.sh)")
endif()
add_library(eigen3 INTERFACE)
target_include_directories(eigen3 SYSTEM INTERFACE ${EIGEN3_INCLUDE_DIR})
# Eigen must never touch the heap in firmware: fixed-size types only, checked at run time too.
target_compile_definitions(eigen3 INTERFACE EIGEN_NO_MALLOC EIGEN_DONT_PARALLELIZE)

# Reproducibility across x86-64 and aarch64: no FMA contraction (GCC contracts by default on
# aarch64, which changes float results), no fast-math anywhere.
add_compile_options(-ffp-contract=off)

# Under the sanitizers the inliner gives up on Eigen's small expression templates (the instrumented
# bodies grow past its threshold), so a 2×2 product becomes a chain of calls and the tests run 14×
# slower than release instead of the ~2–3× the checks themselves cost. Eigen's hook for this is
# EIGEN_STRONG_INLINE (Macros.h: `inline` on GCC/clang unless defined): forced here, in sanitized
# builds only; the checks inside the inlined code are kept.
macro(mmlfw_eigen_always_inline)
  add_compile_definitions("EIGEN_STRONG_INLINE=inline __attribute__((always_inline))")
endmacro()

if(MMLFW_SANITIZE STREQUAL "address")
  # -fno-sanitize=vptr: UBSan's vptr check needs typeinfo, which the -fno-rtti firmware/hal libraries
  # (e.g. hal_sim's polymorphic sources used from RTTI-enabled tests) do not emit: link errors otherwise.
  add_compile_options(-fsanitize=address,undefined -fno-sanitize=vptr -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    # clang's UBSan `function` check emits typeinfo for function types into every object, the
    # -fno-rtti firmware libraries included (symbol_check would report RTTI); GCC has no such check.
    add_compile_options(-fno-sanitize=function)
  endif()
  mmlfw_eigen_always_inline()
elseif(MMLFW_SANITIZE STREQUAL "fuzzer")
  # libFuzzer targets (tests/fuzz, `fuzz` preset, clang only): every library carries the fuzzer's
  # coverage instrumentation plus ASan+UBSan; only the fuzz executables link libFuzzer's main.
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "MMLFW_SANITIZE=fuzzer needs clang (the fuzz preset sets it)")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize=vptr -fno-omit-frame-pointer
                      -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
  mmlfw_eigen_always_inline()
elseif(MMLFW_SANITIZE STREQUAL "thread")
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
  mmlfw_eigen_always_inline()
endif()

# Embedded rules for firmware/ and hal/ targets (DEVELOPERS.md): no exceptions, no RTTI, warnings
# are errors. Tests and sim/ are ordinary C++20 and do not call this.
set(MMLFW_EMBEDDED_FLAGS -fno-exceptions -fno-rtti -Wall -Wextra -Wshadow -Werror -Wno-psabi)
function(mmlfw_embedded_target tgt)
  target_compile_options(${tgt} PRIVATE ${MMLFW_EMBEDDED_FLAGS})
  target_link_libraries(${tgt} PUBLIC eigen3)
  set_property(GLOBAL APPEND PROPERTY MMLFW_EMBEDDED_LIBS ${tgt})
endfunction()

# GoogleTest: built from Debian's source package so that cross builds get a matching library.
if(NOT TARGET gtest)
  set(INSTALL_GTEST OFF CACHE BOOL "" FORCE)
  set(BUILD_GMOCK OFF CACHE BOOL "" FORCE)
  add_subdirectory(/usr/src/googletest ${CMAKE_BINARY_DIR}/_googletest EXCLUDE_FROM_ALL)
endif()

include(${CMAKE_CURRENT_LIST_DIR}/pch.cmake)
mmlfw_pch_donors()

# mmlfw_add_test(NAME SOURCES... LIBS ...): a gtest binary registered with CTest. Tests sit
# beside the code they test (Cartographer style); the fault handler is made fatal by test_main.
# Long tests start first. With no cost data (a clean CI clone) CTest starts tests in the order they
# are defined, so a long one defined late runs alone at the end while the other core idles
# (fresh-clone CI 2026-11-26: fw_antslam_test, 169 s under qemu-aarch64, started last of 34, and the
# stage took 320 s of test time for about 540 s of work on 2 cores). COST is the weight CTest
# schedules by; the figures are seconds measured under ASan / qemu on the 2-core machine.
set(MMLFW_LONG_TESTS fw_antslam_test=190 sim_slam_data_test=160 fw_mml_test=120 sim_kidnap_twin_test=90
    fw_rbsm_test=70 sim_transport_sick_aces_test=60 sim_transport_can_aces_test=55 fw_mml_handoff_test=55
    pransam3d_data_test=50 user_building_cli_path=45 fw_track_test=40 fw_mml_reset_test=40)
# mmlfw_test_entry(NAME TABLE OUT): the value of NAME's "NAME=value" entry in the list TABLE, or
# empty (the tables below: test costs, cases left out of slow builds).
function(mmlfw_test_entry name table out)
  set(_value "")
  foreach(_entry IN LISTS ${table})
    if(_entry MATCHES "^${name}=(.+)$")
      set(_value "${CMAKE_MATCH_1}")
    endif()
  endforeach()
  set(${out} "${_value}" PARENT_SCOPE)
endfunction()
function(mmlfw_test_cost name)
  mmlfw_test_entry(${name} MMLFW_LONG_TESTS _cost)
  if(_cost)
    set_tests_properties(${name} PROPERTIES COST ${_cost})
  endif()
endfunction()

# Slow builds leave out cases whose work the host release build already judges (2-core CI: the
# landings of 2026-11-27/28 took 67-71 min against a 90 min limit).
# - Under an emulator (the aarch64 stage: qemu-user, 20-50x slower than the host) the end-to-end
#   scenario cases of 0.8 s or more in the host release build are left out: 31 cases were 96 % of
#   the stage's test time (1841 s of qemu CPU, 1007 s on 2 cores; fw_antslam_test alone 487 s). On
#   aarch64, TrackedLocalizerTest.FixThenTrackEveryScan still drives MML + tracker end to end and
#   TrackedLocalizerTest.NoHeapInSteps counts the heap in every step. (AntSlamTest.NoHeapAfterInit
#   is out with the ring runs it reads: 299 s under qemu.) Cases added since then and over the
#   line, left out on 2026-12-01 (aarch64 tests 250 s on 2 cores, fw_track_test 244 s of it): the
#   look-alike wing and dead-reckoned outside-map cases (70 % of fw_track_test on the host) and the
#   ring's final-refinement runs (221 s: every AntSLAM ring run is now left to the host and ASan;
#   on aarch64 AntColonyTest, the front end's PoseInEveryFragmentMatchesPropagationFromItsFrame and
#   the host/aarch64 comparison of the ant colony's answer remain).
# - Under ASan, the cases that repeat a run another case already made, to compare the two
#   (determinism: a property of the release build, not of memory safety; the reset paths run under
#   ASan in fw_mml_reset_test), the ring's ant-colony run (AntSLAM's ACO and LM run under ASan on
#   the intel prefix, sim_slam_data_test), and the scripts labelled `scenario` (scripts/test.sh).
#   Measured: ASan tests 1151 -> 813 s on 2 cores before the ring case was added here. Also the
#   final refinement after LM (the same refinement code as after the ant colony, whose case runs
#   here) and the mit-killian carry replays that only judge the scenario (neighbouring steps, the
#   witness without the rule): the 2026-12-01 landing's CI took 68 min, fw_antslam_test 959 s and
#   sim_mml_localize_data_test 348 s of ASan time. The emulated build leaves out the LM case too.
# - Both leave the corpus runner's end-to-end case to the host (sim_corpus_test CorpusRunnerTest: three
#   short generated runs made twice to compare them: determinism, and whole-world behaviour).
# -DMMLFW_SLOW_BUILD_FULL=ON runs them all.
option(MMLFW_SLOW_BUILD_FULL "In emulated and sanitized builds, run the long scenario cases too" OFF)
set(MMLFW_EMULATED_SKIP
    "fw_antslam_test=AntSlamTest.ClosesTheRingAndBeatsTheDriftingFrontEnd:AntSlamTest.SecondLapTraversesTheFirstLapsFragments:AntSlamTest.SameSeedSamePoses:AntSlamTest.NoHeapAfterInit:AntSlamTest.FinalRefinement*"
    "fw_mml_handoff_test=MmlZeroHeapTest.MmlMclAndHandoffStepsAllocateNothing:MmlZeroHeapTest.CorrectionAndReductionAllocateNothing:HandoffTest.TracksAndRecoversFromKidnap"
    "fw_mcl_test=MclTest.GlobalLocalizationBeamModel:MclLocalizerTest.ResetGivesAFreshStart"
    "fw_rbsm_test=RbsmTest.MotionPriorShrinksTheJumpsAlongAFeaturelessCorridor"
    "fw_mml_test=MmlLocalizerTest.UniqueRoomLocalizes*:MmlLocalizerTest.DeterministicAndResettable:MmlLocalizerTest.UnknownAreaReportsOutsideMap:MmlLocalizerTest.SymmetricCorridorStaysAmbiguous:MmlLocalizerTest.StartInUnknownAreaNeverLocalizes"
    "fw_mml_reset_test=MmlResetTest.ResetGivesAFreshStart*"
    "fw_track_test=TrackedLocalizerTest.DeterministicAndResettable:TrackedLocalizerTest.LargeFaultWaitsForGlobalConfirmation:TrackedLocalizerTest.HeadingOnlyFaultRecoversWithoutWaitingForMml:TrackedLocalizerTest.FixIsConfirmedOnTheScansBeforeIt:TrackedLocalizerTest.KidnapIsDetectedAndRefixed:GlobalContextTest.ThreadedEqualsInlineWhenOnTime:GlobalContextTest.LiveScheduleInlineLocalizes:GlobalContextTest.ConfirmedFixScanIsNotOffered:TrackedLocalizerTest.LookAlikeWingBeyondTheMapIsNeverLocalized:TrackedLocalizerTest.OutsideMapComesFromTheScanAtTheDeadReckonedPose:TrackedLocalizerTest.ForwardStartAfterAFailedReplaySharesTheScansBudget"
    "sim_corpus_test=CorpusRunnerTest.*")
set(MMLFW_SANITIZED_SKIP
    "fw_antslam_test=AntSlamTest.SameSeedSamePoses:AntSlamTest.ClosesTheRingAndBeatsTheDriftingFrontEnd:AntSlamTest.FinalRefinementAfterLmLowersTheWholeGraphsCost"
    "fw_mml_test=MmlLocalizerTest.DeterministicAndResettable"
    "fw_track_test=TrackedLocalizerTest.DeterministicAndResettable"
    "sim_corpus_test=CorpusRunnerTest.*"
    "sim_mml_localize_data_test=LocalizeData.MitKillianCarryOneStepEarlierOrLaterIsNotLocalized:LocalizeData.MitKillianCarryWithoutTheRuleIsTheWitness")
function(mmlfw_slow_build_filter name)
  if(MMLFW_SLOW_BUILD_FULL)
    return()
  elseif(CMAKE_CROSSCOMPILING)
    mmlfw_test_entry(${name} MMLFW_EMULATED_SKIP _skip)
  elseif(MMLFW_SANITIZE STREQUAL "address")
    mmlfw_test_entry(${name} MMLFW_SANITIZED_SKIP _skip)
  endif()
  if(_skip)
    set_property(TEST ${name} APPEND PROPERTY ENVIRONMENT "GTEST_FILTER=-${_skip}")
  endif()
endfunction()

function(mmlfw_add_test name)
  cmake_parse_arguments(T "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${T_SOURCES})
  target_link_libraries(${name} PRIVATE ${T_LIBS} mmlfw_test_main gtest)
  add_test(NAME ${name} COMMAND ${name})
  if(T_LABELS)
    set_tests_properties(${name} PROPERTIES LABELS "${T_LABELS}")
  endif()
  if(DEFINED ENV{MMLFW_DATA_DIR})
    set_tests_properties(${name} PROPERTIES ENVIRONMENT "MMLFW_DATA_DIR=$ENV{MMLFW_DATA_DIR}")
  else()
    set_tests_properties(${name} PROPERTIES ENVIRONMENT "MMLFW_DATA_DIR=${CMAKE_SOURCE_DIR}/../shared/data")
  endif()
  mmlfw_test_cost(${name})
  mmlfw_slow_build_filter(${name})
endfunction()

# mmlfw_add_benchmark(NAME SOURCES... LIBS ...): host benchmark executable bench_NAME in
# build/<preset>/bench/, run by scripts/bench.sh NAME with the JSON output path as argv[1].
function(mmlfw_add_benchmark name)
  cmake_parse_arguments(B "" "" "SOURCES;LIBS" ${ARGN})
  if(NOT MMLFW_BUILD_BENCHMARKS)
    return()
  endif()
  add_executable(bench_${name} ${B_SOURCES})
  target_link_libraries(bench_${name} PRIVATE ${B_LIBS} sim_common)
  set_target_properties(bench_${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
endfunction()

# Helpers shared by every folder's CMakeLists.txt.

# pixelgym_set_warnings(target): the warning flags for pixelgym's own code; errors when
# PIXELGYM_WERROR is on. Third-party headers come in through imported targets, which CMake
# marks SYSTEM, so their warnings do not count.
function(pixelgym_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Woverloaded-virtual -Wcast-align -Wnull-dereference)
  if(PIXELGYM_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# pixelgym_add_library(NAME SOURCES ... DEPS ...): library pixelgym_NAME (shared unless
# PIXELGYM_SHARED_LIBS is off) with alias pixelgym::NAME, exported as pixelgym::NAME by
# `cmake --install` (cmake/PixelgymInstall.cmake); headers are included as "pixelgym/NAME/file.h",
# in the build tree through PIXELGYM_INCLUDE_DIR (a folder whose pixelgym/NAME links to the
# source's NAME/), once installed from include/.
function(pixelgym_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  if(PIXELGYM_SHARED_LIBS)
    add_library(pixelgym_${name} SHARED ${ARG_SOURCES})
  else()
    add_library(pixelgym_${name} STATIC ${ARG_SOURCES})
  endif()
  add_library(pixelgym::${name} ALIAS pixelgym_${name})
  target_compile_features(pixelgym_${name} PUBLIC cxx_std_17)
  target_include_directories(pixelgym_${name} PUBLIC $<BUILD_INTERFACE:${PIXELGYM_INCLUDE_DIR}>
                             $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                             $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(pixelgym_${name} PUBLIC ${ARG_DEPS})
  # Installed, the libraries find each other in their own folder.
  set_target_properties(pixelgym_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON EXPORT_NAME ${name}
                        VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR}
                        INSTALL_RPATH "$ORIGIN")
  set_property(GLOBAL APPEND PROPERTY PIXELGYM_LIBRARIES pixelgym_${name})
  pixelgym_set_warnings(pixelgym_${name})
endfunction()

# pixelgym_torch_library(NAME SOURCES ... DEPS ...): static library pixelgym_NAME (alias
# pixelgym::NAME) of the trainer's LibTorch code, linked to LibTorch and DEPS. TorchConfig.cmake
# gives a plain `torch` target plus TORCH_INCLUDE_DIRS (find_package(Torch) before the call);
# those include paths are made SYSTEM so that torch's own warnings do not trip -Werror.
function(pixelgym_torch_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(pixelgym_${name} STATIC ${ARG_SOURCES})
  add_library(pixelgym::${name} ALIAS pixelgym_${name})
  target_compile_features(pixelgym_${name} PUBLIC cxx_std_17)
  target_include_directories(pixelgym_${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
  target_include_directories(pixelgym_${name} SYSTEM PUBLIC ${TORCH_INCLUDE_DIRS})
  target_link_libraries(pixelgym_${name} PUBLIC ${TORCH_LIBRARIES} ${ARG_DEPS})
  pixelgym_set_warnings(pixelgym_${name})
endfunction()

# pixelgym_add_bench(NAME SOURCE LIBS ...): the benchmark program NAME, built only with
# PIXELGYM_BUILD_BENCH (speed is measured in benchmarks, not in tests).
function(pixelgym_add_bench name source)
  cmake_parse_arguments(ARG "" "" "LIBS" ${ARGN})
  if(PIXELGYM_BUILD_BENCH)
    add_executable(${name} ${source})
    target_link_libraries(${name} PRIVATE ${ARG_LIBS})
    pixelgym_set_warnings(${name})
  endif()
endfunction()

# pixelgym_add_test(SOURCE LIBS ...): one GoogleTest executable per test file, named after its
# path under tests/ (tests/envs/array_test.cc -> envs_array_test), its tests registered with
# ctest by gtest_discover_tests at test time. Tests run in the build tree with
# PIXELGYM_TEST_OUTPUT_DIR naming where they may write files a person should look at. LABELS
# gives every test of the file those ctest labels (`threads`: built by the target threads_tests
# and run under ThreadSanitizer by `make test-tsan`).
#
# COUNTS_ALLOCATIONS marks a test that defines malloc and operator new to count allocations
# (tests/alloc_counter.h): a sanitizer's allocator cannot be replaced, so a sanitizer build leaves
# it out (what it measures, allocations per step, is the Release build's anyway).
#
# TENSOR_MATH marks a test whose work is LibTorch's tensor math (networks, distributions, losses,
# optimizer steps): it runs inside LibTorch, which is not instrumented, so the AddressSanitizer
# build leaves it out (issue 31: it keeps CI under an hour; docs/reliability.md lists them).
#
# In the AddressSanitizer build tests compile at -O0 (the libraries they test stay at -O1): a
# third faster to build, and what they run is mostly the libraries. COMPUTES marks a test whose
# own code does heavy numeric work (the acrobot's model-predictive controller, all Eigen): it keeps
# -O1, since at -O0 it ran 213 times slower than in Release (1,033 s, the longest test in CI).
function(pixelgym_add_test source)
  cmake_parse_arguments(ARG "COUNTS_ALLOCATIONS;TENSOR_MATH;COMPUTES" "" "LIBS;LABELS" ${ARGN})
  if(ARG_COUNTS_ALLOCATIONS AND NOT PIXELGYM_SANITIZE STREQUAL "")
    return()
  endif()
  if(ARG_TENSOR_MATH AND PIXELGYM_SANITIZE STREQUAL "address")
    return()
  endif()
  file(RELATIVE_PATH relative ${PROJECT_SOURCE_DIR}/tests ${CMAKE_CURRENT_SOURCE_DIR}/${source})
  string(REGEX REPLACE "\\.cc$" "" target ${relative})
  string(REPLACE "/" "_" target ${target})
  add_executable(${target} ${source})
  target_link_libraries(${target} PRIVATE ${ARG_LIBS} GTest::gmock GTest::gtest_main)
  target_compile_definitions(${target} PRIVATE
    PIXELGYM_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    PIXELGYM_TEST_OUTPUT_DIR="${PROJECT_BINARY_DIR}/test_output")
  pixelgym_set_warnings(${target})
  if(PIXELGYM_SANITIZE STREQUAL "address" AND NOT ARG_COMPUTES)
    target_compile_options(${target} PRIVATE -O0)
  endif()
  set(properties "")
  # A folder's own labels for every test in it (PIXELGYM_FOLDER_TEST_LABELS, set before its
  # pixelgym_add_test calls): render_tasks, built by render_task_tests.
  list(APPEND ARG_LABELS ${PIXELGYM_FOLDER_TEST_LABELS})
  if("threads" IN_LIST ARG_LABELS)
    add_dependencies(threads_tests ${target})
  endif()
  if("render_tasks" IN_LIST ARG_LABELS)
    add_dependencies(render_task_tests ${target})
  endif()
  if(ARG_LABELS)
    set(properties PROPERTIES LABELS "${ARG_LABELS}")
  endif()
  gtest_discover_tests(${target} DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60
                       WORKING_DIRECTORY ${PROJECT_BINARY_DIR} ${properties})
endfunction()

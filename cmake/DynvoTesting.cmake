# SPDX-License-Identifier: BSD-3-Clause
# Test plumbing shared by test/ and pcl_modules/*/test; included from the root before any
# add_subdirectory so that module folders can register their own unit tests.
enable_testing()
find_package(GTest REQUIRED)
include(GoogleTest)

get_filename_component(DYNVO_SHARED_DATA_ABS "${DYNVO_SHARED_DATA_DIR}" ABSOLUTE)

# dynvo_add_test(<name> SOURCES ... LIBS ... [LABEL unit|integration|app|render])
# One gtest executable per topic; data paths come in as compile definitions.
function(dynvo_add_test name)
  cmake_parse_arguments(ARG "" "LABEL" "SOURCES;LIBS" ${ARGN})
  if(NOT ARG_LABEL)
    set(ARG_LABEL integration)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE
    DYNVO_SHARED_DATA_DIR="${DYNVO_SHARED_DATA_ABS}"
    DYNVO_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    DYNVO_BINARY_DIR="${PROJECT_BINARY_DIR}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/test_bin)
  gtest_discover_tests(${name} PROPERTIES LABELS ${ARG_LABEL} DISCOVERY_TIMEOUT 60)
endfunction()

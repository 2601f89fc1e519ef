# Per-target settings shared by every mft-wbc target. Warnings are set per target, never globally.
function(mft_target_settings target)
  target_compile_features(${target} PUBLIC cxx_std_17)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                           -Woverloaded-virtual -Wcast-align -Wformat=2)
  endif()
endfunction()

# Libraries: mft_add_library(name SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
function(mft_add_library name)
  cmake_parse_arguments(A "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} ${A_SOURCES})
  mft_target_settings(${name})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${A_PUBLIC_DEPS} PRIVATE ${A_PRIVATE_DEPS})
endfunction()

# Executables land in <build>/bin so that tests and scripts find every tool in one place.
function(mft_add_executable name)
  cmake_parse_arguments(A "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${A_SOURCES})
  mft_target_settings(${name})
  target_link_libraries(${name} PRIVATE ${A_DEPS})
  target_compile_definitions(${name} PRIVATE MFT_CONFIG_DIR="${MFT_CONFIG_DIR}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
endfunction()

# Unit tests: mft_add_gtest(name LABEL label SOURCES ... DEPS ...)
function(mft_add_gtest name)
  cmake_parse_arguments(A "" "LABEL;TIMEOUT" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${A_SOURCES})
  mft_target_settings(${name})
  target_link_libraries(${name} PRIVATE ${A_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE MFT_CONFIG_DIR="${MFT_CONFIG_DIR}"
                             MFT_SHARED_DIR="${MFT_SHARED_DIR}" MFT_BIN_DIR="${PROJECT_BINARY_DIR}/bin"
                             MFT_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data")
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 300)
  endif()
  gtest_discover_tests(${name} PROPERTIES LABELS "${A_LABEL}" TIMEOUT ${A_TIMEOUT} DISCOVERY_TIMEOUT 60)
endfunction()

# Per-target settings shared by every mft-wbc target. Warnings are set per target, never globally, so code we
# do not write (fastddsgen's generated mft_msgs) gets neither the warnings nor MFT_WERROR.
function(mft_target_settings target)
  target_compile_features(${target} PUBLIC cxx_std_17)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                           -Woverloaded-virtual -Wcast-align -Wformat=2)
    if(MFT_WERROR)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
endfunction()

# Libraries: mft_add_library(name SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
function(mft_add_library name)
  cmake_parse_arguments(A "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} ${A_SOURCES})
  mft_target_settings(${name})
  # Sources include "model/...", "wbc/qp/..." from the repository root; an install keeps that layout under
  # <prefix>/include/mft (docs/library.md).
  target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                                            $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/mft>)
  target_link_libraries(${name} PUBLIC ${A_PUBLIC_DEPS} PRIVATE ${A_PRIVATE_DEPS})
endfunction()

# Executables land in <build>/bin so that tests and scripts find every tool in one place, and in <prefix>/bin
# of an install unless NO_INSTALL (a tool that only makes sense in the source tree).
function(mft_add_executable name)
  cmake_parse_arguments(A "NO_INSTALL" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${A_SOURCES})
  mft_target_settings(${name})
  target_link_libraries(${name} PRIVATE ${A_DEPS})
  target_compile_definitions(${name} PRIVATE MFT_CONFIG_DIR="${MFT_CONFIG_DIR}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
  if(NOT A_NO_INSTALL)
    install(TARGETS ${name} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  endif()
endfunction()

# Unit tests: mft_add_gtest(name LABEL label SOURCES ... DEPS ...)
function(mft_add_gtest name)
  cmake_parse_arguments(A "" "LABEL;TIMEOUT" "SOURCES;DEPS" ${ARGN})
  if(NOT A_SOURCES)
    message(WARNING "test ${name} has no sources yet: skipped")
    return()
  endif()
  add_executable(${name} ${A_SOURCES})
  mft_target_settings(${name})
  target_link_libraries(${name} PRIVATE ${A_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE MFT_CONFIG_DIR="${MFT_CONFIG_DIR}"
                             MFT_BIN_DIR="${PROJECT_BINARY_DIR}/bin"
                             MFT_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data")
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 300)
  endif()
  gtest_discover_tests(${name} PROPERTIES LABELS "${A_LABEL}" TIMEOUT ${A_TIMEOUT} DISCOVERY_TIMEOUT 60)
endfunction()

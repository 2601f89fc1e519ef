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
  # <prefix>/include/mft (docs/guide/library.md).
  target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                                            $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/mft>)
  target_link_libraries(${name} PUBLIC ${A_PUBLIC_DEPS} PRIVATE ${A_PRIVATE_DEPS})
endfunction()

# A program of ours (tool or test): the shared settings, its private dependencies, and where config/ is.
function(mft_add_program name sources deps)
  add_executable(${name} ${sources})
  mft_target_settings(${name})
  target_link_libraries(${name} PRIVATE ${deps})
  target_compile_definitions(${name} PRIVATE MFT_CONFIG_DIR="${MFT_CONFIG_DIR}")
endfunction()

# Executables land in <build>/bin so that tests and scripts find every tool in one place, and in <prefix>/bin
# of an install unless NO_INSTALL (a tool that only makes sense in the source tree).
function(mft_add_executable name)
  cmake_parse_arguments(A "NO_INSTALL" "" "SOURCES;DEPS" ${ARGN})
  mft_add_program(${name} "${A_SOURCES}" "${A_DEPS}")
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
  mft_add_program(${name} "${A_SOURCES}" "${A_DEPS};GTest::gtest;GTest::gtest_main")
  target_compile_definitions(${name} PRIVATE MFT_BIN_DIR="${PROJECT_BINARY_DIR}/bin"
                             MFT_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data")
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 300)
  endif()
  gtest_discover_tests(${name} PROPERTIES LABELS "${A_LABEL}" TIMEOUT ${A_TIMEOUT} DISCOVERY_TIMEOUT 60)
endfunction()

# The Python interpreter for test scripts: Debian's /usr/bin/python3 (which has numpy, yaml, matplotlib) where it
# exists, else the one CMake finds. Sets `var` in the caller.
function(mft_test_python var)
  find_program(MFT_DEBIAN_PYTHON python3 PATHS /usr/bin NO_DEFAULT_PATH)
  if(MFT_DEBIAN_PYTHON)
    set(${var} ${MFT_DEBIAN_PYTHON} PARENT_SCOPE)
  else()
    find_package(Python3 REQUIRED COMPONENTS Interpreter)
    set(${var} ${Python3_EXECUTABLE} PARENT_SCOPE)
  endif()
endfunction()

# Python test scripts: mft_add_python_test(name SCRIPT file LABELS ... TIMEOUT s [REQUIRES targets...]
#   [ARGS ...] [RUN_SERIAL] [BIN_DIR] [DEBIAN_PYTHON] [SKIP_REGULAR_EXPRESSION regex])
# Registered only when every REQUIRES target exists (the executables the script runs). BIN_DIR passes
# MFT_BIN_DIR=<build>/bin in the environment; DEBIAN_PYTHON runs it with mft_test_python's interpreter.
function(mft_add_python_test name)
  cmake_parse_arguments(A "RUN_SERIAL;BIN_DIR;DEBIAN_PYTHON" "SCRIPT;TIMEOUT;SKIP_REGULAR_EXPRESSION"
                        "LABELS;REQUIRES;ARGS" ${ARGN})
  foreach(target ${A_REQUIRES})
    if(NOT TARGET ${target})
      return()
    endif()
  endforeach()
  if(A_DEBIAN_PYTHON)
    mft_test_python(python)
  else()
    find_package(Python3 REQUIRED COMPONENTS Interpreter)
    set(python ${Python3_EXECUTABLE})
  endif()
  add_test(NAME ${name} COMMAND ${python} ${CMAKE_CURRENT_SOURCE_DIR}/${A_SCRIPT} ${A_ARGS})
  set_tests_properties(${name} PROPERTIES LABELS "${A_LABELS}" TIMEOUT ${A_TIMEOUT})
  if(A_RUN_SERIAL)
    set_tests_properties(${name} PROPERTIES RUN_SERIAL TRUE)
  endif()
  if(A_SKIP_REGULAR_EXPRESSION)
    set_tests_properties(${name} PROPERTIES SKIP_REGULAR_EXPRESSION "${A_SKIP_REGULAR_EXPRESSION}")
  endif()
  if(A_BIN_DIR)
    set_tests_properties(${name} PROPERTIES ENVIRONMENT "MFT_BIN_DIR=${PROJECT_BINARY_DIR}/bin")
  endif()
endfunction()

# Every subfolder of the current one that has a CMakeLists.txt (tests/ and tools/: one folder per area or tool).
macro(mft_add_subfolders)
  file(GLOB _mft_subfolders LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/*)
  foreach(_mft_dir ${_mft_subfolders})
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${_mft_dir} AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${_mft_dir}/CMakeLists.txt)
      add_subdirectory(${_mft_dir})
    endif()
  endforeach()
endmacro()

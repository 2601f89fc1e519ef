# What `cmake --install` puts under a prefix and what `cpack -G DEB` packs (docs/guide/library.md):
#   lib/                       the algorithm libraries (static), exported as mft::common, mft::model, mft::qp,
#                              mft::wbc, mft::planner, mft::estimator, mft::sim
#   lib/cmake/mft_wbc/         mft_wbcConfig.cmake (find_package(mft_wbc)), its version file and the targets
#   include/mft/<library>/     their headers, in the layout the sources include them ("model/five_bar.hpp")
#   bin/                       the services, the tools (mft_add_executable) and mft-supervisor
#   share/mft_wbc/config       the configuration; share/mft_wbc/scripts the tools' plotting scripts;
#                              share/mft_wbc/python the supervisor's package (mftstack)
#   share/doc/mft-wbc/         README, docs/guide/library.md and the example project
# No DDS or MRPT library is installed for linking: the stack's middleware is not part of the library interface.
include(CMakePackageConfigHelpers)

set(MFT_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/mft_wbc)
set(MFT_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/mft_wbc)

# Library target -> exported name (mft::<name>) -> header folder of the source tree.
set(MFT_EXPORTED_LIBRARIES
  "mft_common|common|common"   # common/: strict YAML, command line, JSON, tool I/O
  "mft_model|model|model"
  "mft_qp|qp|"                  # headers in wbc/qp, installed with the WBC's
  "mft_wbc|wbc|wbc"
  "mft_planner|planner|planner"
  "mft_estimator|estimator|estimator"
  "mft_sim|sim|sim")
set(MFT_EXPORTED_COMPONENTS "")
foreach(entry ${MFT_EXPORTED_LIBRARIES})
  string(REPLACE "|" ";" parts "${entry}")
  list(GET parts 0 target)
  list(GET parts 1 export_name)
  list(LENGTH parts n)
  if(NOT TARGET ${target})
    continue()
  endif()
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  install(TARGETS ${target} EXPORT mft_wbcTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
          INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mft)
  list(APPEND MFT_EXPORTED_COMPONENTS ${export_name})
  if(n GREATER 2)
    list(GET parts 2 header_dir)
    if(header_dir)
      # ode_*.hpp are the simulator's private ODE wrappers (<ode/ode.h>); nothing public includes them.
      install(DIRECTORY ${PROJECT_SOURCE_DIR}/${header_dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mft/${header_dir}
              COMPONENT development FILES_MATCHING PATTERN "*.hpp" PATTERN "ode_*.hpp" EXCLUDE)
    endif()
  endif()
endforeach()

install(EXPORT mft_wbcTargets NAMESPACE mft:: DESTINATION ${MFT_INSTALL_CMAKEDIR} COMPONENT development)
set(MFT_INSTALL_CONFIGDIR ${MFT_INSTALL_DATADIR}/config)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/mft_wbcConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/cmake/mft_wbcConfig.cmake
                              INSTALL_DESTINATION ${MFT_INSTALL_CMAKEDIR}
                              PATH_VARS MFT_INSTALL_CONFIGDIR CMAKE_INSTALL_INCLUDEDIR)
# 0.x: a minor version may change the interface.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/mft_wbcConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/mft_wbcConfig.cmake ${PROJECT_BINARY_DIR}/cmake/mft_wbcConfigVersion.cmake
        DESTINATION ${MFT_INSTALL_CMAKEDIR} COMPONENT development)

# Data the installed executables find beside their bin/ (common/install_layout.hpp, python/mftstack/paths.py).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION ${MFT_INSTALL_DATADIR}/config COMPONENT runtime)
install(PROGRAMS ${PROJECT_SOURCE_DIR}/tools/mft-export/mft-plot.py ${PROJECT_SOURCE_DIR}/tools/mft-export/mft-video.py
                 ${PROJECT_SOURCE_DIR}/tools/mft-space/mft_space_figure.py
        DESTINATION ${MFT_INSTALL_DATADIR}/scripts COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/tools/mft-export/mft_video_panel.py  # imported by mft-video.py from beside it
        DESTINATION ${MFT_INSTALL_DATADIR}/scripts COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/python/mftstack DESTINATION ${MFT_INSTALL_DATADIR}/python COMPONENT runtime
        PATTERN "__pycache__" EXCLUDE PATTERN "*.pyc" EXCLUDE)
install(PROGRAMS ${PROJECT_SOURCE_DIR}/services/mft-supervisor DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/docs/guide/library.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples COMPONENT development)

# The Debian package: `cpack -G DEB` in the build folder (docs/guide/library.md#debian-package).
set(CPACK_PACKAGE_NAME mft-wbc)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "mft-wbc")
set(CPACK_PACKAGE_CONTACT "mft-wbc maintainers <maintainers@users.noreply.h-seed-20b13785.example>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "MFT-enhanced whole-body control for parallel-legged robots: libraries, services, tools")
set(CPACK_PACKAGE_DESCRIPTION
    "Motion/force-transmissibility-enhanced whole-body control (MFT-WBC) for a planar biped with five-bar legs: \
the model, WBC, planner, estimator and simulator libraries with their headers and CMake package (find_package(mft_wbc)), \
the Fast DDS services and tools, the configuration and the Python supervisor.")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${CPACK_PACKAGE_CONTACT}")
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
# The shared libraries the executables link (Fast DDS, MRPT, ODE, yaml-cpp, Cyclone DDS when built) come from
# dpkg-shlibdeps; the supervisor and the plotting scripts need Debian's python3 packages.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3, python3-yaml")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3-matplotlib, python3-numpy, ffmpeg, fastdds-tools")
# Building against the package (find_package(mft_wbc)): the headers' and the static libraries' dependencies.
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "cmake, pkg-config, g++, libeigen3-dev, libyaml-cpp-dev, libode-dev")
set(CPACK_GENERATOR DEB)
include(CPack)

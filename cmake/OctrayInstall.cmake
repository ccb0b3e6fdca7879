# `cmake --install`: the octray binary with its man pages and completions, the public API (include/octray/, liboctray.a),
# a pkg-config file (octray.pc, for builds without CMake) and an exported CMake package, so
# that another project can
#   find_package(octray CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE octray::octray)
# (examples/embed/, docs/embedding.md). The internal libraries are static and linked
# privately by octray::octray; a static library's private dependencies are still needed
# when the consumer links, so they are installed and exported too (as octray::scene, ...),
# without headers: only include/octray/ is installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(OCTRAY_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/octray)

# Exported names: octray_scene -> octray::scene, ...
foreach(lib core scene kernels prepare render reference image warnings fp_model optimize)
  set_target_properties(octray_${lib} PROPERTIES EXPORT_NAME ${lib})
endforeach()

install(TARGETS octray RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The executables that `octray view` and `octray bench` run (tools/own_executable.h): octray
# finds them at this place relative to itself (tools/CMakeLists.txt,
# OCTRAY_OWN_EXECUTABLES_RELATIVE_DIR).
install(TARGETS octray_viewer octray_bencher RUNTIME DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/octray)
# Its man pages (octray(1), octray-render(1), ...) and shell completions, generated at build
# time from the parser's options (target octray_docs, tools/CMakeLists.txt).
install(DIRECTORY ${OCTRAY_SHARE_DIR}/man/man1 DESTINATION ${CMAKE_INSTALL_MANDIR}
        FILES_MATCHING PATTERN "*.1")
install(FILES ${OCTRAY_SHARE_DIR}/bash-completion/completions/octray
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
install(FILES ${OCTRAY_SHARE_DIR}/zsh/vendor-completions/_octray
        DESTINATION ${CMAKE_INSTALL_DATADIR}/zsh/vendor-completions)
install(TARGETS octray_api octray_batch octray_frames octray_aov octray_core octray_scene octray_kernels octray_prepare octray_render
                octray_reference octray_image octray_image_model
                octray_warnings octray_fp_model octray_optimize
        EXPORT octrayTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/octray
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT octrayTargets NAMESPACE octray:: DESTINATION ${OCTRAY_INSTALL_CMAKEDIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/octrayConfig.cmake.in
  ${PROJECT_BINARY_DIR}/octrayConfig.cmake INSTALL_DESTINATION ${OCTRAY_INSTALL_CMAKEDIR})
# 0.x: a minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/octrayConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/octrayConfig.cmake
              ${PROJECT_BINARY_DIR}/octrayConfigVersion.cmake
        DESTINATION ${OCTRAY_INSTALL_CMAKEDIR})

# octray.pc beside the CMake package: pkg-config --cflags --libs octray. It names the
# installed static libraries in link order and the system packages they need.
file(RELATIVE_PATH OCTRAY_PC_TO_PREFIX "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
string(REGEX REPLACE "/$" "" OCTRAY_PC_TO_PREFIX "${OCTRAY_PC_TO_PREFIX}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/octray.pc.in ${PROJECT_BINARY_DIR}/octray.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/octray.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# `cmake --install BUILD [--prefix PREFIX]`: pixelgym's shared libraries, their headers (under
# include/pixelgym/, included as <pixelgym/envs/registry.h> as in the source tree), the CMake package
# (find_package(pixelgym) gives the pixelgym:: targets), the assets (share/pixelgym/assets, which
# the engine finds from its own library's folder), and, from their own folders, the tool
# (examples/) and the Python package (python/). `make deb` packs the same files into a Debian
# package with CPack.
include(CMakePackageConfigHelpers)

if(NOT PIXELGYM_SHARED_LIBS)
  message(STATUS "pixelgym: PIXELGYM_SHARED_LIBS is off, so cmake --install installs no library")
  return()
endif()

get_property(pixelgym_libraries GLOBAL PROPERTY PIXELGYM_LIBRARIES)
set_target_properties(pixelgym_testing_gtest PROPERTIES EXPORT_NAME testing_gtest)
install(TARGETS ${pixelgym_libraries} pixelgym_testing_gtest EXPORT pixelgymTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
# The renderer's private headers (each says "Private" at its top: the OpenGL declarations and the
# GL objects behind render/renderer.h) are for render/*.cc only; no installed header includes them.
install(DIRECTORY engine envs render testing wrappers
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/pixelgym FILES_MATCHING PATTERN "*.h"
        REGEX "/render/(context_impl|gl|gl_library|gl_object|lod|mesh_arena|render_target|shader_programs|shadow_fit|shadow_pass|texture_cache|transforms)\\.h$"
        EXCLUDE)
# The trainer's run (pixelgym::trainer_run), included as <pixelgym/trainer/algorithm.h>.
if(TARGET pixelgym_trainer_run)
  install(DIRECTORY examples/trainer/run/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/pixelgym/trainer
          FILES_MATCHING PATTERN "*.h")
endif()
install(DIRECTORY assets/ DESTINATION ${PIXELGYM_INSTALL_ASSETS_DIR} PATTERN tools EXCLUDE)

set(pixelgym_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/pixelgym)
install(EXPORT pixelgymTargets NAMESPACE pixelgym:: DESTINATION ${pixelgym_cmake_dir})
configure_package_config_file(cmake/pixelgymConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/pixelgymConfig.cmake
                              INSTALL_DESTINATION ${pixelgym_cmake_dir})
# 0.x: a minor version may change the API, so only the same minor version is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pixelgymConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pixelgymConfig.cmake
              ${PROJECT_BINARY_DIR}/pixelgymConfigVersion.cmake
        DESTINATION ${pixelgym_cmake_dir})

# The Debian package (`make deb`, from a build configured with CMAKE_INSTALL_PREFIX=/usr):
# dpkg-shlibdeps reads the installed programs and libraries and makes the package depend on the
# Debian packages that hold the libraries they link (Bullet, OpenCV, LibTorch ...). The two GL
# backends are loaded at run time, so they are named here: OSMesa (render_backend=auto tries it
# first) as a dependency of a build with it, EGL as a recommendation.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME pixelgym)
set(CPACK_PACKAGE_VENDOR pixelgym)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_CONTACT "pixelgym maintainers <pixelgym@users.noreply.github.com>")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# Headers include Eigen's; find_package(pixelgym) finds it, Threads and nlohmann_json (the
# trainer's headers use it, and pixelgym::testing links it).
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libeigen3-dev (>= 3.4), nlohmann-json3-dev (>= 3), python3-numpy")
if(PIXELGYM_OSMESA)
  string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS ", libosmesa6")
endif()
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libegl1, libegl-mesa0, libgl1-mesa-dri")
set(CPACK_PACKAGING_INSTALL_PREFIX ${CMAKE_INSTALL_PREFIX})
include(CPack)

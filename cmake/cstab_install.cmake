# `cmake --install BUILD --prefix P`: the cstab executable, the headers a
# plugin compiles against, and the CMake package (find_package(cstab)) with
# cstab_add_method / cstab_add_problem (cmake/cstab_plugin.cmake).
include(CMakePackageConfigHelpers)
include(GNUInstallDirs)

set(cstab_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/cstab)
install(TARGETS cstab cstab_plugin_api EXPORT cstabTargets
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT cstabTargets NAMESPACE cstab:: DESTINATION ${cstab_cmake_dir})
install(DIRECTORY core linalg io methods problems plugin harness DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/cstab
        FILES_MATCHING PATTERN "*.hpp")
install(FILES ${CSTAB_GENERATED_DIR}/cstab/build_id.hpp ${CSTAB_GENERATED_DIR}/cstab/every_method.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/cstab/cstab)
# The built-in models' shared-formulation declarations (cstab_model), which a
# plugin's pairs include (cmake/cstab_plugin.cmake).
get_property(cstab_models GLOBAL PROPERTY CSTAB_MODELS)
list(TRANSFORM cstab_models PREPEND ${CSTAB_GENERATED_DIR}/models/)
list(TRANSFORM cstab_models APPEND _shared.hpp)
install(FILES ${cstab_models} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/cstab/models)
configure_package_config_file(cmake/cstabConfig.cmake.in ${PROJECT_BINARY_DIR}/cstabConfig.cmake
                              INSTALL_DESTINATION ${cstab_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cstabConfigVersion.cmake COMPATIBILITY ExactVersion)
install(FILES ${PROJECT_BINARY_DIR}/cstabConfig.cmake ${PROJECT_BINARY_DIR}/cstabConfigVersion.cmake
              ${CSTAB_GENERATED_DIR}/cstabCatalog.cmake cmake/cstab_catalog.cmake cmake/cstab_plugin.cmake
        DESTINATION ${cstab_cmake_dir})

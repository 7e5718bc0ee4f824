# Install rules: `cmake --install build --prefix P` lays out
#   P/bin/tsi                    the runner (finds P/lib/tsi/plugins relative to itself)
#   P/lib/libtsi_core.so*        the core library
#   P/lib/tsi/plugins/tsi_*.so   the shipped plugins (tsi_add_plugin installs them)
#   P/lib/tsi/libtsi_hdf5_fields.so  output.fields_every's HDF5 writer (apps/tsi/CMakeLists.txt)
#   P/include/tsi/*.hpp          the public headers: everything a plugin needs
#   P/lib/cmake/tsi/             the CMake package: find_package(tsi CONFIG), tsi::core,
#                                tsi::tsi (the runner) and tsi_add_plugin()
#   P/share/tsi/examples/plugins/ the example plugins, each buildable against P
# RPATHs are $ORIGIN-relative, so nothing needs LD_LIBRARY_PATH.
include(CMakePackageConfigHelpers)

file(RELATIVE_PATH tsi_bin_to_lib /prefix/${CMAKE_INSTALL_BINDIR} /prefix/${CMAKE_INSTALL_LIBDIR})
set_target_properties(tsi PROPERTIES INSTALL_RPATH "$ORIGIN/${tsi_bin_to_lib}")

install(TARGETS tsi_core tsi EXPORT tsiTargets
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/core/include/tsi DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp")
install(EXPORT tsiTargets NAMESPACE tsi:: DESTINATION ${TSI_INSTALL_CMAKE_DIR})

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/tsiConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/cmake/tsiConfig.cmake
                              INSTALL_DESTINATION ${TSI_INSTALL_CMAKE_DIR}
                              PATH_VARS CMAKE_INSTALL_INCLUDEDIR TSI_INSTALL_PLUGIN_DIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/tsiConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/tsiConfig.cmake ${PROJECT_BINARY_DIR}/cmake/tsiConfigVersion.cmake
              ${CMAKE_CURRENT_LIST_DIR}/TsiPlugin.cmake
        DESTINATION ${TSI_INSTALL_CMAKE_DIR})

# The plotting script `tsi study` calls, found next to an installed runner (share/tsi).
install(FILES ${PROJECT_SOURCE_DIR}/scripts/plot_study.py DESTINATION ${CMAKE_INSTALL_DATADIR}/tsi OPTIONAL)
# The example plugins, each a CMake project of its own that builds against this prefix
# (find_package(tsi)): a model of the general class (van_der_pol), a Hamiltonian model (fput)
# and a scheme (expmid). tests/sdk builds and runs every one from here. A build directory
# left in the source tree stays out.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/plugins/ DESTINATION ${CMAKE_INSTALL_DATADIR}/tsi/examples/plugins
        REGEX "/build[^/]*$" EXCLUDE)
# The documents a plugin author works from, next to the headers they describe: the formulas
# and numbers (SPEC.md), writing a model or a scheme, and the plugin ABI.
install(FILES ${PROJECT_SOURCE_DIR}/docs/SPEC.md ${PROJECT_SOURCE_DIR}/docs/explanation/model-interface.md
              ${PROJECT_SOURCE_DIR}/docs/explanation/scheme-interface.md
              ${PROJECT_SOURCE_DIR}/docs/tutorials/model-plugin.md ${PROJECT_SOURCE_DIR}/docs/tutorials/scheme-plugin.md
              ${PROJECT_SOURCE_DIR}/docs/reference/plugin-abi.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR})

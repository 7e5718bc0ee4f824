# tsi_add_plugin(NAME SOURCES src... [OUTPUT_DIRECTORY dir] [INSTALL_DESTINATION dir] [NO_INSTALL])
#
# A tsi plugin: a MODULE library tsi_<NAME>.so (the runner loads tsi_*.so from a plugin
# directory), linked against tsi::core (which brings C++20, Eigen and nlohmann_json), with
# hidden visibility so that only the entry point TSI_PLUGIN exports, and undefined symbols
# refused at link time rather than at dlopen. The ABI stamp (plugin ABI version, tsi version,
# sizes and alignments of the exchanged structures) is recorded by TSI_PLUGIN at compile time.
#
# Works in the tsi tree (the shipped plugins: built into the build tree's plugin directory,
# installed next to the runner) and from an installed tsi (find_package(tsi): built into the
# current binary directory; `cmake --install` puts it under <prefix>/lib/tsi/plugins of the
# plugin's own project, a directory to name in TSI_PLUGIN_PATH).
include_guard(GLOBAL)
include(GNUInstallDirs)

function(tsi_add_plugin name)
  cmake_parse_arguments(ARG "NO_INSTALL" "OUTPUT_DIRECTORY;INSTALL_DESTINATION" "SOURCES" ${ARGN})
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "tsi_add_plugin(${name}): SOURCES is required")
  endif()
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "tsi_add_plugin(${name}): unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT TARGET tsi::core)
    message(FATAL_ERROR "tsi_add_plugin(${name}): tsi::core is not known (find_package(tsi) first)")
  endif()
  get_target_property(core_imported tsi::core IMPORTED)  # installed tsi, or the tsi tree

  set(target tsi_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE tsi::core)
  set_target_properties(${target} PROPERTIES PREFIX "" OUTPUT_NAME tsi_${name}
                        CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON
                        POSITION_INDEPENDENT_CODE ON)
  # (not in the fuzzing build: clang's sanitizer runtime is in the executable, not the plugin)
  if(CMAKE_SYSTEM_NAME STREQUAL "Linux" AND NOT TSI_BUILD_FUZZERS)
    target_link_options(${target} PRIVATE "LINKER:--no-undefined")
  endif()
  # sqrt and friends need not set errno (nothing reads it), so loops over tau points that
  # call them can be vectorised: the charged particle's field is 13% faster.
  target_compile_options(${target} PRIVATE $<$<AND:$<COMPILE_LANGUAGE:CXX>,$<CXX_COMPILER_ID:GNU,Clang>>:-fno-math-errno>)

  if(ARG_OUTPUT_DIRECTORY)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY})
  elseif(NOT core_imported AND DEFINED TSI_PLUGIN_OUTPUT_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${TSI_PLUGIN_OUTPUT_DIR})
    if(TARGET tsi_plugins)  # the shipped plugins, which the runner's tests need built
      add_dependencies(tsi_plugins ${target})
    endif()
  endif()

  if(ARG_INSTALL_DESTINATION)
    set(destination ${ARG_INSTALL_DESTINATION})
  elseif(DEFINED TSI_INSTALL_PLUGIN_DIR)
    set(destination ${TSI_INSTALL_PLUGIN_DIR})
  else()
    set(destination ${CMAKE_INSTALL_LIBDIR}/tsi/plugins)
  endif()
  if(core_imported)
    # Find the installed libtsi_core wherever the plugin is installed to.
    set_target_properties(${target} PROPERTIES INSTALL_RPATH_USE_LINK_PATH ON)
  else()
    # Shipped plugins: libtsi_core relative to the plugin directory, no LD_LIBRARY_PATH.
    file(RELATIVE_PATH to_libdir /prefix/${destination} /prefix/${CMAKE_INSTALL_LIBDIR})
    set_target_properties(${target} PROPERTIES INSTALL_RPATH "$ORIGIN/${to_libdir}")
  endif()
  if(NOT ARG_NO_INSTALL)
    install(TARGETS ${target} LIBRARY DESTINATION ${destination})
  endif()

  if(COMMAND tsi_set_warnings)
    tsi_set_warnings(${target})
  endif()
endfunction()

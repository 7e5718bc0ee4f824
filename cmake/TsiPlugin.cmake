# tsi_add_plugin(NAME SOURCES src...): a tsi plugin, built as a MODULE library named
# tsi_<NAME>.so in the plugin directory, linked against tsi::core, hidden visibility so
# that only the entry point (TSI_PLUGIN) is exported.
function(tsi_add_plugin name)
  cmake_parse_arguments(ARG "" "OUTPUT_DIRECTORY" "SOURCES" ${ARGN})
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "tsi_add_plugin(${name}): SOURCES is required")
  endif()
  set(target tsi_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE tsi::core)
  set_target_properties(${target} PROPERTIES PREFIX "" OUTPUT_NAME tsi_${name}
                        CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  if(ARG_OUTPUT_DIRECTORY)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY})
  elseif(DEFINED TSI_PLUGIN_OUTPUT_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${TSI_PLUGIN_OUTPUT_DIR})
    if(TARGET tsi_plugins)  # the shipped plugins, which the runner's tests need built
      add_dependencies(tsi_plugins ${target})
    endif()
  endif()
  if(COMMAND tsi_set_warnings)
    tsi_set_warnings(${target})
  endif()
endfunction()

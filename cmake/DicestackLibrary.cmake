# dicestack_add_library(<folder> SOURCES <files>... [PUBLIC <deps>...] [PRIVATE <deps>...])
# One library target per top-level folder (STYLE 1, 12): dicestack_<folder>, aliased
# dicestack::<folder>, C++20 without extensions, its include/ as the public surface, our
# warnings privately, installed into the exported package.
function(dicestack_add_library folder)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  set(target dicestack_${folder})
  add_library(${target} ${ARG_SOURCES})
  add_library(dicestack::${folder} ALIAS ${target})
  set_target_properties(${target} PROPERTIES
    EXPORT_NAME ${folder} OUTPUT_NAME ${target} CXX_EXTENSIONS OFF
    VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR})
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE} $<BUILD_INTERFACE:dicestack_warnings>
                        $<BUILD_INTERFACE:dicestack_determinism>)
  install(TARGETS ${target} EXPORT dicestackTargets
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# dicestack_add_library(<name> [DIR <folder>] SOURCES <files>... [PUBLIC <deps>...] [PRIVATE <deps>...])
# One library target (STYLE 1, 12): dicestack_<name>, aliased dicestack::<name>, C++20 without
# extensions, <folder>/include as its public surface (<folder> defaults to the current source
# folder; the SOURCES are relative to it), our warnings and determinism flags privately,
# installed into the exported package. A top-level folder may hold several such targets, each
# in its own sub-folder (core/: foundation, world, experts, baselines, render).
#
# Every shared library is linked with --no-undefined: a target that uses a symbol of a library
# it does not link fails at its own link, so "links only what it uses" is checked, not hoped.
# (Not in the sanitizer and fuzzing builds, whose runtimes the shared libraries leave undefined.)
function(dicestack_add_library name)
  cmake_parse_arguments(ARG "" "DIR" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  set(dir ${CMAKE_CURRENT_SOURCE_DIR})
  if(ARG_DIR)
    set(dir ${CMAKE_CURRENT_SOURCE_DIR}/${ARG_DIR})
  endif()
  list(TRANSFORM ARG_SOURCES PREPEND ${dir}/)
  set(target dicestack_${name})
  add_library(${target} ${ARG_SOURCES})
  add_library(dicestack::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES
    EXPORT_NAME ${name} OUTPUT_NAME ${target} CXX_EXTENSIONS OFF
    VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR})
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${dir}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE} $<BUILD_INTERFACE:dicestack_warnings>
                        $<BUILD_INTERFACE:dicestack_determinism>)
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "SHARED_LIBRARY" AND NOT DICESTACK_SANITIZE AND NOT DICESTACK_FUZZ)
    target_link_options(${target} PRIVATE LINKER:--no-undefined)
  endif()
  install(TARGETS ${target} EXPORT dicestackTargets
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY ${dir}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# dicestack_add_umbrella(<name> <targets>...)
# An INTERFACE target dicestack::<name> that links `targets`: the name a folder had before it
# was split, kept so that find_package(dicestack) users linking it see no change.
function(dicestack_add_umbrella name)
  set(target dicestack_${name})
  add_library(${target} INTERFACE)
  add_library(dicestack::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  target_link_libraries(${target} INTERFACE ${ARGN})
  install(TARGETS ${target} EXPORT dicestackTargets)
endfunction()

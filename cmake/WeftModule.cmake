# weft_add_module(NAME <name> [DEPENDS <targets...>] [PRIVATE_DEPENDS <targets...>])
#
# One library per module folder: public headers in <name>/include/weft/<name>/, sources and
# internal headers in <name>/src/. Creates target weft_<name> with alias weft::<name>.
#
# With WEFT_INSTALL on, the library is installed with its own export set weft-<name>-targets (as
# weft::<name>) and its include/ tree is installed as is; see cmake/WeftInstall.cmake. The
# weft_<name>_internal targets stay out of every export: they expose src/ for the tests only.
include(GNUInstallDirs)  # CMAKE_INSTALL_LIBDIR, CMAKE_INSTALL_INCLUDEDIR for the install rules

function(weft_add_module)
  cmake_parse_arguments(ARG "" "NAME" "DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  set(target weft_${ARG_NAME})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS
       ${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp)
  file(GLOB_RECURSE headers CONFIGURE_DEPENDS
       ${CMAKE_CURRENT_SOURCE_DIR}/include/*.h ${CMAKE_CURRENT_SOURCE_DIR}/src/*.h)
  if(NOT sources)
    # A header-only module (so far): an interface library with the same name and alias.
    add_library(${target} INTERFACE)
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_NAME})
    target_include_directories(${target} INTERFACE
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} INTERFACE ${ARG_DEPENDS})
    target_compile_features(${target} INTERFACE cxx_std_20)
  else()
    add_library(${target} ${sources} ${headers})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_NAME} OUTPUT_NAME weft_${ARG_NAME})
    target_include_directories(${target}
      PUBLIC  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
              $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
      PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
    target_link_libraries(${target} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS})
    # The public headers use C++20 (std::span, defaulted comparisons): say so on the target, so a
    # project that links weft::<name> compiles them as C++20 whatever its own default.
    target_compile_features(${target} PUBLIC cxx_std_20)
    weft_set_warnings(${target})
  endif()
  add_library(weft::${ARG_NAME} ALIAS ${target})
  if(WEFT_INSTALL)
    weft_install_module(${ARG_NAME} ${CMAKE_CURRENT_SOURCE_DIR}/include)
  endif()
  # Tests reach a module's internals (pure math kernels tested alone) through this interface target.
  add_library(weft_${ARG_NAME}_internal INTERFACE)
  target_include_directories(weft_${ARG_NAME}_internal INTERFACE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(weft_${ARG_NAME}_internal INTERFACE ${target})
endfunction()

# Installs module <name>: library weft_<name> into its own export set weft-<name>-targets, and
# its public header tree. One export set per module lets WeftConfig.cmake load weft::render only
# when its GL and PNG dependencies are there, so a game that uses the engine alone needs no GL
# packages. Headers are copied by directory (not FILE_SET) so CMake 3.22 still works.
function(weft_install_module name include_dir)
  install(TARGETS weft_${name} EXPORT weft-${name}-targets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY ${include_dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.h")
  # WeftInstall.cmake installs one export file per module, in this (dependency) order.
  set_property(GLOBAL APPEND PROPERTY WEFT_INSTALLED_MODULES ${name})
endfunction()

function(weft_set_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra)
    if(WEFT_WERROR)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
  if(WEFT_SANITIZE)
    # PUBLIC, so every executable that links a module is instrumented and linked the same way.
    set(sanitizers ${WEFT_SANITIZE})
    if(WEFT_SANITIZE MATCHES "undefined" AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # GCC leaves float-to-integer overflow out of -fsanitize=undefined (clang includes it);
      # a NaN or huge coordinate cast to a grid cell or bucket index is exactly the UB to catch.
      string(APPEND sanitizers ",float-cast-overflow")
    endif()
    # -fno-sanitize-recover=all: the first report aborts, so a finding fails its test instead of
    # scrolling past in the log of a test that passes.
    target_compile_options(${target} PUBLIC -fsanitize=${sanitizers} -fno-sanitize-recover=all
                                            -fno-omit-frame-pointer)
    target_link_options(${target} PUBLIC -fsanitize=${sanitizers})
  endif()
endfunction()

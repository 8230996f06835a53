# weft_add_module(NAME <name> [DEPENDS <targets...>] [PRIVATE_DEPENDS <targets...>])
#
# One library per module folder: public headers in <name>/include/weft/<name>/, sources and
# internal headers in <name>/src/. Creates target weft_<name> with alias weft::<name>.
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
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>)
    target_link_libraries(${target} INTERFACE ${ARG_DEPENDS})
  else()
    add_library(${target} ${sources} ${headers})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_NAME} OUTPUT_NAME weft_${ARG_NAME})
    target_include_directories(${target}
      PUBLIC  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>
      PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
    target_link_libraries(${target} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS})
    weft_set_warnings(${target})
  endif()
  add_library(weft::${ARG_NAME} ALIAS ${target})
  # Tests reach a module's internals (pure math kernels tested alone) through this interface target.
  add_library(weft_${ARG_NAME}_internal INTERFACE)
  target_include_directories(weft_${ARG_NAME}_internal INTERFACE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(weft_${ARG_NAME}_internal INTERFACE ${target})
endfunction()

function(weft_set_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra)
    if(WEFT_WERROR)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
  if(WEFT_SANITIZE)
    target_compile_options(${target} PUBLIC -fsanitize=${WEFT_SANITIZE} -fno-omit-frame-pointer)
    target_link_options(${target} PUBLIC -fsanitize=${WEFT_SANITIZE})
  endif()
endfunction()

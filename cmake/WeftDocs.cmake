# The API reference: target `docs` runs Doxygen over the public headers (*/include/weft/**) into
# <build>/docs/reference/html. Defined only when Doxygen is found (Debian: apt-get install doxygen).
# Doxygen's warnings fail the target (docs/Doxyfile.in: WARN_AS_ERROR), and with tests on, the
# test docs.reference builds the reference too, so CI keeps it warning-free.
find_package(Doxygen QUIET)
if(NOT DOXYGEN_FOUND)
  message(STATUS "Doxygen not found: no `docs` target (apt-get install doxygen to get it)")
  return()
endif()

set(WEFT_DOCS_OUTPUT ${CMAKE_BINARY_DIR}/docs/reference)
set(WEFT_DOCS_INCLUDE_ROOTS "")
foreach(module threading collision engine render scenes)
  set(root ${PROJECT_SOURCE_DIR}/${module}/include)
  if(EXISTS ${root})
    string(APPEND WEFT_DOCS_INCLUDE_ROOTS " \"${root}\"")
  endif()
endforeach()
set(WEFT_DOCS_INPUT "${WEFT_DOCS_INCLUDE_ROOTS} \"${PROJECT_SOURCE_DIR}/docs/reference.md\"")
configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${CMAKE_BINARY_DIR}/docs/Doxyfile @ONLY)

# Always runs (a few seconds): Doxygen's exit status is the verdict, so no stale reference passes.
add_custom_target(docs
  COMMAND ${CMAKE_COMMAND} -E make_directory ${WEFT_DOCS_OUTPUT}
  COMMAND Doxygen::doxygen ${CMAKE_BINARY_DIR}/docs/Doxyfile
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
  COMMENT "Doxygen: API reference in ${WEFT_DOCS_OUTPUT}/html (a warning fails the build)"
  VERBATIM)

if(WEFT_BUILD_TESTS)
  # The reference builds without a warning.
  add_test(NAME docs.reference COMMAND Doxygen::doxygen ${CMAKE_BINARY_DIR}/docs/Doxyfile
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(docs.reference PROPERTIES LABELS docs TIMEOUT 300)
endif()

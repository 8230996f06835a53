# Install rules of the package: the per-module export files and a generated WeftConfig.cmake and
# WeftConfigVersion.cmake in <prefix>/lib/cmake/Weft, so that a game can write
#   find_package(Weft 0.1 REQUIRED)   and link   weft::engine
# Included by the top-level CMakeLists after every module exists (WEFT_INSTALL on). The libraries
# and headers themselves are installed by weft_add_module (cmake/WeftModule.cmake).
include(CMakePackageConfigHelpers)

set(WEFT_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/Weft CACHE STRING
    "Where WeftConfig.cmake is installed, relative to the install prefix")

# Modules in the order they were added, which is their dependency order: the config includes
# their export files in this order, so each finds the weft:: targets it refers to.
get_property(WEFT_INSTALLED_MODULES GLOBAL PROPERTY WEFT_INSTALLED_MODULES)
foreach(module IN LISTS WEFT_INSTALLED_MODULES)
  install(EXPORT weft-${module}-targets
          NAMESPACE weft::
          FILE weft-${module}-targets.cmake
          DESTINATION ${WEFT_INSTALL_CMAKEDIR})
endforeach()

configure_package_config_file(
  ${CMAKE_CURRENT_LIST_DIR}/WeftConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/WeftConfig.cmake
  INSTALL_DESTINATION ${WEFT_INSTALL_CMAKEDIR})
# Before 1.0 a minor version may change the API, so only the same major.minor is compatible.
write_basic_package_version_file(
  ${CMAKE_CURRENT_BINARY_DIR}/WeftConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/WeftConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/WeftConfigVersion.cmake
        DESTINATION ${WEFT_INSTALL_CMAKEDIR})

# Warnings for the project's own code (not for third-party headers, which are SYSTEM).
function(mrsnake_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-deprecated-copy)
endfunction()

# A module library: mrsnake_add_library(mesh SOURCES ... DEPS ...)
function(mrsnake_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(mrsnake_${name} STATIC ${ARG_SOURCES})
  target_include_directories(mrsnake_${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(mrsnake_${name} PUBLIC ${ARG_DEPS})
  mrsnake_warnings(mrsnake_${name})
endfunction()

# The ITK side of a module: a separate static library whose include path holds ITK's
# (and so ITK's bundled Eigen). Its headers must expose only plain types.
function(mrsnake_add_itk_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(mrsnake_${name} STATIC ${ARG_SOURCES})
  target_include_directories(mrsnake_${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_include_directories(mrsnake_${name} SYSTEM PRIVATE ${ITK_INCLUDE_DIRS})
  target_link_libraries(mrsnake_${name} PRIVATE ${ITK_LIBRARIES} PUBLIC ${ARG_DEPS})
  mrsnake_warnings(mrsnake_${name})
  if(MRSNAKE_SANITIZE)
    # ITK 5.2's neighborhood iterators offset a null pointer in their headers
    # (itkConstNeighborhoodIterator.hxx:705): an upstream defect, harmless in practice.
    target_compile_options(mrsnake_${name} PRIVATE -fno-sanitize=pointer-overflow)
  endif()
endfunction()

# A GoogleTest executable registered with ctest.
function(mrsnake_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  mrsnake_warnings(${name})
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
    PROPERTIES ENVIRONMENT "MRSNAKE_BIN=$<TARGET_FILE:mrsnake>")
endfunction()

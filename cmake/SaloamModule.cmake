# saloam_module(NAME DEPS ...): a static library saloam_<NAME> built from every
# .cpp in the calling folder. Headers are included as "saloam/<NAME>/x.hpp".
function(saloam_module name)
  cmake_parse_arguments(ARG "" "" "DEPS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  if(NOT sources)  # header-only (or not yet written) module
    add_library(saloam_${name} INTERFACE)
    target_include_directories(saloam_${name} INTERFACE ${PROJECT_SOURCE_DIR}/src)
    target_link_libraries(saloam_${name} INTERFACE ${ARG_DEPS})
    add_library(saloam::${name} ALIAS saloam_${name})
    return()
  endif()
  add_library(saloam_${name} STATIC ${sources})
  target_include_directories(saloam_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(saloam_${name} PUBLIC ${ARG_DEPS})
  saloam_warnings(saloam_${name})
  add_library(saloam::${name} ALIAS saloam_${name})
endfunction()

function(saloam_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  if(SALOAM_NATIVE)
    target_compile_options(${target} PRIVATE -march=native)
  endif()
endfunction()

# saloam_test(MODULE LIBS ...): one GoogleTest executable per module from
# tests/<MODULE>/*_test.cpp, registered with CTest test by test and labelled
# MODULE. Tests whose body starts with SALOAM_REQUIRE_SHARED_DATA() (they need
# ../shared) are labelled shared-data as well: `ctest -LE shared-data` leaves
# them out, `ctest -L shared-data` runs only them.
function(saloam_test module)
  cmake_parse_arguments(ARG "" "" "LIBS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${module}/*_test.cpp)
  if(NOT sources)
    return()
  endif()
  set(target saloam_${module}_tests)
  add_executable(${target} ${sources})
  target_link_libraries(${target} PRIVATE ${ARG_LIBS} saloam_testing GTest::gtest GTest::gtest_main)
  saloam_warnings(${target})

  # A GoogleTest filter naming the shared-data tests: "TEST(Suite, Name) {"
  # (or TEST_F, TEST_P) directly followed by SALOAM_REQUIRE_SHARED_DATA().
  # The sources are configure dependencies so that the filter follows edits.
  set(ws "[ \t\r\n]*")
  set(id "[A-Za-z0-9_]+")
  set(test_start "TEST(_F|_P)?\\(${ws}(${id})${ws},${ws}(${id})${ws}\\)${ws}{${ws}")
  set(shared_filter "")
  foreach(source ${sources})
    file(READ ${source} text)
    string(REGEX MATCHALL "${test_start}SALOAM_REQUIRE_SHARED_DATA\\(" found "${text}")
    foreach(match ${found})
      string(REGEX REPLACE "^${test_start}.*" "\\2.\\3" name "${match}")
      if(match MATCHES "^TEST_P")
        set(name "*/${name}/*")  # Instantiation/Suite.Name/Parameter
      endif()
      list(APPEND shared_filter ${name})
    endforeach()
  endforeach()
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${sources})

  # Every test runs with SALOAM_TEST_SHARED_DATA_LABEL=1 (labelled shared-data)
  # or 0: check_shared_data() fails a test that declares the need but was not
  # labelled, so label and declaration cannot drift apart.
  set(other_filter "")
  if(shared_filter)
    list(JOIN shared_filter ":" shared_filter)
    set(other_filter "-${shared_filter}")
    gtest_discover_tests(${target} DISCOVERY_TIMEOUT 60 TEST_FILTER "${shared_filter}" TEST_LIST ${target}_SHARED_DATA
                         PROPERTIES LABELS ${module} ENVIRONMENT SALOAM_TEST_SHARED_DATA_LABEL=1)
    # gtest_discover_tests passes properties one value each, so the second
    # label comes from a script CTest includes after the discovered tests.
    set(labels_script ${CMAKE_CURRENT_BINARY_DIR}/${target}_shared_data_labels.cmake)
    file(WRITE ${labels_script} "if(${target}_SHARED_DATA)\n"
                                "  set_tests_properties(\${${target}_SHARED_DATA} PROPERTIES LABELS \"${module};shared-data\")\n"
                                "endif()\n")
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${labels_script})
  endif()
  gtest_discover_tests(${target} DISCOVERY_TIMEOUT 60 TEST_FILTER "${other_filter}"
                       PROPERTIES LABELS ${module} ENVIRONMENT SALOAM_TEST_SHARED_DATA_LABEL=0)
endfunction()

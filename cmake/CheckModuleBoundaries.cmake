# The module boundaries as a test (CTest `module_boundaries`; run it alone
# with `cmake -DSOURCE_DIR=<repo> -P cmake/CheckModuleBoundaries.cmake`).
# A module is a folder src/saloam/<name>/ built by saloam_module(<name> DEPS
# ...); its sources (and its subfolders') may include its own headers and
# those of the modules it declares in DEPS (saloam_<dep>), nothing else of
# src/saloam/: a module that includes a header of one it does not declare
# fails here, naming the file, the line and the missing dependency. Through
# the declared dependencies' own dependencies a header may compile, but the
# dependency graph in the CMakeLists.txt is the architecture
# (docs/architecture.md), so every edge must be written there.
cmake_minimum_required(VERSION 3.20)
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "give -DSOURCE_DIR=<the repository>")
endif()
file(GLOB module_dirs LIST_DIRECTORIES true "${SOURCE_DIR}/src/saloam/*")
set(violations 0)
set(checked 0)
foreach(dir IN LISTS module_dirs)
  if(NOT IS_DIRECTORY "${dir}" OR NOT EXISTS "${dir}/CMakeLists.txt")
    continue()
  endif()
  get_filename_component(module "${dir}" NAME)
  # The dependencies the module (and its subfolders) declare: saloam_<x>.
  file(GLOB_RECURSE cmake_files "${dir}/CMakeLists.txt")
  set(allowed "${module}")
  foreach(cmake_file IN LISTS cmake_files)
    file(READ "${cmake_file}" text)
    string(REGEX REPLACE "#[^\n]*" "" text "${text}")  # comments name modules too
    string(REGEX MATCHALL "saloam_[a-z_]+" names "${text}")
    foreach(name IN LISTS names)
      string(REGEX REPLACE "^saloam_" "" name "${name}")
      list(APPEND allowed "${name}")
    endforeach()
  endforeach()
  file(GLOB_RECURSE sources "${dir}/*.hpp" "${dir}/*.cpp" "${dir}/*.h")
  foreach(source IN LISTS sources)
    math(EXPR checked "${checked} + 1")
    file(STRINGS "${source}" includes REGEX "^[ \t]*#[ \t]*include[ \t]*\"saloam/[a-z_]+/")
    foreach(line IN LISTS includes)
      string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"saloam/([a-z_]+)/.*$" "\\1" used "${line}")
      if(NOT used IN_LIST allowed)
        file(RELATIVE_PATH relative "${SOURCE_DIR}" "${source}")
        message(SEND_ERROR "${relative}: ${line}: module ${module} does not declare saloam_${used} "
                           "(src/saloam/${module}/CMakeLists.txt)")
        math(EXPR violations "${violations} + 1")
      endif()
    endforeach()
  endforeach()
endforeach()
if(checked EQUAL 0)
  message(FATAL_ERROR "no module sources found under ${SOURCE_DIR}/src/saloam")
endif()
if(violations GREATER 0)
  message(FATAL_ERROR "${violations} include(s) cross a module boundary not declared")
endif()
message(STATUS "module boundaries: ${checked} files, every include of another module declared")

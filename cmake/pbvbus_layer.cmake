# Common compile settings for every pbvbus target.
add_library(pbvbus_options INTERFACE)
target_compile_options(pbvbus_options INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
  -Wno-sign-conversion)
if(PBVBUS_WERROR)
  target_compile_options(pbvbus_options INTERFACE -Werror)
endif()
if(PBVBUS_SANITIZE)
  target_compile_options(pbvbus_options INTERFACE -fsanitize=${PBVBUS_SANITIZE} -fno-omit-frame-pointer
    -fno-sanitize-recover=all)
  target_link_options(pbvbus_options INTERFACE -fsanitize=${PBVBUS_SANITIZE})
endif()

# Several sources of a library in one compilation (PBVBUS_UNITY_BUILD): their common headers are
# parsed, and the templates they use instantiated and compiled, once per batch instead of once
# per file. Batches of 16 took a quarter less CPU time than batches of 8 for a first build
# (docs/benchmarks.md "First run"); 0 puts each library in one batch, which the clang build uses
# so that a name clash between any two files of a folder shows up there whatever the batches.
set(PBVBUS_UNITY_BATCH_SIZE 16 CACHE STRING "Sources per unity batch (0: the whole library)")
function(pbvbus_unity target)
  if(PBVBUS_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON
      UNITY_BUILD_BATCH_SIZE ${PBVBUS_UNITY_BATCH_SIZE})
  endif()
endfunction()

# Code that runs once per run or per command, never per frame (scenario planning, the command
# line, reports, GSD reading): -O1 in the optimised builds. gcc compiles it about a third faster;
# whole commands (plan, run 300 ms, report) measured within 3 % of -O2 (docs/benchmarks.md
# "First run").
function(pbvbus_cold_code target)
  target_compile_options(${target} PRIVATE $<$<CONFIG:RelWithDebInfo,Release>:-O1>)
endfunction()

# pbvbus_layer(NAME <name> [DEPS <targets...>])
# Sources are globbed from src/ so that adding a file needs no CMake edit; headers live in
# include/pbvbus/<name>/.
function(pbvbus_layer)
  cmake_parse_arguments(L "" "NAME" "DEPS" ${ARGN})
  file(GLOB_RECURSE _srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp)
  if(NOT _srcs)
    # A layer still being written: headers only for now.
    add_library(pbvbus_${L_NAME} INTERFACE)
    target_include_directories(pbvbus_${L_NAME} INTERFACE ${CMAKE_CURRENT_SOURCE_DIR}/include)
    target_link_libraries(pbvbus_${L_NAME} INTERFACE pbvbus_options ${L_DEPS})
    add_library(pbvbus::${L_NAME} ALIAS pbvbus_${L_NAME})
    return()
  endif()
  add_library(pbvbus_${L_NAME} STATIC ${_srcs})
  pbvbus_unity(pbvbus_${L_NAME})
  target_include_directories(pbvbus_${L_NAME} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(pbvbus_${L_NAME} PUBLIC pbvbus_options ${L_DEPS})
  add_library(pbvbus::${L_NAME} ALIAS pbvbus_${L_NAME})
endfunction()

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
  if(PBVBUS_UNITY_BUILD)
    # Several sources of a layer in one compilation: their common headers are parsed once per
    # batch instead of once per file (docs/benchmarks.md "Build and CI times").
    set_target_properties(pbvbus_${L_NAME} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endif()
  target_include_directories(pbvbus_${L_NAME} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(pbvbus_${L_NAME} PUBLIC pbvbus_options ${L_DEPS})
  add_library(pbvbus::${L_NAME} ALIAS pbvbus_${L_NAME})
endfunction()

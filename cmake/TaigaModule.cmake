# Compiler warnings shared by every target, as errors. Designated initializers that leave members
# at their defaults ({.scan_period_s = 0.1}) are intended, so missing-field-initializers is off;
# GCC 12 reports maybe-uninitialized falsely for moves of std::variant/optional at -O2 (GCC bug
# 105593 and relatives), so that one is off too (-Wuninitialized stays on).
function(taiga_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wno-missing-field-initializers -Werror)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
  endif()
endfunction()

# taiga_add_module(NAME DEPENDS <public deps> PRIVATE_DEPENDS <private deps>)
# Builds src/NAME/**/*.cpp into the library taiga_NAME with the alias taiga::NAME.
function(taiga_add_module name)
  cmake_parse_arguments(ARG "" "" "DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${name}/*.cpp)
  add_library(taiga_${name} ${sources})
  add_library(taiga::${name} ALIAS taiga_${name})
  target_include_directories(taiga_${name} PUBLIC ${PROJECT_SOURCE_DIR}/include)
  target_link_libraries(taiga_${name} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS})
  target_compile_features(taiga_${name} PUBLIC cxx_std_20)
  taiga_set_warnings(taiga_${name})
endfunction()

# taiga_add_test(MODULE NAME [LABELS ...]) builds tests/MODULE/NAME.cpp against taiga::MODULE.
function(taiga_add_test module name)
  cmake_parse_arguments(ARG "" "" "LABELS;DEPENDS" ${ARGN})
  add_executable(${name} ${name}.cpp)
  target_link_libraries(${name} PRIVATE taiga::${module} ${ARG_DEPENDS} GTest::gtest_main
                                        GTest::gmock)
  taiga_set_warnings(${name})
  # One label joined with '/' (e.g. "pipeline/long"): gtest_discover_tests keeps only the first
  # element of a list in PROPERTIES. ctest -L/-LE take regular expressions, so -L pipeline,
  # -L long and -LE long all see it.
  string(JOIN "/" label ${module} ${ARG_LABELS})
  gtest_discover_tests(${name} PROPERTIES LABELS ${label}
                       WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} DISCOVERY_TIMEOUT 60)
endfunction()

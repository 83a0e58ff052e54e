# Compiler flags shared by every nphand target.
add_library(nphand_flags INTERFACE)
target_compile_options(nphand_flags INTERFACE -Wall -Wextra)
if(NPHAND_WERROR)
  target_compile_options(nphand_flags INTERFACE -Werror)
endif()
if(NPHAND_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "NPHAND_FUZZ needs clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++")
  endif()
  target_compile_options(nphand_flags INTERFACE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(nphand_flags INTERFACE -fsanitize=address,undefined)
elseif(NPHAND_SANITIZE)
  target_compile_options(nphand_flags INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(nphand_flags INTERFACE -fsanitize=address,undefined)
endif()

# nphand_stage(NAME SOURCES ... DEPS ...): one pipeline stage as its own library target,
# nphand_NAME, installed and exported as nphand::NAME. The project's compile flags stay
# private to it (its link options still reach the build's own executables).
function(nphand_stage name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(nphand_${name} STATIC ${ARG_SOURCES})
  set_target_properties(nphand_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON EXPORT_NAME ${name})
  target_include_directories(nphand_${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
                             $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(nphand_${name} PUBLIC ${ARG_PUBLIC_DEPS}
                        PRIVATE $<BUILD_INTERFACE:nphand_flags> ${ARG_PRIVATE_DEPS})
  install(TARGETS nphand_${name} EXPORT nphandTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()

# nphand_test(STAGE UNIT): tests/STAGE/UNIT_test.cc registered in CTest as STAGE/UNIT_test.
function(nphand_test stage unit)
  set(target test_${stage}_${unit})
  add_executable(${target} ${unit}_test.cc)
  target_link_libraries(${target} PRIVATE nphand_flags nphand_testing ${ARGN})
  add_test(NAME ${stage}/${unit}_test COMMAND ${target})
endfunction()

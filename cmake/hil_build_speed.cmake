# How hil keeps its builds short on a 2-core machine (docs/ci.md has the
# measured effect of each): unity builds, one precompiled header of the
# heavy third-party headers that every test program reuses, and test
# programs compiled for a short build (tests/CMakeLists.txt).

option(HIL_UNITY_BUILD "Compile each library and program as one unity source" ON)
option(HIL_PRECOMPILED_HEADERS "Precompile GoogleTest, rapidcheck and the other heavy headers for the tests" ON)

# Unity builds: every target defined after this point compiles its sources
# as one. That shares one parse of Asio, CLI11, yaml-cpp and the standard
# library, which cost more than the code of most hil sources.
# The whole target is one batch, so two files of one target that define the
# same name in their anonymous namespaces always collide, whatever files are
# added later (docs/ci.md). GCC takes the sources a unity file includes for
# headers and warns when a class there holds a type of an anonymous
# namespace (-Wsubobject-linkage); within one target that is intended.
if(HIL_UNITY_BUILD)
  set(CMAKE_UNITY_BUILD ON)
  set(CMAKE_UNITY_BUILD_BATCH_SIZE 0)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(hil_warnings INTERFACE -Wno-subobject-linkage)
  endif()
endif()

# hil_reuse_test_pch(target): the test program compiles against the one
# precompiled header of hil_test_pch (tests/CMakeLists.txt). All targets in
# a tree share the compiler flags that matter to a PCH (standard, sanitizer
# and optimisation flags come from the tree, not the target).
function(hil_reuse_test_pch target)
  if(HIL_PRECOMPILED_HEADERS AND TARGET hil_test_pch)
    target_precompile_headers(${target} REUSE_FROM hil_test_pch)
  endif()
endfunction()

# The linker: mold when it is installed (ci/install-deps.sh installs it).
# It links the hil program in about 1.5 s against 4.9 s for GNU ld, and a
# tree has about 50 programs to link. HIL_LINKER=default keeps the
# compiler's own linker. lld is not offered: with GCC 12 its output aborts
# in the unwinder when some tests throw (docs/ci.md).
set(HIL_LINKER "auto" CACHE STRING "Linker for programs: auto (mold when found), mold or default")
set_property(CACHE HIL_LINKER PROPERTY STRINGS auto mold default)
if(HIL_LINKER STREQUAL "auto")
  find_program(HIL_MOLD ld.mold)
  if(HIL_MOLD)
    set(hil_linker mold)
  else()
    set(hil_linker default)
  endif()
elseif(HIL_LINKER MATCHES "^(mold|default)$")
  set(hil_linker ${HIL_LINKER})
else()
  message(FATAL_ERROR "HIL_LINKER is '${HIL_LINKER}'; it takes auto, mold or default")
endif()
if(hil_linker STREQUAL "mold")
  include(CheckLinkerFlag)
  check_linker_flag(CXX -fuse-ld=mold HIL_HAS_MOLD)
  if(NOT HIL_HAS_MOLD)
    message(FATAL_ERROR "HIL_LINKER=mold, but ${CMAKE_CXX_COMPILER} cannot link with -fuse-ld=mold")
  endif()
  add_link_options(-fuse-ld=mold)
endif()
message(STATUS "hil linker: ${hil_linker}")

# Compressed debug sections: every program's line tables are written
# zlib-compressed (gdb, llvm-symbolizer and the sanitizers read them). A
# tree's programs take about a third less disk (a test program: 23.0 MB
# against 15.1 MB) for no measurable link time; the full CI run holds three
# trees on one disk (docs/ci.md, "Disk").
option(HIL_COMPRESS_DEBUG_SECTIONS "Link programs with zlib-compressed debug sections" ON)
if(HIL_COMPRESS_DEBUG_SECTIONS)
  include(CheckLinkerFlag)
  check_linker_flag(CXX -Wl,--compress-debug-sections=zlib HIL_HAS_COMPRESS_DEBUG_SECTIONS)
  if(HIL_HAS_COMPRESS_DEBUG_SECTIONS)
    add_link_options(-Wl,--compress-debug-sections=zlib)
  endif()
endif()

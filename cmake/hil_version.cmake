# The version every program prints with --version: the project's version
# (project() in the top-level CMakeLists.txt, passed as HIL_VERSION) and the
# commit the tree was built from (HIL_SOURCE_COMMIT in the generated header
# hil_source_commit.h, apps/common/version.hpp).
#
# The commit is looked up on every build by the target hil_source_commit
# (cmake/hil_source_commit.cmake), which rewrites the header only when the
# text changes: a new HEAD or a tree that became dirty recompiles
# apps/common/version.cpp and relinks the programs, and nothing else.

set(HIL_SOURCE_COMMIT "" CACHE STRING
    "The commit --version names (empty: git describe --always --dirty at build time, or unknown)")

set(HIL_GENERATED_DIR ${CMAKE_BINARY_DIR}/generated)
set(HIL_SOURCE_COMMIT_HEADER ${HIL_GENERATED_DIR}/hil_source_commit.h)
add_custom_target(hil_source_commit
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
          -DOUTPUT=${HIL_SOURCE_COMMIT_HEADER} -DCOMMIT=${HIL_SOURCE_COMMIT}
          -P ${PROJECT_SOURCE_DIR}/cmake/hil_source_commit.cmake
  BYPRODUCTS ${HIL_SOURCE_COMMIT_HEADER}
  COMMENT "The source commit for --version"
  VERBATIM)
# Once at configure time as well, so the header exists before any build
# (editors and clang-tidy read it from compile_commands.json).
execute_process(COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
                        -DOUTPUT=${HIL_SOURCE_COMMIT_HEADER} -DCOMMIT=${HIL_SOURCE_COMMIT}
                        -P ${PROJECT_SOURCE_DIR}/cmake/hil_source_commit.cmake)

# Warnings every hil target is built with.
add_library(hil_warnings INTERFACE)
target_compile_options(hil_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
  -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual
  -Wdouble-promotion -Wimplicit-fallthrough)
add_library(hil::warnings ALIAS hil_warnings)
# GCC 12 reports std::string members of std::variant alternatives as "maybe
# uninitialized" when a variant is moved at -O2; the reports are false and
# bury real diagnostics, so GCC skips that one check; clang (every preset's
# compiler) still runs its own uninitialized checks.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(hil_warnings INTERFACE -Wno-maybe-uninitialized)
endif()

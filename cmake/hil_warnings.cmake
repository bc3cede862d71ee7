# Warnings every hil target is built with.
add_library(hil_warnings INTERFACE)
target_compile_options(hil_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
  -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual
  -Wdouble-promotion -Wimplicit-fallthrough)
add_library(hil::warnings ALIAS hil_warnings)

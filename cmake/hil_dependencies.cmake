# Every external dependency is a Debian package installed by ci/install-deps.sh.

# Standalone Asio is header-only and ships no CMake package.
find_path(ASIO_INCLUDE_DIR asio.hpp REQUIRED)
add_library(hil_asio INTERFACE)
target_include_directories(hil_asio SYSTEM INTERFACE ${ASIO_INCLUDE_DIR})
target_compile_definitions(hil_asio INTERFACE ASIO_STANDALONE ASIO_NO_DEPRECATED)
find_package(Threads REQUIRED)
target_link_libraries(hil_asio INTERFACE Threads::Threads)
add_library(hil::asio ALIAS hil_asio)

find_package(box2d 2.4 REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 2.1 REQUIRED)

if(HIL_BUILD_TESTS)
  find_package(GTest REQUIRED)
  find_package(rapidcheck REQUIRED)
  include(GoogleTest)
endif()

if(HIL_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

# simavr (libsimavr-dev) runs real AVR firmware on an emulated ATmega328P
# (mocks/avr/); it loads ELF files through libelf.
find_package(PkgConfig REQUIRED)
pkg_check_modules(SIMAVR REQUIRED simavr)
pkg_check_modules(LIBELF REQUIRED IMPORTED_TARGET libelf)
# Linked statically where hil's own libraries are static: calls into the
# emulator's core from hil's run loop (one per instruction) are about 15 %
# faster than through the shared library's PLT (docs/performance.md, "Real
# firmware"). Debian's libsimavr.a is not position-independent, so a tree of
# shared libraries (the sanitizer preset) links the shared one.
if(BUILD_SHARED_LIBS)
  find_library(HIL_SIMAVR_LIBRARY NAMES simavr REQUIRED)
else()
  find_library(HIL_SIMAVR_LIBRARY NAMES libsimavr.a REQUIRED)
endif()
add_library(hil_simavr INTERFACE)
target_include_directories(hil_simavr SYSTEM INTERFACE ${SIMAVR_INCLUDE_DIRS})
target_link_libraries(hil_simavr INTERFACE ${HIL_SIMAVR_LIBRARY} PkgConfig::LIBELF)
add_library(hil::simavr ALIAS hil_simavr)

# libtelnet (libtelnet-dev) is the Telnet layer under the RFC 2217 listener
# of the serial cars (link/rfc2217*): option negotiation and
# subnegotiation framing; the COM-PORT-OPTION commands are hil's own.
pkg_check_modules(LIBTELNET REQUIRED IMPORTED_TARGET libtelnet)

# pugixml (libpugixml-dev) reads the JUnit XML of the shards that
# `hil report merge` joins.
find_package(pugixml REQUIRED)

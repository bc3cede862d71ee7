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

# Installing hil, and the Debian package made from the install
# (docs/install.md): `cmake --build build --target package`, or
# `cpack -G DEB` in the build tree, writes hil_<version>_<arch>.deb.
#
#   /usr/bin/                    hil, logi-client, wr8-client, arduino-client, leka-client
#                                (their install() rules are in apps/)
#   /usr/share/hil/scenarios/    the scenario library with its fault profiles,
#                                worlds, behaviours, client scripts, captures,
#                                test sketch and schema.json, laid out as in
#                                the source tree, so the relative paths inside
#                                the scenario files still hold
#   /usr/share/man/man1/         a page per program, written by help2man from
#                                its --help and --version
#   /usr/share/doc/hil/          README.md and docs/install.md
#
# The programs link hil's own libraries statically in a tree of static
# libraries (the default preset); a tree of shared ones (the asan preset)
# installs programs without the libraries they need, so package the default
# tree.

include(GNUInstallDirs)

set(HIL_DATA_DESTINATION ${CMAKE_INSTALL_DATADIR}/hil)
set(HIL_CLIENT_PROGRAMS logi-client wr8-client arduino-client leka-client)

# The data the programs read at run time.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenarios/ DESTINATION ${HIL_DATA_DESTINATION}/scenarios)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/docs/install.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR})

# Whether this tree's programs are the ones to package: static hil
# libraries, no sanitizer (a sanitized program needs its runtime and, in
# the asan preset, the tree's shared libraries).
if(BUILD_SHARED_LIBS OR HIL_SANITIZE OR HIL_BUILD_FUZZ OR CMAKE_CXX_FLAGS MATCHES "-fsanitize")
  set(HIL_PACKAGE_TREE OFF)
else()
  set(HIL_PACKAGE_TREE ON)
endif()

# Man pages, section 1: help2man runs each program with --help and
# --version after each link (target hil_man_pages, part of the default
# build). Without help2man, and in a sanitized tree, the pages are left out
# of the install.
find_program(HIL_HELP2MAN help2man)
find_program(HIL_GZIP gzip)
set(HIL_MAN_DIR ${CMAKE_BINARY_DIR}/man)
set(hil_man_summary_hil "test harness and mock cars for robot-car client software")
set(hil_man_summary_logi-client "upper computer for the LOGI logistics car")
set(hil_man_summary_wr8-client "drive the WR8 vehicle over TCP")
set(hil_man_summary_arduino-client "steer the Arduino serial robot")
set(hil_man_summary_leka-client "send command groups to the Leka robot")
if(HIL_HELP2MAN AND HIL_GZIP AND HIL_PACKAGE_TREE)
  set(man_pages "")
  foreach(program hil ${HIL_CLIENT_PROGRAMS})
    set(page ${HIL_MAN_DIR}/${program}.1)
    add_custom_command(
      OUTPUT ${page}.gz
      COMMAND ${CMAKE_COMMAND} -E make_directory ${HIL_MAN_DIR}
      COMMAND ${HIL_HELP2MAN} --no-info --section=1 --name=${hil_man_summary_${program}}
              "--source=hil ${PROJECT_VERSION}" --output=${page} $<TARGET_FILE:${program}>
      # -n: no name or time stamp in the archive, the same bytes for the same page.
      COMMAND ${HIL_GZIP} -9nf ${page}
      DEPENDS ${program}
      COMMENT "Man page ${program}.1 (help2man)"
      VERBATIM)
    list(APPEND man_pages ${page}.gz)
  endforeach()
  add_custom_target(hil_man_pages ALL DEPENDS ${man_pages})
  install(FILES ${man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
elseif(HIL_PACKAGE_TREE)
  message(STATUS "help2man or gzip not found: no man pages (Debian package help2man)")
endif()

# The package.
execute_process(COMMAND dpkg --print-architecture OUTPUT_VARIABLE HIL_DEB_ARCH
                OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT HIL_DEB_ARCH)
  set(HIL_DEB_ARCH amd64)
endif()
set(HIL_PACKAGE_MAINTAINER "hil maintainers <hil-maintainers@example.org>"
    CACHE STRING "Maintainer field of the Debian package")
option(HIL_PACKAGE_STRIP "Strip the programs in the package (their line tables go too)" ON)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME hil)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "hil")
set(CPACK_PACKAGE_CONTACT "${HIL_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "hardware-in-the-loop harness and mock cars for robot-car clients")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ${HIL_PACKAGE_STRIP})
set(CPACK_DEBIAN_PACKAGE_NAME hil)
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${HIL_DEB_ARCH})
set(CPACK_DEBIAN_FILE_NAME hil_${PROJECT_VERSION}_${HIL_DEB_ARCH}.deb)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${HIL_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION devel)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# The long description under the summary line; cpack indents its lines as
# the control file wants them.
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "hil tests the client programs that drive small robot cars over TCP or a
serial line (the LOGI logistics car, the WR8 vehicle, an Arduino robot and
a Leka robot): mock cars that answer as the firmware does, with a simulated
arena and a live view; YAML scenarios run against a client with JUnit XML
and HTML reports; a fault-injecting proxy; protocol encoders and decoders;
and the four reference client programs. The scenario library, fault
profiles and worlds are in /usr/share/hil/scenarios.")
# dpkg-shlibdeps names the packages of the shared libraries the programs
# link (Box2D, yaml-cpp, ncurses, libelf, libtelnet, pugixml, the C++
# runtime); it cannot see what hil starts: the AVR toolchain and the
# Arduino core behind `hil firmware build` and `hil mock arduino --sketch`.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "gcc-avr, avr-libc, arduino-core-avr, arduino-mk")
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS OFF)
# `package_source`: the source tree without .git and the build trees.
set(CPACK_SOURCE_IGNORE_FILES "/\\\\.git/" "/build[^/]*/" "/\\\\.cache/")
include(CPack)

# SPDX-License-Identifier: GPL-2.0-or-later
# Debian package of dissgen, included from the top CMakeLists.txt.
#
#   cmake --build build --target package        # or: cd build && cpack -G DEB
#
# gives build/dissgen_<version>-1_<arch>.deb with
#   /usr/bin/dissgen
#   /usr/share/dissgen/runtime/    plugin runtime + compatibility header (for `dissgen install`)
#   /usr/share/dissgen/rules/      the shipped rule files
#   <Wireshark's global plugin folder>/epan/dissgen-packaged-<stem>.so
#                                  a plugin per shipped rule file (rules/ethercat.xml)
#   /usr/share/man/man1/dissgen.1.gz
#
# The packaged plugins are called dissgen-packaged-<stem>.so, a name that
# `dissgen install` (always dissgen_<stem>.so) never produces: a user's own
# build of the same rules is then a different file, which Wireshark loads too;
# per-user plugins register first, so the user's copy takes the protocol and
# the packaged one steps aside (see "Packaged plugins" in dissgen.1).

include(GNUInstallDirs)

# --- the plugins of the shipped rules, into Wireshark's global plugin folder --
pkg_get_variable(WIRESHARK_PLUGINDIR wireshark plugindir)
set(DISSGEN_WIRESHARK_PLUGIN_DIR "${WIRESHARK_PLUGINDIR}/epan" CACHE PATH
    "Wireshark's global folder for dissector plugins (pkg-config --variable=plugindir wireshark + /epan)")
set(DISSGEN_PACKAGED_PLUGIN_PREFIX "dissgen-packaged-")

foreach(rule_file ${shipped_rules})
  get_filename_component(stem "${rule_file}" NAME_WE)
  string(REGEX REPLACE "[^A-Za-z0-9_-]" "_" stem "${stem}")
  set(packaged_name ${DISSGEN_PACKAGED_PLUGIN_PREFIX}${stem}.so)
  install(FILES $<TARGET_FILE:dissgen_${stem}> DESTINATION ${DISSGEN_WIRESHARK_PLUGIN_DIR}
          RENAME ${packaged_name}
          PERMISSIONS OWNER_READ OWNER_WRITE GROUP_READ WORLD_READ)
  # install(FILES) is not stripped by `cmake --install --strip` / CPACK_STRIP_FILES.
  install(CODE "
    if(CMAKE_INSTALL_DO_STRIP)
      execute_process(COMMAND \"${CMAKE_STRIP}\" --strip-unneeded
                      \"\$ENV{DESTDIR}${DISSGEN_WIRESHARK_PLUGIN_DIR}/${packaged_name}\")
    endif()")
endforeach()

# --- man page and README, gzipped as Debian wants them -----------------------------
find_program(GZIP_PROGRAM gzip)
function(dissgen_install_gzipped file destination)
  get_filename_component(name "${file}" NAME)
  if(NOT GZIP_PROGRAM)
    install(FILES ${file} DESTINATION ${destination})
    return()
  endif()
  set(gz ${CMAKE_BINARY_DIR}/packaging/${name}.gz)
  add_custom_command(OUTPUT ${gz}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/packaging
    COMMAND sh -c "'${GZIP_PROGRAM}' -9 -n -c '${file}' > '${gz}'"
    DEPENDS ${file}
    COMMENT "Compressing ${name}"
    VERBATIM)
  string(MAKE_C_IDENTIFIER "dissgen_gz_${name}" target)
  add_custom_target(${target} ALL DEPENDS ${gz})
  install(FILES ${gz} DESTINATION ${destination})
endfunction()
dissgen_install_gzipped(${CMAKE_CURRENT_LIST_DIR}/dissgen.1 ${CMAKE_INSTALL_MANDIR}/man1)
dissgen_install_gzipped(${CMAKE_SOURCE_DIR}/README.md ${CMAKE_INSTALL_DOCDIR})

# The Maintainer field names whoever builds and distributes the package: set
# DISSGEN_PACKAGE_MAINTAINER, or DEBFULLNAME and DEBEMAIL as for any Debian
# packaging. The project has no mail address yet: the default says so with a
# reserved .invalid domain (RFC 2606; a well-formed address that never delivers).
if(DEFINED ENV{DEBFULLNAME} AND DEFINED ENV{DEBEMAIL})
  set(maintainer_default "$ENV{DEBFULLNAME} <$ENV{DEBEMAIL}>")
else()
  set(maintainer_default "dissgen developers <maintainers@dissgen.invalid>")
endif()
set(DISSGEN_PACKAGE_MAINTAINER "${maintainer_default}" CACHE STRING
    "Maintainer of the Debian package: \"Name <address>\"")

# Debian's changelog, and the machine-readable copyright file (DEP-5; the
# licence itself is LICENSE, the GPL version 2 text).
string(TIMESTAMP changelog_date "%a, %d %b %Y %H:%M:%S +0000" UTC)   # honours SOURCE_DATE_EPOCH
configure_file(${CMAKE_CURRENT_LIST_DIR}/changelog.Debian.in
               ${CMAKE_BINARY_DIR}/packaging/changelog.Debian @ONLY)
dissgen_install_gzipped(${CMAKE_BINARY_DIR}/packaging/changelog.Debian ${CMAKE_INSTALL_DOCDIR})
install(FILES ${CMAKE_CURRENT_LIST_DIR}/copyright DESTINATION ${CMAKE_INSTALL_DOCDIR})

# --- package metadata ------------------------------------------------------------
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME dissgen)
set(CPACK_PACKAGE_VENDOR "dissgen developers")
set(CPACK_PACKAGE_CONTACT "${DISSGEN_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Wireshark dissector plugins from XML protocol rules")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_STRIP_FILES TRUE)
# Absolute destinations (the Wireshark plugin folder) must land in the staging area.
set(CPACK_SET_DESTDIR ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)

# (`package_source`: the sources without build trees or Git data.)
set(CPACK_SOURCE_IGNORE_FILES "/\\.git/" "/build[^/]*/" "__pycache__")

set(CPACK_DEBIAN_PACKAGE_RELEASE 1)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION devel)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${CPACK_PACKAGE_CONTACT}")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)

# Depends: the plugins are only loaded by the Wireshark major.minor they were
# built against, so the libwireshark package is bounded to that minor release.
# Its name (libwireshark16 on bookworm) is the package owning the library the
# build links (dpkg -S), not a guess.
string(REGEX MATCH "^([0-9]+)\\.([0-9]+)" _ "${WIRESHARK_VERSION}")
set(ws_major ${CMAKE_MATCH_1})
set(ws_minor ${CMAKE_MATCH_2})
math(EXPR ws_next_minor "${ws_minor} + 1")
set(ws_lower "${ws_major}.${ws_minor}")
set(ws_upper "${ws_major}.${ws_next_minor}")

pkg_get_variable(WIRESHARK_LIBDIR wireshark libdir)
find_program(DPKG_PROGRAM dpkg)
# dissgen_library_package(LIB VAR): the Debian package owning LIB (libwireshark ->
# the file libwireshark.so points to -> dpkg -S), else a name from its SONAME.
function(dissgen_library_package lib var)
  get_filename_component(real "${WIRESHARK_LIBDIR}/${lib}.so" REALPATH)
  if(DPKG_PROGRAM AND EXISTS "${real}")
    execute_process(COMMAND ${DPKG_PROGRAM} -S "${real}"
                    OUTPUT_VARIABLE owner ERROR_QUIET RESULT_VARIABLE rc)
    if(rc EQUAL 0 AND owner MATCHES "^([^:, ]+)")
      set(${var} ${CMAKE_MATCH_1} PARENT_SCOPE)
      return()
    endif()
  endif()
  # Not from a Debian package: name it after the SONAME (libwireshark.so.16 -> libwireshark16).
  set(package ${lib})
  file(GLOB sonames "${WIRESHARK_LIBDIR}/${lib}.so.[0-9]*")
  if(sonames)
    list(SORT sonames)
    list(GET sonames 0 soname)
    string(REGEX REPLACE ".*\\.so\\.([0-9]+).*" "${lib}\\1" package "${soname}")
  endif()
  message(WARNING "dpkg does not know ${real}; the package will depend on ${package}")
  set(${var} ${package} PARENT_SCOPE)
endfunction()
dissgen_library_package(libwireshark libwireshark_package)
dissgen_library_package(libwsutil libwsutil_package)
get_filename_component(libwireshark_real "${WIRESHARK_LIBDIR}/libwireshark.so" REALPATH)

set(CPACK_PACKAGE_DESCRIPTION "\
dissgen turns an XML rule file describing an industrial-Ethernet protocol
into a Wireshark/tshark dissector plugin: it validates the rules, generates
a table-driven C++ dissector, compiles it against the installed libwireshark
and installs it. Edit the rules, run `dissgen install` again, restart
Wireshark: no C code to write.

Includes the EtherCAT rules and their plugin for Wireshark ${ws_lower}.")

set(wireshark_bound "${libwireshark_package} (>= ${ws_lower}), ${libwireshark_package} (<< ${ws_upper})")
# What `dissgen install` runs: a C++ compiler, pkg-config, and Wireshark's
# headers of the same minor release (wireshark.pc requires glib-2.0.pc, which
# libwireshark-dev does not pull in).
set(install_needs "libwireshark-dev (>= ${ws_lower}), libwireshark-dev (<< ${ws_upper}), libglib2.0-dev, g++ | c++-compiler, pkg-config")
# `dissgen report` embeds Debian's dygraphs into its pages.
string(APPEND install_needs ", libjs-dygraphs")

find_program(DPKG_SHLIBDEPS_PROGRAM dpkg-shlibdeps)   # dpkg-dev
find_program(FILE_PROGRAM file)                     # CPack needs it for shlibdeps
if(DPKG_SHLIBDEPS_PROGRAM AND FILE_PROGRAM)
  # libc6, libstdc++6, libxml2, libglib2.0-0, libwireshark16, libwsutil14 with
  # their minimum versions, from the binaries themselves.
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
  # (Its libwireshark16 minimum comes from the symbols file, 2.9.0: hence the explicit bounds.)
  set(CPACK_DEBIAN_PACKAGE_DEPENDS "${wireshark_bound}, ${install_needs}")
else()
  set(CPACK_DEBIAN_PACKAGE_DEPENDS
      "${wireshark_bound}, ${libwsutil_package}, libxml2, libglib2.0-0, libstdc++6, libc6, ${install_needs}")
endif()
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "wireshark | tshark")
message(STATUS "dissgen package: plugins into ${DISSGEN_WIRESHARK_PLUGIN_DIR}; "
               "Depends on ${wireshark_bound} (${libwireshark_real} is in ${libwireshark_package})")

include(CPack)

# --- tests -----------------------------------------------------------------------
# The package, installed and removed for real: CI (CI set, root) only.
add_test(NAME package_deb
         COMMAND bash ${CMAKE_SOURCE_DIR}/tests/package/test_deb.sh
                 --build-dir ${CMAKE_BINARY_DIR} --source-dir ${CMAKE_SOURCE_DIR})
# Installs and removes system files (and tshark output changes meanwhile): alone.
set_tests_properties(package_deb PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 1200 RUN_SERIAL TRUE)

# `dissgen install` refuses headers and a Wireshark of different minor releases.
add_test(NAME version_mismatch
         COMMAND bash ${CMAKE_SOURCE_DIR}/tests/package/test_version_mismatch.sh
                 --dissgen $<TARGET_FILE:dissgen>)
set_tests_properties(version_mismatch PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300)

# The real Wireshark (Qt) under Xvfb with the EtherCAT plugin: starts, loads it
# with no error dialog, shows the rules' tree, quits with status 0 (~15 s; the
# GUI packages are installed when missing in CI only). The screenshot is kept
# as gui/wireshark-ethercat.png in the build tree.
add_test(NAME gui_screenshot
         COMMAND bash ${CMAKE_SOURCE_DIR}/tests/gui/screenshot.sh --ctest --dissgen $<TARGET_FILE:dissgen>
                 --out ${CMAKE_BINARY_DIR}/gui/wireshark-ethercat.png)
set_tests_properties(gui_screenshot PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 600 RESOURCE_LOCK gui)

# The statistics tree of each shipped protocol's cycles, opened from the real
# Wireshark's Statistics menu on a generated capture: its window shows the rows
# tshark -2 -z P.cycles,tree gives (read back through its Save as...); the
# screenshots are kept as gui/statistics-STEM.png (~30 s each).
add_test(NAME gui_cycle_captures
         COMMAND python3 ${CMAKE_SOURCE_DIR}/tests/gui/cycle_captures.py ${CMAKE_BINARY_DIR}/gui/captures)
set_tests_properties(gui_cycle_captures PROPERTIES FIXTURES_SETUP gui_captures)
foreach(entry "ethercat|ECATR|ethercat-two-tasks" "enip|ENIPR|enip-io" "profinet|PNR|profinet-cyclic"
      "powerlink|EPLR|powerlink-cycle")
  string(REPLACE "|" ";" parts "${entry}")
  list(GET parts 0 stem)
  list(GET parts 1 abbreviation)
  list(GET parts 2 capture)
  add_test(NAME gui_statistics_${stem}
           COMMAND bash ${CMAKE_SOURCE_DIR}/tests/gui/screenshot.sh --ctest --dissgen $<TARGET_FILE:dissgen>
                   --rules ${CMAKE_SOURCE_DIR}/rules/${stem}.xml
                   --capture ${CMAKE_BINARY_DIR}/gui/captures/${capture}.pcap
                   --statistics "${abbreviation} cycles" --out ${CMAKE_BINARY_DIR}/gui/statistics-${stem}.png)
  set_tests_properties(gui_statistics_${stem} PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 600
                       FIXTURES_REQUIRED gui_captures RESOURCE_LOCK gui)
endforeach()

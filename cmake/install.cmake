# `cmake --install build [--prefix P]` and `cpack -G DEB` (from build/): the program, its
# man pages and shell completions (written at build time by the program itself, from its
# option definitions: stipplot help-export), and the shipped palettes and device profiles
# under share/stipplot/, where the installed program looks for them by name
# (../share/stipplot beside bin/stipplot).
include(GNUInstallDirs)

set(STIPPLOT_GENERATED ${CMAKE_BINARY_DIR}/generated)
set(STIPPLOT_GENERATED_STAMP ${STIPPLOT_GENERATED}/stamp)
add_custom_command(OUTPUT ${STIPPLOT_GENERATED_STAMP}
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${STIPPLOT_GENERATED}/man1 ${STIPPLOT_GENERATED}/completions
  COMMAND stipplot help-export --format man ${STIPPLOT_GENERATED}/man1
  COMMAND stipplot help-export --format bash ${STIPPLOT_GENERATED}/completions
  COMMAND stipplot help-export --format zsh ${STIPPLOT_GENERATED}/completions
  COMMAND stipplot help-export --format fish ${STIPPLOT_GENERATED}/completions
  COMMAND ${CMAKE_COMMAND} -E touch ${STIPPLOT_GENERATED_STAMP}
  DEPENDS stipplot
  COMMENT "Man pages and shell completions from stipplot's option definitions")
# Part of the default build (not of `--target stipplot`: the demo does without).
add_custom_target(stipplot_manpages ALL DEPENDS ${STIPPLOT_GENERATED_STAMP})

install(TARGETS stipplot RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${STIPPLOT_GENERATED}/man1/ DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 FILES_MATCHING PATTERN "*.1")
install(FILES ${STIPPLOT_GENERATED}/completions/stipplot DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
install(FILES ${STIPPLOT_GENERATED}/completions/_stipplot DESTINATION ${CMAKE_INSTALL_DATADIR}/zsh/site-functions)
install(FILES ${STIPPLOT_GENERATED}/completions/stipplot.fish DESTINATION ${CMAKE_INSTALL_DATADIR}/fish/vendor_completions.d)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/pens/ DESTINATION ${CMAKE_INSTALL_DATADIR}/stipplot/pens
        FILES_MATCHING PATTERN "*.toml")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/drivers/profiles/ DESTINATION ${CMAKE_INSTALL_DATADIR}/stipplot/profiles
        FILES_MATCHING PATTERN "*.toml")

# The Debian package: its Depends are the shared libraries' packages (dpkg-shlibdeps, in
# dpkg-dev) plus the Hershey fonts the text of labels is drawn with, read at run time.
set(CPACK_PACKAGE_NAME stipplot)
set(CPACK_PACKAGE_VENDOR "stipplot")
set(CPACK_PACKAGE_CONTACT "stipplot maintainers <stipplot@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Photographs to pen-plotter drawings, and the plotter driver")
string(CONCAT CPACK_PACKAGE_DESCRIPTION
  "stipplot turns photographs into drawings for pen plotters (stipples, pen sketches, dendritic trees, "
  "pointillism, tone hatching), plans them, writes SVG, G-code or HPGL and drives the plotter.")
set(CPACK_PACKAGE_INSTALL_DIRECTORY stipplot)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "hershey-fonts-data")
include(CPack)

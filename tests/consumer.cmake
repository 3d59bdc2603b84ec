# The installed package used from outside, as an FE code would (tests/consumer/): the built project is
# installed once into a prefix inside the build tree (a fixture), then tests/consumer/main.cpp is built
# and run through find_package(MeccanoImmerse) and through pkg-config. Included by tests/CMakeLists.txt.
set(MECCANO_CONSUMER_SCRIPT ${CMAKE_CURRENT_SOURCE_DIR}/consumer/run_consumer.sh)
set(MECCANO_CONSUMER_WORK ${CMAKE_CURRENT_BINARY_DIR}/consumer)

add_test(NAME consumer_install
  COMMAND bash ${MECCANO_CONSUMER_SCRIPT} install ${MECCANO_CONSUMER_WORK} ${PROJECT_BINARY_DIR})
add_test(NAME consumer_find_package
  COMMAND bash ${MECCANO_CONSUMER_SCRIPT} cmake ${MECCANO_CONSUMER_WORK})
add_test(NAME consumer_pkg_config
  COMMAND bash ${MECCANO_CONSUMER_SCRIPT} pkg-config ${MECCANO_CONSUMER_WORK} ${CMAKE_INSTALL_LIBDIR})

set_tests_properties(consumer_install consumer_find_package consumer_pkg_config PROPERTIES
  ENVIRONMENT "CMAKE=${CMAKE_COMMAND};CXX=${CMAKE_CXX_COMPILER}"
  TIMEOUT 600
  LABELS pipeline)
set_tests_properties(consumer_install PROPERTIES FIXTURES_SETUP meccano_installed)
set_tests_properties(consumer_find_package consumer_pkg_config PROPERTIES FIXTURES_REQUIRED meccano_installed)

# The deal.II adapter, when it is built: a deal.II program against the installed target (the user
# guide's example).
if(TARGET meccano_dealii)
  add_test(NAME consumer_dealii COMMAND bash ${MECCANO_CONSUMER_SCRIPT} dealii ${MECCANO_CONSUMER_WORK})
  set_tests_properties(consumer_dealii PROPERTIES
    ENVIRONMENT "CMAKE=${CMAKE_COMMAND};CXX=${CMAKE_CXX_COMPILER}"
    TIMEOUT 900
    FIXTURES_REQUIRED meccano_installed
    LABELS long)
endif()

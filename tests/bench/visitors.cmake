# The visitors' evaluation set (tests/data/visitors): its builder, and the
# benchmark that feeds it through the kiosk pipeline. Built with the tests, run on demand.
add_executable(sp-visitors-make tools/visitors_make.c)
target_link_libraries(sp-visitors-make PRIVATE sp_render sp::classifier sp::solver PkgConfig::CJSON ${MATH_LIB})
add_executable(bench_visitors bench/visitors.c)
target_link_libraries(bench_visitors PRIVATE sp_test_fixtures sp_dragon sp_render sp_kiosk_ui)
set_target_properties(bench_visitors PROPERTIES OUTPUT_NAME visitors RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests/bench)

# The whole set, the Quick, Draw! drawings included, built into the build
# folder from designs.json and the data: the repository keeps the hand-placed
# drawings only (the data's terms ask that it not be copied). Without the data
# the set is the hand-placed drawings. Whether the data is there is looked at
# on each build, not at configure: data that came later used to leave a set
# without it, and tests that found the data judged that set as if it had it.
set(SP_VISITORS_DIR ${PROJECT_BINARY_DIR}/tests/data/visitors)
set(SP_VISITORS_SOURCE ${PROJECT_BINARY_DIR}/visitors-source.txt)
add_custom_target(sp_visitors_source
  COMMAND ${CMAKE_COMMAND} -DQD=${SP_SHARED_DATA}/quickdraw -DSTAMP=${SP_VISITORS_SOURCE}
          -P ${CMAKE_CURRENT_SOURCE_DIR}/tools/visitors_source.cmake
  BYPRODUCTS ${SP_VISITORS_SOURCE} VERBATIM)
add_custom_command(OUTPUT ${SP_VISITORS_DIR}/built
  COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:sp-visitors-make> -DDESIGNS=${PROJECT_SOURCE_DIR}/tests/data/visitors/designs.json
          -DQD=${SP_SHARED_DATA}/quickdraw -DOUT=${SP_VISITORS_DIR} -DLOG=${PROJECT_BINARY_DIR}/visitors-make.json
          -DSTAMP=${SP_VISITORS_SOURCE} -P ${CMAKE_CURRENT_SOURCE_DIR}/tools/visitors_build.cmake
  DEPENDS sp-visitors-make ${PROJECT_SOURCE_DIR}/tests/data/visitors/designs.json ${SP_VISITORS_SOURCE}
          ${CMAKE_CURRENT_SOURCE_DIR}/tools/visitors_build.cmake
  COMMENT "Building the visitors' drawings in ${SP_VISITORS_DIR}" VERBATIM)
add_custom_target(sp_visitors_data ALL DEPENDS ${SP_VISITORS_DIR}/built)
add_dependencies(sp_visitors_data sp_visitors_source)
add_test(NAME visitors_set COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:sp-visitors-make> -DSRC=${PROJECT_SOURCE_DIR}
                                   -DOUT=${PROJECT_BINARY_DIR}/visitors-check -DQD=${SP_SHARED_DATA}/quickdraw
                                   -P ${CMAKE_CURRENT_SOURCE_DIR}/tools/visitors_check.cmake)

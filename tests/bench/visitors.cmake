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
# the set is the hand-placed drawings.
set(SP_VISITORS_DIR ${PROJECT_BINARY_DIR}/tests/data/visitors)
set(SP_VISITORS_QD)
if(EXISTS ${SP_SHARED_DATA}/quickdraw)
  set(SP_VISITORS_QD --quickdraw ${SP_SHARED_DATA}/quickdraw)
endif()
add_custom_command(OUTPUT ${SP_VISITORS_DIR}/built
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${SP_VISITORS_DIR}
  COMMAND sp-visitors-make --designs ${PROJECT_SOURCE_DIR}/tests/data/visitors/designs.json ${SP_VISITORS_QD} --out ${SP_VISITORS_DIR} > ${PROJECT_BINARY_DIR}/visitors-make.json
  COMMAND ${CMAKE_COMMAND} -E touch ${SP_VISITORS_DIR}/built
  DEPENDS sp-visitors-make ${PROJECT_SOURCE_DIR}/tests/data/visitors/designs.json
  COMMENT "Building the visitors' drawings in ${SP_VISITORS_DIR}")
add_custom_target(sp_visitors_data ALL DEPENDS ${SP_VISITORS_DIR}/built)
set(SP_VISITORS_CHECK_QD)
if(EXISTS ${SP_SHARED_DATA}/quickdraw)
  set(SP_VISITORS_CHECK_QD -DQD=${SP_SHARED_DATA}/quickdraw)
endif()
add_test(NAME visitors_set COMMAND ${CMAKE_COMMAND} -DTOOL=$<TARGET_FILE:sp-visitors-make> -DSRC=${PROJECT_SOURCE_DIR}
                                   -DOUT=${PROJECT_BINARY_DIR}/visitors-check ${SP_VISITORS_CHECK_QD}
                                   -P ${CMAKE_CURRENT_SOURCE_DIR}/tools/visitors_check.cmake)

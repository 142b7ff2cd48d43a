if(TARGET sketchpose)
  add_test(NAME posing_cli COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/e2e/posing_cli.sh $<TARGET_FILE:sketchpose>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR} ${SP_SHARED_DATA})
  set_tests_properties(posing_cli PROPERTIES TIMEOUT 300)
endif()

# End-to-end tests of `sketchpose inspect` / `export` (tests/e2e/gltf_cli.sh)
# and the Khronos validator on exports (tests/e2e/gltf_validate.sh, skipped
# with code 77 until `npm ci` has run in tests/tools).
if(TARGET sketchpose)
  add_test(NAME cli_gltf COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/e2e/gltf_cli.sh $<TARGET_FILE:sketchpose>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR})
  set_tests_properties(cli_gltf PROPERTIES TIMEOUT 120)
  add_test(NAME gltf_validator COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/e2e/gltf_validate.sh $<TARGET_FILE:sketchpose>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR} ${SP_SHARED_DATA})
  set_tests_properties(gltf_validator PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 77)
endif()

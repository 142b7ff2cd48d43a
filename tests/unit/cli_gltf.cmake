# End-to-end tests of `sketchpose inspect` / `export` (tests/e2e/gltf_cli.sh)
# and the Khronos validator on exports (tests/e2e/gltf_validate.sh, skipped
# with code 77 until `npm ci` has run in tests/tools, failed under
# SP_TEST_REQUIRE_TOOLS=1).
if(TARGET sketchpose)
  add_test(NAME cli_gltf COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/e2e/gltf_cli.sh $<TARGET_FILE:sketchpose>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR})
  set_tests_properties(cli_gltf PROPERTIES TIMEOUT 120)
  add_test(NAME gltf_validator COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/e2e/gltf_validate.sh $<TARGET_FILE:sketchpose>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR} ${SP_SHARED_DATA})
  set_tests_properties(gltf_validator PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 77)
  # Under tools/sp test (SP_TEST_REQUIRE_TOOLS=1) a missing validator fails
  # the script; alone, it skips.
  add_test(NAME gltf_validator_required COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/e2e/gltf_validate.sh $<TARGET_FILE:sketchpose>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR})
  set_tests_properties(gltf_validator_required PROPERTIES ENVIRONMENT
    "SP_TEST_TOOLS_DIR=${PROJECT_BINARY_DIR}/no_tools;SP_TEST_REQUIRE_TOOLS=1"
    PASS_REGULAR_EXPRESSION "FAIL: node or .*/no_tools/node_modules/gltf-validator is not installed, and SP_TEST_REQUIRE_TOOLS=1")
  add_test(NAME gltf_validator_optional COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/e2e/gltf_validate.sh $<TARGET_FILE:sketchpose>
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR})
  set_tests_properties(gltf_validator_optional PROPERTIES ENVIRONMENT
    "SP_TEST_TOOLS_DIR=${PROJECT_BINARY_DIR}/no_tools;SP_TEST_REQUIRE_TOOLS=0"
    PASS_REGULAR_EXPRESSION "SKIP: node or .*/no_tools/node_modules/gltf-validator is missing")
endif()

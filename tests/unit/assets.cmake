# The generated assets (assets/*.glb, issue 4): byte-identical regeneration
# with sp-assetgen, contents, folds under random poses, the Khronos
# validator and a real glTF client, glTF Transform (both skipped without
# tests/tools/node_modules), and the solver's
# recovery rate on every dragon part and per abstraction of the characters
# (cartoon_man stick and outline, elephant stick). One CTest entry per check and per part
# so that they run in parallel (the sanitizer build runs the first 10 seeds
# of each part's recovery and does not assert the rate).
add_executable(test_assets unit/test_assets.c)
target_link_libraries(test_assets PRIVATE sp_test_fixtures sp::partdb PkgConfig::CJSON)
target_compile_definitions(test_assets PRIVATE SP_ASSETGEN="$<TARGET_FILE:sp-assetgen>")
add_dependencies(test_assets sp-assetgen)
foreach(check regenerate_identical contents line characters random_poses validator gltf_client)
  add_test(NAME assets_${check} COMMAND test_assets ${check})
  set_tests_properties(assets_${check} PROPERTIES TIMEOUT 300 ENVIRONMENT "SP_BUILD_DIR=${PROJECT_BINARY_DIR}")
endforeach()
# sp_fixture_node_tools: a missing validator skips, and fails the test under
# SP_TEST_REQUIRE_TOOLS=1 (what tools/sp test sets).
foreach(req 0 1)
  add_test(NAME assets_validator_missing_${req} COMMAND test_assets validator)
  set_tests_properties(assets_validator_missing_${req} PROPERTIES ENVIRONMENT
    "SP_BUILD_DIR=${PROJECT_BINARY_DIR};SP_TEST_TOOLS_DIR=${PROJECT_BINARY_DIR}/no_tools;SP_TEST_REQUIRE_TOOLS=${req}")
endforeach()
set_tests_properties(assets_validator_missing_0 PROPERTIES PASS_REGULAR_EXPRESSION "SKIP validator")
set_tests_properties(assets_validator_missing_1 PROPERTIES PASS_REGULAR_EXPRESSION
  "no_tools/node_modules/gltf-validator\\), and SP_TEST_REQUIRE_TOOLS=1: failing, not skipping")

add_executable(test_assets_recovery unit/test_assets_recovery.c)
target_link_libraries(test_assets_recovery PRIVATE sp_test_fixtures sp::partdb)
if(SP_SANITIZE)
  target_compile_definitions(test_assets_recovery PRIVATE SP_ASSETS_RECOVERY_CASES=10)
endif()
foreach(part torso tail head wings front_legs hind_legs cartoon_man_stick cartoon_man_outline elephant_stick)
  add_test(NAME assets_recovery_${part} COMMAND test_assets_recovery ${part})
  set_tests_properties(assets_recovery_${part} PROPERTIES TIMEOUT 600 ENVIRONMENT "SP_BUILD_DIR=${PROJECT_BINARY_DIR}")
endforeach()

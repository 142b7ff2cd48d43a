# "Identical output" (issue 18): fixed seeds on the shipped assets, the face
# plugin and a dragon session through the kiosk pipeline, compared with the
# pins in unit/identical_pins.txt (iterations, rounds, stop reasons; errors
# and energies to 1e-9). `build/tests/test_identical --repin` re-pins.
# One CTest entry per group so that they run in parallel.
add_executable(test_identical unit/test_identical.c)
target_link_libraries(test_identical PRIVATE sp_test_fixtures sp::partdb sp::plugin)
target_compile_definitions(test_identical PRIVATE SP_FACE_PLUGIN="$<TARGET_FILE:sp_face>")
add_dependencies(test_identical sp_face)
if(TARGET sp_dragon)
  target_link_libraries(test_identical PRIVATE sp_dragon)
  target_compile_definitions(test_identical PRIVATE SP_IDENTICAL_DRAGON)
endif()
foreach(group assets face dragon)
  add_test(NAME identical_${group} COMMAND test_identical ${group})
  set_tests_properties(identical_${group} PROPERTIES TIMEOUT 300 ENVIRONMENT "SP_BUILD_DIR=${PROJECT_BINARY_DIR}")
endforeach()

# Black-box rigs (solver/include/sp/blackbox.h): finite differences against
# analytic Jacobians, threads, the plugin loader's errors (small plugins
# built from unit/blackbox_plugin.c, one defect each), recovery on the face
# plugin, and `sketchpose synth/pose --rig face.so`.
sp_unit_test(blackbox TIMEOUT 300 LIBS sp::plugin)
set(SP_TEST_PLUGIN_DIR ${PROJECT_BINARY_DIR}/tests/plugins)
foreach(variant good nosym null badversion badsize badtri badrest nan nanlater)
  add_library(sp_test_bb_${variant} MODULE unit/blackbox_plugin.c)
  target_compile_definitions(sp_test_bb_${variant} PRIVATE SP_TEST_PLUGIN_${variant})
  target_include_directories(sp_test_bb_${variant} PRIVATE ${PROJECT_SOURCE_DIR}/solver/include)
  target_link_libraries(sp_test_bb_${variant} PRIVATE sp_flags ${MATH_LIB})
  set_target_properties(sp_test_bb_${variant} PROPERTIES C_VISIBILITY_PRESET hidden LIBRARY_OUTPUT_DIRECTORY ${SP_TEST_PLUGIN_DIR})
  add_dependencies(test_blackbox sp_test_bb_${variant})
endforeach()
target_compile_definitions(test_blackbox PRIVATE SP_FACE_PLUGIN="$<TARGET_FILE:sp_face>" SP_TEST_PLUGIN_DIR="${SP_TEST_PLUGIN_DIR}")
add_dependencies(test_blackbox sp_face)
if(TARGET sketchpose)
  add_dependencies(test_blackbox sketchpose)
endif()

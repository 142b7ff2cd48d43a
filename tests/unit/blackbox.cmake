# Black-box rigs (solver/include/sp/blackbox.h): finite differences against
# analytic Jacobians, threads, the plugin loader's errors (small plugins
# built from unit/blackbox_plugin.c, one defect each), recovery on the face
# plugin, and `sketchpose synth/pose --rig face.so`.
sp_unit_test(blackbox TIMEOUT 300 LIBS sp::plugin)
# test_creation_says_why stands in for pthread_create.
target_link_options(test_blackbox PRIVATE -Wl,--wrap=pthread_create)
set(SP_TEST_PLUGIN_DIR ${PROJECT_BINARY_DIR}/tests/plugins)
foreach(variant good nosym null badversion badsize badtri badrest nan nanlater)
  add_library(sp_test_bb_${variant} MODULE unit/blackbox_plugin.c)
  target_compile_definitions(sp_test_bb_${variant} PRIVATE SP_TEST_PLUGIN_${variant})
  target_include_directories(sp_test_bb_${variant} PRIVATE ${PROJECT_SOURCE_DIR}/solver/include)
  target_link_libraries(sp_test_bb_${variant} PRIVATE sp_flags ${MATH_LIB})
  set_target_properties(sp_test_bb_${variant} PROPERTIES C_VISIBILITY_PRESET hidden LIBRARY_OUTPUT_DIRECTORY ${SP_TEST_PLUGIN_DIR})
  add_dependencies(test_blackbox sp_test_bb_${variant})
endforeach()
# docs/blackbox.md's example plugin, built as a reader would copy it.
file(READ ${PROJECT_SOURCE_DIR}/docs/blackbox.md SP_BB_DOC)
string(REGEX MATCH "```c\n([^`]*)```" SP_BB_DOC_C "${SP_BB_DOC}")
if(NOT CMAKE_MATCH_1)
  message(FATAL_ERROR "docs/blackbox.md has no ```c example plugin")
endif()
file(GENERATE OUTPUT ${PROJECT_BINARY_DIR}/tests/doc_sheet_plugin.c CONTENT "${CMAKE_MATCH_1}")
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/docs/blackbox.md)
add_library(sp_test_bb_doc MODULE ${PROJECT_BINARY_DIR}/tests/doc_sheet_plugin.c)
target_include_directories(sp_test_bb_doc PRIVATE ${PROJECT_SOURCE_DIR}/solver/include)
target_link_libraries(sp_test_bb_doc PRIVATE sp_flags ${MATH_LIB})
set_target_properties(sp_test_bb_doc PROPERTIES C_VISIBILITY_PRESET hidden LIBRARY_OUTPUT_DIRECTORY ${SP_TEST_PLUGIN_DIR})
add_dependencies(test_blackbox sp_test_bb_doc)
target_compile_definitions(test_blackbox PRIVATE SP_FACE_PLUGIN="$<TARGET_FILE:sp_face>" SP_TEST_PLUGIN_DIR="${SP_TEST_PLUGIN_DIR}")
add_dependencies(test_blackbox sp_face)
if(TARGET sketchpose)
  add_dependencies(test_blackbox sketchpose)
endif()

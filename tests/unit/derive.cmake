# Deriving kiosk parts from rigged glTF made elsewhere (issue 17): sp/derive.h,
# `sketchpose derive` and `db add-part` on the project-made lizard
# (tests/support/foreign_gltf.h) and, when present, the Khronos samples of
# ../shared/data/gltf; the outline measured on rendered silhouettes (EGL), the
# Khronos validator (skipped without tests/tools/node_modules) and the kiosk
# pipeline after `db train`. One CTest entry per check so that they run in parallel.
if(TARGET sketchpose)
  add_executable(test_derive unit/test_derive.c)
  target_link_libraries(test_derive PRIVATE sp_test_fixtures sp_render sp::partdb PkgConfig::CJSON)
  add_dependencies(test_derive sketchpose)
  set(timeout 300)
  if(SP_SANITIZE)
    set(timeout 1200)
  endif()
  foreach(check what_is_derived options part_carried zup_and_facing refusals collapsed_skin cli add_part_cli_notes silhouette_lizard silhouette_khronos outline_regions selftest validator pipeline)
    add_test(NAME derive_${check} COMMAND test_derive ${check})
    set_tests_properties(derive_${check} PROPERTIES TIMEOUT ${timeout} ENVIRONMENT "SP_BUILD_DIR=${PROJECT_BINARY_DIR}")
  endforeach()
endif()

# The headless kiosk pipeline (sp_dragon, app/dragon) and `sketchpose dragon`.
# Builds its own parts in a temp database; `six_real_parts` uses assets/ when it
# holds parts (skipped before). The validator checks run when tests/tools has
# node_modules (tools/sp installs them), else they say so and pass.
if(TARGET sp_dragon)
  sp_unit_test(dragon LIBS sp_dragon sp_dragon_snapshot SQLite::SQLite3 TIMEOUT 600)
  target_compile_definitions(test_dragon PRIVATE SP_SKETCHPOSE="$<TARGET_FILE:sketchpose>")
  add_dependencies(test_dragon sketchpose)
  # The pipeline's internals, for fault injection (a NaN in a fit).
  target_include_directories(test_dragon PRIVATE ${PROJECT_SOURCE_DIR}/app/dragon/src)
endif()

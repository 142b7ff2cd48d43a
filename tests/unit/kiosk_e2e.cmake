# The kiosk window end to end under Xvfb (tests/unit/test_kiosk_e2e.c): scripted
# sessions draw a dragon, play, turn, save; storms of bad input; record ->
# replay; the database replaced while running; visitors' strokes collected,
# reviewed (sketchpose db review) and trained on (db train). Skips itself without xvfb-run.
if(TARGET dragon-kiosk)
  sp_unit_test(kiosk_e2e LIBS sp_kiosk sp_render sp::partdb SQLite::SQLite3 TIMEOUT 900)
  target_compile_definitions(test_kiosk_e2e PRIVATE SP_DRAGON_KIOSK="$<TARGET_FILE:dragon-kiosk>")
  target_include_directories(test_kiosk_e2e PRIVATE ${PROJECT_SOURCE_DIR}/app/kiosk) # the collector alone (collect_mended)
  add_dependencies(test_kiosk_e2e dragon-kiosk sketchpose)
endif()

# The kiosk's UI state machine, session files and display-mesh LOD, without GL or a window:
# the test compiles app/src/kiosk/ui.c, session.c and lod.c itself (they need only
# libc, cJSON and sp_fail), so it runs wherever the build does.
sp_unit_test(kiosk_ui LIBS PkgConfig::CJSON ${MATH_LIB} TIMEOUT 120)
target_sources(test_kiosk_ui PRIVATE ${PROJECT_SOURCE_DIR}/app/src/kiosk/ui.c ${PROJECT_SOURCE_DIR}/app/src/kiosk/session.c
                                     ${PROJECT_SOURCE_DIR}/app/src/kiosk/lod.c)
target_include_directories(test_kiosk_ui PRIVATE ${PROJECT_SOURCE_DIR}/app/src/kiosk)

# The kiosk's UI state machine, session files and display-mesh LOD, without GL
# or a window: the GL-free sp_kiosk_ui library (app/kiosk_ui), so it runs
# wherever the build does.
if(TARGET sp_kiosk_ui)
  sp_unit_test(kiosk_ui LIBS sp_kiosk_ui PkgConfig::CJSON ${MATH_LIB} TIMEOUT 120)
endif()

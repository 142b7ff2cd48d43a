if(TARGET sp_app_common)
  sp_unit_test(outputs LIBS sp_app_common)
endif()

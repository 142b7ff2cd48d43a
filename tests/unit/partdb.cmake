# The part database (partdb's SQLite store). The test reaches partdb's private
# header for the test hook and helpers, and drives `sketchpose db` for the
# command-line cases (skipped when the app is not built).
find_package(SQLite3 REQUIRED)
sp_unit_test(partdb LIBS sp::partdb SQLite::SQLite3 PkgConfig::CJSON TIMEOUT 600)
target_include_directories(test_partdb PRIVATE ${PROJECT_SOURCE_DIR}/partdb/src)
if(TARGET sketchpose)
  add_dependencies(test_partdb sketchpose)
endif()
# test_partdb's `durable` case records fsync, rename and link through the
# linker (a write's order of calls is what makes it survive a power cut).
target_link_options(test_partdb PRIVATE -Wl,--wrap=fsync,--wrap=rename,--wrap=link)

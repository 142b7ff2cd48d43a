sp_unit_test(recovery LIBS sp::partdb TIMEOUT 900)

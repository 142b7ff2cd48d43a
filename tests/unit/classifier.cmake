sp_unit_test(classifier LIBS sp::classifier TIMEOUT 120)

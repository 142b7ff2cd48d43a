sp_unit_test(rig LIBS sp::solver)

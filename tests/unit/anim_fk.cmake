sp_unit_test(anim_fk LIBS sp::partdb)

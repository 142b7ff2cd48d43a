sp_unit_test(classifier LIBS sp::classifier ZLIB::ZLIB TIMEOUT 120)

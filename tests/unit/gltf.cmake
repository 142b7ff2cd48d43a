# glTF import/export (partdb's tinygltf adapter). The test reaches the
# adapter's private header for constants (SP_STICK_POINTS_PER_BONE).
sp_unit_test(gltf LIBS sp::partdb)
target_include_directories(test_gltf PRIVATE ${PROJECT_SOURCE_DIR}/partdb/src)
